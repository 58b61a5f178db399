//! The partially-saturated-cells (PSM) lattice: populations coupled to moving grains by
//! the Noble-Torczynski collision (Su et al. 2020 Eqs. 9-11) and the hydrodynamic force and
//! moment on each grain (Eq. 14). Written over the lattice (`PsmFluid<T, L>`, D2Q9 by default,
//! D3Q19 too): the 2D API (`step` with `GrainMotion` and `Load`, `init_equilibrium`,
//! `mass_momentum`) is D2Q9's; any lattice steps with `step_motions` (`lbdem_lbm::Motion`,
//! `ForceTorque`). The solid-fraction map of `solid_fraction` (circle ∩ square cells) stays 2D:
//! a 3D run brings its own `SolidMap` (cell index = node index x + nx (y + ny z)).
//!
//! Storage is direction-major (`f[i * nodes + node]`, the structure of arrays of `lbdem-lbm`):
//! the lanes of a block of consecutive nodes load and store each population as one vector
//! (node-major storage made every block a gather and a scatter of stride Q; the lattice step
//! alone takes 0.6 of the time since, docs/performance.md). Checkpoints keep the
//! node-major order ([`PsmState::f`]). Populations are stored in `T` (f64 or f32) and every
//! update is computed in f64. The liquid part of the collision is the operator of
//! `lbdem-lbm` (`lbdem_lbm::Collider`: BGK or TRT, uniform or with per-node τ), so the choice of
//! collision is made in one place for every lattice.
//!
//! Determinism: rows are split into fixed chunks; each chunk writes only its own nodes of the
//! population array and its own slice of the per-cover force buffer, and the per-grain sums run
//! serially in cover order, so the result is bitwise the same for any number of threads.

use crate::error::CouplingError;
use crate::solid_fraction::{CellCover, SolidMap};
use crate::weighting::psm_weight;
use lbdem_core::simd::{self, Simd, WithSimd};
use lbdem_lbm::collision::{CollideParams, Collider, LocalRates, NodeRates, local_rates};
use lbdem_lbm::kernel::{LimitsT, SyncPtr};
use lbdem_lbm::lattice::QMAX;
use lbdem_lbm::plan::{Upstream, neighbour};
use lbdem_lbm::{
    BadNode, Collision, D2Q9, Domain, Face, ForceTorque, Lattice, LbmError, Limits, Motion, Real,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::marker::PhantomData;

/// Rows per rayon task: fixed, so the split is the same for every pool size.
const ROWS_PER_TASK: usize = 4;
/// Marker bit of a pull source that is a bounce-back link (low bits: wall index).
const WALL: u32 = 1 << 31;

/// Rigid motion of one grain in lattice units: centre (node i has its centre at i + ½),
/// velocity and angular velocity (counter-clockwise positive).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
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
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Load {
    pub force: [f64; 2],
    pub torque: f64,
}

/// Collision settings of a PSM lattice.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PsmSettings {
    /// The liquid collision (the operator of `lbdem-lbm`): BGK with τ (Su Eq. 15:
    /// ν = c_s²(τ − ½)), or TRT with τ⁺ = τ and the magic Λ. τ also sets B of Eq. 10.
    pub collision: Collision,
    /// Uniform body-force density on the liquid (Guo forcing, applied to the share 1 − B of
    /// each node), lattice units.
    pub force: [f64; 2],
    pub limits: Limits,
}

/// Populations and the streaming table of a PSM lattice (D2Q9 unless `L` says otherwise).
pub struct PsmFluid<T: Real, L: Lattice = D2Q9> {
    pub nx: usize,
    pub ny: usize,
    /// 1 in 2D.
    pub nz: usize,
    /// Post-collision populations of the current time, `f[i * nodes + node]`.
    f: Vec<T>,
    other: Vec<T>,
    /// Pull source of population i at node x: index of the upstream node, or `WALL | w`.
    src: Vec<u32>,
    /// Per node: every population streams from its upstream node (`src` is x − c_i for each i),
    /// so the step can pull by fixed offsets without reading `src`.
    regular: Vec<bool>,
    /// Wall velocities (index 0: stationary inactive nodes; 1 + face for box walls).
    wall_u: Vec<[f64; 3]>,
    /// Inactive nodes (the domain's solid nodes, and the "solid zone" of Su Fig. 2 step 15 set
    /// by [`PsmFluid::set_zone`]) are never updated; their links bounce back.
    active: Vec<bool>,
    /// The domain's own node kinds and faces (the zone is laid over them).
    domain: Domain,
    base_active: Vec<bool>,
    /// Per node: [`LIQUID`] or the index of the boundary velocity its solid zone shows.
    zone: Vec<u32>,
    /// First `wall_u` index of the zone's velocities (after the stationary entry and the faces).
    zone_base: usize,
    /// Liquid mass (lattice units) dropped by nodes the zone closed and added by nodes it opened,
    /// since the start.
    zone_mass: ZoneMass,
    /// Factor on every population the next step pulls ([`PsmFluid::set_pull_scale`]); 1 after it.
    pull_scale: f64,
    settings: PsmSettings,
    /// Uniform collision constants (f64: every update is computed in f64).
    params: CollideParams<f64>,
    /// Per-node rates and the τ they came from (`set_local_tau`).
    local: Option<(Vec<NodeRates<f64>>, Vec<f64>)>,
    /// Density and velocity of every node after the last step (z = 0 in 2D).
    pub rho: Vec<f64>,
    pub u: Vec<[f64; 3]>,
    /// Per cover of the last solid map: the load its grain received there.
    cover_load: Vec<ForceTorque>,
    /// Scratch: covers of cell c are `covers[cover_start[c]..cover_start[c + 1]]` (kept between
    /// steps: a fresh buffer of the lattice's size each step costs page faults).
    cover_start: Vec<u32>,
    /// The 2D `step`'s grains and loads in the lattice-independent form (scratch).
    motions: Vec<Motion>,
    loads3: Vec<ForceTorque>,
    pub step: u64,
    _l: PhantomData<L>,
}

