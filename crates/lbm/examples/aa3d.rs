//! Development speed probe of the D3Q19 AA kernel on a periodic cube (the benchmark proper, with
//! the bound and lbmpy, is `lbdem bench lbm` with `LBDEM_BENCH_LBM_SIZE=NxNxN`). Prints the MLUPS
//! of each repetition and a hash of the final populations, so that a kernel change can be timed
//! against the build before and shown to leave the bits alone.
//! `cargo run --release -p lbdem-lbm --example aa3d --features probes -- N f64|f32|f16s THREADS [REPS] [STEPS]`

use lbdem_lbm::storage::{ShiftedF16, Storage};
use lbdem_lbm::{Collision, D3Q19, Domain, Fluid, Limits, Real, Settings, StepperAa};
use std::hash::{DefaultHasher, Hash, Hasher};
use std::time::Instant;

fn run<T: Real, St: Storage<T>>(n: usize, reps: usize, steps: usize) {
    let mut fluid = Fluid::<D3Q19, T>::new(Domain::periodic([n, n, n]), Vec::new());
    fluid.init_equilibrium(|p| {
        let s = ((p[0] * 7 + p[1] * 13 + p[2] * 5) % 17) as f64 / 17.0 - 0.5;
        (1.0 + 1e-3 * s, [1e-3 * s, -2e-3 * s, 5e-4])
    });
    let settings = Settings {
        collision: Collision::Bgk { tau: 1.0 / 1.8 },
        force: [0.0; 3],
        limits: Limits::default(),
    };
    let mut st = StepperAa::<D3Q19, T, St>::with_storage(&mut fluid, settings).unwrap();
    let mut rates = Vec::new();
    for _ in 0..reps {
        let t = Instant::now();
        for _ in 0..steps {
            st.step(&mut fluid, None).unwrap();
        }
        rates.push((n * n * n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6);
    }
    let f = st.canonical(&fluid).unwrap();
    let mut h = DefaultHasher::new();
    for v in &f {
        v.to_f64().to_bits().hash(&mut h);
    }
    let mut sorted = rates.clone();
    sorted.sort_by(f64::total_cmp);
    println!(
        "{n}^3 {} t={}: median {:.1} MLUPS (reps {:?}), hash {:016x}",
        St::NAME,
        rayon::current_num_threads(),
        sorted[sorted.len() / 2],
        rates
            .iter()
            .map(|r| (r * 10.0).round() / 10.0)
            .collect::<Vec<_>>(),
        h.finish()
    );
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let n: usize = a.get(1).map_or(128, |s| s.parse().unwrap());
    let prec = a.get(2).map_or("f16s", |s| s.as_str());
    let threads: usize = a.get(3).map_or(1, |s| s.parse().unwrap());
    let reps: usize = a.get(4).map_or(5, |s| s.parse().unwrap());
    let steps: usize = a.get(5).map_or(20, |s| s.parse().unwrap());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| match prec {
        "f64" => run::<f64, f64>(n, reps, steps),
        "f32" => run::<f32, f32>(n, reps, steps),
        "f16s" => run::<f32, ShiftedF16>(n, reps, steps),
        other => eprintln!("precision {other:?}: expected f64, f32 or f16s"),
    });
}
