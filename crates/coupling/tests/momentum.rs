//! Fluid plus grains in a closed periodic box: the PSM solid term (Su Eq. 11) moves momentum
//! between the liquid and the grains and the contacts move it between grains, so the total
//! must stay what it was to round-off (Noble & Torczynski 1998 build the force of Eq. 14 as
//! the exact reaction of the momentum the solid term puts into the liquid), and the liquid's
//! mass must not change at all. A lost half-kick of the held force, a sign error in Eq. 14 or
//! an impulse held for the wrong number of sub-steps would each show at the 1e-3 level.

use lbdem_core::units::lattice::{LatticeInput, LatticeUnits, TimeSpec};
use lbdem_coupling::units::CouplingUnits;
use lbdem_coupling::{Coupled, Hydro, PsmFluid, PsmSettings};
use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::{Bodies, ClumpShape, Damping, Law, StepParams, System, Vec2, Vector};
use lbdem_lbm::{Domain, Limits};

fn build() -> Coupled<f64> {
    let (n, dx) = (64usize, 1e-4);
    let l = n as f64 * dx;
    let lattice =
        LatticeUnits::derive(&LatticeInput::new(dx, 1e-6, 1000.0, 2e-3, TimeSpec::Tau(1.0))).unwrap();
    let ratio = 10;
    let dt_dem = lattice.dt / ratio as f64;
    let units = CouplingUnits::new(lattice, [0.0; 2], dt_dem).unwrap();
    let fluid = PsmFluid::<f64>::new(
        &Domain::periodic([n, n, 1]),
        PsmSettings {
            collision: lbdem_lbm::Collision::Bgk { tau: 1.0 },
            force: [0.0; 2],
            limits: Limits::default(),
        },
    )
    .unwrap();
    // Twelve grains on a jittered grid, two of them two-circle clumps, with fixed "random" velocities.
    let mut bodies = Bodies::new();
    let rho_p = 1500.0;
    for k in 0..12 {
        let (i, j) = (k % 4, k / 4);
        let at = Vec2::new(
            (i as f64 + 0.5 + 0.1 * (k as f64).sin()) * l / 4.0,
            (j as f64 + 0.5) * l / 3.0,
        );
        let shape = if k % 5 == 0 {
            ClumpShape {
                balls: vec![
                    lbdem_dem::Ball {
                        centre: Vec2::new(-2e-4, 0.0),
                        r: 3.5e-4,
                    },
                    lbdem_dem::Ball {
                        centre: Vec2::new(2e-4, 0.0),
                        r: 3.0e-4,
                    },
                ],
            }
        } else {
            ClumpShape::disk(4e-4)
        };
        let b = bodies.add(&shape, rho_p, at, 0.3 * k as f64).unwrap();
        bodies.vel[b] = Vec2::new(1e-3 * (1.7 * k as f64).cos(), 1e-3 * (2.3 * k as f64).sin());
        bodies.omega[b] = 2.0 * (k as f64 - 6.0);
    }
    // Grains 0 (a clump reaching 0.55 mm along x) and 1 start 0.03 mm apart and closing.
    bodies.pos[1] = bodies.pos[0] + Vec2::new(9.8e-4, 0.0);
    bodies.vel[0] = Vec2::new(2e-3, 0.0);
    bodies.vel[1] = Vec2::new(-2e-3, 0.0);
    let m = rho_p * std::f64::consts::PI * 16e-8;
    let k_n = 0.05 * m / (dt_dem * dt_dem);
    let law = Law::Linear(LinearSpringDashpot::new(k_n, 0.5 * k_n, Damping::Ratio(0.2), 0.5));
    let sys = System::new(bodies, lbdem_dem::Domain::periodic(Vec2::ZERO, Vec2::new(l, l)));
    let params = StepParams::new(dt_dem, 1e-4);
    Coupled::new(Hydro::psm(fluid), sys, law.clone(), law, params, units, 0.8).unwrap()
}

#[test]
fn momentum_and_mass_conserved_in_periodic_box() {
    let mut run = build();
    let p0 = run.momentum();
    let (m0, _) = run.fluid.mass_momentum();
    let scale: f64 = (0..run.sys.bodies.len())
        .map(|k| run.sys.bodies.mass[k] * run.sys.bodies.vel[k].norm())
        .sum();
    let mut worst: f64 = 0.0;
    let mut touched = 0;
    for _ in 0..3000 {
        run.step().unwrap();
        touched = touched.max(run.n_contacts());
        let p = run.momentum();
        worst = worst.max((p[0] - p0[0]).abs().max((p[1] - p0[1]).abs()) / scale);
    }
    let (m1, _) = run.fluid.mass_momentum();
    // The grains must really have exchanged momentum with the liquid and with each other.
    let (_, j) = run.fluid.mass_momentum();
    let fluid_share = run.units.momentum_to_si(j);
    eprintln!(
        "worst |P - P0| / sum |m v| = {worst:.2e}; liquid momentum now {fluid_share:?} (grains' start sum {scale:.3e}); \
         mass change {:.2e}; most contacts {touched}",
        (m1 - m0) / m0,
    );
    assert!(touched > 0, "the contact path was not exercised");
    assert!(fluid_share[0].abs().max(fluid_share[1].abs()) > 1e-3 * scale);
    // Measured 2.59e-13 (round-off; identical for 1 and 2 threads).
    assert!(worst < 5e-13, "momentum drift {worst}");
    // Eq. 9-11 conserve mass exactly; measured -6.07e-13 of round-off over the run.
    assert!(((m1 - m0) / m0).abs() < 1.2e-12);
}

#[test]
fn identical_for_one_and_two_threads() {
    let go = |t: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap();
        pool.install(|| {
            let mut run = build();
            for _ in 0..200 {
                run.step().unwrap();
            }
            (
                run.sys.bodies.pos.clone(),
                run.sys.bodies.vel.clone(),
                run.fluid.mass_momentum(),
            )
        })
    };
    assert_eq!(go(1), go(2));
}
