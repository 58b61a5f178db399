//! `lbdem bench lbm`: D2Q9 BGK stream-collide throughput (MLUPS, million fluid-node updates per
//! second) on a periodic box at 256x192, 1024x1024 and 4096x4096, f64 and f32, on 1 and 2 threads,
//! each divided by a memory-traffic bound measured in the same run on the same array sizes.
//!
//! The bound of the in-place AA kernel (lbdem's default, 2 x 9 values moved per node update, no
//! write-allocate) is the largest node-update rate of, per repetition:
//! - the **fused in-place pass** (`lbdem_lbm::roofline::in_place_pass`): one read-modify-write pass
//!   over all 9 direction arrays of an array in the AA stepper's own padded layout, rows spread
//!   over the threads as the stepper spreads them (tasks of 4 rows, work stealing), blocks of two
//!   AVX-512 registers, one multiply per value: the AA kernel's bytes with the least work, so no
//!   correct kernel on that array runs faster;
//! - the **nine-pass ceiling** (the benchmark's former reference, kept for comparison): nine separate
//!   parallel in-place passes, one per array; on 2 threads it runs below the fused pass and lbmpy
//!   beat it, so alone it is *not* a bound;
//! - STREAM copy and triad (`bench::bandwidth`, 256 MiB arrays, measured once per configuration)
//!   converted with the AA byte count. STREAM counts no write-allocate, so a triad moves 4/3 of the
//!   bytes it is credited with and an in-place kernel can beat it; it is printed for comparison.
//!
//! Each timed kernel repetition is followed by one repetition of each in-array reference and the
//! printed ratio is the median of the per-repetition ratios (the machine is shared: load changes
//! hit both sides of a ratio alike). With `--peer` each configuration runs in three rounds, each
//! round = lbdem's repetitions followed by one lbmpy run (scripts/peer-lbmpy.sh, AA + AVX-512
//! variant, 3 blocks of 0.5 s unless LBMPY_BLOCKS / LBMPY_BLOCK_TIME say otherwise), and the printed
//! lbdem / lbmpy is the median of the three per-round ratios. The 1-minute load average is printed
//! before and after every configuration.
//!
//! Like with like: both codes run D2Q9 BGK (lbmpy's SRT) with relaxation rate 1.8 on a periodic
//! box with the AA in-place pattern, in the same precision and on the same number of threads;
//! lbdem's kernel in addition checks the range of ρ and u of every node every step (its failure
//! diagnosis) and keeps the plan for walls and obstacles, which lbmpy's generated kernel has not.
//! The two-array pull kernel (needed for Zou-He faces) is measured next to its own ceiling, a
//! 9-array copy to 9 other arrays (its traffic, write-allocate included).

use super::{BenchArgs, bandwidth, median};
use anyhow::{Context, Result};
use lbdem_lbm::layout::Layout;
use lbdem_lbm::{Collision, D2Q9, Domain, Fluid, Limits, Real, Settings, Stepper, StepperAa, roofline};
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
    /// 1-minute load average before and after this configuration.
    load: [f64; 2],
    /// lbdem's in-place AA kernel (the default for scenes without Zou-He faces), median MLUPS.
    mlups: f64,
    /// The AA bound (max of the references below, per repetition), median, node updates / s / 1e6.
    bound: f64,
    /// The same in GB/s (2 x 9 values per node update).
    bound_gbs: f64,
    /// Fused in-place 9-array pass in the AA layout (median).
    fused: f64,
    /// Nine separate in-place passes (the former reference; not a bound on 2 threads).
    nine_pass: f64,
    /// STREAM copy and triad (GB/s, STREAM byte counting, 256 MiB arrays) on this thread count.
    stream_copy_gbs: f64,
    stream_triad_gbs: f64,
    /// AA MLUPS / bound: the figure of merit (median of the per-repetition ratios, then of rounds).
    ratio_bound: f64,
    /// AA MLUPS / nine-pass ceiling (the former figure of merit).
    ratio_nine_pass: f64,
    /// AA bytes moved (2 × 9 × size_of T per node) per second over the better of STREAM copy and
    /// triad of this run: the issue's "bytes moved per node update / measured STREAM-style
    /// bandwidth". Not a bound where the lattice sits partly in L3 (1024² f32 is 38 MB).
    ratio_stream: f64,
    /// Per-round AA / bound ratios.
    ratio_bound_rounds: Vec<f64>,
    /// lbdem's two-array pull kernel.
    mlups_two_array: f64,
    /// Two-array 9-array copy ceiling (node updates per second / 1e6).
    ceiling_two_array: f64,
    /// Two-array MLUPS / two-array ceiling.
    ratio_two_array: f64,
    /// lbmpy median MLUPS per round, and lbdem / lbmpy (median of the per-round ratios).
    lbmpy_mlups: Vec<f64>,
    ratio_lbmpy: Option<f64>,
    ratio_lbmpy_rounds: Vec<f64>,
}

