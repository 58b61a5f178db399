//! 3D grains in a free-surface liquid by moving bounce-back (`lbdem_coupling::surface_grains`,
//! Leonardi et al. 2014 Sect. 5.1, Eqs. 19-21; issue 20 item 3): the balances a coupled run must
//! keep (momentum to round-off in a closed periodic liquid, mass to round-off whatever crosses
//! the surface), Archimedes for a floating grain, and a bit-for-bit resume.

use lbdem_coupling::surface_grains::{SurfaceCoupled, SurfaceGrains, SurfaceScale};
use lbdem_dem::spheres::clump::DEFAULT_NODES;
use lbdem_dem::spheres::{
    BodyFrame, ClumpTemplate, Domain3, Elastic, HertzMindlinSpring, PlaneWall, SphereStepParams,
    SphereSystem, Surface,
};
use lbdem_dem::{Vec3, Vector};
use lbdem_lbm::free_surface::{FreeSurface, FreeSurfaceParams, FreeSurfaceStepper, INTERFACE, LIQUID};
use lbdem_lbm::{Bingham, Collision, D3Q19, Domain, Face, Lattice, Limits, Settings};
use nalgebra::UnitQuaternion;

/// Lattice units throughout: dx = dt = 1, liquid density 1.
const UNIT: SurfaceScale = SurfaceScale {
    dx: 1.0,
    dt: 1.0,
    rho: 1.0,
    origin: [0.0; 3],
};

/// A soft law: in lattice units the default Rayleigh fraction of a stiff one would refuse a unit
/// step (no contact happens in these tests but the step is checked against it).
fn law() -> HertzMindlinSpring {
    HertzMindlinSpring::uniform(
        Elastic {
            young: 1.0,
            poisson: 0.3,
        },
        Surface {
            mu: 0.3,
            restitution: 0.5,
        },
    )
}

fn coupled(
    n: [usize; 3],
    faces: [Face; 6],
    fill: impl Fn([usize; 3]) -> f64,
    g: f64,
    tau: f64,
    substeps: u32,
) -> SurfaceCoupled<HertzMindlinSpring> {
    let dom = Domain::new(n, faces);
    let h = (0..n[1]).filter(|&y| fill([0, y, 0]) > 0.0).count() as f64;
    let liquid = FreeSurface::<D3Q19>::new(dom, |p| {
        let rho = 1.0 + 3.0 * g * (h - 0.5 - p[1] as f64).max(0.0);
        (fill(p), rho, [0.0; 3])
    })
    .expect("valid liquid");
    let settings = Settings {
        collision: Collision::Bgk { tau },
        force: [0.0, -g, 0.0],
        limits: Limits::default(),
    };
    let stepper = FreeSurfaceStepper::new(&liquid, settings, FreeSurfaceParams::default()).expect("stepper");
    let grains = SurfaceGrains::new(liquid, stepper, UNIT).expect("grains");
    let periodic = [0, 1, 2].map(|a| faces[2 * a].is_periodic());
    let box3 = Domain3::new(
        Vec3::ZERO,
        Vec3::new(n[0] as f64, n[1] as f64, n[2] as f64),
        periodic,
    )
    .expect("box");
    let mut params = SphereStepParams::new(1.0 / substeps as f64, 0.5);
    params.gravity = Vec3::new(0.0, -g, 0.0);
    SurfaceCoupled::new(grains, SphereSystem::new(box3), law(), params, substeps).expect("coupled")
}

/// Σ_i f_i c_i over the liquid and interface nodes.
fn liquid_momentum(s: &FreeSurface<D3Q19>) -> [f64; 3] {
    let n = s.nodes();
    let mut p = [0.0; 3];
    for x in 0..n {
        if matches!(s.cell[x], LIQUID | INTERFACE) {
            for i in 1..D3Q19::Q {
                for (pa, &c) in p.iter_mut().zip(&D3Q19::C[i]) {
                    *pa += s.f[i * n + x] * c as f64;
                }
            }
        }
    }
    p
}

fn add(a: [f64; 3], b: Vec3) -> [f64; 3] {
    [a[0] + b.x, a[1] + b.y, a[2] + b.z]
}

