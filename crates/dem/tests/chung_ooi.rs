//! Chung & Ooi (2011), "Benchmark tests for verifying discrete element modelling codes at
//! particle impact level", Granular Matter 13:643-656: Tests 1-4 on the 3D sphere engine
//! (`lbdem_dem::spheres`, [`HertzMindlinSpring`]).
//!
//! Materials, radii and speeds per test as two public implementations of the benchmark set
//! them up (Yade `examples/ChungOoi/Test*.py`, Kratos `DEMApplication` Chung-Ooi tests); the
//! paper itself was not at hand. The references that carry the weight are independent of any
//! digitisation: Hertz theory in closed form (Tests 1-2), the input restitution (Test 3), the
//! exact gross-sliding limit and an RK4 integration of the no-slip limit (Test 4). The "paper"
//! curves are third-party digitisations of the paper's figures (Kratos `paper_data/
//! benchmark{1,2,4}_graph*.dat`; the figure numbers are not verified here), so agreement with
//! them is bounded by their resolution. Every tolerance is about twice the error measured here
//! (in a comment).
//!
//! Run: `cargo test -p lbdem-dem --test dem chung_ooi:: -- --nocapture` (about a second; CI runs it).

use lbdem_dem::spheres::{
    Domain3, Elastic, HertzMindlinSpring, PlaneWall, SphereStepParams, SphereStepper, SphereSystem, Surface,
};
use lbdem_dem::{Vec3, Vector};
use std::f64::consts::PI;

struct Material {
    name: &'static str,
    young: f64,
    poisson: f64,
    rho: f64,
}

const GLASS: Material = Material {
    name: "glass",
    young: 4.8e10,
    poisson: 0.20,
    rho: 2800.0,
};
const LIMESTONE: Material = Material {
    name: "limestone",
    young: 2.0e10,
    poisson: 0.25,
    rho: 2500.0,
};
const AL_ALLOY_T2: Material = Material {
    name: "aluminium alloy",
    young: 7.0e10,
    poisson: 0.30,
    rho: 2699.0,
};
const MG_ALLOY: Material = Material {
    name: "magnesium alloy",
    young: 4.0e10,
    poisson: 0.35,
    rho: 1800.0,
};
const ALUMINA: Material = Material {
    name: "aluminium oxide",
    young: 3.8e11,
    poisson: 0.23,
    rho: 4000.0,
};
const CAST_IRON: Material = Material {
    name: "cast iron",
    young: 1.0e11,
    poisson: 0.25,
    rho: 7000.0,
};
const AL_ALLOY_T4: Material = Material {
    name: "aluminium alloy",
    young: 7.0e10,
    poisson: 0.33,
    rho: 2700.0,
};

impl Material {
    fn law(&self, mu: f64, restitution: f64) -> HertzMindlinSpring {
        HertzMindlinSpring::uniform(
            Elastic {
                young: self.young,
                poisson: self.poisson,
            },
            Surface { mu, restitution },
        )
    }
}

/// Hertz theory of an elastic impact at relative speed `v` (Johnson, Contact Mechanics, Sect.
/// 11.4): δ_max = (15 m* v² / (16 E* √R*))^{2/5}, F_max = (4/3) E* √R* δ_max^{3/2},
/// t_c = 2.943275 δ_max / v (2√π Γ(7/5)/Γ(9/10)).
struct Hertz {
    delta_max: f64,
    f_max: f64,
    t_c: f64,
}

fn hertz(e_star: f64, r_eff: f64, m_eff: f64, v: f64) -> Hertz {
    let delta_max = (15.0 * m_eff * v * v / (16.0 * e_star * r_eff.sqrt())).powf(0.4);
    Hertz {
        delta_max,
        f_max: 4.0 / 3.0 * e_star * r_eff.sqrt() * delta_max.powf(1.5),
        t_c: 2.943_275 * delta_max / v,
    }
}

/// What an impact gave: peak contact force, peak overlap, contact duration, and the state of
/// sphere 0 after it.
#[derive(Debug)]
struct Impact {
    f_max: f64,
    delta_max: f64,
    t_c: f64,
    vel: Vec3,
    omega: Vec3,
}

fn open_box(half: f64) -> Domain3 {
    Domain3::new(
        Vec3::new(-half, -half, -half),
        Vec3::new(half, half, half),
        [false; 3],
    )
    .unwrap()
}

