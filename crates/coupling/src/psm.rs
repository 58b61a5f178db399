//! The partially-saturated-cells (PSM) lattice: D2Q9 populations coupled to moving grains by
//! the Noble-Torczynski collision (Su et al. 2020 Eqs. 9-11) and the hydrodynamic force and
//! moment on each grain (Eq. 14).
//!
//! Storage is array-of-structures (`f[node * 9 + i]`) so that rows of nodes are contiguous and
//! can be handed to rayon tasks as plain slices; coupled grids are small (Su et al.: about
//! 250 x 190 nodes) and the step is dominated by the DEM sub-cycles, so clarity wins here over
//! the structure-of-arrays kernels of `lbdem-lbm`. Populations are stored in `T` (f64 or f32)
//! and every update is computed in f64.
//!
//! Determinism: rows are split into fixed chunks; each chunk writes its own slice of the
//! population array and of the per-cover force buffer, and the per-grain sums run serially in
//! cover order, so the result is bitwise the same for any number of threads.

use crate::error::CouplingError;
use crate::solid_fraction::SolidMap;
use crate::weighting::psm_weight;
use lbdem_lbm::plan::{Upstream, neighbour};
use lbdem_lbm::{D2Q9, Domain, Face, Lattice, Limits, Real};
use rayon::prelude::*;

const Q: usize = 9;
/// Rows per rayon task: fixed, so the split is the same for every pool size.
const ROWS_PER_TASK: usize = 4;
/// Marker bit of a pull source that is a bounce-back link (low bits: wall index).
const WALL: u32 = 1 << 31;

/// Rigid motion of one grain in lattice units: centre (node i has its centre at i + ½),
/// velocity and angular velocity (counter-clockwise positive).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GrainMotion {
    pub centre: [f64; 2],
    pub velocity: [f64; 2],
    pub omega: f64,
}

impl GrainMotion {
    /// Velocity of the grain's material at offset `r` from its centre: v + ω × r.
    #[inline]
    pub fn velocity_at(&self, r: [f64; 2]) -> [f64; 2] {
        [
            self.velocity[0] - self.omega * r[1],
            self.velocity[1] + self.omega * r[0],
        ]
    }
}

/// Hydrodynamic force (x, y) and moment (z) on one grain, lattice units.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Load {
    pub force: [f64; 2],
    pub torque: f64,
}

/// Collision settings of a PSM lattice.
#[derive(Clone, Copy, Debug)]
pub struct PsmSettings {
    /// BGK relaxation time (Su Eq. 15: ν = c_s²(τ − ½)).
    pub tau: f64,
    /// Uniform body-force density on the liquid (Guo forcing, applied to the share 1 − B of
    /// each node), lattice units.
    pub force: [f64; 2],
    pub limits: Limits,
}

/// Populations and the streaming table of a 2D PSM lattice.
pub struct PsmFluid<T: Real> {
    pub nx: usize,
    pub ny: usize,
    /// Post-collision populations of the current time, `f[node * 9 + i]`.
    pub f: Vec<T>,
    other: Vec<T>,
    /// Pull source of population i at node x: index of the upstream node, or `WALL | w`.
    src: Vec<u32>,
    /// Wall velocities (index 0: stationary inactive nodes; 1 + face for box walls).
    wall_u: Vec<[f64; 2]>,
    /// Inactive nodes (outside the sample: the "solid zone" of Su Sect. 2.4) are never updated.
    active: Vec<bool>,
    settings: PsmSettings,
    /// TRT magic parameter Λ = (τ⁺ − ½)(τ⁻ − ½) of the liquid collision, or `None` for BGK.
    trt_magic: Option<f64>,
    /// Density and velocity of every node after the last step.
    pub rho: Vec<f64>,
    pub u: Vec<[f64; 2]>,
    /// Per cover of the last solid map: the load its grain received there.
    cover_load: Vec<Load>,
    pub step: u64,
}

