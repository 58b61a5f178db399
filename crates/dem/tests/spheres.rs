//! The 3D sphere engine (`lbdem_dem::spheres`): checkpoint round trip bit for bit, momentum
//! and angular momentum conservation, periodic boundaries on every axis, thread-count
//! independence, refusals. The contact law's validation is `chung_ooi.rs`.

use lbdem_dem::spheres::{
    Domain3, Elastic, HertzMindlin, PlaneWall, SphereError, SphereStepParams, SphereStepper, SphereSystem,
    Surface,
};
use lbdem_dem::{Vec3, Vector};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const R: f64 = 1e-3;

fn law() -> HertzMindlin {
    HertzMindlin::uniform(
        Elastic {
            young: 5e7,
            poisson: 0.3,
        },
        Surface {
            mu: 0.5,
            restitution: 0.7,
        },
    )
}

/// `n`³ spheres of radius 0.8-1.0 R on a lattice of spacing 2.1 R with random velocities
/// (1 m/s) and spins, in a box with the given periodic axes (and, when z is not periodic, a
/// floor and a ceiling).
fn packed(n: usize, periodic: [bool; 3], seed: u64) -> SphereSystem {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let l = 2.1 * R * n as f64;
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(l, l, l), periodic).unwrap();
    let mut sys = SphereSystem::new(dom);
    if !periodic[2] {
        sys.walls
            .push(PlaneWall::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0)).unwrap());
        sys.walls
            .push(PlaneWall::new(Vec3::new(0.0, 0.0, l), Vec3::new(0.0, 0.0, -1.0)).unwrap());
    }
    let mut u = || 2.0 * rng.random::<f64>() - 1.0;
    for k in 0..n * n * n {
        let (i, j, m) = (k % n, (k / n) % n, k / (n * n));
        let c = |a: usize| (a as f64 + 0.5) * 2.1 * R;
        let pos = Vec3::new(c(i), c(j), c(m));
        let vel = Vec3::new(u(), u(), u());
        let omega = Vec3::new(u(), u(), u()) * 500.0;
        let r = R * (0.9 + 0.1 * u());
        sys.add_sphere(pos, vel, omega, r, 2500.0).unwrap();
    }
    sys
}

fn params() -> SphereStepParams {
    SphereStepParams {
        dt: 2e-6,
        gravity: Vec3::new(0.0, 0.0, -9.81),
        skin: 0.2 * R,
    }
}

fn run(sys: &mut SphereSystem, st: &mut SphereStepper, p: &SphereStepParams, steps: usize) {
    for _ in 0..steps {
        st.step(p, &law(), sys).unwrap();
    }
}

#[test]
fn checkpoint_round_trip_continues_bit_for_bit() {
    let p = params();
    let mut whole = packed(7, [true, true, false], 1);
    let mut st = SphereStepper::new();
    run(&mut whole, &mut st, &p, 600);
    let mut half = packed(7, [true, true, false], 1);
    let mut st1 = SphereStepper::new();
    run(&mut half, &mut st1, &p, 300);
    let json = serde_json::to_string(&half).unwrap();
    let mut resumed: SphereSystem = serde_json::from_str(&json).unwrap();
    assert_eq!(resumed, half, "the checkpoint reads back equal");
    let mut st2 = SphereStepper::new();
    run(&mut resumed, &mut st2, &p, 300);
    assert_eq!(
        serde_json::to_string(&resumed).unwrap(),
        serde_json::to_string(&whole).unwrap(),
        "resumed run differs"
    );
    // The run exercised what a checkpoint must carry: sliding and sticking contacts with
    // history, wall contacts, list rebuilds on both sides of the checkpoint.
    let live = whole.contacts.xi.iter().filter(|x| x.norm2() > 0.0).count();
    let wall_live = whole.contacts.wall_xi.iter().filter(|x| x.norm2() > 0.0).count();
    println!(
        "contacts with history {live}, wall contacts {wall_live}, rebuilds {} + {}",
        st1.rebuilds, st2.rebuilds
    );
    assert!(live > 20 && wall_live >= 1, "{live} {wall_live}");
    assert!(st1.rebuilds > 2 && st2.rebuilds > 2);
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let go = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut sys = packed(6, [true, true, true], 2);
            run(&mut sys, &mut SphereStepper::new(), &params(), 200);
            serde_json::to_string(&sys).unwrap()
        })
    };
    assert_eq!(go(1), go(2));
}