/// Run `sys` until the contact has opened, sampling the contact force on sphere 0 and the
/// overlap `overlap(sys)`; the duration is interpolated between the steps where the overlap
/// changes sign.
fn run_impact(
    mut sys: SphereSystem,
    law: &HertzMindlinSpring,
    dt: f64,
    max_steps: usize,
    overlap: impl Fn(&SphereSystem) -> f64,
) -> Impact {
    let p = SphereStepParams::new(dt, 0.0);
    let mut st = SphereStepper::new();
    let (mut f_max, mut d_max) = (0.0f64, 0.0f64);
    let (mut t_on, mut t_off) = (None, None);
    let mut prev = (overlap(&sys), sys.time);
    for _ in 0..max_steps {
        st.step(&p, law, &mut sys).unwrap();
        let d = overlap(&sys);
        f_max = f_max.max(sys.spheres.force[0].norm());
        d_max = d_max.max(d);
        let cross = |d0: f64, t0: f64, d1: f64, t1: f64| t0 + (t1 - t0) * d0 / (d0 - d1);
        if t_on.is_none() && prev.0 <= 0.0 && d > 0.0 {
            t_on = Some(cross(prev.0, prev.1, d, sys.time));
        }
        if t_on.is_some() && prev.0 > 0.0 && d <= 0.0 {
            t_off = Some(cross(prev.0, prev.1, d, sys.time));
            // A few more steps so the closing half kick has seen no contact.
            st.step(&p, law, &mut sys).unwrap();
            break;
        }
        prev = (d, sys.time);
    }
    let (t_on, t_off) = (t_on.expect("contact made"), t_off.expect("contact opened"));
    Impact {
        f_max,
        delta_max: d_max,
        t_c: t_off - t_on,
        vel: sys.spheres.vel[0],
        omega: sys.spheres.omega[0],
    }
}

/// Two identical spheres of radius `r` meeting head-on at ±`v` (Test 1 geometry).
fn two_spheres(m: &Material, r: f64, v: f64, steps_per_contact: f64) -> (Impact, Hertz) {
    let law = m.law(0.35, 1.0);
    let mut sys = SphereSystem::new(open_box(10.0 * r));
    let gap = 1e-3 * r;
    sys.add_sphere(
        Vec3::new(-r - gap, 0.0, 0.0),
        Vec3::new(v, 0.0, 0.0),
        Vec3::ZERO,
        r,
        m.rho,
    )
    .unwrap();
    sys.add_sphere(
        Vec3::new(r + gap, 0.0, 0.0),
        Vec3::new(-v, 0.0, 0.0),
        Vec3::ZERO,
        r,
        m.rho,
    )
    .unwrap();
    let mass = sys.spheres.mass[0];
    let reference = hertz(law.pair_coeffs().e_star, 0.5 * r, 0.5 * mass, 2.0 * v);
    let dt = reference.t_c / steps_per_contact;
    let imp = run_impact(sys, &law, dt, (2.0 * steps_per_contact) as usize + 1000, |s| {
        2.0 * r - (s.spheres.pos[1].x - s.spheres.pos[0].x)
    });
    (imp, reference)
}

/// A sphere of radius `r` hitting the rigid plane z = 0 at velocity `v` (z-component < 0).
fn sphere_on_plane(
    m: &Material,
    law: &HertzMindlinSpring,
    r: f64,
    v: Vec3,
    steps_per_contact: f64,
) -> (Impact, Hertz) {
    let mut sys = SphereSystem::new(open_box(10.0 * r));
    sys.walls
        .push(PlaneWall::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0)).unwrap());
    let gap = 1e-3 * r;
    sys.add_sphere(Vec3::new(0.0, 0.0, r + gap), v, Vec3::ZERO, r, m.rho)
        .unwrap();
    let mass = sys.spheres.mass[0];
    let reference = hertz(law.wall_coeffs().e_star, r, mass, -v.z);
    let dt = reference.t_c / steps_per_contact;
    let imp = run_impact(sys, law, dt, (3.0 * steps_per_contact) as usize + 1000, |s| {
        r - s.spheres.pos[0].z
    });
    (imp, reference)
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