/// Equilibrium of D2Q9 (Su Eq. 7).
#[inline(always)]
fn feq(i: usize, rho: f64, u: [f64; 2], usq: f64) -> f64 {
    let c = D2Q9::C[i];
    let cu = c[0] as f64 * u[0] + c[1] as f64 * u[1];
    D2Q9::W[i] * rho * (1.0 + 3.0 * cu + 4.5 * cu * cu - 1.5 * usq)
}

impl<T: Real> PsmFluid<T> {
    /// A fluid at rest with density 1 on the 2D `domain` (faces periodic or walls; nodes of
    /// kind other than fluid are inactive and act as stationary bounce-back walls).
    pub fn new(domain: &Domain, settings: PsmSettings) -> Result<Self, CouplingError> {
        let [nx, ny, nz] = domain.n;
        if nz != 1 {
            return Err(CouplingError::Unsupported(format!(
                "the PSM coupling is 2D (D2Q9); the domain has nz = {nz}, set it to 1"
            )));
        }
        if !(settings.tau > 0.5 && settings.tau.is_finite()) {
            return Err(CouplingError::Tau { tau: settings.tau });
        }
        let mut wall_u = vec![[0.0; 2]];
        for face in &domain.faces {
            match face {
                Face::Periodic => wall_u.push([0.0; 2]),
                Face::Wall { velocity } => wall_u.push([velocity[0], velocity[1]]),
                other => {
                    return Err(CouplingError::Unsupported(format!(
                        "face {other:?}: the PSM lattice takes periodic faces or walls only"
                    )));
                }
            }
        }
        let n = nx * ny;
        let active: Vec<bool> = domain
            .kind
            .iter()
            .map(|&k| k == lbdem_lbm::domain::FLUID)
            .collect();
        let mut src = vec![0u32; n * Q];
        for y in 0..ny {
            for x in 0..nx {
                let idx = x + nx * y;
                for i in 0..Q {
                    let c = D2Q9::C[i];
                    src[idx * Q + i] = match neighbour(domain, [x, y, 0], [-c[0], -c[1], 0]) {
                        Upstream::Node(j) if active[j] => j as u32,
                        Upstream::Node(_) => WALL,
                        Upstream::Face(f) => WALL | (1 + f as u32),
                    };
                }
            }
        }
        let mut f = vec![T::default(); n * Q];
        for node in f.chunks_exact_mut(Q) {
            for i in 0..Q {
                node[i] = T::from_f64(D2Q9::W[i]);
            }
        }
        Ok(Self {
            nx,
            ny,
            other: f.clone(),
            f,
            src,
            wall_u,
            active,
            settings,
            trt_magic: None,
            rho: vec![1.0; n],
            u: vec![[0.0; 2]; n],
            cover_load: Vec::new(),
            step: 0,
        })
    }

    /// Relax the liquid share of each node with two relaxation times instead of one (Ginzburg's
    /// TRT): τ⁺ = τ sets the viscosity, τ⁻ follows from Λ = (τ⁺ − ½)(τ⁻ − ½). BGK is the case
    /// Λ = (τ − ½)²: near τ = ½ (settling pairs at Reynolds numbers of hundreds) that is about
    /// 1e-4, the odd rate is close to 2 and the odd non-equilibrium flips sign every step and
    /// barely decays; Λ = 1/4 damps it. The solid term (Eq. 11) and the weight B (Eq. 10, from
    /// τ⁺) are unchanged.
    pub fn with_trt(mut self, magic: f64) -> Result<Self, CouplingError> {
        if !(magic > 0.0 && magic.is_finite()) {
            return Err(CouplingError::Unsupported(format!(
                "TRT magic parameter {magic} must be positive and finite (1/4 is the usual choice)"
            )));
        }
        self.trt_magic = Some(magic);
        Ok(self)
    }

