//! `lbdem bench dem`: particle-steps per second of the DEM engine on the PEERS.md case: 2D
//! bidisperse disks (d, 1.4d), linear spring-dashpot with tangential history (k_n 2e4,
//! k_t 2/7 k_n, γ_n 100, μ 0.5), periodic box at packing fraction 0.82, slow pure shear
//! (x stretched at strain rate 0.01, area kept), on 1 and 2 threads; with `--peer`, LAMMPS on
//! the same case and core count in the same run (scripts/peer-lammps.sh), and the ratio. lbdem and
//! LAMMPS alternate rep by rep; each row also prints LAMMPS's contacts per disk and the load average.
//! The first `--peer` run prepares and caches the LAMMPS packings in out/peer-lammps/ (the
//! 100,000-disk one takes 45,000 steps: ~20-40 min on a shared machine).

use super::{BenchArgs, median};
use anyhow::{Context, Result, bail};
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
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/peer-lammps.sh");
    let out = std::process::Command::new("bash")
        .arg(&script)
        .args([n_side.to_string(), np.to_string(), steps.to_string()])
        .output()
        .with_context(|| format!("cannot run {}", script.display()))?;
    if !out.status.success() {
        bail!(
            "{} failed: {}",
            script.display(),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    lammps_loop_rate(&String::from_utf8_lossy(&out.stdout))
}

/// (particle-steps/s, contacts per particle) from a LAMMPS run's output: the "Loop time of T on
/// P procs for S steps with N atoms" line and, before it, the last thermo line, whose fifth
/// column is the mean contacts per particle (both peer decks print "step atoms ke phi z ...").
pub(super) fn lammps_loop_rate(text: &str) -> Result<(f64, f64)> {
    let lines: Vec<&str> = text.lines().collect();
    let at = lines
        .iter()
        .rposition(|l| l.starts_with("Loop time"))
        .context("no 'Loop time' line from LAMMPS")?;
    let w: Vec<&str> = lines[at].split_whitespace().collect();
    let field = |k: usize| -> Result<f64> {
        w.get(k)
            .and_then(|v| v.parse().ok())
            .with_context(|| format!("unreadable LAMMPS line '{}'", lines[at]))
    };
    let (t, s, n) = (field(3)?, field(8)?, field(11)?);
    let z = at
        .checked_sub(1)
        .and_then(|k| lines[k].split_whitespace().nth(4))
        .and_then(|v| v.parse().ok())
        .unwrap_or(f64::NAN);
    Ok((n * s / t, z))
}

/// The 1-minute load average (the machine is shared: figures taken under load are depressed).
pub(super) fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
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
    println!(
        "| case | N | threads | lbdem M p-steps/s (median of {reps}) | z | LAMMPS M p-steps/s | LAMMPS z | ratio | load avg |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, n_side, s, steps) in &cases {
        for threads in [1usize, 2] {
            // lbdem and LAMMPS alternate rep by rep, so a change of machine load hits both.
            let lsteps = if *n_side > 100 { 1000 } else { 4000 };
            if a.peer
                && !Path::new(env!("CARGO_MANIFEST_DIR"))
                    .join(format!("out/peer-lammps/lmp2d_n{n_side}.restart"))
                    .exists()
            {
                eprintln!("bench dem: preparing the LAMMPS packing for N_SIDE {n_side} once (slow)");
            }
            let (mut rates, mut pr) = (Vec::new(), Vec::new());
            let (mut z, mut zl) = (0.0, f64::NAN);
            for _ in 0..reps {
                let (r, zz) = timed(s, *steps, threads)?;
                rates.push(r);
                z = zz;
                if a.peer {
                    let (r, zz) = peer(*n_side, threads, lsteps)?;
                    pr.push(r);
                    zl = zz;
                }
            }
            let ours = median(&rates);
            let (theirs, zl, ratio) = if a.peer {
                let t = median(&pr);
                (Some(t), Some(zl), Some(ours / t))
            } else {
                (None, None, None)
            };
            println!(
                "| {name} | {} | {threads} | {:.2} | {z:.2} | {} | {} | {} | {} |",
                s.bodies.len(),
                ours / 1e6,
                theirs.map_or("-".into(), |t| format!("{:.2}", t / 1e6)),
                zl.map_or("-".into(), |z| format!("{z:.2}")),
                ratio.map_or("-".into(), |r| format!("{r:.2}")),
                load_average().map_or("-".into(), |l| format!("{l:.1}"))
            );
            rows.push(serde_json::json!({
                "case": name, "n": s.bodies.len(), "threads": threads, "rate": ours, "rates": rates,
                "contacts_per_particle": z, "lammps_rate": theirs, "lammps_rates": pr, "lammps_contacts_per_particle": zl,
                "ratio_to_lammps": ratio, "load_average": load_average(),
            }));
        }
    }
    if let Some(path) = &a.json {
        let text = serde_json::to_string_pretty(&serde_json::json!({ "bench": "dem", "rows": rows }))?;
        lbdem_core::atomic::write_atomic(path, text.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lammps_loop_line_gives_particle_steps_per_second_and_contacts() {
        let out = "   1200   10648   1.2e-09   0.62   5.01   33.1   0.2\n\
                   Loop time of 1.8436 on 1 procs for 1000 steps with 10648 atoms\n";
        let (rate, z) = lammps_loop_rate(out).unwrap();
        assert!((rate - 10648.0 * 1000.0 / 1.8436).abs() < 1e-6 * rate);
        assert_eq!(z, 5.01);
        let err = lammps_loop_rate("ERROR: Unknown pair style\n").unwrap_err();
        assert!(err.to_string().contains("Loop time"), "{err}");
    }
}