/// Test 1 (elastic normal impact of two identical spheres, R = 0.010 m at ±10 m/s; glass and
/// limestone as in the paper, aluminium oxide and cast iron added): peak force, peak overlap and
/// contact duration against Hertz theory, the glass run against the paper's force-time curve.
#[test]
fn test1_two_identical_spheres_match_hertz() {
    let mut glass = None;
    for m in [&GLASS, &LIMESTONE, &ALUMINA, &CAST_IRON] {
        let (i, h) = two_spheres(m, 0.010, 10.0, 2000.0);
        let (ef, ed, et) = (
            rel(i.f_max, h.f_max),
            rel(i.delta_max, h.delta_max),
            rel(i.t_c, h.t_c),
        );
        println!(
            "Test 1 {}: F_max {:.5} kN ({ef:.1e}), delta_max {:.4} um ({ed:.1e}), t_c {:.4} us ({et:.1e}), v_after {:.9} m/s",
            m.name,
            1e-3 * i.f_max,
            1e6 * i.delta_max,
            1e6 * i.t_c,
            i.vel.x
        );
        println!("  rebound speed off by {:.1e} m/s", (i.vel.x + 10.0).abs());
        // Measured (2000 steps per contact): F_max 1.4-2.8e-7, delta_max 1.0-1.9e-7,
        // t_c 6.6e-8.
        assert!(ef < 6e-7, "{}: F_max off Hertz by {ef:e}", m.name);
        assert!(ed < 4e-7, "{}: delta_max off Hertz by {ed:e}", m.name);
        assert!(et < 1.5e-7, "{}: t_c off Hertz by {et:e}", m.name);
        // Elastic: the spheres leave at the speed they came (measured at most 3.5e-8 m/s off).
        assert!((i.vel.x + 10.0).abs() < 7e-8, "{}: rebound {}", m.name, i.vel.x);
        if m.name == "glass" {
            glass = Some(i);
        }
    }
    // The paper's Test 1 force-time curve for glass as digitised by Kratos
    // (benchmark1_graph2.dat): peak 10.704 kN at 20.45 us, contact over at 40.48 us. Measured
    // here 10.697 kN (6.5e-4) and 40.34 us (3.4e-3), the digitisation's resolution; this adds
    // nothing to the closed-form check above beyond showing the set-up is the paper's.
    let g = glass.expect("glass ran");
    assert!(rel(g.f_max, 10.704e3) < 1.3e-3, "glass F_max {}", g.f_max);
    assert!(rel(g.t_c, 40.48e-6) < 7e-3, "glass t_c {}", g.t_c);
}

/// Test 2 (elastic normal impact of a sphere, R = 0.10 m at 0.2 m/s, on a rigid plane;
/// aluminium and magnesium alloys): against Hertz theory, and the aluminium run against a
/// digitisation of the paper's force-displacement curve.
#[test]
fn test2_sphere_on_rigid_plane_matches_hertz() {
    for m in [&AL_ALLOY_T2, &MG_ALLOY] {
        let law = m.law(0.0, 1.0);
        let (i, h) = sphere_on_plane(m, &law, 0.10, Vec3::new(0.0, 0.0, -0.2), 2000.0);
        let (ef, ed, et) = (
            rel(i.f_max, h.f_max),
            rel(i.delta_max, h.delta_max),
            rel(i.t_c, h.t_c),
        );
        println!(
            "Test 2 {}: F_max {:.5} kN ({ef:.1e}), delta_max {:.4} um ({ed:.1e}), t_c {:.4} us ({et:.1e}), v_after {:.9} m/s",
            m.name,
            1e-3 * i.f_max,
            1e6 * i.delta_max,
            1e6 * i.t_c,
            i.vel.z
        );
        println!("  rebound speed off by {:.1e} m/s", (i.vel.z - 0.2).abs());
        // Measured: F_max 5.3-5.6e-8, delta_max 3.5-3.7e-8, t_c 6.5e-8, rebound 7.6e-10 m/s.
        assert!(
            ef < 1.2e-7 && ed < 8e-8 && et < 1.5e-7,
            "{}: {ef:e} {ed:e} {et:e}",
            m.name
        );
        assert!((i.vel.z - 0.2).abs() < 1.5e-9, "{}: rebound {}", m.name, i.vel.z);
        if m.name == "aluminium alloy" {
            // The paper's Test 2 force-displacement curve as digitised by Kratos
            // (benchmark2_graph1.dat) ends at 11.326 kN, 49.99 um; the digitisation does not
            // say whether that is the peak, so this only checks that the run reaches the end of
            // the digitised curve within its resolution. Measured 11.370 kN (3.9e-3) and
            // 49.72 um (5.4e-3); Hertz in closed form (above) is the real check.
            assert!(rel(i.f_max, 11.326e3) < 8e-3, "F_max {}", i.f_max);
            assert!(rel(i.delta_max, 49.99e-6) < 1.1e-2, "delta_max {}", i.delta_max);
        }
    }
}

