//! Grains in a liquid: LBM-DEM by partially saturated cells (Su et al. 2020 Fig. 2, Eqs. 9-14)
//! or moving bounce-back (Leonardi et al. 2014 Eqs. 19-21), one LBM step and its DEM sub-steps
//! per loop step. The series holds the grains' state, the liquid's mean speed and Mach number,
//! the pressure change Δp of Eq. 19 on the liquid nodes (min, max, mean, area below the
//! threshold), the hydrodynamic force
//! and the total momentum.

use super::contact_list;
use super::dry::{grain_columns, grain_sample};
use super::mass_control::MassControl;
use super::packed_zone::{self, PackedZone};
use super::shear_cell::{self, Origin, Tracked};
use crate::scenes::build::dem::wall_anchor;
use crate::scenes::build::lattice::{LatticeSetup, setup};
use crate::scenes::schema::Scene;
use crate::scenes::snapshot::{FluidFields, write_fluid, write_particles};
use crate::scenes::timeloop::{Model, Probe};
use anyhow::{Context, Result, bail};
use lbdem_core::units::coupled::{
    LOAD_DENSITY_MAX, PSM_DENSITY_RATIO_MIN, PSM_DENSITY_RATIO_WARN, buoyant_load,
};
use lbdem_coupling::MembraneBoundary;
use lbdem_coupling::bounce::BounceFluid;
use lbdem_coupling::units::CouplingUnits;
use lbdem_coupling::{Coupled, Hydro, Method, PsmFluid, PsmSettings};
use lbdem_dem::Vec2;
use lbdem_lbm::lattice::CS2;
use lbdem_lbm::{Collision, Domain, Limits, Real};
use std::path::{Path, PathBuf};

/// Build the model of a coupled scene.
/// The model of a coupled scene in f64, whatever its `precision` (benchmarks reach into it).
pub fn build_f64(s: &Scene, base: &Path) -> Result<CoupledModel<f64>> {
    CoupledModel::<f64>::new(s, setup(s)?, base)
}

pub fn build(s: &Scene, base: &Path) -> Result<Box<dyn Model>> {
    let su = setup(s)?;
    match su.precision.as_str() {
        "f32" => Ok(Box::new(CoupledModel::<f32>::new(s, su, base)?)),
        _ => Ok(Box::new(CoupledModel::<f64>::new(s, su, base)?)),
    }
}

pub struct CoupledModel<T: Real> {
    pub run: Coupled<T>,
    su: LatticeSetup,
    threshold: f64,
    wall_start: Vec<Vec2>,
    pool: rayon::ThreadPool,
    /// The push-plate cell of `[shear_cell]`.
    cell: Option<Tracked>,
    /// The packed layer of `[packed_zone]`.
    zone: Option<PackedZone>,
    /// The mass scale that follows the inertial number (`[dem.mass_scale_control]`).
    mass_control: Option<MassControl>,
    /// Liquid mass at the start (kg; the liquid inside the sample when it is confined).
    liquid_mass0: f64,
    /// ρ_0 of Su Eq. 19 (lattice units): 1 at the start, the liquid nodes' mean density when
    /// the plate starts after `[shear_cell] settle`.
    rho0: f64,
    /// What the checks before the start warned of, repeated in the summary's `warnings`.
    start_warnings: Vec<String>,
}

/// A node is liquid, for Δp (Su Eq. 19, Fig. 10's "interstitial liquid") and the cracking
/// criterion, when less than half its cell is solid. Nodes inside grains relax towards the
/// grains' velocity (Eq. 11) and their density follows the grains' motion, not the liquid's
/// pressure: in the 93 %PK 30 µm/s run the lowest Δp of every snapshot sat on single nodes
/// wholly inside membrane grains (docs/su2020.md, "The cracking criterion on liquid nodes").
pub const LIQUID_NODE_SOLID_MAX: f64 = 0.5;

/// Mean of the finite values, in order (None without any).
fn finite_mean(values: impl Iterator<Item = f64>) -> Option<f64> {
    let (sum, n) = values
        .filter(|v| v.is_finite())
        .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    (n > 0).then(|| sum / n as f64)
}

/// Series columns of the liquid's mass (kg): what the lattice holds, its drift from the start
/// (relative), and what the moving solid zone closed and opened.
const MASS_COLUMNS: [&str; 4] = [
    "liquid_mass",
    "liquid_mass_drift",
    "liquid_mass_closed",
    "liquid_mass_opened",
];

