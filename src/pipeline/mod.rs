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

/// Stages whose page sits at the top of the pipeline's output: they write their few
/// files atomically in place instead of through a staging directory.
fn writes_in_place(kind: &str) -> bool {
    kind == "report"
}

/// Hash the inputs, run the stage and write its manifest atomically.
///
/// Outputs go to a staging directory inside the output directory and are moved into
/// place only when the stage succeeds: a failed stage leaves nothing behind, and a
/// directory the run created is removed again.
pub fn execute(prepared: Prepared, ctx: &StageContext) -> Result<StageRecord> {
    let inputs = cache::hash_inputs(&prepared.inputs)?;
    let key = cache::cache_key(&prepared.kind, &prepared.params_json, &inputs);
    let created = !ctx.out_dir.exists();
    let staging = if writes_in_place(&prepared.kind) {
        ctx.out_dir.clone()
    } else {
        ctx.out_dir.join(format!(".staging-{}", std::process::id()))
    };
    std::fs::create_dir_all(&staging)
        .with_context(|| format!("cannot create output directory {}", staging.display()))?;
    let result = run_and_record(prepared, &ctx.with_out_dir(staging.clone()), key, inputs);
    if staging != ctx.out_dir {
        if result.is_ok() {
            publish(&staging, &ctx.out_dir)?;
        }
        let _ = std::fs::remove_dir_all(&staging);
    }
    if result.is_err() && created {
        let _ = std::fs::remove_dir(&ctx.out_dir); // only succeeds when empty
    }
    result
}

/// Move everything from `staging` into `out`, replacing files of the same name.
fn publish(staging: &Path, out: &Path) -> Result<()> {
    for entry in std::fs::read_dir(staging)? {
        let entry = entry?;
        let dest = out.join(entry.file_name());
        if dest.is_dir() {
            std::fs::remove_dir_all(&dest)?;
        }
        std::fs::rename(entry.path(), &dest)
            .with_context(|| format!("cannot move {} into {}", entry.path().display(), out.display()))?;
    }
    Ok(())
}

fn run_and_record(
    prepared: Prepared,
    ctx: &StageContext,
    key: String,
    inputs: Vec<InputHash>,
) -> Result<StageRecord> {
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
///
/// Every stage's parameters are parsed before anything runs or is written, so a typo in
/// the last stage fails at once instead of after the long ones.
pub fn run_file(path: &Path, force: bool) -> Result<()> {
    let pipeline = schema::Pipeline::load(path)?;
    let out = pipeline.out_dir();
    let mut planned = Vec::new();
    let mut earlier = Vec::new();
    for spec in &pipeline.stages {
        let dir = if writes_in_place(&spec.kind) {
            out.clone()
        } else {
            out.join(&spec.name)
        };
        let mut ctx = StageContext::new(dir.clone(), spec.name.clone(), pipeline.root.clone());
        ctx.earlier = earlier.clone();
        ctx.pipeline_out = Some(out.clone());
        let prepared = stages::prepare(&spec.kind, spec.params.clone(), &ctx)
            .with_context(|| format!("pipeline file {}", path.display()))?;
        earlier.push((spec.name.clone(), dir));
        planned.push((ctx, prepared));
    }
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let mut prov = provenance::Provenance::start(path, &pipeline)?;
    let t_all = Instant::now();
    for (ctx, prepared) in planned {
        let record = match (force, cache::reusable(&prepared, &ctx)?) {
            (false, Some(mut old)) => {
                eprintln!(
                    "{:>12}  unchanged, skipped (ran in {:.2} s before)",
                    ctx.name, old.wall_s
                );
                old.cached = true;
                old
            }
            _ => {
                eprintln!("{:>12}  running ({})", ctx.name, prepared.kind);
                let r = execute(prepared, &ctx)?;
                eprintln!("{:>12}  done in {:.2} s", ctx.name, r.wall_s);
                r
            }
        };
        prov.add(&record, &ctx.out_dir);
        prov.write(&out)?;
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

#[cfg(test)]
mod tests;
