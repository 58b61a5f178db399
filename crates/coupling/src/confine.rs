//! The liquid confined to the sample (Su et al. 2020 Sect. 2.4, Fig. 2 step 15): "the LBM nodes
//! outside of the DEM membrane boundary or overlapping with the push-plate were identified as an
//! effective solid zone", rebuilt before every LBM step from the membrane's shape and the
//! plate's position. The lattice is larger than the sample so the membrane can move.
//!
//! The membrane boundary is the polygon joining the centroids of the membrane grains (the one of
//! Eq. 18); a push-plate's solid region is the quadrilateral behind its segment
//! (`lbdem_dem::polygon::plate_region`). Nodes behind a plate show the liquid the plate's
//! velocity. Nodes outside the polygon show it either a wall at rest ([`MembraneBoundary::AtRest`],
//! step 15 as written) or the membrane's own velocity, interpolated along the polygon's edges
//! ([`MembraneBoundary::Moving`]). The moving boundary hands the reaction of its bounce-back to
//! the two membrane grains of each edge, so that no momentum goes unpaid: an earlier version
//! showed the nearest grain's velocity without the reaction and ran away at the paper's
//! densities (docs/su2020.md, "The liquid confined to the sample"). Its bounce-back would also
//! push the swept liquid ahead of a moving membrane and seal the sample; the mass it puts in is
//! taken out again in proportion to every node's ([`PsmFluid::set_pull_scale`]), so the liquid's
//! mass still follows the sample's area, as with the zone at rest.

use crate::error::CouplingError;
use crate::psm::{LIQUID, Load, PsmFluid};
use crate::units::CouplingUnits;
use lbdem_dem::System;
use lbdem_dem::Vec2;
use lbdem_dem::polygon::{plate_region, scan_rows};
use lbdem_dem::vector::Vector;
use lbdem_lbm::Real;
use rayon::prelude::*;

/// What the liquid sees outside the membrane polygon.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MembraneBoundary {
    /// A wall at rest (Su et al. 2020 step 15 as written): a rising membrane closes over the
    /// liquid next to it and takes it away, a sink wherever the liquid moves with it.
    #[default]
    AtRest,
    /// A wall moving with the membrane (velocity interpolated along the polygon's edges), whose
    /// reaction the membrane grains feel. Explicit, a step behind: a membrane on undamped bonds
    /// rings under it at the LBM step's period until the lattice blows up; with damped bonds it
    /// runs at the paper's masses (docs/su2020.md, "The membrane's bonds must be damped").
    Moving,
}

/// A zone node next to the membrane: the velocity index it shows, and where on which edge.
#[derive(Clone, Copy, Debug)]
struct EdgeNode {
    node: usize,
    /// Index of its velocity (the zone value).
    index: u32,
    /// The edge's end grains (body indices) and the node's place between them (0 at `a`).
    a: u32,
    b: u32,
    /// The same grains' places in the ring.
    ra: u32,
    rb: u32,
    t: f64,
}

/// How far from an edge (lattice units) its nodes are found: a zone node with a liquid
/// neighbour lies within √2 of the polygon.
const EDGE_REACH: f64 = 1.5;

/// Which nodes hold liquid, recomputed from the grains and walls.
#[derive(Clone, Debug)]
pub struct Confinement {
    /// Membrane members in ring order (`Membrane::ring_order`).
    order: Vec<usize>,
    /// Walls (indices in `System::walls`) whose region behind is solid: the push-plates.
    plates: Vec<usize>,
    boundary: MembraneBoundary,
    zone: Vec<u32>,
    velocities: Vec<[f64; 3]>,
    /// Zone nodes showing the membrane's velocity ([`MembraneBoundary::Moving`]).
    edge_nodes: Vec<EdgeNode>,
    /// Scratch: squared distance to the nearest edge found so far, and that edge (`Moving`).
    nearest: Vec<(f64, u32, f64)>,
    /// Velocity slots of the edge nodes (`Moving`), kept while a node stays on the edge.
    slots: EdgeSlots,
    /// Where each membrane grain (ring order) was at the last call of [`Confinement::zone`]
    /// (`Moving`): the boundary shows its mean velocity over the last LBM cycle.
    previous: Vec<Vec2>,
    /// The velocity each membrane grain (ring order) showed the liquid at the last step
    /// (`Moving`), and the weight ω of the new mean in the next one (1: none kept).
    shown: Vec<Vec2>,
    relaxation: f64,
}

