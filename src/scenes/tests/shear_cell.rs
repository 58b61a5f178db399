//! The reduced Su et al. 2020 shear cell (`scenes/su2020/reduced-shear-cell.toml`: 300 grains,
//! the push-plate moving up by about one mean diameter): what a case this small can show. The
//! plate compacts the grains ahead of it, the liquid stays inside the membrane and its mass
//! follows the sample's area, Δp is lowest just above the plate (the resting solid zone's
//! artefact, docs/su2020.md), the run is the same on one
//! and two threads and after an interruption, the same cell without liquid records the same
//! measures, and bad set-ups are refused before anything runs.

use super::*;
use crate::report::table::{f64_column, read_table};
use crate::scenes::snapshot::{read_fluid, read_particles};
use lbdem_dem::Vec2;
use lbdem_dem::polygon::contains;

const SCENE: &str = "su2020/reduced-shear-cell.toml";

/// The shipped reduced cell, runnable from a temporary directory (its grain file beside it).
fn cell(dir: &Path, edit: impl Fn(String) -> String) -> String {
    let src = dir.join("scene");
    std::fs::create_dir_all(&src).unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/su2020/reduced-grains.csv"),
        src.join("reduced-grains.csv"),
    )
    .unwrap();
    edit(shipped(SCENE))
}

/// The run shortened to `time` seconds.
fn shorter(time: &str) -> impl Fn(String) -> String {
    let time = time.to_string();
    move |t: String| {
        t.replace("time = 0.2\n", &format!("time = {time}\n"))
            .replace("series = { every = 20 }", "series = { every = 5 }")
    }
}

fn column(out: &Path, name: &str) -> Vec<f64> {
    let p = out.join("series.csv");
    f64_column(&read_table(&p).unwrap(), name, &p).unwrap()
}

/// The snapshot files of `kind` in `out/snapshots`, oldest first.
fn snapshots(out: &Path, kind: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = walk(&out.join("snapshots"))
        .into_iter()
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy().to_string();
            n.starts_with(kind) && n.ends_with(".csv")
        })
        .collect();
    v.sort();
    v
}

/// The newest snapshot file of `kind` in `out/snapshots`.
fn last_snapshot(out: &Path, kind: &str) -> PathBuf {
    snapshots(out, kind).pop().expect("a snapshot")
}

fn first_snapshot(out: &Path, kind: &str) -> PathBuf {
    snapshots(out, kind).into_iter().next().expect("a snapshot")
}

/// Checks that a fluid snapshot gives Δp on the liquid nodes (solid fraction under one half,
/// Fig. 10's interstitial liquid) and on no other.
fn liquid_nodes_only(fluid: &crate::scenes::snapshot::FluidTable) {
    let solid = fluid
        .solid_fraction
        .as_ref()
        .expect("a coupled snapshot has the solid fraction");
    let (mut liquid, mut covered) = (0, 0);
    for (k, (&s, (&p, ux))) in solid.iter().zip(fluid.pressure.iter().zip(&fluid.ux)).enumerate() {
        let lattice = ux.is_finite();
        if lattice && s < 0.5 {
            assert!(p.is_finite(), "liquid node {k} (solid {s}) has no Δp");
            liquid += 1;
        } else {
            assert!(p.is_nan(), "node {k} (solid {s}) is not liquid but has Δp {p}");
            covered += usize::from(lattice);
        }
    }
    assert!(
        liquid > 1000 && covered > 500,
        "{liquid} liquid and {covered} covered nodes"
    );
}

#[test]
fn the_plate_compacts_the_grains_ahead_and_the_liquid_stays_inside_the_membrane() {
    let t = tempfile::tempdir().unwrap();
    let rec = simulate(&cell(t.path(), |s| s), t.path(), false).unwrap();
    let out = t.path().join("out");
    let s = &rec.output.summary;
    assert!(
        s["stopped"].as_str().unwrap_or("").contains("moved"),
        "the run should stop at u_y = 1 d: {s}"
    );
    let u = column(&out, "plate_displacement");
    assert!(*u.last().unwrap() >= 3.5e-4);

    // Grains ahead of the plate (x in [3, 5] mm, lowest 1.5 mm of the sample) moved up with it;
    // grains beside it (x < 2 mm) much less.
    let before = read_particles(&t.path().join("scene/reduced-grains.csv")).unwrap();
    let after = read_particles(&last_snapshot(&out, "particles")).unwrap();
    let rise = |x0: f64, x1: f64| {
        let (mut sum, mut n) = (0.0, 0);
        for c in 0..before.x.len() {
            let (x, y) = (before.body_x[c], before.body_y[c]);
            if x > x0 && x < x1 && y < 2.5e-3 {
                sum += after.body_y[c] - y;
                n += 1;
            }
        }
        assert!(n > 10, "{n} circles in [{x0}, {x1}]");
        sum / n as f64
    };
    let (ahead, beside) = (rise(3e-3, 5e-3), rise(0.0, 2e-3));
    let u_end = *u.last().unwrap();
    // Measured: ahead 0.90 u_y, beside 0.25 u_y.
    assert!(
        ahead > 0.5 * u_end,
        "grains ahead rose {ahead:e} m for u_y = {u_end:e} m"
    );
    assert!(
        beside < 0.5 * ahead,
        "grains beside rose {beside:e} m, ahead {ahead:e} m"
    );
    let pc = column(&out, "plate_force");
    assert!(*pc.last().unwrap() > 0.0, "the grains resist the plate");

    // The liquid nodes lie inside the polygon through the membrane grains' centroids.
    let fluid = read_fluid(&last_snapshot(&out, "fluid")).unwrap();
    let (lo, dx) = (-5e-4, 1e-4);
    let mut ring: Vec<Vec2> = Vec::new();
    let mut seen = std::collections::BTreeSet::new();
    for c in 0..after.x.len() {
        if after.tag[c] == 1 && seen.insert(after.body[c]) {
            ring.push(Vec2::new(after.body_x[c], after.body_y[c]));
        }
    }
    let centre = ring.iter().fold(Vec2::ZERO, |a, p| a + *p) * (1.0 / ring.len() as f64);
    ring.sort_by(|a, b| {
        let (da, db) = (*a - centre, *b - centre);
        da.y.atan2(da.x).total_cmp(&db.y.atan2(db.x))
    });
    let (mut liquid, mut outside) = (0, 0);
    for n in 0..fluid.i.len() {
        if fluid.ux[n].is_finite() {
            liquid += 1;
            let p = Vec2::new(
                lo + (fluid.i[n] as f64 + 0.5) * dx,
                lo + (fluid.j[n] as f64 + 0.5) * dx,
            );
            if !contains(&ring, p) {
                outside += 1;
            }
        }
    }
    liquid_nodes_only(&fluid);
    // The run orders the ring by the members' starting angles, this test by their present
    // ones: a few nodes along the ring may differ. Measured: 15 of 3018.
    assert!(
        liquid > 2500 && outside <= liquid / 100,
        "{outside} of {liquid} liquid nodes outside"
    );
    // The resting solid zone takes the liquid of the nodes it closes and refills the nodes it
    // opens: the liquid's mass grows with the sample's area, by more than it here (this sample
    // dilates, ε_vol^DEM = +1.5 %; the mass grows 2.3 %, not explained yet). Measured: drift
    // +0.0230 at the end, largest 0.0230.
    let drift = column(&out, "liquid_mass_drift");
    let worst = drift.iter().fold(0.0f64, |a, d| a.max(d.abs()));
    assert!(worst < 0.046, "liquid mass drifted by {worst}");
    let eps = *column(&out, "eps_vol_dem").last().unwrap();
    let last = *drift.last().unwrap();
    assert!(
        eps > 0.0 && last > 0.0,
        "a dilating sample draws liquid in: ε_vol^DEM {eps}, drift {last}"
    );

    // The liquid's pressure falls most just above the plate (within its width, 1.5 mm above
    // it): the resting solid zone under the rising membrane takes liquid the grains above draw
    // after them. That is an artefact of the zone at rest, not Su's physics (docs/su2020.md,
    // "This is an artefact"): issue 13 item 9 asks that Δp rise ahead of a compacting plate.
    // This pins where the artefact acts today, so that a fix shows here. Measured at the end, on
    // liquid nodes: lowest Δp −5.08 Pa at x 4.35 mm (the plate spans 3-5 mm), 0.38 mm above the
    // plate (with the nodes inside grains: −6.4 Pa at 4.15 mm, 0.48 mm above).
    let (x, y) = (
        *column(&out, "dp_min_x").last().unwrap(),
        *column(&out, "dp_min_y").last().unwrap(),
    );
    let plate_y = 0.00102 + *column(&out, "plate_displacement").last().unwrap();
    assert!(
        (2.5e-3..5.5e-3).contains(&x) && (0.0..1.5e-3).contains(&(y - plate_y)),
        "lowest Δp at ({x}, {y}), plate top at {plate_y}"
    );
}

