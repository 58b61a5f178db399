//! Assembly generation (Su et al. 2020 Sect. 2.4): random insertion of clumps from a
//! size/shape distribution, isotropic compression by servo walls to a target 2D stress, radius
//! scaling and grain removal/addition to reach a target packing fraction, and relaxation until
//! every grain is slower than a threshold. Also the periodic bidisperse packings of the benchmark.

use crate::body::Bodies;
use crate::contact::ContactLaw;
use crate::domain::Domain;
use crate::error::DemError;
use crate::shape::ClumpShape;
use crate::stepper::{StepParams, Stepper};
use crate::system::System;
use crate::vector::{Vec2, Vector};
use crate::wall::{ServoLength, Wall, WallMotion, WallShape};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Deterministic generator used everywhere in the crate (portable across rand versions).
pub fn rng(seed: u64) -> Xoshiro256PlusPlus {
    Xoshiro256PlusPlus::seed_from_u64(seed)
}

/// Insert `n` clumps drawn from `templates` (chosen with probabilities ∝ `weights`) at random
/// positions and orientations in the box [lo, hi] without overlap (random sequential addition).
/// Fails if a clump cannot be placed after many trials (box too full: enlarge it).
pub fn random_insert(
    templates: &[ClumpShape<Vec2>],
    weights: &[f64],
    density: f64,
    lo: Vec2,
    hi: Vec2,
    n: usize,
    seed: u64,
) -> Result<Bodies, DemError> {
    let mut r = rng(seed);
    let wsum: f64 = weights.iter().sum();
    let mut bodies = Bodies::new();
    let mut circles: Vec<(Vec2, f64)> = Vec::new();
    for _ in 0..n {
        let u: f64 = r.random::<f64>() * wsum;
        let mut acc = 0.0;
        let mut t = templates.len() - 1;
        for (k, w) in weights.iter().enumerate() {
            acc += w;
            if u < acc {
                t = k;
                break;
            }
        }
        let (shape, _) = templates[t].centred()?;
        let br = shape.bounding_radius();
        let mut placed = false;
        for _ in 0..20_000 {
            let at = Vec2::new(
                lo.x + br + (hi.x - lo.x - 2.0 * br) * r.random::<f64>(),
                lo.y + br + (hi.y - lo.y - 2.0 * br) * r.random::<f64>(),
            );
            let ang = std::f64::consts::TAU * r.random::<f64>();
            let mine: Vec<(Vec2, f64)> = shape
                .balls
                .iter()
                .map(|b| (at + b.centre.rotated(ang), b.r))
                .collect();
            let clash = mine
                .iter()
                .any(|&(p, rr)| circles.iter().any(|&(q, rq)| (p - q).norm2() < (rr + rq).powi(2)));
            if !clash {
                circles.extend(mine);
                bodies.add(&shape, density, at, ang)?;
                placed = true;
                break;
            }
        }
        if !placed {
            return Err(DemError::BadParameter {
                name: "grain count",
                value: n as f64,
                why: "random insertion found no free place; enlarge the box or insert fewer grains",
            });
        }
    }
    Ok(bodies)
}

/// Four plane walls around [lo, hi]: 0 left, 1 right, 2 bottom, 3 top (normals inward).
pub fn box_walls(lo: Vec2, hi: Vec2) -> Vec<Wall> {
    vec![
        Wall::plane(lo, Vec2::new(1.0, 0.0)),
        Wall::plane(hi, Vec2::new(-1.0, 0.0)),
        Wall::plane(lo, Vec2::new(0.0, 1.0)),
        Wall::plane(hi, Vec2::new(0.0, -1.0)),
    ]
}

/// Servo settings of an isotropic compression.
#[derive(Clone, Copy, Debug)]
pub struct Compression {
    /// Target 2D stress (N/m) on every wall.
    pub target_stress: f64,
    /// Servo relaxation factor α (fraction of the stress error closed per step; 0.1-0.5).
    pub alpha: f64,
    pub v_max: f64,
    /// Stop when every wall is within this relative error of the target...
    pub tolerance: f64,
    /// ...and every grain is slower than this (m/s).
    pub v_threshold: f64,
    pub max_steps: u64,
}

/// Compress isotropically with the four box walls (indices 0-3 of `sys.walls`) servo-controlled
/// to `c.target_stress`; returns the steps taken. The walls are fixed again at the end.
pub fn compress_isotropic<L: ContactLaw>(
    sys: &mut System,
    law: &L,
    wall_law: &L,
    p: &StepParams,
    c: &Compression,
    stepper: &mut Stepper,
) -> Result<u64, DemError> {
    start_servo(sys, c);
    let mut steps = 0;
    while steps < c.max_steps {
        stepper.step(p, law, wall_law, sys)?;
        steps += 1;
        if steps % 100 == 0 && servo_settled(sys, c).0 {
            break;
        }
    }
    stop_servo(sys);
    Ok(steps)
}

