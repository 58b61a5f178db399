//! Accuracy of the partially-saturated-cells coupling (Su et al. 2020 Eqs. 9-14) at the paper's
//! resolution: dx = 40 µm for grains of mean diameter d̄ = 120 µm with the hydrodynamic radius
//! factor r_hd = 0.8 (Su Sect. 2.3) is 2.4 cells per hydrodynamic diameter. The other coupling
//! tests start at 10-11 cells per diameter. BGK at τ = 1, as `sangani_psm.rs` and `darcy.rs`.
//!
//! What these tests pin down (figures from the runs quoted in each test; `lbdem bench resolution`
//! prints the whole table):
//! - At 2.4 cells per diameter PSM lets the liquid through the partly covered cells: the drag on
//!   a dilute disk array is half Sangani & Acrivos's, and a packed two-circle assembly is about
//!   40 times too permeable. Both errors fall steadily as the lattice is refined.
//! - The Eq. 14 drag balances the body force on the liquid at every resolution (momentum is
//!   exchanged exactly even when the drag is wrong).
//!
//! The sub-cell position of a disk matters at this resolution: each figure is the mean over 2 × 2
//! offsets of the centre (0 or ½ cell along x and y), and the spread is printed.
//!
//! The fine-lattice reference of the packing is run by the ignored test:
//! `cargo test --release -p lbdem-coupling --test coupling low_resolution:: -- --ignored --nocapture`
//! (about 1 minute on two cores).

use lbdem_coupling::cases::resolution::*;

const TAU: f64 = 1.0;

fn steady() -> Steady {
    Steady {
        tol: 1e-7,
        ..Steady::default()
    }
}

/// Mean F/(μU) over `k` × `k` sub-cell offsets at about `n` cells per diameter, with the
/// smallest and largest, each run's Eq. 14 drag checked against the body force on the liquid.
fn disk_drag(phi: f64, n: f64, k: usize) -> (f64, f64, f64) {
    let v: Vec<f64> = offsets(k)
        .into_iter()
        .map(|o| {
            let r = disk_array(phi, n, o, TAU, &steady()).expect("steady disk array");
            assert!(
                (r.balance - 1.0).abs() < 1e-4,
                "Φ {phi}, {n} cells, offset {o:?}: Eq. 14 drag / force on the liquid = {}",
                r.balance
            );
            r.drag
        })
        .collect();
    spread(&v)
}

/// Relative error of the mean F/(μU) against Sangani & Acrivos 1982 Table 1, printed with its
/// spread over the offsets.
fn disk_error(phi: f64, n: f64, k: usize) -> f64 {
    let want = sangani_acrivos(phi).expect("tabulated Φ");
    let (m, lo, hi) = disk_drag(phi, n, k);
    let e = m / want - 1.0;
    eprintln!(
        "disk array Φ {phi}, {n} cells/d: F/(μU) = {m:.3} [{lo:.3}, {hi:.3}] over {} offsets, \
         Sangani-Acrivos {want}: error {:+.1} % [{:+.1}, {:+.1}]",
        k * k,
        100.0 * e,
        100.0 * (lo / want - 1.0),
        100.0 * (hi / want - 1.0)
    );
    e
}

/// Dilute array (Φ = 0.1, Sangani & Acrivos 1982 Table 1: F/(μU) = 24.83) at Su's 2.4 cells per
/// diameter: PSM gives half the drag. Measured −49.6 % (offsets −51.9 to −46.6 %); asserted within
/// [−60, −40] %, so the test fails if the coarse drag either improves or worsens by a fifth.
#[test]
fn dilute_array_drag_is_half_the_table_at_paper_resolution() {
    let e = disk_error(0.1, PAPER_CELLS, 2);
    assert!((-0.60..=-0.40).contains(&e), "error {e}");
}

/// Denser arrays at 2.4 cells per diameter (Sangani & Acrivos Table 1: 102.90 at Φ = 0.3, 532.55
/// at Φ = 0.5): the gap between neighbouring disks is 0.62 and 0.25 d, about 1.5 and 0.6 cells,
/// and the drag is 5 and 25 times too low. Measured −81.3 % at Φ = 0.3 (−82.8 to −79.4 %) and
/// −96.1 % at Φ = 0.5 (−96.6 to −95.6 %, a period of 3 cells, 2.39 cells per diameter);
/// asserted within [−90, −70] % and [−98.5, −92] %.
#[test]
fn dense_array_drag_at_paper_resolution() {
    let e3 = disk_error(0.3, PAPER_CELLS, 2);
    assert!((-0.90..=-0.70).contains(&e3), "Φ 0.3: error {e3}");
    let e5 = disk_error(0.5, PAPER_CELLS, 2);
    assert!((-0.985..=-0.92).contains(&e5), "Φ 0.5: error {e5}");
}

/// The error against Sangani & Acrivos (Φ = 0.1, Table 1) falls from 2.4 to 5 to 10 cells per
/// diameter, and at 10 cells it is within 11 % (measured −5.7 %, unshifted; the
/// 2.4- and 5-cell means are −49.6 and −18.7 %).
#[test]
fn array_error_falls_from_paper_resolution_to_ten_cells() {
    let e: Vec<f64> = [(PAPER_CELLS, 2), (5.0, 2), (10.0, 1)]
        .iter()
        .map(|&(n, k)| disk_error(0.1, n, k).abs())
        .collect();
    assert!(e[0] > e[1] && e[1] > e[2], "no convergence: {e:?}");
    assert!(e[2] < 0.11, "10 cells: {}", e[2]);
}

