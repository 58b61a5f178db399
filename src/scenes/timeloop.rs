//! One time loop for every scene, with observers on triggers (as HOOMD-blue's writers and
//! LAMMPS's fix hooks): the loop advances a [`Model`] one step at a time; after each step every
//! observer whose trigger fires acts (series row, snapshot, checkpoint, stop condition,
//! progress). The loop also owns resuming: a checkpoint holds the model's state and every
//! observer's, so a resumed run continues to the same bits as an uninterrupted one.

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// What a scene's engine looks like to the loop. A step is the scene's outer step (one DEM
/// step, one LBM step, or one LBM step with its DEM sub-steps).
pub trait Model {
    /// Advance one step; with `fields`, compute what [`Model::sample`], [`Model::probe`] and
    /// [`Model::snapshot`] read (macroscopic fields of the liquid).
    fn step(&mut self, fields: bool) -> Result<()>;
    /// Steps done since the start of the run.
    fn steps_done(&self) -> u64;
    /// Simulated time (s).
    fn time(&self) -> f64;
    /// Duration of one step (s).
    fn dt(&self) -> f64;
    /// Names of the series columns after `step` and `time`.
    fn series_columns(&self) -> Vec<String>;
    /// The series values of the current state (after a step taken with `fields`).
    fn sample(&self) -> Vec<f64>;
    /// A quantity the stop conditions read; `None` when the model has no such thing.
    fn probe(&self, q: Probe) -> Option<f64>;
    /// Whether [`Model::probe`] of `q` reads the fields a step computes only when asked.
    fn probe_needs_fields(&self, _q: Probe) -> bool {
        false
    }
    /// Every grain's centroid (m), for stop conditions that compare positions over a time
    /// window; `None` when the model has no grains.
    fn grain_centroids(&self) -> Option<Vec<[f64; 2]>> {
        None
    }
    /// The largest distance (m) a grain moved since `then` (taken by
    /// [`Model::grain_centroids`]), across periodic faces; `None` without grains, or when the
    /// grains are not the same ones.
    fn max_grain_displacement(&self, _then: &[[f64; 2]]) -> Option<f64> {
        None
    }
    /// Write the current state under `dir` (tables that can be read back, VTK beside them);
    /// returns (kind, path relative to `dir`) of each file.
    fn snapshot(&self, dir: &Path) -> Result<Vec<(&'static str, PathBuf)>>;
    /// A short note on where the run stands, beside the progress bar (e.g. the push-plate's
    /// displacement in grain diameters).
    fn progress_note(&self) -> Option<String> {
        None
    }
    /// What the run was (engine settings, timings) for the summary.
    fn describe(&self) -> serde_json::Value {
        serde_json::Value::Null
    }
    /// Accuracy failures the run measured without stopping (e.g. a Bingham paste creeping at
    /// its clamp), each naming the fix: printed after the run and kept in its summary.
    fn warnings(&self) -> Vec<String> {
        Vec::new()
    }
    /// Whether the state can be saved now (the in-place LBM kernel only after even steps).
    fn can_checkpoint(&self) -> bool {
        true
    }
    /// Everything needed to continue bit for bit.
    fn save(&self) -> Result<serde_json::Value>;
    fn restore(&mut self, state: serde_json::Value) -> Result<()>;
}

/// Quantities the stop conditions read.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Probe {
    /// Largest grain speed (m/s).
    MaxGrainSpeed,
    /// Distance a wall moved from where it started (m).
    WallDisplacement(usize),
    /// Mean liquid speed (m/s).
    MeanLiquidSpeed,
    /// Since when an extruder's mass balance has held (s), if it holds now.
    SteadySince,
    /// Share of an incline's paste at its largest viscosity (τ_max).
    RigidShare,
}

/// When an observer acts, in steps (a `count` or `at` of the scene file is turned into these
/// once the run's length is known).
#[derive(Clone, Debug, PartialEq)]
pub enum Trigger {
    Every(u64),
    /// At the first step whose time reaches each of these (s), ascending.
    AtTimes(Vec<f64>),
    /// Every so many seconds of wall-clock time.
    WallSeconds(f64),
    /// At the step after the one at which `probe` crossed each of `crosses` (upwards).
    When {
        probe: Probe,
        crosses: Vec<f64>,
    },
    Never,
}

