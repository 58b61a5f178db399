//! Leonardi et al. (2014)'s concrete incline as the time loop sees it (`[incline]`, issue 20 item
//! 4): the free-surface paste, its pebbles and the lifted box (`lbdem_coupling::cases::incline`),
//! one LBM step (with its DEM sub-steps) per loop step. Series: how far the box is lifted, the
//! footprint's runout and width, the share of the paste at τ_max (the paper stops at 95 %), the
//! paste's mass drift, the fastest pebble; snapshots: the thickness of the paste per board column
//! (the outline of Fig. 7c), the viscosity on the middle section (Fig. 8) and the sphere table;
//! the checkpoint: the lattice, the spheres and the lift.

use crate::report::table::{Col, write_table};
use crate::scenes::schema::Scene;
use crate::scenes::sphere_table::write_spheres;
use crate::scenes::timeloop::{Model, Probe};
use anyhow::{Context, Result};
use lbdem_coupling::cases::incline::{Incline, InclineSpec, InclineState};
use std::path::{Path, PathBuf};

pub struct InclineModel {
    run: Incline,
    mass0: f64,
}

impl InclineModel {
    pub fn build(s: &Scene) -> Result<Self> {
        let spec = s.incline.as_ref().context("an incline scene needs [incline]")?;
        let run = Incline::build(spec).map_err(|e| anyhow::anyhow!("[incline]: {e}"))?;
        if !crate::contract::quiet() {
            let n = spec.nodes();
            eprintln!(
                "incline: lattice {} x {} x {} at dx = {} m, dt = {:e} s, tau_pl = {:.5}, {} pebbles, {} box spheres",
                n[0],
                n[1],
                n[2],
                spec.dx,
                spec.dt,
                spec.bingham().tau_pl(),
                run.pebbles,
                run.box_spheres.len()
            );
        }
        let mass0 = run.run.grains.liquid.total_mass();
        Ok(Self { run, mass0 })
    }

    fn spec(&self) -> &InclineSpec {
        &self.run.spec
    }
}

/// Node centres (m) of an `na` × `nb` plane of the lattice, first index fastest (the order of
/// `Incline::thickness` and `Incline::viscosity_section`).
fn node_grid(na: usize, nb: usize, dx: f64) -> (Vec<f64>, Vec<f64>) {
    let centre = |k: usize| (k as f64 + 0.5) * dx;
    (0..nb)
        .flat_map(|b| (0..na).map(move |a| (centre(a), centre(b))))
        .unzip()
}

/// The series columns after `time`.
pub const COLUMNS: [&str; 7] = [
    "lifted",
    "runout",
    "width",
    "rigid_share",
    "mass_drift",
    "max_pebble_speed",
    "creep",
];

impl Model for InclineModel {
    fn step(&mut self, _fields: bool) -> Result<()> {
        let step = self.run.run.grains.liquid.step;
        self.run
            .step()
            .map_err(|e| anyhow::anyhow!("incline at LBM step {step}: {e}"))?;
        Ok(())
    }
    fn steps_done(&self) -> u64 {
        self.run.run.grains.liquid.step
    }
    fn time(&self) -> f64 {
        self.run.time()
    }
    fn dt(&self) -> f64 {
        self.spec().dt
    }
    fn series_columns(&self) -> Vec<String> {
        COLUMNS.map(String::from).to_vec()
    }
    fn sample(&self) -> Vec<f64> {
        let (runout, width) = self.run.footprint();
        let mass = self.run.run.grains.liquid.total_mass();
        vec![
            self.run.lifted,
            runout,
            width,
            self.run.rigid_share(),
            (mass - self.mass0) / self.mass0,
            self.run.max_pebble_speed(),
            self.run.creep(),
        ]
    }
    fn probe(&self, q: Probe) -> Option<f64> {
        match q {
            Probe::RigidShare => Some(self.run.rigid_share()),
            Probe::MaxGrainSpeed => Some(self.run.max_pebble_speed()),
            _ => None,
        }
    }
    fn snapshot(&self, dir: &Path) -> Result<Vec<(&'static str, PathBuf)>> {
        let spec = self.spec();
        let [nx, ny, nz] = spec.nodes();
        let step = self.steps_done();
        let th = self.run.thickness();
        let (x, z) = node_grid(nx, nz, spec.dx);
        let thickness = PathBuf::from(format!("snapshots/thickness_{step:09}.csv"));
        write_table(
            &dir.join(&thickness),
            &[
                ("x", Col::F64(&x)),
                ("z", Col::F64(&z)),
                ("thickness", Col::F64(&th)),
            ],
        )?;
        let mu = self.run.viscosity_section();
        let (sx, sy) = node_grid(nx, ny, spec.dx);
        let section = PathBuf::from(format!("snapshots/section_{step:09}.csv"));
        write_table(
            &dir.join(&section),
            &[
                ("x", Col::F64(&sx)),
                ("y", Col::F64(&sy)),
                ("viscosity", Col::F64(&mu)),
            ],
        )?;
        let mut out = vec![("thickness", thickness), ("section", section)];
        out.extend(write_spheres(dir, step, &self.run.run.sys, None)?);
        Ok(out)
    }
    fn progress_note(&self) -> Option<String> {
        let (runout, _) = self.run.footprint();
        Some(format!(
            "runout {:.3} m, {:.0} % at tau_max",
            runout,
            100.0 * self.run.rigid_share()
        ))
    }
    fn warnings(&self) -> Vec<String> {
        self.run.warnings()
    }
    fn describe(&self) -> serde_json::Value {
        serde_json::json!({
            "spec": self.spec(), "pebbles": self.run.pebbles, "box_spheres": self.run.box_spheres.len(),
            "paste_nodes": self.run.paste_nodes, "tau_pl": self.spec().bingham().tau_pl(),
        })
    }
    fn save(&self) -> Result<serde_json::Value> {
        Ok(serde_json::to_value(self.run.state())?)
    }
    fn restore(&mut self, state: serde_json::Value) -> Result<()> {
        let s: InclineState = serde_json::from_value(state)?;
        self.run
            .restore(s)
            .map_err(|e| anyhow::anyhow!("the checkpoint does not fit this incline: {e}"))
    }
}
