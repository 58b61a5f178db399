//! `lbdem sweep SWEEP.toml`: a base scene or pipeline run over axes of parameters and random
//! replicas, every case through the pipeline runner in a directory of its own (so a rerun
//! skips finished cases, resumes interrupted ones and reruns what changed), side by side on
//! the cores of one machine or spread over MPI ranks (the `lbdem-mpi` binary of `crates/mpi`,
//! which drives the same cases through [`plan`], [`local`] and [`finish`]). A failed case is
//! reported and never stops the others. The declared scalar results of the finished cases make
//! the tables (CSV and Parquet, ensemble statistics over replicas) and an HTML page of charts.
//!
//! This sits above the runner (it runs pipelines) and below the CLI; stages never call it.
//! Format: docs/sweeps.md. Clusters: docs/scaling.md.

pub mod cases;
pub mod figures;
pub mod local;
pub mod progress;
pub mod results;
pub mod schema;
pub mod table;

use crate::contract::{InputHash, MANIFEST, Provenance, StageOutput, StageRecord, Table, code_version};
use anyhow::{Context, Result, bail};
use cases::Case;
use local::{CaseOpts, Outcome};
use schema::Sweep;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The command line's choices (each `None`/`false` leaves the sweep file's).
#[derive(Clone, Debug, Default)]
pub struct Args {
    pub file: PathBuf,
    pub out: Option<PathBuf>,
    pub parallel: Option<usize>,
    pub threads: Option<usize>,
    pub force: bool,
    /// Print the cases and their directories; run nothing.
    pub list: bool,
}

/// What a finished sweep found (also its `stage.json` summary).
#[derive(Debug)]
pub struct Summary {
    pub cases: usize,
    pub finished: usize,
    pub failed: usize,
    pub reused: usize,
}

/// Cases side by side and threads per case on a machine of `cores` cores: never more threads
/// in all than cores (a case's result does not depend on either number).
pub fn slots(cases: usize, cores: usize, parallel: usize, threads: usize) -> Result<(usize, usize)> {
    let cores = cores.max(1);
    let cases = cases.max(1);
    let (p, t) = match (parallel, threads) {
        (0, 0) => {
            let p = cases.min(cores);
            (p, (cores / p).max(1))
        }
        (p, 0) => (p, (cores / p).max(1)),
        (0, t) => ((cores / t).clamp(1, cases), t),
        (p, t) => (p, t),
    };
    if p * t > cores {
        bail!(
            "parallel = {p} cases × threads = {t} per case is {} threads on a machine of {cores} cores; \
             lower one of them so that parallel × threads ≤ {cores} (or leave one at 0 to have it chosen)",
            p * t
        );
    }
    Ok((p, t))
}

pub use crate::contract::cores;

/// Whether this process was started by an MPI launcher (mpirun, mpiexec, srun with PMI).
pub fn launched_by_mpi() -> bool {
    MPI_LAUNCHER_VARS.iter().any(|v| std::env::var_os(v).is_some())
}

/// What an MPI launcher sets in every rank's environment.
const MPI_LAUNCHER_VARS: [&str; 4] = ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"];

/// A sweep file read and its cases expanded, before anything runs or is written.
pub struct Plan {
    pub sweep: Sweep,
    pub out: PathBuf,
    pub cases: Vec<Case>,
}

/// Read `file` and expand its cases under `out` (default: the sweep file's own `out`).
pub fn plan(file: &Path, out: Option<PathBuf>) -> Result<Plan> {
    let sweep = Sweep::load(file)?;
    let out = out.unwrap_or_else(|| sweep.out.clone());
    let cases = cases::expand(&sweep, &out)?;
    Ok(Plan { sweep, out, cases })
}

