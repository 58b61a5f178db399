//! `lbdem bench lbm`: BGK stream-collide throughput (MLUPS, million fluid-node updates per
//! second) on a periodic box, D2Q9 at 256x192, 1024x1024 and 4096x4096 and D3Q19 at 128³, in each
//! precision (`lbdem_lbm::Precision`: f64, f32, and the AA kernel's narrower storages f32s = f32
//! storage of f − w with f64 arithmetic and f16s = 16-bit storage of f − w with f32 arithmetic),
//! on 1 and 2 threads, each divided by a memory-traffic bound measured in the same run on the same
//! array sizes. `LBDEM_BENCH_LBM_SIZE=NXxNY` (D2Q9) or `NXxNYxNZ` (D3Q19) runs one size,
//! `LBDEM_BENCH_LBM_PRECISION=f32s,f16s` the listed precisions only.
//!
//! The bound of the in-place AA kernel (lbdem's default, 2 x Q stored values moved per node update,
//! no write-allocate) is the largest node-update rate of, per repetition:
//! - the **fused in-place pass** (`lbdem_lbm::roofline::in_place_pass`): one read-modify-write pass
//!   over all Q direction arrays of an array in the AA stepper's own padded layout and storage type
//!   (a bit flip per value for the 16-bit storage, a multiply otherwise), rows spread
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
//! box with the AA in-place pattern, in the same precision and on the same number of threads (the
//! narrower storages are compared with lbmpy's f64 kernel, the aim of issue 18: f32s computes in
//! f64, and f16s is meant to replace it where its accuracy suffices, `tests/storage.rs`);
//! lbdem's kernel in addition checks the range of ρ and u of every node every step (its failure
//! diagnosis) and keeps the plan for walls and obstacles, which lbmpy's generated kernel has not.
//! The two-array pull kernel (needed for Zou-He faces; f64 and f32 only) is measured next to its own
//! ceiling, a Q-array copy to Q other arrays (its traffic, write-allocate included). For D3Q19 the
//! lbmpy driver is called directly with `--stencil D3Q19` (scripts/peer-lbmpy.sh runs D2Q9 only);
//! it uses the script's venv.

use super::{BenchArgs, bandwidth, median};
use anyhow::{Context, Result};
use lbdem_lbm::layout::Layout;
use lbdem_lbm::{
    Collision, D2Q9, D3Q19, Domain, Fluid, Lattice, Limits, Precision, Real, Settings, ShiftedF16,
    ShiftedF32, Stepper, StepperAa, Storage, roofline,
};
use rayon::prelude::*;
use serde::Serialize;
use std::process::Command;
use std::time::Instant;

#[derive(Debug, Serialize)]
struct Row {
    lattice: &'static str,
    nx: usize,
    ny: usize,
    nz: usize,
    precision: &'static str,
    /// Bytes per stored population.
    bytes: usize,
    threads: usize,
    /// 1-minute load average before and after this configuration.
    load: [f64; 2],
    /// lbdem's in-place AA kernel (the default for scenes without Zou-He faces), median MLUPS.
    mlups: f64,
    /// The AA bound (max of the references below, per repetition), median, node updates / s / 1e6.
    bound: f64,
    /// The same in GB/s (2 x Q stored values per node update).
    bound_gbs: f64,
    /// Fused in-place Q-array pass in the AA layout (median).
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
    /// AA bytes moved (2 × Q × bytes per node) per second over the better of STREAM copy and
    /// triad of this run: the issue's "bytes moved per node update / measured STREAM-style
    /// bandwidth". Not a bound where the lattice sits partly in L3 (1024² f32 is 38 MB).
    ratio_stream: f64,
    /// Per-round AA / bound ratios.
    ratio_bound_rounds: Vec<f64>,
    /// lbdem's two-array pull kernel (f64 and f32 storage only).
    mlups_two_array: Option<f64>,
    /// Two-array Q-array copy ceiling (node updates per second / 1e6).
    ceiling_two_array: Option<f64>,
    /// Two-array MLUPS / two-array ceiling.
    ratio_two_array: Option<f64>,
    /// lbmpy's precision ("f64" for f64, f32s and f16s; "f32" for f32).
    lbmpy_precision: &'static str,
    /// lbmpy median MLUPS per round, and lbdem / lbmpy (median of the per-round ratios).
    lbmpy_mlups: Vec<f64>,
    ratio_lbmpy: Option<f64>,
    ratio_lbmpy_rounds: Vec<f64>,
}

