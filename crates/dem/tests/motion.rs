//! Rigid-body motion against analytic mechanics (references cited per test).

use lbdem_dem::contact::{LinearSpringDashpot, Rolling};
use lbdem_dem::*;
use std::f64::consts::PI;

/// Circular segment cut by a chord at distance d = r cos α from the centre: area, distance of
/// its centroid from the centre, polar second moment about the centre (standard closed forms:
/// A = r²(α − sinα cosα), x̄ = 2 r sin³α / (3(α − sinα cosα)), J = α r⁴/2 − (d⁴/2)(tanα + tan³α/3)).
fn segment(r: f64, alpha: f64) -> (f64, f64, f64) {
    let a = r * r * (alpha - alpha.sin() * alpha.cos());
    let xbar = 2.0 * r * alpha.sin().powi(3) / (3.0 * (alpha - alpha.sin() * alpha.cos()));
    let d = r * alpha.cos();
    let t = alpha.tan();
    let j = alpha * r.powi(4) / 2.0 - d.powi(4) / 2.0 * (t + t.powi(3) / 3.0);
    (a, xbar, j)
}

/// Union of two overlapping circles (Su et al. 2020 two-circle grain): area, centroid and polar
/// moment from the lens (two circular segments) subtracted once, by the parallel-axis theorem.
#[test]
fn two_circle_clump_mass_and_inertia() {
    let (r1, r2, s) = (1.0, 0.7, 1.2);
    let shape = ClumpShape {
        balls: vec![
            Ball {
                centre: Vec2::new(0.0, 0.0),
                r: r1,
            },
            Ball {
                centre: Vec2::new(s, 0.0),
                r: r2,
            },
        ],
    };
    let mp = shape.mass_props().unwrap();
    // Chord abscissa from circle 1.
    let l = (r1 * r1 - r2 * r2 + s * s) / (2.0 * s);
    let (a1, x1, j1) = segment(r1, (l / r1).acos()); // part of circle 1 beyond the chord (x > l)
    let (a2, x2, j2) = segment(r2, ((s - l) / r2).acos()); // part of circle 2 before the chord
    let lens = a1 + a2;
    let lens_cx = (a1 * x1 + a2 * (s - x2)) / lens;
    // Polar moment of the lens about the origin.
    let lens_j0 = j1 + (j2 - a2 * x2 * x2 + a2 * (s - x2).powi(2));
    let (c1, c2) = (PI * r1 * r1, PI * r2 * r2);
    let area = c1 + c2 - lens;
    let cx = (c2 * s - lens * lens_cx) / area;
    let j0 = 0.5 * c1 * r1 * r1 + (0.5 * c2 * r2 * r2 + c2 * s * s) - lens_j0;
    let jc = j0 - area * cx * cx;
    assert!(
        (mp.area - area).abs() / area < 1e-8,
        "area {} vs {}",
        mp.area,
        area
    );
    assert!((mp.centroid.x - cx).abs() < 1e-8 && mp.centroid.y.abs() < 1e-10);
    assert!(
        (mp.polar_moment - jc).abs() / jc < 1e-8,
        "J {} vs {}",
        mp.polar_moment,
        jc
    );
    // A single disk is the one-circle case: J = π r⁴/2.
    let d = ClumpShape::disk(0.3).mass_props().unwrap();
    assert!((d.polar_moment - PI * 0.3f64.powi(4) / 2.0).abs() < 1e-15);
}

fn incline_run(tan_theta: f64, mu: f64) -> (f64, f64, f64) {
    // A three-circle clump lying flat on a plane (it would tip only for tanθ > 2), gravity tilted.
    let r = 0.5;
    let shape = ClumpShape {
        balls: (-1..=1)
            .map(|k| Ball {
                centre: Vec2::new(2.0 * r * k as f64 * 0.9, 0.0),
                r,
            })
            .collect(),
    };
    let theta = tan_theta.atan();
    let g = 9.81;
    let k = 1.0e5;
    let mut bodies = Bodies::new();
    let m_area = shape.mass_props().unwrap().area;
    let delta0 = m_area * g * theta.cos() / (3.0 * k);
    bodies.add(&shape, 1.0, Vec2::new(0.0, r - delta0), 0.0).unwrap();
    let (x, a, _, _) = slide(bodies, theta, g, k, mu);
    (x, a, g * (theta.sin() - mu * theta.cos()))
}

