//! The incline scene (Leonardi et al. 2014 Sect. 6; `scenes/leonardi2014/`) through the runner
//! as `lbdem simulate` runs it: the quick coarse incline lifts its box, spreads its paste keeping
//! the mass and the volume, writes its thickness and section tables, and an interrupted run
//! resumes to the same bits.

use super::*;
use crate::report::table::{f64_column, read_table};

/// The shipped quick incline, `edit`ed, written beside the base it extends.
fn quick(dir: &Path, edit: impl Fn(String) -> String) -> String {
    let src = dir.join("scene");
    std::fs::create_dir_all(&src).unwrap();
    std::fs::write(src.join("incline.toml"), shipped("leonardi2014/incline.toml")).unwrap();
    edit(shipped("leonardi2014/incline-quick.toml"))
}

fn column(dir: &Path, file: &str, name: &str) -> Vec<f64> {
    let p = dir.join("out").join(file);
    f64_column(&read_table(&p).unwrap(), name, &p).unwrap()
}

#[test]
fn the_quick_incline_lifts_its_box_and_spreads_its_paste_keeping_mass_and_volume() {
    let t = tempfile::tempdir().unwrap();
    let rec = simulate(&quick(t.path(), |s| s), t.path(), false).unwrap();
    assert_eq!(rec.output.summary["steps"], 400);
    let (time, lifted, runout, drift) = (
        column(t.path(), "series.csv", "time"),
        column(t.path(), "series.csv", "lifted"),
        column(t.path(), "series.csv", "runout"),
        column(t.path(), "series.csv", "mass_drift"),
    );
    for k in 0..time.len() {
        // the box rises at 0.15 m/s; the paste's mass is kept (measured ≤ 5.9e-15)
        assert!(
            (lifted[k] - 0.15 * time[k]).abs() < 1e-9,
            "lifted {} at {} s",
            lifted[k],
            time[k]
        );
        assert!(
            drift[k].abs() < 1.2e-14,
            "mass drift {:e} at {} s",
            drift[k],
            time[k]
        );
    }
    // the paste runs down the board: 0.13 m past the box at 0.285 s (measured)
    let last = *runout.last().unwrap();
    assert!(
        last > 0.08 && runout.windows(2).all(|w| w[1] >= w[0] - 0.011),
        "runout {runout:?}"
    );
    // the paste on the board, Σ thickness dx², is the cube's 15³ nodes of 1 cm (3.375e-3 m³):
    // measured 3.406e-3 (+0.9 %: the paste started hydrostatic, up to 2.4 % denser at the bottom,
    // and spreads thin)
    let th = column(t.path(), "snapshots/thickness_000000400.csv", "thickness");
    let volume: f64 = th.iter().sum::<f64>() * 1e-4;
    assert!((volume / 3.375e-3 - 1.0).abs() < 0.02, "volume {volume}");
    let mu = column(t.path(), "snapshots/section_000000400.csv", "viscosity");
    assert!(mu.iter().any(|m| m.is_finite()) && mu.iter().any(|m| m.is_nan()));
    // the creep monitor (issue 20 item 6) counts only windows with 95 % of the paste at τ_max:
    // this paste is still spreading (rigid share under 0.95 throughout), so nothing is counted
    // and no creep named; but its front, one or two 1 cm nodes thick and fast, at τ_min 0.501
    // where it shears, flips 2.4e-2 of its interface nodes per step (measured; limit 1e-2), and
    // that is named
    let (creep, rigid) = (
        column(t.path(), "series.csv", "creep"),
        column(t.path(), "series.csv", "rigid_share"),
    );
    assert!(rigid.iter().all(|&r| r < 0.95), "{rigid:?}");
    assert!(creep.iter().all(|&c| c == 0.0), "{creep:?}");
    let warnings = rec.output.summary["warnings"].as_array().unwrap();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    let w = warnings[0].as_str().unwrap();
    assert!(
        w.contains("back and forth") && w.contains("refine the lattice"),
        "{w}"
    );
}

#[test]
fn interrupted_and_resumed_incline_matches_uninterrupted_bitwise() {
    let t = tempfile::tempdir().unwrap();
    let whole_text = quick(&t.path().join("whole"), |s| {
        s.replace("time = 0.3", "time = 0.15")
    });
    simulate(&whole_text, &t.path().join("whole"), false).unwrap();
    let cut = t.path().join("cut");
    let text = quick(&cut, |s| s.replace("time = 0.3", "time = 0.15\nwall_clock = 0.2"));
    // Every attempt makes at least one of the 200 steps; on a loaded machine (2 cores shared
    // with a build, 2026-12-02) an attempt made only one, and a bound of 100 failed the test.
    let interruptions = resume_until_done(&text, &cut, 201);
    for f in [
        "series.csv",
        "snapshots/thickness_000000200.csv",
        "snapshots/spheres_000000200.csv",
    ] {
        let (x, y) = (
            std::fs::read(t.path().join("whole/out").join(f)).unwrap(),
            std::fs::read(cut.join("out").join(f)).unwrap(),
        );
        assert!(x == y, "{f} differs after {interruptions} interruptions");
    }
}
