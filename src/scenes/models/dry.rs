//! Grains only: the DEM system of the scene stepped by `lbdem_dem::Stepper` (one DEM step per
//! loop step), after the optional `[compress]` preparation (Su et al. 2020 Sect. 2.4).

use super::contact_list;
use super::packed_zone::{self, PackedZone};
use super::shear_cell::{self, Origin, Tracked};
use crate::scenes::build::dem::wall_anchor;
use crate::scenes::schema::Scene;
use crate::scenes::snapshot::write_particles;
use crate::scenes::timeloop::{Model, Probe};
use anyhow::{Context, Result};
use lbdem_dem::{Law, StepParams, Stepper, System, Vec2};
use std::path::{Path, PathBuf};

pub struct Dry {
    pub sys: System,
    stepper: Stepper,
    law: Law,
    wall_law: Law,
    params: StepParams,
    /// Where each wall started (the displacement stop condition).
    wall_start: Vec<Vec2>,
    pub critical_dt: f64,
    /// The push-plate cell of `[shear_cell]`.
    pub cell: Option<Tracked>,
    /// The packed layer of `[packed_zone]`.
    zone: Option<PackedZone>,
}

impl Dry {
    /// Build from the scene; `prepare` runs the `[compress]` preparation (not on resume: the
    /// checkpoint holds the prepared state).
    pub fn build(s: &Scene, base: &Path, prepare: bool) -> Result<Self> {
        let mut sys = super::grains(s, base)?;
        let law = s.contact.clone().context("[contact] is required")?;
        let wall_law = s.wall_contact.clone().unwrap_or_else(|| law.clone());
        let dem = s.dem.as_ref().context("[dem] is required")?;
        if dem.mass_scale_control.is_some() {
            anyhow::bail!(
                "[dem.mass_scale_control] changes the DEM step with the LBM-DEM ratio of a coupled scene; a dry \
                 scene has no LBM step to keep: remove it and give [dem] mass_scale"
            );
        }
        let params = dem.step_params();
        let (crit, m_min, k_max) = Stepper::critical_time_step(&sys, &law, &wall_law);
        if !crate::contract::quiet() {
            eprintln!(
                "dem: {} bodies, dt = {:e} s, critical {crit:e} s (m_min {m_min:e} kg, k_max {k_max:e} N/m), law {}, SIMD {}",
                sys.bodies.len(),
                params.dt,
                law_name(&law),
                lbdem_core::simd::level().name()
            );
        }
        let mut stepper = Stepper::new();
        if let (Some(c), true) = (&s.compress, prepare) {
            let n = lbdem_dem::generate::compress_isotropic(
                &mut sys,
                &law,
                &wall_law,
                &params,
                &c.to_kernel(),
                &mut stepper,
            )
            .context("[compress]")?;
            if !crate::contract::quiet() {
                eprintln!(
                    "dem: isotropic compression took {n} steps, packing fraction {:.4}",
                    sys.packing_fraction()
                );
            }
            if let Some(phi) = c.target_packing {
                lbdem_dem::generate::scale_to_packing(&mut sys, phi);
            }
            sys.step = 0;
            sys.time = 0.0;
            stepper = Stepper::new();
        }
        if prepare {
            shear_cell::clear_plate_noting(s, &mut sys)?;
        }
        let wall_start = sys.walls.iter().map(wall_anchor).collect();
        let cell = Tracked::start(s, &mut sys, params.dt)?;
        Ok(Self {
            sys,
            stepper,
            law,
            wall_law,
            params,
            wall_start,
            critical_dt: crit,
            cell,
            zone: PackedZone::new(s)?,
        })
    }

    pub fn law(&self) -> &Law {
        &self.law
    }
}

pub fn law_name(l: &Law) -> &'static str {
    l.name()
}

/// Series columns of a grain system with `walls` walls.
pub fn grain_columns(walls: usize) -> Vec<String> {
    let mut c: Vec<String> = ["kinetic_energy", "packing_fraction", "contacts", "max_speed"]
        .map(String::from)
        .to_vec();
    for w in 0..walls {
        c.push(format!("wall{w}_fx"));
        c.push(format!("wall{w}_fy"));
    }
    c
}

/// Series values of a grain system (same order as [`grain_columns`]).
pub fn grain_sample(sys: &System, st: &Stepper) -> Vec<f64> {
    let mut v = vec![
        sys.bodies.kinetic_energy(),
        sys.packing_fraction(),
        st.n_contacts() as f64,
        sys.bodies.max_speed(),
    ];
    for w in &sys.walls {
        v.push(w.force.x);
        v.push(w.force.y);
    }
    v
}

