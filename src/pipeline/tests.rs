//! The runner's contracts: outputs appear only on success, unchanged stages are skipped,
//! any change to inputs, parameters or outputs reruns them.

use super::*;
use crate::contract::{MANIFEST, StageContext, StageOutput, StageRecord};
use crate::registry::Prepared;
use std::path::{Path, PathBuf};

fn writer_stage(input: PathBuf, param: i64, fail: bool) -> Prepared {
    Prepared::from_parts(
        "test",
        serde_json::json!({ "p": param }),
        vec![input],
        move |ctx: &StageContext| {
            lbdem_core::atomic::write_atomic(&ctx.out_dir.join("a.txt"), b"payload")?;
            if fail {
                anyhow::bail!("parameter p = {param} is invalid");
            }
            Ok(StageOutput {
                files: vec!["a.txt".into()],
                ..Default::default()
            })
        },
    )
}

fn setup() -> (tempfile::TempDir, PathBuf, StageContext) {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.dat");
    std::fs::write(&input, b"input bytes").unwrap();
    let ctx = StageContext::new(dir.path().join("out/stage"), "s".into(), dir.path().into());
    (dir, input, ctx)
}

#[test]
fn success_publishes_outputs_and_manifest() {
    let (_d, input, ctx) = setup();
    let rec = execute(writer_stage(input.clone(), 1, false), &ctx).unwrap();
    assert_eq!(std::fs::read(ctx.out_dir.join("a.txt")).unwrap(), b"payload");
    assert!(ctx.out_dir.join(MANIFEST).is_file());
    assert_eq!(rec.inputs.len(), 1);
    assert_eq!(rec.inputs[0].bytes, 11);
    // No staging directory is left behind.
    let left: Vec<_> = std::fs::read_dir(&ctx.out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "unexpected files: {left:?}");
}

#[test]
fn failure_writes_nothing() {
    let (_d, input, ctx) = setup();
    let err = execute(writer_stage(input, 7, true), &ctx).unwrap_err();
    assert!(format!("{err:#}").contains("p = 7"), "{err:#}");
    assert!(
        !ctx.out_dir.exists(),
        "a failed stage left {}",
        ctx.out_dir.display()
    );
}

#[test]
fn failure_keeps_earlier_good_outputs() {
    let (_d, input, ctx) = setup();
    execute(writer_stage(input.clone(), 1, false), &ctx).unwrap();
    assert!(execute(writer_stage(input, 2, true), &ctx).is_err());
    assert_eq!(std::fs::read(ctx.out_dir.join("a.txt")).unwrap(), b"payload");
    let rec: StageRecord =
        serde_json::from_slice(&std::fs::read(ctx.out_dir.join(MANIFEST)).unwrap()).unwrap();
    assert_eq!(rec.params["p"], 1);
}

#[test]
fn cache_hits_only_when_nothing_changed() {
    let (_d, input, ctx) = setup();
    assert!(
        cache::reusable(&writer_stage(input.clone(), 1, false), &ctx)
            .unwrap()
            .is_none()
    );
    execute(writer_stage(input.clone(), 1, false), &ctx).unwrap();
    assert!(
        cache::reusable(&writer_stage(input.clone(), 1, false), &ctx)
            .unwrap()
            .is_some()
    );
    // A parameter change misses.
    assert!(
        cache::reusable(&writer_stage(input.clone(), 2, false), &ctx)
            .unwrap()
            .is_none()
    );
    // An input byte change misses.
    std::fs::write(&input, b"input bytez").unwrap();
    assert!(
        cache::reusable(&writer_stage(input.clone(), 1, false), &ctx)
            .unwrap()
            .is_none()
    );
    std::fs::write(&input, b"input bytes").unwrap();
    assert!(
        cache::reusable(&writer_stage(input.clone(), 1, false), &ctx)
            .unwrap()
            .is_some()
    );
    // A deleted output misses.
    std::fs::remove_file(ctx.out_dir.join("a.txt")).unwrap();
    assert!(
        cache::reusable(&writer_stage(input, 1, false), &ctx)
            .unwrap()
            .is_none()
    );
}

