//! Quick profiling harness for the pair loop (not the benchmark: `lbdem bench dem` is).
//! `cargo run --release -p lbdem-dem --example dem_rate --features probes -- [THREADS] [STEPS] [TILE]`
//! Caches the prepared 10k packing in the system temporary directory (lbdem_dem_rate_10k.json).

use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::{Damping, StepParams, Stepper, System, Vec2, generate};
use std::time::Instant;

fn main() {
    let a: Vec<usize> = std::env::args().skip(1).map(|s| s.parse().unwrap()).collect();
    let threads = a.first().copied().unwrap_or(1);
    let steps = a.get(1).copied().unwrap_or(2000);
    let tile = a.get(2).copied().unwrap_or(1);
    let law = LinearSpringDashpot::new(2.0e4, 2.0e4 * 2.0 / 7.0, Damping::Gamma(100.0), 0.5);
    let cache = std::env::temp_dir().join("lbdem_dem_rate_10k.json");
    let s10 = match std::fs::read(&cache) {
        Ok(b) => System::from_checkpoint(&b).unwrap(),
        Err(_) => {
            let mut s = generate::bidisperse_lattice(100, 1.0, 1.4, 1.42, 4821).unwrap();
            let mut p = StepParams::new(2.5e-4, 0.1);
            p.viscous_damping = 0.5;
            let mut st = Stepper::new();
            generate::compress_periodic(&mut s, &law, &p, 0.82, 8000, &mut st).unwrap();
            for _ in 0..3000 {
                st.step_linear(&p, &law, &mut s).unwrap();
            }
            std::fs::write(&cache, s.to_checkpoint()).unwrap();
            s
        }
    };
    let s0 = if tile > 1 {
        generate::tile(&s10, 5, 2).unwrap()
    } else {
        s10
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut s = s0.clone();
        let p = StepParams::new(2.5e-4, 0.1);
        let mut st = Stepper::new();
        let area = s.domain.size().x * s.domain.size().y;
        let lx0 = s.domain.size().x;
        let mut t = 0.0;
        let mut cpu0 = 0.0;
        for n in 0..200 + steps as u64 {
            if n == 200 {
                t = 0.0;
                cpu0 = cpu_seconds();
            }
            let lx = lx0 * (1.0 + 0.01 * n as f64 * p.dt);
            let lo = s.domain.lo;
            let mut d = s.domain;
            d.remap_affine(lo, lo + Vec2::new(lx, area / lx), &mut s.bodies);
            s.domain = d;
            let t0 = Instant::now();
            st.step_linear(&p, &law, &mut s).unwrap();
            t += t0.elapsed().as_secs_f64();
        }
        let cpu = cpu_seconds() - cpu0;
        let z = 2.0 * st.n_contacts() as f64 / s.bodies.len() as f64;
        let h: u64 = s.bodies.pos.iter().map(|p| p.x.to_bits() ^ p.y.to_bits()).fold(0, |a, b| a ^ b);
        println!(
            "N {} threads {threads} steps {steps}: {:.2} M p-steps/s (per CPU-second of the process: {:.2}), z {z:.2}, pairs {}, rebuilds {}, hash {h:x}",
            s.bodies.len(),
            s.bodies.len() as f64 * steps as f64 / t / 1e6,
            s.bodies.len() as f64 * steps as f64 / cpu / 1e6,
            s.contacts.pairs.len(),
            st.rebuilds
        );
    });
}

/// User + system CPU seconds of this process (/proc/self/stat, clock ticks of 10 ms): a rate
/// per CPU-second is less sensitive to other processes on a shared machine than wall time.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<f64> = after
        .split_whitespace()
        .map(|v| v.parse().unwrap_or(0.0))
        .collect();
    (f.get(11).unwrap_or(&0.0) + f.get(12).unwrap_or(&0.0)) / 100.0
}