impl Trigger {
    /// From the scene's `[output]` entry, for a run of `total` steps; `probe` is the condition
    /// of a `when` entry, resolved by the caller (it names walls).
    pub fn from_spec(t: &crate::scenes::schema::TriggerSpec, total: u64, probe: Option<Probe>) -> Self {
        if let (Some(w), Some(p)) = (&t.when, probe) {
            let mut c = w.crosses.clone();
            c.sort_by(f64::total_cmp);
            return Trigger::When { probe: p, crosses: c };
        }
        if let Some(n) = t.every {
            Trigger::Every(n.max(1))
        } else if let Some(c) = t.count {
            Trigger::Every((total / c.max(1)).max(1))
        } else if let Some(at) = &t.at {
            let mut v = at.clone();
            v.sort_by(f64::total_cmp);
            Trigger::AtTimes(v)
        } else if let Some(s) = t.wall_seconds {
            Trigger::WallSeconds(s)
        } else {
            Trigger::Never
        }
    }

    /// Whether it fires after step `step` (1-based) that ends at `time`, the previous step
    /// having ended at `prev_time`; `since` is the wall time since it last fired.
    pub fn fires(&self, step: u64, time: f64, prev_time: f64, since: f64) -> bool {
        match self {
            Trigger::Every(n) => step.is_multiple_of(*n),
            Trigger::AtTimes(ts) => ts.iter().any(|&t| prev_time < t && t <= time),
            Trigger::WallSeconds(s) => since >= *s,
            // Conditions are checked by the loop after each step (`Trigger::crossed`).
            Trigger::When { .. } | Trigger::Never => false,
        }
    }
}

impl Trigger {
    /// For a condition trigger: whether the probed quantity went from `before` to `now` across
    /// one of its values.
    pub fn crossed(&self, before: Option<f64>, now: Option<f64>) -> bool {
        match (self, before, now) {
            (Trigger::When { crosses, .. }, b, Some(n)) => {
                let b = b.unwrap_or(f64::NEG_INFINITY);
                crosses.iter().any(|&c| b < c && c <= n)
            }
            _ => false,
        }
    }

    fn probe(&self) -> Option<Probe> {
        match self {
            Trigger::When { probe, .. } => Some(*probe),
            _ => None,
        }
    }
}

/// What an observer tells the loop.
#[derive(Clone, Debug, PartialEq)]
pub enum Flow {
    Continue,
    /// End the run here (a stop condition held); the final outputs are written.
    Stop(String),
    /// Stop here with a checkpoint, to be continued with `--resume` (wall-clock limit).
    Interrupt(String),
}

/// Where the loop writes and what it was asked to do.
pub struct LoopCtx<'a> {
    pub dir: &'a Path,
    /// The run's key (a checkpoint made with another key is refused).
    pub key: &'a str,
    pub total_steps: u64,
    /// Whether this step is the run's last (the series and snapshot observers always act then).
    pub last: bool,
}

/// Something that acts on a model after some steps: a writer, a stop condition, a progress
/// display. Its state must be saved in checkpoints if it affects what is written.
pub trait Observer {
    /// A short name, unique in the loop (it keys the observer's checkpointed state).
    fn name(&self) -> &'static str;
    fn trigger(&self) -> &Trigger;
    /// Whether it acts at the run's last step even when its trigger does not fire.
    fn at_last_step(&self) -> bool {
        false
    }
    /// Whether the model must compute its fields for the step this observer will act on.
    fn needs_fields(&self) -> bool {
        false
    }
    fn observe(&mut self, m: &mut dyn Model, cx: &LoopCtx) -> Result<Flow>;
    /// Whether [`Observer::finish`] also runs when the run fails after it started, to keep what
    /// was recorded until then (the series: [`crate::contract::FailedRun`]).
    fn at_failure(&self) -> bool {
        false
    }
    /// After the loop (also after a stop): write what is left.
    fn finish(&mut self, _m: &mut dyn Model, _cx: &LoopCtx) -> Result<()> {
        Ok(())
    }
    fn save(&self) -> serde_json::Value {
        serde_json::Value::Null
    }
    fn restore(&mut self, _v: serde_json::Value) -> Result<()> {
        Ok(())
    }
    /// After the run: accuracy failures this observer saw in what it recorded, each naming the
    /// fix (printed after the run and kept in its summary beside [`Model::warnings`]).
    fn warnings(&self, _m: &dyn Model) -> Vec<String> {
        Vec::new()
    }
    /// After the run: the files it wrote (relative to the run's directory) and an entry for
    /// the run's summary.
    fn report(&self, _m: &dyn Model) -> (Vec<PathBuf>, Option<(&'static str, serde_json::Value)>) {
        (Vec::new(), None)
    }
}

/// How a run ended.
#[derive(Clone, Debug, Serialize)]
pub struct Ending {
    pub steps: u64,
    pub time: f64,
    /// Why it ended before its last step, if it did.
    pub stopped: Option<String>,
    pub wall_s: f64,
    pub resumed_from: Option<u64>,
}

/// The checkpoint file in the run's directory.
pub use crate::contract::CHECKPOINT;

#[derive(Serialize, Deserialize)]
struct Checkpoint {
    format: u32,
    key: String,
    step: u64,
    model: serde_json::Value,
    observers: Vec<(String, serde_json::Value)>,
    /// Condition triggers that fired at the checkpoint's step and act at the next one, and the
    /// last value of each one's quantity.
    #[serde(default)]
    armed: Vec<bool>,
    #[serde(default)]
    probed: Vec<Option<f64>>,
}

const FORMAT: u32 = 1;

/// What the loop is asked to do besides stepping.
pub struct LoopCfg<'a> {
    /// Where the observers write and the checkpoint lives.
    pub dir: &'a Path,
    /// The run's key: a checkpoint made with another key is refused.
    pub key: &'a str,
    /// Steps of the whole run (a stop condition may end it earlier).
    pub total: u64,
    /// Continue from the checkpoint in `dir`.
    pub resume: bool,
    /// When to write checkpoints.
    pub checkpoints: Trigger,
}