/// Test 3 (normal impact on a rigid plane with damping, R = 2.5 mm at 3.9 m/s; aluminium oxide
/// and cast iron): the rebound speed over the impact speed recovers the input restitution.
#[test]
fn test3_restitution_is_recovered() {
    let mut worst = 0.0f64;
    for m in [&ALUMINA, &CAST_IRON] {
        for e in [0.2, 0.4, 0.6, 0.8, 0.9, 1.0] {
            let law = m.law(0.0, e);
            let (i, _) = sphere_on_plane(m, &law, 0.0025, Vec3::new(0.0, 0.0, -3.9), 2000.0);
            let got = i.vel.z / 3.9;
            println!("Test 3 {}: e = {e}: v_out/v_in = {got:.6}", m.name);
            worst = worst.max((got - e).abs());
        }
    }
    // Measured: at most 1.3e-4 off (cast iron, e = 0.2); the Tsuji/LIGGGHTS damping with its
    // attractive tail reproduces e for Hertz within the step resolution here.
    println!("Test 3 worst restitution error {worst:.2e}");
    assert!(worst < 2.6e-4, "restitution off by {worst}");
    // e = 0 (β = −1, the damping's limit): the sphere comes to rest on the plane and stays
    // in contact.
    let law = ALUMINA.law(0.0, 0.0);
    let mut sys = SphereSystem::new(open_box(0.025));
    sys.walls
        .push(PlaneWall::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0)).unwrap());
    sys.add_sphere(
        Vec3::new(0.0, 0.0, 0.0025),
        Vec3::new(0.0, 0.0, -3.9),
        Vec3::ZERO,
        0.0025,
        4000.0,
    )
    .unwrap();
    let mut st = SphereStepper::new();
    let p = SphereStepParams::new(5e-9, 0.0);
    for _ in 0..4000 {
        st.step(&p, &law, &mut sys).unwrap();
    }
    let v = sys.spheres.vel[0].z;
    println!(
        "Test 3 e = 0: v = {v:.2e} m/s, z - R = {:.2e} m",
        sys.spheres.pos[0].z - 0.0025
    );
    // Measured v = 2.1e-2 m/s (0.55 % of the impact speed) after 20 us (about 3 elastic
    // contact times), the overlap relaxing without a bounce, still in contact.
    assert!(v.abs() < 0.043 && sys.spheres.pos[0].z < 0.0025, "e = 0: v {v}");
}

/// An oblique impact on the rigid plane z = 0: speed `speed` at `angle_deg` from the normal.
/// Returns (tangential restitution of the centre v_x'/v_x, ω_y', contact-point rebound angle
/// atan(v_c'/v_n') in degrees, normal restitution).
fn oblique(
    m: &Material,
    law: &HertzMindlinSpring,
    r: f64,
    speed: f64,
    angle_deg: f64,
) -> (f64, f64, f64, f64) {
    let th = angle_deg * PI / 180.0;
    let v = Vec3::new(speed * th.sin(), 0.0, -speed * th.cos());
    let (i, _) = sphere_on_plane(m, law, r, v, 2000.0);
    let vc = i.vel.x - i.omega.y * r; // the paper's rigid-body contact-point velocity
    (
        i.vel.x / v.x,
        i.omega.y,
        (vc / i.vel.z).atan().to_degrees(),
        -i.vel.z / v.z,
    )
}

