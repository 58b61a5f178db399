//! Plane Poiseuille flow driven by a body force between halfway bounce-back walls.
//!
//! Reference (REFERENCES.md, LBM): u(y) = F(h² − y²)/(2μ); BGK + Guo forcing + halfway bounce-back
//! gives the exact parabola plus a uniform slip u_s = (F/ν)(16Λ − 3)/24 with Λ = (τ − ½)² for BGK
//! and Λ = the magic parameter for TRT (Ginzburg & Adler, J. Phys. II France 4 (1994) 191;
//! Pan, Luo & Miller, Comput. Fluids 35 (2006) 898). A correct code matches it to round-off.

#![allow(clippy::needless_range_loop)]
use crate::common;
use common::*;
use lbdem_lbm::{Collision, D2Q9, D3Q19, Domain, Face, Fluid, Lattice, Stepper};

/// Steady profile of a channel of `h` fluid nodes, force `g` along x. Returns (u_x per row, ν).
fn profile<L: Lattice>(dom: Domain, collision: Collision, g: f64) -> (Vec<f64>, f64) {
    let mut fluid = Fluid::<L, f64>::new(dom, no_obstacles());
    let mut st = Stepper::new(&fluid, settings(collision, [g, 0.0, 0.0])).unwrap();
    let (m, _) = run_steady(&mut fluid, &mut st, 500, 1e-15, 400_000);
    let [nx, ny, _] = fluid.domain.n;
    let u = (0..ny).map(|y| m.u[3 * (y * nx)]).collect();
    (u, collision.nu())
}

fn analytic(y: usize, h: usize, g: f64, nu: f64) -> f64 {
    let half = h as f64 / 2.0;
    let yc = y as f64 + 0.5 - half;
    g * (half * half - yc * yc) / (2.0 * nu)
}

fn slip(lambda: f64, g: f64, nu: f64) -> f64 {
    g / nu * (16.0 * lambda - 3.0) / 24.0
}

/// Measured slip = numerical − analytic, identical on every row; checked against the formula.
fn check_slip<L: Lattice>(h: usize, collision: Collision, g: f64) -> f64 {
    let dom = channel(4, h);
    let (u, nu) = profile::<L>(dom, collision, g);
    let umax = g * (h * h) as f64 / (8.0 * nu);
    let want = slip(collision.lambda(), g, nu);
    for (y, uy) in u.iter().enumerate() {
        let s = uy - analytic(y, h, g, nu);
        assert!(
            (s - want).abs() < 1e-9 * umax,
            "{:?} row {y}: slip {s:e}, formula {want:e} (u_max {umax:e})",
            collision
        );
    }
    want / umax
}

#[test]
fn bgk_slip_grows_with_tau_as_published_and_trt_stays_flat() {
    let h = 16;
    let g = 1e-6;
    let mut bgk = Vec::new();
    let mut trt = Vec::new();
    for tau in [0.6, 0.8, 0.9330127, 1.2, 1.6] {
        bgk.push(check_slip::<D2Q9>(h, Collision::Bgk { tau }, g));
        trt.push(check_slip::<D2Q9>(h, Collision::Trt { tau, magic: 0.25 }, g));
    }
    // BGK: relative slip strictly increasing with tau, exactly zero at tau = 1/2 + sqrt(3/16)
    assert!(bgk.windows(2).all(|w| w[1] > w[0]), "{bgk:?}");
    // TRT with fixed Lambda = 1/4: the relative slip 1/(3 H^2) for every tau
    for s in &trt {
        assert!((s - 1.0 / (3.0 * (h * h) as f64)).abs() < 1e-9, "{trt:?}");
    }
}

#[test]
fn trt_magic_3_16_is_exact_in_d3q19() {
    let wall = Face::Wall { velocity: [0.0; 3] };
    let h = 10;
    let dom = Domain::new(
        [3, h, 3],
        [
            Face::Periodic,
            Face::Periodic,
            wall,
            wall,
            Face::Periodic,
            Face::Periodic,
        ],
    );
    let c = Collision::Trt {
        tau: 0.7,
        magic: 3.0 / 16.0,
    };
    let g = 1e-6;
    let (u, nu) = profile::<D3Q19>(dom, c, g);
    let umax = g * (h * h) as f64 / (8.0 * nu);
    for (y, uy) in u.iter().enumerate() {
        assert!((uy - analytic(y, h, g, nu)).abs() < 1e-9 * umax, "row {y}");
    }
}

#[test]
fn trt_with_halfway_bounce_back_converges_at_second_order() {
    // Lambda = 1/4: error is the slip 1/(3H^2) of u_max, so order 2 (He et al., J. Stat. Phys. 87
    // (1997) 115: halfway bounce-back is second order for straight walls).
    let g_of = |h: usize| 1e-3 / (h * h) as f64; // same u_max for every H
    let mut errs = Vec::new();
    let hs = [8, 16, 32];
    for &h in &hs {
        let c = Collision::Trt {
            tau: 0.8,
            magic: 0.25,
        };
        let g = g_of(h);
        let (u, nu) = profile::<D2Q9>(channel(4, h), c, g);
        let num: f64 = u
            .iter()
            .enumerate()
            .map(|(y, v)| (v - analytic(y, h, g, nu)).powi(2))
            .sum();
        let den: f64 = (0..h).map(|y| analytic(y, h, g, nu).powi(2)).sum();
        errs.push((num / den).sqrt());
    }
    for k in 0..2 {
        let order = (errs[k] / errs[k + 1]).ln() / 2f64.ln();
        assert!((order - 2.0).abs() < 0.15, "order {order} from errors {errs:?}");
    }
}

#[test]
fn results_identical_for_one_and_two_threads() {
    // A channel with a cylinder: boundary links, general and fast paths, forces.
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut dom = channel(64, 33);
            dom.fill_sphere(0, [20.0, 16.0, 0.0], 5.0);
            let mut fluid = Fluid::<D2Q9, f64>::new(
                dom,
                vec![lbdem_lbm::Motion {
                    centre: [20.0, 16.0, 0.0],
                    omega: [0.0, 0.0, 1e-3],
                    ..Default::default()
                }],
            );
            let mut st = Stepper::new(
                &fluid,
                settings(
                    Collision::Trt {
                        tau: 0.7,
                        magic: 0.25,
                    },
                    [1e-5, 0.0, 0.0],
                ),
            )
            .unwrap();
            let mut forces = Vec::new();
            for _ in 0..300 {
                st.step(&mut fluid, None).unwrap();
                forces.push(st.forces[0]);
            }
            (fluid.f, forces)
        })
    };
    let (f1, fo1) = run(1);
    let (f2, fo2) = run(2);
    assert!(f1.iter().zip(&f2).all(|(a, b)| a.to_bits() == b.to_bits()));
    assert_eq!(fo1, fo2);
    assert!(fo1.last().unwrap().force[0] > 0.0);
}
