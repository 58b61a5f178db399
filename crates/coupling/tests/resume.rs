//! Checkpoint and resume of a coupled run (the state the scene layer serialises): N cycles
//! straight against k cycles, `Coupled::state`, serde (JSON with exact f64 round trip), a freshly
//! built run, `Coupled::restore`, N − k cycles: the same bits in the populations, the grains and
//! the held loads, for PSM (with the interior-liquid correction, whose previous motions are part
//! of the state) and for moving bounce-back. Also: equal per-node τ on the PSM lattice gives the
//! uniform run bit for bit.

use lbdem_core::units::lattice::{LatticeInput, LatticeUnits, TimeSpec};
use lbdem_coupling::units::CouplingUnits;
use lbdem_coupling::{BounceFluid, Coupled, CoupledState, Hydro, HydroState, Method, PsmFluid, PsmSettings};
use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::{Bodies, ClumpShape, Damping, Law, StepParams, System, Vec2};
use lbdem_lbm::{Collision, Domain, Limits};

/// Twelve grains (two of them two-circle clumps) moving in a periodic box, two about to touch.
fn build(method: Method, local_tau: bool) -> Coupled<f64> {
    let (n, dx) = (48usize, 1e-4);
    let l = n as f64 * dx;
    let tau = 0.8;
    let lattice =
        LatticeUnits::derive(&LatticeInput::new(dx, 1e-6, 1000.0, 2e-3, TimeSpec::Tau(tau))).unwrap();
    let ratio = 5;
    let dt_dem = lattice.dt / ratio as f64;
    let units = CouplingUnits::new(lattice, [0.0; 2], dt_dem).unwrap();
    let domain = Domain::periodic([n, n, 1]);
    let limits = Limits::default();
    let hydro = match method {
        Method::Psm => {
            let mut fluid = PsmFluid::<f64>::new(
                &domain,
                PsmSettings {
                    collision: Collision::Trt { tau, magic: 0.25 },
                    force: [1e-6, 0.0],
                    limits,
                },
            )
            .unwrap();
            if local_tau {
                fluid.set_local_tau(vec![tau; n * n]).unwrap();
            }
            Hydro::psm(fluid)
        }
        Method::BounceBack => Hydro::BounceBack(Box::new(
            BounceFluid::new(domain, tau, [1e-6, 0.0], limits).unwrap(),
        )),
    };
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
                        centre: Vec2::new(-1.5e-4, 0.0),
                        r: 2.6e-4,
                    },
                    lbdem_dem::Ball {
                        centre: Vec2::new(1.5e-4, 0.0),
                        r: 2.2e-4,
                    },
                ],
            }
        } else {
            ClumpShape::disk(3e-4)
        };
        let b = bodies.add(&shape, rho_p, at, 0.3 * k as f64).unwrap();
        bodies.vel[b] = Vec2::new(1e-3 * (1.7 * k as f64).cos(), 1e-3 * (2.3 * k as f64).sin());
        bodies.omega[b] = 2.0 * (k as f64 - 6.0);
    }
    bodies.pos[1] = bodies.pos[0] + Vec2::new(7.2e-4, 0.0);
    bodies.vel[0] = Vec2::new(3e-3, 0.0);
    bodies.vel[1] = Vec2::new(-3e-3, 0.0);
    let m = rho_p * std::f64::consts::PI * 9e-8;
    let k_n = 0.05 * m / (dt_dem * dt_dem);
    let law = Law::Linear(LinearSpringDashpot::new(k_n, 0.5 * k_n, Damping::Ratio(0.2), 0.5));
    let sys = System::new(bodies, lbdem_dem::Domain::periodic(Vec2::ZERO, Vec2::new(l, l)));
    let params = StepParams::new(dt_dem, 1e-4);
    let mut c = Coupled::new(hydro, sys, law.clone(), law, params, units, 0.8).unwrap();
    // a driver force on one grain (held with the fluid's load)
    c.user_force[3] = Vec2::new(1e-6, -2e-6);
    c.user_torque[3] = 1e-10;
    if method == Method::Psm {
        c = c.with_interior_liquid_correction().unwrap();
    }
    c
}

fn json<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap()
}

fn resume(method: Method) {
    let (steps, k) = (30, 11);
    let mut whole = build(method, false);
    for _ in 0..steps {
        whole.step().unwrap();
    }
    let mut first = build(method, false);
    for _ in 0..k {
        first.step().unwrap();
    }
    let text = json(&first.state());
    drop(first);
    let state: CoupledState<f64> = serde_json::from_str(&text).unwrap();
    let mut resumed = build(method, false);
    resumed.restore(state).unwrap();
    for _ in k..steps {
        resumed.step().unwrap();
    }
    let (a, b) = (whole.state(), resumed.state());
    assert!(json(&a.sys) == json(&b.sys), "{method:?}: grains differ");
    assert!(json(&a.hydro) == json(&b.hydro), "{method:?}: held loads differ");
    assert!(json(&a.fluid) == json(&b.fluid), "{method:?}: fluid differs");
    assert!(whole.n_contacts() > 0 || resumed.n_contacts() == whole.n_contacts());
    // the run did something: the grains moved and felt the fluid
    let moved = a.sys.bodies.pos[0] != build(method, false).sys.bodies.pos[0];
    assert!(moved && a.hydro.iter().any(|l| l.force[0] != 0.0), "{method:?}");
}

#[test]
fn psm_run_resumes_bit_for_bit() {
    resume(Method::Psm);
}

#[test]
fn bounce_back_run_resumes_bit_for_bit() {
    resume(Method::BounceBack);
}

#[test]
fn equal_local_tau_on_the_psm_lattice_is_the_uniform_run() {
    let mut uni = build(Method::Psm, false);
    let mut loc = build(Method::Psm, true);
    for _ in 0..10 {
        uni.step().unwrap();
        loc.step().unwrap();
    }
    let (HydroState::Psm(a), HydroState::Psm(b)) = (uni.fluid.state(), loc.fluid.state()) else {
        panic!("PSM expected")
    };
    assert!(json(&a.f) == json(&b.f) && json(&a.u) == json(&b.u));
    assert!(json(&uni.sys) == json(&loc.sys));
}

#[test]
fn psm_instability_names_step_node_and_mach() {
    // a strong driving force: the liquid runs past |u| = 0.4 and the run stops with the one
    // diagnosis of lbdem-lbm
    let dom = Domain::periodic([16, 16, 1]);
    let mut fluid = PsmFluid::<f64>::new(
        &dom,
        PsmSettings {
            collision: Collision::Bgk { tau: 0.8 },
            force: [2e-2, 0.0],
            limits: Limits::default(),
        },
    )
    .unwrap();
    let map = lbdem_coupling::solid_fraction::SolidMap {
        nx: 16,
        ny: 16,
        covers: Vec::new(),
        total: vec![0.0; 256],
    };
    let mut loads = Vec::new();
    let e = (0..1000)
        .find_map(|_| fluid.step(&map, &[], &mut loads).err())
        .expect("must stop");
    let msg = e.to_string();
    assert!(
        msg.contains("unstable at step") && msg.contains("node") && msg.contains("Mach"),
        "{msg}"
    );
    assert!(matches!(
        e,
        lbdem_coupling::CouplingError::Lbm(lbdem_lbm::LbmError::Unstable { .. })
    ));
}