/// Mean Δp (Pa) of the liquid nodes ahead of the plate (x in [3, 5] mm, up to 1.5 mm above its
/// face) and of all liquid nodes, in the run's last fluid snapshot.
fn pressure_ahead_of_the_plate(out: &Path) -> (f64, f64) {
    let fluid = read_fluid(&last_snapshot(out, "fluid")).unwrap();
    let plate_y = 0.00102 + *column(out, "plate_displacement").last().unwrap();
    let (lo, dx) = (-5e-4, 1e-4);
    let (mut ahead, mut n_ahead, mut all, mut n) = (0.0, 0, 0.0, 0);
    for k in 0..fluid.i.len() {
        let p = fluid.pressure[k];
        if !p.is_finite() {
            continue;
        }
        all += p;
        n += 1;
        let (x, y) = (
            lo + (fluid.i[k] as f64 + 0.5) * dx,
            lo + (fluid.j[k] as f64 + 0.5) * dx,
        );
        if (3e-3..5e-3).contains(&x) && (0.0..1.5e-3).contains(&(y - plate_y)) {
            ahead += p;
            n_ahead += 1;
        }
    }
    // Measured (moving membrane): 99 liquid nodes ahead, 1318 in all.
    assert!(n_ahead > 60 && n > 1000, "{n_ahead} nodes ahead, {n} in all");
    (ahead / n_ahead as f64, all / n as f64)
}

#[test]
fn a_membrane_that_moves_the_liquid_raises_the_pressure_ahead_of_the_plate() {
    // `membrane_boundary = "moving"` with the membrane at the paper's density (0.90 times the
    // liquid's) and its bonds damped (ζ = 0.2): the liquid ahead of the plate is pushed, not
    // drained, and its pressure rises above the liquid's mean (issue 13 item 9), where the zone
    // at rest (the test above) makes it the lowest. Measured at the end, on liquid nodes, with
    // the default membrane_relaxation = ½: ahead +0.080 Pa, mean −0.056 Pa (undamped with the
    // membrane 2.7 times the liquid's density, as until 2026-11-29: +0.063 and −0.053; at rest
    // −3.61 and +0.25 Pa); ε_vol^DEM 0.0157; the liquid's mass +1.8 % (at rest +2.3 %); largest
    // Mach in the series 0.038 (0.049 at rest). The bound on it guards against a blow-up; the
    // random replicas map the stability (sweeps/su2020-membrane-damping.toml).
    let t = tempfile::tempdir().unwrap();
    let moving = moving_membrane;
    let text = moving(shipped(SCENE));
    assert!(text.contains("\"moving\"") && text.contains("damping = 0.2 }"));
    simulate(&cell(t.path(), moving), t.path(), false).unwrap();
    let out = t.path().join("out");
    let (ahead, mean) = pressure_ahead_of_the_plate(&out);
    assert!(
        ahead - mean > 0.06,
        "Δp ahead of the plate {ahead} Pa, liquid mean {mean} Pa"
    );
    let (x, y) = (
        *column(&out, "dp_min_x").last().unwrap(),
        *column(&out, "dp_min_y").last().unwrap(),
    );
    let plate_y = 0.00102 + *column(&out, "plate_displacement").last().unwrap();
    assert!(
        !((2.5e-3..5.5e-3).contains(&x) && (0.0..1.5e-3).contains(&(y - plate_y))),
        "lowest Δp at ({x}, {y}), just above the plate (top at {plate_y})"
    );
    // Measured: drift +0.0179 at the end.
    let drift = *column(&out, "liquid_mass_drift").last().unwrap();
    assert!((0.0..0.036).contains(&drift), "liquid mass drift {drift}");
    let mach = column(&out, "max_mach").into_iter().fold(0.0, f64::max);
    assert!(mach < 0.076, "largest Mach {mach}, measured 0.038");

    // A membrane whose bonds are not damped is refused before anything runs (undamped, it
    // rang and blew up the lattice even at 2.7 times the liquid's density).
    let t = tempfile::tempdir().unwrap();
    let undamped = |s: String| moving(s).replace(", damping = 0.2 }", " }");
    let got = simulate(&cell(t.path(), undamped), t.path(), false);
    assert_refused(got, "damping ratio 0", "params.damping to at least 0.2", t.path());
    // Dashpots too stiff for the DEM step are refused too (here ζ = 0.5: the bound 3.9 is
    // passed at about ζ = 0.3 on this assembly; measured number at ζ = 0.5 above 5).
    let t = tempfile::tempdir().unwrap();
    let stiff = |s: String| moving(s).replace("damping = 0.2 }", "damping = 0.5 }");
    let got = simulate(&cell(t.path(), stiff), t.path(), false);
    assert_refused(
        got,
        "dashpots ([bonds] params.damping) are too stiff",
        "lower the damping ratio to at most",
        t.path(),
    );
}

