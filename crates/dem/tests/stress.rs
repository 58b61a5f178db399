//! The per-contact forces of the 3D sphere engine and the dipole stress σ = −(1/V) Σ r ⊗ F
//! (Ness et al. 2017, Eq. 7; `lbdem_dem::spheres::{ContactForce, dipole_stress}`): a statically
//! compressed lattice between two walls, periodic across them, gives the same σ_zz as the load on
//! the walls and the closed-form σ_xx of its pairs; the lubrication part is reported apart.
//!
//! Run: `cargo test -p lbdem-dem --test dem stress:: -- --nocapture`.

use lbdem_dem::spheres::{
    Domain3, LinearSpring, Lubricated, Lubrication, Partner, PlaneWall, SphereLaw, SphereStepParams,
    SphereStepper, SphereSystem, dipole_stress, sphere_dipoles,
};
use lbdem_dem::{Vec3, Vector};

const A: f64 = 1e-3;
const RHO: f64 = 1000.0;

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// 3 × 3 × 3 spheres of radius A on a cubic lattice of spacing s = 2A − δ, periodic in x and y
/// (box 3 s), between a floor and a ceiling that overlap the outer layers by δ as well: every
/// sphere is pressed equally from both sides on every axis, a static state. The stress is read
/// from the records of one step and compared with (a) the wall route: in equilibrium the sum
/// over all records Σ r ⊗ F reduces to Σ_walls x_c ⊗ F_c, so σ_zz = load × (z_c,top − z_c,bottom)
/// / V with the contact points δ/2 beyond the walls; (b) the lattice by hand: σ_xx = σ_zz =
/// (27 pairs per axis) s k_n δ / V; (c) no shear stress.
#[test]
fn dipole_stress_of_a_compressed_lattice_equals_the_wall_load() {
    let k_n = 200.0;
    let law = LinearSpring::ness(k_n, 0.5, 0.3);
    let delta = 1e-3 * A;
    let s = 2.0 * A - delta;
    let l = 3.0 * s;
    let z1 = 2.0 * A;
    let (z_b, z_t) = (z1 - (A - delta), z1 + 2.0 * s + (A - delta));
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(l, l, z_t + 2.0 * A), [true, true, false]).unwrap();
    let mut sys = SphereSystem::new(dom);
    sys.walls
        .push(PlaneWall::new(Vec3::new(0.0, 0.0, z_b), Vec3::new(0.0, 0.0, 1.0)).unwrap());
    sys.walls
        .push(PlaneWall::new(Vec3::new(0.0, 0.0, z_t), Vec3::new(0.0, 0.0, -1.0)).unwrap());
    for k in 0..27 {
        let (i, j, m) = (k % 3, (k / 3) % 3, k / 9);
        let c = |a: usize| (a as f64 + 0.5) * s;
        let p = Vec3::new(c(i), c(j), z1 + m as f64 * s);
        sys.add_sphere(p, Vec3::ZERO, Vec3::ZERO, A, RHO).unwrap();
    }
    let m = sys.spheres.mass[0];
    let p = SphereStepParams::new(law.max_time_step(A, m).dt, 0.1 * A);
    // Recording is off by default: a step leaves no records, and costs none.
    let mut off = SphereStepper::new();
    let mut copy = sys.clone();
    off.step(&p, &law, &mut copy).unwrap();
    assert!(off.contacts().is_empty());
    let mut st = SphereStepper::new();
    st.record_contacts(true);
    assert!(st.contacts().is_empty());
    st.step(&p, &law, &mut sys).unwrap();
    // Recording changes no number of the run.
    assert_eq!(copy.spheres.force, sys.spheres.force);
    let rec = st.contacts();
    // 3 pairs per sphere (x, y, z neighbours; z only between layers: 18), 9 spheres on each wall.
    let pairs = rec.iter().filter(|c| matches!(c.j, Partner::Sphere(_))).count();
    assert_eq!((pairs, rec.len() - pairs), (27 + 27 + 18, 18));
    let residual = sys.spheres.force.iter().map(|f| f.norm()).fold(0.0, f64::max);
    let load: f64 = rec
        .iter()
        .filter(|c| c.j == Partner::Wall(1))
        .map(|c| -c.force.z)
        .sum();
    let v = l * l * (z_t - z_b);
    let sigma = dipole_stress(rec, v, false);
    let wall_route = load * (z_t - z_b + delta) / v;
    let by_hand = 27.0 * s * k_n * delta / v;
    println!(
        "largest net force {residual:.1e} N (contact force {:.1e} N); sigma_zz {:.12e} Pa, wall \
         route {wall_route:.12e} ({:.1e}); sigma_xx {:.12e}, sigma_yy {:.12e}, by hand \
         {by_hand:.12e} ({:.1e}); shear {:.1e}",
        k_n * delta,
        sigma[2][2],
        rel(sigma[2][2], wall_route),
        sigma[0][0],
        sigma[1][1],
        rel(sigma[0][0], by_hand)
            .max(rel(sigma[1][1], by_hand))
            .max(rel(sigma[2][2], by_hand)),
        sigma[0][1].abs().max(sigma[0][2].abs()).max(sigma[1][2].abs())
    );
    // Measured: the wall route to 3.5e-14 (the net force left on a sphere is 1.3e-16 N of the
    // 2e-4 N contact force: the overlaps are differences of rounded positions), the lattice by
    // hand to 9.7e-14 at worst over the three axes (δ = 2A − s is such a difference too), shear
    // exactly 0.
    assert!(rel(sigma[2][2], wall_route) < 7e-14);
    for (a, row) in sigma.iter().enumerate() {
        assert!(rel(row[a], by_hand) < 2e-13, "{a}: {}", row[a]);
    }
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        assert!(sigma[a][b].abs() < 1e-12 * by_hand && sigma[b][a].abs() < 1e-12 * by_hand);
    }
    // A contact law alone: no hydrodynamic part.
    assert_eq!(dipole_stress(rec, v, true), [[0.0; 3]; 3]);
    // Each sphere's share (what a coarse-graining bin sums): the shares add up to V σ, and
    // every sphere of this lattice carries the same σ_xx share, s k_n δ (its two x pairs, half
    // each), whether it touches a wall or not.
    let shares = sphere_dipoles(rec, &sys.spheres.frozen, &sys.spheres.radius);
    for (a, row) in sigma.iter().enumerate() {
        for (b, sab) in row.iter().enumerate() {
            let sum: f64 = shares.iter().map(|w| w.total[a][b]).sum();
            let scale = by_hand * v;
            // Measured: 0 (a) off the diagonal, ~1e-16 relative on it (summation order).
            assert!(
                (sum - sab * v).abs() < 1e-13 * scale,
                "{a}{b}: {sum} vs {}",
                sab * v
            );
        }
    }
    for w in &shares {
        assert!(rel(w.total[0][0], s * k_n * delta) < 1e-12, "{}", w.total[0][0]);
        assert_eq!(w.hydro, [[0.0; 3]; 3]);
    }
    // A record naming a sphere outside the table is skipped, not a panic.
    assert_eq!(sphere_dipoles(rec, &[false], &[A]).len(), 1);
}

