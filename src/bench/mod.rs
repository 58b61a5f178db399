//! `lbdem bench ...`: rates printed with their ratio to a reference measured in the same
//! run (the machine's memory bandwidth or a peer code), because this machine is shared
//! and noisy and only ratios taken together mean anything.

pub mod bandwidth;
pub mod coupled;
pub mod dem;
pub mod dem3d;
pub mod free_surface;
pub mod grains;
pub mod lammps;
pub mod lbm;
pub mod radiograph;
pub mod resolution;
pub mod su2020;

use anyhow::Result;
use clap::{Args, ValueEnum};
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Which {
    /// STREAM-like copy and triad bandwidth.
    Bandwidth,
    /// Radiograph frames to REV g_S and eps_vol maps.
    Radiograph,
    /// D2Q9 stream-collide MLUPS.
    Lbm,
    /// DEM particle-steps per second.
    Dem,
    /// 3D sphere DEM particle-steps per second (dense frictional Hertz-Mindlin spheres).
    Dem3d,
    /// Two-circle grain fitting rate.
    Grains,
    /// Coupled LBM-DEM steps per second on a shear-cell-sized case.
    Coupled,
    /// A Su et al. 2020 shear-cell scene: time per LBM step and per mean diameter of plate
    /// travel, beside its DEM alone and LBM alone.
    Su2020,
    /// PSM drag and permeability error against cells per grain diameter and wall time.
    Resolution,
    /// D3Q19 free-surface step (3D dam break) against the plain D3Q19 kernel, with and without
    /// the Bingham local tau.
    FreeSurface,
}

#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    pub which: Which,
    /// Repetitions (at least 1); the median is reported.
    #[arg(long, default_value_t = 5, value_parser = at_least_one)]
    pub reps: usize,
    /// Small sizes only (for CI smoke runs).
    #[arg(long)]
    pub quick: bool,
    /// Also run the peer code (lbmpy, LAMMPS) if installed and report the ratio.
    #[arg(long)]
    pub peer: bool,
    /// Write the results as JSON here.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// The scene to run (`su2020`; default scenes/su2020/sim1.toml, or the reduced cell with
    /// --quick); the reduced cell also runs beside it as the second size, unless --quick.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Write tables and charts here (`resolution`; default out/bench-resolution).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `--reps`: a median of no runs is no figure.
fn at_least_one(s: &str) -> Result<usize, String> {
    match s.parse::<usize>() {
        Ok(0) => Err("--reps 0 runs nothing, and a median of no runs is no figure; give at least 1".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!(
            "--reps {s}: {e}; give a whole number of repetitions, at least 1"
        )),
    }
}

pub fn run(a: &BenchArgs) -> Result<()> {
    // Every table is read beside the machine it ran on (issue 18: CPUs of one kind differ).
    println!(
        "machine: {}, {} threads available, SIMD level {}",
        cpu_model(),
        rayon::current_num_threads(),
        lbdem_core::simd::level().name()
    );
    match a.which {
        Which::Bandwidth => bandwidth::run(a),
        Which::Radiograph => radiograph::run(a),
        Which::Lbm => lbm::run(a),
        Which::Dem => dem::run(a),
        Which::Dem3d => dem3d::run(a),
        Which::Grains => grains::run(a),
        Which::Coupled => coupled::run(a),
        Which::Su2020 => su2020::run(a),
        Which::Resolution => resolution::run(a),
        Which::FreeSurface => free_surface::run(a),
    }
}

/// The CPU's model name as the kernel reports it ("unknown" off Linux).
pub fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split_once(':'))
                .map(|(_, v)| v.trim().to_string())
        })
        .unwrap_or_else(|| "unknown".into())
}

/// Median of a sample (sorted copy); NaN-free input assumed.
pub fn median(xs: &[f64]) -> f64 {
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n == 0 {
        return f64::NAN;
    }
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}
