//! STREAM-like memory bandwidth (copy and triad, STREAM's byte counting: reads plus
//! writes, no write-allocate), the ceiling every bandwidth-bound kernel is compared to.

use super::{BenchArgs, median};
use anyhow::Result;
use rayon::prelude::*;
use std::time::Instant;

#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Bandwidth {
    pub threads: usize,
    /// GB/s (1e9 bytes per second).
    pub copy_gbs: f64,
    pub triad_gbs: f64,
}

const CHUNK: usize = 1 << 16;

/// Median over `reps` of copy and triad with `n` f64 per array on a pool of `threads`.
pub fn measure(threads: usize, n: usize, reps: usize) -> Result<Bandwidth> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    pool.install(|| {
        let mut a = vec![0.0f64; n];
        let b: Vec<f64> = (0..n).into_par_iter().map(|i| i as f64).collect();
        let c: Vec<f64> = (0..n).into_par_iter().map(|i| 0.5 * i as f64).collect();
        let (mut copy, mut triad) = (Vec::new(), Vec::new());
        for _ in 0..reps.max(1) {
            let t = Instant::now();
            a.par_chunks_mut(CHUNK)
                .zip(b.par_chunks(CHUNK))
                .for_each(|(a, b)| a.copy_from_slice(b));
            copy.push((2 * n * 8) as f64 / t.elapsed().as_secs_f64() / 1e9);
            let t = Instant::now();
            a.par_chunks_mut(CHUNK)
                .zip(b.par_chunks(CHUNK).zip(c.par_chunks(CHUNK)))
                .for_each(|(a, (b, c))| {
                    a.iter_mut()
                        .zip(b.iter().zip(c))
                        .for_each(|(a, (b, c))| *a = b + 3.0 * c)
                });
            triad.push((3 * n * 8) as f64 / t.elapsed().as_secs_f64() / 1e9);
        }
        std::hint::black_box(&a);
        Ok(Bandwidth {
            threads,
            copy_gbs: median(&copy),
            triad_gbs: median(&triad),
        })
    })
}

/// Array length giving ~256 MiB per array (well past the last-level cache), or 32 MiB quick.
pub fn default_len(quick: bool) -> usize {
    if quick { 1 << 22 } else { 1 << 25 }
}

pub fn run(a: &BenchArgs) -> Result<()> {
    // Two sizes (issue 18 item 6): the memory's (256 MiB per array, or 32 MiB quick) and an
    // eighth of it, which on a large last-level cache runs partly from the cache.
    let big = default_len(a.quick);
    let mut all = Vec::new();
    for n in [big, big / 8] {
        for threads in [1, 2] {
            let bw = measure(threads, n, a.reps)?;
            println!(
                "bandwidth  {:4} MiB per array  threads={threads}  copy {:.1} GB/s  triad {:.1} GB/s",
                (n * 8) >> 20,
                bw.copy_gbs,
                bw.triad_gbs
            );
            all.push(serde_json::json!({
                "mib_per_array": (n * 8) >> 20, "threads": bw.threads,
                "copy_gbs": bw.copy_gbs, "triad_gbs": bw.triad_gbs,
            }));
        }
    }
    if let Some(p) = &a.json {
        lbdem_core::atomic::write_atomic(p, &serde_json::to_vec_pretty(&all)?)?;
    }
    Ok(())
}