impl Confinement {
    /// Confine the liquid to the membrane of `sys` minus the regions behind the walls `plates`.
    pub fn new(sys: &System, plates: Vec<usize>, boundary: MembraneBoundary) -> Result<Self, CouplingError> {
        let mem = sys.membrane.as_ref().ok_or_else(|| {
            CouplingError::Unsupported(
                "confining the liquid needs a membrane: add [membrane] (and [bonds]) to the scene".into(),
            )
        })?;
        if mem.bodies.len() < 3 {
            return Err(CouplingError::Unsupported(format!(
                "the membrane has {} grains: a sample outline needs at least 3; widen [membrane] shell",
                mem.bodies.len()
            )));
        }
        for &k in &plates {
            let w = sys.walls.get(k).ok_or_else(|| {
                CouplingError::Unsupported(format!("push-plate wall {k} of {}", sys.walls.len()))
            })?;
            if plate_region(w).is_none() {
                return Err(CouplingError::Unsupported(format!(
                    "wall {k} is the push-plate but has no region behind it: give it a segment \
                     (a, b) and a velocity"
                )));
            }
        }
        Ok(Self {
            order: mem.ring_order(),
            plates,
            boundary,
            zone: Vec::new(),
            velocities: Vec::new(),
            edge_nodes: Vec::new(),
            nearest: Vec::new(),
            slots: EdgeSlots::default(),
            previous: Vec::new(),
            shown: Vec::new(),
            relaxation: 1.0,
        })
    }

    /// Show the liquid ω × the membrane's mean velocity over the last LBM cycle plus (1 − ω) ×
    /// what it showed the step before (`Moving`; ω = 1 keeps nothing). The reaction is
    /// explicit, a step behind the velocity it answers: for a plain added-mass lag (gain a, the
    /// liquid's mass the bounce-back drives over the grain's) v' = v − a u, u' = ω v + (1 − ω) u
    /// is stable for a < (4 − 2ω)/ω, so a smaller ω carries lighter membranes. Measured, it
    /// helps but is no cure: on six random replicas of the reduced cell with the membrane 2.7
    /// times the liquid's density, ω = 1 blew up in all six, ½ and ¼ in none; at 1.8 times ½
    /// blew up in all six and ¼ in four, at 0.9 times ½ in two and ¼ in none (docs/su2020.md,
    /// "Under-relaxing the membrane's velocity"). The cure was damping the membrane's bonds: the
    /// blow-ups were the membrane ringing on them, driven by the late reaction. What it shows
    /// lags the membrane by (1 − ω)/ω
    /// LBM steps on average: at ω = ½ and Su's 30 µm/s with Table 3's step, 20 nm of membrane
    /// travel, 0.05 % of a 40 µm cell.
    pub fn set_relaxation(&mut self, omega: f64) -> Result<(), CouplingError> {
        if !(omega > 0.0 && omega <= 1.0) {
            return Err(CouplingError::Unsupported(format!(
                "membrane relaxation {omega}: the weight of the new velocity must be in (0, 1]"
            )));
        }
        self.relaxation = omega;
        Ok(())
    }

    /// What the membrane grains showed the liquid at the last step (`Moving`; ring order).
    pub fn shown(&self) -> &[Vec2] {
        &self.shown
    }

    /// Continue from a checkpoint's [`Confinement::shown`].
    pub fn set_shown(&mut self, shown: Vec<Vec2>) {
        self.shown = shown;
    }

    pub fn boundary(&self) -> MembraneBoundary {
        self.boundary
    }

    /// Where the membrane grains were at the last [`Confinement::zone`] (`Moving`; ring order).
    pub fn previous(&self) -> &[Vec2] {
        &self.previous
    }