/// What a PSM lattice needs besides its domain and settings to continue a run bit for bit
/// (`PsmFluid::state`, `PsmFluid::restore`): the post-collision populations, the macroscopic
/// fields of the last step (read by the coupling's outputs), the per-node τ if set, the step.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct PsmState<T: Real> {
    /// Node-major, `f[node * Q + i]` (the lattice itself is direction-major).
    pub f: Vec<T>,
    pub rho: Vec<f64>,
    pub u: Vec<[f64; 3]>,
    pub local_tau: Option<Vec<f64>>,
    pub step: u64,
    /// The solid zone and its velocities ([`PsmFluid::set_zone`]); empty if never set.
    #[serde(default)]
    pub zone: Vec<u32>,
    #[serde(default)]
    pub zone_velocities: Vec<[f64; 3]>,
    #[serde(default)]
    pub zone_mass: ZoneMass,
}

/// A node of the liquid in [`PsmFluid::set_zone`].
pub const LIQUID: u32 = u32::MAX;

/// Liquid mass (lattice units) that the moving solid zone took out of the lattice (nodes it
/// closed) and put in (nodes it opened, refilled at the local density), since the start.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ZoneMass {
    pub removed: f64,
    pub added: f64,
    /// Nodes closed and opened.
    pub closed: u64,
    pub opened: u64,
    /// Mass taken out by [`PsmFluid::set_pull_scale`]: what a moving membrane's bounce-back put
    /// in, so that the liquid's mass follows the sample's area as with a zone at rest.
    #[serde(default)]
    pub rescaled: f64,
}

/// What the bounce-back links pulling from one solid-zone node exchange with the liquid in the
/// next step (lattice units), in parts, so that the momentum can be read for any pull scale s
/// and reference density ρ_ref ([`ZoneExchange::momentum`]). A population f_o leaving liquid
/// node x towards the zone comes back as f_i = s f_o + 6 w_i c_i·u_w (moving-wall bounce-back,
/// Leonardi et al. 2014 Eq. 19 with ρ_w = 1) and hands the wall (s f_o + f_i) c_o.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ZoneExchange {
    /// Σ 2 f_o c_o over the links.
    pub pull: [f64; 3],
    /// Σ 6 w_i (c_i·u_w) c_o: the wall's motion.
    pub wall: [f64; 3],
    /// Σ 2 w_i c_o: what a liquid at rest of unit density hands the wall (its pressure).
    pub gauge: [f64; 3],
    /// Σ 6 w_i c_i·u_w: the mass the links put into the liquid.
    pub mass: f64,
}

impl ZoneExchange {
    /// Momentum handed to the wall in the step, less that of the uniform pressure ρ_ref c_s²
    /// (which pushes on a closed outline with no net force and only loads it internally).
    pub fn momentum(&self, scale: f64, rho_ref: f64) -> [f64; 3] {
        std::array::from_fn(|a| scale * self.pull[a] + self.wall[a] - rho_ref * self.gauge[a])
    }
}

/// Equilibrium (Su Eq. 7, Leonardi Eq. 13).
#[inline(always)]
fn feq<L: Lattice>(i: usize, rho: f64, u: [f64; 3], usq: f64) -> f64 {
    let c = L::C[i];
    let mut cu = c[0] as f64 * u[0] + c[1] as f64 * u[1];
    if L::D == 3 {
        cu += c[2] as f64 * u[2];
    }
    L::W[i] * rho * (1.0 + 3.0 * cu + 4.5 * cu * cu - 1.5 * usq)
}

/// |u|² over the lattice's dimensions (the 2D sum is the one of the 2D code).
#[inline(always)]
fn norm2<L: Lattice>(u: [f64; 3]) -> f64 {
    let mut s = u[0] * u[0] + u[1] * u[1];
    if L::D == 3 {
        s += u[2] * u[2];
    }
    s
}

impl<T: Real, L: Lattice> PsmFluid<T, L> {
    /// A fluid at rest with density 1 on `domain` (nz = 1 for D2Q9, nz > 1 for D3Q19; faces
    /// periodic or walls; nodes of kind other than fluid are inactive and act as stationary
    /// bounce-back walls).
    pub fn new(domain: &Domain, settings: PsmSettings) -> Result<Self, CouplingError> {
        let [nx, ny, nz] = domain.n;
        if (L::D == 2) != (nz == 1) {
            return Err(CouplingError::Unsupported(format!(
                "PSM lattice {} on a box of {nx} x {ny} x {nz} nodes: use nz = 1 with D2Q9 and nz > 1 \
                 with D3Q19",
                L::NAME
            )));
        }
        let tau = settings.collision.tau();
        if !(tau > 0.5 && tau.is_finite()) {
            return Err(CouplingError::Tau { tau });
        }
        let params =
            CollideParams::<f64>::new(&settings.collision, [settings.force[0], settings.force[1], 0.0])?;
        let mut wall_u = vec![[0.0; 3]];
        for face in &domain.faces {
            match face {
                Face::Periodic => wall_u.push([0.0; 3]),
                Face::Wall { velocity } => wall_u.push(if L::D == 3 {
                    *velocity
                } else {
                    [velocity[0], velocity[1], 0.0]
                }),
                other => {
                    return Err(CouplingError::Unsupported(format!(
                        "face {other:?}: the PSM lattice takes periodic faces or walls only"
                    )));
                }
            }
        }
        let n = nx * ny * nz;
        let q = L::Q;
        let active: Vec<bool> = domain
            .kind
            .iter()
            .map(|&k| k == lbdem_lbm::domain::FLUID)
            .collect();
        let zone_base = wall_u.len();
        let mut src = vec![0u32; n * q];
        let zone = vec![LIQUID; n];
        for idx in 0..n {
            for i in 0..q {
                src[idx * q + i] = link::<L>(domain, &active, &active, &zone, zone_base, idx, i);
            }
        }
        let f: Vec<T> = (0..n * q).map(|k| T::from_f64(L::W[k / n])).collect();
        Ok(Self {
            nx,
            ny,
            nz,
            other: f.clone(),
            f,
            regular: regular_nodes::<L>(&src, [nx, ny, nz]),
            src,
            wall_u,
            base_active: active.clone(),
            active,
            domain: domain.clone(),
            zone,
            zone_base,
            zone_mass: ZoneMass::default(),
            pull_scale: 1.0,
            settings,
            params,
            local: None,
            rho: vec![1.0; n],
            u: vec![[0.0; 3]; n],
            cover_load: Vec::new(),
            cover_start: Vec::new(),
            motions: Vec::new(),
            loads3: Vec::new(),
            step: 0,
            _l: PhantomData,
        })
    }