#[test]
fn missing_input_is_named() {
    let (d, _input, ctx) = setup();
    let missing = d.path().join("nope.tif");
    let err = execute(writer_stage(missing, 1, false), &ctx).unwrap_err();
    assert!(format!("{err:#}").contains("nope.tif"), "{err:#}");
    assert!(!ctx.out_dir.exists());
}

#[test]
fn schema_rejects_duplicates_and_unknown_kinds() {
    let p = std::path::Path::new("pipelines/x.toml");
    let dup = "[pipeline]\nname='x'\nout='o'\n[[stage]]\nname='a'\nkind='report'\n[[stage]]\nname='a'\nkind='report'\n";
    let e = schema::Pipeline::parse(dup, p).unwrap_err();
    assert!(format!("{e:#}").contains("two stages are named 'a'"), "{e:#}");
    let unk = "[pipeline]\nname='x'\nout='o'\n[[stage]]\nname='a'\nkind='radiogrph'\n";
    let e = schema::Pipeline::parse(unk, p).unwrap_err();
    assert!(format!("{e:#}").contains("unknown kind 'radiogrph'"), "{e:#}");
    let ok = "[pipeline]\nname='x'\nroot='..'\nout='reports/x'\n[[stage]]\nname='a'\nkind='report'\n";
    let pl = schema::Pipeline::parse(ok, p).unwrap();
    assert_eq!(pl.out_dir(), PathBuf::from("pipelines/../reports/x"));
}

/// `@name/...` must name a stage above the one that reads it: a typo, a later stage or the
/// stage itself is refused when the file is read, naming the key and the stages there are.
#[test]
fn an_at_reference_to_no_earlier_stage_is_refused_before_anything_runs() {
    let p = std::path::Path::new("pipelines/x.toml");
    let head = "[pipeline]\nname='x'\nout='o'\n[[stage]]\nname='synth'\nkind='report'\n";
    let good = format!("{head}[[stage]]\nname='r'\nkind='report'\n[stage.params]\nx = ['@synth/frames']\n");
    schema::Pipeline::parse(&good, p).unwrap();
    for (bad, name) in [("@synht/frames", "synht"), ("@r", "r"), ("@later/x", "later")] {
        let text = format!(
            "{head}[[stage]]\nname='r'\nkind='report'\n[stage.params]\nsection = {{ frames = ['{bad}'] }}\n\
             [[stage]]\nname='later'\nkind='report'\n"
        );
        let e = format!("{:#}", schema::Pipeline::parse(&text, p).unwrap_err());
        assert!(
            e.contains(&format!("params.section.frames[0] = \"{bad}\""))
                && e.contains(&format!("a stage '{name}'"))
                && e.contains("earlier stages: synth"),
            "{e}"
        );
    }
}

/// A rerun that writes fewer files removes those of the earlier run (they would otherwise sit
/// beside a manifest that does not list them), and leaves files it never owned alone.
#[test]
fn rerun_removes_the_earlier_runs_files_it_did_not_write_again() {
    let (_d, input, ctx) = setup();
    let stage = |names: &'static [&'static str]| {
        Prepared::from_parts(
            "test",
            serde_json::json!({}),
            vec![input.clone()],
            move |c: &StageContext| {
                for n in names {
                    lbdem_core::atomic::write_atomic(&c.out_dir.join(n), b"x")?;
                }
                Ok(StageOutput {
                    files: names.iter().map(PathBuf::from).collect(),
                    ..Default::default()
                })
            },
        )
    };
    execute(stage(&["a.txt", "b.txt"]), &ctx).unwrap();
    std::fs::write(ctx.out_dir.join("notes.md"), b"mine").unwrap();
    execute(stage(&["a.txt"]), &ctx).unwrap();
    assert!(ctx.out_dir.join("a.txt").is_file());
    assert!(
        !ctx.out_dir.join("b.txt").exists(),
        "a file of the earlier run stayed"
    );
    assert!(
        ctx.out_dir.join("notes.md").is_file(),
        "a file the stage never wrote was removed"
    );
    let rec: StageRecord =
        serde_json::from_str(&std::fs::read_to_string(ctx.out_dir.join(MANIFEST)).unwrap()).unwrap();
    assert_eq!(rec.output.files, vec![PathBuf::from("a.txt")]);
}

