//! `lbdem bench lbm`: D2Q9 BGK stream-collide throughput (MLUPS, million fluid-node updates per
//! second) on a periodic box at 256x192, 1024x1024 and 4096x4096, f64 and f32, on 1 and 2 threads,
//! each next to two memory-traffic ceilings measured in the same run on the same array sizes:
//! a 9-array two-array copy (read 9 values, write 9 others per node: the traffic of lbdem's
//! two-array pull kernel, write-allocate included) and a 9-array in-place update (read and write
//! the same 9 values: the traffic of an AA-pattern kernel such as lbmpy's fastest). Every timed
//! repetition of a kernel is followed by one of its ceiling and the printed ratio is the median of
//! the per-repetition ratios (the machine is shared: load changes hit both sides alike). With `--peer`
//! it also runs lbmpy (scripts/peer-lbmpy.sh, AA + AVX-512 variant) and prints lbdem / lbmpy.
//!
//! Like with like: both codes run D2Q9 BGK (lbmpy's SRT) with relaxation rate 1.8 on a periodic
//! box with the AA in-place pattern, in the same precision and on the same number of threads;
//! lbdem's kernel in addition checks the range of ρ and u of every node every step (its failure
//! diagnosis) and keeps the plan for walls and obstacles, which lbmpy's generated kernel has not.

use super::{BenchArgs, median};
use anyhow::{Context, Result};
use lbdem_lbm::{Collision, D2Q9, Domain, Fluid, Limits, Real, Settings, Stepper, StepperAa};
use rayon::prelude::*;
use serde::Serialize;
use std::process::Command;
use std::time::Instant;

#[derive(Debug, Serialize)]
struct Row {
    nx: usize,
    ny: usize,
    precision: &'static str,
    threads: usize,
    /// lbdem's in-place AA kernel (the default for scenes without Zou-He faces).
    mlups: f64,
    /// lbdem's two-array pull kernel.
    mlups_two_array: f64,
    /// Two-array 9-array copy ceiling (node updates per second / 1e6).
    ceiling_two_array: f64,
    /// In-place 9-array update ceiling.
    ceiling_in_place: f64,
    /// The memory bandwidth that ceiling stands for: 2 x 9 values per node update (GB/s).
    ceiling_in_place_gbs: f64,
    /// AA MLUPS / in-place ceiling: the figure of merit.
    ratio_in_place: f64,
    /// Two-array MLUPS / two-array ceiling.
    ratio_two_array: f64,
    lbmpy_mlups: Option<f64>,
    ratio_lbmpy: Option<f64>,
}

const Q: usize = 9;
/// Nodes per timed block of work, so that each timed run lasts about 0.2-0.5 s.
const WORK: usize = 60_000_000;

fn steps_for(n: usize) -> usize {
    (WORK / n).max(2)
}

/// One kernel measured against its traffic ceiling, repetition by repetition.
struct Measured {
    /// Median MLUPS of the kernel.
    mlups: f64,
    /// Median node-update rate of the ceiling (MLUPS-equivalent).
    ceiling: f64,
    /// Median over repetitions of kernel / ceiling, each pair timed back to back, so that a
    /// change of load on the shared machine hits both sides of a ratio alike.
    ratio: f64,
}