#[test]
fn a_grain_moving_through_a_periodic_liquid_conserves_the_total_momentum_to_round_off() {
    // A spinning sphere (radius 3.6, twice the liquid's density) launched through a periodic box
    // full of liquid at rest, no gravity. Its nodes change at most steps: covered liquid gives
    // its momentum to the grain, the liquid left behind takes it back (Aidun et al. 1998), the
    // links carry Eq. 21. The DEM kicks with the load of the previous LBM step for half a
    // sub-step at each LBM step's start (velocity Verlet), so the books balance once that lag,
    // ½ dt_DEM (F_1 − F_M), is counted.
    // The same with a four-sphere pebble (the loads of its members act on the clump).
    // And with the `implicit` velocity update: the liquid bounces back with the velocity the
    // grain is loaded with, so the books still balance.
    let run = |conserve: bool, pebble: bool, implicit: bool| {
        let p = [Face::Periodic; 6];
        let mut c = coupled([20, 20, 20], p, |_| 1.0, 0.0, 0.8, 4);
        c.grains.conserve_momentum = conserve;
        c.grains.implicit = implicit;
        let (at, v, w) = (
            Vec3::new(7.3, 9.1, 10.4),
            Vec3::new(0.08, -0.015, 0.01),
            Vec3::new(0.002, 0.0, 0.006),
        );
        if pebble {
            let frame =
                BodyFrame::of(&ClumpTemplate::tetrahedron(2.2, 3.4), 2.0, DEFAULT_NODES).expect("pebble");
            let q = UnitQuaternion::from_euler_angles(0.3, 0.5, -0.2);
            c.sys.add_clump(&frame, at, q, v, w).expect("pebble");
        } else {
            c.sys.add_sphere(at, v, w, 3.6, 2.0).expect("sphere");
        }
        let load =
            |c: &SurfaceCoupled<HertzMindlinSpring>| c.grains.loads().iter().fold(Vec3::ZERO, |a, l| a + l.0);
        let total =
            |c: &SurfaceCoupled<HertzMindlinSpring>| add(liquid_momentum(&c.grains.liquid), c.sys.momentum());
        let (p0, m0) = (total(&c), c.grains.liquid.total_mass());
        let mut f1 = Vec3::ZERO;
        for step in 0..150 {
            c.step().expect("step");
            if step == 0 {
                f1 = load(&c);
            }
        }
        let lag = (f1 - load(&c)) * (0.5 * c.params.dt);
        let p1 = total(&c);
        let drift = [
            p1[0] - p0[0] - lag.x,
            p1[1] - p0[1] - lag.y,
            p1[2] - p0[2] - lag.z,
        ];
        let scale = c.sys.momentum().norm();
        let mass_drift = (c.grains.liquid.total_mass() - m0).abs() / m0;
        (
            drift.iter().map(|d| d.abs()).fold(0.0, f64::max) / scale,
            mass_drift,
            c,
        )
    };
    for (pebble, implicit) in [(false, false), (true, false), (false, true), (true, true)] {
        let (drift, mass, c) = run(true, pebble, implicit);
        let moved = if pebble {
            c.sys.clumps.pos[0].x
        } else {
            c.sys.spheres.pos[0].x
        } - 7.3;
        assert!(moved > 1.5, "the grain crossed nodes: moved {moved}");
        // measured 8.5e-14 (momentum, relative to the grain's: the sum over 8000 nodes) and 9e-16
        // (mass); the pebble 1.2e-13 and 1e-16; implicit 5.1e-14 and 1.5e-13 (pebble)
        assert!(drift < 2e-13, "momentum not conserved: relative drift {drift:e}");
        assert!(mass < 2e-15, "mass drift {mass:e}");
    }
    // the paper's choice (drop the covered liquid's momentum) loses a visible part: measured 0.21
    let (loose, _, _) = run(false, false, false);
    assert!(
        loose > 0.1,
        "without the exchange the drift {loose:e} would be invisible"
    );
}

/// Height of the liquid column at (x, z): Σ fill over y, from the bottom wall.
fn column(s: &FreeSurface<D3Q19>, x: usize, z: usize) -> f64 {
    (0..s.domain.n[1]).map(|y| s.fill(s.domain.index(x, y, z))).sum()
}

