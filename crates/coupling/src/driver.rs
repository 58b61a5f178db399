//! The coupled time loop of Su et al. 2020 Fig. 2: one LBM cycle, then `ratio` DEM cycles with
//! the hydrodynamic force and moment of that LBM cycle held fixed (Table 3: r = δt/Δt).
//!
//! The held load replaces the previous one in the DEM's stored total force as well, so the
//! first half-kick of velocity Verlet already uses it: the impulse the grains receive over the
//! sub-cycles is exactly F δt, the momentum the fluid lost in the LBM step.

use crate::confine::{Confinement, MembraneBoundary};
use crate::error::CouplingError;
use crate::hydro::{Hydro, HydroState};
use crate::psm::{GrainMotion, Load};
use crate::solid_fraction::GrainCircle;
use crate::units::CouplingUnits;
use lbdem_dem::{Law, StepParams, Stepper, System, Vec2};
use lbdem_lbm::Real;
use std::time::{Duration, Instant};

/// The lightest wet grain, over the liquid's density, for which
/// [`Coupled::with_interior_liquid_correction`] is accepted: Uhlmann (2005) reports the explicit
/// correction stable down to about 1.2.
pub const INTERIOR_LIQUID_MIN_RATIO: f64 = 1.2;

/// Wall-clock time spent in each part of the loop.
#[derive(Clone, Copy, Debug, Default)]
pub struct Timing {
    pub lbm: Duration,
    pub dem: Duration,
    /// Solid map, grain motions, solid zone, load conversion (the sum of the three below).
    pub coupling: Duration,
    /// Of `coupling`: the grains' circles and motions on the lattice and the solid map.
    pub map: Duration,
    /// Of `coupling`: the solid zone of a confined liquid (membrane and push-plate), as far as
    /// it outlasts the map (the two are drawn side by side), and handing it to the lattice.
    pub zone: Duration,
}

/// Everything a [`Coupled`] run reads from one cycle to the next besides its configuration
/// (laws, step parameters, units, r_hd, depth, dry bodies, the interior-liquid switch, which
/// the scene sets again): the DEM system, the held loads, the drivers' forces, the previous
/// grain motions of the interior-liquid correction and the fluid's state. Restored into a run
/// built the same way, it continues bit for bit (`tests/resume.rs`).
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound = "")]
pub struct CoupledState<T: Real> {
    pub sys: System,
    /// Load of the last LBM cycle on each body (SI).
    pub hydro: Vec<Load>,
    pub user_force: Vec<Vec2>,
    pub user_torque: Vec<f64>,
    /// Grain motions (lattice units) at the start of the previous LBM cycle.
    pub previous: Vec<GrainMotion>,
    pub fluid: HydroState<T>,
    /// Where each grain was last mapped on the lattice (lattice units, scaled by r_hd), when the
    /// solid map is kept between steps (`Hydro::set_remap_tolerance` above 0); else empty.
    #[serde(default)]
    pub mapped: Vec<GrainCircle>,
    /// Where the membrane grains were at the start of the last LBM cycle (ring order), when the
    /// membrane shows the liquid its velocity ([`MembraneBoundary::Moving`]); else empty.
    #[serde(default)]
    pub membrane_previous: Vec<Vec2>,
    /// The velocities the membrane grains showed the liquid in the last LBM cycle (ring order;
    /// `Moving` only), which an under-relaxed boundary carries on from.
    #[serde(default)]
    pub membrane_shown: Vec<Vec2>,
    /// DEM sub-steps per LBM step when the state was taken ([`Coupled::set_ratio`] may have
    /// changed it from the configuration's; the masses in `sys` went with it). None in
    /// checkpoints written before 2026-11-30: the configuration's.
    #[serde(default)]
    pub ratio: Option<u32>,
    /// LBM steps taken. None in checkpoints written before 2026-11-30: the DEM steps over the
    /// ratio, which is right while the ratio never changed.
    #[serde(default)]
    pub lbm_steps: Option<u64>,
}