#[test]
fn a_shear_cell_run_is_the_same_on_one_and_two_threads() {
    let t = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for threads in [1, 2] {
        let dir = t.path().join(format!("t{threads}"));
        let text = cell(&dir, |s| {
            shorter("0.03")(s).replace("[run]\n", &format!("[run]\nthreads = {threads}\n"))
        });
        simulate(&text, &dir, false).unwrap();
        let out = dir.join("out");
        files.push(
            [
                std::fs::read(out.join("series.csv")).unwrap(),
                std::fs::read(last_snapshot(&out, "particles")).unwrap(),
                std::fs::read(last_snapshot(&out, "fluid")).unwrap(),
            ]
            .concat(),
        );
    }
    assert!(files[0] == files[1], "1 and 2 threads differ");
}

#[test]
fn an_interrupted_shear_cell_run_resumes_to_the_same_bits() {
    resumes_to_the_same_bits(|s| s);
}

/// The same with the membrane showing the liquid its velocity: the checkpoint carries where
/// the membrane grains were at the last LBM step (their mean velocity over it).
#[test]
fn an_interrupted_run_with_a_moving_membrane_boundary_resumes_to_the_same_bits() {
    resumes_to_the_same_bits(moving_membrane);
}

/// The reduced cell with the membrane showing the liquid its velocity, its grains at the paper's
/// density (0.90 times the liquid's) and its bonds damped at ζ = 0.2
/// (`MOVING_MEMBRANE_BOND_DAMPING_MIN`).
fn moving_membrane(s: String) -> String {
    s.replace(
        "[shear_cell]\nplate = \"plate\"\n",
        "[shear_cell]\nplate = \"plate\"\nmembrane_boundary = \"moving\"\n",
    )
    .replace("lambda = 0.5 }", "lambda = 0.5, damping = 0.2 }")
}

/// A moving membrane boundary with membrane grains lighter than
/// `MOVING_MEMBRANE_DENSITY_RATIO_WARN` times the liquid is warned before it starts, and the
/// warning is in the summary with the factor that would pass; a heavier membrane is not. (Simulation
/// I at 0.90, 1.08 and 1.35 times the liquid's density rang after 2 d̄, at 1.80 and 2.7 it did
/// not; docs/stability.md, "Damped membrane bonds".)
#[test]
fn a_moving_membrane_lighter_than_the_map_allows_is_warned_with_the_factor_that_passes() {
    for (factor, warned) in [(1.0, true), (3.0, false)] {
        let t = tempfile::tempdir().unwrap();
        let text = cell(t.path(), |s| {
            moving_membrane(shorter("0.001")(s))
                .replace("[membrane]\n", &format!("[membrane]\nmass_scale = {factor}\n"))
        });
        assert!(text.contains(&format!("mass_scale = {factor}")));
        let rec = simulate(&text, t.path(), false).unwrap();
        let w = rec.output.summary["warnings"].to_string();
        if warned {
            // The paper's membrane: 2658 / 2948 = 0.902 of the liquid's density.
            assert!(
                w.contains("[dem] mass_scale = 1 makes the membrane grains 0.902 times"),
                "{w}"
            );
            assert!(w.contains("[membrane] mass_scale = 2.00 or more"), "{w}");
        } else {
            assert!(!w.contains("membrane_boundary"), "{w}");
        }
    }
}

/// A run refused before it starts: the message names `needle` and `fix`, and nothing is left
/// in `dir`.
fn assert_refused(got: anyhow::Result<StageRecord>, needle: &str, fix: &str, dir: &Path) {
    let e = format!("{:#}", got.unwrap_err());
    assert!(e.contains(needle) && e.contains(fix), "{e}");
    assert!(!dir.join("out").exists(), "the refused run left output behind");
}

fn resumes_to_the_same_bits(edit: impl Fn(String) -> String) {
    let t = tempfile::tempdir().unwrap();
    let whole = t.path().join("whole");
    // With the solid map kept between steps (a tolerance above 0), the state a resume needs
    // includes where each grain was last mapped; at 0 the map is recomputed from the grains
    // (`remap::tests::at_tolerance_zero_it_gives_the_bits_of_a_fresh_map`).
    // The plate held for the first 12 steps: checkpoints fall inside the settling and after it.
    let text = cell(&whole, |s| {
        edit(settled("0.006")(shorter("0.03")(s)))
            .replace("[output]\n", "[output]\ncheckpoints = { every = 5 }\n")
            .replace("r_hd = 0.8 ", "remap_tolerance = 0.02\nr_hd = 0.8 ")
    });
    assert!(text.contains("remap_tolerance") && text.contains("settle"));
    simulate(&text, &whole, false).unwrap();
    let cut = t.path().join("cut");
    cell(&cut, |s| s);
    let limited = text.replace("[run]\n", "[run]\nwall_clock = 0.05\n");
    let interruptions = resume_until_done(&limited, &cut, 400);
    let a = std::fs::read(whole.join("out/series.csv")).unwrap();
    let b = std::fs::read(cut.join("out/series.csv")).unwrap();
    assert!(a == b, "series.csv differs after {interruptions} interruptions");
    let a = std::fs::read(last_snapshot(&whole.join("out"), "fluid")).unwrap();
    let b = std::fs::read(last_snapshot(&cut.join("out"), "fluid")).unwrap();
    assert!(a == b, "the last fluid snapshot differs");
}

/// The same with a settling to rest (`[shear_cell] settle_until_rest`): the step the plate was
/// let go is in the checkpoint, not in the scene. Grains kicked towards the plate at 2 mm/s come
/// below 5e-4 m/s at LBM step 49 (measured; the next test), after the 12 steps of `settle` and
/// before the 80 of `max_time`, so checkpoints (every 5 steps) fall before and after the release.
#[test]
fn an_interrupted_run_settling_to_rest_resumes_to_the_same_bits() {
    resumes_to_the_same_bits(|s| kicked(until_rest("5.0e-4", "0.04")(s)));
}

