//! Lid-driven square cavity against Ghia, Ghia & Shin, J. Comput. Phys. 48 (1982) 387, Table I:
//! u along the vertical centre line x = 0.5 (129 x 129 grid for Re = 100 and 1000).
//! Lid = halfway bounce-back wall moving at U (Leonardi Eq. 19); the other walls at rest.

#![allow(clippy::needless_range_loop)]
use crate::common;
use common::*;
use lbdem_lbm::{Collision, D2Q9, Domain, Face, Fluid, Stepper};

const GHIA_Y: [f64; 17] = [
    1.0000, 0.9766, 0.9688, 0.9609, 0.9531, 0.8516, 0.7344, 0.6172, 0.5000, 0.4531, 0.2813, 0.1719, 0.1016,
    0.0703, 0.0625, 0.0547, 0.0000,
];
const GHIA_U_RE100: [f64; 17] = [
    1.0, 0.84123, 0.78871, 0.73722, 0.68717, 0.23151, 0.00332, -0.13641, -0.20581, -0.21090, -0.15662,
    -0.10150, -0.06434, -0.04775, -0.04192, -0.03717, 0.0,
];
const GHIA_U_RE1000: [f64; 17] = [
    1.0, 0.65928, 0.57492, 0.51117, 0.46604, 0.33304, 0.18719, 0.05702, -0.06080, -0.10648, -0.27805,
    -0.38289, -0.29730, -0.22220, -0.20196, -0.18109, 0.0,
];

/// Largest |u/U − Ghia| over the interior table points.
fn cavity(n: usize, re: f64, u_lid: f64, collision_of: impl Fn(f64) -> Collision, table: &[f64; 17]) -> f64 {
    let nu = u_lid * n as f64 / re;
    let coll = collision_of(0.5 + 3.0 * nu);
    let wall = Face::Wall { velocity: [0.0; 3] };
    let lid = Face::Wall {
        velocity: [u_lid, 0.0, 0.0],
    };
    let dom = Domain::new([n, n, 1], [wall, wall, wall, lid, Face::Periodic, Face::Periodic]);
    let mut fluid = Fluid::<D2Q9, f64>::new(dom, no_obstacles());
    let mut st = Stepper::new(&fluid, settings(coll, [0.0; 3])).unwrap();
    let (m, steps) = run_steady(&mut fluid, &mut st, 1000, 1e-7 * u_lid, 200 * n * n);
    // centre line: node columns n/2 - 1 and n/2 straddle x = 0.5 (node x at (i + 1/2)/n)
    let col = |y: usize| 0.5 * (m.u[3 * (y * n + n / 2 - 1)] + m.u[3 * (y * n + n / 2)]) / u_lid;
    let mut worst: f64 = 0.0;
    for k in 1..16 {
        let yy = GHIA_Y[k] * n as f64 - 0.5;
        let j = (yy.floor() as usize).min(n - 2);
        let t = yy - j as f64;
        let u = (1.0 - t) * col(j) + t * col(j + 1);
        worst = worst.max((u - table[k]).abs());
    }
    eprintln!("cavity N={n} Re={re}: max |u/U - Ghia| = {worst:.4} after {steps} steps");
    worst
}

#[test]
fn re100_matches_ghia() {
    let err = cavity(64, 100.0, 0.1, |tau| Collision::Bgk { tau }, &GHIA_U_RE100);
    // 64 nodes across: measured 0.0061 of the lid speed at the worst table point (test
    // profile, deterministic); the tolerance is twice that.
    assert!(err < 0.012, "{err}");
}

/// `cargo test --release -p lbdem-lbm --test lbm cavity:: -- --ignored`
#[test]
#[ignore]
fn re1000_matches_ghia() {
    let err = cavity(
        256,
        1000.0,
        0.1,
        |tau| Collision::Trt { tau, magic: 0.25 },
        &GHIA_U_RE1000,
    );
    // Measured 0.0061 (docs/lbm.md, release); the tolerance is twice that.
    assert!(err < 0.012, "{err}");
}
