//! The runner: every stage runs through [`execute`], alone (`lbdem <stage>`, [`run_alone`]) or
//! as a step of a pipeline (`lbdem run`, [`run_file`]): a content-hash cache, atomic outputs,
//! a `stage.json` manifest and a provenance record (code version, pipeline file, SHA-256 of
//! every input, wall time of every stage). The runner calls stages; stages never call it.

mod cache;
mod key_parts;
pub mod lanes;
pub mod provenance;
pub mod schema;

use crate::contract::{
    CHECKPOINT, FailedRun, Interrupted, MANIFEST, StageContext, StageRecord, code_version,
};
use crate::registry::{self, Prepared, StageKind};
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::time::Instant;

pub use cache::{hash_file, hash_inputs};

/// The working directory of a resumable stage inside its output directory: kept when the
/// process dies or the stage is [`Interrupted`], so `--resume` can continue it.
pub const PARTIAL: &str = ".partial";

/// Stages whose page sits at the top of the pipeline's output: they write their few files
/// atomically in place instead of through a working directory.
fn writes_in_place(kind: &str) -> bool {
    kind == "report"
}

/// Hash the inputs, run the stage and write its manifest atomically.
///
/// Outputs go to a working directory inside the output directory and are moved into place
/// only when the stage succeeds: a refused or failed stage publishes nothing, and a directory the
/// run created is removed again. Resumable stages work in [`PARTIAL`], which survives a killed
/// process or an [`Interrupted`] stop (with `ctx.resume` the stage continues from it), and a run
/// that failed after it started ([`FailedRun`]: kept to be looked at, never published).
pub fn execute(prepared: Prepared, ctx: &StageContext) -> Result<StageRecord> {
    let kind = prepared.kind.clone();
    let inputs = cache::hash_inputs(&prepared.inputs)?;
    let parts = key_parts::KeyParts::now(&prepared.kind, &prepared.params_json, &inputs);
    let key = parts.key();
    // A directory that holds only an interrupted run's working directory counts as this run's:
    // a refused `--resume` that removes the working directory removes it too.
    let created = !ctx.out_dir.exists() || holds_only(&ctx.out_dir, PARTIAL);
    let staging = if writes_in_place(&prepared.kind) {
        ctx.out_dir.clone()
    } else if prepared.resumable {
        ctx.out_dir.join(PARTIAL)
    } else {
        ctx.out_dir.join(format!(".staging-{}", std::process::id()))
    };
    if ctx.resume {
        if !prepared.resumable {
            bail!(
                "stage '{}' (kind '{}') cannot be resumed: it keeps no checkpoint; run it without --resume",
                ctx.name,
                prepared.kind
            );
        }
        if !staging.is_dir() {
            bail!(
                "--resume: there is no interrupted run in {} (no {PARTIAL} directory); run without --resume \
                 to start one",
                ctx.out_dir.display()
            );
        }
    } else if prepared.resumable && staging.is_dir() {
        if !crate::contract::quiet() {
            eprintln!(
                "{:>12}  discarding the interrupted run in {} (use --resume to continue one)",
                ctx.name,
                staging.display()
            );
        }
        std::fs::remove_dir_all(&staging).with_context(|| format!("cannot remove {}", staging.display()))?;
    }
    std::fs::create_dir_all(&staging)
        .with_context(|| format!("cannot create output directory {}", staging.display()))?;
    if prepared.resumable {
        let key_file = staging.join(cache::KEY_FILE);
        let parts_file = staging.join(key_parts::KEY_PARTS_FILE);
        if ctx.resume {
            let stored = std::fs::read_to_string(&key_file).unwrap_or_default();
            if stored.trim() != key {
                let what = std::fs::read(&parts_file)
                    .ok()
                    .and_then(|b| serde_json::from_slice::<key_parts::KeyParts>(&b).ok())
                    .map(|old| old.changes(&parts, 6))
                    .filter(|c| !c.is_empty())
                    .map(|c| format!(": {}", c.join("; ")))
                    .unwrap_or_default();
                bail!(
                    "--resume: the interrupted run in {} was made with other parameters, inputs or code{what} \
                     (run key {}, now {key}); undo the change to continue it, or run without --resume to start \
                     again",
                    staging.display(),
                    stored.trim()
                );
            }
        } else {
            lbdem_core::atomic::write_atomic(&key_file, key.as_bytes())?;
            lbdem_core::atomic::write_atomic(&parts_file, &serde_json::to_vec_pretty(&parts)?)?;
        }
    }
    // What the record says: the stage continued a run only if asked to and its working
    // directory held a checkpoint to continue from (a stage asked to resume a run killed before
    // its first checkpoint starts from nothing, or refuses).
    let resumed = ctx.resume && staging.join(CHECKPOINT).is_file();
    let mut wctx = ctx.with_out_dir(staging.clone());
    wctx.key = key.clone();
    // A panic is a bug, but even then the stage leaves nothing behind: it becomes an error here
    // and the working directory is removed below.
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        run_and_record(prepared, &wctx, key, inputs, resumed)
    }))
    .unwrap_or_else(|panic| {
        let why = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        Err(anyhow::anyhow!(
            "stage '{}' (kind '{}') stopped on an internal error (a bug in lbdem; please report it with the \
             input that caused it): {why}",
            ctx.name,
            kind
        ))
    });
    // An interrupted run keeps its working directory to be resumed, a run that failed after it
    // started keeps it to be looked at; neither publishes anything.
    let kept = result.as_ref().err().is_some_and(|e| {
        e.downcast_ref::<Interrupted>().is_some() || e.downcast_ref::<FailedRun>().is_some()
    });
    if staging != ctx.out_dir {
        if result.is_ok() {
            publish(&staging, &ctx.out_dir)?;
        }
        if !kept {
            let _ = std::fs::remove_dir_all(&staging);
        }
    }
    if result.is_err() && created && !kept {
        let _ = std::fs::remove_dir(&ctx.out_dir); // only succeeds when empty
    }
    result
}