    /// Relax the liquid share of each node with two relaxation times instead of one (Ginzburg's
    /// TRT): τ⁺ = τ sets the viscosity, τ⁻ follows from Λ = (τ⁺ − ½)(τ⁻ − ½). BGK is the case
    /// Λ = (τ − ½)²: near τ = ½ (settling pairs at Reynolds numbers of hundreds) that is about
    /// 1e-4, the odd rate is close to 2 and the odd non-equilibrium flips sign every step and
    /// barely decays; Λ = 1/4 damps it. The solid term (Eq. 11) and the weight B (Eq. 10, from
    /// τ⁺) are unchanged. The same as `PsmSettings::collision = Collision::Trt { tau, magic }`.
    pub fn with_trt(mut self, magic: f64) -> Result<Self, CouplingError> {
        let collision = Collision::Trt {
            tau: self.settings.collision.tau(),
            magic,
        };
        let force = [self.settings.force[0], self.settings.force[1], 0.0];
        self.params = CollideParams::new(&collision, force)?;
        self.settings.collision = collision;
        if let Some((_, tau)) = self.local.take() {
            self.set_local_tau(tau)?;
        }
        Ok(self)
    }

    /// Relax node x with τ⁺ = `tau[x]` (node order x + nx y) instead of the settings' τ, with the
    /// settings' kind of collision; B of Eq. 10 then takes the local τ too. The seam of local-τ
    /// rheology (Bingham, Leonardi et al. 2014 Eq. 8). Equal values everywhere give the uniform
    /// run bit for bit.
    pub fn set_local_tau(&mut self, tau: Vec<f64>) -> Result<(), CouplingError> {
        let nodes = self.nodes();
        if tau.len() != nodes {
            return Err(LbmError::LocalTauLength {
                got: tau.len(),
                nodes,
            }
            .into());
        }
        let (rates, bgk) = local_rates::<f64>(&self.settings.collision, &tau)?;
        self.params.bgk = bgk;
        self.local = Some((rates, tau));
        Ok(())
    }

    /// Back to the settings' uniform τ.
    pub fn clear_local_tau(&mut self) {
        self.local = None;
        let (wp, wm) = (self.params.omega_p, self.params.omega_m);
        self.params.bgk = wp == wm;
    }

    /// The state to checkpoint (see [`PsmState`]).
    pub fn state(&self) -> PsmState<T> {
        let (n, q) = (self.nodes(), L::Q);
        PsmState {
            f: (0..n * q).map(|k| self.f[(k % q) * n + k / q]).collect(),
            rho: self.rho.clone(),
            u: self.u.clone(),
            local_tau: self.local.as_ref().map(|(_, t)| t.clone()),
            step: self.step,
            zone: if self.zone_is_set() {
                self.zone.clone()
            } else {
                Vec::new()
            },
            zone_velocities: self.wall_u[self.zone_base..].to_vec(),
            zone_mass: self.zone_mass,
        }
    }

    /// Continue from `state` on a lattice built with the same domain and settings.
    pub fn restore(&mut self, state: PsmState<T>) -> Result<(), CouplingError> {
        let n = self.nodes();
        if state.f.len() != n * L::Q || state.rho.len() != n || state.u.len() != n {
            return Err(CouplingError::Unsupported(format!(
                "PSM state of {} populations and {} nodes for a lattice of {} x {} nodes: restore into \
                 a lattice built with the checkpoint's domain",
                state.f.len(),
                state.rho.len(),
                self.nx,
                self.ny
            )));
        }
        match state.local_tau {
            Some(t) => self.set_local_tau(t)?,
            None => self.clear_local_tau(),
        }
        if !state.zone.is_empty() && state.zone.len() != n {
            return Err(CouplingError::Unsupported(format!(
                "PSM state with a solid zone of {} nodes for a lattice of {n} nodes: the file is \
                 inconsistent; write it again",
                state.zone.len()
            )));
        }
        let q = L::Q;
        self.f = (0..n * q).map(|k| state.f[(k % n) * q + k / n]).collect();
        self.rho = state.rho;
        self.u = state.u;
        self.step = state.step;
        self.zone_mass = state.zone_mass;
        self.wall_u.truncate(self.zone_base);
        self.wall_u.extend(state.zone_velocities);
        self.zone = if state.zone.is_empty() {
            vec![LIQUID; n]
        } else {
            state.zone
        };
        for idx in 0..n {
            self.active[idx] = self.base_active[idx] && self.zone[idx] == LIQUID;
        }
        for idx in 0..n {
            for i in 0..L::Q {
                self.src[idx * L::Q + i] = link::<L>(
                    &self.domain,
                    &self.active,
                    &self.base_active,
                    &self.zone,
                    self.zone_base,
                    idx,
                    i,
                );
            }
        }
        self.regular = regular_nodes::<L>(&self.src, [self.nx, self.ny, self.nz]);
        Ok(())
    }

    fn zone_is_set(&self) -> bool {
        self.zone.iter().any(|&z| z != LIQUID)
    }