/// A sphere of radius `r` and density `density` (liquid 1) dropped from the gas into a pool of
/// `level` nodes in a box of `n` × `2n` × `n` (walls on x and y, periodic in z), after `steps`:
/// (the submerged fraction of its volume at rest, the lowest its centre went (node coordinates),
/// the worst relative drift of the liquid mass). The interface is checked closed at every step.
fn float(r: f64, density: f64, n: usize, level: usize, steps: usize) -> (f64, f64, f64) {
    let wall = Face::Wall { velocity: [0.0; 3] };
    let faces = [wall, wall, wall, wall, Face::Periodic, Face::Periodic];
    let g = 2e-4;
    let mut c = coupled(
        [n, 2 * n, n],
        faces,
        |p| if p[1] < level { 1.0 } else { 0.0 },
        g,
        0.9,
        4,
    );
    let mid = n as f64 / 2.0;
    c.sys
        .add_sphere(
            Vec3::new(mid, level as f64 + r + 1.5, mid),
            Vec3::ZERO,
            Vec3::ZERO,
            r,
            density,
        )
        .expect("sphere");
    let m0 = c.grains.liquid.total_mass();
    let (mut lowest, mut worst) = (f64::MAX, 0.0f64);
    for _ in 0..steps {
        c.step().expect("step");
        lowest = lowest.min(c.sys.spheres.pos[0].y - 0.5);
        worst = worst.max((c.grains.liquid.total_mass() - m0).abs() / m0);
        assert!(
            c.grains.liquid.open_interface().is_none(),
            "a liquid node touches the gas"
        );
    }
    // the surface away from the sphere and the walls (mean column height), as a y coordinate of
    // node centres: the interface node's centre is where the pressure is the gas's
    let s = &c.grains.liquid;
    let far: Vec<f64> = (3..n - 3)
        .flat_map(|x| (3..n - 3).map(move |z| (x, z)))
        .filter(|&(x, z)| ((x as f64 + 0.5 - mid).powi(2) + (z as f64 + 0.5 - mid).powi(2)).sqrt() > r + 2.0)
        .map(|(x, z)| column(s, x, z))
        .collect();
    let surface = far.iter().sum::<f64>() / far.len() as f64 - 0.5;
    let centre = c.sys.spheres.pos[0].y - 0.5;
    let h = r - (centre - surface);
    let submerged = h * h * (3.0 * r - h) / (4.0 * r * r * r);
    (submerged, lowest, worst)
}

#[test]
fn a_grain_dropped_into_the_liquid_floats_at_archimedes_depth_and_the_mass_is_kept() {
    // Half the liquid's density: at rest half its volume is under the surface (Archimedes). It
    // starts in the gas, crosses the surface and settles.
    let (level, r) = (14, 4.5);
    let (submerged, lowest, drift) = float(r, 0.5, 22, level, 6000);
    assert!(
        lowest - r < level as f64 - 0.5,
        "the sphere never entered the liquid: lowest centre {lowest}"
    );
    // measured 2.6e-14
    assert!(drift < 5e-14, "mass drift {drift:e}");
    // measured 0.406 at 4.5 nodes of radius (the staircase sphere; 0.4973 at 7.5, the ignored
    // test below)
    assert!((submerged - 0.5).abs() < 0.15, "submerged fraction {submerged}");
}

#[test]
#[ignore = "finer floating grain (about 45 s): cargo test -p lbdem-coupling --test coupling -- --ignored surface_grains::"]
fn a_finer_floating_grain() {
    let (submerged, _, drift) = float(7.5, 0.5, 34, 22, 9000);
    // measured 1.5e-13 (46 000 nodes) and 0.4973
    assert!(drift < 3e-13, "mass drift {drift:e}");
    assert!((submerged - 0.5).abs() < 0.005, "submerged fraction {submerged}");
}

#[test]
fn a_coupled_run_resumes_bit_for_bit() {
    // A sphere falling through the surface into a pool: run 40 LBM steps, keep the states, run
    // 40 more; a run rebuilt from the kept states (through serde, as a checkpoint) gives the same
    // bits.
    let wall = Face::Wall { velocity: [0.0; 3] };
    let faces = [wall, wall, wall, wall, Face::Periodic, Face::Periodic];
    let make = || {
        let mut c = coupled(
            [14, 20, 14],
            faces,
            |p| if p[1] < 9 { 1.0 } else { 0.0 },
            5e-4,
            0.8,
            3,
        );
        c.sys
            .add_sphere(
                Vec3::new(7.2, 12.5, 6.1),
                Vec3::new(0.0, -0.05, 0.0),
                Vec3::new(0.0, 0.0, 0.01),
                3.0,
                2.5,
            )
            .expect("sphere");
        c
    };
    let mut a = make();
    for _ in 0..40 {
        a.step().expect("step");
    }
    let json = serde_json::to_string(&(a.grains.state(), &a.sys)).expect("serialise");
    for _ in 0..40 {
        a.step().expect("step");
    }
    let (state, sys): (lbdem_coupling::surface_grains::SurfaceGrainsState, SphereSystem) =
        serde_json::from_str(&json).expect("read back");
    let fresh = make();
    let stepper = FreeSurfaceStepper::new(
        &state.liquid,
        *fresh.grains.stepper().settings(),
        FreeSurfaceParams::default(),
    )
    .expect("stepper");
    let grains = SurfaceGrains::restore(state, stepper, UNIT).expect("restore");
    let mut b = SurfaceCoupled::new(grains, sys, law(), fresh.params, fresh.substeps).expect("coupled");
    for _ in 0..40 {
        b.step().expect("step");
    }
    assert_eq!(a.sys.spheres.pos, b.sys.spheres.pos);
    assert_eq!(a.sys.spheres.vel, b.sys.spheres.vel);
    assert_eq!(a.grains.liquid.f, b.grains.liquid.f);
    assert_eq!(a.grains.liquid.mass, b.grains.liquid.mass);
    assert_eq!(a.grains.liquid.cell, b.grains.liquid.cell);
    assert!(
        a.sys.spheres.pos[0].y - 3.0 < 8.5,
        "the sphere went under: {:?}",
        a.sys.spheres.pos[0]
    );
}

