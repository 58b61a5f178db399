//! Probe (not a test): where the incline's paste (no pebbles) speeds up before a run fails, and
//! whether it reaches the paper's stop. Prints the fastest liquid or interface node every 200
//! steps and at every step where it exceeds 0.2 (lattice units), with its cell type, fill, ρ and τ.
//!   cargo run --release -p lbdem-coupling --example incline_probe --features probes -- C THETA F
//! C: Smagorinsky constant, THETA: lonely-node threshold, F: coarsening factor of the paper's
//! 2 mm lattice (5: 10 mm), optionally DT: the LBM step (s) instead of the diffusive F² x 3e-5.
//! MAGIC=Λ in the environment runs TRT with that magic parameter instead of BGK. docs/free_surface.md, "The incline", has what it found.
use lbdem_coupling::cases::incline::{Incline, InclineSpec};
use lbdem_lbm::free_surface::{INTERFACE, LIQUID};

fn main() {
    let args: Vec<f64> = std::env::args().skip(1).map(|a| a.parse().unwrap()).collect();
    let factor = args.get(2).copied().unwrap_or(5.0);
    let mut spec = InclineSpec::leonardi2014().coarsened(factor);
    spec.pebbles = 0;
    spec.substeps = 30;
    spec.smagorinsky = args.first().copied().unwrap_or(0.0);
    if let Some(&dt) = args.get(3) {
        // another time step: substeps keep the DEM step
        spec.substeps = ((spec.substeps as f64) * dt / spec.dt).ceil().max(1.0) as u32;
        spec.dt = dt;
    }
    spec.lonely = args.get(1).copied().unwrap_or(0.0);
    spec.magic = std::env::var("MAGIC")
        .ok()
        .and_then(|m| m.parse().ok())
        .unwrap_or(0.0);
    let b = spec.bingham();
    println!(
        "dx {} dt {} tau_pl {:.6} (clamp [{}, {}]) smagorinsky {} lonely {}",
        spec.dx,
        spec.dt,
        b.tau_pl(),
        b.tau_min,
        b.tau_max,
        spec.smagorinsky,
        spec.lonely
    );
    let mut inc = Incline::build(&spec).unwrap();
    let n = spec.nodes();
    for step in 0..200000 {
        let r = inc.step();
        let s = &inc.run.grains.liquid;
        let tau = inc.run.grains.stepper().tau().map(|t| t.to_vec());
        let mut best = (0.0, 0usize);
        for i in 0..s.cell.len() {
            if s.cell[i] == LIQUID || s.cell[i] == INTERFACE {
                let u = s.u[i];
                let m = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
                if m > best.0 {
                    best = (m, i);
                }
            }
        }
        let i = best.1;
        let (x, y, z) = (i % n[0], (i / n[0]) % n[1], i / (n[0] * n[1]));
        if step % 200 == 0 || best.0 > 0.2 || r.is_err() {
            println!(
                "step {step} t {:.3} max|u| {:.4} at [{x},{y},{z}] cell {} fill {:.3} rho {:.4} tau {:.4} u {:?}",
                inc.time(),
                best.0,
                s.cell[i],
                s.fill(i),
                s.rho[i],
                tau.as_ref().map(|t| t[i]).unwrap_or(0.0),
                s.u[i].map(|v| (v * 1000.0).round() / 1000.0)
            );
        }
        if let Err(e) = r {
            println!("{e}");
            break;
        }
        if step % 200 == 0 {
            println!(
                "  rigid share {:.3} footprint {:?}",
                inc.rigid_share(),
                inc.footprint()
            );
            if inc.rigid_share() >= spec.stop_share {
                println!("stopped: {:.3} at tau_max", inc.rigid_share());
                break;
            }
        }
    }
}