    /// Lay a solid zone over the lattice (Su et al. 2020 Fig. 2, step 15): nodes with
    /// `zone[x] == LIQUID` hold liquid, the others are solid and show the liquid the boundary
    /// velocity `velocities[zone[x]]` (lattice units; the moving-wall bounce-back of the box
    /// faces). Called before every LBM step as the sample deforms: only the nodes whose zone
    /// changed are relinked.
    ///
    /// A node that closes loses its liquid (counted in [`ZoneMass::removed`]); a node that opens
    /// is refilled with the equilibrium at the mean density of its liquid neighbours and the
    /// velocity of the boundary that uncovered it (counted in [`ZoneMass::added`]), the
    /// refilling rule of moving bounce-back (Leonardi et al. 2014 Eq. 21).
    pub fn set_zone(&mut self, zone: &[u32], velocities: &[[f64; 3]]) -> Result<(), CouplingError> {
        let n = self.nodes();
        let q = L::Q;
        if zone.len() != n {
            return Err(CouplingError::Unsupported(format!(
                "solid zone of {} nodes for a lattice of {n} nodes",
                zone.len()
            )));
        }
        if let Some(&z) = zone
            .iter()
            .find(|&&z| z != LIQUID && z as usize >= velocities.len())
        {
            return Err(CouplingError::Unsupported(format!(
                "solid zone refers to boundary velocity {z} of {}",
                velocities.len()
            )));
        }
        // A node that opens is refilled with the velocity of the boundary that covered it.
        let covered_by: Vec<[f64; 3]> = self.wall_u.split_off(self.zone_base);
        self.wall_u.extend_from_slice(velocities);
        let mut changed = Vec::new();
        let mut opened = Vec::new();
        for idx in 0..n {
            if zone[idx] == self.zone[idx] || !self.base_active[idx] {
                continue;
            }
            changed.push(idx);
            if self.zone[idx] == LIQUID {
                let m: f64 = (0..q).map(|i| self.f[i * n + idx].to_f64()).sum();
                self.zone_mass.removed += m;
                self.zone_mass.closed += 1;
                self.active[idx] = false;
            } else if zone[idx] == LIQUID {
                opened.push((idx, self.zone[idx]));
            }
        }
        // Refill from the liquid that was there before this call (not from nodes opening now).
        let was_active = self.active.clone();
        for &(idx, from) in &opened {
            let p = self.domain.coords(idx);
            let (mut sum, mut count) = (0.0, 0usize);
            for i in 1..q {
                let c = L::C[i];
                if let Upstream::Node(j) = neighbour(&self.domain, p, [c[0], c[1], c[2]])
                    && was_active[j]
                {
                    sum += self.rho[j];
                    count += 1;
                }
            }
            let rho = if count > 0 { sum / count as f64 } else { 1.0 };
            let u = covered_by[from as usize];
            let usq = norm2::<L>(u);
            for i in 0..q {
                self.f[i * n + idx] = T::from_f64(feq::<L>(i, rho, u, usq));
            }
            self.rho[idx] = rho;
            self.u[idx] = u;
            self.zone_mass.added += rho;
            self.zone_mass.opened += 1;
        }
        for &(idx, _) in &opened {
            self.active[idx] = true;
        }
        for &idx in &changed {
            self.zone[idx] = zone[idx];
        }
        // Relink each changed node and the nodes that pull from it.
        for &idx in &changed {
            let p = self.domain.coords(idx);
            for i in 0..q {
                self.src[idx * q + i] = link::<L>(
                    &self.domain,
                    &self.active,
                    &self.base_active,
                    &self.zone,
                    self.zone_base,
                    idx,
                    i,
                );
                let c = L::C[i];
                if let Upstream::Node(x) = neighbour(&self.domain, p, [c[0], c[1], c[2]]) {
                    self.src[x * q + i] = link::<L>(
                        &self.domain,
                        &self.active,
                        &self.base_active,
                        &self.zone,
                        self.zone_base,
                        x,
                        i,
                    );
                    self.regular[x] = is_regular::<L>(&self.src, [self.nx, self.ny, self.nz], x);
                }
            }
            self.regular[idx] = is_regular::<L>(&self.src, [self.nx, self.ny, self.nz], idx);
        }
        Ok(())
    }

    /// Start counting [`ZoneMass`] afresh (after laying the first zone).
    pub fn reset_zone_mass(&mut self) {
        self.zone_mass = ZoneMass::default();
    }

    /// The liquid mass the solid zone removed and added so far ([`PsmFluid::set_zone`]).
    pub fn zone_mass(&self) -> ZoneMass {
        self.zone_mass
    }

    /// Multiply every population the next step pulls by `scale` (then back to 1): takes the
    /// mass (1 − s) M out of the liquid in proportion to each node's, leaving its velocity as
    /// it is. Counted in [`ZoneMass::rescaled`]. `liquid_mass` is M, `liquid_mass_nodes().0` of
    /// the state as it is: the caller has it already (`Confinement::membrane_reaction` needs it
    /// for `scale`), and the sum over every node is not done twice per LBM step.
    pub fn set_pull_scale(&mut self, scale: f64, liquid_mass: f64) {
        debug_assert_eq!(liquid_mass.to_bits(), self.liquid_mass_nodes().0.to_bits());
        // Every population of an active node is pulled once in the step (by its neighbour, or
        // by itself through a bounce-back link), so the step takes (1 − s) of the mass.
        self.zone_mass.rescaled += (1.0 - scale) * liquid_mass;
        self.pull_scale = scale;
    }

    /// Mass of the liquid (Σ ρ over the active nodes, in node order) and its node count, as the
    /// last step (or the zone's refilling) left them.
    pub fn liquid_mass_nodes(&self) -> (f64, usize) {
        let (mut m, mut n) = (0.0, 0);
        for (r, &a) in self.rho.iter().zip(&self.active) {
            if a {
                m += r;
                n += 1;
            }
        }
        (m, n)
    }

    /// What the links from the solid-zone node `node` to its liquid neighbours exchange in the
    /// next step (see [`ZoneExchange`]); zero for a liquid node or one with no liquid beside it.
    pub fn zone_exchange(&self, node: usize) -> ZoneExchange {
        let q = L::Q;
        let mut e = ZoneExchange::default();
        if self.active[node] || !self.base_active[node] || self.zone[node] == LIQUID {
            return e;
        }
        let w = self.zone_base as u32 + self.zone[node];
        let uw = self.wall_u[w as usize];
        let p = self.domain.coords(node);
        for i in 1..q {
            let c = L::C[i];
            let Upstream::Node(x) = neighbour(&self.domain, p, [c[0], c[1], c[2]]) else {
                continue;
            };
            if !self.active[x] || self.src[x * q + i] != WALL | w {
                continue;
            }
            let o = L::OPP[i];
            let co = L::C[o];
            let cu = c[0] as f64 * uw[0] + c[1] as f64 * uw[1] + c[2] as f64 * uw[2];
            let inject = 6.0 * L::W[i] * cu;
            let fo = self.f[o * self.nodes() + x].to_f64();
            for a in 0..3 {
                e.pull[a] += 2.0 * fo * co[a] as f64;
                e.wall[a] += inject * co[a] as f64;
                e.gauge[a] += 2.0 * L::W[i] * co[a] as f64;
            }
            e.mass += inject;
        }
        e
    }

    /// Nodes of the lattice.
    pub fn nodes(&self) -> usize {
        self.nx * self.ny * self.nz
    }

    /// Total mass and momentum of the populations of the active nodes (lattice units).
    pub fn mass_momentum3(&self) -> (f64, [f64; 3]) {
        let (q, n) = (L::Q, self.nodes());
        let (mut m, mut j) = (0.0, [0.0; 3]);
        for (idx, a) in self.active.iter().enumerate() {
            if !a {
                continue;
            }
            for i in 0..q {
                let v = self.f[i * n + idx].to_f64();
                m += v;
                j[0] += v * L::C[i][0] as f64;
                j[1] += v * L::C[i][1] as f64;
                if L::D == 3 {
                    j[2] += v * L::C[i][2] as f64;
                }
            }
        }
        (m, j)
    }

