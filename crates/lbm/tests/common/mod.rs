//! Shared helpers of the validation tests.
#![allow(dead_code)]

use lbdem_lbm::{Collision, Fluid, Lattice, Limits, Macro, Motion, Real, Settings, Stepper};

pub fn settings(collision: Collision, force: [f64; 3]) -> Settings {
    Settings {
        collision,
        force,
        limits: Limits::default(),
    }
}

/// Run until the largest change of u over `every` steps falls below `tol` (absolute, lattice
/// units) or `max_steps` pass; returns the last macroscopic fields and the steps run.
pub fn run_steady<L: Lattice, T: Real>(
    fluid: &mut Fluid<L, T>,
    st: &mut Stepper<L, T>,
    every: usize,
    tol: f64,
    max_steps: usize,
) -> (Macro, usize) {
    let mut m = Macro::default();
    let mut prev: Vec<f64> = Vec::new();
    let mut steps = 0;
    while steps < max_steps {
        for k in 0..every {
            let out = if k + 1 == every { Some(&mut m) } else { None };
            st.step(fluid, out).expect("stable run");
        }
        steps += every;
        if !prev.is_empty() {
            let d =
                m.u.iter()
                    .zip(&prev)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
            if d < tol {
                break;
            }
        }
        prev.clone_from(&m.u);
    }
    (m, steps)
}

#[allow(unused_imports)] // not every test binary uses it
pub use lbdem_lbm::cases::poiseuille::channel;

pub fn no_obstacles() -> Vec<Motion> {
    Vec::new()
}