/// Put the four box walls (indices 0-3 of `sys.walls`: left, right, bottom, top) under servo
/// control to `c.target_stress` (Su Sect. 2.4); each wall's stress is its force over the gap
/// between the perpendicular pair. Each pair's speed limit is `c.v_max` times its gap over the
/// larger gap, so that while the walls close in at full speed both directions strain at the
/// same rate and the box keeps its shape (equal speeds squeezed a 7.5 × 10 mm box 11 % more
/// across than along).
pub fn start_servo(sys: &mut System, c: &Compression) {
    let gx = Wall::gap(&sys.walls[0], &sys.walls[1]);
    let gy = Wall::gap(&sys.walls[2], &sys.walls[3]);
    let g_max = gx.max(gy).max(f64::MIN_POSITIVE);
    for k in 0..4 {
        let (length, gap) = if k < 2 {
            (ServoLength::Between(2, 3), gx)
        } else {
            (ServoLength::Between(0, 1), gy)
        };
        sys.walls[k].motion = WallMotion::Servo {
            target_stress: c.target_stress,
            alpha: c.alpha,
            v_max: c.v_max * gap / g_max,
            length,
        };
    }
}

/// Whether the servo compression has settled: every wall within `c.tolerance` of the target
/// stress and every grain slower than `c.v_threshold`; also the largest relative stress error.
pub fn servo_settled(sys: &System, c: &Compression) -> (bool, f64) {
    let err = (0..4)
        .map(|k| {
            let l = if k < 2 {
                Wall::gap(&sys.walls[2], &sys.walls[3])
            } else {
                Wall::gap(&sys.walls[0], &sys.walls[1])
            };
            (sys.walls[k].stress(l) / c.target_stress - 1.0).abs()
        })
        .fold(0.0, f64::max);
    (err < c.tolerance && sys.bodies.max_speed() < c.v_threshold, err)
}

/// Fix the four box walls where the servo left them.
pub fn stop_servo(sys: &mut System) {
    for w in sys.walls.iter_mut().take(4) {
        w.motion = WallMotion::Fixed;
        w.vel = Vec2::ZERO;
    }
}

/// Scale all grain sizes so that the packing fraction becomes `target` (Su Sect. 2.4).
pub fn scale_to_packing(sys: &mut System, target: f64) {
    let s = (target / sys.packing_fraction()).sqrt();
    sys.bodies.scale_sizes(s);
    sys.contacts = Default::default();
}

/// Delete `n` grains chosen at random (lowers the packing fraction).
pub fn remove_random(sys: &mut System, n: usize, seed: u64) {
    let mut r = rng(seed);
    let mut drop = vec![false; sys.bodies.len()];
    let mut left = n.min(sys.bodies.len());
    while left > 0 {
        let k = r.random_range(0..drop.len());
        if !drop[k] {
            drop[k] = true;
            left -= 1;
        }
    }
    sys.bodies.retain(|k| !drop[k]);
    sys.contacts = Default::default();
}

/// Add up to `n` copies of `shape` into interstices (random trials without overlap inside the
/// box of walls 0-3); returns how many were added (raises the packing fraction).
pub fn add_in_voids(
    sys: &mut System,
    shape: &ClumpShape<Vec2>,
    density: f64,
    n: usize,
    seed: u64,
) -> Result<usize, DemError> {
    let mut r = rng(seed);
    let (lo, hi) = wall_box(sys);
    let (shape, _) = shape.centred()?;
    let mut added = 0;
    let mut trials = 0;
    while added < n && trials < 200_000 {
        trials += 1;
        let at = Vec2::new(
            lo.x + (hi.x - lo.x) * r.random::<f64>(),
            lo.y + (hi.y - lo.y) * r.random::<f64>(),
        );
        let ang = std::f64::consts::TAU * r.random::<f64>();
        let br = shape.bounding_radius();
        if at.x - br < lo.x || at.x + br > hi.x || at.y - br < lo.y || at.y + br > hi.y {
            continue;
        }
        let b = &sys.bodies;
        let clash = shape.balls.iter().any(|ball| {
            let p = at + ball.centre.rotated(ang);
            (0..b.n_circles()).any(|c| (b.circle_pos(c) - p).norm2() < (b.circle_r[c] + ball.r).powi(2))
        });
        if !clash {
            sys.bodies.add(&shape, density, at, ang)?;
            added += 1;
        }
    }
    sys.contacts = Default::default();
    Ok(added)
}

