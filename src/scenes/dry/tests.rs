//! Scene-level tests: a run killed after a checkpoint and resumed ends bit for bit like the
//! uninterrupted run; the digitise CSV format is read with its JSON header.

use super::super::SimContext;
use std::path::Path;

const SCENE: &str = r#"
[scene]
kind = "dry"
[domain]
lo = [0.0, 0.0]
hi = [0.01, 0.01]
[particles]
density = 2.6
[particles.generate]
count = 60
lo = [0.0, 0.0]
hi = [0.01, 0.01]
seed = 3
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
[step]
dt = 4.0e-6
skin = 5.0e-5
gravity = { x = 0.0, y = -9.81 }
[run]
steps = 3000
output_every = 100
checkpoint_every = 1000
"#;

fn run(text: &str, dir: &Path, resume: bool) -> anyhow::Result<crate::stages::StageOutput> {
    let v: toml::Value = toml::from_str(text)?;
    super::run(
        &v,
        &SimContext {
            out_dir: dir.to_path_buf(),
            resume,
            base_dir: dir.to_path_buf(),
        },
    )
}

#[test]
fn resumed_run_matches_uninterrupted_bitwise() {
    let t = tempfile::tempdir().unwrap();
    let (a, b) = (t.path().join("whole"), t.path().join("killed"));
    run(SCENE, &a, false).unwrap();
    let killed = SCENE.replace(
        "checkpoint_every = 1000",
        "checkpoint_every = 1000\nstop_after_steps_for_test = 2500",
    );
    assert!(
        run(&killed, &b, false).is_err(),
        "the simulated interruption must stop the run"
    );
    run(SCENE, &b, true).unwrap();
    let load = |d: &Path| {
        lbdem_dem::System::from_checkpoint(&std::fs::read(d.join("final_state.json")).unwrap()).unwrap()
    };
    let (fa, fb) = (load(&a), load(&b));
    // Bodies, walls and clock bit for bit (the candidate-pair list may differ in pairs that do
    // not touch, which carry no force and no history).
    assert!(fa.bodies == fb.bodies && fa.walls == fb.walls && fa.step == fb.step && fa.time == fb.time);
    let touching = |s: &lbdem_dem::System| -> Vec<_> {
        s.contacts
            .pairs_with_history()
            .map(|(p, h)| (p, h.to_vec()))
            .collect()
    };
    assert_eq!(touching(&fa), touching(&fb));
    let sa = std::fs::read(a.join("series.csv")).unwrap();
    let sb = std::fs::read(b.join("series.csv")).unwrap();
    assert!(sa == sb, "resumed time series differs");
}

#[test]
fn reads_digitised_circles_in_pixels() {
    let t = tempfile::tempdir().unwrap();
    let csv = t.path().join("grains.csv");
    std::fs::write(&csv, "grain_id,x,y,r\n0,10,10,4\n0,14,10,3\n1,30,30,5\n").unwrap();
    std::fs::write(
        t.path().join("grains.json"),
        r#"{"units": "px", "pixel_size": 1.0e-5}"#,
    )
    .unwrap();
    let b = super::particles::read_csv(&csv, 2.6).unwrap();
    assert_eq!(b.len(), 2);
    assert_eq!(b.n_circles(), 3);
    assert!((b.circle_r[2] - 5e-5).abs() < 1e-18);
    // The second grain is a single disk at (30, 30) px.
    assert!((b.pos[1].x - 3e-4).abs() < 1e-15 && (b.pos[1].y - 3e-4).abs() < 1e-15);
    std::fs::write(&csv, "grain_id,x,y\n0,1,1\n").unwrap();
    let err = super::particles::read_csv(&csv, 2.6).unwrap_err().to_string();
    assert!(err.contains("no column \"r\""), "{err}");
}