/// Test 4 (oblique impact of an aluminium oxide sphere, R = 2.5 mm at 3.9 m/s, on a rigid
/// plane; μ = 0.092, e = 0.98 as in Yade's and Kratos' set-ups): tangential restitution,
/// spin and rebound angle against the paper's aluminium-oxide curves as digitised by Kratos
/// (benchmark4_graph{1,2,3}.dat, first series; the spin is plotted there with the opposite
/// sign; the same files' third series are Kharaz et al. 2001's experimental points, not used
/// here), and against the exact gross-sliding limit. Kratos' graph3 file carries identical
/// "Al. oxide" and "Al. alloy" series, so the rebound-angle curve is less certain than the
/// other two.
#[test]
fn test4_oblique_impact_matches_the_paper_and_the_sliding_limit() {
    let law = ALUMINA.law(0.092, 0.98);
    let r = 0.0025;
    let et_ref: [(f64, f64); 13] = [
        (5.1683, 0.94811),
        (10.1584, 0.68699),
        (14.9901, 0.62438),
        (20.0594, 0.61614),
        (25.0495, 0.63427),
        (30.1188, 0.68369),
        (35.0297, 0.73723),
        (40.0198, 0.78089),
        (50.0, 0.84514),
        (59.9802, 0.89292),
        (69.9604, 0.93163),
        (80.0198, 0.96623),
        (85.0099, 0.98270),
    ];
    let omega_ref: [(f64, f64); 13] = [
        (4.9507, 19.27),
        (10.0789, 213.00),
        (14.9704, 377.83),
        (19.9408, 510.55),
        (24.9112, 599.39),
        (29.9606, 616.51),
        (34.9310, 582.26),
        (39.9803, 544.80),
        (50.0, 457.03),
        (60.0197, 357.49),
        (69.9606, 246.18),
        (80.0592, 126.30),
        (85.0296, 63.15),
    ];
    let rebound_ref: [(f64, f64); 13] = [
        (4.9010, 3.761),
        (9.9588, -1.556),
        (14.9346, -5.544),
        (19.9876, -7.538),
        (24.9575, -7.538),
        (29.9217, -3.550),
        (34.9616, 3.429),
        (39.9197, 11.571),
        (49.8336, 29.350),
        (59.9871, 47.795),
        (69.7422, 64.577),
        (79.8218, 78.701),
        (84.7833, 84.517),
    ];
    // Largest deviations below 30 deg (sticking and micro-slip: the curves are steep there,
    // 0.05 in e_t per degree near 5 deg, so digitisation offsets in angle count) and from
    // 30 deg on (gross sliding).
    let (mut d_et, mut d_om, mut d_reb) = ([0.0f64; 2], [0.0f64; 2], [0.0f64; 2]);
    let regime = |a: f64| usize::from(a >= 29.5);
    for &(a, want) in &et_ref {
        let (et, ..) = oblique(&ALUMINA, &law, r, 3.9, a);
        println!("Test 4 e_t at {a:.2} deg: {et:.4} (paper {want:.4})");
        d_et[regime(a)] = d_et[regime(a)].max((et - want).abs());
    }
    for &(a, want) in &omega_ref {
        let (_, w, ..) = oblique(&ALUMINA, &law, r, 3.9, a);
        println!("Test 4 omega at {a:.2} deg: {w:.1} rad/s (paper {want:.1})");
        d_om[regime(a)] = d_om[regime(a)].max((w - want).abs());
    }
    for &(a, want) in &rebound_ref {
        let (_, _, reb, _) = oblique(&ALUMINA, &law, r, 3.9, a);
        println!("Test 4 rebound angle at {a:.2} deg: {reb:.2} deg (paper {want:.2})");
        d_reb[regime(a)] = d_reb[regime(a)].max((reb - want).abs());
    }
    println!(
        "Test 4 largest deviations below / from 30 deg: e_t {:.4} / {:.4}, omega {:.1} / {:.1} rad/s, rebound {:.2} / {:.2} deg",
        d_et[0], d_et[1], d_om[0], d_om[1], d_reb[0], d_reb[1]
    );
    // Measured below / from 30 deg: e_t 0.0143 (at 5.2 deg) / 0.0029, omega 8.1 (at 10 deg) /
    // 3.7 rad/s of 617, rebound angle 1.13 (at 15 deg) / 0.35 deg.
    assert!(
        d_et[0] < 0.029 && d_et[1] < 0.0058,
        "e_t off the paper by {d_et:?}"
    );
    assert!(
        d_om[0] < 16.0 && d_om[1] < 7.4,
        "omega off the paper by {d_om:?} rad/s"
    );
    assert!(
        d_reb[0] < 2.3 && d_reb[1] < 0.7,
        "rebound angle off the paper by {d_reb:?} deg"
    );

    // Gross sliding (rigid-body impulse): for tan θ > (7/2) μ (1 + e_n) the contact slides
    // throughout, the tangential impulse is μ times the normal one, and
    // e_t = 1 − μ (1 + e_n) cot θ, ω' R = (5/2) μ (1 + e_n) v_n, exactly whatever the normal law.
    let mut worst = (0.0f64, 0.0f64);
    for a in [35.0, 45.0, 55.0, 65.0, 75.0, 85.0] {
        let (et, w, _, en) = oblique(&ALUMINA, &law, r, 3.9, a);
        let th = f64::to_radians(a);
        let vn = 3.9 * th.cos();
        let et_slide = 1.0 - 0.092 * (1.0 + en) / th.tan();
        let w_slide = 2.5 * 0.092 * (1.0 + en) * vn / r;
        worst = (worst.0.max((et - et_slide).abs()), worst.1.max(rel(w, w_slide)));
    }
    println!(
        "Test 4 gross sliding: e_t off by {:.1e}, omega off by {:.1e} (relative)",
        worst.0, worst.1
    );
    // Measured: e_t 1.9e-5; omega 1.2e-3 relative, below the rigid value because the friction
    // acts at the contact point, R − δ/2 from the centre (δ_max/R ≤ 2.8e-3 here).
    assert!(
        worst.0 < 3.8e-5 && worst.1 < 2.4e-3,
        "gross-sliding limit off by {worst:?}"
    );
}

