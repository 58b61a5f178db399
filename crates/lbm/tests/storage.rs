//! Narrower population storage in the AA kernel (`lbdem_lbm::storage`): each validation case of
//! this crate run with the AA stepper in every precision, f64 and f32 (stored as themselves),
//! f32s (f32 storage of f − w, f64 arithmetic) and f16s (binary16 storage of f − w, f32
//! arithmetic), each against its analytic or published answer:
//! - plane Poiseuille flow, D2Q9 and D3Q19, TRT with Λ = 3/16 (exact parabola u(y) = g(h² − y²)/(2ν),
//!   Ginzburg & Adler 1994; see `poiseuille.rs`);
//! - the Taylor-Green vortex, D2Q9 and D3Q19: energy decaying as exp(−4νk²t) (Taylor & Green 1937);
//! - Stokes drag of a periodic array of cylinders against Sangani & Acrivos 1982, Table 1;
//! - the lid-driven cavity at Re = 100 against Ghia, Ghia & Shin 1982, Table I.
//!
//! The tolerances are about twice the error measured with each precision (figures in the
//! comments, test profile, deterministic). Where f32 stored as itself misses the answer (the
//! slow Poiseuille channel), the test says so: that is what the shift is for.

#![allow(clippy::needless_range_loop)]
use crate::common;
use common::*;
use lbdem_lbm::{
    Collision, D2Q9, D3Q19, Domain, Face, Fluid, Lattice, Macro, Motion, Real, ShiftedF16, ShiftedF32,
    StepperAa, Storage,
};
use std::f64::consts::PI;