    /// Continue from a checkpoint's [`Confinement::previous`] (empty: the grains' own velocities
    /// for the next step).
    pub fn set_previous(&mut self, previous: Vec<Vec2>) {
        self.previous = previous;
    }

    /// The zone and its velocities as the last [`Confinement::zone`] drew them.
    pub fn current_zone(&self) -> (&[u32], &[[f64; 3]]) {
        (&self.zone, &self.velocities)
    }

    /// The solid zone of an `nx` × `ny` lattice for the present grains and walls, and the
    /// boundary velocities it refers to (lattice units): 0 at rest (outside the membrane),
    /// 1 + k behind plate k, and after those (`Moving`) one per zone node along the membrane.
    pub fn zone(
        &mut self,
        sys: &System,
        units: &CouplingUnits,
        nx: usize,
        ny: usize,
    ) -> (&[u32], &[[f64; 3]]) {
        let to_lattice = |p: Vec2| {
            let q = units.position_to_lattice([p.x, p.y]);
            Vec2::new(q[0], q[1])
        };
        self.zone.clear();
        self.zone.resize(nx * ny, 0);
        self.velocities.clear();
        self.velocities.push([0.0; 3]);
        let mem = sys.membrane.as_ref().expect("checked in new");
        let ring: Vec<Vec2> = mem
            .polygon(&self.order, &sys.bodies)
            .into_iter()
            .map(to_lattice)
            .collect();
        fill(&ring, nx, ny, |i| self.zone[i] = LIQUID);
        let old_edges = std::mem::take(&mut self.edge_nodes);
        let candidates = if self.boundary == MembraneBoundary::Moving {
            self.edges(&ring, nx, ny)
        } else {
            Vec::new()
        };
        // One velocity per plate, then the edges' (from `first_edge_index` on).
        for (k, &w) in self.plates.iter().enumerate() {
            let wall = &sys.walls[w];
            let v = units.velocity_to_lattice([wall.vel.x, wall.vel.y]);
            self.velocities.push([v[0], v[1], 0.0]);
            let Some(q) = plate_region(wall) else { continue };
            let quad: Vec<Vec2> = q.into_iter().map(to_lattice).collect();
            let z = 1 + k as u32;
            fill(&quad, nx, ny, |i| self.zone[i] = z);
        }
        if self.boundary == MembraneBoundary::Moving {
            // A plate drawn over an edge node takes it.
            let m = self.order.len();
            let edges: Vec<(usize, u32, f64)> = candidates
                .into_iter()
                .filter(|&(idx, _, _)| self.zone[idx] == 0)
                .collect();
            let first_edge_index = 1 + self.plates.len() as u32;
            let slots = self.slots.assign(
                nx * ny,
                old_edges.iter().map(|e| e.node),
                edges.iter().map(|e| e.0),
            );
            for (&(node, e, t), slot) in edges.iter().zip(slots) {
                let index = first_edge_index + slot;
                self.zone[node] = index;
                self.edge_nodes.push(EdgeNode {
                    node,
                    index,
                    a: mem.bodies[self.order[e as usize]],
                    b: mem.bodies[self.order[(e as usize + 1) % m]],
                    ra: e,
                    rb: ((e as usize + 1) % m) as u32,
                    t,
                });
            }
            self.velocities
                .resize(first_edge_index as usize + self.slots.len(), [0.0; 3]);
        }
        if self.boundary == MembraneBoundary::Moving {
            let b = &sys.bodies;
            let now: Vec<Vec2> = self
                .order
                .iter()
                .map(|&k| b.pos[mem.bodies[k] as usize])
                .collect();
            let dt = units.dt();
            let mean: Vec<Vec2> = if self.previous.len() == now.len() {
                now.iter()
                    .zip(&self.previous)
                    .map(|(p, q)| (*p - *q) * (1.0 / dt))
                    .collect()
            } else {
                self.order
                    .iter()
                    .map(|&k| b.vel[mem.bodies[k] as usize])
                    .collect()
            };
            self.previous = now;
            let w = self.relaxation;
            if self.shown.len() == mean.len() && w < 1.0 {
                for (u, m) in self.shown.iter_mut().zip(&mean) {
                    *u = *m * w + *u * (1.0 - w);
                }
            } else {
                self.shown = mean;
            }
            let shown = &self.shown;
            for e in &self.edge_nodes {
                let (va, vb) = (shown[e.ra as usize], shown[e.rb as usize]);
                let v = va * (1.0 - e.t) + vb * e.t;
                let v = units.velocity_to_lattice([v.x, v.y]);
                self.velocities[e.index as usize] = [v[0], v[1], 0.0];
            }
        }
        (&self.zone, &self.velocities)
    }

