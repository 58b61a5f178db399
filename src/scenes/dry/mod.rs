//! `dry` scenes: DEM without fluid. A scene file names the particles (a CSV of circles from the
//! digitise stage, or a generator), walls, the contact law, drivers and stop conditions; the run
//! writes a time series (CSV + JSON), VTK particle snapshots and atomic checkpoints, and
//! `--resume` continues from the last checkpoint bit for bit. Format: docs/dem.md.

pub(crate) mod config;
mod particles;

use super::SimContext;
use crate::stages::{StageOutput, Table};
use anyhow::{Context, Result, bail};
use config::DryScene;
use lbdem_core::atomic::write_atomic;
use lbdem_core::vtk::{Array, Values, write_pvd, write_vtp_points};
use lbdem_dem::{ContactLaw, Law, Stepper, System};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One row of the time series.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Row {
    pub step: u64,
    pub time: f64,
    pub kinetic_energy: f64,
    pub packing_fraction: f64,
    pub contacts: usize,
    pub max_speed: f64,
    /// Force of the particles on each wall (x, y), in wall order.
    pub wall_forces: Vec<[f64; 2]>,
}

/// Everything needed to continue a run.
#[derive(Serialize, Deserialize)]
struct Checkpoint {
    system: System,
    rows: Vec<Row>,
    snapshots: Vec<(f64, String)>,
}

pub fn run(scene: &toml::Value, ctx: &SimContext) -> Result<StageOutput> {
    let cfg: DryScene = scene
        .clone()
        .try_into()
        .context("dry scene: the file does not match the dry-scene format (see docs/dem.md for every key)")?;
    std::fs::create_dir_all(ctx.out_dir.join("snapshots"))
        .with_context(|| format!("cannot create {}", ctx.out_dir.display()))?;
    let ck_path = ctx.out_dir.join("checkpoint.json");
    let (mut sys, mut rows, mut snaps) = if ctx.resume && ck_path.exists() {
        let text = std::fs::read_to_string(&ck_path)
            .with_context(|| format!("cannot read checkpoint {}", ck_path.display()))?;
        let ck: Checkpoint = serde_json::from_str(&text).with_context(|| {
            format!(
                "checkpoint {} is damaged; delete it and run without --resume",
                ck_path.display()
            )
        })?;
        eprintln!(
            "dry: resuming at step {} from {}",
            ck.system.step,
            ck_path.display()
        );
        (ck.system, ck.rows, ck.snapshots)
    } else {
        (cfg.build_system(&ctx.base_dir)?, Vec::new(), Vec::new())
    };
    let law = cfg.contact.clone();
    let wall_law = cfg.wall_contact.clone().unwrap_or_else(|| law.clone());
    let p = cfg.step;
    let mut st = Stepper::new();
    let (crit, m_min, k_max) = Stepper::critical_time_step(&sys, &law, &wall_law);
    eprintln!(
        "dry: {} bodies, dt = {:e} s, critical {:e} s (m_min {m_min:e} kg, k_max {k_max:e} N/m)",
        sys.bodies.len(),
        p.dt,
        crit
    );
    if let Some(c) = &cfg.run.compress
        && sys.step == 0
    {
        let n =
            lbdem_dem::generate::compress_isotropic(&mut sys, &law, &wall_law, &p, &c.to_kernel(), &mut st)
                .context("dry scene [run.compress]")?;
        eprintln!(
            "dry: isotropic compression took {n} steps, packing fraction {:.4}",
            sys.packing_fraction()
        );
        if let Some(phi) = c.target_packing {
            lbdem_dem::generate::scale_to_packing(&mut sys, phi);
        }
        sys.step = 0;
        sys.time = 0.0;
        st = Stepper::new();
    }
    let r = &cfg.run;
    let record = |sys: &System, st: &Stepper| Row {
        step: sys.step,
        time: sys.time,
        kinetic_energy: sys.bodies.kinetic_energy(),
        packing_fraction: sys.packing_fraction(),
        contacts: st.n_contacts(),
        max_speed: sys.bodies.max_speed(),
        wall_forces: sys.walls.iter().map(|w| [w.force.x, w.force.y]).collect(),
    };
    while sys.step < r.steps {
        st.step_law(&p, &law, &wall_law, &mut sys)
            .map_err(|e| anyhow::anyhow!("dry scene: {e} (set [step] dt in the scene file)"))?;
        let n = sys.step;
        if n % r.output_every == 0 {
            rows.push(record(&sys, &st));
        }
        if r.snapshot_every > 0 && n % r.snapshot_every == 0 {
            let name = format!("snapshots/particles_{n:09}.vtp");
            write_snapshot(&ctx.out_dir.join(&name), &sys)?;
            snaps.push((sys.time, name));
        }
        if r.checkpoint_every > 0 && n % r.checkpoint_every == 0 {
            let ck = Checkpoint {
                system: sys.clone(),
                rows: rows.clone(),
                snapshots: snaps.clone(),
            };
            let text = serde_json::to_vec(&ck)?;
            write_atomic(&ck_path, &text).with_context(|| format!("cannot write {}", ck_path.display()))?;
            write_series(&ctx.out_dir, &rows)?;
        }
        if let Some(v) = r.stop_when_slower_than
            && n % r.output_every == 0
            && sys.bodies.max_speed() < v
        {
            eprintln!("dry: every grain slower than {v:e} m/s at step {n}; stopping");
            break;
        }
        if let Some(limit) = r.stop_after_steps_for_test
            && n >= limit
        {
            bail!("dry scene: stopped at step {n} by run.stop_after_steps_for_test (simulated interruption)");
        }
    }
    let mut files = write_series(&ctx.out_dir, &rows)?;
    let last = format!("snapshots/particles_{:09}.vtp", sys.step);
    if !snaps.iter().any(|(_, n)| *n == last) {
        write_snapshot(&ctx.out_dir.join(&last), &sys)?;
        snaps.push((sys.time, last));
    }
    write_pvd(&ctx.out_dir.join("particles.pvd"), &snaps)?;
    let final_path = ctx.out_dir.join("final_state.json");
    write_atomic(&final_path, &serde_json::to_vec(&sys)?)?;
    files.push("particles.pvd".into());
    files.push("final_state.json".into());
    files.extend(snaps.iter().map(|(_, n)| PathBuf::from(n)));
    let last_row = rows.last().cloned();
    Ok(StageOutput {
        summary: serde_json::json!({
            "steps": sys.step, "time": sys.time, "bodies": sys.bodies.len(),
            "packing_fraction": sys.packing_fraction(), "last": last_row,
            "contact_law": law_name(&law), "critical_time_step": crit,
        }),
        figures: vec![],
        tables: vec![Table {
            path: "series.csv".into(),
            caption: "DEM time series".into(),
        }],
        files,
    })
}