/// `lbdem sweep`.
pub fn run(args: &Args) -> Result<Summary> {
    let t0 = Instant::now();
    let Plan { sweep, out, cases } = plan(&args.file, args.out.clone())?;
    if args.list {
        for c in &cases {
            println!("{:>5}  {}  {}", c.index, c.dir.display(), c.label());
        }
        return Ok(Summary {
            cases: cases.len(),
            finished: 0,
            failed: 0,
            reused: 0,
        });
    }
    let parallel = args.parallel.unwrap_or(sweep.parallel);
    let threads = args.threads.unwrap_or(sweep.threads);
    if launched_by_mpi() {
        bail!(
            "`lbdem sweep` was started by an MPI launcher, but it runs on one machine: every rank \
             would run every case of {}. Run the MPI binary instead, `mpirun -n N lbdem-mpi sweep {}` \
             (built by `cargo build --release -p lbdem-mpi`, which needs Open MPI: docs/scaling.md)",
            sweep.file.display(),
            args.file.display()
        );
    }
    let (parallel, threads) = slots(cases.len(), cores(), parallel, threads)
        .with_context(|| format!("sweep file {}", sweep.file.display()))?;
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    crate::contract::set_quiet(true);
    eprintln!(
        "sweep '{}': {} cases, {parallel} side by side with {threads} thread(s) each; outputs in {}",
        sweep.name,
        cases.len(),
        out.display()
    );
    let progress = progress::SweepProgress::new(cases.len(), parallel, false);
    let opts = CaseOpts {
        sweep_file: &sweep.file,
        results: &sweep.results,
        threads,
        force: args.force,
    };
    let outcomes = local::run_all(&cases, sweep.interleave, parallel, &opts, &progress);
    progress.finish();
    finish(
        &sweep,
        &out,
        &cases,
        &outcomes,
        t0.elapsed().as_secs_f64(),
        parallel * threads,
    )
}