/// A coupled LBM-DEM run: the lattice, the grains and the scratch of both engines.
pub struct Coupled<T: Real> {
    pub fluid: Hydro<T>,
    pub sys: System,
    pub law: Law,
    pub wall_law: Law,
    /// DEM step parameters (`dt` = the DEM time step of `units`).
    pub params: StepParams,
    pub units: CouplingUnits,
    /// Hydrodynamic radius factor, LBM step only (Su Sect. 2.3: 0.8 in 2D).
    pub r_hd: f64,
    /// Depth of the 2D sample (m): DEM masses are per this depth (density × area × depth is
    /// what `Bodies::add` gets as density × area), so the fluid's per-metre loads are scaled by it.
    pub depth: f64,
    /// Bodies that do not feel the fluid (e.g. the membrane ring), by body index.
    pub dry: Vec<bool>,
    /// Forces and moments other than the fluid's (drivers), added to the held load.
    pub user_force: Vec<Vec2>,
    pub user_torque: Vec<f64>,
    /// Load of the last LBM cycle on each body (SI: N and N m over the depth).
    pub hydro: Vec<Load>,
    /// Give back to each grain the inertia of the liquid the PSM collision carries inside it
    /// (see [`Coupled::with_interior_liquid_correction`]). Off by default.
    interior_liquid_correction: bool,
    pub timing: Timing,
    /// The liquid confined to the sample (membrane and push-plates), if set.
    confine: Option<Confinement>,
    /// Scratch: the load a moving membrane boundary puts on each body (lattice units).
    membrane_loads: Vec<Load>,
    /// Grain motions (lattice units) at the start of the previous LBM cycle.
    previous: Vec<GrainMotion>,
    dem: Stepper,
    motions: Vec<GrainMotion>,
    circles: Vec<GrainCircle>,
    loads: Vec<Load>,
    /// LBM steps taken (the DEM's step count over the ratio no longer says it once
    /// [`Coupled::set_ratio`] has changed the ratio).
    lbm_steps: u64,
    /// The configuration's ratio and DEM step, which [`Coupled::set_ratio`] returns to exactly.
    configured: (u32, f64),
}

/// Grain motions and circles in lattice units, then the solid fraction of every cell.
fn map_grains<T: Real>(
    sys: &System,
    u: &CouplingUnits,
    dry: &[bool],
    r_hd: f64,
    motions: &mut Vec<GrainMotion>,
    circles: &mut Vec<GrainCircle>,
    fluid: &mut Hydro<T>,
) -> Result<(), CouplingError> {
    let b = &sys.bodies;
    motions.clear();
    circles.clear();
    for k in 0..b.len() {
        let p = u.position_to_lattice([b.pos[k].x, b.pos[k].y]);
        motions.push(GrainMotion {
            centre: p,
            velocity: u.velocity_to_lattice([b.vel[k].x, b.vel[k].y]),
            omega: u.omega_to_lattice(b.omega[k]),
        });
        if dry[k] {
            continue;
        }
        // One sin_cos per grain, not per circle.
        let (sin, cos) = b.angle[k].sin_cos();
        for c in b.circle_start[k]..b.circle_start[k + 1] {
            let off = b.circle_offset[c].rotated_sc(sin, cos);
            let cp = u.position_to_lattice([b.pos[k].x + off.x, b.pos[k].y + off.y]);
            circles.push(GrainCircle {
                body: k as u32,
                centre: cp,
                radius: u.length_to_lattice(b.circle_r[c]),
            });
        }
    }
    fluid.map(circles, motions, r_hd, sys.domain.periodic)
}

