//! Lees-Edwards boundaries of the 3D sphere engine (`Domain3::with_lees_edwards`; Lees &
//! Edwards 1972, J. Phys. C 5, 1921): free spheres crossing the sheared faces, a pair straddling
//! them against the same pair inside the box, and a checkpoint of a sheared suspension resumed
//! bit for bit. The engine is serial, so there is no thread-count test (one could not fail).
//!
//! Run: `cargo test -p lbdem-dem --test dem lees_edwards:: -- --nocapture`.

use crate::suspension;

use lbdem_dem::spheres::{Domain3, LinearSpring, SphereLaw, SphereStepParams, SphereStepper, SphereSystem};
use lbdem_dem::{Vec3, Vector};
use suspension::{ness_law, sheared};

/// Spheres that never touch (one per z plane, 0.1 apart, radius 0.04) moving at constant lab
/// velocities through a Lees-Edwards box (L = 2 × 3 × 1, γ̇ = 0.5) for 10 time units: each
/// crosses the y faces 1-7 times. Their stored state must be the wrapped image of the
/// straight-line motion: k = floor(Y/L_y) boxes up, y = Y − k L_y, x = X − k s(t) modulo L_x with
/// s(t) = γ̇ L_y t modulo L_x, v_x = V_x − k γ̇ L_y; and the velocity relative to the affine
/// profile, v_x − γ̇ y, is continuous across the faces (equal to V_x − γ̇ Y).
#[test]
fn free_spheres_cross_the_sheared_faces_consistently() {
    let (lx, ly, lz, rate) = (2.0, 3.0, 1.0, 0.5);
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(lx, ly, lz), [true; 3])
        .unwrap()
        .with_lees_edwards(rate)
        .unwrap();
    let mut sys = SphereSystem::new(dom);
    let mut start = Vec::new();
    for k in 0..8 {
        let y = 0.3 + 0.35 * k as f64;
        let vy = [1.3, -0.7, 2.1, -1.9, 0.5, -0.45, 1.0, -2.3][k];
        // The affine profile plus a peculiar part.
        let v = Vec3::new(rate * (y - 0.5 * ly) + 0.1 * k as f64 - 0.3, vy, 0.0);
        let p = Vec3::new(0.2 * k as f64, y, 0.05 + 0.1 * k as f64);
        sys.add_sphere(p, v, Vec3::ZERO, 0.04, 1.0).unwrap();
        start.push((p, v));
    }
    let law = LinearSpring::ness(1.0, 0.5, 0.5);
    let dt = 5e-4;
    assert!(dt < law.max_time_step(0.04, sys.spheres.mass[0]).dt);
    let p = SphereStepParams::new(dt, 0.005);
    let mut st = SphereStepper::new();
    let steps = 20_000;
    let (mut worst_x, mut worst_v, mut worst_s) = (0.0f64, 0.0f64, 0.0f64);
    let mut crossings = vec![0i64; 8];
    for n in 1..=steps {
        st.step(&p, &law, &mut sys).unwrap();
        if n % 100 != 0 {
            continue;
        }
        let t = n as f64 * dt;
        let s = (rate * ly * t).rem_euclid(lx);
        worst_s = worst_s.max((sys.domain.shear_offset() - s).abs());
        for (k, (p0, v0)) in start.iter().enumerate() {
            let (big_x, big_y) = (p0.x + v0.x * t, p0.y + v0.y * t);
            let boxes = (big_y / ly).floor();
            crossings[k] = crossings[k].max(boxes.abs() as i64);
            let (x, y) = ((big_x - boxes * s).rem_euclid(lx), big_y - boxes * ly);
            let got = sys.spheres.pos[k];
            let v = sys.spheres.vel[k];
            // Compared through the sheared minimum image: a sphere within rounding of a face
            // may sit on either side of it.
            let (d, dv) = sys.domain.min_image_moving(Vec3::new(x, y, got.z) - got);
            worst_x = worst_x.max(d.norm());
            let vx = v0.x - boxes * rate * ly;
            worst_v = worst_v
                .max((vx + dv.x - v.x).abs())
                .max((v.y - v0.y).abs())
                .max(((v.x - rate * got.y) - (v0.x - rate * big_y)).abs());
        }
    }
    println!(
        "box crossings per sphere {crossings:?}; worst position error {worst_x:.1e}, velocity \
         {worst_v:.1e}, offset {worst_s:.1e}"
    );
    assert!(crossings.iter().all(|&c| c >= 1), "{crossings:?}");
    // Measured: position 1.8e-12 (the offset summed 20 000 times, the drift x += v dt against
    // X0 + V t), velocity 7.0e-13 (γ̇ times that in v_x − γ̇ y), offset 3.4e-13.
    assert!(worst_x < 3.6e-12 && worst_v < 1.4e-12 && worst_s < 7e-13);
}

