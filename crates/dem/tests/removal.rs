//! Changing the sphere count of a running 3D assembly (issue 19: Ness et al. 2017 insert spheres
//! at the inlet and remove them at the open outlet): appended spheres keep the others'
//! sphere-wall histories; a removal continues bit for bit as an assembly built without the
//! removed spheres from the same state, and a checkpoint taken after it resumes bit for bit.
//!
//! Run: `cargo test -p lbdem-dem --test dem removal:: -- --nocapture`.

use lbdem_dem::spheres::{
    Domain3, LinearSpring, PlaneWall, SphereError, SphereLaw, SphereStepParams, SphereStepper, SphereSystem,
};
use lbdem_dem::{Histories, Vec3, Vector};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::collections::HashMap;

const A: f64 = 1e-3;
const RHO: f64 = 2500.0;

fn law() -> LinearSpring {
    LinearSpring::ness(200.0, 0.5, 0.3)
}

fn params(law: &LinearSpring) -> SphereStepParams {
    let m = RHO * 4.0 / 3.0 * std::f64::consts::PI * (0.9 * A).powi(3);
    SphereStepParams {
        dt: law.max_time_step(0.9 * A, m).dt,
        gravity: Vec3::new(0.0, 0.0, -9.81),
        skin: 0.2 * A,
    }
}

/// 4 × 4 × 3 spheres (radius 0.9-1.0 A) with random velocities over a floor, periodic in x and
/// y, settled for `steps` steps so that pair and floor contacts carry tangential springs.
fn settled(steps: usize) -> SphereSystem {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(19);
    let l = 8.4 * A;
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(l, l, 4.0 * l), [true, true, false]).unwrap();
    let mut sys = SphereSystem::new(dom);
    sys.walls
        .push(PlaneWall::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0)).unwrap());
    let mut u = || 2.0 * rng.random::<f64>() - 1.0;
    for k in 0..48 {
        let (i, j, m) = (k % 4, (k / 4) % 4, k / 16);
        let c = |a: usize| (a as f64 + 0.5) * 2.1 * A;
        let vel = Vec3::new(u(), u(), u()) * 0.05;
        let r = A * (0.95 + 0.05 * u());
        sys.add_sphere(Vec3::new(c(i), c(j), c(m)), vel, Vec3::ZERO, r, RHO)
            .unwrap();
    }
    let (law, p) = (law(), params(&law()));
    let mut st = SphereStepper::new();
    for _ in 0..steps {
        st.step(&p, &law, &mut sys).unwrap();
    }
    sys
}

fn run(sys: &mut SphereSystem, steps: usize) {
    let (law, p) = (law(), params(&law()));
    let mut st = SphereStepper::new();
    for _ in 0..steps {
        st.step(&p, &law, sys).unwrap();
    }
}

fn live(h: &Histories) -> Vec<bool> {
    h.as_slice::<Vec3>()
        .unwrap_or(&[])
        .iter()
        .map(|x| *x != Vec3::ZERO)
        .collect()
}

/// The same state without the spheres `gone`, built independently of `remove_spheres`: spheres
/// added one by one, forces copied, pair and wall histories looked up by the old indices, no
/// list reference (the first step rebuilds the list and carries the histories onto it).
fn rebuilt_without(sys: &SphereSystem, gone: &[usize]) -> SphereSystem {
    let s = &sys.spheres;
    let mut b = SphereSystem::new(sys.domain);
    b.walls = sys.walls.clone();
    let mut id = HashMap::new();
    for k in (0..s.len()).filter(|k| !gone.contains(k)) {
        let n = b
            .add_sphere(s.pos[k], s.vel[k], s.omega[k], s.radius[k], RHO)
            .unwrap();
        assert_eq!(b.spheres.mass[n], s.mass[k]);
        b.spheres.force[n] = s.force[k];
        b.spheres.torque[n] = s.torque[k];
        id.insert(k as u32, n as u32);
    }
    let hist = sys.contacts.hist.as_slice::<Vec3>().unwrap();
    let (mut pairs, mut kept) = (Vec::new(), Vec::new());
    for (p, h) in sys.contacts.pairs.iter().zip(hist) {
        if let (Some(&i), Some(&j)) = (id.get(&p[0]), id.get(&p[1])) {
            pairs.push([i, j]);
            kept.push(*h);
        }
    }
    let nw = sys.walls.len();
    let wall = sys.contacts.wall_hist.as_slice::<Vec3>().unwrap();
    let rows: Vec<Vec3> = (0..s.len())
        .filter(|k| !gone.contains(k))
        .flat_map(|k| wall[k * nw..(k + 1) * nw].iter().copied())
        .collect();
    b.contacts.pairs = pairs;
    b.contacts.hist = Histories::from_slice(&kept);
    b.contacts.wall_hist = Histories::from_slice(&rows);
    b.contacts.wall_count = nw;
    b.time = sys.time;
    b.step = sys.step;
    b
}