/// One body on the plane y = 0 under gravity g tilted by θ, 1 s of the linear law (stiffness k,
/// friction μ): (distance along the slope, acceleration over the second half, final velocity
/// along the slope, final spin).
fn slide(bodies: Bodies, theta: f64, g: f64, k: f64, mu: f64) -> (f64, f64, f64, f64) {
    let mut s = System::new(bodies, Domain::open(Vec2::new(-50.0, -5.0), Vec2::new(50.0, 5.0)));
    s.walls.push(Wall::plane(Vec2::ZERO, Vec2::new(0.0, 1.0)));
    let law = LinearSpringDashpot::new(k, k / 2.0, Damping::Ratio(0.5), mu);
    let mut p = StepParams::new(2e-4, 0.05);
    p.gravity = Vec2::new(g * theta.sin(), -g * theta.cos());
    let mut st = Stepper::new();
    let steps = 5000; // 1 s
    let mut v_half = 0.0;
    for n in 0..steps {
        st.step(&p, &law, &law, &mut s).unwrap();
        if n == steps / 2 - 1 {
            v_half = s.bodies.vel[0].x;
        }
    }
    let a = (s.bodies.vel[0].x - v_half) / (0.5 * steps as f64 * p.dt);
    (s.bodies.pos[0].x, a, s.bodies.vel[0].x, s.bodies.omega[0])
}

/// Block on an incline (Coulomb friction, e.g. Goldstein/any mechanics text): it sticks for
/// tanθ < μ and slides for tanθ > μ with a = g (sinθ − μ cosθ).
#[test]
fn incline_sticks_below_mu_and_slides_above() {
    let mu = 0.5;
    let (x, a, _) = incline_run(0.4, mu);
    assert!(x.abs() < 1e-4, "tanθ = 0.4 < μ: must stick, moved {x}");
    assert!(a.abs() < 1e-6, "sticking acceleration {a}");
    let (x, a, a_exact) = incline_run(0.6, mu);
    assert!(x > 0.1, "tanθ = 0.6 > μ: must slide, moved {x}");
    assert!(
        (a - a_exact).abs() / a_exact < 1e-3,
        "sliding acceleration {a}, analytic {a_exact}"
    );
}

/// Rolling resistance (linear rolling spring with limit μ_r r F_n, Ai et al., Powder Technol. 206
/// (2011) 269): a disk rolling without slip on a plane decelerates at a = M_r/(R (m + I/R²)) =
/// (2/3) μ_r g (I = mR²/2), so it stops after s = v0²/(2a) = 3 v0²/(4 μ_r g).
#[test]
fn rolling_resistance_stops_disk_at_analytic_distance() {
    let (r, g, v0, mu_r) = (0.5, 9.81, 0.3, 0.1);
    let k = 1.0e6;
    let mut bodies = Bodies::new();
    let m = PI * r * r;
    let delta0 = m * g / k;
    bodies
        .add(&ClumpShape::disk(r), 1.0, Vec2::new(0.0, r - delta0), 0.0)
        .unwrap();
    bodies.vel[0] = Vec2::new(v0, 0.0);
    bodies.omega[0] = -v0 / r;
    let mut s = System::new(bodies, Domain::open(Vec2::new(-5.0, -5.0), Vec2::new(5.0, 5.0)));
    s.walls.push(Wall::plane(Vec2::ZERO, Vec2::new(0.0, 1.0)));
    let mut law = LinearSpringDashpot::new(k, k / 2.0, Damping::Ratio(0.7), 0.8);
    law.rolling = Some(Rolling {
        k_r: 0.05 * k * r * r,
        mu_r,
    });
    let mut p = StepParams::new(5e-5, 0.05);
    p.gravity = Vec2::new(0.0, -g);
    let mut st = Stepper::new();
    let t_stop = v0 / (2.0 / 3.0 * mu_r * g);
    let n = (1.5 * t_stop / p.dt) as usize;
    for _ in 0..n {
        st.step(&p, &law, &law, &mut s).unwrap();
    }
    let s_exact = 3.0 * v0 * v0 / (4.0 * mu_r * g);
    let x = s.bodies.pos[0].x;
    // After stopping, the undamped rolling spring leaves a small elastic rocking.
    assert!(
        s.bodies.vel[0].x.abs() < 1e-2 * v0,
        "disk still moving: {}",
        s.bodies.vel[0].x
    );
    assert!(
        (x - s_exact).abs() / s_exact < 0.01,
        "stopped at {x}, analytic {s_exact}"
    );
}

fn energy(s: &System, k: f64) -> f64 {
    let b = &s.bodies;
    let mut e = b.kinetic_energy();
    for i in 0..b.len() {
        for j in i + 1..b.len() {
            let d = (b.pos[j] - b.pos[i]).norm();
            let delta = b.circle_r[i] + b.circle_r[j] - d;
            if delta > 0.0 {
                e += 0.5 * k * delta * delta;
            }
        }
        for w in &s.walls {
            if let Some((delta, _)) = w.touch(b.pos[i], b.circle_r[i]) {
                e += 0.5 * k * delta * delta;
            }
        }
    }
    e
}