/// The relative state of a pair: separation (minimum image) and the velocity of j's image
/// relative to i, and both spins.
fn relative(sys: &SphereSystem) -> [Vec3; 4] {
    let s = &sys.spheres;
    let (d, dv) = sys.domain.min_image_moving(s.pos[1] - s.pos[0]);
    [d, s.vel[1] + dv - s.vel[0], s.omega[0], s.omega[1]]
}

/// A pair in sliding, lubricated contact (Ness's law: overlap 1e-3 d, h_eff = h_min) straddling
/// the top face of a Lees-Edwards box (offset 3.1 of 8, γ̇ = 0.3): sphere 0 below the face,
/// sphere 1 stored at the bottom, its image across the top one moving at v_1 + γ̇ L_y. The same
/// pair placed mid-box in a plain periodic box, sphere 1 given that image's velocity, must feel
/// the same force (lubrication reads the shifted relative velocity) and move the same way.
#[test]
fn a_pair_across_the_sheared_face_matches_the_pair_inside_the_box() {
    let (l, rate, a) = (8.0, 0.3, 0.5);
    let law = ness_law(1e4, 0.5);
    // j's image approaches i (relative velocity (1.9, 0.15, -0.08)·n < 0) and slides past it.
    let n = Vec3::new(-0.3, 0.9, 0.3) * (1.0 / (0.3f64 * 0.3 + 0.9 * 0.9 + 0.3 * 0.3).sqrt());
    let xi = Vec3::new(1.0, l - 0.3, 4.0);
    let xj = xi + n * (2.0 * a - 1e-3);
    let (vi, vj) = (Vec3::new(0.2, -0.05, 0.1), Vec3::new(-0.3, 0.1, 0.02));
    let (wi, wj) = (Vec3::new(0.0, 0.5, -0.2), Vec3::new(0.3, 0.0, 0.1));
    // Sheared box: j stored one box down from its image, shifted back by the offset.
    let mut dom = Domain3::new(Vec3::ZERO, Vec3::new(l, l, l), [true; 3])
        .unwrap()
        .with_lees_edwards(rate)
        .unwrap();
    dom.shear.as_mut().unwrap().offset = 3.1;
    let mut le = SphereSystem::new(dom);
    le.add_sphere(xi, vi, wi, a, 1.0).unwrap();
    le.add_sphere(xj, vj, wj, a, 1.0).unwrap();
    assert!(
        le.spheres.pos[1].y < 1.0,
        "stored at the bottom: {:?}",
        le.spheres.pos[1]
    );
    assert!((le.spheres.vel[1].x - (vj.x - rate * l)).abs() < 1e-15);
    // The same pair mid-box, plain periodic.
    let plain_dom = Domain3::new(Vec3::ZERO, Vec3::new(l, l, l), [true; 3]).unwrap();
    let mut mid = SphereSystem::new(plain_dom);
    let down = Vec3::new(0.0, -4.0, 0.0);
    mid.add_sphere(xi + down, vi, wi, a, 1.0).unwrap();
    mid.add_sphere(xj + down, vj, wj, a, 1.0).unwrap();
    let m = le.spheres.mass[0];
    let p = SphereStepParams::new(law.max_time_step(a, m).dt, 0.05);
    let (mut st_le, mut st_mid) = (SphereStepper::new(), SphereStepper::new());
    st_le.record_contacts(true);
    st_mid.record_contacts(true);
    let mut worst_state = 0.0f64;
    let mut sliding = 0;
    // Forces compared on the scale of the largest one of the run.
    let mut f_max = 0.0f64;
    let mut f_diff = 0.0f64;
    for _ in 0..400 {
        st_le.step(&p, &law, &mut le).unwrap();
        st_mid.step(&p, &law, &mut mid).unwrap();
        let (cl, cm) = (st_le.contacts(), st_mid.contacts());
        assert_eq!(cl.len(), cm.len());
        for (x, y) in cl.iter().zip(cm) {
            f_max = f_max.max(y.force.norm());
            f_diff = f_diff
                .max((x.force - y.force).norm())
                .max((x.hydro - y.hydro).norm());
            worst_state = worst_state.max((x.branch - y.branch).norm());
            // The spring has slid: |F_t| = μ F_n.
            let nb = y.branch * (1.0 / y.branch.norm());
            let fc = y.force - y.hydro;
            let f_n = -fc.dot(nb);
            let f_t = (fc + nb * f_n).norm();
            if f_n > 0.0 && (f_t - 0.5 * f_n).abs() < 1e-9 * f_n {
                sliding += 1;
            }
        }
        let (r1, r2) = (relative(&le), relative(&mid));
        for (u, w) in r1.iter().zip(&r2) {
            worst_state = worst_state.max((*u - *w).norm());
        }
    }
    let worst_f = f_diff / f_max;
    println!(
        "force (total and lubrication) and branch, relative: {worst_f:.1e}; relative state \
         {worst_state:.1e}; steps sliding {sliding}; largest force {f_max:.3}"
    );
    assert!(sliding > 0);
    // Measured: forces 2.1e-13 of the largest (the positions differ by the box shifts, so the
    // overlap of 1e-3 carries ~1e-15 of absolute rounding, times k_n = 1e4), separation,
    // relative velocity and spins 4.8e-13 over 400 steps.
    assert!(worst_f < 4.2e-13 && worst_state < 9.6e-13);
}