/// The same with the mass scale following the inertial number (`[dem.mass_scale_control]`):
/// the checkpoint carries the ratio the run had reached (the masses in the grains went with it)
/// and the LBM step count, which the DEM's step count no longer gives.
#[test]
fn an_interrupted_run_whose_mass_scale_follows_the_inertial_number_resumes_to_the_same_bits() {
    let t = tempfile::tempdir().unwrap();
    let probe = t.path().join("probe");
    // The run below, uninterrupted, must leave the scene's ratio after the settling and before
    // most checkpoints (every 5 LBM steps), so that the resumed runs start from a ratio the
    // scene does not give (measured: 25 to the settling's end, 125 from the first choice on).
    let text = cell(&probe, |s| {
        following("4.0e-4", 5)(settled("0.006")(shorter("0.03")(s)))
    });
    simulate(&text, &probe, false).unwrap();
    let ratios = column(&probe.join("out"), "dem_steps_per_lbm_step");
    let first = ratios.iter().position(|&r| r != 25.0);
    assert!(first.is_some_and(|k| k < ratios.len() / 2), "ratios {ratios:?}");
    resumes_to_the_same_bits(following("4.0e-4", 5));
}

/// `held = "smallest"`: while the plate is held the ladder stands on its bottom rung (the
/// grains' own masses, ratio 125 here) and follows I from there once the plate moves. The rung
/// is chosen from the LBM step count alone, so a run resumed inside the settling or after it
/// takes the same masses, to the bit.
#[test]
fn a_mass_scale_held_at_the_bottom_rung_while_the_plate_is_held_resumes_to_the_same_bits() {
    let t = tempfile::tempdir().unwrap();
    let probe = t.path().join("probe");
    let held =
        |s: String| following("4.0e-4", 5)(s).replace("every = 5\n", "every = 5\nheld = \"smallest\"\n");
    let text = cell(&probe, |s| held(settled("0.006")(shorter("0.03")(s))));
    assert!(text.contains("held = \"smallest\""));
    simulate(&text, &probe, false).unwrap();
    let out = probe.join("out");
    let (time, ratio) = (column(&out, "time"), column(&out, "dem_steps_per_lbm_step"));
    // Outputs after the first step and before the plate moves (t < 6 ms) sit on the bottom
    // rung; without `held` they keep the scene's 25 (the resume test above).
    let during: Vec<f64> = time
        .iter()
        .zip(&ratio)
        .filter(|&(&t, _)| t > 0.0 && t < 0.006 - 1e-9)
        .map(|(_, &r)| r)
        .collect();
    assert!(
        !during.is_empty() && during.iter().all(|&r| r == 125.0),
        "ratios {ratio:?}"
    );
    resumes_to_the_same_bits(held);
}

/// The reduced cell at mass scale 25 (DEM step 2e-5 s, 25 DEM steps per LBM step: the top of
/// the ladder), its scale following the inertial number with target `target`, chosen every
/// `every` LBM steps.
fn following(target: &'static str, every: u32) -> impl Fn(String) -> String {
    move |s: String| {
        s.replace("dt = 4.0e-6", "dt = 2.0e-5\nmass_scale = 25.0")
            .replace(
                "[fluid]\n",
                &format!(
                    "[dem.mass_scale_control]\ninertial_number = {target}\nevery = {every}\n\n[fluid]\n"
                ),
            )
    }
}

/// The plate held for `time` seconds before it moves (`[shear_cell] settle`), and a snapshot as
/// it starts to move.
fn settled(time: &str) -> impl Fn(String) -> String {
    let time = time.to_string();
    move |t: String| {
        t.replace(
            "[shear_cell]\nplate = \"plate\"\n",
            &format!("[shear_cell]\nplate = \"plate\"\nsettle = {time}\n"),
        )
        .replace(
            "snapshots = { count = 2 }",
            "snapshots = { when = { quantity = \"wall_displacement\", wall = \"plate\", crosses = [0.0, 1.0e-5] } }",
        )
    }
}

/// The plate held after `settle` until every grain is slower than `speed` (m/s), for at most
/// `max_time` seconds (`[shear_cell] settle_until_rest`); needs [`settled`] first.
fn until_rest(speed: &'static str, max_time: &'static str) -> impl Fn(String) -> String {
    move |t: String| {
        let at = t.find("\nsettle = ").expect("settled() first") + 1;
        let end = at + t[at..].find('\n').unwrap() + 1;
        format!(
            "{}settle_until_rest = {{ speed = {speed}, max_time = {max_time} }}\n{}",
            &t[..end],
            &t[end..]
        )
    }
}

/// The grains start towards the plate at 2 mm/s (the committed assembly is at rest, 1e-17 m/s),
/// so that there is something to settle.
fn kicked(t: String) -> String {
    t.replace("[particles]\n", "[particles]\nvelocity = [0.0, -2.0e-3]\n")
}

/// `[shear_cell] settle_until_rest` (Su Sect. 2.4: relaxed until every grain is slower than
/// 1e-7 m/s): the plate is let go at the first LBM step after `settle` with every grain slower
/// than the criterion, the shear is measured from there, and a run whose grains never get there
/// is let go at `max_time` and says so.
#[test]
fn a_settling_to_rest_lets_the_plate_go_when_every_grain_is_slower_than_the_criterion() {
    let t = tempfile::tempdir().unwrap();
    // Held at least 0.005 s (10 LBM steps), at most 0.1 s (200); then 0.01 s moving.
    let run = |dir: &Path, speed: &'static str| {
        let text = cell(dir, |s| {
            kicked(until_rest(speed, "0.1")(settled("0.005")(shorter("0.01")(s))))
                .replace("series = { every = 5 }", "series = { every = 1 }")
        });
        assert!(text.contains("settle_until_rest = { speed = ") && text.contains("every = 1 }"));
        let rec = simulate(&text, dir, false).unwrap();
        (rec, dir.join("out"))
    };
    // Measured: the fastest grain falls from 1.1e-3 m/s at step 5 to 5.1e-4 at step 48 and 4.5e-4
    // at step 49, where the plate is let go (with 1e-9 it goes on ringing between 2e-4 and 9e-4).
    let (rec, out) = run(&t.path().join("rest"), "5.0e-4");
    let (step, settling) = (column(&out, "step"), column(&out, "settling"));
    let (fastest, u) = (column(&out, "fastest_grain"), column(&out, "plate_displacement"));
    let eps = column(&out, "eps_vol_dem");
    let k = settling
        .iter()
        .position(|&x| x == 0.0)
        .expect("the plate was let go");
    let released = step[k];
    assert!(
        (11.0..200.0).contains(&released),
        "let go at step {released}: not the shortest hold nor the longest"
    );
    assert!(fastest[k] < 5.0e-4, "let go with a grain at {:e} m/s", fastest[k]);
    for j in 0..k {
        assert_eq!(u[j], 0.0, "the plate moved at step {}", step[j]);
        if step[j] >= 10.0 {
            assert!(fastest[j] >= 5.0e-4, "at rest at step {} already", step[j]);
        }
    }
    assert!(settling[k..].iter().all(|&x| x == 0.0));
    assert_eq!(eps[k], 0.0, "A_0 is the sample's area when the plate is let go");
    assert!(u.last().unwrap() > &0.0);
    // [run] time counts after the longest hold: let go early, the run goes on to its end.
    assert_eq!(rec.output.summary["steps"], 220, "{}", rec.output.summary);
    // Let go in time: no settling warning. (The kicked cell's liquid spikes to Mach 0.216 at its
    // last step, 220, and is named for it by the series' Mach check: measured in a run 20 steps
    // longer, the spike is an event at that step, falling back to 0.038 within four steps.)
    let w = rec.output.summary["warnings"].to_string();
    assert!(!w.contains("settle_until_rest"), "{w}");

    // Never at rest: let go at max_time, and said so.
    let (rec, out) = run(&t.path().join("never"), "1.0e-9");
    let settling = column(&out, "settling");
    let step = column(&out, "step");
    let k = settling.iter().position(|&x| x == 0.0).unwrap();
    assert_eq!(step[k], 200.0, "let go at max_time");
    let w = rec.output.summary["warnings"].to_string();
    assert!(
        w.contains("settle_until_rest") && w.contains("raise max_time"),
        "{w}"
    );
}

