//! Grains in a liquid: the shipped example, both methods, both precisions, and refusals.

use super::*;

/// The shipped example with `edit` applied to its text.
fn example(edit: impl Fn(String) -> String) -> String {
    edit(shipped("coupled-float.toml"))
}

fn short(t: String) -> String {
    t.replace("steps = 1000", "steps = 60")
        .replace("snapshots = { every = 500 }", "snapshots = { every = 30 }")
}

#[test]
fn float_example_runs_and_the_liquid_resists_the_rise() {
    let dir = tempfile::tempdir().unwrap();
    let rec = simulate(&example(short), dir.path(), false).unwrap();
    let out = dir.path().join("out");
    for f in [
        "series.csv",
        "stage.json",
        "snapshots.csv",
        "fluid.pvd",
        "particles.pvd",
        "pressure_change.png",
        "pressure_min.png",
        "snapshots/fluid_000000030.vti",
        "snapshots/fluid_000000030.csv",
        "snapshots/particles_000000060.vtp",
        "snapshots/particles_000000060.csv",
        "snapshots/contacts_000000060.csv",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    let s = &rec.output.summary;
    // Grains lighter than the liquid rise; the liquid's drag on them points down.
    assert!(s["last"]["momentum_y"].as_f64().unwrap() > 0.0);
    assert!(s["last"]["hydro_fy"].as_f64().unwrap() < 0.0);
    let share = &s["engine"]["time_share"];
    let sum: f64 = ["lbm", "dem", "coupling"]
        .iter()
        .map(|k| share[k].as_f64().unwrap())
        .sum();
    assert!((sum - 1.0).abs() < 1e-9);
    assert_eq!(s["engine"]["dem_steps_per_lbm_step"], 40);
    assert_eq!(rec.output.figures.len(), 2);
}

#[test]
fn bounce_back_and_f32_run_the_same_scene() {
    for (method, precision) in [("bounce-back", "f64"), ("psm", "f32")] {
        let dir = tempfile::tempdir().unwrap();
        // tau = 0.67: bounce-back is unstable at the example's 0.567 (see the next test).
        let v = example(|t| {
            short(t)
                .replace("dt = 5.6e-5", "dt = 1.4e-4")
                .replace("method = \"psm\"", &format!("method = \"{method}\""))
                .replace("precision = \"f64\"", &format!("precision = \"{precision}\""))
        });
        let rec = simulate(&v, dir.path(), false).unwrap();
        assert!(
            rec.output.summary["last"]["hydro_fy"].as_f64().unwrap() < 0.0,
            "{method} {precision}"
        );
    }
}

#[test]
fn non_integer_time_step_ratio_is_refused_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    let v = example(|t| t.replace("dt = 1.4e-6", "dt = 1.5e-6"));
    let e = format!("{:#}", simulate(&v, dir.path(), false).unwrap_err());
    assert!(e.contains("37.33") && e.contains("whole number"), "{e}");
    assert!(!dir.path().join("out").exists());
}

/// Where a method fails: at tau = 0.567 moving bounce-back with refilling blows up within 60
/// LBM steps on the example while PSM runs it; the failure names the step, the node and the
/// cause, publishes none of the run's files, and keeps what the run recorded until then in its
/// working directory, where the error says (`contract::FailedRun`).
#[test]
fn bounce_back_failure_is_diagnosed_and_keeps_only_its_series() {
    let dir = tempfile::tempdir().unwrap();
    let v = example(|t| {
        short(t)
            .replace("method = \"psm\"", "method = \"bounce-back\"")
            .replace("series = { every = 50 }", "series = { every = 5 }")
    });
    let e = format!("{:#}", simulate(&v, dir.path(), false).unwrap_err());
    assert!(
        e.contains("unstable at step") && e.contains("node") && e.contains("Mach"),
        "{e}"
    );
    let partial = dir.path().join("out").join(crate::pipeline::PARTIAL);
    assert!(e.contains(&partial.display().to_string()), "{e}");
    let left = walk(dir.path());
    assert!(
        left.iter()
            .all(|p| p.starts_with(dir.path().join("scene")) || p.starts_with(&partial)),
        "published: {left:?}"
    );
    // The series ends at the last output before the failure, which it names.
    let series = partial.join("series.csv");
    let steps = crate::report::table::f64_column(
        &crate::report::table::read_table(&series).unwrap(),
        "step",
        &series,
    )
    .unwrap();
    let failed_at: f64 = e
        .split("unstable at step ")
        .nth(1)
        .unwrap()
        .split(|c: char| !c.is_ascii_digit())
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(
        !steps.is_empty() && *steps.last().unwrap() < failed_at,
        "series steps {steps:?}, failed at {failed_at}"
    );
    assert!(simulate(&example(short), &dir.path().join("psm"), false).is_ok());
}

