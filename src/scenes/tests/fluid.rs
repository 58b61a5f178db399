//! Liquid only.

use super::*;

/// Water between plates 1 mm apart driven by a body acceleration g: u_mean = g H²/(12 ν)
/// (REFERENCES.md plane Poiseuille: mean = 2/3 of F H²/(8μ)); TRT Λ = 3/16 makes it exact.
pub(super) const POISEUILLE: &str = r#"
[lattice]
collision = "trt"
magic = 0.1875
dx = 5e-5
tau = 0.9
[domain]
lo = [0.0, 0.0]
hi = [2e-4, 1e-3]
periodic = [true, false]
[fluid]
density = 1000.0
viscosity = 1e-6
u_max = 0.007
[forcing]
acceleration = [0.05, 0.0]
[run]
time = 3.0
until_steady = 1e-9
[output]
series = { count = 400 }
snapshots = { count = 2 }
"#;

#[test]
fn poiseuille_scene_in_si() {
    let dir = tempfile::tempdir().unwrap();
    let rec = simulate(POISEUILLE, dir.path(), false).unwrap();
    let out = dir.path().join("out");
    let mean = rec.output.summary["last"]["mean_ux"].as_f64().unwrap();
    // the analytic parabola averaged over the 20 node rows at (j + 1/2) dx: factor 1 + dx²/(2H²)
    let want = 0.05 * 1e-6 / (12.0 * 1e-6) * (1.0 + 1.0 / (2.0 * 20.0 * 20.0));
    assert!((mean - want).abs() < 1e-6 * want, "{mean} vs {want}");
    assert!(rec.output.summary["stopped"].as_str().unwrap().contains("steady"));
    for f in ["series.csv", "stage.json", "fluid.pvd", "snapshots.csv"] {
        assert!(out.join(f).exists(), "{f}");
    }
    let vti = rec
        .output
        .files
        .iter()
        .find(|f| f.extension().is_some_and(|e| e == "vti"))
        .unwrap();
    let text = std::fs::read(out.join(vti)).unwrap();
    assert!(text.starts_with(b"<?xml") && text.windows(9).any(|w| w == b"ImageData"));
    // The fluid table of the last snapshot holds the same parabola, node by node.
    let step = rec.output.summary["steps"].as_u64().unwrap();
    let fl =
        crate::scenes::snapshot::read_fluid(&out.join(format!("snapshots/fluid_{step:09}.csv"))).unwrap();
    let mean_table = fl.ux.iter().sum::<f64>() / fl.ux.len() as f64;
    assert!((mean_table - mean).abs() < 1e-12 * mean, "{mean_table} vs {mean}");
}

#[test]
fn mach_too_high_is_refused_naming_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let s = POISEUILLE.replace("u_max = 0.007", "u_max = 2.0");
    let e = format!("{:#}", simulate(&s, dir.path(), false).unwrap_err());
    assert!(e.contains("Mach") && e.contains("0.3") && e.contains("dt"), "{e}");
    assert!(!dir.path().join("out").exists());
}

#[test]
fn unstable_run_stops_and_writes_no_report() {
    let dir = tempfile::tempdir().unwrap();
    // lattice-like SI (dx = 1 m, dt = 1 s): BGK at tau = 0.500001 driven by g = 1e-3 runs away
    let s = POISEUILLE
        .replace("collision = \"trt\"", "collision = \"bgk\"")
        .replace("dx = 5e-5", "dx = 1.0")
        .replace("tau = 0.9", "tau = 0.500001")
        .replace("hi = [2e-4, 1e-3]", "hi = [8.0, 16.0]")
        .replace("viscosity = 1e-6", "viscosity = 3.333333e-7")
        .replace("acceleration = [0.05, 0.0]", "acceleration = [1e-3, 0.0]")
        .replace("time = 3.0", "time = 100000.0");
    let e = format!("{:#}", simulate(&s, dir.path(), false).unwrap_err());
    assert!(
        e.contains("unstable at step") && e.contains("likely cause"),
        "{e}"
    );
    // Nothing published: the run's working directory alone is kept, with its series
    // (`contract::FailedRun`), and the next run there discards it.
    let out = dir.path().join("out");
    let partial = out.join(crate::pipeline::PARTIAL);
    let left = walk(&out);
    assert!(
        left.iter().all(|p| p.starts_with(&partial)) && left.contains(&partial.join("series.csv")),
        "left: {left:?}"
    );
    assert!(
        e.contains("is kept in") && e.contains(&partial.display().to_string()),
        "{e}"
    );
}

