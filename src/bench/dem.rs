//! `lbdem bench dem`: particle-steps per second of the DEM engine on the PEERS.md case: 2D
//! bidisperse disks (d, 1.4d), linear spring-dashpot with tangential history (k_n 2e4,
//! k_t 2/7 k_n, γ_n 100, μ 0.5), periodic box at packing fraction 0.82, slow pure shear
//! (x stretched at strain rate 0.01, area kept), on 1 and 2 threads; with `--peer`, LAMMPS on
//! the same case and core count in the same run (scripts/peer-lammps.sh), and the ratio. lbdem and
//! LAMMPS alternate rep by rep; each row also prints LAMMPS's contacts per disk and the load average.
//! The first `--peer` run prepares and caches the LAMMPS packings in out/peer-lammps/ (the
//! 100,000-disk one takes 45,000 steps: ~20-40 min on a shared machine).

use super::{BenchArgs, lammps};
use anyhow::Result;
use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::{Damping, StepParams, Stepper, System, Vec2, generate};
use std::path::Path;
use std::time::Instant;

fn law() -> LinearSpringDashpot {
    LinearSpringDashpot::new(2.0e4, 2.0e4 * 2.0 / 7.0, Damping::Gamma(100.0), 0.5)
}

/// The jammed 10,000-disk packing (100 x 100 lattice, spacing 1.42 d, compressed to φ = 0.82
/// with weak viscous damping, then relaxed), as peers/lammps_2d_prep.in does with fewer steps.
pub fn packing_10k(quick: bool) -> Result<System> {
    let mut s = generate::bidisperse_lattice(100, 1.0, 1.4, 1.42, 4821)?;
    let law = law();
    let mut p = StepParams::new(2.5e-4, 0.1);
    p.viscous_damping = 0.5;
    let mut st = Stepper::new();
    let (nc, nr) = if quick { (2000, 500) } else { (8000, 3000) };
    generate::compress_periodic(&mut s, &law, &p, 0.82, nc, &mut st)?;
    for _ in 0..nr {
        st.step_linear(&p, &law, &mut s)?;
    }
    Ok(s)
}

/// Timed slow pure shear: returns (particle-steps/s, contacts per particle at the end).
fn timed(s0: &System, steps: usize, threads: usize) -> Result<(f64, f64)> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    pool.install(|| {
        let mut s = s0.clone();
        let law = law();
        let p = StepParams::new(2.5e-4, 0.1);
        let mut st = Stepper::new();
        let area = s.domain.size().x * s.domain.size().y;
        let lx0 = s.domain.size().x;
        let shear = |s: &mut System, n: u64| {
            let lx = lx0 * (1.0 + 0.01 * n as f64 * p.dt);
            let lo = s.domain.lo;
            let mut d = s.domain;
            d.remap_affine(lo, lo + Vec2::new(lx, area / lx), &mut s.bodies);
            s.domain = d;
        };
        for n in 0..200 {
            shear(&mut s, n);
            st.step_linear(&p, &law, &mut s)?;
        }
        let t0 = Instant::now();
        for n in 200..200 + steps as u64 {
            shear(&mut s, n);
            st.step_linear(&p, &law, &mut s)?;
        }
        let el = t0.elapsed().as_secs_f64();
        let z = 2.0 * st.n_contacts() as f64 / s.bodies.len() as f64;
        Ok((s.bodies.len() as f64 * steps as f64 / el, z))
    })
}

/// LAMMPS rate (particle-steps/s) and contacts per disk from scripts/peer-lammps.sh.
fn peer(n_side: usize, np: usize, steps: usize) -> Result<(f64, f64)> {
    lammps::run_script(
        "peer-lammps.sh",
        &[n_side.to_string(), np.to_string(), steps.to_string()],
    )
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let reps = a.reps.max(1);
    eprintln!("bench dem: preparing the jammed 10,000-disk packing ...");
    let s10 = packing_10k(a.quick)?;
    let mut cases = vec![("10k", 100usize, s10.clone(), if a.quick { 300 } else { 2000 })];
    if !a.quick {
        // 100,000 disks: the periodic 10k packing tiled 5 x 2 (same structure, same φ).
        cases.push(("100k", 316, generate::tile(&s10, 5, 2)?, 400));
    }
    let mut rows = Vec::new();
    lammps::header(reps);
    for (name, n_side, s, steps) in &cases {
        for threads in [1usize, 2] {
            let lsteps = if *n_side > 100 { 1000 } else { 4000 };
            if a.peer
                && !Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join(format!("out/peer-lammps/lmp2d_n{n_side}.restart"))
                    .exists()
            {
                eprintln!("bench dem: preparing the LAMMPS packing for N_SIDE {n_side} once (slow)");
            }
            rows.push(lammps::row(
                name,
                s.bodies.len(),
                threads,
                reps,
                a.peer,
                2,
                || timed(s, *steps, threads),
                || peer(*n_side, threads, lsteps),
            )?);
        }
    }
    lammps::write_json(a.json.as_ref(), "dem", rows)
}