/// `run_steady` with the AA stepper storing populations as `St`.
fn steady<L: Lattice, T: Real, St: Storage<T>>(
    fluid: &mut Fluid<L, T>,
    st: &mut StepperAa<L, T, St>,
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

/// Call `$f::<T, St>($args)` for each precision, giving [f64, f32, f32s, f16s].
macro_rules! each_precision {
    ($f:ident $(::<$l:ty>)? ($($a:expr),*)) => {
        [
            $f::<$($l,)? f64, f64>($($a),*),
            $f::<$($l,)? f32, f32>($($a),*),
            $f::<$($l,)? f64, ShiftedF32>($($a),*),
            $f::<$($l,)? f32, ShiftedF16>($($a),*),
        ]
    };
}

const NAMES: [&str; 4] = ["f64", "f32", "f32s", "f16s"];

// ---------------------------------------------------------------- Poiseuille

/// Largest |u − u_exact| / u_max over the rows of a channel of `h` nodes driven by the body force
/// `g` (TRT, Λ = 3/16: the exact parabola; f64 matches it to round-off, `poiseuille.rs`).
fn poiseuille<L: Lattice, T: Real, St: Storage<T>>(h: usize, g: f64) -> f64 {
    let wall = Face::Wall { velocity: [0.0; 3] };
    let n = if L::D == 2 { [4, h, 1] } else { [3, h, 3] };
    let p = Face::Periodic;
    let dom = Domain::new(n, [p, p, wall, wall, p, p]);
    let c = Collision::Trt {
        tau: 0.8,
        magic: 3.0 / 16.0,
    };
    let nu = c.nu();
    let mut fluid = Fluid::<L, T>::new(dom, no_obstacles());
    let mut st = StepperAa::<L, T, St>::with_storage(&mut fluid, settings(c, [g, 0.0, 0.0])).unwrap();
    let umax = g * (h * h) as f64 / (8.0 * nu);
    let (m, _) = steady(&mut fluid, &mut st, 500, 1e-9 * umax, 100_000);
    let half = h as f64 / 2.0;
    (0..h)
        .map(|y| {
            let yc = y as f64 + 0.5 - half;
            let exact = g * (half * half - yc * yc) / (2.0 * nu);
            (m.u[3 * (y * n[0])] - exact).abs() / umax
        })
        .fold(0.0, f64::max)
}

#[test]
fn poiseuille_in_every_precision() {
    // a slow channel (u_max 3.2e-4 in D2Q9, 1.25e-4 in D3Q19: Ma below 1e-3, where the stored
    // deviation f − w is smallest) and a fast one (u_max 0.032 / 0.0125, Ma 0.055 / 0.022)
    let slow2 = each_precision!(poiseuille::<D2Q9>(16, 1e-6));
    let slow3 = each_precision!(poiseuille::<D3Q19>(10, 1e-6));
    let fast2 = each_precision!(poiseuille::<D2Q9>(16, 1e-4));
    let fast3 = each_precision!(poiseuille::<D3Q19>(10, 1e-4));
    for k in 0..4 {
        eprintln!(
            "Poiseuille {}: slow D2Q9 {:.2e}, D3Q19 {:.2e}; fast D2Q9 {:.2e}, D3Q19 {:.2e}",
            NAMES[k], slow2[k], slow3[k], fast2[k], fast3[k]
        );
    }
    // Measured, max |u - exact| / u_max (slow D2Q9, slow D3Q19, fast D2Q9, fast D3Q19):
    // f64 9.5e-11, 9.5e-12, 9.3e-11, 4.4e-14 (round-off); f32 5.05e-3, 6.26e-3, 5.68e-5, 5.74e-5;
    // f32s 3.49e-6, 2.18e-6, 4.90e-6, 2.32e-6; f16s 4.24e-2, 6.63e-3, 5.04e-2, 1.56e-2 (its 11
    // significant bits: the channel's steady state is set by changes below a binary16 step).
    let tol = [
        [2e-10, 2e-11, 2e-10, 1e-13],
        [1e-2, 1.3e-2, 1.2e-4, 1.2e-4],
        [7e-6, 4.4e-6, 1e-5, 4.7e-6],
        [8.5e-2, 1.3e-2, 0.1, 3.1e-2],
    ];
    for k in 0..4 {
        let e = [slow2[k], slow3[k], fast2[k], fast3[k]];
        assert!((0..4).all(|c| e[c] < tol[k][c]), "{}: {e:?}", NAMES[k]);
    }
    // the shift is what keeps f32 storage at the f64 answer: 1450 times smaller in the slow
    // channel (measured), asserted 100
    assert!(slow2[2] * 100.0 < slow2[1] && slow3[2] * 100.0 < slow3[1]);
}

// ---------------------------------------------------------------- Taylor-Green

/// Relative error of the viscosity measured from the energy decay of a Taylor-Green vortex of
/// wavelength `l` (BGK τ = 0.8, u0 = 0.01; as `taylor_green.rs`), in the x-y plane of the lattice.
fn taylor_green<L: Lattice, T: Real, St: Storage<T>>(l: usize) -> f64 {
    let c = Collision::Bgk { tau: 0.8 };
    let u0 = 0.01;
    let k = 2.0 * PI / l as f64;
    let nu = c.nu();
    let t1 = (0.1 / (nu * k * k)) as usize;
    let t2 = (0.6 / (nu * k * k)) as usize;
    let nz = if L::D == 2 { 1 } else { 2 };
    let mut fl = Fluid::<L, T>::new(Domain::periodic([l, l, nz]), no_obstacles());
    fl.init_equilibrium(|p| {
        let (x, y) = (p[0] as f64, p[1] as f64);
        let u = [
            -u0 * (k * x).cos() * (k * y).sin(),
            u0 * (k * x).sin() * (k * y).cos(),
            0.0,
        ];
        let rho = 1.0 - 3.0 * u0 * u0 / 4.0 * ((2.0 * k * x).cos() + (2.0 * k * y).cos());
        (rho, u)
    });
    let mut st = StepperAa::<L, T, St>::with_storage(&mut fl, settings(c, [0.0; 3])).unwrap();
    let mut m = Macro::default();
    let mut e = [0.0; 2];
    for s in 1..=t2 {
        let want = s == t1 || s == t2;
        st.step(&mut fl, if want { Some(&mut m) } else { None }).unwrap();
        if want {
            e[usize::from(s == t2)] = m.u.iter().map(|v| v * v).sum::<f64>();
        }
    }
    let nu_meas = (e[0] / e[1]).ln() / (4.0 * k * k * (t2 - t1) as f64);
    (nu_meas - nu).abs() / nu
}

#[test]
fn taylor_green_in_every_precision() {
    let e2 = each_precision!(taylor_green::<D2Q9>(32));
    let e3 = each_precision!(taylor_green::<D3Q19>(32));
    for k in 0..4 {
        eprintln!(
            "Taylor-Green nu error {}: D2Q9 {:.3e}, D3Q19 {:.3e}",
            NAMES[k], e2[k], e3[k]
        );
    }
    // Measured (D2Q9, D3Q19): f64 1.136e-3, 1.136e-3; f32 1.135e-3, 1.132e-3; f32s 1.136e-3,
    // 1.136e-3; f16s 9.49e-4, 1.03e-3 (the lattice's own error, second order in k)
    let tol = [
        [2.3e-3, 2.3e-3],
        [2.3e-3, 2.3e-3],
        [2.3e-3, 2.3e-3],
        [1.9e-3, 2.1e-3],
    ];
    for k in 0..4 {
        assert!(
            e2[k] < tol[k][0] && e3[k] < tol[k][1],
            "{}: {} {}",
            NAMES[k],
            e2[k],
            e3[k]
        );
    }
}

// ---------------------------------------------------------------- Sangani-Acrivos

/// Relative error of K = gL²/(μU) of a periodic square array of cylinders at solid fraction 0.2
/// (L = 48, TRT τ = 1, Λ = 3/16; as `sangani_acrivos.rs`) against Sangani & Acrivos' 51.53.
fn sangani_acrivos<L: Lattice, T: Real, St: Storage<T>>(l: usize) -> f64 {
    let (phi, want) = (0.2, 51.53);
    let mut dom = Domain::periodic([l, l, 1]);
    let c0 = (l as f64 - 1.0) / 2.0;
    dom.fill_sphere(0, [c0, c0, 0.0], l as f64 * (phi / PI).sqrt());
    let mut fluid = Fluid::<L, T>::new(
        dom,
        vec![Motion {
            centre: [c0, c0, 0.0],
            ..Default::default()
        }],
    );
    let coll = Collision::Trt {
        tau: 1.0,
        magic: 3.0 / 16.0,
    };
    let g = 1e-6;
    let mut st = StepperAa::<L, T, St>::with_storage(&mut fluid, settings(coll, [g, 0.0, 0.0])).unwrap();
    let (m, _) = steady(&mut fluid, &mut st, 200, 1e-13, 60_000);
    let u_sum: f64 = (0..fluid.nodes())
        .filter(|&i| fluid.domain.kind[i] == 0)
        .map(|i| m.u[3 * i])
        .sum();
    let k = g * (l * l) as f64 / (coll.nu() * u_sum / (l * l) as f64);
    (k - want).abs() / want
}

#[test]
fn sangani_acrivos_in_every_precision() {
    let e = each_precision!(sangani_acrivos::<D2Q9>(48));
    for k in 0..4 {
        eprintln!(
            "Sangani-Acrivos phi 0.2 L 48 {}: error {:.3}%",
            NAMES[k],
            100.0 * e[k]
        );
    }
    // Measured: f64 2.538 %, f32 2.533 %, f32s 2.538 %, f16s 2.676 % (the staircase cylinder's
    // error, as `sangani_acrivos.rs`)
    let tol = [0.051, 0.051, 0.051, 0.054];
    for k in 0..4 {
        assert!(e[k] < tol[k], "{}: {}", NAMES[k], e[k]);
    }
}

// ---------------------------------------------------------------- cavity

const GHIA_Y: [f64; 17] = [
    1.0000, 0.9766, 0.9688, 0.9609, 0.9531, 0.8516, 0.7344, 0.6172, 0.5000, 0.4531, 0.2813, 0.1719, 0.1016,
    0.0703, 0.0625, 0.0547, 0.0000,
];
const GHIA_U_RE100: [f64; 17] = [
    1.0, 0.84123, 0.78871, 0.73722, 0.68717, 0.23151, 0.00332, -0.13641, -0.20581, -0.21090, -0.15662,
    -0.10150, -0.06434, -0.04775, -0.04192, -0.03717, 0.0,
];

/// Largest |u/U − Ghia| on the vertical centre line of a 64² cavity at Re = 100 (BGK, lid speed
/// 0.1; as `cavity.rs`, at most 50 000 steps: the narrow storages settle on their round-off,
/// not on the steady tolerance).
fn cavity<L: Lattice, T: Real, St: Storage<T>>(n: usize) -> f64 {
    let u_lid = 0.1;
    let coll = Collision::Bgk {
        tau: 0.5 + 3.0 * u_lid * n as f64 / 100.0,
    };
    let wall = Face::Wall { velocity: [0.0; 3] };
    let lid = Face::Wall {
        velocity: [u_lid, 0.0, 0.0],
    };
    let dom = Domain::new([n, n, 1], [wall, wall, wall, lid, Face::Periodic, Face::Periodic]);
    let mut fluid = Fluid::<L, T>::new(dom, no_obstacles());
    let mut st = StepperAa::<L, T, St>::with_storage(&mut fluid, settings(coll, [0.0; 3])).unwrap();
    let (m, steps) = steady(&mut fluid, &mut st, 1000, 1e-7 * u_lid, 50_000);
    eprintln!("cavity {}: {steps} steps", St::NAME);
    let col = |y: usize| 0.5 * (m.u[3 * (y * n + n / 2 - 1)] + m.u[3 * (y * n + n / 2)]) / u_lid;
    let mut worst: f64 = 0.0;
    for k in 1..16 {
        let yy = GHIA_Y[k] * n as f64 - 0.5;
        let j = (yy.floor() as usize).min(n - 2);
        let t = yy - j as f64;
        worst = worst.max(((1.0 - t) * col(j) + t * col(j + 1) - GHIA_U_RE100[k]).abs());
    }
    worst
}

#[test]
fn cavity_in_every_precision() {
    let e = each_precision!(cavity::<D2Q9>(64));
    for k in 0..4 {
        eprintln!("cavity Re 100 64^2 {}: max |u/U - Ghia| {:.4}", NAMES[k], e[k]);
    }
    // Measured: f64 0.0061 (steady after 21 000 steps), f32 0.0048, f32s 0.0061 (22 000), f16s
    // 0.0049 (f32 and f16s never meet the steady tolerance; run to 819 200 steps they drifted to
    // 0.0338 and 0.0119, f32s stayed at 0.0061)
    let tol = [0.0122, 0.0096, 0.0122, 0.0098];
    for k in 0..4 {
        assert!(e[k] < tol[k], "{}: {}", NAMES[k], e[k]);
    }
}

// ---------------------------------------------------------------- thread count, state

/// A narrow storage gives the same bits on 1 and 2 threads, and `canonical`, `finish` and a new
/// stepper continue the run exactly (the state is the stored values, decoded).
fn threads_and_state<L: Lattice, T: Real, St: Storage<T>>(n: [usize; 3]) {
    let s = settings(
        Collision::Trt {
            tau: 0.7,
            magic: 0.25,
        },
        [1e-5, 0.0, 0.0],
    );
    let run = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut fl = busy_fluid::<L, T>(n);
            let mut st = StepperAa::<L, T, St>::with_storage(&mut fl, s).unwrap();
            assert!(fl.f.is_empty() || St::NAME == T::NAME);
            for _ in 0..40 {
                st.step(&mut fl, None).unwrap();
            }
            let mid = st.canonical(&fl).unwrap();
            let forces = st.forces.clone();
            // continue in a new stepper from the exported state
            let mut again = st.export(&fl).unwrap();
            let mut st2 = StepperAa::<L, T, St>::with_storage(&mut again, s).unwrap();
            for _ in 0..20 {
                st.step(&mut fl, None).unwrap();
                st2.step(&mut again, None).unwrap();
            }
            st.finish(&mut fl).unwrap();
            st2.finish(&mut again).unwrap();
            let bits = |f: &[T]| f.iter().map(|v| v.to_f64().to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fl.f), bits(&again.f), "{} restart", St::NAME);
            (bits(&mid), forces, bits(&fl.f))
        })
    };
    let one = run(1);
    let two = run(2);
    assert!(one == two, "{} {}: 1 and 2 threads differ", L::NAME, St::NAME);
}

#[test]
fn narrow_storage_is_independent_of_threads_and_restarts_exactly() {
    threads_and_state::<D2Q9, f64, ShiftedF32>([67, 33, 1]);
    threads_and_state::<D2Q9, f32, ShiftedF16>([67, 33, 1]);
    threads_and_state::<D3Q19, f64, ShiftedF32>([37, 18, 9]);
    threads_and_state::<D3Q19, f32, ShiftedF16>([37, 18, 9]);
}
