//! Grains only.

use super::*;

pub(super) const SCENE: &str = r#"
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
[dem]
dt = 4.0e-6
skin = 5.0e-5
gravity = [0.0, -9.81]
[run]
steps = 3000
[output]
series = { every = 100 }
snapshots = { every = 1000 }
checkpoints = { every = 1000 }
"#;

/// A run interrupted (wall-clock limit, then more interruptions on every resume) and resumed
/// until done ends bit for bit like the uninterrupted run: the series, and every snapshot's
/// particle and contact tables.
#[test]
fn interrupted_and_resumed_run_matches_uninterrupted_bitwise() {
    let t = tempfile::tempdir().unwrap();
    let whole = simulate(SCENE, &t.path().join("whole"), false).unwrap();
    assert_eq!(whole.output.summary["steps"], 3000);
    let limited = SCENE.replace("steps = 3000", "steps = 3000\nwall_clock = 0.01");
    let dir = t.path().join("cut");
    let interruptions = resume_until_done(&limited, &dir, 3000);
    let (a, b) = (t.path().join("whole/out"), dir.join("out"));
    for f in
        ["series.csv", "snapshots.csv"]
            .into_iter()
            .map(PathBuf::from)
            .chain(["particles", "contacts"].iter().flat_map(|k| {
                [1000u64, 2000, 3000].map(|s| PathBuf::from(format!("snapshots/{k}_{s:09}.csv")))
            }))
    {
        let (x, y) = (
            std::fs::read(a.join(&f)).unwrap(),
            std::fs::read(b.join(&f)).unwrap(),
        );
        assert!(
            x == y,
            "{} differs after {interruptions} interruptions",
            f.display()
        );
    }
    let p = crate::scenes::snapshot::read_particles(&b.join("snapshots/particles_000003000.csv")).unwrap();
    assert_eq!(p.circle.len(), 120, "two circles per grain");
    assert!(p.vy.iter().sum::<f64>() < 0.0, "the grains fall");
    assert!(!b.join(".partial").exists() && !b.join("checkpoint.json").exists());
}

/// The particle table reads back to the bits of the state it was written from.
#[test]
fn particle_table_reads_back_exactly() {
    let t = tempfile::tempdir().unwrap();
    let text = SCENE.replace("steps = 3000", "steps = 200");
    let l = {
        std::fs::create_dir_all(t.path().join("s")).unwrap();
        std::fs::write(t.path().join("s/scene.toml"), &text).unwrap();
        crate::scenes::schema::load(&t.path().join("s/scene.toml"), &Default::default()).unwrap()
    };
    let mut m = crate::scenes::models::dry::Dry::build(&l.scene, &l.base_dir, true).unwrap();
    use crate::scenes::timeloop::Model;
    for _ in 0..200 {
        m.step(false).unwrap();
    }
    std::fs::create_dir_all(t.path().join("snapshots")).unwrap();
    let files = m.snapshot(t.path()).unwrap();
    let table = crate::scenes::snapshot::read_particles(&t.path().join(&files[0].1)).unwrap();
    let want = crate::scenes::snapshot::ParticleTable::of(&m.sys);
    assert_eq!(table, want);
    assert!(table.vy.iter().any(|v| *v < 0.0), "the grains fall");
}