impl<T: Real> Coupled<T> {
    pub fn new(
        fluid: Hydro<T>,
        sys: System,
        law: Law,
        wall_law: Law,
        params: StepParams,
        units: CouplingUnits,
        r_hd: f64,
    ) -> Result<Self, CouplingError> {
        if (params.dt - units.dt_dem).abs() > 1e-12 * units.dt_dem {
            return Err(CouplingError::Unsupported(format!(
                "DEM step {} s differs from the coupling units' {} s",
                params.dt, units.dt_dem
            )));
        }
        if !(r_hd > 0.0 && r_hd <= 1.0) {
            return Err(CouplingError::Unsupported(format!(
                "hydrodynamic radius factor r_hd = {r_hd} must be in (0, 1]; set [coupling] r_hd \
                 (Su et al. use 0.8 in 2D, 1 for validation)"
            )));
        }
        if params.local_damping != 0.0 {
            // The held-load swap below edits the stored Verlet force after local damping was
            // applied to it, so the two do not mix.
            return Err(CouplingError::Unsupported(format!(
                "[step] local_damping = {} is not supported in coupled runs (the liquid damps the grains); \
                 remove it or use viscous_damping",
                params.local_damping
            )));
        }
        let n = sys.bodies.len();
        let configured = (units.ratio, units.dt_dem);
        Ok(Self {
            fluid,
            law,
            wall_law,
            params,
            units,
            r_hd,
            depth: 1.0,
            dry: vec![false; n],
            user_force: sys.bodies.ext_force.clone(),
            user_torque: sys.bodies.ext_torque.clone(),
            hydro: vec![Load::default(); n],
            interior_liquid_correction: false,
            previous: Vec::new(),
            sys,
            timing: Timing::default(),
            confine: None,
            membrane_loads: Vec::new(),
            dem: Stepper::new(),
            motions: Vec::new(),
            circles: Vec::new(),
            loads: Vec::new(),
            lbm_steps: 0,
            configured,
        })
    }

    /// Confine the liquid to the membrane minus the regions behind the walls `plates` (Su et
    /// al. 2020 Fig. 2 step 15), from now on and before every LBM step. PSM only. The nodes
    /// outside close at once; their liquid is not counted in [`crate::ZoneMass`]. With
    /// [`MembraneBoundary::Moving`] the membrane grains feel the reaction of the liquid's
    /// bounce-back on the outline (`Confinement::membrane_reaction`), whether or not they are dry.
    pub fn with_confinement(
        mut self,
        plates: Vec<usize>,
        boundary: MembraneBoundary,
    ) -> Result<Self, CouplingError> {
        let mut c = Confinement::new(&self.sys, plates, boundary)?;
        let [nx, ny] = self.fluid.size();
        let (zone, vel) = c.zone(&self.sys, &self.units, nx, ny);
        self.fluid.set_zone(zone, vel)?;
        if let Hydro::Psm { fluid, .. } = &mut self.fluid {
            fluid.reset_zone_mass();
        }
        self.confine = Some(c);
        Ok(self)
    }

    /// Under-relax the velocity the moving membrane shows the liquid
    /// ([`Confinement::set_relaxation`]); after [`Coupled::with_confinement`].
    pub fn with_membrane_relaxation(mut self, omega: f64) -> Result<Self, CouplingError> {
        let c = self.confine.as_mut().ok_or_else(|| {
            CouplingError::Unsupported("membrane relaxation without a confined liquid".into())
        })?;
        c.set_relaxation(omega)?;
        Ok(self)
    }