impl Model for Dry {
    fn step(&mut self, _fields: bool) -> Result<()> {
        self.stepper
            .step_law(&self.params, &self.law, &self.wall_law, &mut self.sys)
            .map_err(|e| anyhow::anyhow!("{e} (set [dem] dt in the scene file)"))?;
        let steps = self.sys.step;
        if let Some(c) = &mut self.cell {
            c.after_step(&mut self.sys, steps);
        }
        Ok(())
    }
    fn steps_done(&self) -> u64 {
        self.sys.step
    }
    fn time(&self) -> f64 {
        self.sys.time
    }
    fn dt(&self) -> f64 {
        self.params.dt
    }
    fn series_columns(&self) -> Vec<String> {
        let mut c = grain_columns(self.sys.walls.len());
        if self.cell.is_some() {
            c.extend(shear_cell::COLUMNS.map(String::from));
        }
        if self.zone.is_some() {
            c.extend(packed_zone::COLUMNS.map(String::from));
        }
        c
    }
    fn sample(&self) -> Vec<f64> {
        let mut v = grain_sample(&self.sys, &self.stepper);
        if let Some(c) = &self.cell {
            v.extend(c.sample(&self.sys, &self.stepper, self.sys.step));
        }
        if let Some(z) = &self.zone {
            v.extend(z.sample(&self.sys));
        }
        v
    }
    fn grain_centroids(&self) -> Option<Vec<[f64; 2]>> {
        Some(super::centroids(&self.sys))
    }
    fn max_grain_displacement(&self, then: &[[f64; 2]]) -> Option<f64> {
        super::max_displacement(&self.sys, then)
    }
    fn probe(&self, q: Probe) -> Option<f64> {
        match q {
            Probe::MaxGrainSpeed => Some(self.sys.bodies.max_speed()),
            Probe::WallDisplacement(k) => shear_cell::wall_displacement(
                &self.sys,
                &self.wall_start,
                self.cell.as_ref(),
                k,
                self.sys.step,
            ),
            Probe::MeanLiquidSpeed | Probe::SteadySince | Probe::RigidShare => None,
        }
    }
    fn snapshot(&self, dir: &Path) -> Result<Vec<(&'static str, PathBuf)>> {
        write_particles(
            dir,
            self.sys.step,
            &self.sys,
            &contact_list(&self.stepper, &self.sys),
        )
    }
    fn progress_note(&self) -> Option<String> {
        self.cell.as_ref().map(|c| c.note(&self.sys, self.sys.step))
    }
    fn warnings(&self) -> Vec<String> {
        self.cell
            .as_ref()
            .map_or_else(Vec::new, |c| c.warnings(&self.sys, self.params.dt))
    }
    fn describe(&self) -> serde_json::Value {
        serde_json::json!({
            "bodies": self.sys.bodies.len(), "contact_law": law_name(&self.law),
            "critical_time_step": self.critical_dt, "packing_fraction": self.sys.packing_fraction(),
        })
    }
    fn save(&self) -> Result<serde_json::Value> {
        Ok(
            serde_json::json!({ "system": self.sys, "wall_start": self.wall_start,
                               "cell": self.cell.as_ref().map(Tracked::origin) }),
        )
    }
    fn restore(&mut self, state: serde_json::Value) -> Result<()> {
        #[derive(serde::Deserialize)]
        struct S {
            system: System,
            wall_start: Vec<Vec2>,
            #[serde(default)]
            cell: Option<Origin>,
        }
        let s: S = serde_json::from_value(state)?;
        s.system
            .check_state()
            .map_err(|why| anyhow::anyhow!("the checkpoint's grains are inconsistent: {why}"))?;
        if s.wall_start.len() != s.system.walls.len() {
            anyhow::bail!(
                "the checkpoint has {} wall start positions for {} walls",
                s.wall_start.len(),
                s.system.walls.len()
            );
        }
        // Where the walls started is part of the state: a [compress] preparation moved them
        // before the run, and a resumed run does not repeat it.
        self.sys = s.system;
        self.wall_start = s.wall_start;
        if let (Some(c), Some(o)) = (&mut self.cell, s.cell) {
            c.set_origin(o);
        }
        self.stepper = Stepper::new();
        Ok(())
    }
}
