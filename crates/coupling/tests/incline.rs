//! Leonardi et al. (2014) Sect. 6, the concrete incline (`lbdem_coupling::cases::incline`, issue
//! 20 item 4): the set-up against the paper's numbers, and where it fails today (a coarse paste
//! front at the Mach limit; pebbles of about a node rocking), each provoked by a run.

use lbdem_coupling::CouplingError;
use lbdem_coupling::cases::incline::{Incline, InclineSpec, place_pebbles};
use lbdem_dem::spheres::{Domain3, SphereSystem};
use lbdem_dem::{Vec3, Vector};
use lbdem_lbm::LbmError;
use lbdem_lbm::free_surface::{GRAIN, INTERFACE};

#[test]
fn the_incline_in_lattice_units_is_the_papers() {
    // Sect. 6: "350 × 250 × 80 nodes", "μ_pl^LBM = 6.25e-4", "τ_y^LBM = 7.75e-6",
    // "||g^LBM|| = 4.41e-6" (the paper rounds 4.4145e-6).
    let spec = InclineSpec::leonardi2014();
    assert_eq!(spec.nodes(), [350, 80, 250]);
    let b = spec.bingham();
    assert!((b.mu_pl / 6.25e-4 - 1.0).abs() < 1e-12, "{}", b.mu_pl);
    assert!(
        (b.yield_stress / 7.75e-6 - 1.0).abs() < 1e-12,
        "{}",
        b.yield_stress
    );
    let g = spec.gravity().norm() * spec.dt * spec.dt / spec.dx;
    assert!((g / 4.41e-6 - 1.0).abs() < 2e-3, "{g}");
    // τ_pl = ½ + 3 ν_pl = 0.501875: just inside the paper's clamp [0.501, 3.5]
    assert!(b.tau_pl() > b.tau_min && b.tau_pl() < 0.502);
}

#[test]
fn the_papers_thousand_pebbles_weigh_what_it_reports() {
    // "1,000 silica rounded pebbles with radius R = 4.0-8.0 mm. The total weight of the grains
    // is 2.629 kg, and the density 2680 kg/m³": radii uniform in [4, 8] mm with the volume
    // 4/3 π R³ give 2.69 kg on average. Measured 2.698 kg (+2.6 %) for seed 1; every pebble's
    // spheres inside the 150 mm box.
    let spec = InclineSpec::leonardi2014();
    let mut sys =
        SphereSystem::new(Domain3::new(Vec3::ZERO, Vec3::new(0.2, 0.2, 0.2), [false; 3]).expect("box"));
    let n = place_pebbles(&spec, &mut sys, [0.0; 3], spec.box_edge).expect("placed");
    assert_eq!((n, sys.clumps.len(), sys.spheres.len()), (1000, 1000, 4000));
    let mass: f64 = sys.clumps.mass.iter().sum();
    assert!((mass / 2.629 - 1.0).abs() < 0.05, "pebbles weigh {mass} kg");
    for (p, r) in sys.spheres.pos.iter().zip(&sys.spheres.radius) {
        for v in [p.x, p.y, p.z] {
            assert!(
                v - r >= -1e-12 && v + r <= spec.box_edge + 1e-12,
                "a sphere at {p:?} leaves the box"
            );
        }
    }
}

#[test]
fn a_coarse_paste_alone_spreads_keeping_its_mass_until_its_front_passes_the_mach_limit() {
    // The paper's paste without pebbles on a lattice 5 times coarser (10 mm; Δt 7.5e-4 s, scaled
    // with dx² so that τ_pl is the paper's 0.501875). It slumps and runs down the board (0.14 m
    // past the box at 0.3 s), the mass kept to 6e-15, then a node at the foot of the front passes
    // the Mach limit at step 501 (t = 0.38 s, measured). Issue 20 item 6's "Mach limit in the
    // falling front", provoked here: the run must stop there with the engine's diagnosis, at a
    // node of the free surface or next to it, and say so. A floor τ_min = 0.52 postpones it
    // (step 860), 0.6 to step 1918 (measured): not the fix.
    let spec = InclineSpec {
        pebbles: 0,
        ..InclineSpec::leonardi2014().coarsened(5.0)
    };
    let mut run = Incline::build(&spec).expect("build");
    let m0 = run.run.grains.liquid.total_mass();
    let start = run.footprint().0;
    let (mut worst, mut shares) = (0.0f64, Vec::new());
    let mut failure = None;
    for k in 0..3000 {
        if let Err(e) = run.step() {
            failure = Some((k, e));
            break;
        }
        if k == 0 || k == 400 {
            shares.push(run.rigid_share());
            // the section's viscosity lies in the clamp's range [μ(τ_min), μ(τ_max)]
            let unit = spec.rho_paste * spec.dx * spec.dx / spec.dt / 3.0;
            let (lo, hi) = ((spec.tau_min - 0.5) * unit, (spec.tau_max - 0.5) * unit);
            let wet: Vec<f64> = run
                .viscosity_section()
                .into_iter()
                .filter(|v| !v.is_nan())
                .collect();
            let inside = |&m: &f64| m >= lo * (1.0 - 1e-9) && m <= hi * (1.0 + 1e-9);
            assert!(!wet.is_empty() && wet.iter().all(inside));
        }
        if k == 400 {
            assert!(
                run.footprint().0 > start + 0.1,
                "the paste ran {start} -> {:?}",
                run.footprint()
            );
        }
        worst = worst.max((run.run.grains.liquid.total_mass() - m0).abs() / m0);
    }
    // measured 5.9e-15; rigid shares 0.748 and 0.000
    assert!(worst < 1.2e-14, "mass drift {worst:e}");
    // at rest the paste is partly unyielded (τ_max), then it yields throughout (Fig. 8: "the
    // yielded region ... grows ... to the whole sample")
    assert!(
        shares.len() == 2 && shares[1] < 0.5 * shares[0],
        "rigid shares {shares:?}"
    );
    let Some((k, CouplingError::Lbm(LbmError::Unstable { node, cause, .. }))) = failure else {
        panic!("expected the front to pass the Mach limit within 3000 steps: {failure:?}");
    };
    assert!(k > 400, "failed at step {k}");
    // the diagnosis names the place (issue 20 item 6)
    assert!(cause.contains("free surface"), "{cause}");
    let s = &run.run.grains.liquid;
    let x = s.domain.index(node[0], node[1], node[2]);
    let at_surface = s.cell[x] == INTERFACE || s.neighbours(x).any(|j| s.cell[j] == INTERFACE);
    assert!(
        at_surface,
        "the failure at {node:?} (step {k}) is not at the free surface"
    );
}