/// ten Cate et al. (2002) Table 1 (as the project's reference list quotes it): liquid density (kg/m³),
/// dynamic viscosity (Pa s) and the measured terminal velocity (m/s) of cases E1-E4.
const TEN_CATE: [(f64, f64, f64); 4] = [
    (970.0, 0.373, 0.038),
    (965.0, 0.212, 0.060),
    (962.0, 0.113, 0.091),
    (960.0, 0.058, 0.128),
];

/// The settling sphere of ten Cate et al. (2002), case `case` (0-3 for E1-E4), with `cells`
/// lattice spacings across the diameter: nylon sphere d = 15 mm, ρ_p = 1120 kg/m³, in a closed
/// box 100 × 160 × 100 mm (y up) full of liquid, released at rest with its centre 127.5 mm above
/// the bottom. BGK (TRT with Λ = 3/16 went unstable at E3's τ = 0.6 within 200 steps, BGK did
/// not), the published terminal velocity `u_lattice` in lattice units.
/// Gravity acts on the sphere as its buoyant weight (1 − ρ_f/ρ_p) g and not on the liquid: in a
/// closed full box the liquid's weight only adds the hydrostatic pressure, whose push on the
/// sphere is its buoyancy, and at this Δt the hydrostatic density ramp (3 g h in lattice units)
/// would be several times the density itself. The floating-grain test above checks buoyancy from
/// the liquid's pressure.
/// Runs until the sphere is one diameter above the bottom or 2 s have passed; returns the
/// largest settling speed (m/s).
fn ten_cate(case: usize, cells: f64, u_lattice: f64) -> f64 {
    let (rho_f, mu, u_ref) = TEN_CATE[case];
    let d = 0.015;
    let dx = d / cells;
    let dt = u_lattice * dx / u_ref;
    let nu = mu / rho_f * dt / (dx * dx);
    let tau = 0.5 + 3.0 * nu;
    let n = [
        (0.1 / dx).round() as usize,
        (0.16 / dx).round() as usize,
        (0.1 / dx).round() as usize,
    ];
    let wall = Face::Wall { velocity: [0.0; 3] };
    let dom = Domain::new(n, [wall; 6]);
    let liquid = FreeSurface::<D3Q19>::new(dom, |_| (1.0, 1.0, [0.0; 3])).expect("liquid");
    let settings = Settings {
        collision: Collision::Bgk { tau },
        force: [0.0; 3],
        limits: Limits::default(),
    };
    let stepper = FreeSurfaceStepper::new(&liquid, settings, FreeSurfaceParams::default()).expect("stepper");
    let scale = SurfaceScale {
        dx,
        dt,
        rho: rho_f,
        origin: [0.0; 3],
    };
    let grains = SurfaceGrains::new(liquid, stepper, scale).expect("grains");
    let size = Vec3::new(n[0] as f64 * dx, n[1] as f64 * dx, n[2] as f64 * dx);
    let mut sys = SphereSystem::new(Domain3::new(Vec3::ZERO, size, [false; 3]).expect("box"));
    sys.add_sphere(
        Vec3::new(size.x / 2.0, 0.1275, size.z / 2.0),
        Vec3::ZERO,
        Vec3::ZERO,
        d / 2.0,
        1120.0,
    )
    .expect("sphere");
    // soft: no contact happens before the run stops; the step is checked against it
    let law = HertzMindlinSpring::uniform(
        Elastic {
            young: 1e6,
            poisson: 0.3,
        },
        Surface {
            mu: 0.3,
            restitution: 0.5,
        },
    );
    let substeps = 20;
    let mut params = SphereStepParams::new(dt / substeps as f64, 0.1 * d);
    params.gravity = Vec3::new(0.0, -9.81 * (1.0 - rho_f / 1120.0), 0.0);
    let mut c = SurfaceCoupled::new(grains, sys, law, params, substeps).expect("coupled");
    let mut top = 0.0f64;
    while c.sys.spheres.pos[0].y > 1.5 * d && c.sys.time < 2.0 {
        c.step().expect("step");
        top = top.max(-c.sys.spheres.vel[0].y);
    }
    top
}