/// The box of the four plane walls 0-3 (left, right, bottom, top): lower and upper corners.
pub fn wall_box(sys: &System) -> (Vec2, Vec2) {
    let x = |w: &Wall| match w.shape {
        WallShape::Plane { p, .. } => p,
        WallShape::Segment { a, .. } => a,
    };
    (
        Vec2::new(x(&sys.walls[0]).x, x(&sys.walls[2]).y),
        Vec2::new(x(&sys.walls[1]).x, x(&sys.walls[3]).y),
    )
}

/// Step until every grain is slower than `v_threshold` (checked every 100 steps) or `max_steps`.
pub fn relax<L: ContactLaw>(
    sys: &mut System,
    law: &L,
    wall_law: &L,
    p: &StepParams,
    v_threshold: f64,
    max_steps: u64,
    stepper: &mut Stepper,
) -> Result<u64, DemError> {
    let mut steps = 0;
    while steps < max_steps {
        stepper.step(p, law, wall_law, sys)?;
        steps += 1;
        if steps % 100 == 0 && sys.bodies.max_speed() < v_threshold {
            break;
        }
    }
    Ok(steps)
}

/// Bidisperse disks (diameters d and `ratio`·d, 50/50 at random) on a square lattice of
/// `n_side`² sites with spacing `a`, in a periodic box (the start of the benchmark packing,
/// as in peers/lammps_2d_prep.in). Density per area 1 → disk mass π r².
pub fn bidisperse_lattice(n_side: usize, d: f64, ratio: f64, a: f64, seed: u64) -> Result<System, DemError> {
    let mut r = rng(seed);
    let mut bodies = Bodies::new();
    let small = ClumpShape::disk(0.5 * d);
    let large = ClumpShape::disk(0.5 * d * ratio);
    for iy in 0..n_side {
        for ix in 0..n_side {
            let s = if r.random::<f64>() < 0.5 { &small } else { &large };
            let k = bodies.add(
                s,
                1.0,
                Vec2::new((ix as f64 + 0.5) * a, (iy as f64 + 0.5) * a),
                0.0,
            )?;
            bodies.vel[k] = Vec2::new(r.random::<f64>() - 0.5, r.random::<f64>() - 0.5) * 2e-4;
        }
    }
    let l = n_side as f64 * a;
    Ok(System::new(bodies, Domain::periodic(Vec2::ZERO, Vec2::new(l, l))))
}

/// Compress a periodic system affinely to packing fraction `phi` over `steps` steps (the box
/// shrinks uniformly about its lower corner), like `fix deform ... final` in the LAMMPS prep deck.
pub fn compress_periodic<L: ContactLaw>(
    sys: &mut System,
    law: &L,
    p: &StepParams,
    phi: f64,
    steps: u64,
    stepper: &mut Stepper,
) -> Result<(), DemError> {
    let area = sys.bodies.total_area();
    let s0 = sys.domain.size();
    let target = (area / phi / (s0.x * s0.y)).sqrt();
    for k in 1..=steps {
        let f = 1.0 + (target - 1.0) * k as f64 / steps as f64;
        let lo = sys.domain.lo;
        let mut d = sys.domain;
        d.remap_affine(lo, lo + Vec2::new(s0.x * f, s0.y * f), &mut sys.bodies);
        sys.domain = d;
        stepper.step(p, law, law, sys)?;
    }
    Ok(())
}

/// Replicate a periodic system `nx` × `ny` times (contacts and velocities included), giving a
/// larger periodic packing with the same structure.
pub fn tile(sys: &System, nx: usize, ny: usize) -> Result<System, DemError> {
    let s = sys.domain.size();
    let mut b = Bodies::new();
    for ty in 0..ny {
        for tx in 0..nx {
            let shift = Vec2::new(tx as f64 * s.x, ty as f64 * s.y);
            for k in 0..sys.bodies.len() {
                let nk = b.add(
                    &sys.bodies.shape(k),
                    sys.bodies.density[k],
                    sys.bodies.pos[k] + shift,
                    sys.bodies.angle[k],
                )?;
                b.vel[nk] = sys.bodies.vel[k];
                b.omega[nk] = sys.bodies.omega[k];
            }
        }
    }
    let lo = sys.domain.lo;
    let hi = lo + Vec2::new(s.x * nx as f64, s.y * ny as f64);
    Ok(System::new(
        b,
        Domain {
            lo,
            hi,
            periodic: sys.domain.periodic,
        },
    ))
}
