//! Bad pipeline files fail with the file and the offending name in the message, before
//! anything is written.

use crate::common;
use common::run;

#[test]
fn bad_pipeline_is_named_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let path = dir.path().join("bad.toml");
    std::fs::write(
        &path,
        format!(
            "[pipeline]\nname = 'bad'\nout = '{}'\n[[stage]]\nname = 'a'\nkind = 'radiogrph'\n",
            out.display()
        ),
    )
    .unwrap();
    let (ok, err) = run(&["run", path.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("bad.toml") && err.contains("radiogrph"), "{err}");
    assert!(!out.exists());
    let (ok, err) = run(&["run", dir.path().join("missing.toml").to_str().unwrap()]);
    assert!(!ok && err.contains("missing.toml"), "{err}");
}

#[test]
fn bad_parameters_of_a_late_stage_fail_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let path = dir.path().join("late.toml");
    let text = format!(
        "[pipeline]\nname = 'late'\nout = '{}'\n[[stage]]\nname = 'r'\nkind = 'report'\n[stage.params]\ntitle = 't'\n\
         [[stage]]\nname = 'r2'\nkind = 'report'\n[stage.params]\ntitel = 'typo'\n",
        out.display()
    );
    std::fs::write(&path, text).unwrap();
    let (ok, err) = run(&["run", path.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("r2") && err.contains("titel"), "{err}");
    assert!(!out.exists(), "a stage ran before the pipeline was checked");
}

/// Regression (issue 17): a pipeline whose first stage fails at run time (its parameters parse,
/// but a region lies outside the image) left an empty output directory.
#[test]
fn a_pipeline_failing_in_its_first_stage_leaves_no_output_directory() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let repo = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{repo}/pipelines/quickstart.toml"))
        .unwrap()
        .replace("root = \"..\"", &format!("root = \"{repo}\""))
        .replace(
            "out = \"reports/quickstart\"",
            &format!("out = \"{}\"", out.display()),
        )
        .replace("i_s0_roi = [16, 8, 480, 32]", "i_s0_roi = [16, 8, 4800, 32]");
    let path = dir.path().join("p.toml");
    std::fs::write(&path, text).unwrap();
    let (ok, err) = run(&["run", path.to_str().unwrap()]);
    assert!(!ok);
    assert!(err.contains("i_s0_roi") && err.contains("outside"), "{err}");
    assert!(!out.exists(), "a failed pipeline left {}", out.display());
}

/// Regression (issue 17): `bench radiograph --reps 0` exited 0 and printed a rate as the
/// "median of 0" runs.
#[test]
fn a_benchmark_of_zero_repetitions_is_refused() {
    let (ok, err) = run(&["bench", "radiograph", "--reps", "0"]);
    assert!(!ok, "{err}");
    assert!(err.contains("--reps") && err.contains("at least 1"), "{err}");
}

/// A refusal prints its message and causes, not a stack backtrace, even under RUST_BACKTRACE=1.
#[test]
fn a_refusal_prints_no_backtrace_under_rust_backtrace() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.toml");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_lbdem"))
        .args(["run", missing.to_str().unwrap()])
        .env("RUST_BACKTRACE", "1")
        .env_remove("RUST_LIB_BACKTRACE")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("missing.toml"), "{err}");
    assert!(!err.contains("backtrace"), "{err}");
}
