//! The stage contract: what every stage is given and what it returns, and what the runner
//! records about it. This module sits at the bottom of the `lbdem` crate and imports nothing
//! from it, so that stages, scenes, the runner and the CLI can all depend on it without a loop:
//!
//! ```text
//! cli ─► pipeline (runner) ─► registry ─► stages ─► scenes ─► engine crates ─► kernels
//!   └──────────┴─────────────────┴───────────┴─────────┴──► contract (this module)
//! ```
//!
//! A stage reads files and writes files. It declares its input files (hashed for the cache
//! and provenance), runs in a directory the runner gives it, and returns a [`StageOutput`]:
//! figures and tables for the report, every file it wrote, and a JSON summary. The runner
//! wraps that in a [`StageRecord`] (the `stage.json` manifest) and a [`Provenance`] block.

use anyhow::{Context, Result};
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize, de::DeserializeOwned};
use sha2::{Digest, Sha256};
use std::io::Read;
use std::path::{Path, PathBuf};

/// The file name of a stage's manifest, in its output directory.
pub const MANIFEST: &str = "stage.json";

/// The file name of a resumable stage's checkpoint, in its working directory (`.partial`).
pub const CHECKPOINT: &str = "checkpoint.json";

/// The file name of a pipeline's provenance record, in its output directory.
pub const PROVENANCE: &str = "provenance.json";

static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Hide every run's own progress bars and notes for the rest of the process: a sweep runs many
/// cases side by side under one progress display of its own.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, std::sync::atomic::Ordering::Relaxed);
}

/// Whether runs keep their progress bars and notes to themselves ([`set_quiet`]).
pub fn quiet() -> bool {
    QUIET.load(std::sync::atomic::Ordering::Relaxed)
}

/// The cores of this machine (or of this rank's share of it): what a sweep's cases and a
/// pipeline's lanes share out.
pub fn cores() -> usize {
    std::thread::available_parallelism().map_or(1, |n| n.get())
}

/// A progress bar of `len` steps: drawn on a terminal, hidden when [`quiet`].
pub fn progress_bar(len: u64) -> ProgressBar {
    if quiet() {
        ProgressBar::hidden()
    } else {
        ProgressBar::new(len)
    }
}

/// The code version compiled in: crate version and git commit (with `-dirty`).
pub fn code_version() -> String {
    format!("{} ({})", env!("CARGO_PKG_VERSION"), env!("LBDEM_GIT_DESCRIBE"))
}

/// A unit of work that reads files and writes files; run alone from the CLI or as a step of a
/// pipeline, always through the runner (atomic outputs, manifest, provenance).
pub trait Stage {
    /// The `kind` in a pipeline file (and the subcommand name).
    const KIND: &'static str;
    /// One line for `lbdem --help`.
    const ABOUT: &'static str;
    /// Whether an interrupted run can be continued (`--resume`): its working directory is
    /// kept when the process dies or the stage stops with [`Interrupted`].
    const RESUMABLE: bool = false;
    type Params: DeserializeOwned + Serialize;
    /// Input files the stage reads (resolved), hashed for the cache and provenance.
    fn inputs(params: &Self::Params, ctx: &StageContext) -> Vec<PathBuf>;
    fn run(params: &Self::Params, ctx: &StageContext) -> Result<StageOutput>;
}

/// A resumable stage stopped on purpose before its end (a wall-clock limit): its working
/// directory and checkpoint are kept for `--resume`. Returned inside an `anyhow::Error`.
#[derive(Debug, thiserror::Error)]
#[error("{reason}; the checkpoint at step {step} is kept: rerun with --resume to continue")]
pub struct Interrupted {
    pub reason: String,
    pub step: u64,
}

/// A run that failed after it started (a blow-up the engine diagnosed): nothing is published,
/// but its working directory is kept with what it recorded until then (the series, the last
/// checkpoint), because how the failure grew is what a user needs to see: a Simulation I run that
/// blew up after 27 minutes left nothing to show where it started (docs/stability.md, "Damped
/// membrane bonds"). Returned inside an `anyhow::Error`, as context over the failure.
#[derive(Debug, thiserror::Error)]
#[error(
    "the run failed (below); what it recorded until then is kept in {} (series.csv; not published, and \
     the next run there without --resume removes it)",
    dir.display()
)]
pub struct FailedRun {
    pub dir: PathBuf,
}

/// What a stage gets besides its parameters.
#[derive(Clone)]
pub struct StageContext {
    /// Where the stage writes (the runner's working directory). Exists when `run` is called.
    pub out_dir: PathBuf,
    /// The stage's name in the pipeline (its kind when run alone).
    pub name: String,
    /// Directory of the pipeline (or params) file: relative input paths resolve from here.
    pub base_dir: PathBuf,
    /// Output directories of earlier stages of the same pipeline, by stage name.
    pub earlier: Vec<(String, PathBuf)>,
    /// The pipeline's output directory (None when the stage runs alone).
    pub pipeline_out: Option<PathBuf>,
    /// Continue from the checkpoint in `out_dir` (resumable stages only).
    pub resume: bool,
    /// The cache key of this run (resumable stages store it in their checkpoint and refuse to
    /// resume a checkpoint made with other parameters or inputs).
    pub key: String,
    progress: MultiProgress,
}

impl StageContext {
    pub fn new(out_dir: PathBuf, name: String, base_dir: PathBuf) -> Self {
        Self {
            out_dir,
            name,
            base_dir,
            earlier: Vec::new(),
            pipeline_out: None,
            resume: false,
            key: String::new(),
            progress: MultiProgress::new(),
        }
    }

