//! Pipelines: an ordered list of stages in a TOML file, run with a content-hash cache
//! and a provenance record (code version, pipeline file, SHA-256 of every input, wall
//! time of every stage).

mod cache;
pub mod provenance;
pub mod schema;

use crate::stages::{self, Prepared, StageContext, StageOutput};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

pub use cache::{InputHash, hash_file};

/// The code version compiled in: crate version and git commit (with `-dirty`).
pub fn code_version() -> String {
    format!("{} ({})", env!("CARGO_PKG_VERSION"), env!("LBDEM_GIT_DESCRIBE"))
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
    pub output: StageOutput,
}

pub const MANIFEST: &str = "stage.json";

/// Hash the inputs, run the stage and write its manifest atomically.
pub fn execute(prepared: Prepared, ctx: &StageContext) -> Result<StageRecord> {
    let inputs = cache::hash_inputs(&prepared.inputs)?;
    let key = cache::cache_key(&prepared.kind, &prepared.params_json, &inputs);
    std::fs::create_dir_all(&ctx.out_dir)
        .with_context(|| format!("cannot create output directory {}", ctx.out_dir.display()))?;
    let (kind, params) = (prepared.kind.clone(), prepared.params_json.clone());
    let t0 = Instant::now();
    let output = prepared
        .run(ctx)
        .with_context(|| format!("stage '{}' (kind '{kind}') failed", ctx.name))?;
    let record = StageRecord {
        name: ctx.name.clone(),
        kind,
        code_version: code_version(),
        cache_key: key,
        params,
        inputs,
        wall_s: t0.elapsed().as_secs_f64(),
        cached: false,
        output,
    };
    let json = serde_json::to_vec_pretty(&record)?;
    lbdem_core::atomic::write_atomic(&ctx.out_dir.join(MANIFEST), &json)?;
    Ok(record)
}

/// `lbdem run PIPELINE.toml`.
pub fn run_file(path: &Path, force: bool) -> Result<()> {
    let pipeline = schema::Pipeline::load(path)?;
    let out = pipeline.out_dir();
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let mut prov = provenance::Provenance::start(path, &pipeline)?;
    let mut earlier = Vec::new();
    let t_all = Instant::now();
    for spec in &pipeline.stages {
        let mut ctx = StageContext::new(out.join(&spec.name), spec.name.clone(), pipeline.root.clone());
        ctx.earlier = earlier.clone();
        let prepared = stages::prepare(&spec.kind, spec.params.clone(), &ctx)?;
        let record = match (force, cache::reusable(&prepared, &ctx)?) {
            (false, Some(mut old)) => {
                eprintln!(
                    "{:>12}  unchanged, skipped (ran in {:.2} s before)",
                    spec.name, old.wall_s
                );
                old.cached = true;
                old
            }
            _ => {
                eprintln!("{:>12}  running ({})", spec.name, spec.kind);
                let r = execute(prepared, &ctx)?;
                eprintln!("{:>12}  done in {:.2} s", spec.name, r.wall_s);
                r
            }
        };
        prov.add(&record, &ctx.out_dir);
        prov.write(&out)?;
        earlier.push((spec.name.clone(), ctx.out_dir.clone()));
    }
    prov.total_wall_s = t_all.elapsed().as_secs_f64();
    prov.write(&out)?;
    eprintln!(
        "pipeline '{}' finished in {:.2} s; outputs in {}",
        pipeline.name,
        prov.total_wall_s,
        out.display()
    );
    Ok(())
}
