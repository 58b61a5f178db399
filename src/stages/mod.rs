//! Stages: units of work that read files and write files, run alone from the CLI or as
//! steps of a pipeline. A stage declares its input files (for the content-hash cache and
//! provenance) and returns what it made (figures and tables for the report, a JSON
//! summary). Stages know the kernels only through their public APIs.

pub mod digitise;
pub mod radiograph;
pub mod report;
pub mod settling_study;
pub mod synth;

use anyhow::{Context, Result, bail};
use indicatif::{MultiProgress, ProgressBar, ProgressStyle};
use serde::{Deserialize, Serialize, de::DeserializeOwned};
use std::path::{Path, PathBuf};

/// What a stage gets besides its parameters.
pub struct StageContext {
    /// Where the stage writes. Exists when `run` is called.
    pub out_dir: PathBuf,
    /// The stage's name in the pipeline (its kind when run alone).
    pub name: String,
    /// Directory of the pipeline (or params) file: relative input paths resolve from here.
    pub base_dir: PathBuf,
    /// Output directories of earlier stages of the same pipeline, by stage name.
    pub earlier: Vec<(String, PathBuf)>,
    /// The pipeline's output directory (None when the stage runs alone).
    pub pipeline_out: Option<PathBuf>,
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
            progress: MultiProgress::new(),
        }
    }

    /// The same context writing somewhere else (the runner's staging directory).
    pub fn with_out_dir(&self, out_dir: PathBuf) -> Self {
        Self {
            out_dir,
            name: self.name.clone(),
            base_dir: self.base_dir.clone(),
            earlier: self.earlier.clone(),
            pipeline_out: self.pipeline_out.clone(),
            progress: self.progress.clone(),
        }
    }

    /// The pipeline's output directory, if the stage runs in a pipeline.
    pub fn pipeline_dir(&self) -> Option<&Path> {
        self.pipeline_out.as_deref()
    }

    /// A progress bar for multi-frame or multi-step work; drawn only on a terminal.
    pub fn progress_bar(&self, len: u64, message: &str) -> ProgressBar {
        let pb = self.progress.add(ProgressBar::new(len));
        pb.set_style(
            ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} ({eta})")
                .expect("static template")
                .progress_chars("=> "),
        );
        pb.set_message(message.to_string());
        pb
    }

    /// Resolve a path from the parameters against the pipeline's directory.
    pub fn resolve(&self, p: &Path) -> PathBuf {
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

/// Plot `field` as `dir/file`, and record it as a figure (with `caption`) and an output
/// file: the bookkeeping every map a stage makes needs.
pub fn field_figure(
    dir: &Path,
    file: String,
    field: ndarray::ArrayView2<f64>,
    opts: &crate::report::plot::FieldPlot,
    caption: String,
    figures: &mut Vec<Figure>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    crate::report::plot::field_png(&dir.join(&file), field, opts)?;
    figures.push(Figure {
        path: PathBuf::from(&file),
        caption,
    });
    files.push(file.into());
    Ok(())
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

pub trait Stage {
    /// The `kind` in a pipeline file and the subcommand name.
    const KIND: &'static str;
    type Params: DeserializeOwned + Serialize;
    /// Input files the stage reads (resolved), hashed for the cache and provenance.
    fn inputs(params: &Self::Params, ctx: &StageContext) -> Vec<PathBuf>;
    fn run(params: &Self::Params, ctx: &StageContext) -> Result<StageOutput>;
}

/// A stage's work, deferred until the runner decides it must run.
type RunFn = Box<dyn FnOnce(&StageContext) -> Result<StageOutput>>;

/// A stage with its parameters already parsed, ready to hash or run.
pub struct Prepared {
    pub kind: String,
    /// Canonical JSON of the parsed parameters (defaults filled in), for the cache key.
    pub params_json: serde_json::Value,
    pub inputs: Vec<PathBuf>,
    run: RunFn,
}

impl Prepared {
    /// A prepared stage from parts (the runner's own tests use this with a closure).
    #[cfg(test)]
    pub(crate) fn from_parts(
        kind: &str,
        params_json: serde_json::Value,
        inputs: Vec<PathBuf>,
        run: impl FnOnce(&StageContext) -> Result<StageOutput> + 'static,
    ) -> Self {
        Self {
            kind: kind.into(),
            params_json,
            inputs,
            run: Box::new(run),
        }
    }

    pub fn run(self, ctx: &StageContext) -> Result<StageOutput> {
        (self.run)(ctx)
    }
}

fn prepare_as<S: Stage + 'static>(params: toml::Value, ctx: &StageContext) -> Result<Prepared> {
    let p: S::Params = params
        .try_into()
        .with_context(|| format!("parameters of stage '{}' (kind '{}')", ctx.name, S::KIND))?;
    let params_json = serde_json::to_value(&p)?;
    let inputs = S::inputs(&p, ctx);
    Ok(Prepared {
        kind: S::KIND.into(),
        params_json,
        inputs,
        run: Box::new(move |c| S::run(&p, c)),
    })
}

/// Every stage kind, for error messages.
pub const KINDS: &[&str] = &[
    "synth-radiograph",
    "radiograph",
    "digitise",
    "simulate",
    "settling-study",
    "report",
];

/// Parse `params` for the stage `kind`.
pub fn prepare(kind: &str, params: toml::Value, ctx: &StageContext) -> Result<Prepared> {
    match kind {
        "synth-radiograph" => prepare_as::<synth::SynthRadiograph>(params, ctx),
        "radiograph" => prepare_as::<radiograph::Radiograph>(params, ctx),
        "digitise" => prepare_as::<digitise::Digitise>(params, ctx),
        "simulate" => prepare_as::<crate::scenes::SimulateStage>(params, ctx),
        "settling-study" => prepare_as::<settling_study::SettlingStudy>(params, ctx),
        "report" => prepare_as::<report::Report>(params, ctx),
        other => bail!("unknown stage kind '{other}'; known kinds: {}", KINDS.join(", ")),
    }
}

/// Apply `--set key=value` overrides (dotted keys reach into sub-tables).
pub fn apply_overrides(params: &mut toml::Value, sets: &[String]) -> Result<()> {
    for s in sets {
        let (key, raw) = s
            .split_once('=')
            .with_context(|| format!("--set '{s}': expected KEY=VALUE, e.g. --set rev_factor=3.16"))?;
        let value: toml::Value = match toml::from_str::<toml::Table>(&format!("v = {raw}")) {
            Ok(mut t) => t.remove("v").unwrap_or(toml::Value::String(raw.into())),
            Err(_) => toml::Value::String(raw.into()),
        };
        let mut cur = &mut *params;
        let parts: Vec<&str> = key.trim().split('.').collect();
        for (i, part) in parts.iter().enumerate() {
            let table = cur
                .as_table_mut()
                .with_context(|| format!("--set '{s}': '{part}' is inside a value that is not a table"))?;
            if i + 1 == parts.len() {
                table.insert((*part).into(), value.clone());
                break;
            }
            cur = table
                .entry(*part)
                .or_insert_with(|| toml::Value::Table(Default::default()));
        }
    }
    Ok(())
}

/// `lbdem <stage> PARAMS.toml --out DIR`: one stage, no cache.
pub fn run_standalone(kind: &str, args: &crate::cli::StageArgs) -> Result<()> {
    let text = std::fs::read_to_string(&args.params)
        .with_context(|| format!("cannot read parameter file {}", args.params.display()))?;
    let mut params: toml::Value =
        toml::from_str(&text).with_context(|| format!("{} is not valid TOML", args.params.display()))?;
    apply_overrides(&mut params, &args.set)?;
    let base = args.params.parent().map(Path::to_path_buf).unwrap_or_default();
    let ctx = StageContext::new(args.out.clone(), kind.to_string(), base);
    let prepared = prepare(kind, params, &ctx)?;
    let record = crate::pipeline::execute(prepared, &ctx)?;
    eprintln!(
        "{kind}: wrote {} files to {} in {:.2} s",
        record.output.files.len(),
        args.out.display(),
        record.wall_s
    );
    Ok(())
}