    /// One LBM step on any lattice: pull-stream, then collide with the PSM term of every grain
    /// covering each node (Su Eq. 9, per-grain weights B_s = B ε_s / ε so that Σ_s B_s = B of
    /// Eq. 10), and return the force and moment on each of `grains.len()` grains (Eq. 14, summed
    /// over the grain's cells). Grain centres are in lattice coordinates with node i at i + ½
    /// (z = 0 in 2D); the map's cell index is the node index.
    ///
    /// The force on a grain is the reaction to the momentum its solid term puts into the
    /// fluid: F_s = −Σ_x B_s Σ_i Ω_i^s c_i (Su writes Eq. 14 as the momentum transfer; the
    /// sign here makes fluid plus grains conserve momentum, which a test checks).
    pub fn step_motions(
        &mut self,
        map: &SolidMap,
        grains: &[Motion],
        loads: &mut Vec<ForceTorque>,
    ) -> Result<(), CouplingError> {
        let (nx, ny, nz) = (self.nx, self.ny, self.nz);
        let n = self.nodes();
        assert!(
            (map.nx, map.ny) == (nx, ny) && map.total.len() == n,
            "solid map and lattice differ in size"
        );
        // Covers of cell c are covers[start[c]..start[c + 1]] (the map is sorted by cell).
        // One pass over the covers: each cell's first cover is where the cell index first
        // reaches it.
        let mut start = std::mem::take(&mut self.cover_start);
        start.resize(n + 1, 0);
        let mut next = 0;
        for (k, cv) in map.covers.iter().enumerate() {
            let c = cv.cell as usize;
            if c >= next {
                start[next..=c].fill(k as u32);
                next = c + 1;
            }
        }
        start[next..].fill(map.covers.len() as u32);
        // Every cover's load is written by the step (zero on inactive nodes): no clearing.
        self.cover_load.resize(map.covers.len(), ForceTorque::default());

        let forced = self.settings.force.iter().any(|&x| x != 0.0);
        let limits = self.settings.limits;
        let step = self.step;
        let base = Base {
            nx,
            ny,
            nz,
            n,
            f_in: &self.f,
            src: &self.src,
            regular: &self.regular,
            wall_u: &self.wall_u,
            active: &self.active,
            map,
            start: &start,
            grains,
            tau: self.settings.collision.tau(),
            local_tau: self.local.as_ref().map(|(_, t)| t.as_slice()),
            limits: limits.in_precision::<f64>(),
            scale: self.pull_scale,
        };

        // Split every per-node and per-cover output into the same fixed row chunks.
        let rows_chunk = ROWS_PER_TASK * nx;
        let mut tasks = Vec::with_capacity(ny.div_ceil(ROWS_PER_TASK));
        {
            let f_out = SyncPtr(self.other.as_mut_ptr());
            let mut rho: &mut [f64] = &mut self.rho;
            let mut u: &mut [[f64; 3]] = &mut self.u;
            let mut loads_rest: &mut [ForceTorque] = &mut self.cover_load;
            let mut node0 = 0;
            while node0 < n {
                let len = rows_chunk.min(n - node0);
                let (ra, rb) = std::mem::take(&mut rho).split_at_mut(len);
                let (ua, ub) = std::mem::take(&mut u).split_at_mut(len);
                let nc = (start[node0 + len] - start[node0]) as usize;
                let (la, lb) = std::mem::take(&mut loads_rest).split_at_mut(nc);
                tasks.push(Chunk {
                    node0,
                    f_out,
                    rho: ra,
                    u: ua,
                    loads: la,
                });
                rho = rb;
                u = ub;
                loads_rest = lb;
                node0 += len;
            }
        }
        let params = self.params;
        let bad = match &self.local {
            None => run_chunks::<T, L, _>(&base, params, tasks, forced),
            Some((rates, _)) => {
                run_chunks::<T, L, _>(&base, LocalRates { base: params, rates }, tasks, forced)
            }
        };
        if let Some((idx, rho, u)) = bad {
            let tau = match &self.local {
                Some((_, t)) => t[idx],
                None => self.settings.collision.tau(),
            };
            let bad = BadNode {
                step: step + 1,
                node: [idx % nx, (idx / nx) % ny, idx / (nx * ny)],
                rho,
                u,
                tau,
            };
            return Err(CouplingError::Lbm(bad.into_error(&limits)));
        }
        std::mem::swap(&mut self.f, &mut self.other);
        self.step += 1;
        self.pull_scale = 1.0;
        self.cover_start = start;

        loads.clear();
        loads.resize(grains.len(), ForceTorque::default());
        for (cv, l) in map.covers.iter().zip(&self.cover_load) {
            let t = &mut loads[cv.body as usize];
            for a in 0..3 {
                t.force[a] += l.force[a];
                t.torque[a] += l.torque[a];
            }
        }
        Ok(())
    }

    /// BGK relaxation time (TRT: the even one, τ⁺), which sets the viscosity and B of Eq. 10.
    pub fn tau(&self) -> f64 {
        self.settings.collision.tau()
    }

    /// The settings the lattice was built with (the collision after `with_trt`).
    pub fn settings(&self) -> &PsmSettings {
        &self.settings
    }

    /// Whether node `idx` is updated (not in the inactive zone).
    pub fn is_active(&self, idx: usize) -> bool {
        self.active[idx]
    }
}

/// The 2D API (grains as `GrainMotion`, loads as `Load`).
impl<T: Real> PsmFluid<T, D2Q9> {
    /// Set every node to the equilibrium of density `rho` and velocity `u(x, y)`.
    pub fn init_equilibrium(&mut self, init: impl Fn(usize, usize) -> (f64, [f64; 2])) {
        let (q, n) = (D2Q9::Q, self.nx * self.ny);
        for idx in 0..n {
            let (rho, u) = init(idx % self.nx, idx / self.nx);
            let u = [u[0], u[1], 0.0];
            let usq = norm2::<D2Q9>(u);
            for i in 0..q {
                self.f[i * n + idx] = T::from_f64(feq::<D2Q9>(i, rho, u, usq));
            }
            self.rho[idx] = rho;
            self.u[idx] = u;
        }
    }

    /// Total mass and momentum of the populations (lattice units).
    pub fn mass_momentum(&self) -> (f64, [f64; 2]) {
        let (m, j) = self.mass_momentum3();
        (m, [j[0], j[1]])
    }