/// Whether `dir` holds exactly one entry, `name`.
fn holds_only(dir: &Path, name: &str) -> bool {
    std::fs::read_dir(dir).is_ok_and(|entries| {
        let names: Vec<_> = entries.filter_map(|e| e.ok().map(|e| e.file_name())).collect();
        names.len() == 1 && names[0] == name
    })
}

/// Move everything from `staging` into `out` (but the run key of a resumable stage),
/// replacing files and directories of the same name. The files an earlier run of the stage
/// listed and this one did not write are removed first, and the manifest moves last, so a
/// manifest never lists a file of another run.
fn publish(staging: &Path, out: &Path) -> Result<()> {
    let old: Option<StageRecord> = std::fs::read_to_string(out.join(MANIFEST))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let _ = std::fs::remove_file(out.join(MANIFEST));
    if let Some(old) = old {
        for f in &old.output.files {
            if !staging.join(f).exists() {
                let _ = std::fs::remove_file(out.join(f));
            }
        }
    }
    let mut entries: Vec<_> = std::fs::read_dir(staging)?.collect::<Result<_, _>>()?;
    entries.sort_by_key(|e| e.file_name() == MANIFEST);
    for entry in entries {
        if entry.file_name() == cache::KEY_FILE || entry.file_name() == key_parts::KEY_PARTS_FILE {
            continue;
        }
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
    inputs: Vec<crate::contract::InputHash>,
    resumed: bool,
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
        resumed,
        output,
    };
    let json = serde_json::to_vec_pretty(&record)?;
    lbdem_core::atomic::write_atomic(&ctx.out_dir.join(MANIFEST), &json)?;
    Ok(record)
}

/// One stage run alone from the command line (`lbdem radiograph`, `lbdem simulate`, ...).
pub struct Invocation {
    pub params: toml::Value,
    pub out: PathBuf,
    /// Relative paths in the parameters resolve from here.
    pub base_dir: PathBuf,
    pub resume: bool,
}

/// `lbdem <stage> ...`: one stage through [`execute`], no cache (it always runs).
pub fn run_alone(kind: &StageKind, inv: Invocation) -> Result<()> {
    let mut ctx = StageContext::new(inv.out.clone(), kind.kind.to_string(), inv.base_dir);
    ctx.resume = inv.resume;
    let prepared = kind.prepare(inv.params, &ctx)?;
    let record = execute(prepared, &ctx)?;
    eprintln!(
        "{}: wrote {} files to {} in {:.2} s",
        kind.kind,
        record.output.files.len(),
        inv.out.display(),
        record.wall_s
    );
    Ok(())
}