#[test]
fn reads_digitised_circles_in_pixels() {
    let t = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(t.path().join("scene")).unwrap();
    let csv = t.path().join("scene/grains.csv");
    std::fs::write(&csv, "grain_id,x,y,r\n0,10,10,4\n0,14,10,3\n1,30,30,5\n").unwrap();
    std::fs::write(
        t.path().join("scene/grains.json"),
        r#"{"units": "px", "pixel_size": 1.0e-5}"#,
    )
    .unwrap();
    let text = SCENE
        .replace(
            "[particles.generate]\ncount = 60\nlo = [0.0, 0.0]\nhi = [0.01, 0.01]\nseed = 3\ntemplates = [ { circles = [[0.0, 0.0, 3.0e-4], [2.5e-4, 0.0, 2.5e-4]] } ]",
            "csv = \"grains.csv\"",
        )
        .replace("steps = 3000", "steps = 1")
        // These grains are 20 times lighter than the generated ones: 4e-6 s is above their
        // largest accepted step (2.9e-6 s).
        .replace("dt = 4.0e-6", "dt = 2.0e-6");
    let rec = simulate(&text, t.path(), false).unwrap();
    assert_eq!(rec.output.summary["engine"]["bodies"], 2);
    let p = crate::scenes::snapshot::read_particles(&t.path().join("out/snapshots/particles_000000001.csv"))
        .unwrap();
    assert_eq!(p.circle.len(), 3);
    assert!((p.r[2] - 5e-5).abs() < 1e-18);
    // The second grain is a single disk at (30, 30) px (it has fallen one step since).
    assert!((p.body_x[2] - 3e-4).abs() < 1e-12 && (p.body_y[2] - 3e-4).abs() < 1e-9);
    std::fs::write(&csv, "grain_id,x,y\n0,1,1\n").unwrap();
    let err = format!("{:#}", simulate(&text, t.path(), false).unwrap_err());
    assert!(err.contains("no column \"r\""), "{err}");
}

/// Condition triggers and a named wall: a push-plate (a segment named "plate") rises at a known
/// speed; snapshots are taken at the step after it has moved 0.1 and 0.2 mm, and the run stops
/// when it has moved 0.3 mm.
#[test]
fn snapshots_when_the_plate_has_moved_and_stop_at_a_distance() {
    let t = tempfile::tempdir().unwrap();
    let scene = SCENE
        .replace(
            "[[walls]]\nbox = [0.0, 0.0, 0.01, 0.01]",
            "[[walls]]\nbox = [0.0, 0.0, 0.01, 0.01]\n[[walls]]\nname = \"plate\"\na = [0.003, 0.0005]\nb = [0.007, 0.0005]\nvelocity = [0.0, 0.05]",
        )
        .replace(
            "snapshots = { every = 1000 }",
            "snapshots = { when = { quantity = \"wall_displacement\", wall = \"plate\", crosses = [1e-4, 2e-4] } }",
        )
        .replace("steps = 3000", "steps = 3000\nuntil_wall_moved = { wall = \"plate\", distance = 3e-4 }");
    let rec = simulate(&scene, t.path(), false).unwrap();
    // The plate moves by v dt = 2e-7 m per step (accumulated as the stepper does).
    let (mut y, y0, mut n, mut crossed) = (0.0005f64, 0.0005f64, 0u64, Vec::new());
    let mut next = [1e-4, 2e-4, 3e-4].into_iter().peekable();
    while let Some(&d) = next.peek() {
        y += 0.05 * 4.0e-6;
        n += 1;
        if (y - y0).abs() >= d {
            crossed.push(n);
            next.next();
        }
    }
    let stop = crossed[2];
    assert_eq!(
        rec.output.summary["steps"], stop,
        "{}",
        rec.output.summary["stopped"]
    );
    assert!(rec.output.summary["stopped"].as_str().unwrap().contains("moved"));
    let index = crate::report::table::read_table(&t.path().join("out/snapshots.csv")).unwrap();
    let p = t.path().join("out/snapshots.csv");
    let steps = crate::report::table::u64_column(&index, "step", &p).unwrap();
    let mut snap: Vec<u64> = steps.clone();
    snap.dedup();
    // one step after each crossing, and the state the run ended in
    assert_eq!(snap, vec![crossed[0] + 1, crossed[1] + 1, stop], "{steps:?}");
    let bad = scene.replace("wall = \"plate\", distance", "wall = \"plates\", distance");
    let e = format!("{:#}", simulate(&bad, &t.path().join("bad"), false).unwrap_err());
    assert!(e.contains("\"plates\"") && e.contains("plate"), "{e}");
}

