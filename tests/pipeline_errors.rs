//! Bad pipeline files fail with the file and the offending name in the message, before
//! anything is written.

mod common;
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
