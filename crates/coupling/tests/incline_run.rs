//! The incline of Leonardi et al. (2014) run to its stop on a coarse lattice (issue 20 item 4),
//! ignored in CI (about an hour): `cargo test --release -p lbdem-coupling --test coupling --
//! --ignored --nocapture incline_run::`.

use lbdem_coupling::cases::incline::{Incline, InclineSpec};

/// Runout (m, down the board from the box's downslope side) and width (m, across) of the
/// footprint: the columns at least half a node thick.
fn footprint(run: &Incline) -> (f64, f64) {
    let spec = &run.spec;
    let [nx, _, nz] = spec.nodes();
    let th = run.thickness();
    let wet: Vec<(usize, usize)> = (0..nz)
        .flat_map(|z| (0..nx).map(move |x| (x, z)))
        .filter(|&(x, z)| th[x + nx * z] > 0.5 * spec.dx)
        .collect();
    let x_max = wet.iter().map(|p| p.0).max().unwrap_or(0) as f64 + 1.0;
    let (z_lo, z_hi) = (
        wet.iter().map(|p| p.1).min().unwrap_or(0),
        wet.iter().map(|p| p.1).max().unwrap_or(0),
    );
    (
        x_max * spec.dx - (spec.box_from_top + spec.box_edge),
        (z_hi + 1 - z_lo) as f64 * spec.dx,
    )
}

#[test]
#[ignore = "the incline at 4 mm to its stop (about an hour): cargo test --release -p lbdem-coupling --test coupling -- --ignored --nocapture incline_run::"]
fn the_incline_at_4_mm_runs_until_the_paste_stops() {
    // The paper's case on a lattice twice as coarse (4 mm, Δt 6e-5 s), its 1000 pebbles, the
    // implicit velocity update, and τ_min = 0.52 (the paper's 0.501 lets the front pass the Mach
    // limit on coarse lattices: `incline::a_coarse_paste_alone_...`). Stops at the paper's
    // criterion (95 % of the paste at τ_max) or after 6 s.
    let spec = InclineSpec {
        tau_min: 0.52,
        ..InclineSpec::leonardi2014().coarsened(2.0)
    };
    let mut run = Incline::build(&spec).expect("build");
    run.run.grains.implicit = true;
    let m0 = run.run.grains.liquid.total_mass();
    let t0 = std::time::Instant::now();
    let every = (0.1 / spec.dt).round() as u64;
    let mut worst = 0.0f64;
    loop {
        run.step().expect("step");
        worst = worst.max((run.run.grains.liquid.total_mass() - m0).abs() / m0);
        let step = run.run.grains.liquid.step;
        if step.is_multiple_of(every) {
            let (runout, width) = footprint(&run);
            let rigid = run.rigid_share();
            eprintln!(
                "t {:.1} s: runout {runout:.3} m, width {width:.3} m, rigid {rigid:.3}, mass {worst:.1e}, wall {:.0} s",
                run.time(),
                t0.elapsed().as_secs_f64()
            );
            if rigid >= 0.95 || run.time() >= 6.0 {
                break;
            }
        }
    }
    assert!(worst < 1e-12, "mass drift {worst:e}");
    assert!(
        run.rigid_share() >= 0.95,
        "the paste still flows after {} s",
        run.time()
    );
}