/// Two spheres across a lubrication gap: the one record carries all its force as hydrodynamic,
/// contact point halfway across the gap, branch x_j − x_i through the periodic boundary.
#[test]
fn lubrication_force_is_reported_as_hydrodynamic() {
    let law = Lubricated {
        lubrication: Lubrication::ness(1e-3),
        contact: LinearSpring::ness(50.0, 0.5, 0.1),
    };
    let l = 10.0 * A;
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(l, l, l), [true; 3]).unwrap();
    let mut sys = SphereSystem::new(dom);
    let h = 0.02 * A;
    // Sphere 0 near the top of x, sphere 1 just across the periodic face, approaching.
    sys.add_sphere(
        Vec3::new(l - A - 0.5 * h, l / 2.0, l / 2.0),
        Vec3::new(1e-3, 0.0, 0.0),
        Vec3::ZERO,
        A,
        RHO,
    )
    .unwrap();
    sys.add_sphere(
        Vec3::new(A + 0.5 * h, l / 2.0, l / 2.0),
        Vec3::ZERO,
        Vec3::ZERO,
        A,
        RHO,
    )
    .unwrap();
    let m = sys.spheres.mass[0];
    let dt = law.max_time_step(A, m).dt;
    let mut st = SphereStepper::new();
    st.record_contacts(true);
    st.step(&SphereStepParams::new(dt, 0.1 * A), &law, &mut sys)
        .unwrap();
    let rec = st.contacts();
    assert_eq!(rec.len(), 1);
    let c = rec[0];
    assert_eq!(c.j, Partner::Sphere(1));
    assert!(c.force.x < 0.0 && c.force == c.hydro, "{c:?}");
    let branch = sys.domain.min_image(sys.spheres.pos[1] - sys.spheres.pos[0]);
    assert_eq!(c.branch, branch);
    assert!(branch.x > 0.0 && branch.x < 2.1 * A);
    // The point lies midway across the gap: A + h/2 from the centre of i.
    let gap = branch.x - 2.0 * A;
    let arm = c.point.x - sys.spheres.pos[0].x;
    // Measured: 8e-16.
    assert!(rel(arm, A + 0.5 * gap) < 2e-15);
    let sigma = dipole_stress(rec, l * l * l, true);
    assert_eq!(sigma, dipole_stress(rec, l * l * l, false));
    // The squeeze film resists the approach as a contact would: compressive (positive).
    assert!(sigma[0][0] > 0.0, "{sigma:?}");
}

/// A step that fails part way (here the cell list refusing a sphere that drifted out of the box
/// on an open axis) leaves no records behind: the last ones are not this state's.
#[test]
fn a_failed_step_leaves_no_records() {
    let law = LinearSpring::ness(200.0, 0.5, 0.3);
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(0.01, 0.01, 0.01), [false; 3]).unwrap();
    let mut sys = SphereSystem::new(dom);
    let c = Vec3::new(0.005, 0.005, 0.005);
    sys.add_sphere(c, Vec3::ZERO, Vec3::ZERO, A, RHO).unwrap();
    sys.add_sphere(c + Vec3::new(1.9 * A, 0.0, 0.0), Vec3::ZERO, Vec3::ZERO, A, RHO)
        .unwrap();
    let m = sys.spheres.mass[0];
    let p = SphereStepParams::new(law.max_time_step(A, m).dt, 0.1 * A);
    let mut st = SphereStepper::new();
    st.record_contacts(true);
    st.step(&p, &law, &mut sys).unwrap();
    assert_eq!(st.contacts().len(), 1);
    sys.spheres.vel[0] = Vec3::new(0.0, 0.0, 1.0 / p.dt);
    assert!(st.step(&p, &law, &mut sys).is_err());
    assert!(st.contacts().is_empty());
}
