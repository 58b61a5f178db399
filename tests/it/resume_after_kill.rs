//! A run killed part way by a real signal (SIGKILL, as a crash or a scheduler would) and then
//! continued with `lbdem simulate --resume` ends bit for bit like the uninterrupted run, for
//! every kind of scene: grains only, liquid only, and grains in a liquid. The kill lands right
//! after the first checkpoint is written; the test fails if the run had already finished.

use crate::common;
use common::run;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// Run `scene` whole into `a`; run it again into `b`, kill it after its first checkpoint, and
/// resume it; then compare `files` of both.
fn kill_and_resume(scene: &str, files: &[&str]) {
    let t = tempfile::tempdir().unwrap();
    let path = t.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    let (a, b) = (t.path().join("a"), t.path().join("b"));
    let p = path.to_str().unwrap();
    let (ok, err) = run(&["simulate", p, "--out", a.to_str().unwrap()]);
    assert!(ok, "{err}");
    start_and_kill(p, &b);
    let (ok, err) = run(&["simulate", p, "--out", b.to_str().unwrap(), "--resume"]);
    assert!(ok, "{err}");
    assert!(err.contains("resuming at step"), "{err}");
    for f in files {
        let (x, y) = (read(&a, f), read(&b, f));
        assert!(
            x == y,
            "{f} differs between the whole and the killed-and-resumed run"
        );
    }
    let manifest: serde_json::Value = serde_json::from_slice(&read(&b, "stage.json")).unwrap();
    assert_eq!(manifest["resumed"], true);
}

/// Start `lbdem simulate SCENE --out B` and SIGKILL it right after its first checkpoint.
fn start_and_kill(p: &str, b: &Path) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_lbdem"))
        .args(["simulate", p, "--out", b.to_str().unwrap()])
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let ck = b.join(".partial/checkpoint.json");
    let t0 = Instant::now();
    while !ck.exists() {
        assert!(t0.elapsed() < Duration::from_secs(120), "no checkpoint appeared");
        if let Some(s) = child.try_wait().unwrap() {
            panic!("the run ended ({s}) before its first checkpoint: make the scene longer");
        }
        std::thread::sleep(Duration::from_millis(2));
    }
    child.kill().unwrap(); // SIGKILL on Unix
    child.wait().unwrap();
    assert!(
        !b.join("stage.json").exists(),
        "the run finished before the kill: make the scene longer"
    );
}

fn read(dir: &Path, f: &str) -> Vec<u8> {
    std::fs::read(dir.join(f)).unwrap_or_else(|e| panic!("{}: {e}", dir.join(f).display()))
}

/// 80 two-circle grains settling in a box, long enough to be killed after a checkpoint.
const GRAINS: &str = r#"
[domain]
lo = [0.0, 0.0]
hi = [0.01, 0.01]
[particles]
density = 2.6
[particles.generate]
count = 80
lo = [0.0, 0.0]
hi = [0.01, 0.01]
seed = 5
templates = [ { circles = [[0.0, 0.0, 3.0e-4], [2.5e-4, 0.0, 2.5e-4]] } ]
[[walls]]
box = [0.0, 0.0, 0.01, 0.01]
[contact]
law = "linear"
k_n = 1000.0
k_t = 500.0
damping = { ratio = 0.3 }
mu = 0.5
rolling = { k_r = 1.0e-5, mu_r = 0.1 }
[dem]
dt = 4.0e-6
skin = 5.0e-5
gravity = [0.0, -9.81]
[run]
steps = 60000
[output]
series = { every = 500 }
snapshots = { every = 20000 }
checkpoints = { every = 2000 }
"#;

#[test]
fn grains_resume_bitwise_after_sigkill() {
    let scene = GRAINS;
    kill_and_resume(
        scene,
        &[
            "series.csv",
            "snapshots.csv",
            "snapshots/particles_000060000.csv",
            "snapshots/contacts_000060000.csv",
        ],
    );
}