/// Pair forces are equal and opposite and the torques act about the contact point (arms
/// R − δ/2 summing to the centre distance), so an isolated cluster keeps its momentum and its
/// angular momentum about the origin to rounding.
#[test]
fn isolated_cluster_conserves_momentum_and_angular_momentum() {
    let mut sys = packed(5, [false; 3], 3);
    sys.walls.clear();
    let p = SphereStepParams::new(2e-6, 0.2 * R);
    let ang = |s: &SphereSystem| {
        let b = &s.spheres;
        (0..b.len()).fold(Vec3::ZERO, |acc, k| {
            acc + b.pos[k].cross(b.vel[k] * b.mass[k]) + b.omega[k] * b.inertia[k]
        })
    };
    let (p0, l0, e0) = (sys.momentum(), ang(&sys), sys.kinetic_energy());
    run(&mut sys, &mut SphereStepper::new(), &p, 1000);
    let (p1, l1, e1) = (sys.momentum(), ang(&sys), sys.kinetic_energy());
    let pscale: f64 = sys.spheres.mass.iter().sum::<f64>() * 1.0;
    let lscale = pscale * 2.1 * R * 5.0;
    let (dp, dl) = ((p1 - p0).norm() / pscale, (l1 - l0).norm() / lscale);
    println!("momentum drift {dp:.1e}, angular momentum drift {dl:.1e}, energy {e0:.3e} -> {e1:.3e} J");
    // Measured: 1.7e-16 and 1.4e-15 after 1000 steps (rounding); damping and friction
    // dissipated a third of the energy.
    assert!(dp < 4e-16 && dl < 3e-15, "{dp:e} {dl:e}");
    assert!(e1 < 0.9 * e0, "collisions with e = 0.7 dissipate: {e0} -> {e1}");
}

/// A head-on collision through a periodic face gives what the same collision gives in the
/// middle of the box, on each axis.
#[test]
fn periodic_collision_through_each_face_matches_the_middle() {
    let l = 10.0 * R;
    let law = law();
    let p = SphereStepParams::new(1e-6, 0.1 * R);
    let collide = |axis: usize, at: f64| {
        let dom = Domain3::new(Vec3::ZERO, Vec3::new(l, l, l), [true; 3]).unwrap();
        let mut sys = SphereSystem::new(dom);
        let e = [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ][axis];
        let centre = Vec3::new(0.5 * l, 0.5 * l, 0.5 * l) + e * (at - 0.5 * l);
        // Slightly oblique, spinning: normal, tangential and rotational parts all act.
        let side = Vec3::new(1.0, 1.0, 1.0) * 0.1 * R - e * (0.1 * R);
        sys.add_sphere(centre - e * 1.05 * R + side, e * 0.5, e * 100.0, R, 2500.0)
            .unwrap();
        sys.add_sphere(centre + e * 1.05 * R, e * -0.5, Vec3::ZERO, R, 2500.0)
            .unwrap();
        let mut st = SphereStepper::new();
        let mut touched = false;
        for _ in 0..400 {
            st.step(&p, &law, &mut sys).unwrap();
            touched |= sys.spheres.force[0].norm() > 0.0;
        }
        assert!(touched, "axis {axis}: no contact");
        (sys.spheres.vel.clone(), sys.spheres.omega.clone())
    };
    for axis in 0..3 {
        let (vm, wm) = collide(axis, 0.5 * l);
        let (vb, wb) = collide(axis, 0.0);
        for k in 0..2 {
            let dv = (vm[k] - vb[k]).norm();
            let dw = (wm[k] - wb[k]).norm();
            println!("axis {axis}, sphere {k}: dv {dv:.1e} m/s, dw {dw:.1e} rad/s");
            // Measured: at most 9.9e-14 m/s of 0.5 and 2.2e-10 rad/s of ~100 (positions
            // rounded differently near a face).
            assert!(
                dv < 2e-13 && dw < 4.4e-10,
                "axis {axis}, sphere {k}: {dv:e} {dw:e}"
            );
        }
        assert!(
            vm[0].norm() > 0.0 && (vm[0] - vm[1]).norm() > 0.1,
            "collision happened"
        );
    }
}

#[test]
fn bad_input_is_refused_with_the_parameter_named() {
    let mut sys = packed(2, [false; 3], 4);
    let mut st = SphereStepper::new();
    let rayleigh = SphereStepper::rayleigh_time_step(&sys, &law());
    let err = st
        .step(&SphereStepParams::new(1.5 * rayleigh, 0.0), &law(), &mut sys)
        .unwrap_err();
    assert!(matches!(err, SphereError::TimeStepTooLarge { .. }), "{err}");
    assert!(err.to_string().contains("Rayleigh"), "{err}");
    let err = st
        .step(&SphereStepParams::new(-1.0, 0.0), &law(), &mut sys)
        .unwrap_err();
    assert_eq!(err, SphereError::BadTimeStep { dt: -1.0 });
    let mut bad = law();
    bad.pair.restitution = 1.5;
    let err = st
        .step(&SphereStepParams::new(1e-7, 0.0), &bad, &mut sys)
        .unwrap_err();
    assert!(err.to_string().contains("restitution"), "{err}");
    let err = sys
        .add_sphere(Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, -1.0, 2500.0)
        .unwrap_err();
    assert!(err.to_string().contains("radius"), "{err}");
    let err = sys
        .add_sphere(Vec3::ZERO, Vec3::new(f64::NAN, 0.0, 0.0), Vec3::ZERO, R, 2500.0)
        .unwrap_err();
    assert!(matches!(err, SphereError::NonFinite { .. }), "{err}");
    assert!(PlaneWall::new(Vec3::ZERO, Vec3::ZERO).is_err());
    // Nothing was stepped by the refusals.
    assert_eq!(sys.step, 0);
}