/// `[shear_cell] settle`: the plate stays still while the grains settle against the membrane,
/// then moves for `[run] time`; ε_vol^DEM and the plate's displacement start from the settled
/// sample, a snapshot is written as the plate starts, and the analysis reads the shear only.
#[test]
fn a_settling_holds_the_plate_and_the_shear_is_measured_from_the_settled_sample() {
    let t = tempfile::tempdir().unwrap();
    // 0.01 s held (20 LBM steps of 5e-4 s), then 0.01 s moving at 2.5 mm/s. The committed
    // assembly is at rest (1e-17 m/s), so the grains start towards the plate at 2 mm/s to have
    // something to settle.
    let text = cell(t.path(), |s| {
        settled("0.01")(shorter("0.01")(s))
            .replace("[particles]\n", "[particles]\nvelocity = [0.0, -2.0e-3]\n")
    });
    assert!(
        text.contains("settle = 0.01")
            && text.contains("crosses = [0.0, 1.0e-5]")
            && text.contains("-2.0e-3")
    );
    let rec = simulate(&text, t.path(), false).unwrap();
    let out = t.path().join("out");
    assert_eq!(rec.output.summary["steps"], 40, "{}", rec.output.summary);
    let (step, settling) = (column(&out, "step"), column(&out, "settling"));
    let (u, eps) = (column(&out, "plate_displacement"), column(&out, "eps_vol_dem"));
    for k in 0..step.len() {
        assert_eq!(settling[k], if step[k] < 20.0 { 1.0 } else { 0.0 }, "row {k}");
        if step[k] <= 20.0 {
            assert_eq!(u[k], 0.0, "the plate moved at step {}", step[k]);
        }
        if step[k] == 20.0 {
            assert_eq!(eps[k], 0.0, "A_0 is the settled sample's area");
        }
    }
    // Measured: ε_vol^DEM +1.9e-5 at step 15 (from the file's grains), the plate still.
    let held = eps[step.iter().position(|&s| s == 15.0).unwrap()];
    assert!(held != 0.0, "the grains did not move while the plate was held");
    let moved = *u.last().unwrap();
    assert!(
        (moved - 0.01 * 2.5e-3).abs() < 1e-9,
        "the plate moved {moved:e} m in the 0.01 s after the settling"
    );
    // The snapshot of the settled sample, one step after the plate starts.
    let index = std::fs::read_to_string(out.join("snapshots.csv")).unwrap();
    assert!(index.contains("\n21,"), "{index}");
    // Δp counts from the settled liquid's mean density (Su Eq. 19's ρ_0 as the deformation
    // starts), on liquid nodes only.
    liquid_nodes_only(&read_fluid(&first_snapshot(&out, "fluid")).unwrap());
    let dp = column(&out, "dp_mean");
    let at = |s: f64| dp[step.iter().position(|&x| x == s).unwrap()];
    // Measured: mean Δp +1.1e-3 Pa at step 15 (from ρ = 1, the grains pushing the liquid), −1.2e-13
    // Pa at step 20 as the plate starts (+5.6e-4 Pa with ρ_0 left at 1).
    assert!(
        at(15.0).abs() > 1e-4,
        "the settling liquid's mean Δp {}",
        at(15.0)
    );
    assert!(
        at(20.0).abs() < 1e-9,
        "mean Δp {} Pa as the plate starts",
        at(20.0)
    );

    // The analysis reads the shear: no settling rows, and the settled grains as reference.
    let run = crate::stages::run_data::Run::open(&out, Some(&t.path().join("scene/scene.toml"))).unwrap();
    assert!(run.series("settling").unwrap().iter().all(|&s| s == 0.0));
    assert_eq!(run.series("step").unwrap()[0], 20.0);
    // The sweeps' results and the atlas's run pairs read the series the same way.
    let sheared = crate::stages::run_data::read_series(&out.join("series.csv")).unwrap();
    assert_eq!(sheared.height(), run.series("step").unwrap().len());
    let first = run.grains(21).unwrap();
    assert!(
        run.initial_grains(&first).is_none(),
        "the file's grains are not the settled ones"
    );
}

/// The cell without its liquid (Su Fig. 11, right column: "LBM turned off").
fn dry(s: String) -> String {
    s.replace("[coupling]\n", "[coupling]\nliquid = false\n")
}

#[test]
fn the_same_cell_without_liquid_records_the_same_measures() {
    let t = tempfile::tempdir().unwrap();
    // A dry step is one DEM step: 0.05 s is 12 500 steps.
    let text = cell(t.path(), |s| {
        dry(s)
            .replace("time = 0.2\n", "time = 0.05\n")
            .replace("series = { every = 20 }", "series = { every = 500 }")
    });
    simulate(&text, t.path(), false).unwrap();
    let out = t.path().join("out");
    let eps = column(&out, "eps_vol_dem");
    let u = column(&out, "plate_displacement");
    assert!(
        (u.last().unwrap() - 0.05 * 2.5e-3).abs() < 1e-9,
        "u_y = {:?}",
        u.last()
    );
    assert!(eps.iter().all(|e| e.is_finite() && e.abs() < 0.05), "{eps:?}");
    assert_eq!(eps[0], 0.0, "ε_vol^DEM starts at 0 (A_def = A_0)");
    assert!(column(&out, "mean_stress").last().unwrap() > &0.0);
}