/// The kernel (AA if `aa`, else two-array) for `reps` timed blocks after one warm-up block, each
/// followed by one block of its ceiling on 9 arrays of the same size (64-byte aligned): an
/// in-place update (AA traffic) or a copy to 9 other arrays (two-array traffic, write-allocate
/// included). Only the kernel measured and its ceiling hold memory at a time (4096² f64 is
/// 1.2 GB per population array).
fn measure<T: Real>(nx: usize, ny: usize, reps: usize, aa: bool) -> Result<Measured> {
    const CHUNK: usize = 1 << 14;
    let n = nx * ny;
    let mut fluid = Fluid::<D2Q9, T>::new(Domain::periodic([nx, ny, 1]), Vec::new());
    // relaxation rate 1.8 as in lbmpy_bench.py; small perturbation so nothing is trivially constant
    fluid.init_equilibrium(|p| {
        (
            1.0 + 1e-4 * (((p[0] * 7 + p[1] * 13) % 17) as f64 / 17.0 - 0.5),
            [0.0; 3],
        )
    });
    let settings = Settings {
        collision: Collision::Bgk { tau: 1.0 / 1.8 },
        force: [0.0; 3],
        limits: Limits::default(),
    };
    let (mut two, mut st_aa) = if aa {
        (None, Some(StepperAa::new(&mut fluid, settings)?))
    } else {
        (Some(Stepper::new(&fluid, settings)?), None)
    };
    let mut src: Vec<_> = (0..Q).map(|i| aligned(n, T::from_f64(1.0 + i as f64))).collect();
    let mut dst: Vec<_> = if aa {
        Vec::new()
    } else {
        (0..Q).map(|_| aligned(n, T::default())).collect()
    };
    let scale = T::from_f64(0.999);
    let steps = steps_for(n) & !1;
    let (mut rates, mut ceils, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    for rep in 0..=reps {
        let t = Instant::now();
        for _ in 0..steps {
            match (st_aa.as_mut(), two.as_mut()) {
                (Some(s), _) => s.step(&mut fluid, None)?,
                (None, Some(s)) => s.step(&mut fluid, None)?,
                (None, None) => unreachable!(),
            }
        }
        let rate = (n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6;
        let t = Instant::now();
        for _ in 0..steps {
            if aa {
                for (arr, o) in src.iter_mut() {
                    arr[*o..*o + n]
                        .par_chunks_mut(CHUNK)
                        .for_each(|x| x.iter_mut().for_each(|v| *v = *v * scale));
                }
            } else {
                for ((d, od), (s, os)) in dst.iter_mut().zip(&src) {
                    d[*od..*od + n]
                        .par_chunks_mut(CHUNK)
                        .zip(s[*os..*os + n].par_chunks(CHUNK))
                        .for_each(|(d, s)| d.copy_from_slice(s));
                }
            }
        }
        let ceil = (n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6;
        if rep > 0 {
            rates.push(rate);
            ceils.push(ceil);
            ratios.push(rate / ceil);
        }
    }
    std::hint::black_box((&src, &dst));
    Ok(Measured {
        mlups: median(&rates),
        ceiling: median(&ceils),
        ratio: median(&ratios),
    })
}

/// `n` values of `x` starting on a 64-byte boundary, as the kernel's arrays (`lbdem_lbm::layout`):
/// the vector and the offset of the first value.
fn aligned<T: Real>(n: usize, x: T) -> (Vec<T>, usize) {
    let v = vec![x; n + 64 / std::mem::size_of::<T>()];
    let off = v.as_ptr().align_offset(64);
    (v, off)
}

/// lbmpy's median MLUPS for one configuration, or None (with a note) if it cannot run.
fn lbmpy(nx: usize, ny: usize, precision: &str, threads: usize) -> Option<f64> {
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/peer-lbmpy.sh");
    let dtype = if precision == "f64" { "float64" } else { "float32" };
    let out = Command::new("bash")
        .arg(&script)
        .args([
            format!("{nx}x{ny}"),
            dtype.into(),
            threads.to_string(),
            "aa".into(),
        ])
        .output();
    let parse = |o: std::process::Output| -> Option<f64> {
        let line = String::from_utf8_lossy(&o.stdout).lines().last()?.to_string();
        serde_json::from_str::<serde_json::Value>(&line)
            .ok()?
            .get("median")?
            .as_f64()
    };
    match out {
        Ok(o) if o.status.success() => parse(o),
        Ok(o) => {
            eprintln!("lbmpy failed: {}", String::from_utf8_lossy(&o.stderr).trim());
            None
        }
        Err(e) => {
            eprintln!("lbmpy: cannot run {}: {e}", script.display());
            None
        }
    }
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let mut sizes: Vec<(usize, usize)> = if a.quick {
        vec![(256, 192)]
    } else {
        vec![(256, 192), (1024, 1024), (4096, 4096)]
    };
    // LBDEM_BENCH_LBM_SIZE=1024x1024 runs one size only (to repeat a case on a busy machine)
    if let Ok(v) = std::env::var("LBDEM_BENCH_LBM_SIZE") {
        let (x, y) = v
            .split_once('x')
            .and_then(|(x, y)| Some((x.parse().ok()?, y.parse().ok()?)))
            .with_context(|| format!("LBDEM_BENCH_LBM_SIZE = {v:?}: expected NXxNY, e.g. 1024x1024"))?;
        sizes = vec![(x, y)];
    }
    println!(
        "lbm: D2Q9 BGK (lbmpy: SRT), relaxation rate 1.8, periodic; AA in-place kernels on both sides; \
         ceilings = 9-array updates of the same size measured in this run"
    );
    let mut rows = Vec::new();
    for &(nx, ny) in &sizes {
        for precision in ["f64", "f32"] {
            for threads in [1, 2] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
                let (aa, two) = pool.install(|| -> Result<_> {
                    Ok(if precision == "f64" {
                        (
                            measure::<f64>(nx, ny, a.reps, true)?,
                            measure::<f64>(nx, ny, a.reps, false)?,
                        )
                    } else {
                        (
                            measure::<f32>(nx, ny, a.reps, true)?,
                            measure::<f32>(nx, ny, a.reps, false)?,
                        )
                    })
                })?;
                let (mlups, m2, c2, ci) = (aa.mlups, two.mlups, two.ceiling, aa.ceiling);
                let bytes = if precision == "f64" { 8 } else { 4 };
                let peer = if a.peer {
                    lbmpy(nx, ny, precision, threads)
                } else {
                    None
                };
                let row = Row {
                    nx,
                    ny,
                    precision,
                    threads,
                    mlups,
                    mlups_two_array: m2,
                    ceiling_two_array: c2,
                    ceiling_in_place: ci,
                    ceiling_in_place_gbs: ci * 1e6 * (2 * Q * bytes) as f64 / 1e9,
                    ratio_in_place: aa.ratio,
                    ratio_two_array: two.ratio,
                    lbmpy_mlups: peer,
                    ratio_lbmpy: peer.map(|p| mlups / p),
                };
                println!(
                    "lbm D2Q9 BGK {nx}x{ny} {precision} t={threads}: AA {mlups:6.1} MLUPS = {:3.0}% of in-place \
                     ceiling {ci:6.1} ({:4.1} GB/s) | two-array {m2:6.1} = {:3.0}% of two-array ceiling {c2:6.1}{}",
                    100.0 * row.ratio_in_place,
                    row.ceiling_in_place_gbs,
                    100.0 * row.ratio_two_array,
                    match peer {
                        Some(p) => format!(" | lbmpy AA {p:7.1} -> lbdem/lbmpy {:.2}", mlups / p),
                        None if a.peer => " | lbmpy n/a".into(),
                        None => String::new(),
                    }
                );
                rows.push(row);
            }
        }
    }
    if let Some(p) = &a.json {
        lbdem_core::atomic::write_atomic(p, &serde_json::to_vec_pretty(&rows)?)
            .with_context(|| format!("cannot write {}", p.display()))?;
    }
    Ok(())
}