    /// Switch on the interior-liquid correction (PSM only; refused where it cannot be stable).
    ///
    /// Inside a grain the PSM collision (Eqs. 9, 11) replaces the share B_s of the liquid's
    /// momentum by the grain's every step, and Eq. 14 charges the grain for it, so that in the
    /// end the liquid inside moves with the grain: a grain
    /// accelerates as if it weighed (ρ_s + ρ_f) V instead of ρ_s V (its buoyant weight is already
    /// applied through the DEM's reduced gravity). The correction gives back, per LBM cycle, the
    /// momentum and angular momentum that moving that liquid rigidly from the grain's previous
    /// motion to its present one takes (Uhlmann, J. Comput. Phys. 209 (2005) 448, Eq. 15, the
    /// rigid-body approximation of the interior liquid), with the weights of
    /// [`Hydro::interior_liquid`]. It is explicit; Uhlmann reports it stable for density ratios
    /// down to about 1.2 (`tests/added_mass.rs` checks 1.25), so the lightest grain that feels
    /// the liquid must be at least [`INTERIOR_LIQUID_MIN_RATIO`] times denser than it. Conservative
    /// on every case run: `lbdem interior-liquid-map` (a settling disk) found its edge at 0.3-0.7,
    /// lower the better the grain is resolved (docs/stability.md, "Near-neutral grains").
    ///
    /// With it on, [`Coupled::momentum`] (all the liquid plus the grains) is no longer conserved:
    /// the liquid inside the grains is counted twice.
    pub fn with_interior_liquid_correction(self) -> Result<Self, CouplingError> {
        let rho_f = self.units.lattice.rho;
        let lightest = self.lightest_wet_density();
        let ratio = lightest / rho_f;
        if ratio.is_nan() || ratio < INTERIOR_LIQUID_MIN_RATIO {
            return Err(CouplingError::Unsupported(format!(
                "interior-liquid correction with grain/liquid density ratio {ratio:.3} (lightest wet grain \
                 {lightest} kg/m³, liquid {rho_f} kg/m³): it is explicit and unstable below about \
                 {INTERIOR_LIQUID_MIN_RATIO} (Uhlmann 2005; docs/stability.md, \"Near-neutral grains\"); \
                 switch it off for near-neutral grains"
            )));
        }
        self.force_interior_liquid_correction()
    }

    /// [`Coupled::with_interior_liquid_correction`] without its density-ratio refusal: for the
    /// stability map that finds where the refusal should sit (`lbdem interior-liquid-map`), not
    /// for scenes. Still PSM only.
    pub fn force_interior_liquid_correction(mut self) -> Result<Self, CouplingError> {
        if self.fluid.method() != crate::hydro::Method::Psm {
            return Err(CouplingError::Unsupported(
                "the interior-liquid correction is for PSM; bounce-back grains hold no liquid: \
                 switch it off or use method = \"psm\""
                    .into(),
            ));
        }
        self.interior_liquid_correction = true;
        Ok(self)
    }

    /// Density (kg/m³: the per-area density over the depth, mass scaling included) of the lightest
    /// grain that feels the liquid; infinite if none does.
    pub fn lightest_wet_density(&self) -> f64 {
        let b = &self.sys.bodies;
        (0..b.len())
            .filter(|&k| !self.dry[k])
            .map(|k| b.density[k] / self.depth)
            .fold(f64::INFINITY, f64::min)
    }

    /// The lattice's liquid density (kg/m³).
    pub fn liquid_density(&self) -> f64 {
        self.units.lattice.rho
    }

