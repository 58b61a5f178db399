//! `lbdem bench grains`: the digitise kernels on synthetic images of ~1000 and ~300 touching disks
//! and two-circle grains (`lbdem_grains::synth`). Prints, median of `--reps` runs on 1 and
//! 2 threads: grains per second for the whole chain (threshold, distance transform,
//! watershed, measures, two-circle fits, templates) and for the fits alone, and the chain's
//! input traffic (8 bytes per pixel) as a fraction of the STREAM triad bandwidth measured
//! in the same run. The target of issue 5: a thousand grains under a second on 2 cores.

use super::{BenchArgs, bandwidth, median};
use anyhow::Result;
use lbdem_grains::measure::GrainPixels;
use lbdem_grains::synth::{SynthSpec, generate};
use lbdem_grains::twocircle::fit_grain;
use lbdem_grains::{Params, digitise};
use rayon::prelude::*;
use std::time::Instant;

#[derive(serde::Serialize)]
struct Row {
    threads: usize,
    grains: usize,
    pixels: usize,
    chain_s: f64,
    chain_grains_per_s: f64,
    fit_grains_per_s: f64,
    triad_gbs: f64,
    chain_fraction_of_triad: f64,
}

pub fn run(a: &BenchArgs) -> Result<()> {
    // Two sizes, so the cost growth with size is on record beside the growth with threads
    // (issue 18 item 6).
    let sizes: [(usize, usize); 2] = if a.quick {
        [(560, 300), (400, 150)]
    } else {
        [(1100, 1000), (560, 300)]
    };
    let mut rows = Vec::new();
    for (side, n) in sizes {
        rows.extend(one_size(a, side, n)?);
    }
    if let Some(p) = &a.json {
        lbdem_core::atomic::write_atomic(p, &serde_json::to_vec_pretty(&rows)?)?;
    }
    Ok(())
}

/// One synthetic image of `n` grains on a `side`² image, on 1 and 2 threads.
fn one_size(a: &BenchArgs, side: usize, n: usize) -> Result<Vec<Row>> {
    let spec = SynthSpec {
        width: side,
        height: side,
        n_grains: n,
        d_mean_px: 30.0,
        d_spread: 0.25,
        seed: 11,
        ..SynthSpec::default()
    };
    let img = generate(&spec);
    let pixels = side * side;
    println!(
        "grains: synthetic {side} x {side} px image with {} grains (d = 30 px +- 25 %)",
        img.grains.len()
    );
    let params = Params::default();
    let mut rows = Vec::new();
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
        let (mut chain, mut fit) = (Vec::new(), Vec::new());
        let mut found = 0;
        for _ in 0..a.reps.max(1) {
            let t = Instant::now();
            let d = pool.install(|| digitise(img.image.view(), &params))?;
            chain.push(t.elapsed().as_secs_f64());
            found = d.grains.len();
            // The fits alone, on the segmentation just made.
            let px = GrainPixels::from_labels(d.labels.view(), d.grains.len());
            let flat = d.labels.as_slice().expect("standard layout");
            let w = d.labels.dim().1;
            let t = Instant::now();
            let fits: Vec<_> = pool.install(|| {
                (0..d.grains.len())
                    .into_par_iter()
                    .map(|g| fit_grain(&d.grains[g], px.of(g), flat, w, params.round_aspect))
                    .collect()
            });
            fit.push(t.elapsed().as_secs_f64());
            std::hint::black_box(fits);
        }
        let bw = bandwidth::measure(threads, bandwidth::default_len(a.quick), a.reps)?;
        let chain_s = median(&chain);
        let row = Row {
            threads,
            grains: found,
            pixels,
            chain_s,
            chain_grains_per_s: found as f64 / chain_s,
            fit_grains_per_s: found as f64 / median(&fit),
            triad_gbs: bw.triad_gbs,
            chain_fraction_of_triad: (pixels * 8) as f64 / chain_s / 1e9 / bw.triad_gbs,
        };
        println!(
            "grains  threads={threads}  {} grains in {:.3} s: {:.0} grains/s (chain), {:.0} grains/s (fits alone); \
             input {:.3} GB/s = {:.4} of triad {:.1} GB/s",
            row.grains,
            row.chain_s,
            row.chain_grains_per_s,
            row.fit_grains_per_s,
            (pixels * 8) as f64 / chain_s / 1e9,
            row.chain_fraction_of_triad,
            row.triad_gbs
        );
        rows.push(row);
    }
    Ok(rows)
}