/// `until_slower_than = { speed, over }` (Su et al. 2020 Sect. 3.2's radiograph criterion, the
/// Float case's stop): the run stops at the end of the first window in which no grain moved more
/// than speed × window, and not a window earlier. Checked against the same scene run without the
/// stop to the same step (the runs are deterministic), whose snapshots give the grains'
/// displacements over the last two windows; and a run interrupted again and again stops at the
/// same step with the same bits (the window's start is checkpointed).
#[test]
fn the_windowed_stop_ends_at_the_first_still_window_and_resumes_to_the_same_bits() {
    let t = tempfile::tempdir().unwrap();
    let still = SCENE
        .replace(
            "steps = 3000",
            "time = 2.0\nuntil_slower_than = { speed = 1.0e-4, over = 0.02 }",
        )
        .replace("series = { every = 100 }", "series = { every = 500 }")
        .replace("snapshots = { every = 1000 }", "snapshots = { every = 100000 }");
    let rec = simulate(&still, &t.path().join("still"), false).unwrap();
    let s = &rec.output.summary;
    let why = s["stopped"].as_str().unwrap_or("");
    assert!(why.contains("every grain moved less than"), "{s}");
    // Windows of 5000 steps from the first series sample (step 500); measured: step 30 500.
    let stop = s["steps"].as_u64().unwrap();
    assert!(stop < 500_000 && (stop - 500).is_multiple_of(5000), "{s}");
    let (window, limit) = (5000, 1.0e-4 * 0.02);
    let plain = still
        .replace(
            "time = 2.0\nuntil_slower_than = { speed = 1.0e-4, over = 0.02 }",
            &format!("steps = {stop}"),
        )
        .replace("snapshots = { every = 100000 }", "snapshots = { every = 500 }");
    simulate(&plain, &t.path().join("plain"), false).unwrap();
    let at = |step: u64| {
        crate::scenes::snapshot::read_particles(
            &t.path()
                .join(format!("plain/out/snapshots/particles_{step:09}.csv")),
        )
        .unwrap()
    };
    let moved = |a: u64, b: u64| {
        let (p, q) = (at(a), at(b));
        (0..p.body_x.len())
            .map(|k| (q.body_x[k] - p.body_x[k]).hypot(q.body_y[k] - p.body_y[k]))
            .fold(0.0, f64::max)
    };
    let (last, before) = (
        moved(stop - window, stop),
        moved(stop - 2 * window, stop - window),
    );
    assert!(last < limit, "the last window moved {last:e} m (limit {limit:e})");
    assert!(
        before >= limit,
        "the window before moved {before:e} m: it should have stopped then"
    );
    // Interrupted every 0.05 s of wall time and resumed: the same stop, the same bits.
    let limited = still.replace("time = 2.0", "time = 2.0\nwall_clock = 0.05");
    let cut = t.path().join("cut");
    let interruptions = resume_until_done(&limited, &cut, 10_000);
    for f in [
        "series.csv".to_string(),
        format!("snapshots/particles_{stop:09}.csv"),
    ] {
        let (x, y) = (
            std::fs::read(t.path().join("still/out").join(&f)).unwrap(),
            std::fs::read(cut.join("out").join(&f)).unwrap(),
        );
        assert!(x == y, "{f} differs after {interruptions} interruptions");
    }
}

/// `[dem.mass_scale_control]` moves the DEM step with the LBM-DEM ratio; a dry scene has no
/// LBM step, and is refused before anything is written.
#[test]
fn a_dry_scene_refuses_a_mass_scale_that_follows_the_run() {
    let t = tempfile::tempdir().unwrap();
    let text = SCENE.replace(
        "[run]\n",
        "[dem.mass_scale_control]\ninertial_number = 0.002\n[run]\n",
    );
    assert!(text.contains("[dem.mass_scale_control]"));
    let e = format!("{:#}", simulate(&text, t.path(), false).unwrap_err());
    assert!(
        e.contains("a dry scene has no LBM step") && e.contains("remove it"),
        "{e}"
    );
    assert!(
        !t.path().join("out").exists(),
        "the refused run left output behind"
    );
}
