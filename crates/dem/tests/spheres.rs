//! The 3D sphere engine (`lbdem_dem::spheres`): checkpoint round trip bit for bit, corrupt
//! checkpoints refused, momentum and angular momentum conservation, periodic boundaries on every
//! axis, user forces, refusals, and the same bits on 1 and 2 threads (the pair pass runs on
//! rayon's threads at any size, the per-sphere passes from 8192 spheres up). The contact law's
//! validation is `chung_ooi.rs`.

use lbdem_dem::spheres::clump::DEFAULT_NODES;
use lbdem_dem::spheres::{
    BodyFrame, ClumpTemplate, Domain3, Elastic, FREE, HertzMindlinSpring, PlaneWall, SphereError,
    SphereStepParams, SphereStepper, SphereSystem, Surface,
};
use lbdem_dem::{Histories, Vec3, Vector};
use nalgebra::UnitQuaternion;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

const R: f64 = 1e-3;

fn law() -> HertzMindlinSpring {
    HertzMindlinSpring::uniform(
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

fn run(
    sys: &mut SphereSystem,
    st: &mut SphereStepper<HertzMindlinSpring>,
    p: &SphereStepParams,
    steps: usize,
) {
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
    let loaded = |h: &Histories| {
        h.as_slice::<Vec3>()
            .map_or(0, |x| x.iter().filter(|x| x.norm2() > 0.0).count())
    };
    let live = loaded(&whole.contacts.hist);
    let wall_live = loaded(&whole.contacts.wall_hist);
    println!(
        "contacts with history {live}, wall contacts {wall_live}, rebuilds {} + {}",
        st1.rebuilds, st2.rebuilds
    );
    assert!(live > 20 && wall_live >= 1, "{live} {wall_live}");
    assert!(st1.rebuilds > 2 && st2.rebuilds > 2);
}

/// Pair forces are equal and opposite and the torques act about the contact point (arms
/// R − δ/2 summing to the centre distance), so an isolated cluster keeps its momentum and its
/// angular momentum about the origin to rounding.
#[test]
fn isolated_cluster_conserves_momentum_and_angular_momentum() {
    let mut sys = packed(5, [false; 3], 3);
    sys.walls.clear();
    // No walls: a box large enough that nothing leaves it.
    let l = sys.domain.hi.x;
    sys.domain = Domain3::new(
        Vec3::new(-l, -l, -l),
        Vec3::new(2.0 * l, 2.0 * l, 2.0 * l),
        [false; 3],
    )
    .unwrap();
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
    // Measured: 6.0e-17 and 4.2e-15 after 1000 steps (rounding); damping and friction
    // dissipated a third of the energy.
    assert!(dp < 1.2e-16 && dl < 8.4e-15, "{dp:e} {dl:e}");
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
            // Measured: at most 5.1e-14 m/s of 0.5 and 6.0e-11 rad/s of ~100 (positions
            // rounded differently near a face).
            assert!(
                dv < 1.1e-13 && dw < 1.2e-10,
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
    let mut bad = law();
    bad.sphere.poisson = 0.7;
    let err = st
        .step(&SphereStepParams::new(1e-7, 0.0), &bad, &mut sys)
        .unwrap_err();
    assert!(
        err.to_string().contains("Poisson's ratio of the spheres"),
        "{err}"
    );
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

/// The step is refused above `rayleigh_fraction` (default 0.2) of the smallest sphere's
/// Rayleigh time step, as the message says, and taken just below it.
#[test]
fn time_step_is_refused_above_the_rayleigh_fraction() {
    let sys = packed(2, [false; 3], 4);
    let law = law();
    let s = &sys.spheres;
    let t_r = (0..s.len())
        .map(|k| law.rayleigh_time_step(s.radius[k], s.mass[k]))
        .fold(f64::INFINITY, f64::min);
    let try_step = |frac: f64| {
        let mut sys = sys.clone();
        SphereStepper::new().step(&SphereStepParams::new(frac * t_r, 0.0), &law, &mut sys)
    };
    assert!(try_step(0.19).is_ok());
    let err = try_step(0.21).unwrap_err();
    assert!(matches!(err, SphereError::TimeStepTooLarge { .. }), "{err}");
    assert!(
        err.to_string().contains("Rayleigh") && err.to_string().contains("at most"),
        "{err}"
    );
    // The fraction is the law's: raised to 0.3, 0.21 t_R passes.
    let loose = HertzMindlinSpring {
        rayleigh_fraction: 0.3,
        ..law
    };
    let mut sys2 = sys.clone();
    assert!(
        SphereStepper::new()
            .step(&SphereStepParams::new(0.21 * t_r, 0.0), &loose, &mut sys2)
            .is_ok()
    );
    let bad = HertzMindlinSpring {
        rayleigh_fraction: 1.5,
        ..law
    };
    let err = SphereStepper::new()
        .step(&SphereStepParams::new(0.1 * t_r, 0.0), &bad, &mut sys2)
        .unwrap_err();
    assert!(err.to_string().contains("rayleigh_fraction"), "{err}");
}

/// A checkpoint is user input: a corrupt one is refused with the field named, never a panic
/// at a later step; one written before clumps existed (no `owner`) loads with every sphere
/// free and takes new spheres and clumps.
#[test]
fn corrupt_checkpoints_are_refused_and_old_ones_load() {
    let mut sys = packed(3, [true, true, false], 5);
    let mut st = SphereStepper::new();
    run(&mut sys, &mut st, &params(), 50);
    let good: serde_json::Value = serde_json::to_value(&sys).unwrap();
    let load = |v: &serde_json::Value| serde_json::from_value::<SphereSystem>(v.clone());
    assert_eq!(load(&good).unwrap(), sys);
    type Corrupt = fn(&mut serde_json::Value);
    let cases: [(&str, Corrupt); 6] = [
        ("spheres.mass", |v| {
            v["spheres"]["mass"].as_array_mut().unwrap().pop();
        }),
        ("spheres.radius", |v| v["spheres"]["radius"][3] = (-1.0).into()),
        ("contacts.pairs", |v| {
            v["contacts"]["pairs"][0] = serde_json::json!([0, 999])
        }),
        ("walls", |v| {
            v["walls"][0]["normal"] = serde_json::json!({"x": 0.0, "y": 0.0, "z": 2.0})
        }),
        ("spheres.owner", |v| v["spheres"]["owner"][2] = 7.into()),
        ("spheres.inertia", |v| v["spheres"]["inertia"][1] = 0.0.into()),
    ];
    for (field, corrupt) in cases {
        let mut v = good.clone();
        corrupt(&mut v);
        let err = load(&v).unwrap_err().to_string();
        assert!(err.contains(field), "{field}: {err}");
    }
    // No owner field: all free; adding a sphere and a clump and stepping works.
    let mut old = good.clone();
    old["spheres"].as_object_mut().unwrap().remove("owner");
    let mut back = load(&old).unwrap();
    assert!(back.spheres.owner.iter().all(|&o| o == FREE));
    // Into two interstices of the lattice (1.82 R from its nearest centres).
    let hole = |a: f64| Vec3::new(a, a, a) * (2.1 * R);
    back.add_sphere(hole(1.0), Vec3::ZERO, Vec3::ZERO, 0.3 * R, 2500.0)
        .unwrap();
    let frame = BodyFrame::of(
        &ClumpTemplate::tetrahedron(0.4 * R, 0.6 * R),
        2500.0,
        DEFAULT_NODES,
    )
    .unwrap();
    back.add_clump(
        &frame,
        hole(2.0),
        UnitQuaternion::identity(),
        Vec3::ZERO,
        Vec3::ZERO,
    )
    .unwrap();
    run(&mut back, &mut SphereStepper::new(), &params(), 20);
    // A clump whose quaternion is not a unit is refused.
    let mut v = serde_json::to_value(&back).unwrap();
    v["clumps"]["quat"][0][0] = 2.0.into();
    let err = load(&v).unwrap_err().to_string();
    assert!(err.contains("clumps.quat"), "{err}");
    // A member list that disagrees with the owners is refused.
    let mut v = serde_json::to_value(&back).unwrap();
    v["clumps"]["members"][0] = 0.into();
    let err = load(&v).unwrap_err().to_string();
    assert!(err.contains("clumps.members"), "{err}");
}

/// A hook's force acts as a body force: a constant force F on a free sphere and on a clump
/// member gives v = F t / m (velocity Verlet is exact for a constant force), the clump's
/// being the whole clump's mass.
#[test]
fn a_force_hook_drives_spheres_and_clumps() {
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(0.1, 0.1, 0.1), [false; 3]).unwrap();
    let mut sys = SphereSystem::new(dom);
    sys.add_sphere(Vec3::new(0.02, 0.05, 0.05), Vec3::ZERO, Vec3::ZERO, R, 2500.0)
        .unwrap();
    let frame = BodyFrame::of(&ClumpTemplate::tetrahedron(R, 1.5 * R), 2500.0, DEFAULT_NODES).unwrap();
    sys.add_clump(
        &frame,
        Vec3::new(0.06, 0.05, 0.05),
        UnitQuaternion::identity(),
        Vec3::ZERO,
        Vec3::ZERO,
    )
    .unwrap();
    let f = Vec3::new(1e-4, -2e-4, 0.5e-4);
    let mut calls = 0;
    let mut hook = |_: f64, _: &SphereSystem, force: &mut [Vec3], _: &mut [Vec3]| {
        calls += 1;
        force[0] += f;
        force[1] += f;
    };
    let (dt, steps) = (2e-6, 500);
    let mut st = SphereStepper::new();
    for _ in 0..steps {
        st.step_with(&SphereStepParams::new(dt, 0.0), &law(), &mut sys, &mut hook)
            .unwrap();
    }
    let t = dt * steps as f64;
    let want_free = f * (t / sys.spheres.mass[0]);
    let want_clump = f * (t / sys.clumps.mass[0]);
    let (e0, e1) = (
        (sys.spheres.vel[0] - want_free).norm() / want_free.norm(),
        (sys.clumps.vel[0] - want_clump).norm() / want_clump.norm(),
    );
    println!("hook-driven velocity off by {e0:.1e} (sphere), {e1:.1e} (clump)");
    // Measured: 2.7e-14 and 1.6e-14 (rounding over 500 steps).
    assert!(e0 < 5.4e-14 && e1 < 3.2e-14, "{e0:e} {e1:e}");
    // Once to prime F(0), once per step.
    assert_eq!(calls, steps + 1);
    // Off-centre on the clump (member 1, not at the centre of mass): it spins up.
    assert!(sys.clumps.ang_mom[0].norm() > 0.0);
}

/// 9261 spheres (above the size from which the kicks and per-sphere checks run on the pool)
/// colliding in a periodic box with walls: the same state, bit for bit, on 1 and 2 threads.
#[test]
fn a_large_system_gives_the_same_bits_on_one_and_two_threads() {
    let s0 = packed(21, [true, true, false], 11);
    assert!(s0.spheres.len() >= 8192);
    let p = params();
    let go = |threads: usize| {
        crate::common::on_threads(threads, || {
            let mut s = s0.clone();
            run(&mut s, &mut SphereStepper::new(), &p, 60);
            s
        })
    };
    let (a, b) = (go(1), go(2));
    // The spheres met: some pair holds a tangential spring.
    let xi = a.contacts.hist.as_slice::<Vec3>().unwrap();
    assert!(xi.iter().any(|x| x.norm2() > 0.0), "no sphere touched another");
    assert!(a == b, "1 and 2 threads part");
}

/// The batched Hertz-Mindlin pair kernel (`spheres::hm_batched`, taken when no contact records
/// are kept) against the scalar pass (taken while recording): the same state to the bit after
/// hundreds of steps, on a periodic box with walls and gravity (with frozen spheres and two
/// tetrahedral clumps among the free ones), and on a Lees-Edwards box (pairs across the
/// sheared faces, whose images move), each at the SIMD level the CPU offers and on one thread
/// and two; and a system above the size from which the packing and the sums use the pool.
#[test]
fn the_batched_hertz_mindlin_kernel_gives_the_scalar_pass_bits() {
    let frame = BodyFrame::of(
        &ClumpTemplate::tetrahedron(0.5 * R, 0.7 * R),
        2500.0,
        DEFAULT_NODES,
    )
    .unwrap();
    let mut walled = packed(9, [true, true, false], 5);
    for k in [3, 40, 41, 300, 500] {
        walled.set_frozen(k, true).unwrap();
    }
    // Two clumps in the gaps of the lattice's first layer (a member meets its neighbours soon).
    for c in [
        Vec3::new(2.1 * R, 2.1 * R, 2.1 * R),
        Vec3::new(6.3 * R, 4.2 * R, 2.1 * R),
    ] {
        let q = UnitQuaternion::from_euler_angles(0.3, 0.2, -0.4);
        walled
            .add_clump(&frame, c, q, Vec3::new(0.5, 0.0, 0.0), Vec3::new(0.0, 100.0, 0.0))
            .unwrap();
    }
    let mut sheared = packed(9, [true, true, true], 6);
    sheared.domain = sheared.domain.with_lees_edwards(2000.0).unwrap();
    for (name, s0) in [("walled", walled), ("Lees-Edwards", sheared)] {
        let p = SphereStepParams {
            gravity: if name == "walled" {
                params().gravity
            } else {
                Vec3::ZERO
            },
            ..params()
        };
        let go = |record: bool, threads: usize| {
            crate::common::on_threads(threads, || {
                let mut s = s0.clone();
                let mut st = SphereStepper::new();
                st.record_contacts(record);
                run(&mut s, &mut st, &p, 400);
                s
            })
        };
        let scalar = go(true, 1);
        let xi = scalar.contacts.hist.as_slice::<Vec3>().unwrap();
        let sliding = xi.iter().filter(|x| x.norm2() > 0.0).count();
        assert!(sliding > 50, "{name}: only {sliding} springs loaded");
        assert!(
            go(false, 1) == scalar,
            "{name}: the batched kernel parts from the scalar pass"
        );
        assert!(go(false, 2) == scalar, "{name}: two threads part");
    }
    // From 8192 spheres the lines are packed on the pool and the force and torque sums run
    // side by side: still the scalar pass's bits.
    let big = packed(21, [true, true, false], 11);
    let go = |record: bool| {
        crate::common::on_threads(2, || {
            let mut s = big.clone();
            let mut st = SphereStepper::new();
            st.record_contacts(record);
            run(&mut s, &mut st, &params(), 60);
            s
        })
    };
    assert!(
        go(false) == go(true),
        "the large system parts from the scalar pass"
    );
}