#[test]
fn zero_viscosity_is_refused_naming_the_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let v = example(|t| t.replace("dynamic_viscosity = 1.82e-3", "dynamic_viscosity = 0.0"));
    let e = format!("{:#}", simulate(&v, dir.path(), false).unwrap_err());
    assert!(e.contains("viscosity = 0") && e.contains("[fluid]"), "{e}");
    assert!(!dir.path().join("out").exists());
}

#[test]
fn zero_output_interval_and_moving_walls_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let v = example(|t| t.replace("series = { every = 50 }", "series = { every = 0 }"));
    let e = format!("{:#}", simulate(&v, dir.path(), false).unwrap_err());
    assert!(e.contains("every / count must be at least 1"), "{e}");
    let v = example(|t| {
        t.replace(
            "box = [0.0, 0.0, 0.004, 0.004]",
            "p = [0.0, 0.004]\nn = [0.0, -1.0]\nvelocity = [0.001, 0.0]",
        )
    });
    let e = format!("{:#}", simulate(&v, dir.path(), false).unwrap_err());
    assert!(
        e.contains("a moving wall is seen by the liquid only as the push-plate"),
        "{e}"
    );
    assert!(!dir.path().join("out").exists());
}

#[test]
fn trt_runs_and_the_interior_correction_is_refused_for_floating_grains() {
    let dir = tempfile::tempdir().unwrap();
    let trt = example(|t| short(t).replace("collision = \"bgk\"", "collision = \"trt\"\nmagic = 0.25"));
    let rec = simulate(&trt, dir.path(), false).unwrap();
    assert!(rec.output.summary["last"]["hydro_fy"].as_f64().unwrap() < 0.0);

    // The example's grains are lighter than the liquid (2550 vs 2856 kg/m³): the explicit
    // correction would be unstable, so it is refused, naming the parameter and the ratio.
    let dir = tempfile::tempdir().unwrap();
    let corr = example(|t| {
        short(t).replace(
            "depth = 1.0e-3",
            "depth = 1.0e-3\ninterior_liquid_correction = true",
        )
    });
    let e = format!("{:#}", simulate(&corr, dir.path(), false).unwrap_err());
    assert!(
        e.contains("interior_liquid_correction") && e.contains("0.89"),
        "{e}"
    );
    assert!(!dir.path().join("out").exists(), "nothing may be written");

    let dir = tempfile::tempdir().unwrap();
    let bb = example(|t| {
        short(t)
            .replace("method = \"psm\"", "method = \"bounce-back\"")
            .replace("collision = \"bgk\"", "collision = \"trt\"")
    });
    let e = format!("{:#}", simulate(&bb, dir.path(), false).unwrap_err());
    assert!(e.contains("trt") && e.contains("psm"), "{e}");
}

/// A coupled run interrupted by the wall-clock limit (again on every resume) ends bit for bit
/// like the whole run: grains, populations, held loads and the interior-liquid state are all in
/// the checkpoint.
#[test]
fn interrupted_coupled_run_resumes_bitwise() {
    let t = tempfile::tempdir().unwrap();
    let s = example(|t| {
        t.replace("steps = 1000", "steps = 90")
            .replace("snapshots = { every = 500 }", "snapshots = { every = 45 }")
            .replace("series = { every = 50 }", "series = { every = 5 }")
            .replace("collision = \"bgk\"", "collision = \"trt\"")
    });
    simulate(&s, &t.path().join("whole"), false).unwrap();
    let limited = s.replace("steps = 90", "steps = 90\nwall_clock = 0.05");
    let dir = t.path().join("cut");
    let interruptions = resume_until_done(&limited, &dir, 90);
    for f in [
        "series.csv",
        "snapshots/fluid_000000090.csv",
        "snapshots/particles_000000090.csv",
    ] {
        let a = std::fs::read(t.path().join("whole/out").join(f)).unwrap();
        let b = std::fs::read(dir.join("out").join(f)).unwrap();
        assert!(a == b, "{f} differs after {interruptions} interruptions");
    }
}