#[test]
fn removal_continues_as_an_assembly_built_without_the_spheres() {
    let law = law();
    let sys = settled(3000);
    // Remove two spheres that touch others and the floor (their pairs and rows must go, the
    // ones after them move down), given out of order and with a repeat.
    let pair_live = live(&sys.contacts.hist);
    let wall_live = live(&sys.contacts.wall_hist);
    let touching = |k: usize| {
        sys.contacts
            .pairs
            .iter()
            .zip(&pair_live)
            .any(|(p, &l)| l && (p[0] as usize == k || p[1] as usize == k))
            && wall_live[k]
    };
    let gone: Vec<usize> = (0..48).filter(|&k| touching(k)).take(2).collect();
    assert_eq!(gone.len(), 2, "no sphere touching the floor and a neighbour");
    let later_wall_live = wall_live[gone[1] + 1..].iter().filter(|&&l| l).count();
    let later_pairs_live = sys
        .contacts
        .pairs
        .iter()
        .zip(&pair_live)
        .filter(|(p, l)| **l && p[0] as usize > gone[1])
        .count();
    println!(
        "removing {gone:?}; live after them: {later_wall_live} floor contacts, {later_pairs_live} pairs"
    );
    assert!(later_wall_live > 0 && later_pairs_live > 0);

    let mut removed = sys.clone();
    removed
        .remove_spheres(&law, &[gone[1], gone[0], gone[1]])
        .unwrap();
    let mut built = rebuilt_without(&sys, &gone);
    assert_eq!(removed.spheres, built.spheres);
    // A checkpoint of the removed state resumes bit for bit.
    let json = serde_json::to_string(&removed).unwrap();
    let mut resumed: SphereSystem = serde_json::from_str(&json).unwrap();
    run(&mut removed, 2000);
    run(&mut built, 2000);
    run(&mut resumed, 2000);
    let moved = removed
        .spheres
        .pos
        .iter()
        .zip(&sys.spheres.pos)
        .any(|(a, b)| a != b);
    assert!(moved, "nothing moved");
    assert_eq!(
        removed.spheres, built.spheres,
        "removal differs from the rebuilt assembly"
    );
    assert_eq!(
        serde_json::to_string(&resumed).unwrap(),
        serde_json::to_string(&removed).unwrap()
    );
}

#[test]
fn removal_refuses_missing_spheres() {
    let mut sys = settled(0);
    assert_eq!(
        sys.remove_spheres(&law(), &[3, 48]),
        Err(SphereError::NoSuchSphere {
            sphere: 48,
            count: 48
        })
    );
    assert_eq!(sys.spheres.len(), 48);
}

/// A sphere appended while another one slides on the floor: the sliding sphere continues bit for
/// bit as in a run where the new sphere (far away, at rest, no gravity) was there from the
/// start. Before, the count change cleared every sphere-wall spring.
#[test]
fn appending_a_sphere_keeps_the_wall_springs() {
    let law = law();
    let mut p = params(&law);
    p.gravity = Vec3::ZERO;
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(20.0 * A, 20.0 * A, 20.0 * A), [false; 3]).unwrap();
    let mut one = SphereSystem::new(dom);
    one.walls
        .push(PlaneWall::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0)).unwrap());
    // Pressed 1e-3 A into the floor, sliding along x: a bounce with a tangential spring.
    one.add_sphere(
        Vec3::new(5.0 * A, 5.0 * A, 0.999 * A),
        Vec3::new(1e-3, 0.0, 0.0),
        Vec3::ZERO,
        A,
        RHO,
    )
    .unwrap();
    let far = Vec3::new(15.0 * A, 15.0 * A, 10.0 * A);
    let mut both = one.clone();
    both.add_sphere(far, Vec3::ZERO, Vec3::ZERO, A, RHO).unwrap();
    let (mut s1, mut s2) = (SphereStepper::new(), SphereStepper::new());
    for step in 0..400 {
        if step == 5 {
            let xi = one.contacts.wall_hist.as_slice::<Vec3>().unwrap()[0];
            println!("floor spring at the append: {xi:?}");
            assert!(xi.norm() > 0.0);
            one.add_sphere(far, Vec3::ZERO, Vec3::ZERO, A, RHO).unwrap();
        }
        s1.step(&p, &law, &mut one).unwrap();
        s2.step(&p, &law, &mut both).unwrap();
    }
    assert!(one.spheres.pos[0].z > A, "still in contact");
    assert_eq!(one.spheres, both.spheres);
}