/// A stage that panics (a bug) still leaves nothing behind: the panic becomes an error that
/// says it is one, and the working directory and the output directory it created are removed.
#[test]
fn a_panicking_stage_becomes_an_error_and_leaves_nothing_behind() {
    let (_d, input, ctx) = setup();
    let p = Prepared::from_parts(
        "test",
        serde_json::json!({}),
        vec![input],
        |ctx: &StageContext| {
            std::fs::create_dir_all(ctx.out_dir.join("snapshots"))?;
            let v: Vec<u8> = Vec::new();
            let _ = v[std::hint::black_box(3)];
            Ok(StageOutput::default())
        },
    );
    let e = format!("{:#}", execute(p, &ctx).unwrap_err());
    assert!(
        e.contains("internal error") && e.contains("index out of bounds"),
        "{e}"
    );
    assert!(
        !ctx.out_dir.exists(),
        "left {:?}",
        std::fs::read_dir(&ctx.out_dir).map(|d| d.count())
    );
}

/// `resumed` in the record says whether the stage continued a run, not whether it was asked
/// to: asked to resume a run killed before its first checkpoint (its working directory holds
/// the run key and nothing else), a stage starts from nothing and the record says false; with a
/// checkpoint there, true.
#[test]
fn resumed_is_recorded_only_when_there_was_a_checkpoint_to_continue() {
    let (_d, input, mut ctx) = setup();
    let stage = || resumable_stage(&input, serde_json::json!({}), false);
    ctx.resume = true;
    let interrupted = |checkpoint| interrupted_run(&ctx, &input, serde_json::json!({}), checkpoint);
    let on_disk = |ctx: &StageContext| -> StageRecord {
        serde_json::from_slice(&std::fs::read(ctx.out_dir.join(MANIFEST)).unwrap()).unwrap()
    };
    interrupted(false);
    let rec = execute(stage(), &ctx).unwrap();
    assert!(
        !rec.resumed && !on_disk(&ctx).resumed,
        "a fresh run recorded as resumed"
    );
    interrupted(true);
    let rec = execute(stage(), &ctx).unwrap();
    assert!(
        rec.resumed && on_disk(&ctx).resumed,
        "a resumed run recorded as fresh"
    );
}

/// A resumable test stage with parameters `params` that writes `a.txt`, or fails.
fn resumable_stage(input: &Path, params: serde_json::Value, fail: bool) -> Prepared {
    let mut p = Prepared::from_parts(
        "test",
        params,
        vec![input.to_path_buf()],
        move |c: &StageContext| {
            if fail {
                anyhow::bail!("the stage refused its input");
            }
            lbdem_core::atomic::write_atomic(&c.out_dir.join("a.txt"), b"x")?;
            Ok(StageOutput {
                files: vec!["a.txt".into()],
                ..Default::default()
            })
        },
    );
    p.resumable = true;
    p
}

/// An interrupted run as `execute` leaves one: its working directory with the run key, what the
/// key was made of, and (if the run got that far) a checkpoint.
fn interrupted_run(ctx: &StageContext, input: &Path, params: serde_json::Value, checkpoint: bool) {
    let partial = ctx.out_dir.join(PARTIAL);
    std::fs::create_dir_all(&partial).unwrap();
    let inputs = cache::hash_inputs(&[input.to_path_buf()]).unwrap();
    std::fs::write(
        partial.join(cache::KEY_FILE),
        cache::cache_key("test", &params, &inputs),
    )
    .unwrap();
    let parts = key_parts::KeyParts::now("test", &params, &inputs);
    std::fs::write(
        partial.join(key_parts::KEY_PARTS_FILE),
        serde_json::to_vec(&parts).unwrap(),
    )
    .unwrap();
    if checkpoint {
        std::fs::write(partial.join(CHECKPOINT), b"{}").unwrap();
    }
}