#[test]
fn the_coarse_paste_runs_past_its_failures_with_the_eddy_viscosity_and_the_lonely_rule() {
    // The paste of the test above (10 mm, no pebbles) with the two coarse-lattice options (not in
    // the paper): a Smagorinsky eddy viscosity C = 0.1 keeps the front's foot (τ ≈ ½, where BGK
    // breaks down) and the lonely-node rule at 1 empties the one-node sheets of paste that drip
    // from the lifted box. Measured with `examples/incline_probe` (docs/free_surface.md, "The
    // incline"): without options the run fails at step 501, with C = 0.1 alone at step 1367 (a
    // drip near the board), with the lonely rule alone at step 502, with C = 0.1 and the rule at
    // 0.1 at step 1968; with both as here it runs 2000 steps (1.5 s; and on to the paper's stop,
    // 37.7 s), keeping the mass to 1.2e-14 (measured 7.2e-15) while 24 % of the paste is at τ_max.
    let spec = InclineSpec {
        pebbles: 0,
        smagorinsky: 0.1,
        lonely: 1.0,
        ..InclineSpec::leonardi2014().coarsened(5.0)
    };
    let mut run = Incline::build(&spec).expect("build");
    let m0 = run.run.grains.liquid.total_mass() + run.run.grains.liquid.reservoir;
    let mut worst = 0.0f64;
    for k in 0..2000 {
        if let Err(e) = run.step() {
            panic!("step {k}: {e}");
        }
        let s = &run.run.grains.liquid;
        worst = worst.max((s.total_mass() + s.reservoir - m0).abs() / m0);
    }
    let share = run.rigid_share();
    eprintln!("coarse paste with the options: mass drift {worst:e}, rigid share {share:.3}");
    assert!(worst < 1.2e-14, "mass drift {worst:e}");
    // measured 0.239: the paste is setting, well short of the paper's 95 % stop
    assert!(share > 0.12 && share < 0.5, "rigid share {share}");
}

#[test]
fn the_papers_pebbles_on_a_4_mm_lattice_rock_unless_the_velocity_update_is_implicit() {
    // The paper's pebbles on a 4 mm lattice (factor 2, Δt 1.2e-4 s): spheres of 0.8-1.6 nodes,
    // 1.5 times the paste's density, the paste at τ up to 3.5 and down to τ_min. Explicit (the
    // paper's coupling), a pebble spins up from step to step (ω × 1.3-1.5 per LBM step) until it
    // outruns the mapping (0.3 nodes per step; step 12, measured) or the liquid beside it passes
    // the Mach limit; with the implicit velocity update the 60 steps run.
    let spec = InclineSpec {
        pebbles: 200,
        ..InclineSpec::leonardi2014().coarsened(2.0)
    };
    let run_for = |implicit: bool| {
        let mut run = Incline::build(&spec).expect("build");
        run.run.grains.implicit = implicit;
        for k in 0..60 {
            if let Err(e) = run.step() {
                return Some((k, e, run));
            }
        }
        None
    };
    assert!(run_for(true).is_none(), "the implicit coupling failed");
    let Some((k, err, run)) = run_for(false) else {
        panic!("expected a pebble or the liquid beside it to outrun the grid within 60 steps");
    };
    let s = &run.run.grains.liquid;
    let beside_a_pebble = match &err {
        CouplingError::Unsupported(msg) => msg.contains("nodes per LBM step"),
        CouplingError::Lbm(LbmError::Unstable { node, .. }) => {
            let x = s.domain.index(node[0], node[1], node[2]);
            s.neighbours(x).any(|j| s.cell[j] == GRAIN)
        }
        _ => false,
    };
    assert!(beside_a_pebble && k > 5, "step {k}: {err}");
}