    /// Draw this stage's progress bars in `progress`, beside those of stages running alongside
    /// it (`lbdem run --lanes`), instead of in a display of its own.
    pub fn share_progress(&mut self, progress: &MultiProgress) {
        self.progress = progress.clone();
    }

    /// The same context writing somewhere else (the runner's working directory).
    pub fn with_out_dir(&self, out_dir: PathBuf) -> Self {
        Self {
            out_dir,
            name: self.name.clone(),
            base_dir: self.base_dir.clone(),
            earlier: self.earlier.clone(),
            pipeline_out: self.pipeline_out.clone(),
            resume: self.resume,
            key: self.key.clone(),
            progress: self.progress.clone(),
        }
    }

    /// The pipeline's output directory, if the stage runs in a pipeline.
    pub fn pipeline_dir(&self) -> Option<&Path> {
        self.pipeline_out.as_deref()
    }

    /// A progress bar for multi-frame or multi-step work; drawn only on a terminal.
    pub fn progress_bar(&self, len: u64, message: &str) -> ProgressBar {
        let pb = self.progress.add(progress_bar(len));
        pb.set_style(
            ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} ({eta})")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        pb.set_message(message.to_string());
        pb
    }

    /// Resolve a path from the parameters against the pipeline's directory. `@name/rest` is
    /// `rest` inside the output directory of the earlier stage `name` (so a pipeline can feed one
    /// stage's files to the next wherever its output goes).
    pub fn resolve(&self, p: &Path) -> PathBuf {
        if let Some(rest) = p.to_str().and_then(|s| s.strip_prefix('@')) {
            let (name, tail) = rest.split_once('/').unwrap_or((rest, ""));
            if let Some(d) = self.earlier_stage(name) {
                return d.join(tail);
            }
        }
        if p.is_absolute() {
            p.to_path_buf()
        } else {
            self.base_dir.join(p)
        }
    }

    /// Output directory of an earlier stage of the pipeline, by name.
    pub fn earlier_stage(&self, name: &str) -> Option<&Path> {
        self.earlier
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, p)| p.as_path())
    }
}

/// A figure a stage made, path relative to the stage's output directory.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Figure {
    pub path: PathBuf,
    pub caption: String,
}

/// A table (CSV) a stage made, path relative to the stage's output directory.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Table {
    pub path: PathBuf,
    pub caption: String,
}

/// What a stage returns; the runner stores it in the stage's `stage.json` manifest.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct StageOutput {
    pub summary: serde_json::Value,
    pub figures: Vec<Figure>,
    pub tables: Vec<Table>,
    /// Every file written, relative to the stage's output directory.
    pub files: Vec<PathBuf>,
}

/// SHA-256 of one input file.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, Eq)]
pub struct InputHash {
    pub path: PathBuf,
    pub sha256: String,
    pub bytes: u64,
}

/// SHA-256 of a file (streamed): what the runner records of each input, and what a stage
/// compares with a record (a run's scene found again elsewhere).
pub fn hash_file(path: &Path) -> Result<InputHash> {
    let mut f = std::fs::File::open(path)
        .with_context(|| format!("input file {} cannot be opened", path.display()))?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    let mut bytes = 0u64;
    loop {
        let n = f
            .read(&mut buf)
            .with_context(|| format!("reading {}", path.display()))?;
        if n == 0 {
            break;
        }
        bytes += n as u64;
        h.update(&buf[..n]);
    }
    Ok(InputHash {
        path: path.to_path_buf(),
        sha256: hex::encode(h.finalize()),
        bytes,
    })
}

/// What the runner stores for one executed (or cache-hit) stage in `stage.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageRecord {
    pub name: String,
    pub kind: String,
    pub code_version: String,
    pub cache_key: String,
    pub params: serde_json::Value,
    pub inputs: Vec<InputHash>,
    pub wall_s: f64,
    /// True when this run reused the outputs of an earlier, identical run.
    #[serde(default)]
    pub cached: bool,
    /// True when the stage continued an interrupted run from its checkpoint.
    #[serde(default)]
    pub resumed: bool,
    pub output: StageOutput,
}

/// Provenance of one stage in a pipeline run.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageProvenance {
    pub name: String,
    pub kind: String,
    pub wall_s: f64,
    pub cached: bool,
    pub out_dir: PathBuf,
    pub inputs: Vec<InputHash>,
}

/// The provenance block of every report: code version, pipeline file and its hash, the SHA-256
/// of every input and the wall time of every stage.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Provenance {
    pub pipeline_name: String,
    pub code_version: String,
    pub pipeline_file: InputHash,
    /// Seconds since the Unix epoch when the run started.
    pub started_unix_s: u64,
    pub threads: usize,
    /// The instruction-set level the kernels ran with (`lbdem_core::simd`): wall times depend
    /// on it, results do not.
    #[serde(default)]
    pub simd: String,
    pub stages: Vec<StageProvenance>,
    pub total_wall_s: f64,
}

impl Provenance {
    pub fn add(&mut self, r: &StageRecord, out_dir: &Path) {
        self.stages.push(StageProvenance {
            name: r.name.clone(),
            kind: r.kind.clone(),
            wall_s: r.wall_s,
            cached: r.cached,
            out_dir: out_dir.to_path_buf(),
            inputs: r.inputs.clone(),
        });
    }

    pub fn write(&self, out: &Path) -> Result<()> {
        lbdem_core::atomic::write_atomic(&out.join(PROVENANCE), &serde_json::to_vec_pretty(self)?)?;
        Ok(())
    }

    pub fn load(out: &Path) -> Option<Self> {
        serde_json::from_str(&std::fs::read_to_string(out.join(PROVENANCE)).ok()?).ok()
    }
}