    /// Set every node to the equilibrium of density `rho` and velocity `u(x, y)`.
    pub fn init_equilibrium(&mut self, init: impl Fn(usize, usize) -> (f64, [f64; 2])) {
        for idx in 0..self.nx * self.ny {
            let (rho, u) = init(idx % self.nx, idx / self.nx);
            let usq = u[0] * u[0] + u[1] * u[1];
            for i in 0..Q {
                self.f[idx * Q + i] = T::from_f64(feq(i, rho, u, usq));
            }
            self.rho[idx] = rho;
            self.u[idx] = u;
        }
    }

    /// Total mass and momentum of the populations (lattice units).
    pub fn mass_momentum(&self) -> (f64, [f64; 2]) {
        let (mut m, mut j) = (0.0, [0.0; 2]);
        for (node, a) in self.f.chunks_exact(Q).zip(&self.active) {
            if !a {
                continue;
            }
            for i in 0..Q {
                let v = node[i].to_f64();
                m += v;
                j[0] += v * D2Q9::C[i][0] as f64;
                j[1] += v * D2Q9::C[i][1] as f64;
            }
        }
        (m, j)
    }

    /// One LBM step: pull-stream, then collide with the PSM term of every grain covering each
    /// node (Su Eq. 9, per-grain weights B_s = B ε_s / ε so that Σ_s B_s = B of Eq. 10), and
    /// return the load on each of `grains.len()` grains (Eq. 14, summed over the grain's
    /// circles because the map holds one cover per grain and cell).
    ///
    /// The force on a grain is the reaction to the momentum its solid term puts into the
    /// fluid: F_s = −Σ_x B_s Σ_i Ω_i^s c_i (Su writes Eq. 14 as the momentum transfer; the
    /// sign here makes fluid plus grains conserve momentum, which a test checks).
    pub fn step(
        &mut self,
        map: &SolidMap,
        grains: &[GrainMotion],
        loads: &mut Vec<Load>,
    ) -> Result<(), CouplingError> {
        let (nx, ny) = (self.nx, self.ny);
        assert_eq!((map.nx, map.ny), (nx, ny), "solid map and lattice differ in size");
        let n = nx * ny;
        // Covers of cell c are covers[start[c]..start[c + 1]] (the map is sorted by cell).
        let mut start = vec![0u32; n + 1];
        for cv in &map.covers {
            start[cv.cell as usize + 1] += 1;
        }
        for c in 0..n {
            start[c + 1] += start[c];
        }
        self.cover_load.clear();
        self.cover_load.resize(map.covers.len(), Load::default());

        let tau = self.settings.tau;
        let omega = 1.0 / tau;
        // Odd-moment rate: equal to ω for BGK, from Λ for TRT.
        let omega_odd = match self.trt_magic {
            None => omega,
            Some(l) => 1.0 / (0.5 + l / (tau - 0.5)),
        };
        let trt = self.trt_magic.is_some();
        let force = self.settings.force;
        let limits = self.settings.limits;
        let step = self.step;
        let f_in = &self.f;
        let src = &self.src;
        let wall_u = &self.wall_u;
        let active = &self.active;

        // Split every per-node and per-cover output into the same fixed row chunks.
        let rows_chunk = ROWS_PER_TASK * nx;
        let mut tasks = Vec::with_capacity(ny.div_ceil(ROWS_PER_TASK));
        {
            let mut f_out: &mut [T] = &mut self.other;
            let mut rho: &mut [f64] = &mut self.rho;
            let mut u: &mut [[f64; 2]] = &mut self.u;
            let mut loads_rest: &mut [Load] = &mut self.cover_load;
            let mut node0 = 0;
            while node0 < n {
                let len = rows_chunk.min(n - node0);
                let (fa, fb) = std::mem::take(&mut f_out).split_at_mut(len * Q);
                let (ra, rb) = std::mem::take(&mut rho).split_at_mut(len);
                let (ua, ub) = std::mem::take(&mut u).split_at_mut(len);
                let nc = (start[node0 + len] - start[node0]) as usize;
                let (la, lb) = std::mem::take(&mut loads_rest).split_at_mut(nc);
                tasks.push((node0, fa, ra, ua, la));
                f_out = fb;
                rho = rb;
                u = ub;
                loads_rest = lb;
                node0 += len;
            }
        }
        let bad = tasks
            .into_par_iter()
            .map(|(node0, f_out, rho_out, u_out, load_out)| {
                let c0 = start[node0] as usize;
                let mut first_bad = None;
                for k in 0..rho_out.len() {
                    let idx = node0 + k;
                    let out = &mut f_out[k * Q..(k + 1) * Q];
                    if !active[idx] {
                        continue;
                    }
                    // Pull-stream (Su Eq. 12), bounce-back from walls and inactive nodes.
                    let mut f = [0.0; Q];
                    for i in 0..Q {
                        let s = src[idx * Q + i];
                        f[i] = if s & WALL == 0 {
                            f_in[s as usize * Q + i].to_f64()
                        } else {
                            let uw = wall_u[(s & !WALL) as usize];
                            let c = D2Q9::C[i];
                            let o = D2Q9::OPP[i];
                            f_in[idx * Q + o].to_f64()
                                + 6.0 * D2Q9::W[i] * (c[0] as f64 * uw[0] + c[1] as f64 * uw[1])
                        };
                    }
                    // Moments (Su Eq. 13) with the Guo half-force shift.
                    let mut rho = 0.0;
                    let mut j = [0.0; 2];
                    for i in 0..Q {
                        rho += f[i];
                        j[0] += f[i] * D2Q9::C[i][0] as f64;
                        j[1] += f[i] * D2Q9::C[i][1] as f64;
                    }
                    let u = [(j[0] + 0.5 * force[0]) / rho, (j[1] + 0.5 * force[1]) / rho];
                    let usq = u[0] * u[0] + u[1] * u[1];
                    let mut fe = [0.0; Q];
                    for i in 0..Q {
                        fe[i] = feq(i, rho, u, usq);
                    }
                    // Fluid part of Eq. 9 plus the Guo source (Leonardi Eq. 16) on the liquid share 1 − B:
                    // with u shifted by F/2 this puts exactly (1 − B) F of momentum into the node.
                    let cover = &map.covers[start[idx] as usize..start[idx + 1] as usize];
                    let eps = map.total[idx];
                    let b = if cover.is_empty() {
                        0.0
                    } else {
                        psm_weight(eps, tau)
                    };
                    let mut post = [0.0; Q];
                    let mut src_term = [0.0; Q];
                    for i in 0..Q {
                        let c = D2Q9::C[i];
                        let cu = c[0] as f64 * u[0] + c[1] as f64 * u[1];
                        let s = D2Q9::W[i]
                            * ((3.0 * (c[0] as f64 - u[0]) + 9.0 * cu * c[0] as f64) * force[0]
                                + (3.0 * (c[1] as f64 - u[1]) + 9.0 * cu * c[1] as f64) * force[1]);
                        post[i] = if trt {
                            0.0 // filled below from the even and odd parts
                        } else {
                            f[i] - (1.0 - b) * omega * (f[i] - fe[i]) + (1.0 - b) * (1.0 - 0.5 * omega) * s
                        };
                        src_term[i] = s;
                    }
                    if trt {
                        for i in 0..Q {
                            let o = D2Q9::OPP[i];
                            let (ne_even, ne_odd) = (
                                0.5 * ((f[i] - fe[i]) + (f[o] - fe[o])),
                                0.5 * ((f[i] - fe[i]) - (f[o] - fe[o])),
                            );
                            let (s_even, s_odd) = (
                                0.5 * (src_term[i] + src_term[o]),
                                0.5 * (src_term[i] - src_term[o]),
                            );
                            post[i] = f[i] - (1.0 - b) * (omega * ne_even + omega_odd * ne_odd)
                                + (1.0 - b)
                                    * ((1.0 - 0.5 * omega) * s_even + (1.0 - 0.5 * omega_odd) * s_odd);
                        }
                    }
                    // Solid part: Ω of Eq. 11 for each covering grain, weighted by B_s.
                    let x = [(idx % nx) as f64 + 0.5, (idx / nx) as f64 + 0.5];
                    for (m, cv) in cover.iter().enumerate() {
                        let bs = b * cv.fraction / eps;
                        let g = &grains[cv.body as usize];
                        let r = min_image(x, g.centre, nx, ny);
                        let us = g.velocity_at(r);
                        let ussq = us[0] * us[0] + us[1] * us[1];
                        let mut p = [0.0; 2];
                        for i in 0..Q {
                            let o = D2Q9::OPP[i];
                            let om = f[o] - f[i] + feq(i, rho, us, ussq) - fe[o];
                            post[i] += bs * om;
                            p[0] += bs * om * D2Q9::C[i][0] as f64;
                            p[1] += bs * om * D2Q9::C[i][1] as f64;
                        }
                        let fs = [-p[0], -p[1]];
                        load_out[start[idx] as usize - c0 + m] = Load {
                            force: fs,
                            torque: r[0] * fs[1] - r[1] * fs[0],
                        };
                    }
                    for i in 0..Q {
                        out[i] = T::from_f64(post[i]);
                    }
                    let speed = usq.sqrt();
                    let ok = rho.is_finite()
                        && speed.is_finite()
                        && rho > limits.rho_min
                        && rho < limits.rho_max
                        && speed < limits.u_max;
                    if !ok && first_bad.is_none() {
                        first_bad = Some((idx, rho, u));
                    }
                    rho_out[k] = rho;
                    u_out[k] = u;
                }
                first_bad
            })
            .collect::<Vec<_>>()
            .into_iter()
            .flatten()
            .next();
        if let Some((idx, rho, u)) = bad {
            return Err(CouplingError::Unstable {
                step: step + 1,
                node: [idx % nx, idx / nx],
                rho,
                u,
                cause: diagnose(rho, u, tau, &limits),
            });
        }
        std::mem::swap(&mut self.f, &mut self.other);
        self.step += 1;

        loads.clear();
        loads.resize(grains.len(), Load::default());
        for (cv, l) in map.covers.iter().zip(&self.cover_load) {
            let t = &mut loads[cv.body as usize];
            t.force[0] += l.force[0];
            t.force[1] += l.force[1];
            t.torque += l.torque;
        }
        Ok(())
    }

