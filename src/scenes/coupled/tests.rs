//! Scene-level tests: the example runs and writes its outputs, the physics points the right way,
//! both methods and both precisions run, and bad set-ups are refused before anything is written.

use super::run;
use crate::scenes::SimContext;

fn ctx(dir: &std::path::Path) -> SimContext {
    SimContext {
        out_dir: dir.to_path_buf(),
        resume: false,
        base_dir: dir.to_path_buf(),
    }
}

/// The shipped example with `edit` applied to its text.
fn example(edit: impl Fn(String) -> String) -> toml::Value {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/coupled-float.toml")).unwrap();
    toml::from_str(&edit(text)).unwrap()
}

fn short(t: String) -> String {
    t.replace("steps = 1000", "steps = 60")
        .replace("snapshot_every = 500", "snapshot_every = 30")
}

#[test]
fn float_example_runs_and_the_liquid_resists_the_rise() {
    let dir = tempfile::tempdir().unwrap();
    let out = run(&example(short), &ctx(dir.path())).unwrap();
    for f in [
        "series.csv",
        "series.json",
        "summary.json",
        "fluid.pvd",
        "particles.pvd",
        "pressure_change.png",
        "fields/fluid_00000030.vti",
        "fields/particles_00000060.vtp",
    ] {
        assert!(dir.path().join(f).exists(), "{f} missing");
    }
    let last = &out.summary["last"];
    // Grains lighter than the liquid rise; the liquid's drag on them points down.
    assert!(last["momentum"][1].as_f64().unwrap() > 0.0);
    assert!(last["hydro_force"][1].as_f64().unwrap() < 0.0);
    let share = &out.summary["time_share"];
    let sum: f64 = ["lbm", "dem", "coupling"]
        .iter()
        .map(|k| share[k].as_f64().unwrap())
        .sum();
    assert!((sum - 1.0).abs() < 1e-9);
    assert_eq!(out.summary["dem_steps_per_lbm_step"], 40);
}

#[test]
fn bounce_back_and_f32_run_the_same_scene() {
    for (method, precision) in [("bounce-back", "f64"), ("psm", "f32")] {
        let dir = tempfile::tempdir().unwrap();
        let v = example(|t| {
            // tau = 0.67: bounce-back is unstable at the example's 0.567 (see the next test).
            short(t)
                .replace("dt = 5.6e-5", "dt = 1.4e-4")
                .replace("method = \"psm\"", &format!("method = \"{method}\""))
                .replace("precision = \"f64\"", &format!("precision = \"{precision}\""))
        });
        let out = run(&v, &ctx(dir.path())).unwrap();
        assert!(
            out.summary["last"]["hydro_force"][1].as_f64().unwrap() < 0.0,
            "{method} {precision}"
        );
    }
}

#[test]
fn non_integer_time_step_ratio_is_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let v = example(|t| t.replace("dt = 1.4e-6", "dt = 1.5e-6"));
    let e = run(&v, &ctx(&out_dir)).unwrap_err().to_string();
    assert!(e.contains("37.33") && e.contains("whole number"), "{e}");
    assert!(!out_dir.exists());
}

/// Where a method fails: at tau = 0.567 moving bounce-back with refilling blows up within 60
/// LBM steps on the example while PSM runs it; the failure names the step, the node and the
/// cause, and leaves none of the run's files behind.
#[test]
fn bounce_back_failure_is_diagnosed_and_leaves_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let v = example(|t| short(t).replace("method = \"psm\"", "method = \"bounce-back\""));
    let e = format!("{:#}", run(&v, &ctx(dir.path())).unwrap_err());
    assert!(
        e.contains("unstable at step") && e.contains("node") && e.contains("Mach"),
        "{e}"
    );
    let left: Vec<_> = walk(dir.path());
    assert!(left.is_empty(), "left behind: {left:?}");
    assert!(run(&example(short), &ctx(&dir.path().join("psm"))).is_ok());
}

fn walk(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        if e.path().is_dir() {
            out.extend(walk(&e.path()));
        } else {
            out.push(e.path());
        }
    }
    out
}

#[test]
fn zero_viscosity_is_refused_naming_the_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let v = example(|t| t.replace("dynamic_viscosity = 1.82e-3", "dynamic_viscosity = 0.0"));
    let out_dir = dir.path().join("out");
    let e = format!("{:#}", run(&v, &ctx(&out_dir)).unwrap_err());
    assert!(e.contains("viscosity = 0") && e.contains("[fluid]"), "{e}");
    assert!(!out_dir.exists());
}

#[test]
fn zero_output_interval_and_moving_walls_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let v = example(|t| t.replace("output_every = 50", "output_every = 0"));
    let e = format!("{:#}", run(&v, &ctx(&out_dir)).unwrap_err());
    assert!(e.contains("output_every = 0"), "{e}");
    let v = example(|t| {
        t.replace(
            "box = [0.0, 0.0, 0.004, 0.004]",
            "p = [0.0, 0.004]\nn = [0.0, -1.0]\nvelocity = [0.001, 0.0]",
        )
    });
    let e = format!("{:#}", run(&v, &ctx(&out_dir)).unwrap_err());
    assert!(e.contains("moving walls"), "{e}");
    assert!(!out_dir.exists());
}

#[test]
fn trt_runs_and_the_interior_correction_is_refused_for_floating_grains() {
    let dir = tempfile::tempdir().unwrap();
    let trt = example(|t| short(t).replace("depth = 1.0e-3", "depth = 1.0e-3\ntrt_magic = 0.25"));
    let out = run(&trt, &ctx(dir.path())).unwrap();
    assert!(out.summary["last"]["hydro_force"][1].as_f64().unwrap() < 0.0);

    // The example's grains are lighter than the liquid (2550 vs 2856 kg/m³): the explicit
    // correction would be unstable, so it is refused, naming the parameter and the ratio.
    let dir = tempfile::tempdir().unwrap();
    let corr = example(|t| {
        short(t).replace(
            "depth = 1.0e-3",
            "depth = 1.0e-3\ninterior_liquid_correction = true",
        )
    });
    let e = format!("{:#}", run(&corr, &ctx(dir.path())).unwrap_err());
    assert!(
        e.contains("interior_liquid_correction") && e.contains("0.89"),
        "{e}"
    );
    assert!(
        walk(dir.path()).is_empty(),
        "nothing may be written: {:?}",
        walk(dir.path())
    );

    let dir = tempfile::tempdir().unwrap();
    let bb = example(|t| {
        short(t)
            .replace("method = \"psm\"", "method = \"bounce-back\"")
            .replace("depth = 1.0e-3", "depth = 1.0e-3\ntrt_magic = 0.25")
    });
    let e = format!("{:#}", run(&bb, &ctx(dir.path())).unwrap_err());
    assert!(e.contains("trt_magic") && e.contains("psm"), "{e}");
}
