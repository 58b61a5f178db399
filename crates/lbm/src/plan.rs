//! Per-row work plan derived from the geometry: which runs of nodes take the branch-free fast
//! path (fluid node whose every upstream neighbour is fluid and inside the box without an x wrap),
//! which nodes sit on a periodic x edge with only fluid neighbours (a cheap path with wrapped
//! indices), which nodes need the general path (walls, obstacles, Zou-He), the runs of fluid
//! nodes of each row, and the list of boundary links used for the momentum-exchange force
//! (Leonardi Eq. 21).

use crate::domain::{Domain, FLUID, Face, NO_OBSTACLE};
use crate::lattice::Lattice;

/// Id of the force target of a link: obstacles are 0.., the six faces follow the obstacles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Link {
    /// Fluid node.
    pub node: u32,
    /// Direction from the fluid node into the wall.
    pub dir: u8,
    /// Obstacle id, or `n_obstacles + face` for a box wall, or `u16::MAX` for an inactive node.
    pub target: u16,
}

#[derive(Clone, Debug, Default)]
pub struct Plan {
    /// Fast spans [x0, x1) of each row, flat; row r owns `spans[span_start[r]..span_start[r+1]]`.
    pub span_start: Vec<u32>,
    pub spans: Vec<(u32, u32)>,
    /// x of each general-path node, flat, same scheme.
    pub gen_start: Vec<u32>,
    pub gens: Vec<u32>,
    /// x of each periodic-edge node whose every neighbour is a fluid node (through the x wrap).
    pub wrap_start: Vec<u32>,
    pub wraps: Vec<u32>,
    /// Runs [x0, x1) of fluid nodes of each row (the AA kernel's local even step).
    pub run_start: Vec<u32>,
    pub runs: Vec<(u32, u32)>,
    pub links: Vec<Link>,
    pub fluid_nodes: usize,
}

/// Where the upstream node of `x` along `-c` is: inside (index), or outside through face `f`.
pub enum Upstream {
    Node(usize),
    Face(usize),
}

/// The node at `p + d` with periodic wrap, or the non-periodic face it leaves through.
#[inline]
pub fn neighbour(dom: &Domain, p: [usize; 3], d: [i32; 3]) -> Upstream {
    let mut q = [0usize; 3];
    let mut face = None;
    for a in 0..3 {
        let n = dom.n[a] as i64;
        let mut s = p[a] as i64 + d[a] as i64;
        if s < 0 || s >= n {
            let f = 2 * a + usize::from(s >= n);
            if dom.faces[f].is_periodic() {
                s = s.rem_euclid(n);
            } else {
                // a wall face takes precedence over a Zou-He face at an edge or corner
                match face {
                    Some(g) if matches!(dom.faces[g], Face::Wall { .. }) => {}
                    _ => face = Some(f),
                }
                s = s.clamp(0, n - 1);
            }
        }
        q[a] = s as usize;
    }
    match face {
        Some(f) => Upstream::Face(f),
        None => Upstream::Node(dom.index(q[0], q[1], q[2])),
    }
}

impl Plan {
    pub fn build<L: Lattice>(dom: &Domain, n_obstacles: usize) -> Self {
        let [nx, ny, nz] = dom.n;
        let rows = ny * nz;
        let mut plan = Plan {
            span_start: Vec::with_capacity(rows + 1),
            gen_start: Vec::with_capacity(rows + 1),
            wrap_start: Vec::with_capacity(rows + 1),
            run_start: Vec::with_capacity(rows + 1),
            ..Default::default()
        };
        for r in 0..rows {
            plan.span_start.push(plan.spans.len() as u32);
            plan.gen_start.push(plan.gens.len() as u32);
            plan.wrap_start.push(plan.wraps.len() as u32);
            plan.run_start.push(plan.runs.len() as u32);
            let (y, z) = (r % ny, r / ny);
            let mut run: Option<u32> = None;
            let mut fluid_run: Option<u32> = None;
            for x in 0..nx {
                let idx = dom.index(x, y, z);
                let fluid = dom.kind[idx] == FLUID;
                // every upstream neighbour a fluid node (through periodic faces)
                let mut inner = fluid;
                let mut clean = fluid && x >= 1 && x + 1 < nx;
                if fluid {
                    plan.fluid_nodes += 1;
                    for i in 1..L::Q {
                        let c = L::C[i];
                        // pull source x - c_i
                        let up = neighbour(dom, [x, y, z], [-c[0], -c[1], -c[2]]);
                        match up {
                            Upstream::Node(s) => inner &= dom.kind[s] == FLUID,
                            Upstream::Face(_) => inner = false,
                        }
                        // link x -> x + c_i into a wall, for the momentum exchange
                        let target = match neighbour(dom, [x, y, z], c) {
                            Upstream::Node(s) if dom.kind[s] != FLUID => Some(dom.obstacle[s]),
                            Upstream::Node(_) => None,
                            Upstream::Face(f) => match dom.faces[f] {
                                Face::Wall { .. } => Some((n_obstacles + f) as u16),
                                _ => None,
                            },
                        };
                        if let Some(t) = target {
                            let t = if t == NO_OBSTACLE { u16::MAX } else { t };
                            plan.links.push(Link {
                                node: idx as u32,
                                dir: i as u8,
                                target: t,
                            });
                        }
                    }
                }
                clean &= inner;
                match (fluid, fluid_run) {
                    (true, None) => fluid_run = Some(x as u32),
                    (false, Some(x0)) => {
                        plan.runs.push((x0, x as u32));
                        fluid_run = None;
                    }
                    _ => {}
                }
                match (clean, run) {
                    (true, None) => run = Some(x as u32),
                    (false, Some(x0)) => {
                        plan.spans.push((x0, x as u32));
                        run = None;
                    }
                    _ => {}
                }
                if inner && !clean {
                    plan.wraps.push(x as u32);
                } else if fluid && !clean {
                    plan.gens.push(x as u32);
                }
            }
            if let Some(x0) = run {
                plan.spans.push((x0, nx as u32));
            }
            if let Some(x0) = fluid_run {
                plan.runs.push((x0, nx as u32));
            }
        }
        plan.span_start.push(plan.spans.len() as u32);
        plan.gen_start.push(plan.gens.len() as u32);
        plan.wrap_start.push(plan.wraps.len() as u32);
        plan.run_start.push(plan.runs.len() as u32);
        plan
    }
}