/// Reference for the no-slip limit (μ → ∞) of an elastic oblique impact on a rigid plane:
/// the model's own equations integrated by RK4 at 200 000 steps per contact, independently of
/// the engine. State: overlap δ, its rate, the tangential spring u, the centre's tangential
/// velocity v and spin ω (about the axis normal to the plane of incidence):
/// m δ̈ = −(4/3) E* √R δ^{3/2}; F = −8 G* √(R δ) u; m v̇ = F; I ω̇ = −a F; u̇ = v − a ω, with the
/// contact point a = R − δ/2 below the centre (as in the engine). Returns the contact-point
/// tangential velocity v − ω R after separation over the one before impact: for full stick a
/// function of ν alone (Maw, Barber & Fawcett 1976; k_t/k_n = 2(1−ν)/(2−ν)).
fn no_slip_tangential_restitution(e_star: f64, g_star: f64, r: f64, m: f64, vn: f64, vt: f64) -> f64 {
    let k = 4.0 / 3.0 * e_star * r.sqrt();
    let inertia = 0.4 * m * r * r;
    let h = hertz(e_star, r, m, vn).t_c / 200_000.0;
    let rhs = |y: [f64; 5]| -> [f64; 5] {
        let d = y[0].max(0.0);
        let a = r - 0.5 * d;
        let f = -8.0 * g_star * (r * d).sqrt() * y[2];
        [
            y[1],
            -k / m * d * d.sqrt(),
            y[3] - a * y[4],
            f / m,
            -a * f / inertia,
        ]
    };
    let mut y = [0.0, vn, 0.0, vt, 0.0];
    loop {
        let add = |y: [f64; 5], k: [f64; 5], s: f64| -> [f64; 5] { std::array::from_fn(|i| y[i] + s * k[i]) };
        let k1 = rhs(y);
        let k2 = rhs(add(y, k1, 0.5 * h));
        let k3 = rhs(add(y, k2, 0.5 * h));
        let k4 = rhs(add(y, k3, h));
        let next: [f64; 5] =
            std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
        if next[0] <= 0.0 {
            // Past separation the state no longer changes but for δ: take it at the step's end.
            return (next[3] - next[4] * r) / vt;
        }
        y = next;
    }
}