/// `lbdem run PIPELINE.toml`.
///
/// Every stage's parameters are parsed before anything runs or is written, so a typo in the
/// last stage fails at once instead of after the long ones. A resumable stage whose earlier
/// run was interrupted with the same parameters and inputs continues from its checkpoint.
pub fn run_file(path: &Path, force: bool, lanes: usize) -> Result<()> {
    let pipeline = schema::Pipeline::load(path)?;
    let out = pipeline.out_dir();
    run_pipeline(
        &pipeline,
        path,
        &out,
        RunOpts {
            force,
            quiet: false,
            lanes,
        },
    )?;
    Ok(())
}

/// How [`run_pipeline`] runs.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunOpts {
    /// Rerun every stage even when its key is unchanged.
    pub force: bool,
    /// Print nothing per stage (a sweep runs many pipelines side by side under one progress
    /// display).
    pub quiet: bool,
    /// Stages side by side (0 and 1: one after another): a stage starts once the stages it
    /// reads have finished ([`lanes::dependencies`]), in a pool of its share of the cores.
    pub lanes: usize,
}

/// Run `pipeline` into `out`, its provenance naming `file` (the pipeline file, or the sweep
/// file a case comes from). Returns every stage's record, in order. The cache, resume and
/// atomic outputs are those of [`run_file`]; a sweep runs each case through here.
pub fn run_pipeline(
    pipeline: &schema::Pipeline,
    file: &Path,
    out: &Path,
    opts: RunOpts,
) -> Result<Vec<StageRecord>> {
    let out = out.to_path_buf();
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
        let prepared = registry::find(&spec.kind)
            .and_then(|k| k.prepare(spec.params.clone(), &ctx))
            .with_context(|| format!("pipeline file {}", file.display()))?;
        earlier.push((spec.name.clone(), dir));
        planned.push((ctx, prepared, spec));
    }
    let created = !out.exists();
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let result = run_planned(file, pipeline, &out, planned, opts);
    if result.is_err() && created {
        // Only succeeds when empty: a failed first stage leaves no empty output directory.
        let _ = std::fs::remove_dir(&out);
    }
    result
}

/// The stages of a pipeline whose parameters are all parsed, in order, into `out`.
fn run_planned(
    file: &Path,
    pipeline: &schema::Pipeline,
    out: &Path,
    planned: Vec<(StageContext, Prepared, &schema::StageSpec)>,
    opts: RunOpts,
) -> Result<Vec<StageRecord>> {
    let out = out.to_path_buf();
    let prov = std::sync::Mutex::new(provenance::start(file, pipeline)?);
    let t_all = Instant::now();
    let say = |m: String| {
        if !opts.quiet {
            eprintln!("{m}");
        }
    };
    // The plans were only the check that every stage's parameters parse: each is prepared
    // again as it starts.
    let (ctxs, specs): (Vec<StageContext>, Vec<&schema::StageSpec>) =
        planned.into_iter().map(|(ctx, _, spec)| (ctx, spec)).unzip();
    let done = |ctx: &StageContext, record: &StageRecord| -> Result<()> {
        let mut p = prov.lock().unwrap_or_else(|e| e.into_inner());
        p.add(record, &ctx.out_dir);
        p.write(&out)
    };
    let records = if opts.lanes > 1 && specs.len() > 1 {
        side_by_side(&ctxs, &specs, opts, &say, &done)?
    } else {
        let mut records = Vec::new();
        for (ctx, spec) in ctxs.into_iter().zip(specs) {
            let record = run_stage(ctx.clone(), spec, opts, &say)?;
            done(&ctx, &record)?;
            records.push(record);
        }
        records
    };
    let mut prov = prov.into_inner().unwrap_or_else(|e| e.into_inner());
    // Stages side by side finish in any order; the record lists them in the file's.
    prov.stages
        .sort_by_key(|st| pipeline.stages.iter().position(|s| s.name == st.name));
    prov.total_wall_s = t_all.elapsed().as_secs_f64();
    prov.write(&out)?;
    say(format!(
        "pipeline '{}' finished in {:.2} s; outputs in {}",
        pipeline.name,
        prov.total_wall_s,
        out.display()
    ));
    Ok(records)
}