const Q: usize = 9;
/// Nodes per timed block of work, so that each timed run lasts about 0.2-0.5 s.
const WORK: usize = 60_000_000;
/// Rayon chunk of the nine-pass and copy ceilings (values).
const CHUNK: usize = 1 << 14;

fn steps_for(n: usize) -> usize {
    (WORK / n).max(2) & !1
}

fn fluid<T: Real>(nx: usize, ny: usize) -> Fluid<D2Q9, T> {
    let mut fluid = Fluid::<D2Q9, T>::new(Domain::periodic([nx, ny, 1]), Vec::new());
    // relaxation rate 1.8 as in lbmpy_bench.py; small perturbation so nothing is trivially constant
    fluid.init_equilibrium(|p| {
        (
            1.0 + 1e-4 * (((p[0] * 7 + p[1] * 13) % 17) as f64 / 17.0 - 0.5),
            [0.0; 3],
        )
    });
    fluid
}

fn settings() -> Settings {
    Settings {
        collision: Collision::Bgk { tau: 1.0 / 1.8 },
        force: [0.0; 3],
        limits: Limits::default(),
    }
}

/// Node updates per second / 1e6 of `steps` calls of `f` on `n` nodes.
fn rate(n: usize, steps: usize, mut f: impl FnMut()) -> f64 {
    let t = Instant::now();
    for _ in 0..steps {
        f();
    }
    (n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6
}

/// One round of the AA kernel against its references.
struct AaRound {
    mlups: f64,
    bound: f64,
    fused: f64,
    nine_pass: f64,
    /// Median over repetitions of kernel / bound, each timed back to back.
    ratio: f64,
    ratio_nine_pass: f64,
}

/// The AA stepper and the arrays of its references, kept across rounds.
struct AaCase<T: Real> {
    fluid: Fluid<D2Q9, T>,
    st: StepperAa<D2Q9, T>,
    layout: Layout,
    fused: Vec<T>,
    nine: Vec<(Vec<T>, usize)>,
    /// STREAM copy and triad as node-update rates with the AA byte count.
    stream: f64,
}

impl<T: Real> AaCase<T> {
    fn new(nx: usize, ny: usize, stream_gbs: f64) -> Result<Self> {
        let mut fluid = fluid::<T>(nx, ny);
        let st = StepperAa::new(&mut fluid, settings())?;
        let mut layout = st.layout();
        let fused = layout.pack(&vec![T::from_f64(1.0); Q * nx * ny], Q);
        let nine = (0..Q)
            .map(|i| aligned(nx * ny, T::from_f64(1.0 + i as f64)))
            .collect();
        let bytes = (2 * Q * std::mem::size_of::<T>()) as f64;
        Ok(Self {
            fluid,
            st,
            layout,
            fused,
            nine,
            stream: stream_gbs * 1e9 / bytes / 1e6,
        })
    }

    /// `reps` timed blocks after one warm-up block, each followed by one block of each reference.
    fn round(&mut self, reps: usize) -> Result<AaRound> {
        let [nx, ny, _] = self.fluid.domain.n;
        let n = nx * ny;
        let steps = steps_for(n);
        // alternate the factor so that the reference arrays neither decay nor grow
        let (s, s_inv) = (T::from_f64(0.999), T::from_f64(1.0 / 0.999));
        let (mut k, mut b, mut fu, mut ni, mut r, mut rn) = (vec![], vec![], vec![], vec![], vec![], vec![]);
        for rep in 0..=reps {
            let t = Instant::now();
            for _ in 0..steps {
                self.st.step(&mut self.fluid, None)?;
            }
            let kernel = (n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6;
            let (lay, base, part) = (self.layout, self.layout.base, self.st.partition);
            let f = &mut self.fused;
            let mut flip = false;
            let fused = rate(n, steps, || {
                flip = !flip;
                roofline::in_place_pass(&mut f[base..], &lay, Q, ny, part, if flip { s } else { s_inv });
            });
            let nine = &mut self.nine;
            let mut flip = false;
            let nine_pass = rate(n, steps, || {
                flip = !flip;
                let x = if flip { s } else { s_inv };
                for (arr, o) in nine.iter_mut() {
                    arr[*o..*o + n]
                        .par_chunks_mut(CHUNK)
                        .for_each(|c| c.iter_mut().for_each(|v| *v = *v * x));
                }
            });
            let bound = fused.max(nine_pass).max(self.stream);
            if rep > 0 {
                k.push(kernel);
                b.push(bound);
                fu.push(fused);
                ni.push(nine_pass);
                r.push(kernel / bound);
                rn.push(kernel / nine_pass);
            }
        }
        std::hint::black_box((&self.fused, &self.nine));
        Ok(AaRound {
            mlups: median(&k),
            bound: median(&b),
            fused: median(&fu),
            nine_pass: median(&ni),
            ratio: median(&r),
            ratio_nine_pass: median(&rn),
        })
    }
}

/// The two-array kernel against a 9-array copy to 9 other arrays (its traffic, write-allocate
/// included), repetition by repetition: (median MLUPS, median ceiling, median ratio).
fn two_array<T: Real>(nx: usize, ny: usize, reps: usize) -> Result<(f64, f64, f64)> {
    let n = nx * ny;
    let mut fluid = fluid::<T>(nx, ny);
    let mut st = Stepper::new(&fluid, settings())?;
    let src: Vec<_> = (0..Q).map(|i| aligned(n, T::from_f64(1.0 + i as f64))).collect();
    let mut dst: Vec<_> = (0..Q).map(|_| aligned(n, T::default())).collect();
    let steps = steps_for(n);
    let (mut rates, mut ceils, mut ratios) = (Vec::new(), Vec::new(), Vec::new());
    for rep in 0..=reps {
        let t = Instant::now();
        for _ in 0..steps {
            st.step(&mut fluid, None)?;
        }
        let k = (n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6;
        let c = rate(n, steps, || {
            for ((d, od), (s, os)) in dst.iter_mut().zip(&src) {
                d[*od..*od + n]
                    .par_chunks_mut(CHUNK)
                    .zip(s[*os..*os + n].par_chunks(CHUNK))
                    .for_each(|(d, s)| d.copy_from_slice(s));
            }
        });
        if rep > 0 {
            rates.push(k);
            ceils.push(c);
            ratios.push(k / c);
        }
    }
    std::hint::black_box(&dst);
    Ok((median(&rates), median(&ceils), median(&ratios)))
}

/// `n` values of `x` starting on a 64-byte boundary, as the kernel's arrays (`lbdem_lbm::layout`):
/// the vector and the offset of the first value.
fn aligned<T: Real>(n: usize, x: T) -> (Vec<T>, usize) {
    let v = vec![x; n + 64 / std::mem::size_of::<T>()];
    let off = v.as_ptr().align_offset(64);
    (v, off)
}

/// 1-minute load average (NaN where /proc/loadavg is missing).
fn load() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(f64::NAN)
}

/// lbmpy's median MLUPS for one configuration, or None (with a note) if it cannot run.
fn lbmpy(nx: usize, ny: usize, precision: &str, threads: usize) -> Option<f64> {
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/peer-lbmpy.sh");
    let dtype = if precision == "f64" { "float64" } else { "float32" };
    let mut cmd = Command::new("bash");
    cmd.arg(&script).args([
        format!("{nx}x{ny}"),
        dtype.into(),
        threads.to_string(),
        "aa".into(),
    ]);
    for (var, default) in [("LBMPY_BLOCKS", "3"), ("LBMPY_BLOCK_TIME", "0.5")] {
        if std::env::var_os(var).is_none() {
            cmd.env(var, default);
        }
    }
    let parse = |o: std::process::Output| -> Option<f64> {
        let line = String::from_utf8_lossy(&o.stdout).lines().last()?.to_string();
        serde_json::from_str::<serde_json::Value>(&line)
            .ok()?
            .get("median")?
            .as_f64()
    };
    match cmd.output() {
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

/// One configuration: STREAM, then `rounds` rounds of the AA kernel (each followed by lbmpy if
/// `peer`), then the two-array kernel.
fn config<T: Real>(
    a: &BenchArgs,
    nx: usize,
    ny: usize,
    threads: usize,
    precision: &'static str,
) -> Result<Row> {
    let load0 = load();
    let bw = bandwidth::measure(threads, bandwidth::default_len(a.quick), 3)?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    let rounds = if a.peer { 3 } else { 1 };
    let mut case = pool.install(|| AaCase::<T>::new(nx, ny, bw.copy_gbs.max(bw.triad_gbs)))?;
    let (mut aa, mut peer) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        aa.push(pool.install(|| case.round(a.reps))?);
        if a.peer
            && let Some(p) = lbmpy(nx, ny, precision, threads)
        {
            peer.push((p, aa.last().map_or(f64::NAN, |r| r.mlups / p)));
        }
    }
    drop(case);
    let (m2, c2, r2) = pool.install(|| two_array::<T>(nx, ny, a.reps))?;
    let med = |f: fn(&AaRound) -> f64| median(&aa.iter().map(f).collect::<Vec<_>>());
    let bound = med(|r| r.bound);
    let ratio_lbmpy_rounds: Vec<f64> = peer.iter().map(|p| p.1).collect();
    Ok(Row {
        nx,
        ny,
        precision,
        threads,
        load: [load0, load()],
        mlups: med(|r| r.mlups),
        bound,
        bound_gbs: bound * 1e6 * (2 * Q * std::mem::size_of::<T>()) as f64 / 1e9,
        fused: med(|r| r.fused),
        nine_pass: med(|r| r.nine_pass),
        stream_copy_gbs: bw.copy_gbs,
        stream_triad_gbs: bw.triad_gbs,
        ratio_bound: med(|r| r.ratio),
        ratio_nine_pass: med(|r| r.ratio_nine_pass),
        ratio_stream: med(|r| r.mlups) * 1e6 * (2 * Q * std::mem::size_of::<T>()) as f64
            / 1e9
            / bw.copy_gbs.max(bw.triad_gbs),
        ratio_bound_rounds: aa.iter().map(|r| r.ratio).collect(),
        mlups_two_array: m2,
        ceiling_two_array: c2,
        ratio_two_array: r2,
        lbmpy_mlups: peer.iter().map(|p| p.0).collect(),
        ratio_lbmpy: (!peer.is_empty()).then(|| median(&ratio_lbmpy_rounds)),
        ratio_lbmpy_rounds,
    })
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
         bound = max(fused in-place 9-array pass in the AA layout, nine-pass ceiling, STREAM x 144|72 B) \
         per repetition, measured in this run"
    );
    let mut rows = Vec::new();
    for &(nx, ny) in &sizes {
        for precision in ["f64", "f32"] {
            for threads in [1, 2] {
                let row = if precision == "f64" {
                    config::<f64>(a, nx, ny, threads, "f64")?
                } else {
                    config::<f32>(a, nx, ny, threads, "f32")?
                };
                print_row(&row, a.peer);
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

fn print_row(r: &Row, peer: bool) {
    let pct = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{:.0}", 100.0 * x))
            .collect::<Vec<_>>()
            .join(" ")
    };
    println!(
        "lbm D2Q9 BGK {}x{} {} t={} (load {:.2} -> {:.2}): AA {:6.1} MLUPS = {:3.0}% of bound {:6.1} \
         ({:4.1} GB/s; rounds [{}]) | fused {:6.1}, nine-pass {:6.1} (AA = {:3.0}% of it), STREAM copy/triad \
         {:4.1}/{:4.1} GB/s (AA = {:3.0}% of the STREAM limit) | two-array {:6.1} = {:3.0}% of two-array ceiling {:6.1}{}",
        r.nx,
        r.ny,
        r.precision,
        r.threads,
        r.load[0],
        r.load[1],
        r.mlups,
        100.0 * r.ratio_bound,
        r.bound,
        r.bound_gbs,
        pct(&r.ratio_bound_rounds),
        r.fused,
        r.nine_pass,
        100.0 * r.ratio_nine_pass,
        r.stream_copy_gbs,
        r.stream_triad_gbs,
        100.0 * r.ratio_stream,
        r.mlups_two_array,
        100.0 * r.ratio_two_array,
        r.ceiling_two_array,
        match r.ratio_lbmpy {
            Some(q) => format!(
                " | lbmpy AA {} -> lbdem/lbmpy {q:.2} (rounds [{}])",
                r.lbmpy_mlups
                    .iter()
                    .map(|x| format!("{x:.0}"))
                    .collect::<Vec<_>>()
                    .join(" "),
                r.ratio_lbmpy_rounds
                    .iter()
                    .map(|x| format!("{x:.2}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            ),
            None if peer => " | lbmpy n/a".into(),
            None => String::new(),
        }
    );
}
