//! Shared helpers of the coupling validation tests.
#![allow(dead_code)]

use lbdem_coupling::solid_fraction::{GrainCircle, SolidMap, solid_map};
use lbdem_coupling::{GrainMotion, Load, PsmFluid, PsmSettings};
use lbdem_lbm::{Domain, Face, Limits};

/// A PSM lattice of nx × ny nodes walled on all four sides, liquid at rest, BGK at `tau`.
pub fn walled_box(nx: usize, ny: usize, tau: f64) -> PsmFluid<f64> {
    let wall = Face::Wall { velocity: [0.0; 3] };
    PsmFluid::<f64>::new(
        &Domain::new(
            [nx, ny, 1],
            [wall, wall, wall, wall, Face::Periodic, Face::Periodic],
        ),
        settings(tau, [0.0; 2]),
    )
    .unwrap()
}

pub fn settings(tau: f64, force: [f64; 2]) -> PsmSettings {
    PsmSettings {
        collision: lbdem_lbm::Collision::Bgk { tau },
        force,
        limits: Limits::default(),
    }
}

/// Fixed grains (zero velocity) given as circles; one body per circle unless grouped.
pub fn fixed(
    circles: &[GrainCircle],
    nx: usize,
    ny: usize,
    periodic: [bool; 2],
) -> (SolidMap, Vec<GrainMotion>) {
    let map = solid_map(circles, 1.0, nx, ny, periodic);
    let n_bodies = circles.iter().map(|c| c.body as usize + 1).max().unwrap_or(0);
    let motions = (0..n_bodies)
        .map(|b| {
            let c = circles.iter().find(|c| c.body as usize == b).unwrap();
            GrainMotion {
                centre: c.centre,
                ..Default::default()
            }
        })
        .collect();
    (map, motions)
}

/// Run until the mean x velocity changes by less than `tol` (relative) over `every` steps;
/// panics if that does not happen within `max_steps`.
pub fn run_steady(
    fluid: &mut PsmFluid<f64>,
    map: &SolidMap,
    motions: &[GrainMotion],
    every: usize,
    tol: f64,
    max_steps: usize,
) -> (Vec<Load>, usize) {
    let mut loads = Vec::new();
    let mut last = f64::NAN;
    let mut steps = 0;
    while steps < max_steps {
        for _ in 0..every {
            fluid.step(map, motions, &mut loads).expect("stable run");
        }
        steps += every;
        let u = mean_u(fluid)[0];
        if ((u - last) / u).abs() < tol {
            return (loads, steps);
        }
        last = u;
    }
    panic!("not steady after {max_steps} steps (mean u changing by more than {tol} per {every} steps)");
}

/// Mean velocity over every node (the superficial velocity).
pub fn mean_u(fluid: &PsmFluid<f64>) -> [f64; 2] {
    let n = fluid.u.len() as f64;
    let s = fluid.u.iter().fold([0.0; 2], |a, u| [a[0] + u[0], a[1] + u[1]]);
    [s[0] / n, s[1] / n]
}

/// Box with walls on every face (2D).
pub fn closed_box(nx: usize, ny: usize) -> Domain {
    let w = Face::Wall { velocity: [0.0; 3] };
    Domain::new([nx, ny, 1], [w, w, w, w, Face::Periodic, Face::Periodic])
}