    /// One LBM cycle and `ratio` DEM cycles.
    pub fn step(&mut self) -> Result<(), CouplingError> {
        let t0 = Instant::now();
        // The solid map and the solid zone read the grains and write apart: side by side (each
        // is mostly serial work), with the same results as one after the other.
        let [nx, ny] = self.fluid.size();
        let (mapped, t_map) = rayon::join(
            || {
                let r = map_grains(
                    &self.sys,
                    &self.units,
                    &self.dry,
                    self.r_hd,
                    &mut self.motions,
                    &mut self.circles,
                    &mut self.fluid,
                );
                (r, Instant::now())
            },
            || {
                if let Some(c) = &mut self.confine {
                    c.zone(&self.sys, &self.units, nx, ny);
                }
            },
        )
        .0;
        mapped?;
        if let Some(c) = &mut self.confine {
            let (zone, vel) = c.current_zone();
            self.fluid.set_zone(zone, vel)?;
            if c.boundary() == MembraneBoundary::Moving {
                self.membrane_loads.clear();
                self.membrane_loads.resize(self.sys.bodies.len(), Load::default());
                if let Hydro::Psm { fluid, .. } = &mut self.fluid {
                    c.membrane_reaction(fluid, &mut self.membrane_loads);
                }
            }
        }
        let t1 = Instant::now();
        self.fluid.step(&self.motions, &mut self.loads)?;
        if self
            .confine
            .as_ref()
            .is_some_and(|c| c.boundary() == MembraneBoundary::Moving)
        {
            for (l, m) in self.loads.iter_mut().zip(&self.membrane_loads) {
                l.force[0] += m.force[0];
                l.force[1] += m.force[1];
            }
        }
        let t2 = Instant::now();
        if self.interior_liquid_correction {
            self.add_interior_liquid();
        }
        let b = &mut self.sys.bodies;
        for k in 0..b.len() {
            let l = &self.loads[k];
            let f = self.units.force_to_si(l.force).map(|x| x * self.depth);
            let t = self.units.torque_to_si(l.torque) * self.depth;
            self.hydro[k] = Load { force: f, torque: t };
            let new_f = self.user_force[k] + Vec2::new(f[0], f[1]);
            let new_t = self.user_torque[k] + t;
            // Swap the held load in the stored total too (see the module note).
            b.force[k] += new_f - b.ext_force[k];
            b.torque[k] += new_t - b.ext_torque[k];
            b.ext_force[k] = new_f;
            b.ext_torque[k] = new_t;
        }
        let t3 = Instant::now();
        for _ in 0..self.units.ratio {
            self.dem
                .step_law(&self.params, &self.law, &self.wall_law, &mut self.sys)?;
        }
        let t4 = Instant::now();
        self.timing.coupling += (t1 - t0) + (t3 - t2);
        self.timing.map += t_map - t0;
        self.timing.zone += t1 - t_map;
        self.timing.lbm += t2 - t1;
        self.timing.dem += t4 - t3;
        self.lbm_steps += 1;
        Ok(())
    }

    /// LBM steps taken.
    pub fn lbm_steps(&self) -> u64 {
        self.lbm_steps
    }

    /// Take `ratio` DEM sub-steps per LBM step from now on, and scale every body's mass and
    /// inertia by (old ratio / new ratio)², so that the DEM step δt/ratio keeps its margin to the
    /// critical step (which goes with √m): mass scaling that follows the run (Su Table 3's
    /// δt/Δt = 100 is the unscaled end of the ladder). Velocities are kept, and so are the DEM's
    /// contact list and last forces (its scratch refreshes h/m per body when the step or a mass
    /// changes, and a fresh one continues the same bits: `tests/resume.rs`). Returns the factor
    /// the masses were scaled by.
    pub fn set_ratio(&mut self, ratio: u32) -> Result<f64, CouplingError> {
        if ratio == 0 {
            return Err(CouplingError::Unsupported(
                "a DEM-LBM ratio of 0: give at least one DEM step per LBM step".into(),
            ));
        }
        let old = self.units.ratio;
        if ratio == old {
            return Ok(1.0);
        }
        let factor = (f64::from(old) / f64::from(ratio)).powi(2);
        self.sys.bodies.scale_mass(factor);
        self.set_step(ratio);
        Ok(factor)
    }

    /// The DEM step δt/ratio in the units and the step parameters, masses untouched (the
    /// configuration's own step, to the bit, at its ratio).
    fn set_step(&mut self, ratio: u32) {
        self.units.ratio = ratio;
        self.units.dt_dem = if ratio == self.configured.0 {
            self.configured.1
        } else {
            self.units.dt() / f64::from(ratio)
        };
        self.params.dt = self.units.dt_dem;
    }

    /// Cancel the interior liquid's share of the last load: in this LBM cycle the collision
    /// moved the liquid it carries with each grain from the grain's previous motion to its
    /// present one (before the first cycle the liquid is at rest). For the rigid field
    /// v + ω ẑ × r the momentum is A v + ω ẑ × S and the angular momentum S × v + J ω.
    fn add_interior_liquid(&mut self) {
        let Some(inner) = self.fluid.interior_liquid(&self.motions) else {
            return;
        };
        if self.previous.len() != self.motions.len() {
            self.previous = vec![GrainMotion::default(); self.motions.len()];
        }
        for (k, m) in inner.into_iter().enumerate() {
            let (now, before) = (&self.motions[k], &self.previous[k]);
            let dv = [
                now.velocity[0] - before.velocity[0],
                now.velocity[1] - before.velocity[1],
            ];
            let dw = now.omega - before.omega;
            let l = &mut self.loads[k];
            l.force[0] += m.area * dv[0] - dw * m.first[1];
            l.force[1] += m.area * dv[1] + dw * m.first[0];
            l.torque += m.first[0] * dv[1] - m.first[1] * dv[0] + m.polar * dw;
        }
        self.previous.clone_from(&self.motions);
    }