/// Relative error of the largest settling speed against ten Cate's terminal velocity.
fn ten_cate_error(case: usize, cells: f64, u_lattice: f64) -> f64 {
    ten_cate(case, cells, u_lattice) / TEN_CATE[case].2 - 1.0
}

#[test]
fn a_settling_sphere_reaches_ten_cates_terminal_velocity() {
    // E1 and E2 at 6 cells across the diameter (about 13 s): measured +1.8 % and −1.7 %.
    for case in [0, 1] {
        let err = ten_cate_error(case, 6.0, 0.05);
        assert!(err.abs() < 0.035, "E{}: {:+.1} %", case + 1, 100.0 * err);
    }
}

#[test]
#[ignore = "E1-E4 at 8 cells (about 3 min): cargo test -p lbdem-coupling --test coupling -- --ignored surface_grains::ten_cates"]
fn ten_cates_four_cases_at_eight_cells() {
    // measured +2.1 %, −1.2 %, −4.7 %, −7.0 % (E4 at lattice velocity 0.1: τ 0.576)
    for (case, u, tol) in [(0, 0.05, 0.04), (1, 0.05, 0.025), (2, 0.05, 0.09), (3, 0.1, 0.12)] {
        let err = ten_cate_error(case, 8.0, u);
        assert!(err.abs() < tol, "E{}: {:+.1} %", case + 1, 100.0 * err);
    }
}