#[test]
fn shear_cell_set_ups_that_cannot_work_are_refused_before_anything_runs() {
    let t = tempfile::tempdir().unwrap();
    let cases: [(&dyn Fn(String) -> String, &str); 7] = [
        (
            // critical step about 1.5e-5 s (lightest grain 2.4e-7 kg, k_n 1000 N/m); the grain
            // springs allow up to 2 sqrt(m/(6k + 2k)) = 1.09e-5 s, a clump resting on a wall
            // only up to 8.84e-6 s (docs/stability.md, "Wall contacts of clumps")
            &|s: String| {
                s.replace("dt = 4.0e-6", "dt = 5.0e-5")
                    .replace("dt = 5.0e-4 ", "dt = 1.0e-3 ")
            },
            "[dem] dt: time step dt = 5e-5 s is above 8.8",
        ),
        (
            &|s: String| s.replace("[shear_cell]\nplate = \"plate\"", ""),
            "a moving wall is seen by the liquid only as the push-plate",
        ),
        (
            &|s: String| {
                s.replace("method = \"psm\"", "method = \"bounce-back\"")
                    .replace("collision = \"trt\"\nmagic = 0.25", "collision = \"bgk\"")
            },
            "method = \"psm\" only",
        ),
        (
            &|s: String| dry(s).replace("plate = \"plate\"", "plate = \"lid\""),
            "that wall does not move",
        ),
        (
            &|s: String| {
                moving_membrane(s).replace(
                    "plate = \"plate\"\n",
                    "plate = \"plate\"\nmembrane_relaxation = 0.0\n",
                )
            },
            "[shear_cell] membrane_relaxation = 0.0: the weight",
        ),
        (
            &|s: String| s.replace("lambda = 0.5 }", "lambda = 0.5, damping = 1.0 }"),
            "[bonds] params.damping = 1",
        ),
        (
            &|s: String| until_rest("1.0e-7", "0.01")(settled("0.02")(s)),
            "settle_until_rest.max_time = 0.01 s is shorter than settle = 0.02 s",
        ),
    ];
    for (k, (edit, msg)) in cases.iter().enumerate() {
        let dir = t.path().join(format!("c{k}"));
        let e = format!("{:#}", simulate(&cell(&dir, edit), &dir, false).unwrap_err());
        assert!(e.contains(msg), "case {k}: {e}");
        assert!(!dir.join("out").exists(), "case {k} left output behind");
    }
    // [shear_cell] without a membrane.
    let dir = t.path().join("nomem");
    let text = cell(&dir, |s| {
        let a = s.find("[bonds]").unwrap();
        let b = s.find("[dem]").unwrap();
        format!("{}{}", &s[..a], &s[b..])
    });
    let e = format!("{:#}", simulate(&text, &dir, false).unwrap_err());
    assert!(
        e.contains("[shear_cell] measures the sample inside its membrane"),
        "{e}"
    );
}

/// What a run of the reduced cell records at its end, for comparing speed switches (issue 13
/// item 7) against the paper's own steps.
#[derive(Debug)]
struct Measures {
    eps_vol: f64,
    /// Mean over the last quarter of the records: the plate force fluctuates as force chains
    /// form and break.
    plate_force: f64,
    displacement: f64,
    inertial: Vec<f64>,
    /// Rise of the grains above the plate, in 1 mm bands: the displacement profile.
    profile: Vec<f64>,
}

fn measured(dir: &Path, edit: impl Fn(String) -> String) -> Measures {
    let text = cell(dir, edit);
    simulate(&text, dir, false).unwrap();
    let out = dir.join("out");
    let before = read_particles(&dir.join("scene/reduced-grains.csv")).unwrap();
    let after = read_particles(&last_snapshot(&out, "particles")).unwrap();
    let mut profile = [(0.0, 0usize); 6];
    for c in 0..before.x.len() {
        let (x, y) = (before.body_x[c], before.body_y[c]);
        if x > 3e-3 && x < 5e-3 {
            let k = (((y - 1e-3) / 1e-3) as usize).min(5);
            profile[k].0 += after.body_y[c] - y;
            profile[k].1 += 1;
        }
    }
    let f = column(&out, "plate_force");
    let tail = &f[f.len() * 3 / 4..];
    Measures {
        eps_vol: *column(&out, "eps_vol_dem").last().unwrap(),
        plate_force: tail.iter().sum::<f64>() / tail.len() as f64,
        displacement: *column(&out, "plate_displacement").last().unwrap(),
        inertial: column(&out, "inertial_number"),
        profile: profile.iter().map(|(s, n)| s / (*n).max(1) as f64).collect(),
    }
}

/// The reduced cell at the paper's choices (every grain mapped every LBM step, unscaled
/// masses), run once for all the comparisons below.
fn paper_steps() -> &'static Measures {
    static BASE: std::sync::OnceLock<Measures> = std::sync::OnceLock::new();
    BASE.get_or_init(|| {
        let t = tempfile::tempdir().unwrap();
        measured(t.path(), |s| s)
    })
}

/// `b` within the relative tolerances `eps` (ε_vol^DEM) and `force` (plate force) of `a`, and
/// its displacement profile within `profile` × u_y of `a`'s.
fn assert_within(a: &Measures, b: &Measures, eps: f64, force: f64, profile: f64) {
    assert!(
        (a.eps_vol - b.eps_vol).abs() < eps * a.eps_vol.abs(),
        "ε_vol^DEM {} and {}",
        a.eps_vol,
        b.eps_vol
    );
    assert!(
        (a.plate_force - b.plate_force).abs() < force * a.plate_force.abs(),
        "plate force {} and {}",
        a.plate_force,
        b.plate_force
    );
    assert!(
        profile_gap(a, b) < profile * a.displacement,
        "profiles {:?} and {:?}",
        a.profile,
        b.profile
    );
}

