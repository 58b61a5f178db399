//! Quick kernel throughput probe for development (the benchmark with ceilings and the peer is
//! `lbdem bench lbm`): `cargo run --release -p lbdem-lbm --example mlups -- 1024 1024 f64 2 aa`.

use lbdem_lbm::{Collision, D2Q9, Domain, Fluid, Limits, Real, Settings, Stepper, StepperAa};
use std::time::Instant;

fn run<T: Real>(nx: usize, ny: usize, aa: bool, steps: usize) -> f64 {
    let mut fl = Fluid::<D2Q9, T>::new(Domain::periodic([nx, ny, 1]), Vec::new());
    let s = Settings {
        collision: Collision::Bgk { tau: 1.0 / 1.8 },
        force: [0.0; 3],
        limits: Limits::default(),
    };
    let t;
    if aa {
        let mut st = StepperAa::new(&mut fl, s).unwrap();
        st.step(&mut fl, None).unwrap();
        st.step(&mut fl, None).unwrap();
        t = Instant::now();
        for _ in 0..steps {
            st.step(&mut fl, None).unwrap();
        }
    } else {
        let mut st = Stepper::new(&fl, s).unwrap();
        st.step(&mut fl, None).unwrap();
        t = Instant::now();
        for _ in 0..steps {
            st.step(&mut fl, None).unwrap();
        }
    }
    (nx * ny * steps) as f64 / t.elapsed().as_secs_f64() / 1e6
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let nx: usize = a.get(1).map_or(1024, |s| s.parse().unwrap());
    let ny: usize = a.get(2).map_or(1024, |s| s.parse().unwrap());
    let f32s = a.get(3).is_some_and(|s| s == "f32");
    let threads: usize = a.get(4).map_or(1, |s| s.parse().unwrap());
    let aa = a.get(5).is_none_or(|s| s == "aa");
    let steps = (100_000_000 / (nx * ny)).max(2) & !1;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let m = pool.install(|| {
        if f32s {
            run::<f32>(nx, ny, aa, steps)
        } else {
            run::<f64>(nx, ny, aa, steps)
        }
    });
    println!("{nx}x{ny} f32={f32s} threads={threads} aa={aa}: {m:.1} MLUPS");
}
