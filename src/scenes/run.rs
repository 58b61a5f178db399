//! Running a scene: load its sections, build the model its physics names, attach the
//! observers its `[run]` and `[output]` ask for, and hand both to the one time loop.

use super::models;
use super::observers::{
    self, MassBalanced, PasteStopped, Progress, Series, Snapshots, Steady, StillOver, WallClock, WallMoved,
};
use super::schema::{Loaded, Physics, Scene, SlowerOver, SlowerThan, TriggerSpec, WallRef};
use super::timeloop::{self, LoopCfg, Model, Observer, Probe, Trigger};
use crate::contract::Table;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// What a scene run wrote and what it found; the `simulate` stage draws its figures from it.
pub struct SceneResult {
    pub physics: Physics,
    pub summary: serde_json::Value,
    /// Every file written, relative to the run's directory.
    pub files: Vec<PathBuf>,
    pub tables: Vec<Table>,
}

/// Build the model of the scene's physics (without `[compress]` preparation when resuming:
/// the checkpoint holds the prepared state).
pub fn model(l: &Loaded, resume: bool) -> Result<Box<dyn Model>> {
    Ok(match l.physics {
        Physics::Dry => Box::new(models::dry::Dry::build(&l.scene, &l.base_dir, !resume)?),
        Physics::Fluid => models::fluid::build(&l.scene, &l.base_dir)?,
        Physics::Coupled => models::coupled::build(&l.scene, &l.base_dir)
            .with_context(|| format!("scene {} refused", l.path.display()))?,
        Physics::Extruder => Box::new(models::extruder::Extruder::build(&l.scene)?),
        Physics::Incline => Box::new(models::incline::InclineModel::build(&l.scene)?),
    })
}

/// The run's length in steps: `[run] steps` or `time`, after the shear cell's settling if any
/// (its longest, with `settle_until_rest`: a run let go earlier ends at its stop condition or
/// runs on for the time its settling did not take).
pub fn total_steps(s: &Scene, dt: f64) -> u64 {
    let run = match (s.run.steps, s.run.time) {
        (Some(n), _) => n,
        (None, Some(t)) => (t / dt).round().max(1.0) as u64,
        _ => 1,
    };
    run + models::shear_cell::settle_steps(s, dt).map_or(0, |(_, last)| last)
}

/// The DEM index of a wall given by index (a box counts as four) or by its `name`.
pub fn wall_index(s: &Scene, w: &WallRef) -> Result<usize> {
    let count = |e: &super::schema::WallSection| if e.box_.is_some() { 4 } else { 1 };
    let total: usize = s.walls.iter().map(count).sum();
    match w {
        WallRef::Index(k) if *k < total => Ok(*k),
        WallRef::Index(k) => anyhow::bail!(
            "wall = {k}, but the scene has {total} walls (a box counts as four: left, right, bottom, top)"
        ),
        WallRef::Name(n) => {
            let mut k = 0;
            for e in &s.walls {
                if e.name.as_deref() == Some(n.as_str()) {
                    if e.box_.is_some() {
                        anyhow::bail!(
                            "wall = \"{n}\" names a box (four walls); refer to one of them by index"
                        );
                    }
                    return Ok(k);
                }
                k += count(e);
            }
            let names: Vec<&str> = s.walls.iter().filter_map(|e| e.name.as_deref()).collect();
            anyhow::bail!("wall = \"{n}\": no [[walls]] entry has this name; named walls: {names:?}")
        }
    }
}

/// A trigger of `[output]`, with its condition resolved.
fn trigger(s: &Scene, what: &str, t: &TriggerSpec, total: u64) -> Result<Trigger> {
    let probe = match &t.when {
        None => None,
        Some(w) => Some(match (w.quantity.as_str(), &w.wall) {
            ("wall_displacement", Some(r)) => {
                Probe::WallDisplacement(wall_index(s, r).with_context(|| format!("[output] {what} when"))?)
            }
            ("max_grain_speed", _) => Probe::MaxGrainSpeed,
            _ => Probe::MeanLiquidSpeed,
        }),
    };
    Ok(Trigger::from_spec(t, total, probe))
}

