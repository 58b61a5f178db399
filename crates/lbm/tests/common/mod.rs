//! Shared helpers of the validation tests.
#![allow(dead_code)]

use lbdem_lbm::{Collision, Domain, Face, Fluid, Lattice, Limits, Macro, Motion, Real, Settings, Stepper};

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

/// A lattice with every kind of node (moving lid, a moving and spinning obstacle, periodic x
/// edges) and a non-uniform start: the fixture of the local-τ and Bingham kernel comparisons.
pub fn busy_fluid<L: Lattice, T: Real>(n: [usize; 3]) -> Fluid<L, T> {
    let lid = Face::Wall {
        velocity: [0.02, 0.0, 0.0],
    };
    let wall = Face::Wall { velocity: [0.0; 3] };
    let mut dom = Domain::new(
        n,
        [
            Face::Periodic,
            Face::Periodic,
            wall,
            lid,
            Face::Periodic,
            Face::Periodic,
        ],
    );
    let c = [
        n[0] as f64 / 3.0,
        n[1] as f64 / 2.0,
        if n[2] > 1 { n[2] as f64 / 2.0 } else { 0.0 },
    ];
    dom.fill_sphere(0, c, n[1] as f64 / 5.0);
    let mut fl = Fluid::<L, T>::new(
        dom,
        vec![Motion {
            centre: c,
            velocity: [0.0, 0.005, 0.0],
            omega: [0.0, 0.0, 2e-3],
        }],
    );
    fl.init_equilibrium(|p| (1.0 + 1e-3 * ((p[0] * 3 + p[1]) % 5) as f64, [0.01, 0.0, 0.0]));
    fl
}