    /// Total momentum of fluid and grains (SI, over the sample's depth); conserved to round-off
    /// unless the interior-liquid correction is on.
    pub fn momentum(&self) -> [f64; 2] {
        let (_, j) = self.fluid.mass_momentum();
        let mut p = self.units.momentum_to_si(j).map(|x| x * self.depth);
        let b = &self.sys.bodies;
        for k in 0..b.len() {
            p[0] += b.mass[k] * b.vel[k].x;
            p[1] += b.mass[k] * b.vel[k].y;
        }
        p
    }

    /// The state to checkpoint (see [`CoupledState`]).
    pub fn state(&self) -> CoupledState<T> {
        CoupledState {
            sys: self.sys.clone(),
            hydro: self.hydro.clone(),
            user_force: self.user_force.clone(),
            user_torque: self.user_torque.clone(),
            previous: self.previous.clone(),
            fluid: self.fluid.state(),
            mapped: self.fluid.mapped_circles(),
            membrane_previous: self
                .confine
                .as_ref()
                .map(|c| c.previous().to_vec())
                .unwrap_or_default(),
            membrane_shown: self
                .confine
                .as_ref()
                .map(|c| c.shown().to_vec())
                .unwrap_or_default(),
            ratio: Some(self.units.ratio),
            lbm_steps: Some(self.lbm_steps),
        }
    }

    /// Continue from `state` in a run built with the same configuration. The DEM scratch starts
    /// afresh (the DEM resumes bit for bit from its `System` alone).
    pub fn restore(&mut self, state: CoupledState<T>) -> Result<(), CouplingError> {
        let n = state.sys.bodies.len();
        if state.hydro.len() != n || state.user_force.len() != n || state.user_torque.len() != n {
            return Err(CouplingError::Unsupported(format!(
                "coupled checkpoint with {n} bodies but {} loads and {} driver forces: the file is \
                 inconsistent; write it again",
                state.hydro.len(),
                state.user_force.len()
            )));
        }
        state.sys.check_state().map_err(|why| {
            CouplingError::Unsupported(format!("coupled checkpoint: the grains are inconsistent: {why}"))
        })?;
        if state.ratio == Some(0) {
            return Err(CouplingError::Unsupported(
                "coupled checkpoint with 0 DEM steps per LBM step: the file is damaged; write it again"
                    .into(),
            ));
        }
        self.fluid.restore(state.fluid)?;
        self.fluid.restore_mapped(state.mapped, state.sys.domain.periodic);
        self.sys = state.sys;
        self.hydro = state.hydro;
        self.user_force = state.user_force;
        self.user_torque = state.user_torque;
        self.previous = state.previous;
        if let Some(c) = &mut self.confine {
            c.set_previous(state.membrane_previous);
            c.set_shown(state.membrane_shown);
        }
        self.dry.resize(n, false);
        // The masses in `sys` are those of the checkpoint's ratio already.
        if let Some(r) = state.ratio {
            self.set_step(r);
        }
        self.lbm_steps = state
            .lbm_steps
            .unwrap_or(self.sys.step / u64::from(self.units.ratio));
        self.dem = Stepper::new();
        Ok(())
    }

    /// The DEM stepper (its contact list of the last force evaluation).
    pub fn dem_stepper(&self) -> &Stepper {
        &self.dem
    }

    /// Number of DEM contacts at the last force evaluation.
    pub fn n_contacts(&self) -> usize {
        self.dem.n_contacts()
    }
}