/// Velocity Verlet is symplectic (Hairer, Lubich & Wanner, Geometric Numerical Integration,
/// 2006): with conservative forces (frictionless, undamped linear springs) the energy of a gas of
/// 40 disks in a box does not drift; it stays within 1e-4 of its start over 1e5 steps.
#[test]
fn energy_conserved_over_1e5_undamped_steps() {
    let shapes = [ClumpShape::disk(0.5), ClumpShape::disk(0.7)];
    let (lo, hi) = (Vec2::new(0.0, 0.0), Vec2::new(12.0, 12.0));
    let bodies = generate::random_insert(&shapes, &[1.0, 1.0], 1.0, lo, hi, 40, 7).unwrap();
    let mut s = System::new(bodies, Domain::open(lo, hi));
    s.walls = generate::box_walls(lo, hi);
    let mut r = generate::rng(3);
    use rand::RngExt;
    for v in s.bodies.vel.iter_mut() {
        *v = Vec2::new(r.random::<f64>() - 0.5, r.random::<f64>() - 0.5);
    }
    let k = 1.0e4;
    let law = LinearSpringDashpot::new(k, 0.0, Damping::Ratio(0.0), 0.0);
    let (crit, _, _) = Stepper::critical_time_step(&s, &law, &law);
    let p = StepParams::new(crit / 40.0, 0.1);
    let mut st = Stepper::new();
    let e0 = energy(&s, k);
    let mut worst: f64 = 0.0;
    for n in 0..100_000 {
        st.step(&p, &law, &law, &mut s).unwrap();
        if n % 500 == 0 {
            worst = worst.max((energy(&s, k) - e0).abs() / e0);
        }
    }
    worst = worst.max((energy(&s, k) - e0).abs() / e0);
    assert!(worst < 1e-4, "relative energy error {worst}");
}

/// A single disk on the incline: returns (distance moved along the slope, acceleration along it
/// over the second half of 1 s, final velocity along it, final spin). `lock_spin` gives it an
/// inertia so large that it cannot turn (a disk held against rolling).
fn disk_incline(tan_theta: f64, mu: f64, lock_spin: bool) -> (f64, f64, f64, f64) {
    let (r, g, k) = (0.5, 9.81, 1.0e5);
    let theta = tan_theta.atan();
    let shape = ClumpShape::disk(r);
    let mut bodies = Bodies::new();
    let area = shape.mass_props().unwrap().area;
    let b = bodies
        .add(&shape, 1.0, Vec2::new(0.0, r - area * g * theta.cos() / k), 0.0)
        .unwrap();
    if lock_spin {
        bodies.inertia[b] *= 1e12;
    }
    slide(bodies, theta, g, k, mu)
}

/// A disk on an incline (Coulomb friction; e.g. Kleppner & Kolenkow, An Introduction to
/// Mechanics, 2nd ed. 2014, Ch. 7). Held against rolling it sticks for tanθ < μ and slides above
/// with a = g(sinθ − μ cosθ). Free to roll (I = m r²/2) it rolls without slipping while
/// tanθ < 3μ, with a = (2/3) g sinθ and ω = −v/r, and slides above, with a = g(sinθ − μ cosθ).
#[test]
fn disk_on_incline_sticks_or_rolls_and_slides_as_coulomb_says() {
    let (mu, g, r) = (0.5, 9.81, 0.5);
    let th = |t: f64| t.atan();
    let (x, a, _, _) = disk_incline(0.4, mu, true);
    assert!(
        x.abs() < 1e-4 && a.abs() < 1e-6,
        "held disk, tanθ 0.4 < μ: moved {x}, a {a}"
    );
    let (x, a, _, _) = disk_incline(0.6, mu, true);
    let want = g * (th(0.6).sin() - mu * th(0.6).cos());
    assert!(
        x > 0.1 && (a - want).abs() < 1e-3 * want,
        "held disk sliding: a {a} vs {want}"
    );
    // Rolling without slip: the contact point stays at rest, v = −ω r.
    let (_, a, v, w) = disk_incline(0.4, mu, false);
    let want = 2.0 / 3.0 * g * th(0.4).sin();
    assert!((a - want).abs() < 2e-3 * want, "rolling: a {a} vs {want}");
    assert!(
        (w * r + v).abs() < 1e-3 * v,
        "rolling: ω r = {} vs v = {v}",
        -w * r
    );
    let (_, a, v, w) = disk_incline(2.0, mu, false);
    let want = g * (th(2.0).sin() - mu * th(2.0).cos());
    assert!(
        (a - want).abs() < 1e-3 * want,
        "rolling and slipping: a {a} vs {want}"
    );
    assert!(
        -w * r < 0.9 * v,
        "tanθ = 2 > 3μ must slip: ω r = {} vs v = {v}",
        -w * r
    );
}