/// The packed assembly (`two_circle_packing(7)`: 32 two-circle grains, packing fraction π/4,
/// r_hd = 0.8, hydrodynamic solid fraction 0.54 on the lattice).
const SEED: u64 = 7;

/// Its permeability k/d̄² extrapolated from the fine lattices: 1.6012e-3 at 20 and 1.2057e-3 at
/// 40 cells per diameter (successive differences from 10 cells shrink 3.9×: second order), so
/// k = 1.2057e-3 − (1.6012e-3 − 1.2057e-3)/3 = 1.0738e-3 (`fine_lattice_reference`).
const FINE_K: f64 = 1.0738e-3;

/// Mean k/d̄² over 2 × 2 offsets of the whole assembly (k = 1 offset: unshifted).
fn packing_k(n: f64, k: usize) -> f64 {
    let p = two_circle_packing(SEED).expect("packing");
    let v: Vec<f64> = offsets(k)
        .into_iter()
        .map(|o| {
            let r = packing_permeability(&p, n, R_HD, o, TAU, &steady()).expect("steady packing");
            assert!(
                (r.balance - 1.0).abs() < 1e-4,
                "{n} cells, offset {o:?}: Eq. 14 drag / force on the liquid = {}",
                r.balance
            );
            r.permeability
        })
        .collect();
    let (m, lo, hi) = spread(&v);
    eprintln!(
        "packing, {n} cells/d: k/d̄² = {m:.4e} [{lo:.4e}, {hi:.4e}] over {} offsets, {:.2} × the fine-lattice \
         value {FINE_K:.4e}",
        k * k,
        m / FINE_K
    );
    m
}

/// The packing generator is deterministic and gives the packing fraction it is built for.
#[test]
fn packing_is_deterministic_and_at_pi_over_four() {
    let a = two_circle_packing(SEED).expect("packing");
    assert_eq!(a, two_circle_packing(SEED).expect("packing"));
    assert_eq!(a.grains.len(), PACKING_GRAINS);
    assert!((a.packing_fraction - std::f64::consts::FRAC_PI_4).abs() < 1e-9);
    assert_ne!(a, two_circle_packing(SEED + 1).expect("packing"));
}

/// Permeability at Su's 2.4 cells per diameter against the fine-lattice result of the same
/// assembly (`FINE_K`): measured 41.1 × too permeable (offsets 40.6-41.4 ×), then 8.98 × at 5 cells
/// and 2.94 × at 10 (unshifted). Asserted: 30-55 × at 2.4 cells, 6.5-12 × at 5, 2-4 × at 10, falling.
#[test]
fn packing_permeability_against_fine_lattice() {
    let r: Vec<f64> = [(PAPER_CELLS, 2), (5.0, 2), (10.0, 1)]
        .iter()
        .map(|&(n, k)| packing_k(n, k) / FINE_K)
        .collect();
    assert!((30.0..=55.0).contains(&r[0]), "2.4 cells: {}", r[0]);
    assert!((6.5..=12.0).contains(&r[1]), "5 cells: {}", r[1]);
    assert!((2.0..=4.0).contains(&r[2]), "10 cells: {}", r[2]);
    assert!(r[0] > r[1] && r[1] > r[2], "no convergence: {r:?}");
}

/// The fine-lattice reference of the packing (`FINE_K`): 20 and 40 cells per diameter, unshifted,
/// extrapolated at second order; the constant must be within 0.5 % of the rerun, and the
/// differences from 10 to 20 to 40 cells must shrink at least 3× (second order: 4×).
/// `cargo test --release -p lbdem-coupling --test coupling low_resolution:: -- --ignored --nocapture`
/// (about 40 s on two cores).
#[test]
#[ignore]
fn fine_lattice_reference() {
    let k: Vec<f64> = [10.0, 20.0, 40.0].iter().map(|&n| packing_k(n, 1)).collect();
    let (d1, d2) = (k[0] - k[1], k[1] - k[2]);
    let fine = k[2] - d2 / 3.0;
    eprintln!(
        "k/d̄² at 10, 20, 40 cells: {k:?}; differences shrink {:.2}×; extrapolated {fine:.4e}",
        d1 / d2
    );
    assert!(d1 > 3.0 * d2, "not second order: {k:?}");
    assert!((fine / FINE_K - 1.0).abs() < 0.005, "{fine} vs {FINE_K}");
}

/// The disk arrays on the fine lattice (40 cells per diameter, unshifted) against Sangani &
/// Acrivos Table 1: measured −0.25, −1.5 and −7.4 % at Φ = 0.1, 0.3 and 0.5 (the gap at Φ = 0.5
/// is only 10 cells); asserted within 0.5, 3 and 15 %.
/// `cargo test --release -p lbdem-coupling --test coupling low_resolution:: -- --ignored --nocapture`
/// (about 20 s).
#[test]
#[ignore]
fn fine_disk_arrays_meet_the_table() {
    for (phi, tol) in [(0.1, 0.005), (0.3, 0.03), (0.5, 0.15)] {
        let e = disk_error(phi, 40.0, 1);
        assert!(e.abs() < tol, "Φ {phi}: error {e}");
    }
}
