#![allow(dead_code)]
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