    /// The zone nodes within [`EDGE_REACH`] of the polygon `ring` (lattice coordinates), each
    /// with its nearest edge and its place on it, in the order they were first reached.
    fn edges(&mut self, ring: &[Vec2], nx: usize, ny: usize) -> Vec<(usize, u32, f64)> {
        let n = nx * ny;
        if self.nearest.len() != n {
            self.nearest = vec![(f64::INFINITY, 0, 0.0); n];
        }
        let mut touched: Vec<usize> = Vec::new();
        let m = ring.len();
        for e in 0..m {
            let (a, b) = (ring[e], ring[(e + 1) % m]);
            let ab = b - a;
            let len2 = ab.dot(ab).max(1e-300);
            let lo = |p: f64, q: f64| ((p.min(q) - EDGE_REACH - 0.5).floor().max(0.0)) as usize;
            let hi = |p: f64, q: f64, n: usize| ((p.max(q) + EDGE_REACH).ceil().max(0.0) as usize).min(n);
            for j in lo(a.y, b.y)..hi(a.y, b.y, ny) {
                for i in lo(a.x, b.x)..hi(a.x, b.x, nx) {
                    let idx = j * nx + i;
                    if self.zone[idx] == LIQUID {
                        continue;
                    }
                    let p = Vec2::new(i as f64 + 0.5, j as f64 + 0.5);
                    let t = ((p - a).dot(ab) / len2).clamp(0.0, 1.0);
                    let d = p - (a + ab * t);
                    let d2 = d.dot(d);
                    let slot = &mut self.nearest[idx];
                    if d2 < EDGE_REACH * EDGE_REACH && d2 < slot.0 {
                        if slot.0 == f64::INFINITY {
                            touched.push(idx);
                        }
                        *slot = (d2, e as u32, t);
                    }
                }
            }
        }
        touched
            .into_iter()
            .map(|idx| {
                let (_, e, t) = self.nearest[idx];
                self.nearest[idx].0 = f64::INFINITY;
                (idx, e, t)
            })
            .collect()
    }

    /// With the zone of this step laid on `fluid` (`Moving` only; nothing at rest): take out
    /// the mass the membrane's bounce-back will put into the liquid ([`PsmFluid::set_pull_scale`])
    /// and add to `loads` (lattice units, per body) the momentum it will take from the liquid,
    /// less that of the liquid's mean pressure, shared between each edge's two grains in
    /// proportion to the node's place on it.
    pub fn membrane_reaction<T: Real>(&self, fluid: &mut PsmFluid<T>, loads: &mut [Load]) {
        if self.boundary != MembraneBoundary::Moving {
            return;
        }
        // Each node's exchange reads the fluid only; collected in edge order, so the sums below
        // are the same on any number of threads.
        let ex: Vec<_> = {
            let f = &*fluid;
            self.edge_nodes
                .par_iter()
                .with_min_len(64)
                .map(|e| f.zone_exchange(e.node))
                .collect()
        };
        let injected: f64 = ex.iter().map(|e| e.mass).sum();
        let (mass, nodes) = fluid.liquid_mass_nodes();
        if nodes == 0 || mass <= 0.0 {
            return;
        }
        let scale = 1.0 - injected / mass;
        fluid.set_pull_scale(scale, mass);
        let rho_ref = mass / nodes as f64;
        for (e, x) in self.edge_nodes.iter().zip(&ex) {
            let p = x.momentum(scale, rho_ref);
            for (body, share) in [(e.a, 1.0 - e.t), (e.b, e.t)] {
                let l = &mut loads[body as usize];
                l.force[0] += share * p[0];
                l.force[1] += share * p[1];
            }
        }
    }
}