    /// One LBM step with the grains' 2D motions; the load on each of `grains.len()` grains
    /// (Eq. 14, summed over the grain's circles because the map holds one cover per grain and
    /// cell). See [`PsmFluid::step_motions`].
    pub fn step(
        &mut self,
        map: &SolidMap,
        grains: &[GrainMotion],
        loads: &mut Vec<Load>,
    ) -> Result<(), CouplingError> {
        let mut motions = std::mem::take(&mut self.motions);
        let mut loads3 = std::mem::take(&mut self.loads3);
        motions.clear();
        motions.extend(grains.iter().map(|g| Motion {
            centre: [g.centre[0], g.centre[1], 0.0],
            velocity: [g.velocity[0], g.velocity[1], 0.0],
            omega: [0.0, 0.0, g.omega],
        }));
        let r = self.step_motions(map, &motions, &mut loads3);
        loads.clear();
        loads.extend(loads3.iter().map(|l| Load {
            force: [l.force[0], l.force[1]],
            torque: l.torque[2],
        }));
        self.motions = motions;
        self.loads3 = loads3;
        r
    }
}

/// The pull source of population `i` at node `idx`: the upstream node if it holds liquid, else
/// a bounce-back link to what is there: a box face, the domain's stationary solid, or the solid
/// zone with its boundary velocity.
fn link<L: Lattice>(
    domain: &Domain,
    active: &[bool],
    base_active: &[bool],
    zone: &[u32],
    zone_base: usize,
    idx: usize,
    i: usize,
) -> u32 {
    let c = L::C[i];
    match neighbour(domain, domain.coords(idx), [-c[0], -c[1], -c[2]]) {
        Upstream::Node(j) if active[j] => j as u32,
        Upstream::Node(j) if base_active[j] && zone[j] != LIQUID => WALL | (zone_base as u32 + zone[j]),
        Upstream::Node(_) => WALL,
        Upstream::Face(f) => WALL | (1 + f as u32),
    }
}

/// The node-index step from the node population i streams from to the node it streams to:
/// c_x + nx c_y + nx ny c_z.
#[inline(always)]
fn pull_offset<L: Lattice>(i: usize, n: [usize; 3]) -> isize {
    let c = L::C[i];
    c[0] as isize + n[0] as isize * (c[1] as isize + n[1] as isize * c[2] as isize)
}

/// Whether every population of node `idx` streams from its upstream node without a wrap or a
/// bounce-back (see `PsmFluid::regular`).
fn is_regular<L: Lattice>(src: &[u32], n: [usize; 3], idx: usize) -> bool {
    (0..L::Q).all(|i| {
        let up = idx as isize - pull_offset::<L>(i, n);
        up >= 0 && src[idx * L::Q + i] == up as u32
    })
}

fn regular_nodes<L: Lattice>(src: &[u32], n: [usize; 3]) -> Vec<bool> {
    (0..n[0] * n[1] * n[2])
        .map(|idx| is_regular::<L>(src, n, idx))
        .collect()
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

/// Offset x − c with the minimum-image convention on a periodic box (the 2D arithmetic of
/// `min_image` for x and y; z only in 3D).
#[inline]
fn min_image3<L: Lattice>(x: [f64; 3], c: [f64; 3], n: [usize; 3]) -> [f64; 3] {
    let d = min_image([x[0], x[1]], [c[0], c[1]], n[0], n[1]);
    let mut z = 0.0;
    if L::D == 3 {
        let l = n[2] as f64;
        z = x[2] - c[2];
        if z > 0.5 * l {
            z -= l;
        } else if z < -0.5 * l {
            z += l;
        }
    }
    [d[0], d[1], z]
}

/// Velocity of a grain's material at offset `r`: v + ω × r (Leonardi Eq. 20); in 2D the
/// expression of `GrainMotion::velocity_at`.
#[inline]
fn velocity_at<L: Lattice>(g: &Motion, r: [f64; 3]) -> [f64; 3] {
    if L::D == 3 {
        g.velocity_at(r)
    } else {
        let w = g.omega[2];
        [g.velocity[0] - w * r[1], g.velocity[1] + w * r[0], 0.0]
    }
}

/// What every chunk of a step reads.
struct Base<'a, T> {
    nx: usize,
    ny: usize,
    nz: usize,
    /// Nodes of the lattice: the stride between the planes of `f_in` and `Chunk::f_out`.
    n: usize,
    f_in: &'a [T],
    src: &'a [u32],
    regular: &'a [bool],
    wall_u: &'a [[f64; 3]],
    active: &'a [bool],
    map: &'a SolidMap,
    start: &'a [u32],
    grains: &'a [Motion],
    tau: f64,
    local_tau: Option<&'a [f64]>,
    limits: LimitsT<f64>,
    /// Factor on every pulled population (`PsmFluid::set_pull_scale`).
    scale: f64,
}

/// The nodes [node0, node0 + rho.len()) of one task and its share of the outputs.
struct Chunk<'a, T> {
    node0: usize,
    /// The whole post-collision array (direction-major): the chunk writes its own nodes only.
    f_out: SyncPtr<T>,
    rho: &'a mut [f64],
    u: &'a mut [[f64; 3]],
    loads: &'a mut [ForceTorque],
}

/// Every chunk on the rayon pool with the liquid collision `C`; the first node outside the
/// limits (node order), if any: (node, ρ, u).
fn run_chunks<T: Real, L: Lattice, C: Collider<L, f64>>(
    base: &Base<T>,
    coll: C,
    tasks: Vec<Chunk<T>>,
    forced: bool,
) -> Option<(usize, f64, [f64; 3])> {
    tasks
        .into_par_iter()
        .map(|c| {
            simd::dispatch(ChunkOp::<T, L, C> {
                base,
                coll: &coll,
                chunk: c,
                forced,
                _l: PhantomData,
            })
        })
        .collect::<Vec<_>>()
        .into_iter()
        .flatten()
        .next()
}

/// One chunk, compiled for each instruction-set level (`lbdem_core::simd`).
struct ChunkOp<'a, T, L, C> {
    base: &'a Base<'a, T>,
    coll: &'a C,
    chunk: Chunk<'a, T>,
    forced: bool,
    _l: PhantomData<L>,
}

impl<T: Real, L: Lattice, C: Collider<L, f64>> WithSimd for ChunkOp<'_, T, L, C> {
    type Output = Option<(usize, f64, [f64; 3])>;
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) -> Self::Output {
        if self.forced {
            chunk::<T, L, C, true>(self.base, self.coll, self.chunk)
        } else {
            chunk::<T, L, C, false>(self.base, self.coll, self.chunk)
        }
    }
}

