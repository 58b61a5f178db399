//! Development speed probe of one configuration (the benchmark proper, with STREAM and the peer,
//! is `lbdem bench lbm`). Each repetition times the AA kernel once per row partition
//! (`Partition::Rows(4)`, then `Partition::Contiguous`: an A/B of the partition in one process),
//! then the nine-pass in-place ceiling and the fused in-place bound (`roofline::in_place_pass`)
//! on arrays of the same size, so that the printed ratios are robust to other load on the machine.
//! `cargo run --release -p lbdem-lbm --example mlups --features probes -- NX NY f64|f32 THREADS [REPS] [bgk|trt] [aa|two] [WORK]`

use lbdem_lbm::layout::Layout;
use lbdem_lbm::{
    Collision, D2Q9, Domain, Fluid, Limits, Partition, Real, Settings, Stepper, StepperAa, roofline,
};
use rayon::prelude::*;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn run<T: Real>(nx: usize, ny: usize, reps: usize, collision: Collision, two: bool, work: usize) {
    let n = nx * ny;
    let mut fluid = Fluid::<D2Q9, T>::new(Domain::periodic([nx, ny, 1]), Vec::new());
    fluid.init_equilibrium(|p| {
        (
            1.0 + 1e-4 * (((p[0] * 7 + p[1] * 13) % 17) as f64 / 17.0 - 0.5),
            [0.0; 3],
        )
    });
    let settings = Settings {
        collision,
        force: [0.0; 3],
        limits: Limits::default(),
    };
    let steps = ((work / n).max(2)) & !1;
    // 64-byte aligned, as the kernel's array and `lbdem bench lbm`'s ceilings
    let mut c: Vec<(Vec<T>, usize)> = (0..9)
        .map(|i| {
            let v = vec![T::from_f64(1.0 + i as f64); n + 16];
            let off = v.as_ptr().align_offset(64);
            (v, off)
        })
        .collect();
    let s = T::from_f64(0.999);
    let mut ceiling = || {
        let t = Instant::now();
        for _ in 0..steps {
            for (arr, o) in c.iter_mut() {
                arr[*o..*o + n]
                    .par_chunks_mut(1 << 14)
                    .for_each(|x| x.iter_mut().for_each(|v| *v = *v * s));
            }
        }
        (n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6
    };
    let (mut two_st, mut aa_st) = if two {
        (Some(Stepper::new(&fluid, settings).unwrap()), None)
    } else {
        (None, Some(StepperAa::new(&mut fluid, settings).unwrap()))
    };
    // the fused in-place bound on an array in the AA stepper's own layout
    let mut lay = Layout::padded::<T>([nx, ny, 1]);
    let mut g = lay.pack(&vec![T::from_f64(1.0); 9 * n], 9);
    let mut bound = || {
        let t = Instant::now();
        for _ in 0..steps {
            roofline::in_place_pass(&mut g[lay.base..], &lay, 9, ny, Partition::Rows(4), s);
        }
        (n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6
    };
    // AA: each partition in turn; two-array: one entry
    let parts: Vec<Option<Partition>> = if two {
        vec![None]
    } else {
        vec![Some(Partition::Rows(4)), Some(Partition::Contiguous)]
    };
    let mut rates = vec![Vec::new(); parts.len()];
    let (mut ceils, mut bounds) = (Vec::new(), Vec::new());
    for rep in 0..=reps {
        let mut r = Vec::new();
        for p in &parts {
            let t = Instant::now();
            for _ in 0..steps {
                match (aa_st.as_mut(), two_st.as_mut()) {
                    (Some(a), _) => {
                        a.partition = p.unwrap();
                        a.step(&mut fluid, None).unwrap()
                    }
                    (None, Some(b)) => b.step(&mut fluid, None).unwrap(),
                    _ => unreachable!(),
                }
            }
            r.push((n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6);
        }
        let cl = ceiling();
        let bd = bound();
        if rep > 0 {
            for (k, x) in r.into_iter().enumerate() {
                rates[k].push(x);
            }
            ceils.push(cl);
            bounds.push(bd);
        }
    }
    let b = median(bounds.clone());
    println!(
        "{nx}x{ny} {} {} t={}: fused in-place bound {:.1} MLUPS, nine-pass ceiling {:.1} (medians of {reps})",
        T::NAME,
        if two { "two-array" } else { "AA" },
        rayon::current_num_threads(),
        b,
        median(ceils.clone()),
    );
    for (p, r) in parts.iter().zip(&rates) {
        let ratios: Vec<f64> = r.iter().zip(&bounds).map(|(x, y)| x / y).collect();
        println!(
            "  {:?}: {:.1} MLUPS, {:.0}% of the bound (per-rep ratios {:?})",
            p,
            median(r.clone()),
            100.0 * median(ratios.clone()),
            ratios.iter().map(|r| (100.0 * r).round()).collect::<Vec<_>>()
        );
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let nx: usize = a.get(1).map_or(1024, |s| s.parse().unwrap());
    let ny: usize = a.get(2).map_or(1024, |s| s.parse().unwrap());
    let prec = a.get(3).map_or("f64", |s| s.as_str());
    let threads: usize = a.get(4).map_or(1, |s| s.parse().unwrap());
    let reps: usize = a.get(5).map_or(5, |s| s.parse().unwrap());
    let collision = match a.get(6).map_or("bgk", |s| s.as_str()) {
        "trt" => Collision::Trt {
            tau: 1.0 / 1.8,
            magic: 0.25,
        },
        _ => Collision::Bgk { tau: 1.0 / 1.8 },
    };
    let two = a.get(7).is_some_and(|s| s == "two");
    let work: usize = a.get(8).map_or(60_000_000, |s| s.parse().unwrap());
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        if prec == "f32" {
            run::<f32>(nx, ny, reps, collision, two, work)
        } else {
            run::<f64>(nx, ny, reps, collision, two, work)
        }
    });
}