/// One stage of a pipeline whose earlier stages it reads have run: reused when its key is
/// unchanged, continued from an interrupted run's checkpoint, or run.
fn run_stage(
    mut ctx: StageContext,
    spec: &schema::StageSpec,
    opts: RunOpts,
    say: &(dyn Fn(String) + Sync),
) -> Result<StageRecord> {
    // Prepared now that the earlier stages have run: a stage that reads what an earlier one
    // wrote (a snapshot directory) lists those files among its inputs only now, and its key
    // must hold them the first time as on every rerun.
    let prepared = registry::find(&spec.kind)?.prepare(spec.params.clone(), &ctx)?;
    Ok(match (opts.force, cache::reusable(&prepared, &ctx)?) {
        (false, Some(mut old)) => {
            say(format!(
                "{:>12}  unchanged, skipped (ran in {:.2} s before)",
                ctx.name, old.wall_s
            ));
            old.cached = true;
            old
        }
        _ => {
            ctx.resume = prepared.resumable && cache::resumable(&prepared, &ctx)?;
            let how = if ctx.resume { "resuming" } else { "running" };
            say(format!("{:>12}  {how} ({})", ctx.name, prepared.kind));
            let r = execute(prepared, &ctx)?;
            say(format!("{:>12}  done in {:.2} s", ctx.name, r.wall_s));
            r
        }
    })
}

/// [`run_stage`] for every stage, `opts.lanes` at a time, each once the stages it reads
/// ([`lanes::dependencies`]) have finished; the first ready stage in file order takes a free
/// lane. After a failure no stage starts; those running finish, and the first error is returned.
fn side_by_side(
    ctxs: &[StageContext],
    specs: &[&schema::StageSpec],
    opts: RunOpts,
    say: &(dyn Fn(String) + Sync),
    done: &(dyn Fn(&StageContext, &StageRecord) -> Result<()> + Sync),
) -> Result<Vec<StageRecord>> {
    use std::sync::{Condvar, Mutex};
    let n = specs.len();
    let refs: Vec<&StageContext> = ctxs.iter().collect();
    let deps: Vec<Vec<usize>> = (0..n).map(|i| lanes::dependencies(specs, &refs, i)).collect();
    let lanes = opts.lanes.min(n);
    let threads = (crate::contract::cores() / lanes).max(1);
    let progress = indicatif::MultiProgress::new();
    if crate::contract::quiet() {
        progress.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    say(format!(
        "{lanes} stages side by side with {threads} thread(s) each (a stage starts once those it reads have finished)"
    ));
    struct State {
        started: Vec<bool>,
        records: Vec<Option<StageRecord>>,
        error: Option<anyhow::Error>,
    }
    let state = Mutex::new(State {
        started: vec![false; n],
        records: (0..n).map(|_| None).collect(),
        error: None,
    });
    let wake = Condvar::new();
    let lock = || state.lock().unwrap_or_else(|e| e.into_inner());
    std::thread::scope(|scope| {
        for _ in 0..lanes {
            scope.spawn(|| {
                let mut st = lock();
                loop {
                    if st.error.is_some() || st.started.iter().all(|&s| s) {
                        return;
                    }
                    let ready =
                        (0..n).find(|&i| !st.started[i] && deps[i].iter().all(|&j| st.records[j].is_some()));
                    let Some(i) = ready else {
                        st = wake.wait(st).unwrap_or_else(|e| e.into_inner());
                        continue;
                    };
                    st.started[i] = true;
                    drop(st);
                    let mut ctx = ctxs[i].clone();
                    ctx.share_progress(&progress);
                    let result = in_lane(threads, &specs[i].name, || {
                        run_stage(ctx, specs[i], opts, say).and_then(|r| done(&ctxs[i], &r).map(|_| r))
                    });
                    st = lock();
                    match result {
                        Ok(r) => st.records[i] = Some(r),
                        Err(e) => {
                            say(format!(
                                "{:>12}  failed; the stages running finish, no other starts",
                                specs[i].name
                            ));
                            if st.error.is_none() {
                                st.error = Some(e);
                            }
                        }
                    }
                    wake.notify_all();
                }
            });
        }
    });
    let st = state.into_inner().unwrap_or_else(|e| e.into_inner());
    if let Some(e) = st.error {
        return Err(e);
    }
    Ok(st.records.into_iter().flatten().collect())
}

/// `work` in a rayon pool of `threads` threads of its own. A panic outside `execute`'s own guard
/// becomes an error: left to unwind, it would leave the other lanes waiting for this stage.
fn in_lane(
    threads: usize,
    name: &str,
    work: impl FnOnce() -> Result<StageRecord> + Send,
) -> Result<StageRecord> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .context("cannot start a lane's thread pool")?
            .install(work)
    }))
    .unwrap_or_else(|_| {
        Err(anyhow::anyhow!(
            "stage '{name}' stopped on an internal error (a bug in lbdem; please report it)"
        ))
    })
}

#[cfg(test)]
mod tests;