/// Nodes collided side by side (as the lanes of `lbdem_lbm`'s collision): eight f64 lanes fill
/// an AVX-512 register (two AVX2 ones). Runs of fewer active nodes go four or one at a time
/// through the same code.
const LANES: usize = 8;

/// The first node outside the limits: (node, ρ, u).
type Bad = Option<(usize, f64, [f64; 3])>;

/// One chunk of nodes: runs of [`LANES`] active nodes through [`nodes`] together, the rest one
/// by one. A node's result does not depend on which way it went (the lanes do not mix).
#[inline(always)] // into each instruction-set level's copy
fn chunk<T: Real, L: Lattice, C: Collider<L, f64>, const F: bool>(
    b: &Base<T>,
    coll: &C,
    mut out: Chunk<T>,
) -> Bad {
    let q = L::Q;
    // The lattice's velocities as floats (z = 0 in 2D).
    let cf: [[f64; 3]; QMAX] = std::array::from_fn(|i| {
        if i < q {
            let c = L::C[i];
            [
                c[0] as f64,
                c[1] as f64,
                if L::D == 3 { c[2] as f64 } else { 0.0 },
            ]
        } else {
            [0.0; 3]
        }
    });
    let len = out.rho.len();
    let mut first_bad = None;
    let mut k = 0;
    while k < len {
        let idx = out.node0 + k;
        if k + LANES <= len && b.active[idx..idx + LANES].iter().all(|&a| a) {
            nodes::<T, L, C, F, LANES>(b, coll, &cf, &mut out, k, &mut first_bad);
            k += LANES;
        } else if k + 4 <= len && b.active[idx..idx + 4].iter().all(|&a| a) {
            nodes::<T, L, C, F, 4>(b, coll, &cf, &mut out, k, &mut first_bad);
            k += 4;
        } else {
            if b.active[idx] {
                nodes::<T, L, C, F, 1>(b, coll, &cf, &mut out, k, &mut first_bad);
            } else {
                // A closed node's grains take no load from it.
                let c0 = b.start[out.node0] as usize;
                let (lo, hi) = (b.start[idx] as usize - c0, b.start[idx + 1] as usize - c0);
                out.loads[lo..hi].fill(ForceTorque::default());
            }
            k += 1;
        }
    }
    first_bad
}