/// `--resume` of a run made with another parameter or input says which, and keeps the
/// interrupted run for a resume with the change undone.
#[test]
fn a_refused_resume_names_the_parameter_and_the_input_that_changed() {
    let (_d, input, mut ctx) = setup();
    interrupted_run(&ctx, &input, serde_json::json!({"set": {"run.time": 1.0}}), true);
    ctx.resume = true;
    let stage = |time: f64| resumable_stage(&input, serde_json::json!({"set": {"run.time": time}}), false);
    let refusal = |time: f64| format!("{:#}", execute(stage(time), &ctx).unwrap_err());
    let e = refusal(2.0);
    assert!(e.contains("parameter set.run.time (1.0 → 2.0)"), "{e}");
    assert!(!e.contains("in.dat"), "{e}");
    std::fs::write(&input, b"other bytes").unwrap();
    let e = refusal(1.0);
    assert!(
        e.contains("in.dat changed") && !e.contains("parameter set"),
        "{e}"
    );
    assert!(
        ctx.out_dir.join(PARTIAL).join(CHECKPOINT).is_file(),
        "the interrupted run was lost"
    );
    // With the change undone it continues, and its key files are not published.
    std::fs::write(&input, b"input bytes").unwrap();
    let rec = execute(stage(1.0), &ctx).unwrap();
    assert!(rec.resumed);
    assert!(!ctx.out_dir.join(key_parts::KEY_PARTS_FILE).exists());
    assert!(!ctx.out_dir.join(cache::KEY_FILE).exists());
}

/// A failing resume of a run killed before its first checkpoint (its output directory holds
/// only the working directory) leaves no empty output directory behind.
#[test]
fn a_failed_resume_of_a_run_without_a_checkpoint_leaves_no_directory() {
    let (_d, input, mut ctx) = setup();
    let params = serde_json::json!({});
    interrupted_run(&ctx, &input, params.clone(), false);
    ctx.resume = true;
    assert!(execute(resumable_stage(&input, params, true), &ctx).is_err());
    assert!(!ctx.out_dir.exists(), "an empty output directory was left behind");
}

/// What `lbdem run --lanes` waits for, on the quickstart pipeline: a stage waits for the stages
/// its parameters name (by name, `@name/...` or `from_stage`), the report for all before it,
/// and the shear run for nothing.
#[test]
fn a_stage_waits_for_the_stages_it_names() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("pipelines/quickstart.toml");
    let p = schema::Pipeline::load(&path).unwrap();
    let out = p.out_dir();
    let mut earlier = Vec::new();
    let ctxs: Vec<StageContext> = p
        .stages
        .iter()
        .map(|s| {
            let mut c = StageContext::new(out.join(&s.name), s.name.clone(), p.root.clone());
            c.earlier = earlier.clone();
            earlier.push((s.name.clone(), out.join(&s.name)));
            c
        })
        .collect();
    let specs: Vec<_> = p.stages.iter().collect();
    let refs: Vec<_> = ctxs.iter().collect();
    let names = |i: usize| -> Vec<&str> {
        lanes::dependencies(&specs, &refs, i)
            .into_iter()
            .map(|j| specs[j].name.as_str())
            .collect()
    };
    let at = |n: &str| specs.iter().position(|s| s.name == n).unwrap();
    assert_eq!(names(at("radiograph")), Vec::<&str>::new());
    assert_eq!(names(at("digitise")), ["radiograph"]);
    assert_eq!(names(at("shear")), Vec::<&str>::new());
    assert_eq!(names(at("analyse")), ["shear"]);
    assert_eq!(names(at("run-radiograph-maps")), ["run-radiographs"]);
    assert_eq!(names(at("compare")), ["shear", "run-radiograph-maps"]);
    assert_eq!(names(at("report")).len(), specs.len() - 1);
}
