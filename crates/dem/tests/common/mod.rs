#![allow(dead_code)]
use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::*;

/// Two bodies in open space.
pub fn two(shape_a: &ClumpShape<Vec2>, shape_b: &ClumpShape<Vec2>, a: Vec2, b: Vec2) -> System {
    let mut bodies = Bodies::new();
    bodies.add(shape_a, 1.0, a, 0.0).unwrap();
    bodies.add(shape_b, 1.0, b, 0.0).unwrap();
    System::new(
        bodies,
        Domain::open(Vec2::new(-10.0, -10.0), Vec2::new(10.0, 10.0)),
    )
}

pub fn bits(s: &System) -> Vec<u64> {
    let b = &s.bodies;
    let mut v = Vec::new();
    for k in 0..b.len() {
        v.extend(
            [
                b.pos[k].x, b.pos[k].y, b.vel[k].x, b.vel[k].y, b.angle[k], b.omega[k],
            ]
            .map(f64::to_bits),
        );
    }
    v
}

/// The two-circle grain (radii 0.4 and 0.3, centres 0.45 apart) of the clump tests.
pub fn two_circle_grain() -> ClumpShape<Vec2> {
    ClumpShape {
        balls: vec![
            Ball {
                centre: Vec2::new(-0.2, 0.0),
                r: 0.4,
            },
            Ball {
                centre: Vec2::new(0.25, 0.0),
                r: 0.3,
            },
        ],
    }
}

/// Two-circle clumps and disks (3:1) inserted at random in a walled open box of side `side`,
/// under gravity, with the linear law of the determinism tests: the general (non-disk) path of
/// the stepper.
pub fn clumps_in_walled_box(side: f64, count: usize, seed: u64) -> (System, LinearSpringDashpot, StepParams) {
    let grain = two_circle_grain();
    let (lo, hi) = (Vec2::ZERO, Vec2::new(side, side));
    let bodies = generate::random_insert(
        &[grain, ClumpShape::disk(0.4)],
        &[3.0, 1.0],
        1.0,
        lo,
        hi,
        count,
        seed,
    )
    .unwrap();
    let mut s = System::new(bodies, Domain::open(lo, hi));
    s.walls = generate::box_walls(lo, hi);
    let law = contact::LinearSpringDashpot::new(2e4, 2e4 * 2.0 / 7.0, Damping::Gamma(50.0), 0.5);
    let mut p = StepParams::new(2.0e-4, 0.1);
    p.gravity = Vec2::new(0.0, -9.81);
    (s, law, p)
}

/// `f` run on a pool of `threads` threads (the thread-count tests compare its results).
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}