/// `W` consecutive active nodes of a chunk, from its node `k`: pull-stream (Su Eq. 12) with
/// bounce-back from walls and inactive nodes, then the PSM collision of Su Eq. 9,
///
///   f_i⁺ = f_i + (1 − B)(C(f)_i − f_i) + Σ_s B_s Ω_i^s,
///
/// where C is the liquid collision of `lbdem-lbm` (BGK, Su Eq. 9 with B = 0, or TRT, with the
/// Guo source of Leonardi Eq. 16 and u = (Σ f c + F/2)/ρ, Su Eq. 13 / Leonardi Eq. 17: with B the
/// node receives exactly (1 − B) F of momentum), B from Eq. 10, B_s = B ε_s / ε so that
/// Σ_s B_s = B, and Ω^s the solid term of Eq. 11. The load on grain s is the reaction to the
/// momentum Ω^s puts into the liquid (Eq. 14).
///
/// Ω_i^s = f_o − f_i + f_i^eq(ρ, u_s) − f_o^eq(ρ, u) is linear in B_s but for f_i^eq(ρ, u_s),
/// which is quadratic in u_s: the sum over the grains needs only Σ B_s, Σ B_s u_s and
/// Σ B_s u_s u_s, and the momentum grain s puts into the node, Σ_i B_s Ω_i^s c_i, is
/// B_s (ρ u_s + ρ u − 2 j) with j = Σ f c (the equilibrium's first moment is exact). So each
/// covering grain costs a few products, not a loop over the directions.
#[inline(always)]
fn nodes<T: Real, L: Lattice, C: Collider<L, f64>, const F: bool, const W: usize>(
    b: &Base<T>,
    coll: &C,
    cf: &[[f64; 3]; QMAX],
    out: &mut Chunk<T>,
    k: usize,
    first_bad: &mut Bad,
) {
    let q = L::Q;
    let n = b.n;
    let idx0 = out.node0 + k;
    let c0 = b.start[out.node0] as usize;
    // Pull-stream (Su Eq. 12), bounce-back from walls and inactive nodes (Leonardi Eq. 19).
    let mut f = [[0.0; W]; QMAX];
    if b.regular[idx0..idx0 + W].iter().all(|&r| r) {
        // Every lane pulls from its upstream nodes: the same values `src` names, W consecutive
        // values of plane i. A scale of 1 is left out (1 x is x: the same bits).
        for i in 0..q {
            let up = (i * n) as isize + idx0 as isize - pull_offset::<L>(i, [b.nx, b.ny, b.nz]);
            let row = &b.f_in[up as usize..up as usize + W];
            if b.scale == 1.0 {
                for w in 0..W {
                    f[i][w] = row[w].to_f64();
                }
            } else {
                for w in 0..W {
                    f[i][w] = b.scale * row[w].to_f64();
                }
            }
        }
    } else {
        for i in 0..q {
            for w in 0..W {
                let idx = idx0 + w;
                let s = b.src[idx * q + i];
                f[i][w] = if s & WALL == 0 {
                    b.scale * b.f_in[i * n + s as usize].to_f64()
                } else {
                    let uw = b.wall_u[(s & !WALL) as usize];
                    let c = cf[i];
                    let mut cu = c[0] * uw[0] + c[1] * uw[1];
                    if L::D == 3 {
                        cu += c[2] * uw[2];
                    }
                    b.scale * b.f_in[L::OPP[i] * n + idx].to_f64() + 6.0 * L::W[i] * cu
                };
            }
        }
    }
    // The liquid collision C(f) and the moments it used.
    let mut post = f;
    let m = C::collide::<W, F>(coll, &mut post, idx0);
    // Per node: whether grains cover it, B (Eq. 10), and Σ B_s, Σ B_s u_s, Σ B_s u_s u_s (xx,
    // yy, zz, xy, xz, yz) over its grains.
    let mut covered = [false; W];
    let mut eps = [0.0; W];
    let mut tau = [b.tau; W];
    for w in 0..W {
        let idx = idx0 + w;
        covered[w] = b.start[idx] != b.start[idx + 1];
        eps[w] = b.map.total[idx];
        if let Some(t) = b.local_tau {
            tau[w] = t[idx];
        }
    }
    let any_covered = covered.iter().any(|&c| c);
    // B (Eq. 10) and B / ε, side by side (no cover: ε = 0 and B = 0).
    let mut weight = [0.0; W];
    let mut b_per_eps = [0.0; W];
    // The pre-collision momentum j = Σ f c (u carries half the force as well).
    let mut j = [[0.0; W]; 3];
    if any_covered {
        for w in 0..W {
            weight[w] = psm_weight(eps[w], tau[w]);
            b_per_eps[w] = if covered[w] { weight[w] / eps[w] } else { 0.0 };
        }
        for i in 0..q {
            for a in 0..L::D {
                for w in 0..W {
                    j[a][w] += f[i][w] * cf[i][a];
                }
            }
        }
    }
    let mut s0 = [0.0; W];
    let mut s1 = [[0.0; W]; 3];
    let mut s2 = [[0.0; W]; 6];
    // The first node's lattice coordinates (one integer division per group, not per node).
    let at = [idx0 % b.nx, (idx0 / b.nx) % b.ny, idx0 / (b.nx * b.ny)];
    for w in 0..W {
        if !covered[w] {
            continue;
        }
        let idx = idx0 + w;
        let cover: &[CellCover] = &b.map.covers[b.start[idx] as usize..b.start[idx + 1] as usize];
        let rho = m.rho[w];
        let u = [m.u[0][w], m.u[1][w], m.u[2][w]];
        let j = [j[0][w], j[1][w], j[2][w]];
        // The node's centre (lanes past the end of a row wrap onto the next).
        let mut p = [at[0] + w, at[1], at[2]];
        if p[0] >= b.nx {
            p = [p[0] - b.nx, p[1] + 1, p[2]];
            if p[1] >= b.ny {
                p = [p[0], 0, p[2] + 1];
            }
        }
        let x = [
            p[0] as f64 + 0.5,
            p[1] as f64 + 0.5,
            if L::D == 3 { p[2] as f64 + 0.5 } else { 0.0 },
        ];
        let b_per_eps = b_per_eps[w];
        for (mm, cv) in cover.iter().enumerate() {
            let bs = b_per_eps * cv.fraction;
            let g = &b.grains[cv.body as usize];
            let r = min_image3::<L>(x, g.centre, [b.nx, b.ny, b.nz]);
            let us = velocity_at::<L>(g, r);
            s0[w] += bs;
            let bu = [bs * us[0], bs * us[1], bs * us[2]];
            s1[0][w] += bu[0];
            s1[1][w] += bu[1];
            s2[0][w] += bu[0] * us[0];
            s2[1][w] += bu[1] * us[1];
            s2[3][w] += bu[0] * us[1];
            if L::D == 3 {
                s1[2][w] += bu[2];
                s2[2][w] += bu[2] * us[2];
                s2[4][w] += bu[0] * us[2];
                s2[5][w] += bu[1] * us[2];
            }
            let mut fs = [0.0; 3];
            for a in 0..L::D {
                fs[a] = -bs * (rho * (us[a] + u[a]) - 2.0 * j[a]);
            }
            out.loads[b.start[idx] as usize - c0 + mm] = ForceTorque {
                force: fs,
                torque: [
                    r[1] * fs[2] - r[2] * fs[1],
                    r[2] * fs[0] - r[0] * fs[2],
                    r[0] * fs[1] - r[1] * fs[0],
                ],
            };
        }
    }
    // The covered nodes' results overwrite `post` (which they read only at their own i).
    if any_covered {
        let mut usq = [0.0; W];
        let mut trace = [0.0; W];
        for w in 0..W {
            usq[w] = m.u[0][w] * m.u[0][w] + m.u[1][w] * m.u[1][w];
            if L::D == 3 {
                usq[w] += m.u[2][w] * m.u[2][w];
            }
            trace[w] = s2[0][w] + s2[1][w] + s2[2][w];
        }
        for i in 0..q {
            let o = L::OPP[i];
            let c = cf[i];
            for w in 0..W {
                let (rho, u) = (m.rho[w], [m.u[0][w], m.u[1][w], m.u[2][w]]);
                let mut cs1 = c[0] * s1[0][w] + c[1] * s1[1][w];
                let mut cs2c = c[0] * c[0] * s2[0][w] + c[1] * c[1] * s2[1][w] + 2.0 * c[0] * c[1] * s2[3][w];
                let mut cu = c[0] * u[0] + c[1] * u[1];
                if L::D == 3 {
                    cs1 += c[2] * s1[2][w];
                    cs2c += c[2] * c[2] * s2[2][w] + 2.0 * (c[0] * c[2] * s2[4][w] + c[1] * c[2] * s2[5][w]);
                    cu += c[2] * u[2];
                }
                // Σ_s B_s f_i^eq(ρ, u_s) and f_o^eq(ρ, u) (c_o = −c_i), Eq. 7.
                let eq_s = L::W[i] * rho * (s0[w] + 3.0 * cs1 + 4.5 * cs2c - 1.5 * trace[w]);
                let eq_o = L::W[o] * rho * (1.0 - 3.0 * cu + 4.5 * cu * cu - 1.5 * usq[w]);
                let (fi, fo) = (f[i][w], f[o][w]);
                let v = fi + (1.0 - weight[w]) * (post[i][w] - fi) + (s0[w] * (fo - fi - eq_o) + eq_s);
                post[i][w] = if covered[w] { v } else { post[i][w] };
            }
        }
    }
    for (i, p) in post.iter().enumerate().take(q) {
        for w in 0..W {
            // SAFETY: node idx0 + w belongs to this chunk (`Chunk::f_out`), plane i is in bounds.
            unsafe { *out.f_out.0.add(i * n + idx0 + w) = T::from_f64(p[w]) };
        }
    }
    let bad = b.limits.bad_lanes(&m.rho, &m.usq);
    if bad != 0 && first_bad.is_none() {
        let w = bad.trailing_zeros() as usize;
        *first_bad = Some((idx0 + w, m.rho[w], [m.u[0][w], m.u[1][w], m.u[2][w]]));
    }
    for w in 0..W {
        out.rho[k + w] = m.rho[w];
        out.u[k + w] = [m.u[0][w], m.u[1][w], m.u[2][w]];
    }
}