    /// BGK relaxation time (TRT: the even one, τ⁺), which sets the viscosity and B of Eq. 10.
    pub fn tau(&self) -> f64 {
        self.settings.tau
    }

    /// Whether node `idx` is updated (not in the inactive zone).
    pub fn is_active(&self, idx: usize) -> bool {
        self.active[idx]
    }
}

/// Offset x − c with the minimum-image convention on a periodic nx × ny lattice (harmless on
/// walled boxes: grains never sit half a box away from the nodes they cover).
#[inline]
pub(crate) fn min_image(x: [f64; 2], c: [f64; 2], nx: usize, ny: usize) -> [f64; 2] {
    let mut d = [x[0] - c[0], x[1] - c[1]];
    for (a, l) in [(0, nx as f64), (1, ny as f64)] {
        if d[a] > 0.5 * l {
            d[a] -= l;
        } else if d[a] < -0.5 * l {
            d[a] += l;
        }
    }
    d
}

fn diagnose(rho: f64, u: [f64; 2], tau: f64, limits: &Limits) -> String {
    let speed = (u[0] * u[0] + u[1] * u[1]).sqrt();
    if !rho.is_finite() || !speed.is_finite() {
        format!("non-finite state; tau = {tau} is too close to 0.5 or the grains move too fast for dt")
    } else if speed >= limits.u_max {
        format!(
            "velocity {speed:.3} (lattice) above {}: Mach too high; reduce the LBM time step",
            limits.u_max
        )
    } else {
        "density out of range: pressure waves too strong; reduce the LBM time step or the grain speed".into()
    }
}