/// Velocity slots of the moving boundary's edge nodes. A node keeps its slot for as long as it
/// stays on the edge, so its zone value does not change from one LBM step to the next and
/// [`PsmFluid::set_zone`] relinks only the nodes that joined or left the edge. When every edge
/// node took a fresh index each step (its rank in the edge search), one changed node renumbered
/// all after it and the whole outline and its neighbours were relinked every step: the solid
/// zone then cost 1.6 ms per LBM step on Simulation I against about 0.5 ms at rest (docs/su2020.md).
/// The slot numbers carry no physics: which slot a node holds changes only which entry of the
/// velocity table it reads, so a run that restarts with fresh slots gives the same bits.
#[derive(Clone, Debug, Default)]
struct EdgeSlots {
    /// Slot of each node, or [`EdgeSlots::NONE`].
    of: Vec<u32>,
    /// Slots freed by nodes that left the edge, reused last-freed first.
    free: Vec<u32>,
    /// Slots handed out so far (the velocity table's length after the plates).
    count: u32,
    /// Scratch: which nodes are on the edge in this step.
    now: Vec<bool>,
}

impl EdgeSlots {
    const NONE: u32 = u32::MAX;

    fn len(&self) -> usize {
        self.count as usize
    }

    /// Free the slots of the nodes in `before` that are not in `after`, then return the slot of
    /// each node of `after` (its old one, else a freed or a new one), in `after`'s order.
    fn assign(
        &mut self,
        n: usize,
        before: impl Iterator<Item = usize>,
        after: impl Iterator<Item = usize> + Clone,
    ) -> Vec<u32> {
        if self.of.len() != n {
            *self = Self {
                of: vec![Self::NONE; n],
                now: vec![false; n],
                ..Self::default()
            };
        }
        for idx in after.clone() {
            self.now[idx] = true;
        }
        for idx in before {
            if !self.now[idx] && self.of[idx] != Self::NONE {
                self.free.push(self.of[idx]);
                self.of[idx] = Self::NONE;
            }
        }
        after
            .map(|idx| {
                self.now[idx] = false;
                if self.of[idx] == Self::NONE {
                    self.of[idx] = self.free.pop().unwrap_or_else(|| {
                        self.count += 1;
                        self.count - 1
                    });
                }
                self.of[idx]
            })
            .collect()
    }
}

/// Call `f(node)` for every node whose centre (i + ½, j + ½) lies inside `poly` (lattice
/// coordinates).
fn fill(poly: &[Vec2], nx: usize, ny: usize, mut f: impl FnMut(usize)) {
    scan_rows(poly, (0..ny).map(|j| j as f64 + 0.5), |j, x0, x1| {
        // centres i + ½ in [x0, x1)
        let i0 = (x0 - 0.5).ceil().max(0.0);
        let i1 = (x1 - 0.5).ceil().min(nx as f64);
        let mut i = i0;
        while i < i1 {
            f(j * nx + i as usize);
            i += 1.0;
        }
    });
}

#[cfg(test)]
mod tests {
    use super::EdgeSlots;

    /// A node that stays on the edge keeps its slot, so its zone value does not change and the
    /// lattice does not relink it; a node that leaves gives its slot to the next newcomer.
    #[test]
    fn an_edge_node_keeps_its_slot_while_it_stays_on_the_edge() {
        let mut s = EdgeSlots::default();
        let first = s.assign(10, [].into_iter(), [3, 4, 5].into_iter());
        assert_eq!(first, vec![0, 1, 2]);
        // 4 leaves, 7 joins before the others in the search order: 3 and 5 keep theirs.
        let second = s.assign(10, [3, 4, 5].into_iter(), [7, 5, 3].into_iter());
        assert_eq!(second, vec![1, 2, 0]);
        assert_eq!(s.len(), 3);
        // Two join where none left: the table grows.
        let third = s.assign(10, [7, 5, 3].into_iter(), [7, 5, 3, 8, 9].into_iter());
        assert_eq!(third, vec![1, 2, 0, 3, 4]);
        assert_eq!(s.len(), 5);
    }
}
