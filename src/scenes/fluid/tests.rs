//! Scene-level tests: SI set-up reproduces a known flow, outputs exist, bad set-ups are refused,
//! and an unstable run writes nothing built on it.

use super::run;
use crate::scenes::SimContext;

fn ctx(dir: &std::path::Path) -> SimContext {
    SimContext {
        out_dir: dir.to_path_buf(),
        resume: false,
        base_dir: dir.to_path_buf(),
    }
}

/// Water between plates 1 mm apart driven by a body acceleration g: u_mean = g H²/(12 ν)
/// (REFERENCES.md plane Poiseuille: mean = 2/3 of F H²/(8μ)); TRT Λ = 3/16 makes it exact.
const POISEUILLE: &str = r#"
[scene]
kind = "fluid"
[lattice]
collision = "trt"
magic = 0.1875
dx = 5e-5
tau = 0.9
[domain]
size = [2e-4, 1e-3]
[fluid]
density = 1000.0
viscosity = 1e-6
u_max = 0.007
[boundaries]
y_min = { type = "wall" }
y_max = { type = "wall" }
[forcing]
acceleration = [0.05, 0.0]
[stop]
time = 3.0
steady_tol = 1e-9
[output]
samples = 400
snapshots = 2
"#;

#[test]
fn poiseuille_scene_in_si() {
    let dir = tempfile::tempdir().unwrap();
    let v: toml::Value = toml::from_str(POISEUILLE).unwrap();
    let out = run(&v, &ctx(dir.path())).unwrap();
    let mean = out.summary["final"]["mean_u"][0].as_f64().unwrap();
    // the analytic parabola averaged over the 20 node rows at (j + 1/2) dx: factor 1 + dx²/(2H²)
    let want = 0.05 * 1e-6 / (12.0 * 1e-6) * (1.0 + 1.0 / (2.0 * 20.0 * 20.0));
    assert!((mean - want).abs() < 1e-6 * want, "{mean} vs {want}");
    for f in ["series.csv", "series.json", "summary.json", "fluid.pvd"] {
        assert!(dir.path().join(f).exists(), "{f}");
    }
    let vti = out
        .files
        .iter()
        .find(|f| f.extension().is_some_and(|e| e == "vti"))
        .unwrap();
    let text = std::fs::read(dir.path().join(vti)).unwrap();
    assert!(text.starts_with(b"<?xml") && text.windows(9).any(|w| w == b"ImageData"));
}

#[test]
fn mach_too_high_is_refused_naming_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let s = POISEUILLE.replace("u_max = 0.007", "u_max = 2.0");
    let v: toml::Value = toml::from_str(&s).unwrap();
    let e = format!("{:#}", run(&v, &ctx(dir.path())).unwrap_err());
    assert!(e.contains("Mach") && e.contains("0.3") && e.contains("dt"), "{e}");
}

#[test]
fn unstable_run_stops_and_writes_no_report() {
    let dir = tempfile::tempdir().unwrap();
    // lattice-like SI (dx = 1 m, dt = 1 s): BGK at tau = 0.500001 driven by g = 1e-3 runs away
    let s = POISEUILLE
        .replace("collision = \"trt\"", "collision = \"bgk\"")
        .replace("dx = 5e-5", "dx = 1.0")
        .replace("tau = 0.9", "tau = 0.500001")
        .replace("size = [2e-4, 1e-3]", "size = [8.0, 16.0]")
        .replace("viscosity = 1e-6", "viscosity = 3.333333e-7")
        .replace("acceleration = [0.05, 0.0]", "acceleration = [1e-3, 0.0]")
        .replace("time = 3.0", "time = 100000.0");
    let v: toml::Value = toml::from_str(&s).unwrap();
    let e = format!("{:#}", run(&v, &ctx(dir.path())).unwrap_err());
    assert!(
        e.contains("unstable at step") && e.contains("likely cause"),
        "{e}"
    );
    for f in ["series.csv", "series.json", "summary.json", "fluid.pvd"] {
        assert!(!dir.path().join(f).exists(), "{f} written after a failed run");
    }
    let left = std::fs::read_dir(dir.path().join("fields")).unwrap().count();
    assert_eq!(left, 0);
}