/// Largest difference between two displacement profiles.
fn profile_gap(a: &Measures, b: &Measures) -> f64 {
    a.profile
        .iter()
        .zip(&b.profile)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Mass scaling (`[dem] mass_scale`, issue 13 item 7) on the reduced cell: ten times the masses
/// and a 3.1 times larger DEM step (4e-6 → 1.25e-5 s, LBM-DEM ratio 125 → 40) leave what the
/// run records within a few per cent at u_y = 1 d̄, and the inertial number quasi-static.
#[test]
fn mass_scaling_by_ten_leaves_the_strain_and_the_plate_force_unchanged() {
    let t = tempfile::tempdir().unwrap();
    let b = measured(t.path(), |s| {
        s.replace("dt = 4.0e-6", "dt = 1.25e-5\nmass_scale = 10.0")
    });
    let a = paper_steps();
    eprintln!("mass scaling: {a:?} and {b:?}");
    // Measured (2026-11-24, after the closed-form two-circle mass properties changed the
    // grains' inertia in the 10th digit): ε_vol^DEM 0.01580 and 0.01534 (2.9 %), plate force
    // (mean of the last quarter) 0.01101 and 0.01011 N (8.1 %), profiles at most 2.4 µm apart
    // (0.7 % of u_y = 351 µm). Before that change: 0.5 %, 1.6 %, 2.2 %. After the PSM's solid
    // term was summed in moments (2026-11-29, the liquid's forces changed in the last bits):
    // 0.014746 and 0.015681 (6.3 %), 0.010662 and 0.010257 N (3.8 %), profiles 2.8 µm (0.79 %).
    // The differences move with last-bit changes of the set-up, so they are of the order of the
    // chaotic spread of one realisation (the bias itself is measured over sixteen assemblies:
    // docs/su2020.md, "Mass scaling by 100"); the tolerances are twice the largest of the
    // three measurements.
    assert_within(a, &b, 0.13, 0.16, 0.045);
    // Quasi-static (I ≤ 1e-3, Su Sect. 3.4) once the grains carry stress: measured 3.7e-4
    // scaled, 1.2e-4 unscaled at the end.
    let i_end = *b.inertial.last().unwrap();
    assert!(
        i_end < 1e-3 && i_end > *a.inertial.last().unwrap(),
        "inertial numbers {:?}",
        (a.inertial.last(), i_end)
    );
}

/// A mass scale that follows the inertial number (`[dem.mass_scale_control]`, issue 13 item 7)
/// on the reduced cell: from scale 25 at the top, down to the grains' own masses (Table 3's
/// ratio here, 125) while the scaled I is over the target, up again where it stays well under
/// it. Every output either keeps the scaled I under the target or sits on the bottom rung, and
/// what the run records stays within a few per cent of the paper's own steps.
#[test]
fn a_mass_scale_that_follows_the_inertial_number_keeps_it_quasi_static_and_the_results() {
    let t = tempfile::tempdir().unwrap();
    let b = measured(t.path(), following("4.0e-4", 10));
    let out = t.path().join("out");
    let (ratio, scale) = (column(&out, "dem_steps_per_lbm_step"), column(&out, "mass_scale"));
    // The run went down to the bottom rung (the plate's first strokes, unscaled I about 2e-3 at
    // 2.5 mm/s) and came back up part of the way (measured: ratio 125, then 69 to 46, scales
    // 1 and 3.3 to 7.4).
    assert!(ratio.contains(&125.0), "ratios {ratio:?}");
    assert!(ratio.iter().any(|&r| r > 25.0 && r < 125.0), "ratios {ratio:?}");
    for ((&r, &m), &i) in ratio.iter().zip(&scale).zip(&b.inertial) {
        // The scale is the scene's 25 x (25 / r)^2 ...
        assert!((m - 25.0 * (25.0 / r).powi(2)).abs() < 1e-12 * m, "{r} {m}");
        // ... and the scaled I under 4e-4 wherever the ladder had a lighter rung to give; the
        // outputs fall between two choices, so up to 10 % over (measured: at most 3.2e-4 off
        // the bottom rung).
        assert!(r == 125.0 || i <= 4.4e-4, "I = {i} at ratio {r}");
    }
    let a = paper_steps();
    eprintln!("mass scale following I: {a:?} and {b:?}");
    // Measured (2026-11-30): ε_vol^DEM 0.014746 and 0.014807 (0.41 %), plate force 0.010662 and
    // 0.010898 N (2.2 %), profiles at most 0.69 µm apart (0.20 % of u_y = 351 µm): closer than
    // the fixed scale 10 (the note above), as the scale here stays under 7.4. Tolerances are
    // twice these; like the others they may need measuring again when a change moves the chaos.
    assert_within(a, &b, 0.009, 0.045, 0.004);
}

/// What `[dem.mass_scale_control]` refuses before anything runs: a smallest scale above the
/// scene's, a ladder of one rung, a scene without a shear cell to measure I in, a dry scene.
#[test]
fn a_mass_scale_control_without_a_ladder_or_an_inertial_number_is_refused() {
    let t = tempfile::tempdir().unwrap();
    let dir = t.path();
    let text = cell(dir, |s| {
        following("4.0e-4", 10)(s).replace("every = 10\n", "every = 10\nsmallest = 30.0\n")
    });
    assert_refused(
        simulate(&text, dir, false),
        "smallest = 30",
        "give a smaller one",
        dir,
    );
    let text = cell(dir, |s| {
        following("4.0e-4", 10)(s).replace("every = 10\n", "every = 10\nsmallest = 24.0\n")
    });
    assert_refused(
        simulate(&text, dir, false),
        "no other rung",
        "give a smaller smallest scale",
        dir,
    );
    let text = cell(dir, |s| {
        // Without the cell the plate must stand still: the liquid sees a moving wall only as a
        // confined sample's push-plate.
        following("4.0e-4", 10)(s)
            .replace("[shear_cell]\nplate = \"plate\"\n", "")
            .replace("velocity = [0.0, 2.5e-3]\n", "")
    });
    assert!(!text.contains("[shear_cell]"));
    assert_refused(
        simulate(&text, dir, false),
        "needs [shear_cell]",
        "add the cell",
        dir,
    );
}

/// Keeping the solid map between LBM steps (`[coupling] remap_tolerance`, issue 13 item 7): a
/// grain mapped again only once it moved 0.05 lattice cells (1.4 % of d̄ here, twice the
/// relative lag of Simulation I's 0.02 cells at 2.6 cells per d̄) leaves what the run records
/// as close to the paper's every-step map as run-to-run chaos allows.
#[test]
fn keeping_the_solid_map_within_a_twentieth_of_a_cell_leaves_the_results_unchanged() {
    let t = tempfile::tempdir().unwrap();
    let b = measured(t.path(), |s| {
        s.replace("r_hd = 0.8 ", "remap_tolerance = 0.05\nr_hd = 0.8 ")
    });
    let a = paper_steps();
    eprintln!("remap tolerance: {a:?} and {b:?}");
    // Measured (2026-11-24): ε_vol^DEM 0.015802 and 0.015719 (0.52 %), plate force 0.011008 and
    // 0.010948 N (0.54 %), profiles at most 1.0 µm apart (0.29 % of u_y = 351 µm): smaller than
    // the spread last-bit changes of the set-up cause (the mass-scaling note above). Tolerances
    // are twice these; a change of the code that moves the chaos may need them measured again.
    assert_within(a, &b, 0.011, 0.011, 0.006);
}

/// A lower damping ratio on the grain-wall law (`[wall_contact] damping`, issue 13 item 7): the
/// wall-contact step limit grows with it (docs/stability.md, "Wall contacts of clumps"), which is
/// what lets `sim1-quick.toml` keep its DEM step. The wall law here is the cell's pair law with
/// ζ 0.3 instead of 0.5, at the same step; what the run records stays within run-to-run chaos.
#[test]
fn a_lower_wall_damping_ratio_leaves_the_results_unchanged() {
    let t = tempfile::tempdir().unwrap();
    let b = measured(t.path(), |s| {
        s.replace(
            "[bonds]",
            "[wall_contact]\nlaw = \"linear\"\nk_n = 1000.0\nk_t = 500.0\ndamping = { ratio = 0.3 }\n\
             mu = 0.05\nrolling = { k_r = 1.0e-5, mu_r = 0.5 }\n\n[bonds]",
        )
    });
    let a = paper_steps();
    eprintln!("wall damping 0.3: {a:?} and {b:?}");
    // Measured (2026-11-28): ε_vol^DEM 0.014746 and 0.014695 (0.34 %), plate force 0.010649 and
    // 0.010692 N (0.40 %), profiles at most 0.22 µm apart (0.061 % of u_y = 351 µm), below the
    // spread last-bit changes of the set-up cause (the mass-scaling note above). Tolerances are
    // twice these; a change of the code that moves the chaos may need them measured again.
    assert_within(a, &b, 0.007, 0.008, 0.0013);
}

/// A push-plate drawn into the bottom row (as an assembly built inside servo walls leaves it:
/// the 84 %PK assembly by 4.5 µm) is moved back along its motion until it just touches the
/// grains, so the first step kicks none (docs/minimal.md: the unscaled pk84-2150um scene blew
/// up at LBM step 217 from that kick).
#[test]
fn a_plate_drawn_into_the_grains_starts_just_touching_them() {
    let t = tempfile::tempdir().unwrap();
    let text = cell(t.path(), |s| {
        dry(s).replace(
            "a = [0.003, 0.00102]\nb = [0.005, 0.00102]",
            "a = [0.003, 0.0011]\nb = [0.005, 0.0011]",
        )
    });
    assert!(text.contains("a = [0.003, 0.0011]"));
    let path = t.path().join("scene/scene.toml");
    std::fs::write(&path, text).unwrap();
    let l = crate::scenes::schema::load(&path, &Default::default()).unwrap();
    let built = crate::scenes::models::dry::Dry::build(&l.scene, &l.base_dir, true).unwrap();
    let (sys, k) = (&built.sys, 0);
    let b = &sys.bodies;
    let overlaps: Vec<f64> = (0..b.n_circles())
        .filter_map(|c| sys.walls[k].touch_within(b.circle_pos(c), b.circle_r[c], 1e-12))
        .map(|(o, _)| o)
        .collect();
    // Touching (within 1e-12 m), overlapping nothing.
    assert!(
        !overlaps.is_empty() && overlaps.iter().all(|o| *o <= 1e-12),
        "{overlaps:?}"
    );
    let y = match sys.walls[k].shape {
        lbdem_dem::WallShape::Segment { a, .. } => a.y,
        _ => unreachable!(),
    };
    assert!(y < 0.0011 - 1e-6, "the plate did not move: {y}");
}

/// The 84 %PK assembly at Table 1's masses (grains 0.96 times the liquid's density), the plate
/// at rest, 30 LBM steps: the grains pick up speed from the start (the liquid and the membrane
/// settle together), then slow down. With the membrane's outside nodes showing the liquid the
/// membrane grains' velocity, as the solid zone did before 2026-11-25, the same run only
/// speeds up (its kinetic energy grew every step, 4.2 times this run's peak by step 20) and runs
/// away within 0.02 s: the zone put momentum into the liquid that no grain paid for
/// (docs/su2020.md, "The liquid confined to the sample").
#[test]
fn an_undriven_sample_at_the_papers_densities_settles_in_its_confined_liquid() {
    let t = tempfile::tempdir().unwrap();
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/su2020");
    let src = t.path().join("scene");
    std::fs::create_dir_all(src.join("assemblies/pk84")).unwrap();
    // The zone at rest, which this test is about (the shipped scenes show the liquid the
    // membrane's motion since 2026-11-29; with it the undriven sample's kinetic energy still
    // grew at step 30, 9.9e-13 J, as the liquid no longer holds the membrane back).
    let base = std::fs::read_to_string(scenes.join("shear-base.toml")).unwrap();
    let at_rest = base.replace(
        "membrane_boundary = \"moving\"",
        "membrane_boundary = \"at_rest\"",
    );
    assert_ne!(base, at_rest);
    std::fs::write(src.join("shear-base.toml"), at_rest).unwrap();
    for file in ["assembly.csv", "assembly.json"] {
        let at = format!("assemblies/pk84/{file}");
        std::fs::copy(scenes.join(&at), src.join(&at)).unwrap();
    }
    let text = shipped("su2020/pk84-2150um.toml");
    let text = text
        .replace("velocity = [0.0, 0.00215]", "velocity = [0.0, 1.0e-9]")
        .replace("time = 0.56372", "time = 0.00279");
    assert!(text.contains("1.0e-9") && text.contains("0.00279"));
    simulate(&text, t.path(), false).unwrap();
    let ke = column(&t.path().join("out"), "kinetic_energy");
    assert_eq!(ke.len(), 30);
    let peak = ke.iter().cloned().fold(0.0, f64::max);
    // Measured: 7.25e-14 J at step 1, peak 8.67e-13 J at step 15, 6.51e-13 J (0.75 of it) at
    // step 30.
    assert!(peak > 5.0 * ke[0], "the grains never picked up speed: {ke:?}");
    assert!(
        ke[29] < 0.85 * peak,
        "kinetic energy {:.3e} J at step 30, peak {peak:.3e} J: the grains do not settle",
        ke[29]
    );
}

/// The near-neutral-grain check agrees with the density-ratio map (docs/stability.md): the
/// reduced cell with grains 0.45 times the liquid's density (mass scale 0.5; every such run
/// blew up) is refused before it starts and leaves nothing behind, at 0.56 (every such run
/// finished) it runs.
#[test]
fn grains_lighter_than_half_the_liquid_are_refused_as_the_density_map_found() {
    for (scale, refused) in [(0.5, true), (0.625, false)] {
        let t = tempfile::tempdir().unwrap();
        let text = cell(t.path(), |s| {
            shorter("0.001")(s).replace("[dem]\n", &format!("[dem]\nmass_scale = {scale}\n"))
        });
        assert!(text.contains(&format!("mass_scale = {scale}")));
        let got = simulate(&text, t.path(), false);
        if refused {
            assert_refused(
                got,
                "0.451 times the liquid's",
                "mass_scale to at least",
                t.path(),
            );
        } else {
            got.unwrap();
        }
    }
}
