//! Running a scene: load its sections, build the model its physics names, attach the
//! observers its `[run]` and `[output]` ask for, and hand both to the one time loop.

use super::models;
use super::observers::{Progress, Series, SlowerThan, Snapshots, Steady, WallClock, WallMoved};
use super::schema::{Loaded, Physics, Scene};
use super::timeloop::{self, LoopCfg, Model, Observer, Trigger};
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
        Physics::Coupled => models::coupled::build(&l.scene, &l.base_dir)?,
    })
}

/// The run's length in steps.
pub fn total_steps(s: &Scene, dt: f64) -> u64 {
    match (s.run.steps, s.run.time) {
        (Some(n), _) => n,
        (None, Some(t)) => (t / dt).round().max(1.0) as u64,
        _ => 1,
    }
}

/// The observers of the scene, in the order they act after a step.
pub fn observers(s: &Scene, total: u64, name: &str) -> (Vec<Box<dyn Observer>>, Trigger) {
    let out = &s.output;
    let series = Trigger::from_spec(&out.series, total);
    let mut obs: Vec<Box<dyn Observer>> = vec![
        Box::new(Series::new(series.clone())),
        Box::new(Snapshots::new(Trigger::from_spec(&out.snapshots, total))),
    ];
    let r = &s.run;
    if let Some(v) = r.until_slower_than {
        obs.push(Box::new(SlowerThan {
            v,
            trigger: series.clone(),
        }));
    }
    if let Some(tol) = r.until_steady {
        obs.push(Box::new(Steady {
            tol,
            trigger: series.clone(),
            last: None,
        }));
    }
    if let Some(w) = r.until_wall_moved {
        obs.push(Box::new(WallMoved {
            wall: w.wall,
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
    obs.push(Box::new(Progress::new(total, 0, name)));
    (obs, Trigger::from_spec(&out.checkpoints, total))
}

/// Run the loaded scene in `dir` (the runner's working directory).
pub fn run(l: &Loaded, dir: &Path, key: &str, resume: bool) -> Result<SceneResult> {
    let s = &l.scene;
    if let Some(w) = s.run.until_wall_moved
        && w.wall
            >= s.walls
                .iter()
                .map(|w| if w.box_.is_some() { 4 } else { 1 })
                .sum::<usize>()
    {
        anyhow::bail!(
            "[run] until_wall_moved: wall = {} but the scene has fewer walls (a box counts as four)",
            w.wall
        );
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(s.run.threads)
        .build()
        .context("cannot start the thread pool")?;
    pool.install(|| {
        let mut m = model(l, resume)?;
        let total = total_steps(s, m.dt());
        let (mut obs, checkpoints) = observers(s, total, &l.name);
        let cfg = LoopCfg {
            dir,
            key,
            total,
            resume,
            checkpoints,
        };
        let ending = timeloop::run(m.as_mut(), &mut obs, &cfg)?;
        if let Some(why) = &ending.stopped {
            eprintln!("{}: {why}; stopping", l.name);
        }
        let mut files = Vec::new();
        let mut summary = serde_json::json!({
            "scene": l.name, "physics": l.physics, "steps": ending.steps, "time": ending.time,
            "stopped": ending.stopped, "wall_seconds": ending.wall_s, "resumed_from": ending.resumed_from,
            "steps_per_second": ending.steps as f64 / ending.wall_s.max(1e-12),
            "engine": m.describe(),
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