/// Nodes per timed block of work, so that each timed run lasts about 0.2-0.5 s.
const WORK: usize = 60_000_000;
/// Rayon chunk of the nine-pass and copy ceilings (values).
const CHUNK: usize = 1 << 14;

fn steps_for(n: usize) -> usize {
    (WORK / n).max(2) & !1
}

fn fluid<L: Lattice, T: Real>(n: [usize; 3]) -> Fluid<L, T> {
    let mut fluid = Fluid::<L, T>::new(Domain::periodic(n), Vec::new());
    // relaxation rate 1.8 as in lbmpy_bench.py; small perturbation so nothing is trivially constant
    fluid.init_equilibrium(|p| {
        (
            1.0 + 1e-4 * (((p[0] * 7 + p[1] * 13 + p[2] * 5) % 17) as f64 / 17.0 - 0.5),
            [0.0; 3],
        )
    });
    fluid
}

/// A stored value the references read and write: `touch(up)` changes it with the least work (a
/// multiply by 0.999 or its inverse, alternately so that nothing decays; a bit flip for 16-bit
/// values), so the pass moves the array's bytes and cannot be optimised away.
trait Touch: Copy + Send + Sync + Default + 'static {
    fn one() -> Self;
    fn touch(self, up: bool) -> Self;
}

impl Touch for f64 {
    fn one() -> Self {
        1.0
    }
    #[inline(always)]
    fn touch(self, up: bool) -> Self {
        self * if up { 0.999 } else { 1.0 / 0.999 }
    }
}

impl Touch for f32 {
    fn one() -> Self {
        1.0
    }
    #[inline(always)]
    fn touch(self, up: bool) -> Self {
        self * if up { 0.999 } else { 1.0 / 0.999 }
    }
}

impl Touch for ShiftedF32 {
    fn one() -> Self {
        ShiftedF32(1.0)
    }
    #[inline(always)]
    fn touch(self, up: bool) -> Self {
        ShiftedF32(self.0.touch(up))
    }
}