/// Run `model` with `observers` as `cfg` says.
pub fn run(model: &mut dyn Model, observers: &mut [Box<dyn Observer>], cfg: &LoopCfg) -> Result<Ending> {
    let t0 = Instant::now();
    let (dir, key, total) = (cfg.dir, cfg.key, cfg.total);
    let mut armed = vec![false; observers.len()];
    // Last value of each condition trigger's quantity (the run's state at the start counts).
    let mut probed: Vec<Option<f64>> = observers
        .iter()
        .map(|o| o.trigger().probe().and_then(|p| model.probe(p)))
        .collect();
    let resumed_from = if cfg.resume {
        Some(restore(model, observers, &mut armed, &mut probed, dir, key)?)
    } else {
        None
    };
    // Condition triggers whose quantity needs the liquid's fields get them every step.
    let condition_fields = observers
        .iter()
        .any(|o| o.trigger().probe().is_some_and(|p| model.probe_needs_fields(p)));
    let mut last_fired: Vec<Instant> = vec![Instant::now(); observers.len()];
    let mut last_checkpoint = Instant::now();
    // A checkpoint or interruption asked for at a step where the model cannot be saved waits
    // for the next step that can.
    let mut pending_checkpoint = false;
    let mut pending_interrupt: Option<String> = None;
    let mut stopped = None;
    let mut step = model.steps_done();
    while step < total {
        let next = step + 1;
        let (prev_t, t) = (model.time(), model.time() + model.dt());
        let last = next == total;
        let fire: Vec<bool> = observers
            .iter()
            .zip(&last_fired)
            .zip(&armed)
            .map(|((o, lf), a)| {
                o.trigger().fires(next, t, prev_t, lf.elapsed().as_secs_f64())
                    || *a
                    || (last && o.at_last_step())
            })
            .collect();
        let fields = condition_fields || observers.iter().zip(&fire).any(|(o, f)| *f && o.needs_fields());
        if let Err(e) = model.step(fields) {
            return Err(failed(model, observers, dir, key, total, e));
        }
        step = model.steps_done();
        let cx = LoopCtx {
            dir,
            key,
            total_steps: total,
            last,
        };
        let mut flow = Flow::Continue;
        for (k, o) in observers.iter_mut().enumerate() {
            if let Some(p) = o.trigger().probe() {
                let now = model.probe(p);
                armed[k] = o.trigger().crossed(probed[k], now);
                probed[k] = now;
            }
            if !fire[k] {
                continue;
            }
            last_fired[k] = Instant::now();
            match o.observe(model, &cx)? {
                Flow::Continue => {}
                f if flow == Flow::Continue => flow = f,
                _ => {}
            }
        }
        match flow {
            Flow::Continue => {}
            Flow::Stop(why) => {
                // The series and snapshot writers record the state the run ends in.
                let cx = LoopCtx { last: true, ..cx };
                for (k, o) in observers.iter_mut().enumerate() {
                    if o.at_last_step() && !fire[k] {
                        o.observe(model, &cx)?;
                    }
                }
                stopped = Some(why);
                break;
            }
            Flow::Interrupt(why) => pending_interrupt = Some(why),
        }
        if let Some(why) = &pending_interrupt
            && model.can_checkpoint()
        {
            save(model, observers, &armed, &probed, dir, key)?;
            return Err(crate::contract::Interrupted {
                reason: why.clone(),
                step,
            }
            .into());
        }
        pending_checkpoint |= !last
            && cfg
                .checkpoints
                .fires(step, t, prev_t, last_checkpoint.elapsed().as_secs_f64());
        if pending_checkpoint && model.can_checkpoint() {
            save(model, observers, &armed, &probed, dir, key)?;
            last_checkpoint = Instant::now();
            pending_checkpoint = false;
        }
    }
    let cx = LoopCtx {
        dir,
        key,
        total_steps: total,
        last: true,
    };
    for o in observers.iter_mut() {
        o.finish(model, &cx)?;
    }
    let _ = std::fs::remove_file(dir.join(CHECKPOINT));
    Ok(Ending {
        steps: model.steps_done(),
        time: model.time(),
        stopped,
        wall_s: t0.elapsed().as_secs_f64(),
        resumed_from,
    })
}