/// A sheared suspension (64 spheres, φ = 0.45, Ness's law, Lees-Edwards at γ̇ = 0.05) run for
/// 600 steps against 300 + JSON checkpoint + 300 with a fresh stepper: identical JSON. At the
/// checkpoint the offset is non-zero and pairs straddle the sheared faces.
#[test]
fn sheared_checkpoint_resumes_bit_for_bit() {
    let law = ness_law(1e4, 0.5);
    let mut sys = sheared(64, 0.45, 0.05, 7);
    let m = sys.spheres.mass[0];
    let p = SphereStepParams::new(law.max_time_step(0.5, m).dt, 0.1);
    let run = |sys: &mut SphereSystem, steps: usize| {
        let mut st = SphereStepper::new();
        for _ in 0..steps {
            st.step(&p, &law, sys).unwrap();
        }
    };
    let mut whole = sys.clone();
    run(&mut whole, 600);
    run(&mut sys, 300);
    let json = serde_json::to_string(&sys).unwrap();
    let l = sys.domain.size().y;
    let straddling = sys
        .contacts
        .pairs
        .iter()
        .filter(|&&[i, j]| (sys.spheres.pos[j as usize].y - sys.spheres.pos[i as usize].y).abs() > 0.5 * l)
        .count();
    println!(
        "offset at the checkpoint {:.3e} of L_x = {l:.3}; {straddling} listed pairs straddle the \
         sheared faces",
        sys.domain.shear_offset()
    );
    assert!(sys.domain.shear_offset() > 0.0 && straddling > 0);
    let mut resumed: SphereSystem = serde_json::from_str(&json).unwrap();
    run(&mut resumed, 300);
    assert_eq!(
        serde_json::to_string(&resumed).unwrap(),
        serde_json::to_string(&whole).unwrap()
    );
}