#[test]
fn liquid_resumes_bitwise_after_sigkill() {
    let scene = r#"
[lattice]
dx = 5e-5
tau = 0.9
[domain]
lo = [0.0, 0.0]
hi = [4e-3, 2e-3]
periodic = [true, false]
[fluid]
density = 1000.0
viscosity = 1e-6
u_max = 0.015
[forcing]
acceleration = [0.02, 0.0]
[[obstacles]]
shape = "circle"
centre = [1e-3, 1e-3]
radius = 3e-4
[run]
steps = 12000
[output]
series = { every = 100 }
snapshots = { every = 4000 }
checkpoints = { every = 400 }
"#;
    kill_and_resume(
        scene,
        &["series.csv", "snapshots.csv", "snapshots/fluid_000012000.csv"],
    );
}

#[test]
fn grains_in_liquid_resume_bitwise_after_sigkill() {
    let scene =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/coupled-float.toml"))
            .unwrap()
            .replace("steps = 1000", "steps = 600")
            .replace(
                "series = { every = 50 }",
                "series = { every = 20 }\ncheckpoints = { every = 40 }",
            )
            .replace("snapshots = { every = 500 }", "snapshots = { every = 300 }");
    kill_and_resume(
        &scene,
        &[
            "series.csv",
            "snapshots.csv",
            "snapshots/fluid_000000600.csv",
            "snapshots/particles_000000600.csv",
            "snapshots/contacts_000000600.csv",
        ],
    );
}

/// Where resuming is impossible it is refused with a message, and nothing is written.
#[test]
fn resume_without_an_interrupted_run_is_refused() {
    let t = tempfile::tempdir().unwrap();
    let scene = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dry-settle.toml"))
        .unwrap();
    let path = t.path().join("s.toml");
    std::fs::write(&path, scene).unwrap();
    let out = t.path().join("out");
    let (ok, err) = run(&[
        "simulate",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--resume",
    ]);
    assert!(!ok);
    assert!(
        err.contains("no interrupted run") && err.contains("without --resume"),
        "{err}"
    );
    assert!(!out.exists(), "a refused resume left {}", out.display());
}

/// The reduced Su et al. 2020 shear cell: moving push-plate, membrane, the liquid's solid zone
/// rebuilt every LBM step (its state is in the checkpoint), shear-cell series.
#[test]
fn shear_cell_resumes_bitwise_after_sigkill() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let grains = root.join("scenes/su2020/reduced-grains.csv");
    let scene = std::fs::read_to_string(root.join("scenes/su2020/reduced-shear-cell.toml"))
        .unwrap()
        .replace(
            "\"reduced-grains.csv\"",
            &format!("{:?}", grains.to_str().unwrap()),
        )
        .replace("time = 0.2\n", "time = 0.04\n")
        .replace(
            "series = { every = 20 }",
            "series = { every = 4 }\ncheckpoints = { every = 8 }",
        );
    kill_and_resume(
        &scene,
        &[
            "series.csv",
            "snapshots/fluid_000000080.csv",
            "snapshots/particles_000000080.csv",
        ],
    );
}

/// A damaged checkpoint of a 2D dry run (a clump's circle range cut, as a truncated or edited
/// file could leave it) is refused on `--resume` with the reason, instead of the panic inside
/// the contact kernel the fuzzer found before `System::check_state` (docs/fuzzing.md).
#[test]
fn a_damaged_dry_checkpoint_is_refused_not_panicked() {
    let t = tempfile::tempdir().unwrap();
    let path = t.path().join("scene.toml");
    std::fs::write(&path, GRAINS).unwrap();
    let b = t.path().join("b");
    let p = path.to_str().unwrap();
    start_and_kill(p, &b);
    let ck = b.join(".partial/checkpoint.json");
    let mut v: serde_json::Value = serde_json::from_slice(&read(&b, ".partial/checkpoint.json")).unwrap();
    let starts = v["model"]["system"]["bodies"]["circle_start"]
        .as_array_mut()
        .expect("a dry checkpoint holds the clumps' circle ranges");
    starts.pop();
    std::fs::write(&ck, serde_json::to_vec(&v).unwrap()).unwrap();
    let (code, err) = common::run_code(None, &["simulate", p, "--out", b.to_str().unwrap(), "--resume"]);
    assert_eq!(
        code,
        Some(1),
        "refused with exit code 1, not a panic (101): {err}"
    );
    assert!(
        err.contains("inconsistent") && err.contains("circle_start"),
        "{err}"
    );
}