/// Tables, charts, manifest, provenance and page of a sweep whose cases have all ended; an
/// error after writing them when a case failed (so scripts notice), naming how many.
pub fn finish(
    sweep: &Sweep,
    out: &Path,
    cases: &[Case],
    outcomes: &[Outcome],
    wall_s: f64,
    threads: usize,
) -> Result<Summary> {
    let replicas = sweep.replicas.is_some();
    let mut files = Vec::new();
    let mut tables = Vec::new();
    let mut results = table::results_frame(cases, outcomes, &sweep.results, replicas)?;
    files.extend(table::write_both(out, "results", &mut results)?);
    tables.push(Table {
        path: "results.csv".into(),
        caption: "One row per finished case: its axis values, replica and results (also results.parquet)"
            .into(),
    });
    let numeric_idx = table::numeric_results(&sweep.results, cases, outcomes);
    let numeric: Vec<(String, Option<String>)> = numeric_idx
        .iter()
        .map(|&k| (sweep.results[k].name.clone(), sweep.results[k].unit.clone()))
        .collect();
    let axes: Vec<String> = sweep.axes.iter().map(|a| a.name.clone()).collect();
    let ensemble = if replicas && results.height() > 0 {
        let names: Vec<String> = numeric.iter().map(|n| n.0.clone()).collect();
        let mut e = table::ensemble_frame(&results, &axes, &names)?;
        files.extend(table::write_both(out, "ensemble", &mut e)?);
        tables.push(Table {
            path: "ensemble.csv".into(),
            caption:
                "Per point of the axes: finished replicas n, mean, standard deviation and 95 % confidence \
                      half-width of each result (also ensemble.parquet)"
                    .into(),
        });
        Some(e)
    } else {
        None
    };
    let mut cases_df = table::cases_frame(cases, outcomes)?;
    files.extend(table::write_both(out, "cases", &mut cases_df)?);
    tables.push(Table {
        path: "cases.csv".into(),
        caption: "Every case: status, wall time, reused or resumed, and the error of a failed case".into(),
    });
    let (figures, figure_files) = figures::draw(out, &results, ensemble.as_ref(), &axes, &numeric)?;
    files.extend(figure_files);

    let failed: Vec<(&Case, &str)> = cases
        .iter()
        .zip(outcomes)
        .filter_map(|(c, o)| match o {
            Outcome::Failed { error, .. } => Some((c, error.as_str())),
            Outcome::Done { .. } => None,
        })
        .collect();
    let reused = outcomes
        .iter()
        .filter(|o| matches!(o, Outcome::Done { cached: true, .. }))
        .count();
    let finished = outcomes.iter().filter(|o| o.is_done()).count();
    let mut missing = serde_json::Map::new();
    for (k, spec) in sweep.results.iter().enumerate() {
        let n = outcomes
            .iter()
            .filter(|o| matches!(o, Outcome::Done { values, .. } if values[k].is_null()))
            .count();
        missing.insert(spec.name.clone(), serde_json::json!(n));
    }
    let warnings: Vec<String> = failed
        .iter()
        .map(|(c, e)| format!("case {} ({}) failed: {e}", c.id, c.label()))
        .collect();
    let summary = serde_json::json!({
        "sweep": sweep.name,
        "cases": cases.len(),
        "finished": finished,
        "failed": failed.len(),
        "missing_cases": cases.len() - finished,
        "reused": reused,
        "threads": threads,
        "missing_values": missing,
        "failures": failed.iter().map(|(c, e)| serde_json::json!({"case": c.id, "label": c.label(), "error": e})).collect::<Vec<_>>(),
        "warnings": warnings,
    });
    let sweep_hash = crate::pipeline::hash_file(&sweep.file)?;
    let mut inputs = vec![sweep_hash.clone()];
    let mut bases: Vec<&str> = cases.iter().map(|c| c.base.as_str()).collect();
    bases.sort_unstable();
    bases.dedup();
    for b in bases {
        if let Ok(h) = crate::pipeline::hash_file(&sweep.dir.join(b)) {
            inputs.push(h);
        }
    }
    let params = serde_json::to_value(toml::from_str::<toml::Value>(&std::fs::read_to_string(
        &sweep.file,
    )?)?)?;
    let record = StageRecord {
        name: sweep.name.clone(),
        kind: "sweep".into(),
        code_version: code_version(),
        cache_key: sweep_hash.sha256.clone(),
        params,
        inputs,
        wall_s,
        cached: false,
        resumed: false,
        output: StageOutput {
            summary,
            figures,
            tables,
            files: files.clone(),
        },
    };
    lbdem_core::atomic::write_atomic(&out.join(MANIFEST), &serde_json::to_vec_pretty(&record)?)?;
    provenance(sweep, &sweep_hash, cases, wall_s, threads).write(out)?;
    let mut ctx = crate::contract::StageContext::new(out.to_path_buf(), "report".into(), sweep.dir.clone());
    ctx.earlier = vec![(sweep.name.clone(), out.to_path_buf())];
    ctx.pipeline_out = Some(out.to_path_buf());
    use crate::contract::Stage;
    crate::stages::report::Report::run(
        &crate::stages::report::Params {
            title: format!("Sweep {}", sweep.name),
            stages: None,
            table_rows: 60,
        },
        &ctx,
    )?;
    let s = Summary {
        cases: cases.len(),
        finished,
        failed: failed.len(),
        reused,
    };
    eprintln!(
        "sweep '{}': {} of {} cases finished ({} reused from earlier runs) in {:.1} s; tables in {}, page {}",
        sweep.name,
        s.finished,
        s.cases,
        s.reused,
        wall_s,
        out.display(),
        out.join(crate::stages::report::PAGE).display()
    );
    if s.failed > 0 {
        bail!(
            "{} of {} cases failed (their errors are in {} and on the page); the tables hold the {} finished \
             cases; run the sweep again to retry the failed ones",
            s.failed,
            s.cases,
            out.join("cases.csv").display(),
            s.finished
        );
    }
    Ok(s)
}

/// The sweep's provenance: its file, and every stage of every case with its inputs' hashes.
fn provenance(sweep: &Sweep, file: &InputHash, cases: &[Case], wall_s: f64, threads: usize) -> Provenance {
    let mut stages = Vec::new();
    for c in cases {
        if let Some(p) = Provenance::load(&c.dir) {
            for mut s in p.stages {
                s.name = format!("{}/{}", c.id, s.name);
                stages.push(s);
            }
        }
    }
    Provenance {
        pipeline_name: format!("sweep {}", sweep.name),
        code_version: code_version(),
        pipeline_file: file.clone(),
        started_unix_s: std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_secs().saturating_sub(wall_s as u64)),
        threads,
        simd: lbdem_core::simd::level().name().to_string(),
        stages,
        total_wall_s: wall_s,
    }
}

#[cfg(test)]
mod tests;