/// The observers of the scene, in the order they act after a step, and the checkpoint trigger.
pub fn observers(s: &Scene, total: u64) -> Result<(Vec<Box<dyn Observer>>, Trigger)> {
    let out = &s.output;
    let series = trigger(s, "series", &out.series, total)?;
    let mut obs: Vec<Box<dyn Observer>> = vec![
        Box::new(Series::new(series.clone()).warn_above_mach(s.lattice.as_ref().map(|l| l.mach_warn))),
        Box::new(Snapshots::new(trigger(s, "snapshots", &out.snapshots, total)?)),
    ];
    let r = &s.run;
    match r.until_slower_than {
        Some(SlowerThan::Speed(v)) => obs.push(Box::new(observers::SlowerThan {
            v,
            trigger: series.clone(),
        })),
        Some(SlowerThan::Window(SlowerOver { speed, over })) => obs.push(Box::new(StillOver {
            speed,
            over,
            trigger: series.clone(),
            start: None,
        })),
        None => {}
    }
    if let Some(tol) = r.until_steady {
        obs.push(Box::new(Steady {
            tol,
            trigger: series.clone(),
            last: None,
        }));
    }
    if s.extruder.as_ref().is_some_and(|e| e.stop_when_steady) {
        obs.push(Box::new(MassBalanced {
            trigger: series.clone(),
        }));
    }
    if let Some(i) = &s.incline {
        obs.push(Box::new(PasteStopped {
            share: i.stop_share,
            trigger: series.clone(),
        }));
    }
    if let Some(w) = &r.until_wall_moved {
        obs.push(Box::new(WallMoved {
            wall: wall_index(s, &w.wall).context("[run] until_wall_moved")?,
            distance: w.distance,
            trigger: Trigger::Every(1),
        }));
    }
    if let Some(seconds) = r.wall_clock {
        obs.push(Box::new(WallClock {
            seconds,
            start: std::time::Instant::now(),
            trigger: Trigger::Every(1),
        }));
    }
    Ok((obs, trigger(s, "checkpoints", &out.checkpoints, total)?))
}

/// Run the loaded scene in `dir` (the runner's working directory).
pub fn run(l: &Loaded, dir: &Path, key: &str, resume: bool) -> Result<SceneResult> {
    let s = &l.scene;
    // Refuse a bad wall reference before anything is built or written.
    observers(s, 1)?;
    // `threads = 0` takes the pool the run is called in: all cores alone, a sweep case's share
    // when cases run side by side.
    let threads = match s.run.threads {
        0 => rayon::current_num_threads(),
        n => n,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the thread pool")?;
    if !l.simplified.is_empty() && !crate::contract::quiet() {
        eprintln!("{}: simplified: {}", l.name, l.simplified.join("; "));
    }
    pool.install(|| {
        let mut m = model(l, resume)?;
        let total = total_steps(s, m.dt());
        let (mut obs, checkpoints) = observers(s, total)?;
        obs.push(Box::new(Progress::new(total, 0, &l.name)));
        let cfg = LoopCfg {
            dir,
            key,
            total,
            resume,
            checkpoints,
        };
        let ending = timeloop::run(m.as_mut(), &mut obs, &cfg)?;
        if let Some(why) = ending.stopped.as_ref().filter(|_| !crate::contract::quiet()) {
            eprintln!("{}: {why}; stopping", l.name);
        }
        let mut warnings = m.warnings();
        for o in &obs {
            warnings.extend(o.warnings(m.as_ref()));
        }
        if !crate::contract::quiet() {
            for w in &warnings {
                eprintln!("{}: warning: {w}", l.name);
            }
        }
        let mut files = Vec::new();
        let mut summary = serde_json::json!({
            "scene": l.name, "physics": l.physics, "steps": ending.steps, "time": ending.time,
            "stopped": ending.stopped, "wall_seconds": ending.wall_s, "resumed_from": ending.resumed_from,
            "steps_per_second": ending.steps as f64 / ending.wall_s.max(1e-12),
            "engine": m.describe(), "simplified": l.simplified, "warnings": warnings,
        });
        for o in &obs {
            let (f, entry) = o.report(m.as_ref());
            files.extend(f);
            if let Some((k, v)) = entry {
                summary[k] = v;
            }
        }
        Ok(SceneResult {
            physics: l.physics,
            summary,
            files,
            tables: vec![Table {
                path: super::observers::SERIES_FILE.into(),
                caption: format!("{} time series (SI)", l.name),
            }],
        })
    })
}
