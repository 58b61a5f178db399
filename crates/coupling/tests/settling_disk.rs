//! A disk settling midway between two walls at Re ≈ 0.06 reaches the terminal velocity of the
//! Faxén (1946) wall-corrected Stokes drag (see `lbdem_coupling::cases::settling` for the
//! formula and its sources; Happel & Brenner 1965; Ben Richou et al., Chem. Eng. Sci. 59 (2004)
//! 3215).

use lbdem_coupling::Method;
use lbdem_coupling::cases::settling::{SettlingSpec, faxen_drag, run};

#[test]
fn faxen_formula_values() {
    // Limits of the expansion: drag grows as the walls close in, and ln(1/k) dominates far away.
    assert!(faxen_drag(0.5) > faxen_drag(0.25) && faxen_drag(0.25) > faxen_drag(0.1));
    let k: f64 = 1e-3;
    let far = 4.0 * std::f64::consts::PI / ((1.0 / k).ln() - 0.9157);
    assert!((faxen_drag(k) / far - 1.0).abs() < 1e-6);
}

fn check(n: usize, method: Method, tol: f64) -> f64 {
    let spec = SettlingSpec {
        cells_per_diameter: n,
        method,
        ..Default::default()
    };
    let r = run::<f64>(&spec).expect("stable run");
    eprintln!(
        "{method:?} d = {n} cells: U = {:.4e} m/s (the sixth before {:.4e}), Faxen {:.4e}, error {:+.2}%, \
         Re {:.3}, drift {:.2e} m, {} steps, {:.1} s",
        r.velocity,
        r.velocity_earlier,
        r.reference,
        100.0 * r.error,
        r.reynolds,
        r.drift,
        r.lbm_steps,
        r.wall_seconds
    );
    assert!(
        ((r.velocity - r.velocity_earlier) / r.velocity).abs() < 1e-2,
        "not terminal yet"
    );
    assert!(r.error.abs() < tol, "error {}", r.error);
    assert!(r.drift.abs() < 1e-3 * spec.diameter, "left the mid-plane");
    r.error
}

/// 16 cells per diameter: PSM within 3 % (measured +2.0 %; +5.1 % at 10 cells, +0.9 % at 24,
/// +0.5 % at 32). Bounce-back (measured -1.0 %) runs in the ignored test below.
#[test]
fn psm_disk_reaches_faxen_terminal_velocity() {
    check(16, Method::Psm, 0.03);
}

/// Both methods over resolution; PSM's error must fall with every refinement:
/// `cargo test --release -p lbdem-coupling --test coupling settling_disk:: -- --ignored --nocapture`
/// (about 5 minutes; 32 cells per diameter adds 15 more).
#[test]
#[ignore]
fn settling_converges_with_resolution() {
    let mut last = f64::INFINITY;
    for n in [10, 16, 24] {
        let e = check(n, Method::Psm, 0.06).abs();
        assert!(e < last, "PSM error {e} did not fall at {n} cells per diameter");
        last = e;
        check(n, Method::BounceBack, 0.015);
    }
    assert!(last < 0.015);
}