fn law_name(l: &Law) -> &'static str {
    let _ = l.friction();
    match l {
        Law::Linear(_) => "linear",
        Law::Hertz(_) => "hertz",
        Law::Plastic(_) => "plastic",
    }
}

fn write_series(dir: &Path, rows: &[Row]) -> Result<Vec<PathBuf>> {
    let nw = rows.first().map_or(0, |r| r.wall_forces.len());
    let mut csv = String::from("step,time,kinetic_energy,packing_fraction,contacts,max_speed");
    for w in 0..nw {
        csv.push_str(&format!(",wall{w}_fx,wall{w}_fy"));
    }
    csv.push('\n');
    for r in rows {
        csv.push_str(&format!(
            "{},{:e},{:e},{:e},{},{:e}",
            r.step, r.time, r.kinetic_energy, r.packing_fraction, r.contacts, r.max_speed
        ));
        for f in &r.wall_forces {
            csv.push_str(&format!(",{:e},{:e}", f[0], f[1]));
        }
        csv.push('\n');
    }
    write_atomic(&dir.join("series.csv"), csv.as_bytes())?;
    write_atomic(&dir.join("series.json"), &serde_json::to_vec_pretty(rows)?)?;
    Ok(vec!["series.csv".into(), "series.json".into()])
}

/// One point per circle: radius, body id, body velocity and angular velocity.
pub(crate) fn write_snapshot(path: &Path, sys: &System) -> Result<()> {
    let b = &sys.bodies;
    let nc = b.n_circles();
    let pos: Vec<[f64; 3]> = (0..nc)
        .map(|c| {
            let p = b.circle_pos(c);
            [p.x, p.y, 0.0]
        })
        .collect();
    let body: Vec<i32> = b.circle_body.iter().map(|&k| k as i32).collect();
    let vel: Vec<f64> = (0..nc)
        .flat_map(|c| {
            let v = b.vel[b.circle_body[c] as usize];
            [v.x, v.y, 0.0]
        })
        .collect();
    let omega: Vec<f64> = (0..nc).map(|c| b.omega[b.circle_body[c] as usize]).collect();
    write_vtp_points(
        path,
        &pos,
        &[
            Array::scalar("radius", Values::F64(&b.circle_r)),
            Array::scalar("body", Values::I32(&body)),
            Array::vector("velocity", Values::F64(&vel)),
            Array::scalar("omega", Values::F64(&omega)),
        ],
    )
    .with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests;
