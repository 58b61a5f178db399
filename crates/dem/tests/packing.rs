//! Isotropic compression of bidisperse disks by servo walls (Su et al. 2020 Sect. 2.4 protocol)
//! against the published 2D jamming packing fraction: frictionless bidisperse (1:1.4) disks jam at
//! φ_J ≈ 0.84 (O'Hern, Silbert, Liu & Nagel, PRE 68 (2003) 011306; REFERENCES.md, also ≈ 0.84
//! for polydisperse disks, Meer et al. arXiv 2404.02316); friction lowers the jamming packing
//! fraction (REFERENCES.md; PEERS.md: μ = 0.5 disks are not jammed at 0.80 in the LAMMPS protocol).
//!
//! The test uses ~1000 disks; the full version (4000 disks) runs with
//! `cargo test --release -p lbdem-dem --test packing -- --ignored`.
//! Tolerance: 0.84 ± 0.02 covers the finite-size spread of φ_J at N ~ 10³ reported by O'Hern
//! et al. (their Fig. on the width of the φ_J distribution) and the finite compression rate.
//! Measured (2026-11-25): frictionless φ = 0.8399 at 1000 disks, 0.8410 at 4000; μ = 0.5:
//! 0.8057 and 0.8067.

use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::*;

/// Area fraction inside the window [lo, hi] by point sampling on a grid of spacing h.
fn window_fraction(s: &System, lo: Vec2, hi: Vec2, h: f64) -> f64 {
    let b = &s.bodies;
    let cell = 1.5;
    let nx = ((hi.x - lo.x) / cell).ceil() as usize + 2;
    let ny = ((hi.y - lo.y) / cell).ceil() as usize + 2;
    let mut bins = vec![Vec::new(); nx * ny];
    for c in 0..b.n_circles() {
        let p = b.circle_pos(c);
        let ix = ((p.x - lo.x) / cell + 1.0).floor();
        let iy = ((p.y - lo.y) / cell + 1.0).floor();
        if ix >= 0.0 && iy >= 0.0 && (ix as usize) < nx && (iy as usize) < ny {
            bins[iy as usize * nx + ix as usize].push(c);
        }
    }
    let (mut hit, mut tot) = (0u64, 0u64);
    let mut y = lo.y + 0.5 * h;
    while y < hi.y {
        let mut x = lo.x + 0.5 * h;
        while x < hi.x {
            tot += 1;
            let ix = ((x - lo.x) / cell + 1.0) as usize;
            let iy = ((y - lo.y) / cell + 1.0) as usize;
            'found: for dy in 0..3 {
                for dx in 0..3 {
                    let (jx, jy) = (ix + dx - 1, iy + dy - 1);
                    if jx >= nx || jy >= ny {
                        continue;
                    }
                    for &c in &bins[jy * nx + jx] {
                        if (b.circle_pos(c) - Vec2::new(x, y)).norm2() < b.circle_r[c] * b.circle_r[c] {
                            hit += 1;
                            break 'found;
                        }
                    }
                }
            }
            x += h;
        }
        y += h;
    }
    hit as f64 / tot as f64
}