impl Touch for ShiftedF16 {
    fn one() -> Self {
        <ShiftedF16 as Storage<f32>>::encode(1.0)
    }
    #[inline(always)]
    fn touch(self, _: bool) -> Self {
        ShiftedF16::from_bits(self.to_bits() ^ 1)
    }
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

/// The AA stepper (populations stored as `St`) and the arrays of its references, kept across
/// rounds.
struct AaCase<L: Lattice, T: Real, St: Storage<T>> {
    fluid: Fluid<L, T>,
    st: StepperAa<L, T, St>,
    layout: Layout,
    fused: Vec<St>,
    nine: Vec<(Vec<St>, usize)>,
    /// STREAM copy and triad as node-update rates with the AA byte count.
    stream: f64,
}

impl<L: Lattice, T: Real, St: Storage<T> + Touch> AaCase<L, T, St> {
    fn new(n: [usize; 3], stream_gbs: f64) -> Result<Self> {
        let mut fluid = fluid::<L, T>(n);
        let st = StepperAa::<L, T, St>::with_storage(&mut fluid, settings())?;
        let mut layout = st.layout();
        let nodes = n[0] * n[1] * n[2];
        let fused = layout.pack(&vec![St::one(); L::Q * nodes], L::Q);
        let nine = (0..L::Q).map(|_| aligned(nodes, St::one())).collect();
        let bytes = (2 * L::Q * std::mem::size_of::<St>()) as f64;
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
        let n = self.fluid.nodes();
        let rows = n / self.layout.nx;
        let steps = steps_for(n);
        let (mut k, mut b, mut fu, mut ni, mut r, mut rn) = (vec![], vec![], vec![], vec![], vec![], vec![]);
        for rep in 0..=reps {
            let t = Instant::now();
            for _ in 0..steps {
                self.st.step(&mut self.fluid, None)?;
            }
            let kernel = (n * steps) as f64 / t.elapsed().as_secs_f64() / 1e6;
            let (lay, base, part) = (self.layout, self.layout.base, self.st.partition);
            let f = &mut self.fused;
            // alternate the factor so that the reference arrays neither decay nor grow
            let mut flip = false;
            let fused = rate(n, steps, || {
                flip = !flip;
                let up = flip;
                roofline::in_place_map(&mut f[base..], &lay, L::Q, rows, part, move |v: St| v.touch(up));
            });
            let nine = &mut self.nine;
            let mut flip = false;
            let nine_pass = rate(n, steps, || {
                flip = !flip;
                let up = flip;
                for (arr, o) in nine.iter_mut() {
                    arr[*o..*o + n]
                        .par_chunks_mut(CHUNK)
                        .for_each(|c| c.iter_mut().for_each(|v| *v = v.touch(up)));
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

/// The two-array kernel against a Q-array copy to Q other arrays (its traffic, write-allocate
/// included), repetition by repetition: (median MLUPS, median ceiling, median ratio).
fn two_array<L: Lattice, T: Real>(n3: [usize; 3], reps: usize) -> Result<(f64, f64, f64)> {
    let mut fluid = fluid::<L, T>(n3);
    let n = fluid.nodes();
    let mut st = Stepper::new(&fluid, settings())?;
    let src: Vec<_> = (0..L::Q)
        .map(|i| aligned(n, T::from_f64(1.0 + i as f64)))
        .collect();
    let mut dst: Vec<_> = (0..L::Q).map(|_| aligned(n, T::default())).collect();
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
fn aligned<T: Copy>(n: usize, x: T) -> (Vec<T>, usize) {
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

/// lbmpy's median MLUPS for one configuration, or None (with a note) if it cannot run. D2Q9 runs
/// through scripts/peer-lbmpy.sh; D3Q19 calls its driver with the script's venv directly (the
/// script passes `--stencil D2Q9`), after `peer-lbmpy.sh install` has made sure the venv exists.
pub(super) fn lbmpy(lattice: &str, n: [usize; 3], precision: &str, threads: usize) -> Option<f64> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let script = root.join("scripts/peer-lbmpy.sh");
    let dtype = if precision == "f64" { "float64" } else { "float32" };
    let blocks = std::env::var("LBMPY_BLOCKS").unwrap_or_else(|_| "3".into());
    let block_time = std::env::var("LBMPY_BLOCK_TIME").unwrap_or_else(|_| "0.5".into());
    let mut cmd = if lattice == "D2Q9" {
        let mut cmd = Command::new("bash");
        cmd.arg(&script).args([
            format!("{}x{}", n[0], n[1]),
            dtype.into(),
            threads.to_string(),
            "aa".into(),
        ]);
        cmd.env("LBMPY_BLOCKS", &blocks)
            .env("LBMPY_BLOCK_TIME", &block_time);
        cmd
    } else {
        match Command::new("bash").arg(&script).arg("install").status() {
            Ok(s) if s.success() => {}
            other => {
                eprintln!("lbmpy: {} install failed: {other:?}", script.display());
                return None;
            }
        }
        let venv = std::env::var_os("LBMPY_VENV")
            .map(std::path::PathBuf::from)
            .unwrap_or_else(|| root.join("target/peer-lbmpy-venv"));
        let mut cmd = Command::new(venv.join("bin/python"));
        cmd.arg(root.join("scripts/peers/lbmpy_bench.py")).args([
            "--stencil".into(),
            lattice.to_string(),
            "--size".into(),
            format!("{}x{}x{}", n[0], n[1], n[2]),
            "--dtype".into(),
            dtype.to_string(),
            "--variant".into(),
            "aa".into(),
            "--blocks".into(),
            blocks,
            "--block-time".into(),
            block_time,
            "--warmup-time".into(),
            "0.5".into(),
            "--cache".into(),
            root.join("target/peer-lbmpy-cache").display().to_string(),
        ]);
        // as the script: threads pinned to cores unless the caller says otherwise
        for (var, default) in [("OMP_PROC_BIND", "close"), ("OMP_PLACES", "cores")] {
            if std::env::var_os(var).is_none() {
                cmd.env(var, default);
            }
        }
        cmd.env("OMP_NUM_THREADS", threads.to_string());
        cmd
    };
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
            eprintln!("lbmpy: cannot run ({e})");
            None
        }
    }
}

/// One configuration: STREAM, then `rounds` rounds of the AA kernel (each followed by lbmpy if
/// `peer`), then the two-array kernel where the storage is the arithmetic type.
fn config<L: Lattice, T: Real, St: Storage<T> + Touch>(
    a: &BenchArgs,
    n: [usize; 3],
    threads: usize,
    precision: Precision,
) -> Result<Row> {
    let load0 = load();
    let bw = bandwidth::measure(threads, bandwidth::default_len(a.quick), 3)?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    let rounds = if a.peer { 3 } else { 1 };
    // lbmpy in the arithmetic precision of f32 runs; f64 for the rest (module doc)
    let peer_precision = if precision == Precision::F32 { "f32" } else { "f64" };
    let mut case = pool.install(|| AaCase::<L, T, St>::new(n, bw.copy_gbs.max(bw.triad_gbs)))?;
    let (mut aa, mut peer) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        aa.push(pool.install(|| case.round(a.reps))?);
        if a.peer
            && let Some(p) = lbmpy(L::NAME, n, peer_precision, threads)
        {
            peer.push((p, aa.last().map_or(f64::NAN, |r| r.mlups / p)));
        }
    }
    drop(case);
    let two = if St::SHIFTED {
        None
    } else {
        Some(pool.install(|| two_array::<L, T>(n, a.reps))?)
    };
    let med = |f: fn(&AaRound) -> f64| median(&aa.iter().map(f).collect::<Vec<_>>());
    let bound = med(|r| r.bound);
    let bytes = 2 * L::Q * std::mem::size_of::<St>();
    let ratio_lbmpy_rounds: Vec<f64> = peer.iter().map(|p| p.1).collect();
    Ok(Row {
        lattice: L::NAME,
        nx: n[0],
        ny: n[1],
        nz: n[2],
        precision: precision.name(),
        bytes: std::mem::size_of::<St>(),
        threads,
        load: [load0, load()],
        mlups: med(|r| r.mlups),
        bound,
        bound_gbs: bound * 1e6 * bytes as f64 / 1e9,
        fused: med(|r| r.fused),
        nine_pass: med(|r| r.nine_pass),
        stream_copy_gbs: bw.copy_gbs,
        stream_triad_gbs: bw.triad_gbs,
        ratio_bound: med(|r| r.ratio),
        ratio_nine_pass: med(|r| r.ratio_nine_pass),
        ratio_stream: med(|r| r.mlups) * 1e6 * bytes as f64 / 1e9 / bw.copy_gbs.max(bw.triad_gbs),
        ratio_bound_rounds: aa.iter().map(|r| r.ratio).collect(),
        mlups_two_array: two.map(|t| t.0),
        ceiling_two_array: two.map(|t| t.1),
        ratio_two_array: two.map(|t| t.2),
        lbmpy_precision: peer_precision,
        lbmpy_mlups: peer.iter().map(|p| p.0).collect(),
        ratio_lbmpy: (!peer.is_empty()).then(|| median(&ratio_lbmpy_rounds)),
        ratio_lbmpy_rounds,
    })
}

/// One configuration in the precision `p` (its arithmetic and storage types).
fn config_in<L: Lattice>(a: &BenchArgs, n: [usize; 3], threads: usize, p: Precision) -> Result<Row> {
    match p {
        Precision::F64 => config::<L, f64, f64>(a, n, threads, p),
        Precision::F32 => config::<L, f32, f32>(a, n, threads, p),
        Precision::F32s => config::<L, f64, ShiftedF32>(a, n, threads, p),
        Precision::F16s => config::<L, f32, ShiftedF16>(a, n, threads, p),
    }
}

/// `NXxNY` (D2Q9) or `NXxNYxNZ` (D3Q19).
fn parse_size(v: &str) -> Option<[usize; 3]> {
    let parts: Vec<usize> = v
        .split('x')
        .map(|s| s.trim().parse().ok())
        .collect::<Option<_>>()?;
    match parts[..] {
        [x, y] if x > 0 && y > 0 => Some([x, y, 1]),
        [x, y, z] if x > 0 && y > 0 && z > 0 => Some([x, y, z]),
        _ => None,
    }
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let mut sizes: Vec<[usize; 3]> = if a.quick {
        vec![[256, 192, 1]]
    } else {
        vec![[256, 192, 1], [1024, 1024, 1], [4096, 4096, 1], [128, 128, 128]]
    };
    // LBDEM_BENCH_LBM_SIZE=1024x1024 runs one size only (to repeat a case on a busy machine)
    if let Ok(v) = std::env::var("LBDEM_BENCH_LBM_SIZE") {
        let n = parse_size(&v).with_context(|| {
            format!("LBDEM_BENCH_LBM_SIZE = {v:?}: expected NXxNY (D2Q9) or NXxNYxNZ (D3Q19), e.g. 1024x1024")
        })?;
        sizes = vec![n];
    }
    let mut precisions = Precision::ALL.to_vec();
    if let Ok(v) = std::env::var("LBDEM_BENCH_LBM_PRECISION") {
        precisions = v
            .split(',')
            .map(str::parse::<Precision>)
            .collect::<Result<_, _>>()
            .with_context(|| format!("LBDEM_BENCH_LBM_PRECISION = {v:?}"))?;
    }
    println!(
        "lbm: BGK (lbmpy: SRT), relaxation rate 1.8, periodic; AA in-place kernels on both sides; \
         bound = max(fused in-place Q-array pass in the AA layout, nine-pass ceiling, STREAM x 2Q x bytes) \
         per repetition, measured in this run; CPU: {}",
        cpu_model()
    );
    let mut rows = Vec::new();
    for &n in &sizes {
        for &precision in &precisions {
            for threads in [1, 2] {
                let row = if n[2] == 1 {
                    config_in::<D2Q9>(a, n, threads, precision)?
                } else {
                    config_in::<D3Q19>(a, n, threads, precision)?
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

/// The CPU's model name (/proc/cpuinfo), printed beside every table.
fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, m)| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

fn print_row(r: &Row, peer: bool) {
    let pct = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{:.0}", 100.0 * x))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let size = if r.nz > 1 {
        format!("{}x{}x{}", r.nx, r.ny, r.nz)
    } else {
        format!("{}x{}", r.nx, r.ny)
    };
    let two = match (r.mlups_two_array, r.ratio_two_array, r.ceiling_two_array) {
        (Some(m), Some(q), Some(c)) => {
            format!(
                " | two-array {m:6.1} = {:3.0}% of two-array ceiling {c:6.1}",
                100.0 * q
            )
        }
        _ => String::new(),
    };
    println!(
        "lbm {} BGK {size} {} t={} (load {:.2} -> {:.2}): AA {:6.1} MLUPS = {:3.0}% of bound {:6.1} \
         ({:4.1} GB/s; rounds [{}]) | fused {:6.1}, nine-pass {:6.1} (AA = {:3.0}% of it), STREAM copy/triad \
         {:4.1}/{:4.1} GB/s (AA = {:3.0}% of the STREAM limit){two}{}",
        r.lattice,
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
        match r.ratio_lbmpy {
            Some(q) => format!(
                " | lbmpy AA {} {} -> lbdem/lbmpy {q:.2} (rounds [{}])",
                r.lbmpy_precision,
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