impl<T: Real> CoupledModel<T> {
    fn new(s: &Scene, su: LatticeSetup, base: &Path) -> Result<Self> {
        let cs = s.coupling.clone().unwrap_or_default();
        let dem = s.dem.as_ref().context("[dem] is required")?;
        if s.lattice.as_ref().is_some_and(|l| l.dt.is_none()) {
            bail!("[lattice]: a coupled scene gives dt (a whole multiple of [dem] dt, Su Table 3), not tau");
        }
        if !(cs.depth > 0.0 && cs.depth.is_finite()) {
            bail!(
                "[coupling] depth = {}: must be a positive length in m (the sample depth, default 1)",
                cs.depth
            );
        }
        let confined_plate = s
            .shear_cell
            .as_ref()
            .filter(|c| c.confine_liquid)
            .map(|c| crate::scenes::run::wall_index(s, &c.plate))
            .transpose()?;
        let mut dem_wall = 0;
        for (k, w) in s.walls.iter().enumerate() {
            let here = dem_wall;
            dem_wall += if w.box_.is_some() { 4 } else { 1 };
            if w.velocity.is_some() && confined_plate != Some(here) {
                bail!(
                    "[[walls]] #{k}: a moving wall is seen by the liquid only as the push-plate of a \
                     confined sample ([shear_cell] plate, confine_liquid = true); remove the velocity, \
                     make it the plate, or use a scene without [fluid]"
                );
            }
        }
        if su.dim != 2 {
            bail!("a coupled scene is 2D (D2Q9); give [domain] lo and hi with 2 numbers");
        }
        for w in &su.units.warnings {
            eprintln!("coupled: warning: {w}");
        }
        let units = CouplingUnits::new(su.units.clone(), s.domain.lo2(), dem.dt)
            .map_err(|e| anyhow::anyhow!("[lattice] dt and [dem] dt: {e}"))?;
        let density = s.particles.as_ref().map_or(0.0, |p| p.density);
        let fluid_density = s.fluid.as_ref().map_or(0.0, |f| f.density);
        let ratio = 1.0 - fluid_density * cs.depth / density;
        if (dem.gravity_factor - ratio).abs() > 1e-3 * ratio.abs().max(1e-3) && dem.gravity != [0.0; 2] {
            eprintln!(
                "coupled: note: [dem] gravity_factor = {} but 1 - rho_L depth / density = {ratio:.4}; \
                 the buoyancy of Su et al. Sect. 2.4 uses the latter",
                dem.gravity_factor
            );
        }
        let sys = super::grains(s, base)?;
        pressure_load(s, &sys, &units, cs.depth)?;
        let [nx, ny, _] = su.n;
        let domain = Domain::new(su.n, su.faces);
        let tau = su.units.tau;
        let limits = Limits::default();
        let trt = match su.collision {
            Collision::Trt { magic, .. } => Some(magic),
            Collision::Bgk { .. } => None,
        };
        let mut hydro = match cs.method {
            Method::Psm => {
                let fluid = PsmFluid::<T>::new(
                    &domain,
                    PsmSettings {
                        collision: su.collision,
                        force: [su.force[0], su.force[1]],
                        limits,
                    },
                )
                .map_err(|e| anyhow::anyhow!("[lattice] collision / magic: {e}"))?;
                Hydro::psm(fluid)
            }
            Method::BounceBack => {
                if trt.is_some() {
                    bail!(
                        "[lattice] collision = \"trt\" is for [coupling] method = \"psm\" only; use collision = \"bgk\""
                    );
                }
                if cs.interior_liquid_correction {
                    bail!("[coupling] interior_liquid_correction is for method = \"psm\" only; remove it");
                }
                Hydro::BounceBack(Box::new(BounceFluid::<T>::new(
                    domain,
                    tau,
                    [su.force[0], su.force[1]],
                    limits,
                )?))
            }
        };
        let law = s.contact.clone().context("[contact] is required")?;
        let wall_law = s.wall_contact.clone().unwrap_or_else(|| law.clone());
        lbdem_dem::Stepper::check_step(&sys, &law, &wall_law, dem.dt).map_err(|e| {
            anyhow::anyhow!("[dem] dt: {e} (lower [lattice] dt with it, keeping a whole ratio)")
        })?;
        hydro
            .set_remap_tolerance(cs.remap_tolerance)
            .map_err(|e| anyhow::anyhow!("coupled scene: {e}"))?;
        let mut run = Coupled::new(hydro, sys, law, wall_law, dem.step_params(), units, cs.r_hd)
            .map_err(|e| anyhow::anyhow!("coupled scene: {e}"))?;
        run.depth = cs.depth;
        if cs.dry_membrane {
            for k in 0..run.sys.bodies.len() {
                run.dry[k] = run.sys.bodies.tag[k] == 1;
            }
        }
        let mass_control = match &dem.mass_scale_control {
            None => None,
            Some(c) => {
                if s.shear_cell.is_none() {
                    bail!(
                        "[dem.mass_scale_control] follows the inertial number of a shear cell (Su Eq. 20), which \
                         needs [shear_cell]; remove the control or add the cell"
                    );
                }
                Some(MassControl::new(c, dem.mass_scale, run.units.ratio)?)
            }
        };
        // The lightest grains the run may reach: the bottom of the ladder.
        let lightest = mass_control
            .as_ref()
            .map_or(dem.mass_scale, MassControl::smallest_scale);
        if cs.method == Method::Psm {
            light_grains(&run, s, lightest)?;
        }
        if cs.interior_liquid_correction {
            run = run
                .with_interior_liquid_correction()
                .map_err(|e| anyhow::anyhow!("[coupling] interior_liquid_correction = true: {e}"))?;
        }
        if !crate::contract::quiet() {
            eprintln!(
                "coupled: {} grains, lattice {nx} x {ny} (dx = {:e} m, tau = {tau:.4}), LBM dt = {:e} s, \
             DEM dt = {:e} s, ratio {}, {:?}, {}, SIMD {}",
                run.sys.bodies.len(),
                run.units.dx(),
                run.units.dt(),
                run.units.dt_dem,
                run.units.ratio,
                cs.method,
                T::NAME,
                lbdem_core::simd::level().name()
            );
        }
        // `threads = 0` takes the pool the model is built in (`scenes::run::run`'s: all cores
        // alone, a lane's or a sweep case's share beside others), not every core.
        let threads = match s.run.threads {
            0 => rayon::current_num_threads(),
            n => n,
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .context("cannot start the thread pool")?;
        // A resumed run takes the plate, the origin and the wall starts from its checkpoint.
        shear_cell::clear_plate_noting(s, &mut run.sys)?;
        let dt = run.units.dt();
        let cell = Tracked::start(s, &mut run.sys, dt)?;
        let mut start_warnings = Vec::new();
        if let (Some(c), Some(sc)) = (&cell, &s.shear_cell)
            && sc.confine_liquid
        {
            if sc.membrane_boundary == MembraneBoundary::Moving {
                damped_membrane(s)?;
                start_warnings.extend(light_membrane(&run, s, lightest));
            }
            run = run
                .with_confinement(vec![c.cell.plate], sc.membrane_boundary)
                .and_then(|r| r.with_membrane_relaxation(sc.membrane_relaxation))
                .map_err(|e| anyhow::anyhow!("[shear_cell] confine_liquid = true: {e}"))?;
        }
        let wall_start = run.sys.walls.iter().map(wall_anchor).collect();
        let mut m = Self {
            run,
            su,
            threshold: s.output.pressure_threshold,
            wall_start,
            pool,
            cell,
            zone: PackedZone::new(s)?,
            mass_control,
            liquid_mass0: 0.0,
            rho0: 1.0,
            start_warnings,
        };
        if !crate::contract::quiet() {
            for w in &m.start_warnings {
                eprintln!("coupled: warning: {w}");
            }
        }
        m.liquid_mass0 = m.liquid_mass();
        Ok(m)
    }

    /// Δp = (ρ − ρ_0) c_s² of every node (Pa, Su Eq. 19); NaN off the liquid nodes
    /// ([`LIQUID_NODE_SOLID_MAX`]).
    pub fn pressure_change(&self) -> Vec<f64> {
        let [nx, ny] = self.run.fluid.size();
        (0..nx * ny)
            .map(|i| match self.liquid_density(i) {
                Some(rho) => self.run.units.pressure_to_si((rho - self.rho0) * CS2),
                None => f64::NAN,
            })
            .collect()
    }

    /// The density of node `i` if it is a liquid node ([`LIQUID_NODE_SOLID_MAX`]).
    fn liquid_density(&self, i: usize) -> Option<f64> {
        let rho = self.run.fluid.node(i).0;
        let solid = match &self.run.fluid {
            Hydro::Psm { map, .. } => map.total.get(i).copied().unwrap_or(0.0),
            Hydro::BounceBack(_) => 0.0,
        };
        (rho.is_finite() && solid < LIQUID_NODE_SOLID_MAX).then_some(rho)
    }

    /// The liquid nodes' mean density (lattice units), 1 without any.
    fn mean_liquid_density(&self) -> f64 {
        let [nx, ny] = self.run.fluid.size();
        finite_mean((0..nx * ny).filter_map(|i| self.liquid_density(i))).unwrap_or(1.0)
    }

    /// Position (m) of the liquid node with the lowest Δp (the first of equals), NaN without liquid.
    fn dp_min_site(&self, dp: &[f64]) -> [f64; 2] {
        let nx = self.su.n[0].max(1);
        let dx = self.run.units.dx();
        dp.iter()
            .enumerate()
            .filter(|(_, p)| p.is_finite())
            .min_by(|a, b| a.1.total_cmp(b.1).then(a.0.cmp(&b.0)))
            .map_or([f64::NAN; 2], |(k, _)| {
                [
                    self.su.lo[0] + ((k % nx) as f64 + 0.5) * dx,
                    self.su.lo[1] + ((k / nx) as f64 + 0.5) * dx,
                ]
            })
    }

    /// Mean liquid speed over the active nodes (m/s) and the largest speed in lattice units
    /// (for the Mach number, Su Eq. 16).
    fn liquid_speeds(&self) -> (f64, f64) {
        let run = &self.run;
        let [nx, ny] = run.fluid.size();
        let vscale = run.units.dx() / run.units.dt();
        let (mut speed_sum, mut n_active, mut max_u) = (0.0, 0usize, 0.0f64);
        for i in 0..nx * ny {
            let (rho, v) = run.fluid.node(i);
            if rho.is_finite() {
                let s = (v[0] * v[0] + v[1] * v[1]).sqrt();
                speed_sum += s;
                max_u = max_u.max(s);
                n_active += 1;
            }
        }
        (speed_sum / n_active.max(1) as f64 * vscale, max_u)
    }

    /// The push-plate cell, if the scene has `[shear_cell]`.
    pub fn shear_cell(&self) -> Option<&Tracked> {
        self.cell.as_ref()
    }

    /// Mass of the liquid the lattice holds (kg, over the sample's depth).
    fn liquid_mass(&self) -> f64 {
        self.lattice_mass_to_si(self.run.fluid.mass_momentum().0)
    }

    fn lattice_mass_to_si(&self, m: f64) -> f64 {
        let u = &self.run.units;
        m * u.lattice.rho * u.dx() * u.dx() * self.run.depth
    }

    pub fn lattice_size(&self) -> [usize; 2] {
        [self.su.n[0], self.su.n[1]]
    }
}

impl<T: Real> Model for CoupledModel<T> {
    fn step(&mut self, _fields: bool) -> Result<()> {
        // While the plate is held the ladder may stand on its own rung (`held = "smallest"`);
        // decided from the step count alone, so a resumed run does the same.
        if let (Some(mc), Some(c)) = (&self.mass_control, &self.cell)
            && let Some(r) = mc.held_ratio()
            && c.settling(self.run.lbm_steps())
        {
            self.run
                .set_ratio(r)
                .map_err(|e| anyhow::anyhow!("[dem.mass_scale_control] held: {e}"))?;
        }
        let run = &mut self.run;
        self.pool
            .install(|| run.step())
            .map_err(|e| anyhow::anyhow!("coupled scene: {e}"))?;
        let steps = self.steps_done();
        if let Some(c) = &mut self.cell {
            // Su's liquid is at rest at ρ_0 when the deformation starts (Sect. 2.4 relaxes the
            // assembly first): Δp counts from the settled liquid's mean, not from the density
            // the settling left (the whole 84 %PK sample −0.11 Pa after 1 s; docs/su2020.md).
            if c.after_step(&mut self.run.sys, steps) {
                self.rho0 = self.mean_liquid_density();
            }
        }
        // The shear's inertial number: none while the plate is held (the settling keeps the
        // scene's scale, or the bottom rung with `held = "smallest"`).
        if let (Some(mc), Some(c)) = (&self.mass_control, &self.cell)
            && steps.is_multiple_of(mc.every)
            && !c.settling(steps)
        {
            let i = c.cell.inertial_now(&self.run.sys, self.run.dem_stepper());
            let r = mc.choose(self.run.units.ratio, i);
            self.run
                .set_ratio(r)
                .map_err(|e| anyhow::anyhow!("[dem.mass_scale_control]: {e}"))?;
        }
        Ok(())
    }
    fn steps_done(&self) -> u64 {
        self.run.lbm_steps()
    }
    fn time(&self) -> f64 {
        self.steps_done() as f64 * self.run.units.dt()
    }
    fn dt(&self) -> f64 {
        self.run.units.dt()
    }
    fn series_columns(&self) -> Vec<String> {
        let mut c = grain_columns(self.run.sys.walls.len());
        c.extend(
            [
                "mean_liquid_speed",
                "max_mach",
                "dp_min",
                "dp_max",
                "dp_mean",
                "area_below_threshold",
                "hydro_fx",
                "hydro_fy",
                "momentum_x",
                "momentum_y",
            ]
            .map(String::from),
        );
        c.extend(MASS_COLUMNS.map(String::from));
        // Where Δp_min sits (m): the cracking site of Su Sect. 3.5 (issue 14's analysis).
        c.extend(["dp_min_x", "dp_min_y"].map(String::from));
        if self.cell.is_some() {
            c.extend(shear_cell::COLUMNS.map(String::from));
        }
        if self.zone.is_some() {
            c.extend(packed_zone::COLUMNS.map(String::from));
        }
        if self.mass_control.is_some() {
            c.extend(["dem_steps_per_lbm_step", "mass_scale"].map(String::from));
        }
        c
    }
    fn sample(&self) -> Vec<f64> {
        let run = &self.run;
        let u = &run.units;
        let (mean_speed, max_u) = self.liquid_speeds();
        let dp = self.pressure_change();
        let (lo, hi) = crate::report::plot::finite_range(dp.iter().copied()).unwrap_or((0.0, 0.0));
        let below = dp.iter().filter(|&&p| p < self.threshold).count() as f64 * u.dx() * u.dx();
        let mean_dp = finite_mean(dp.iter().copied()).unwrap_or(f64::NAN);
        let hydro = run
            .hydro
            .iter()
            .fold([0.0; 2], |a, l| [a[0] + l.force[0], a[1] + l.force[1]]);
        let mom = run.momentum();
        let mut v = grain_sample(&run.sys, run.dem_stepper());
        v.extend([
            mean_speed,
            max_u * 3f64.sqrt(),
            lo,
            hi,
            mean_dp,
            below,
            hydro[0],
            hydro[1],
            mom[0],
            mom[1],
        ]);
        let m = self.liquid_mass();
        let zm = run.fluid.zone_mass();
        v.extend([
            m,
            m / self.liquid_mass0 - 1.0,
            self.lattice_mass_to_si(zm.removed),
            self.lattice_mass_to_si(zm.added),
        ]);
        v.extend(self.dp_min_site(&dp));
        if let Some(c) = &self.cell {
            v.extend(c.sample(&run.sys, run.dem_stepper(), self.steps_done()));
        }
        if let Some(z) = &self.zone {
            v.extend(z.sample(&run.sys));
        }
        if let Some(mc) = &self.mass_control {
            v.extend([f64::from(u.ratio), mc.scale(u.ratio)]);
        }
        v
    }
    fn grain_centroids(&self) -> Option<Vec<[f64; 2]>> {
        Some(super::centroids(&self.run.sys))
    }
    fn max_grain_displacement(&self, then: &[[f64; 2]]) -> Option<f64> {
        super::max_displacement(&self.run.sys, then)
    }
    fn probe(&self, q: Probe) -> Option<f64> {
        match q {
            Probe::MaxGrainSpeed => Some(self.run.sys.bodies.max_speed()),
            Probe::WallDisplacement(k) => shear_cell::wall_displacement(
                &self.run.sys,
                &self.wall_start,
                self.cell.as_ref(),
                k,
                self.steps_done(),
            ),
            Probe::MeanLiquidSpeed => Some(self.liquid_speeds().0),
            Probe::SteadySince | Probe::RigidShare => None,
        }
    }
    fn snapshot(&self, dir: &Path) -> Result<Vec<(&'static str, PathBuf)>> {
        let run = &self.run;
        let [nx, ny] = run.fluid.size();
        let u = &run.units;
        let vscale = u.dx() / u.dt();
        let mut velocity = Vec::with_capacity(3 * nx * ny);
        for i in 0..nx * ny {
            let (rho, v) = run.fluid.node(i);
            if rho.is_finite() {
                velocity.extend([v[0] * vscale, v[1] * vscale, 0.0]);
            } else {
                velocity.extend([f64::NAN; 3]);
            }
        }
        let solid = match &run.fluid {
            Hydro::Psm { map, .. } => map.total.clone(),
            Hydro::BounceBack(b) => b.fluid.domain.kind.iter().map(|&k| f64::from(k != 0)).collect(),
        };
        let f = FluidFields {
            n: self.su.n,
            lo: self.su.lo,
            dx: u.dx(),
            velocity,
            pressure: self.pressure_change(),
            solid_fraction: Some(solid),
            node_kind: None,
        };
        let mut out = write_fluid(dir, self.steps_done(), &f)?;
        // The particle files carry the LBM step in their name too, so one step's files sort together.
        out.extend(write_particles(
            dir,
            self.steps_done(),
            &run.sys,
            &contact_list(run.dem_stepper(), &run.sys),
        )?);
        Ok(out)
    }
    fn progress_note(&self) -> Option<String> {
        self.cell
            .as_ref()
            .map(|c| c.note(&self.run.sys, self.steps_done()))
    }
    fn warnings(&self) -> Vec<String> {
        let Some(c) = &self.cell else {
            return self.start_warnings.clone();
        };
        let mut w = self.start_warnings.clone();
        w.extend(c.warnings(&self.run.sys, self.dt()));
        // The liquid ends at the lattice's faces: a membrane pushed beyond them confines its
        // liquid there, not along itself (the 95 %PK sample settling to rest reached x = 8.6 mm
        // of a lattice ending at 8.5 mm).
        let dx = self.run.units.dx();
        let hi = [
            self.su.lo[0] + self.su.n[0] as f64 * dx,
            self.su.lo[1] + self.su.n[1] as f64 * dx,
        ];
        let out = shear_cell::ShearCell::membrane_outside(&self.run.sys, [self.su.lo[0], self.su.lo[1]], hi);
        if out > 0 {
            w.push(format!(
                "[shear_cell]: {out} membrane grain(s) lie outside the lattice [{:.3e}, {:.3e}] x [{:.3e}, {:.3e}] m \
                 at the end: the liquid there is confined by the lattice's faces, not by the membrane; \
                 widen [domain]",
                self.su.lo[0], hi[0], self.su.lo[1], hi[1]
            ));
        }
        w
    }
    fn describe(&self) -> serde_json::Value {
        let tm = self.run.timing;
        let total = (tm.lbm + tm.dem + tm.coupling).as_secs_f64().max(1e-12);
        serde_json::json!({
            "dem_steps_per_lbm_step": self.run.units.ratio, "grains": self.run.sys.bodies.len(),
            "lattice": self.lattice_size(), "dx": self.run.units.dx(), "tau": self.su.units.tau, "method": self.run.fluid.method(),
            "precision": T::NAME, "collision": self.su.collision,
            "time_share": { "lbm": tm.lbm.as_secs_f64() / total, "dem": tm.dem.as_secs_f64() / total,
                            "coupling": tm.coupling.as_secs_f64() / total },
        })
    }
    fn save(&self) -> Result<serde_json::Value> {
        Ok(
            serde_json::json!({ "run": self.run.state(), "wall_start": self.wall_start,
                               "cell": self.cell.as_ref().map(Tracked::origin),
                               "liquid_mass0": self.liquid_mass0, "rho0": self.rho0 }),
        )
    }
    fn restore(&mut self, state: serde_json::Value) -> Result<()> {
        #[derive(serde::Deserialize)]
        #[serde(bound = "")]
        struct S<T: Real> {
            run: lbdem_coupling::driver::CoupledState<T>,
            wall_start: Vec<Vec2>,
            #[serde(default)]
            cell: Option<Origin>,
            liquid_mass0: f64,
            #[serde(default = "one")]
            rho0: f64,
        }
        fn one() -> f64 {
            1.0
        }
        let s: S<T> = serde_json::from_value(state)?;
        self.run.restore(s.run)?;
        self.wall_start = s.wall_start;
        self.liquid_mass0 = s.liquid_mass0;
        self.rho0 = s.rho0;
        if let (Some(c), Some(o)) = (&mut self.cell, s.cell) {
            c.set_origin(o);
        }
        Ok(())
    }
}

/// Least damping ratio of the membrane's bonds (`[bonds] params.damping`) with which the moving
/// membrane boundary runs. Undamped, membrane grains ring on their bonds, their velocity flipping
/// sign every LBM step, driven by the liquid that answers their motion a step late (the velocity
/// shown is last cycle's mean, under-relaxed), until the lattice blows up (docs/su2020.md, "The
/// membrane's bonds must be damped"). On the reduced cell's six random
/// assemblies at the paper's membrane mass and two LBM steps: ζ = 0.05 blew up in 6 of 12, 0.1
/// ran all 12 but reached Mach 0.21, 0.2 ran all 12 below Mach 0.06 (and all 12 with the membrane
/// three times heavier, below 0.03). Undamped, even a membrane 2.7 times the liquid's density
/// blew up in all six at the halved LBM step.
pub const MOVING_MEMBRANE_BOND_DAMPING_MIN: f64 = 0.2;

/// Refuse a membrane that shows the liquid its velocity if its bonds are not damped enough to
/// stop it ringing ([`MOVING_MEMBRANE_BOND_DAMPING_MIN`]).
fn damped_membrane(s: &Scene) -> Result<()> {
    let Some(b) = &s.bonds else {
        return Ok(());
    };
    let zeta = b.params.damping;
    if zeta < MOVING_MEMBRANE_BOND_DAMPING_MIN {
        bail!(
            "[shear_cell] membrane_boundary = \"moving\": the membrane's bonds have damping ratio {zeta} \
             ([bonds] params.damping); an undamped membrane rings on its bonds and the liquid, answering \
             a step late, drives the ringing until the lattice blows up (docs/su2020.md). Set [bonds] \
             params.damping to at least {MOVING_MEMBRANE_BOND_DAMPING_MIN}, or membrane_boundary = \"at_rest\""
        );
    }
    Ok(())
}

/// Lightest membrane grain, against the liquid's density, below which a moving membrane boundary
/// is warned before the run starts. Simulation I at Table 1's masses (bonds damped at ζ = 0.2)
/// with the membrane grains 0.90, 1.08, 1.35, 1.80 and 2.7 times the liquid's density
/// (`sweeps/su2020-membrane-mass.toml`): quiet to u_y = 2 d̄ in every run; then the lighter three
/// rang with the liquid, from 2.08, 2.23 and about 2.9 d̄ (1.35 blowing up at LBM step 16 910),
/// while at 1.80 the disturbance near 2.9 d̄ died out (Mach 0.0017, back to 0.0009; quiet to
/// 4.33 d̄) and at 2.7 the run stayed quiet to 6.26 d̄ (docs/stability.md, "Damped membrane
/// bonds"). The edge lies between 1.35 and 1.80; the limit is the lowest ratio that held. Short
/// runs at 0.90 (the reduced cell's 0.4 s) were accurate, so this warns, as the density map's
/// inaccurate band does, rather than refuses.
pub const MOVING_MEMBRANE_DENSITY_RATIO_WARN: f64 = 1.8;

/// The warning of [`MOVING_MEMBRANE_DENSITY_RATIO_WARN`], if the lightest membrane grain (at the
/// mass scale `scale`, the bottom of a mass-scale ladder if there is one) is under it.
fn light_membrane<T: Real>(run: &Coupled<T>, s: &Scene, scale: f64) -> Option<String> {
    let at = s.dem.as_ref().map_or(1.0, |d| d.mass_scale);
    let density = &run.sys.bodies.density;
    let membrane = run.sys.membrane.as_ref()?;
    // as `light_grains` reads `lightest_wet_density`: per area over the depth, at `scale`
    let lightest = membrane
        .bodies
        .iter()
        .map(|&k| density[k as usize])
        .fold(f64::INFINITY, f64::min);
    let ratio = lightest / run.depth * scale / at / run.liquid_density();
    if ratio >= MOVING_MEMBRANE_DENSITY_RATIO_WARN {
        return None;
    }
    let ladder = s.dem.as_ref().and_then(|d| d.mass_scale_control.as_ref());
    let at_key = match ladder {
        Some(c) if scale != at => format!(
            "[dem.mass_scale_control] smallest = {}, if the run goes down to it,",
            c.smallest
        ),
        _ => format!("[dem] mass_scale = {at}"),
    };
    let factor = s.membrane.as_ref().map_or(1.0, |m| m.mass_scale);
    let need = factor * MOVING_MEMBRANE_DENSITY_RATIO_WARN / ratio;
    Some(format!(
        "[shear_cell] membrane_boundary = \"moving\": {at_key} makes the membrane grains {ratio:.3} times the \
         liquid's density; Simulation I at Table 1's masses with membranes 0.90-1.35 times it ran quietly to \
         u_y = 2 d, then rang with the liquid (at 1.35 it blew up near 2.9 d), at 1.80 and 2.7 it did not \
         (docs/stability.md, \"Damped membrane bonds\"). A run past 2 d needs [membrane] mass_scale = \
         {need:.2} or more (the membrane is confinement, not sample: at 2 times Table 1's mass it moved \
         eps_vol^DEM by 0.0005-0.0008)"
    ))
}

/// Refuse a PSM scene whose lightest wet grain is under [`PSM_DENSITY_RATIO_MIN`] times the
/// liquid's density (its inertia, mass scaling included): the explicit coupling blows up there
/// (docs/stability.md, "Near-neutral grains"). Warn below [`PSM_DENSITY_RATIO_WARN`], above the
/// highest ratio at which the settling disk of the interior-liquid map blew up.
fn light_grains<T: Real>(run: &Coupled<T>, s: &Scene, scale: f64) -> Result<()> {
    let at = s.dem.as_ref().map_or(1.0, |d| d.mass_scale);
    let lightest = run.lightest_wet_density() * scale / at;
    let ratio = lightest / run.liquid_density();
    let density = s.particles.as_ref().map_or(0.0, |p| p.density);
    // The scale checked is the bottom of a mass-scale ladder when there is one.
    let key = if scale == at {
        "[dem] mass_scale"
    } else {
        "[dem.mass_scale_control] smallest"
    };
    if ratio < PSM_DENSITY_RATIO_MIN {
        let need = scale * 1.1 * PSM_DENSITY_RATIO_MIN / ratio;
        bail!(
            "[particles] density = {density} kg/m² with {key} = {scale} over [coupling] depth = {} m \
             makes the lightest wet grain {lightest:.1} kg/m³, {ratio:.3} times the liquid's {} kg/m³; below \
             {PSM_DENSITY_RATIO_MIN} the explicit PSM coupling blows up (the reduced shear cell did at 0.45, \
             docs/stability.md). Raise {key} to at least {need:.3} (a quasi-static run allows it) \
             or the grains' density",
            run.depth,
            run.liquid_density()
        );
    }
    if ratio < PSM_DENSITY_RATIO_WARN && !crate::contract::quiet() {
        eprintln!(
            "coupled: warning: the lightest wet grain is {ratio:.3} times the liquid's density; the reduced \
             shear cell ran from 0.56 (accurate from 0.68), but a disk settling in open liquid blew up up to \
             0.8 and ran from 0.9 (docs/stability.md, \"Near-neutral grains\"): raise {key} to \
             {:.3} or more if the run is quasi-static",
            scale * PSM_DENSITY_RATIO_WARN / ratio
        );
    }
    Ok(())
}

/// Refuse a scene whose grains' buoyant weight the lattice cannot carry: the pressure difference
/// [`buoyant_load`] as a density change at this step's pressure unit c_s² ρ_L (dx/δt)² must stay
/// below [`LOAD_DENSITY_MAX`] (the full Float case at Table 3's δt needs 2.2 and stops at LBM step
/// 94; docs/stability.md). The load goes with δt², so the fix is a smaller `[lattice] dt`.
fn pressure_load(s: &Scene, sys: &lbdem_dem::System, units: &CouplingUnits, depth: f64) -> Result<()> {
    let Some(dem) = &s.dem else { return Ok(()) };
    let accel = [
        dem.gravity[0] * dem.gravity_factor,
        dem.gravity[1] * dem.gravity_factor,
    ];
    // the real masses: mass scaling (a quasi-static device) does not change what the liquid carries
    let mass = sys.bodies.mass.iter().sum::<f64>() / dem.mass_scale;
    let size = [s.domain.size(0), s.domain.size(1)];
    let load = buoyant_load(mass, accel, size, depth);
    let drho = units.lattice.pressure_to_density(load);
    if drho > LOAD_DENSITY_MAX {
        // Δρ ∝ δt²: the largest whole multiple of the DEM step that brings it to a fifth of the limit
        let fix = units.dt() * (0.2 * LOAD_DENSITY_MAX / drho).sqrt();
        let fix = (fix / units.dt_dem).floor().max(1.0) * units.dt_dem;
        bail!(
            "[lattice] dt = {:e} s: the grains' buoyant weight needs the liquid to carry a pressure difference \
             of about {load:.3} Pa (|rho_S - rho_L| g x solid fraction x packing height), a density change \
             of {drho:.2} at this step's pressure unit c_s^2 rho_L (dx/dt)^2 = {:.3} Pa; above {LOAD_DENSITY_MAX} \
             the lattice cannot carry it (the run would stop on a density below 0.5, docs/stability.md). \
             Lower [lattice] dt, e.g. to {fix:e} s (a whole multiple of [dem] dt; the change goes with dt^2)",
            units.dt(),
            units.lattice.density_to_pressure(2.0),
        );
    }
    if drho > 0.2 * LOAD_DENSITY_MAX {
        eprintln!(
            "coupled: warning: the grains' buoyant weight ({load:.3} Pa) is a density change of {drho:.2} at \
             [lattice] dt = {:e} s; the Float case's grains move up to 1.5 times faster at 0.2 than at 0.09 \
             (docs/stability.md): lower dt for a converged answer",
            units.dt()
        );
    }
    Ok(())
}