/// Compress `n` bidisperse disks with friction `mu`; returns (interior φ, system, law, params).
fn compress(n: usize, mu: f64, seed: u64) -> (f64, System, LinearSpringDashpot, StepParams) {
    let shapes = [ClumpShape::disk(0.5), ClumpShape::disk(0.7)];
    let area = n as f64 * std::f64::consts::PI * (0.25 + 0.49) / 2.0;
    let l = (area / 0.45).sqrt();
    let (lo, hi) = (Vec2::ZERO, Vec2::new(l, l));
    let bodies = generate::random_insert(&shapes, &[1.0, 1.0], 1.0, lo, hi, n, seed).unwrap();
    let mut s = System::new(bodies, Domain::open(lo, hi));
    s.walls = generate::box_walls(lo, hi);
    let k = 1.0e4;
    let law = LinearSpringDashpot::new(k, k / 2.0, Damping::Ratio(0.5), mu);
    let (crit, _, _) = Stepper::critical_time_step(&s, &law, &law);
    let mut p = StepParams::new(0.2 * crit, 0.2);
    p.local_damping = 0.2;
    let target = 1.0; // σ/k_n = 1e-4: overlaps of 1e-4 d, close to the jamming point
    // The walls travel about 0.14 L each from φ = 0.45 to jamming, so the run length grows with
    // the box side L ∝ √n. A cap of 30 000 steps left 1000 disks 30 % off the target stress
    // (their φ passed by luck) and stopped 4000 at φ = 0.63 (2026-11-24); 60 000 at 1000 disks
    // reach it (error 0.033).
    let max_steps = (60_000.0 * (n as f64 / 1000.0).sqrt()).ceil() as u64;
    let c = generate::Compression {
        target_stress: target,
        alpha: 0.05,
        v_max: 0.3,
        tolerance: 0.05,
        v_threshold: 1e-3,
        max_steps,
    };
    let mut st = Stepper::new();
    let steps = generate::compress_isotropic(&mut s, &law, &law, &p, &c, &mut st).unwrap();
    eprintln!("mu = {mu}: compression took {steps} steps (cap {max_steps})");
    // The packing fraction means something only at the target stress. The servo's full stop
    // (also every grain slower than v_threshold) is not reached: rattlers, grains without
    // contacts, keep their speed (1.2e-2 at 1000 disks, frictionless), so the cap ends the run;
    // what is checked is that the walls hold the target stress (error 0.033 measured).
    let (_, err) = generate::servo_settled(&s, &c);
    eprintln!(
        "wall stress error {err:.3}, largest grain speed {:.1e}",
        s.bodies.max_speed()
    );
    assert!(
        err < c.tolerance,
        "mu = {mu}: wall stress {err} off the target after {steps} steps"
    );
    // Interior window 3 large diameters away from every wall (no wall layering).
    let gx = Wall::gap(&s.walls[0], &s.walls[1]);
    let gy = Wall::gap(&s.walls[2], &s.walls[3]);
    let x0 = match s.walls[0].shape {
        WallShape::Plane { p, .. } => p.x,
        _ => 0.0,
    };
    let y0 = match s.walls[2].shape {
        WallShape::Plane { p, .. } => p.y,
        _ => 0.0,
    };
    let m = 4.2;
    let phi = window_fraction(
        &s,
        Vec2::new(x0 + m, y0 + m),
        Vec2::new(x0 + gx - m, y0 + gy - m),
        0.04,
    );
    (phi, s, law, p)
}

fn check(n: usize) {
    let (phi0, ..) = compress(n, 0.0, 21);
    let (phi_f, mut s, law, p) = compress(n, 0.5, 21);
    eprintln!("N = {n}: frictionless φ = {phi0:.4}, μ = 0.5 φ = {phi_f:.4}");
    assert!(
        (phi0 - 0.84).abs() < 0.02,
        "frictionless φ = {phi0}, published φ_J ≈ 0.84"
    );
    assert!(
        phi_f < phi0 - 0.01,
        "frictional φ = {phi_f} must be below frictionless {phi0}"
    );
    // Then radius scaling to a target packing fraction and relaxation (Su Sect. 2.4).
    let target = s.packing_fraction() * 0.99;
    generate::scale_to_packing(&mut s, target);
    assert!((s.packing_fraction() - target).abs() < 1e-12);
    let mut st = Stepper::new();
    // Grains freed by the shrink fly without contact forces: damp them viscously.
    let p = StepParams {
        viscous_damping: 5.0,
        ..p
    };
    let steps = generate::relax(&mut s, &law, &law, &p, 1e-4, 100_000, &mut st).unwrap();
    assert!(s.bodies.max_speed() < 1e-4, "still moving after {steps} steps");
}

#[test]
fn isotropic_compression_packing_fraction_quick() {
    check(1000);
}

#[test]
#[ignore = "full size (4000 disks): cargo test --release -p lbdem-dem --test packing -- --ignored"]
fn isotropic_compression_packing_fraction_full() {
    check(4000);
}