/// The Verlet list on a Lees-Edwards box: spheres at rest (no affine profile) in two rows just
/// inside the bottom and top faces of a fast-sheared box (γ̇ L_y = 2, 4 spheres a row, radius
/// 0.05, 0.06 apart across the face in y) are reached only by the images sliding past along x,
/// so nothing moves a sphere before the first collision: only the offset term of the skin check
/// can rebuild the list in time. The run with a skin must match, bit for bit, a run whose list
/// is rebuilt every step (its reference positions dropped before each step, so the rebuild does
/// not rest on the skin check under test). Measured: equal at every step; with the offset term
/// taken out of the check the run with the skin misses the first contact (forces differ at it).
#[test]
fn verlet_list_follows_the_sliding_images() {
    let (lx, ly, lz, rate, a) = (2.0, 1.0, 0.5, 2.0, 0.05);
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(lx, ly, lz), [true; 3])
        .unwrap()
        .with_lees_edwards(rate)
        .unwrap();
    let mut sys = SphereSystem::new(dom);
    for k in 0..4 {
        let x = 0.5 * k as f64;
        sys.add_sphere(Vec3::new(x + 0.25, 0.03, 0.25), Vec3::ZERO, Vec3::ZERO, a, 1.0)
            .unwrap();
        sys.add_sphere(Vec3::new(x, ly - 0.03, 0.25), Vec3::ZERO, Vec3::ZERO, a, 1.0)
            .unwrap();
    }
    let law = LinearSpring::ness(100.0, 0.5, 0.5);
    let dt = 0.5 * law.max_time_step(a, sys.spheres.mass[0]).dt;
    let p = SphereStepParams::new(dt, 0.02);
    let (mut sa, mut sb) = (sys.clone(), sys);
    let (mut ta, mut tb) = (SphereStepper::new(), SphereStepper::new());
    // Two passes of the images along the whole box.
    let steps = (2.0 * lx / (rate * ly * dt)).ceil() as usize;
    let (mut first_touch, mut f_max) = (None, 0.0f64);
    for n in 0..steps {
        ta.step(&p, &law, &mut sa).unwrap();
        // A list without reference positions is rebuilt.
        sb.contacts.list_ref.clear();
        tb.step(&p, &law, &mut sb).unwrap();
        assert_eq!(sa.spheres.force, sb.spheres.force, "step {n}");
        assert_eq!(sa.spheres.pos, sb.spheres.pos, "step {n}");
        assert_eq!(sa.spheres.vel, sb.spheres.vel, "step {n}");
        let f = sb.spheres.force.iter().map(|f| f.norm()).fold(0.0, f64::max);
        if f > 0.0 && first_touch.is_none() {
            first_touch = Some(n);
        }
        f_max = f_max.max(f);
    }
    println!(
        "{steps} steps, first contact at step {first_touch:?}, largest force {f_max:.2e}; list \
         rebuilds {} with the skin check, {} forced",
        ta.rebuilds, tb.rebuilds
    );
    // The first contact comes after the list with the skin was built, and was caught.
    assert!(first_touch.is_some_and(|n| n > 10), "{first_touch:?}");
    assert!(ta.rebuilds > 1 && ta.rebuilds < tb.rebuilds / 4);
}

/// A state with a sphere outside the box on a periodic axis (a hand-edited or corrupt
/// checkpoint) is refused, naming the sphere, the axis, the value and the fix; the stepper
/// refuses it before moving anything. Outside on an open axis is the cell list's to refuse.
#[test]
fn positions_outside_a_periodic_box_are_refused() {
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(2.0, 3.0, 1.0), [true, true, false])
        .unwrap()
        .with_lees_edwards(0.5)
        .unwrap();
    let mut sys = SphereSystem::new(dom);
    sys.add_sphere(Vec3::new(0.5, 1.0, 0.5), Vec3::ZERO, Vec3::ZERO, 0.04, 1.0)
        .unwrap();
    sys.add_sphere(Vec3::new(1.5, 2.0, 0.5), Vec3::ZERO, Vec3::ZERO, 0.04, 1.0)
        .unwrap();
    assert!(sys.validate().is_ok());
    for (axis, name, v) in [(1, "y", 3.0), (0, "x", -1e-3)] {
        let mut bad = sys.clone();
        match axis {
            0 => bad.spheres.pos[1].x = v,
            _ => bad.spheres.pos[1].y = v,
        }
        let msg = bad.validate().unwrap_err().to_string();
        println!("{msg}");
        assert!(
            msg.contains("spheres.pos")
                && msg.contains(&format!("sphere 1 at {name} = {v:e} m"))
                && msg.contains("wrap_moving"),
            "{msg}"
        );
        let json = serde_json::to_string(&bad).unwrap();
        let err = serde_json::from_str::<SphereSystem>(&json)
            .unwrap_err()
            .to_string();
        assert!(err.contains("sphere 1 at"), "{err}");
        let law = LinearSpring::ness(1.0, 0.5, 0.5);
        let before = bad.clone();
        assert!(
            SphereStepper::new()
                .step(&SphereStepParams::new(1e-4, 0.005), &law, &mut bad)
                .is_err()
        );
        assert_eq!(bad, before);
    }
    // Above the box on the open z axis: not this check's.
    sys.spheres.pos[0].z = 1.5;
    assert!(sys.validate().is_ok());
}