/// The error of a run that failed after it started, with what its observers recorded until then
/// written to `dir` (kept by the runner: [`crate::contract::FailedRun`]); the failure alone if
/// nothing could be written.
fn failed(
    model: &mut dyn Model,
    observers: &mut [Box<dyn Observer>],
    dir: &Path,
    key: &str,
    total: u64,
    e: anyhow::Error,
) -> anyhow::Error {
    let cx = LoopCtx {
        dir,
        key,
        total_steps: total,
        last: true,
    };
    let mut wrote = false;
    for o in observers.iter_mut().filter(|o| o.at_failure()) {
        wrote |= o.finish(model, &cx).is_ok();
    }
    if wrote {
        e.context(crate::contract::FailedRun {
            dir: dir.to_path_buf(),
        })
    } else {
        e
    }
}

/// Write the checkpoint (atomically).
pub fn save(
    model: &dyn Model,
    observers: &[Box<dyn Observer>],
    armed: &[bool],
    probed: &[Option<f64>],
    dir: &Path,
    key: &str,
) -> Result<()> {
    let ck = Checkpoint {
        format: FORMAT,
        key: key.to_string(),
        step: model.steps_done(),
        model: model.save()?,
        observers: observers
            .iter()
            .map(|o| (o.name().to_string(), o.save()))
            .collect(),
        armed: armed.to_vec(),
        probed: probed.to_vec(),
    };
    // JSON: self-describing (the engines' tagged enums need it) and exact for every finite f64
    // (NaN and infinities become null: states that can hold them say how they read it back).
    let bytes = serde_json::to_vec(&ck).context("cannot encode the checkpoint")?;
    let path = dir.join(CHECKPOINT);
    lbdem_core::atomic::write_atomic(&path, &bytes)
        .with_context(|| format!("cannot write {}", path.display()))
}

fn restore(
    model: &mut dyn Model,
    observers: &mut [Box<dyn Observer>],
    armed: &mut [bool],
    probed: &mut [Option<f64>],
    dir: &Path,
    key: &str,
) -> Result<u64> {
    let path = dir.join(CHECKPOINT);
    let bytes = std::fs::read(&path).with_context(|| {
        format!(
            "--resume: no checkpoint {} (the run was stopped before its first checkpoint); run without --resume",
            path.display()
        )
    })?;
    let ck: Checkpoint = serde_json::from_slice(&bytes).with_context(|| {
        format!(
            "checkpoint {} is damaged; delete it and run without --resume",
            path.display()
        )
    })?;
    if ck.format != FORMAT {
        bail!(
            "checkpoint {} has format {} but this lbdem writes {FORMAT}; run without --resume",
            path.display(),
            ck.format
        );
    }
    if ck.key != key {
        bail!(
            "checkpoint {} was made by a run with other parameters, inputs or code; run without --resume",
            path.display()
        );
    }
    model
        .restore(ck.model)
        .with_context(|| format!("cannot restore the model from {}", path.display()))?;
    for o in observers.iter_mut() {
        if let Some((_, v)) = ck.observers.iter().find(|(n, _)| n == o.name()) {
            o.restore(v.clone())?;
        }
    }
    if ck.armed.len() == armed.len() && ck.probed.len() == probed.len() {
        armed.copy_from_slice(&ck.armed);
        probed.copy_from_slice(&ck.probed);
    }
    eprintln!("resuming at step {} from {}", ck.step, path.display());
    Ok(ck.step)
}