#[test]
fn a_few_pebbles_ride_a_spreading_bingham_paste() {
    // Leonardi et al. 2014 Sect. 6 in miniature (issue 20 item 7): a column of Bingham paste
    // (μ_pl 0.1, σ_y 5e-5, τ clamped to [0.55, 3.5], lattice units) 14 × 16 nodes against the
    // left wall of a 48 × 24 box, periodic in z (12 nodes), with three four-sphere pebbles
    // (spheres of radius 2.2 in a tetrahedron of edge 3.4, twice the paste's density) inside,
    // released at rest under g = 1e-4. The paste slumps and spreads, carrying the pebbles. (With
    // spheres of radius 1.6 at 1.5 times the density a pebble rocked from step to step until the
    // liquid beside it passed the Mach limit at step 1489: docs/free_surface.md, "Where it
    // failed".)
    let wall = Face::Wall { velocity: [0.0; 3] };
    let faces = [wall, wall, wall, wall, Face::Periodic, Face::Periodic];
    let (n, width, height, g) = ([48, 24, 12], 14, 16, 1e-4);
    let mut c = coupled(
        n,
        faces,
        |p| if p[0] < width && p[1] < height { 1.0 } else { 0.0 },
        g,
        0.8,
        4,
    );
    c.grains
        .stepper_mut()
        .set_bingham(Some(Bingham {
            mu_pl: 0.1,
            yield_stress: 5e-5,
            rho: 1.0,
            tau_min: 0.55,
            tau_max: 3.5,
            smagorinsky: 0.0,
        }))
        .expect("set Bingham");
    let frame = BodyFrame::of(&ClumpTemplate::tetrahedron(2.2, 3.4), 2.0, DEFAULT_NODES).expect("pebble");
    for (k, p) in [[5.0, 5.0, 3.0], [10.0, 5.5, 9.0], [7.0, 12.0, 6.0]]
        .iter()
        .enumerate()
    {
        let q = UnitQuaternion::from_euler_angles(0.3 * k as f64, 0.5, -0.2 * k as f64);
        c.sys
            .add_clump(&frame, Vec3::new(p[0], p[1], p[2]), q, Vec3::ZERO, Vec3::ZERO)
            .expect("pebble");
    }
    let walls = [
        ([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ([48.0, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 24.0, 0.0], [0.0, -1.0, 0.0]),
    ];
    for (p, nrm) in walls {
        c.sys.walls.push(
            PlaneWall::new(Vec3::new(p[0], p[1], p[2]), Vec3::new(nrm[0], nrm[1], nrm[2])).expect("wall"),
        );
    }
    let x0: Vec<f64> = c.sys.clumps.pos.iter().map(|p| p.x).collect();
    let m0 = c.grains.liquid.total_mass();
    let mut worst = 0.0f64;
    for _ in 0..3000 {
        c.step().expect("step");
        worst = worst.max((c.grains.liquid.total_mass() - m0).abs() / m0);
        assert!(
            c.grains.liquid.open_interface().is_none(),
            "a liquid node touches the gas"
        );
    }
    let s = &c.grains.liquid;
    let front = (0..n[0])
        .rev()
        .find(|&x| (0..n[2]).any(|z| s.fill(s.domain.index(x, 0, z)) >= 0.5))
        .map_or(0, |x| x + 1);
    let moved: Vec<f64> = c.sys.clumps.pos.iter().zip(&x0).map(|(p, x)| p.x - x).collect();
    let speed = c.sys.clumps.vel.iter().map(|v| v.norm()).fold(0.0, f64::max);
    // measured: mass 7.6e-15, front 17 (from 14), pebbles carried 1.6, 7.6, 6.3 nodes
    assert!(worst < 2e-14, "mass drift {worst:e}");
    assert!(front > width + 2, "the paste did not spread: front at {front}");
    assert!(
        moved.iter().all(|&m| m > 1.0),
        "the paste did not carry the pebbles: {moved:?}"
    );
    assert!(speed < 0.05, "a pebble is racing: {speed}");
}

/// A four-sphere pebble (spheres of radius `r` nodes, centres half a radius apart, density `rho`
/// times the liquid's) released at rest in a 24 × 40 × 24 pool (walls on x and y, periodic in z,
/// g = 1e-4) at relaxation time `tau`, for `steps` LBM steps: the step it blew up at, if it did,
/// and its settling speed at the end.
fn pebble_in_a_pool(r: f64, rho: f64, tau: f64, implicit: bool, steps: usize) -> (Option<usize>, f64) {
    let wall = Face::Wall { velocity: [0.0; 3] };
    let faces = [wall, wall, wall, wall, Face::Periodic, Face::Periodic];
    let mut c = coupled(
        [24, 40, 24],
        faces,
        |p| if p[1] < 36 { 1.0 } else { 0.0 },
        1e-4,
        tau,
        4,
    );
    c.grains.implicit = implicit;
    let frame = BodyFrame::of(&ClumpTemplate::tetrahedron(r, 0.5 * r), rho, DEFAULT_NODES).expect("pebble");
    let q = UnitQuaternion::from_euler_angles(0.3, 0.5, -0.2);
    c.sys
        .add_clump(&frame, Vec3::new(12.2, 28.3, 11.7), q, Vec3::ZERO, Vec3::ZERO)
        .expect("pebble");
    for k in 0..steps {
        if c.step().is_err() {
            return (Some(k), f64::NAN);
        }
    }
    (None, -c.sys.clumps.vel[0].y)
}

#[test]
fn the_implicit_velocity_update_keeps_a_small_light_pebble_stable() {
    // Spheres of 1.6 nodes at 1.5 times the liquid's density, τ = 0.52: the explicit coupling
    // blows up (the liquid beside the pebble past the Mach limit at step 64, measured); the
    // implicit update runs the 400 steps. At τ = 0.8, 2-node spheres, where both are stable,
    // they agree on the settling speed (2.554e-4 and 2.531e-4 at 200 steps, measured: 0.9 %).
    let (blew, _) = pebble_in_a_pool(1.6, 1.5, 0.52, false, 400);
    assert!(blew.is_some_and(|k| k > 10), "explicit: {blew:?}");
    let (blew, _) = pebble_in_a_pool(1.6, 1.5, 0.52, true, 400);
    assert_eq!(blew, None, "implicit blew up");
    let (a, explicit) = pebble_in_a_pool(2.0, 1.5, 0.8, false, 200);
    let (b, implicit) = pebble_in_a_pool(2.0, 1.5, 0.8, true, 200);
    assert!(a.is_none() && b.is_none());
    assert!(
        (implicit / explicit - 1.0).abs() < 0.02,
        "settling {implicit:e} against {explicit:e}"
    );
}
