//! Ness et al. (2017)'s extruder as the time loop sees it: the sphere system with its frozen
//! walls, the extruder's state (counts, mass balance), Ness's law (lubrication Eqs. 3-5 plus
//! the linear spring of Eq. 6), one extruder step per loop step. Series: the counts, the inlet
//! box's φ, the barrel and die velocities, the paste's force on each wall segment and the mass
//! balance; snapshots: the sphere table; the checkpoint: the system and the extruder state.

use crate::scenes::schema::{NessLaw, Scene};
use crate::scenes::sphere_table::write_spheres;
use crate::scenes::timeloop::{Model, Probe};
use anyhow::{Context, Result};
use lbdem_dem::Vector;
use lbdem_dem::spheres::extruder::{ExtruderSpec, ExtruderState, Segment};
use lbdem_dem::spheres::{SphereStepParams, SphereStepper, SphereSystem, sphere_dipoles};
use std::path::{Path, PathBuf};

pub struct Extruder {
    spec: ExtruderSpec,
    law: NessLaw,
    params: SphereStepParams,
    pub sys: SphereSystem,
    pub state: ExtruderState,
    stepper: SphereStepper<NessLaw>,
    stop_when_steady: bool,
    /// Whether the last step recorded its interactions (a step taken with `fields`): the
    /// snapshot's dipole shares are NaN otherwise.
    recorded: bool,
}

impl Extruder {
    /// Build from the scene (checked when it was loaded): walls, and the initial fill if asked.
    pub fn build(s: &Scene) -> Result<Self> {
        let (e, susp) = s
            .extruder
            .as_ref()
            .zip(s.suspension.as_ref())
            .context("an extruder scene needs [extruder] and [suspension]")?;
        let spec = e.spec(susp);
        let law = susp.law();
        let params = SphereStepParams::new(susp.time_step()?, susp.skin());
        let (sys, state) = ExtruderState::build(&spec).map_err(|err| anyhow::anyhow!("[extruder]: {err}"))?;
        if !crate::contract::quiet() {
            eprintln!(
                "extruder: {} wall grains, {} grains filled, dt = {:e} s ({}), channel {:.0} x {:.0} d",
                state.walls,
                state.prefilled,
                params.dt,
                susp.limit().bound,
                (spec.geometry.die_end()) / susp.diameters[0],
                spec.geometry.barrel_width / susp.diameters[0],
            );
        }
        Ok(Self {
            spec,
            law,
            params,
            sys,
            state,
            stepper: SphereStepper::new(),
            stop_when_steady: e.stop_when_steady,
            recorded: false,
        })
    }

    pub fn spec(&self) -> &ExtruderSpec {
        &self.spec
    }
}

/// The series columns after `time`.
pub const COLUMNS: [&str; 17] = [
    "inserted",
    "removed",
    "grains",
    "phi_inlet",
    "barrel_velocity",
    "die_velocity",
    "wall_fx_ram",
    "wall_fx_barrel",
    "wall_fx_entry",
    "wall_fx_die",
    "wall_fy_barrel",
    "wall_fy_die",
    "rate_in",
    "rate_out",
    "imbalance",
    "steady",
    "max_speed",
];

impl Model for Extruder {
    fn step(&mut self, fields: bool) -> Result<()> {
        // Interactions are recorded only on the steps an output reads (snapshots' dipoles).
        self.stepper.record_contacts(fields);
        self.recorded = false;
        self.state
            .step(
                &self.spec,
                &self.law,
                &self.params,
                &mut self.stepper,
                &mut self.sys,
            )
            .map_err(|e| anyhow::anyhow!("extruder at step {}: {e}", self.sys.step))?;
        self.recorded = fields;
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
        COLUMNS.map(String::from).to_vec()
    }
    fn sample(&self) -> Vec<f64> {
        let m = self.state.measure(&self.spec, &self.sys);
        let f = |s: Segment| m.wall_force[s.index()];
        let r = self.state.balance.rates(&self.spec.steady);
        let s = &self.sys.spheres;
        let max_speed = (self.state.walls..s.len())
            .map(|k| s.vel[k].norm())
            .fold(0.0, f64::max);
        vec![
            self.state.inserted as f64,
            self.state.removed as f64,
            m.grains as f64,
            m.phi_inlet,
            m.barrel_velocity,
            m.die_velocity,
            f(Segment::Ram).x,
            f(Segment::Barrel).x,
            f(Segment::Entry).x,
            f(Segment::Die).x,
            f(Segment::Barrel).y,
            f(Segment::Die).y,
            r.map_or(f64::NAN, |r| r.r_in),
            r.map_or(f64::NAN, |r| r.r_out),
            r.map_or(f64::NAN, |r| r.imbalance),
            f64::from(u8::from(self.state.balance.steady_since.is_some())),
            max_speed,
        ]
    }
    fn probe(&self, q: Probe) -> Option<f64> {
        match q {
            Probe::SteadySince if self.stop_when_steady => self.state.balance.steady_since,
            _ => None,
        }
    }
    fn snapshot(&self, dir: &Path) -> Result<Vec<(&'static str, PathBuf)>> {
        let shares = self.recorded.then(|| {
            sphere_dipoles(
                self.stepper.contacts(),
                &self.sys.spheres.frozen,
                &self.sys.spheres.radius,
            )
        });
        write_spheres(dir, self.sys.step, &self.sys, shares.as_deref())
    }
    fn progress_note(&self) -> Option<String> {
        let m = self.state.measure(&self.spec, &self.sys);
        Some(format!(
            "{} grains, {} out, V_die {:.3e} m/s",
            m.grains, self.state.removed, m.die_velocity
        ))
    }
    fn describe(&self) -> serde_json::Value {
        let b = &self.state.balance;
        serde_json::json!({
            "wall_grains": self.state.walls, "grains": self.sys.spheres.len() - self.state.walls,
            "prefilled": self.state.prefilled, "inserted": self.state.inserted, "removed": self.state.removed,
            "dt": self.params.dt, "skin": self.params.skin, "first_steady": b.first_steady,
            "steady_since": b.steady_since, "channel_phi": self.state.channel_phi(&self.spec, &self.sys),
            "spec": self.spec, "law": self.law,
        })
    }
    fn save(&self) -> Result<serde_json::Value> {
        Ok(serde_json::json!({ "system": self.sys, "extruder": self.state }))
    }
    fn restore(&mut self, state: serde_json::Value) -> Result<()> {
        #[derive(serde::Deserialize)]
        struct S {
            system: SphereSystem,
            extruder: ExtruderState,
        }
        let s: S = serde_json::from_value(state)?;
        s.extruder
            .check(&s.system)
            .map_err(|why| anyhow::anyhow!("the checkpoint's extruder state is inconsistent: {why}"))?;
        self.sys = s.system;
        self.state = s.extruder;
        self.stepper = SphereStepper::new();
        self.recorded = false;
        Ok(())
    }
}