/// The in-place kernel can be saved only after an even number of steps: an interruption at an
/// odd step waits one step, and the resumed run still ends bit for bit like the whole one.
#[test]
fn interrupted_liquid_resumes_bitwise() {
    let t = tempfile::tempdir().unwrap();
    let s = POISEUILLE
        .replace("time = 3.0\nuntil_steady = 1e-9", "steps = 3001")
        .replace("series = { count = 400 }", "series = { every = 7 }");
    simulate(&s, &t.path().join("whole"), false).unwrap();
    let limited = s.replace("steps = 3001", "steps = 3001\nwall_clock = 0.005");
    let dir = t.path().join("cut");
    let interruptions = resume_until_done(&limited, &dir, 3001);
    for f in ["series.csv", "snapshots/fluid_000003001.csv"] {
        let a = std::fs::read(t.path().join("whole/out").join(f)).unwrap();
        let b = std::fs::read(dir.join("out").join(f)).unwrap();
        assert!(a == b, "{f} differs after {interruptions} interruptions");
    }
}

/// A condition on the liquid: a snapshot at the step after the mean speed first reaches half
/// its steady value (the fields are computed every step for it).
#[test]
fn snapshot_when_the_mean_speed_crosses_a_value() {
    let dir = tempfile::tempdir().unwrap();
    let half = 0.5 * 0.05 * 1e-6 / (12.0 * 1e-6);
    let s = POISEUILLE
        .replace("time = 3.0\nuntil_steady = 1e-9", "time = 1.0")
        .replace(
            "snapshots = { count = 2 }",
            &format!("snapshots = {{ when = {{ quantity = \"mean_liquid_speed\", crosses = [{half:e}] }} }}"),
        );
    let rec = simulate(&s, dir.path(), false).unwrap();
    let out = dir.path().join("out");
    let p = out.join("snapshots.csv");
    let index = crate::report::table::read_table(&p).unwrap();
    let mut steps = crate::report::table::u64_column(&index, "step", &p).unwrap();
    steps.dedup();
    let last = rec.output.summary["steps"].as_u64().unwrap();
    assert_eq!(steps.len(), 2, "{steps:?}");
    assert_eq!(steps[1], last);
    let mean = |step: u64| {
        let fl =
            crate::scenes::snapshot::read_fluid(&out.join(format!("snapshots/fluid_{step:09}.csv"))).unwrap();
        fl.ux.iter().sum::<f64>() / fl.ux.len() as f64
    };
    let at = mean(steps[0]);
    // The step after the crossing: above the value, by at most two steps' growth.
    assert!(at >= half && at < 1.05 * half, "{at} vs {half}");
    let bad = POISEUILLE.replace(
        "snapshots = { count = 2 }",
        "snapshots = { when = { quantity = \"max_grain_speed\", crosses = [1.0] } }",
    );
    let e = format!(
        "{:#}",
        simulate(&bad, &dir.path().join("bad"), false).unwrap_err()
    );
    assert!(e.contains("max_grain_speed") && e.contains("[particles]"), "{e}");
}

/// A run whose liquid goes above `[lattice] mach_warn` is named after it ends, with the step it
/// first did: the Poiseuille channel peaks at lattice Mach 0.073 (u = 6.3 mm/s at the centre,
/// 0.042 in lattice units), under the default 0.1 and above 0.05.
#[test]
fn a_run_whose_liquid_outgrew_mach_warn_is_named() {
    let t = tempfile::tempdir().unwrap();
    let quick = POISEUILLE.replace("time = 3.0", "time = 0.5");
    let rec = simulate(&quick, &t.path().join("default"), false).unwrap();
    assert_eq!(rec.output.summary["warnings"], serde_json::json!([]));
    let low = quick.replace("tau = 0.9", "tau = 0.9\nmach_warn = 0.05");
    let rec = simulate(&low, &t.path().join("low"), false).unwrap();
    let w = rec.output.summary["warnings"].to_string();
    assert!(
        w.contains("mach_warn = 0.05") && w.contains("reached 0.07"),
        "{w}"
    );
}