/// Test 4, small-angle (sticking) limit: with friction too large to slide, the contact-point
/// tangential velocity is reversed by the Mindlin spring alone; the engine's history carried
/// across the whole contact must give the restitution of the RK4 reference above.
#[test]
fn test4_no_slip_limit_matches_an_independent_integration() {
    for m in [&ALUMINA, &AL_ALLOY_T4] {
        let law = m.law(1e6, 1.0);
        let r = 0.0025;
        let c = law.wall_coeffs();
        let mass = m.rho * 4.0 / 3.0 * PI * r * r * r;
        for a in [5.0, 30.0] {
            let th = f64::to_radians(a);
            let v = Vec3::new(3.9 * th.sin(), 0.0, -3.9 * th.cos());
            let want = no_slip_tangential_restitution(c.e_star, c.g_star, r, mass, -v.z, v.x);
            let mut err = [0.0; 2];
            for (e, n) in err.iter_mut().zip([2000.0, 16000.0]) {
                let (i, _) = sphere_on_plane(m, &law, r, v, n);
                // Contact-point velocity (arm R: the contact is open again).
                let beta = (i.vel.x - i.omega.y * r) / v.x;
                println!(
                    "no-slip {} at {a} deg, {n} steps per contact: v_c'/v_c = {beta:.7}, RK4 {want:.7}",
                    m.name
                );
                *e = (beta - want).abs();
            }
            // Measured: at most 1.12e-3 off at 2000 steps per contact, 2.2e-4 at 16 000 (the
            // engine converges to the reference at about first order in dt, the √δ stiffness
            // being singular where the contact opens and closes; error ratios 5.1-19.6).
            assert!(err[0] < 2.3e-3 && err[1] < 4.4e-4, "{}: errors {err:?}", m.name);
            assert!(err[1] < err[0] / 3.0, "{}: no convergence {err:?}", m.name);
        }
    }
}

/// The accepted step against the error it gives: Tests 3 and 4 on aluminium oxide
/// (R = 2.5 mm at 3.9 m/s, contact about 6 us, t_R = 1.4 us) at 20, 50 and 100 steps per
/// contact — 0.22, 0.09 and 0.04 t_R; the default `rayleigh_fraction` 0.2 admits about 22 —
/// with the fraction lifted to 1 so every step runs. Errors: restitution at e = 0.5, e_t at
/// 45 deg against the exact gross-sliding value, the no-slip tangential restitution at 5 deg
/// against the RK4 reference. The table is in `docs/dem3d.md`.
#[test]
fn error_against_steps_per_contact() {
    let m = &ALUMINA;
    let r = 0.0025;
    let mass = m.rho * 4.0 / 3.0 * PI * r * r * r;
    let loose = |mu: f64, e: f64| HertzMindlinSpring {
        rayleigh_fraction: 1.0,
        ..m.law(mu, e)
    };
    let t_r = loose(0.0, 1.0).rayleigh_time_step(r, mass);
    let c = loose(1e6, 1.0).wall_coeffs();
    let th5 = 5f64.to_radians();
    let v5 = Vec3::new(3.9 * th5.sin(), 0.0, -3.9 * th5.cos());
    let no_slip = no_slip_tangential_restitution(c.e_star, c.g_star, r, mass, -v5.z, v5.x);
    let mut errs = Vec::new();
    for n in [20.0, 50.0, 100.0] {
        let (i, h) = sphere_on_plane(m, &loose(0.0, 0.5), r, Vec3::new(0.0, 0.0, -3.9), n);
        let d_e = (i.vel.z / 3.9 - 0.5).abs();
        let th = 45f64.to_radians();
        let v = Vec3::new(3.9 * th.sin(), 0.0, -3.9 * th.cos());
        let (j, _) = sphere_on_plane(m, &loose(0.092, 0.98), r, v, n);
        let en = -j.vel.z / v.z;
        let d_et = (j.vel.x / v.x - (1.0 - 0.092 * (1.0 + en) / th.tan())).abs();
        let (k, _) = sphere_on_plane(m, &loose(1e6, 1.0), r, v5, n);
        let d_ns = ((k.vel.x - k.omega.y * r) / v5.x - no_slip).abs();
        println!(
            "{n} steps per contact (dt = {:.3} t_R): restitution off by {d_e:.1e}, e_t at 45 deg {d_et:.1e}, no-slip at 5 deg {d_ns:.1e}",
            h.t_c / n / t_r
        );
        errs.push([d_e, d_et, d_ns]);
    }
    // Measured (20 / 50 / 100 steps per contact): restitution 1.5e-3 / 9.2e-4 / 1.2e-3 (the
    // restitution model's own error at this e, not the step's), e_t at 45 deg 2e-16 / 1.3e-5 /
    // 8.0e-6, no-slip 1.9e-2 / 1.5e-2 / 1.5e-2 (first order, 1.1e-3 at 2000). Tolerances twice
    // the worst of each row.
    let tol = [3e-3, 2.6e-5, 3.8e-2];
    for e in &errs {
        for k in 0..3 {
            assert!(e[k] < tol[k], "{errs:?}");
        }
    }
}
