//! `lbdem bench lbm`: D2Q9 BGK stream-collide throughput (MLUPS, million fluid-node updates per
//! second) on a periodic box at 256x192, 1024x1024 and 4096x4096, f64 and f32, on 1 and 2 threads,
//! each next to two memory-traffic ceilings measured in the same run on the same array sizes:
//! a 9-array two-array copy (read 9 values, write 9 others per node: the traffic of lbdem's
//! two-array pull kernel, write-allocate included) and a 9-array in-place update (read and write
//! the same 9 values: the traffic of an AA-pattern kernel such as lbmpy's fastest). With `--peer`
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

/// Median MLUPS of `reps` timed blocks after one warm-up block (AA kernel if `aa`).
fn lbm_mlups<T: Real>(nx: usize, ny: usize, reps: usize, aa: bool) -> Result<f64> {
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
    // only the kernel measured allocates its scratch (4096² f64 is 1.2 GB per population array)
    let (mut two, mut st_aa) = if aa {
        (None, Some(StepperAa::new(&mut fluid, settings)?))
    } else {
        (Some(Stepper::new(&fluid, settings)?), None)
    };
    let steps = steps_for(nx * ny) & !1;
    let mut rates = Vec::new();
    for rep in 0..=reps {
        let t = Instant::now();
        for _ in 0..steps {
            match (st_aa.as_mut(), two.as_mut()) {
                (Some(s), _) => s.step(&mut fluid, None)?,
                (None, Some(s)) => s.step(&mut fluid, None)?,
                (None, None) => unreachable!(),
            }
        }
        if rep > 0 {
            rates.push((nx * ny * steps) as f64 / t.elapsed().as_secs_f64() / 1e6);
        }
    }
    Ok(median(&rates))
}

/// `n` values of `x` starting on a 64-byte boundary, as the kernel's arrays (`lbdem_lbm::layout`):
/// the vector and the offset of the first value.
fn aligned<T: Real>(n: usize, x: T) -> (Vec<T>, usize) {
    let v = vec![x; n + 64 / std::mem::size_of::<T>()];
    let off = v.as_ptr().align_offset(64);
    (v, off)
}

/// Median node-update rates (MLUPS-equivalent) of the two traffic ceilings on 9 arrays of n values.
fn ceilings<T: Real>(n: usize, reps: usize) -> (f64, f64) {
    const CHUNK: usize = 1 << 14;
    let a: Vec<_> = (0..Q).map(|i| aligned(n, T::from_f64(1.0 + i as f64))).collect();
    let mut b: Vec<_> = (0..Q).map(|_| aligned(n, T::default())).collect();
    let mut c: Vec<_> = (0..Q).map(|i| aligned(n, T::from_f64(1.0 + i as f64))).collect();
    let steps = steps_for(n);
    let s = T::from_f64(0.999);
    let (mut two, mut inplace) = (Vec::new(), Vec::new());
    for rep in 0..=reps {
        let t = Instant::now();
        for _ in 0..steps {
            for ((d, od), (s, os)) in b.iter_mut().zip(&a) {
                d[*od..*od + n]
                    .par_chunks_mut(CHUNK)
                    .zip(s[*os..*os + n].par_chunks(CHUNK))
                    .for_each(|(d, s)| d.copy_from_slice(s));
            }
        }
        let t_two = t.elapsed().as_secs_f64();
        let t = Instant::now();
        for _ in 0..steps {
            for (arr, o) in c.iter_mut() {
                arr[*o..*o + n]
                    .par_chunks_mut(CHUNK)
                    .for_each(|x| x.iter_mut().for_each(|v| *v = *v * s));
            }
        }
        let t_in = t.elapsed().as_secs_f64();
        if rep > 0 {
            two.push((n * steps) as f64 / t_two / 1e6);
            inplace.push((n * steps) as f64 / t_in / 1e6);
        }
    }
    std::hint::black_box((&b, &c));
    (median(&two), median(&inplace))
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
    let sizes: &[(usize, usize)] = if a.quick {
        &[(256, 192)]
    } else {
        &[(256, 192), (1024, 1024), (4096, 4096)]
    };
    println!(
        "lbm: D2Q9 BGK (lbmpy: SRT), relaxation rate 1.8, periodic; AA in-place kernels on both sides; \
         ceilings = 9-array updates of the same size measured in this run"
    );
    let mut rows = Vec::new();
    for &(nx, ny) in sizes {
        for precision in ["f64", "f32"] {
            for threads in [1, 2] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
                let (mlups, m2, (c2, ci)) = pool.install(|| -> Result<_> {
                    Ok(if precision == "f64" {
                        (
                            lbm_mlups::<f64>(nx, ny, a.reps, true)?,
                            lbm_mlups::<f64>(nx, ny, a.reps, false)?,
                            ceilings::<f64>(nx * ny, a.reps),
                        )
                    } else {
                        (
                            lbm_mlups::<f32>(nx, ny, a.reps, true)?,
                            lbm_mlups::<f32>(nx, ny, a.reps, false)?,
                            ceilings::<f32>(nx * ny, a.reps),
                        )
                    })
                })?;
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
                    ratio_in_place: mlups / ci,
                    ratio_two_array: m2 / c2,
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
