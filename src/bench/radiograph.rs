//! `lbdem bench radiograph`: frames per second from a raw 2048 x 2048 16-bit frame to the
//! REV g_S map (Eq. 4b, summed-area table) and the eps_vol map (Eq. 5), with the thickness
//! of each frame from Eq. (2) over a liquid ROI; and the ratio of the bytes those passes
//! move per second to the STREAM triad bandwidth measured in the same run.
//!
//! Bytes counted per pixel (STREAM convention: reads plus writes, no write-allocate):
//! SAT pass: u16 frame read twice (strip totals, then strip prefixes) 2 x 2, table written
//! once 8 (`Sat::build_u16`); fused REV window and Eq. (5) pass: read 2 x 8 (top and bottom
//! SAT rows) + 8 (g0), write 8 (g_S) + 8 (eps): 52 B/px.
//!
//! Beside the kernel, the stage as users run it (`lbdem radiograph` on TIFF files, every output
//! on disk), once with its default map grid (`map_step`: the REV at the centre of every block of
//! about a sixteenth of the REV side, 11 px at 2048²) and once with maps on every pixel
//! (`map_step = 1`, 36 MB of maps a 2048² frame, which a disk writing about 640 MB/s with fsync
//! cannot take at 25 frames/s): both against the kernel alone in the same run (issue 18 item 5).

use super::{BenchArgs, bandwidth, median};
use anyhow::Result;
use lbdem_imaging::Roi;
use lbdem_imaging::beer_lambert::{self as bl, FractionMap};
use lbdem_imaging::rev::Sat;
use lbdem_imaging::synth::{self, Beam, GrainShape};
use ndarray::Array2;
use std::time::Instant;

const BYTES_PER_PX: f64 = 52.0;

/// Synthetic raw frames (frame 0 and a 5% thinner frame) of `n` x `n` px.
fn frames(n: usize) -> Result<Vec<Array2<u16>>> {
    let d = n as f64 / 60.0;
    let region = Roi::new(0, n / 16, n, n - n / 8);
    let disks = synth::pack_disks(region, d, 0.2, 0.45, 7)?;
    let beam = Beam {
        i0: 30000.0,
        mu_s: 2147.85,
        mu_l: 10120.559,
    };
    let mut out = Vec::new();
    for (k, l) in [150e-6, 142.5e-6].into_iter().enumerate() {
        let px = 6e-6 * 1024.0 / n as f64;
        let (_, counts) = synth::render(
            n,
            n,
            &disks,
            1,
            GrainShape::TruncatedSphere,
            l / px,
            l,
            &beam,
            &[],
            &[],
        );
        out.push(synth::noisy_u16(counts.view(), 11 + k as u64)?);
    }
    Ok(out)
}

fn roi_mean(f: &Array2<u16>, r: Roi) -> f64 {
    let v = f.slice(ndarray::s![r.y..r.y + r.h, r.x..r.x + r.w]);
    v.iter().map(|&c| c as f64).sum::<f64>() / v.len() as f64
}

/// The REV side (px) of the synthetic frames of `n` rows: sqrt(10) d_bar, d_bar = 30 px at 1024
/// rows (the stage's `rev_side_px` with the parameters of [`time_stage`]).
fn rev_side(n: usize) -> usize {
    (10f64.sqrt() * 30.0 * n as f64 / 1024.0).round() as usize
}

/// Seconds per frame (median of `reps`), on a pool of `threads`: the REV and Eq. 5 maps on every
/// pixel (`grid` None) or on the stage's default grid of cells (`grid` Some(step)).
fn time_frames(threads: usize, raw: &[Array2<u16>], reps: usize, grid: Option<usize>) -> Result<f64> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    pool.install(|| {
        let (h, w) = raw[0].dim();
        let side = rev_side(h);
        let (mu_s, mu_l, l0) = (2147.85, 10120.559, 150e-6);
        let liquid = Roi::new(16, h - h / 32, w - 32, h / 32 - 2);
        let solid_like = Roi::new(16, 2, w - 32, h / 32 - 2);
        let (i_l0, i_s0) = (roi_mean(&raw[0], liquid), roi_mean(&raw[0], solid_like).max(1.0));
        let mut sat = Sat::new();
        let mut g0 = Array2::zeros((h, w));
        let mut gn = Array2::zeros((h, w));
        let mut eps = Array2::zeros((h, w));
        sat.build_u16(raw[0].view(), &FractionMap::eq1(i_l0, i_s0)?.lut_u16());
        match grid {
            None => sat.rev_mean_into(side, 0.5, &mut g0)?,
            Some(k) => sat.rev_grid_into(side, 0.5, k, &mut g0, None)?,
        }
        let mut per_frame = Vec::new();
        for _ in 0..reps.max(1) {
            let frames = 4;
            let t = Instant::now();
            for k in 0..frames {
                let f = &raw[1 + k % (raw.len() - 1)];
                let ln_ = bl::thickness_eq2(l0, mu_s, mu_l, i_l0, roi_mean(f, liquid), 0.0, 0.0);
                let map = FractionMap::eq4(i_l0, mu_s, mu_l, l0, ln_)?;
                sat.build_u16(f.view(), &map.lut_u16());
                match grid {
                    None => sat.rev_mean_eps_into(side, 0.5, g0.view(), 0.1, &mut gn, &mut eps)?,
                    Some(k) => sat.rev_grid_into(side, 0.5, k, &mut gn, Some((g0.view(), 0.1, &mut eps)))?,
                }
            }
            per_frame.push(t.elapsed().as_secs_f64() / frames as f64);
            std::hint::black_box(&eps);
        }
        Ok(median(&per_frame))
    })
}

/// Two frame sizes (2048² and 1024²; `--quick`: 512² and 256²), each on 1 and 2 threads: the
/// kernel against the STREAM triad, and the stage as users run it against the kernel at the same
/// size and thread count, so the cost growth with size and cores is on record (issue 18 item 6).
pub fn run(a: &BenchArgs) -> Result<()> {
    let sizes = if a.quick { [512, 256] } else { [2048, 1024] };
    let mut results = Vec::new();
    for n in sizes {
        let raw = frames(n)?;
        for threads in [1, 2] {
            let bw = bandwidth::measure(threads, bandwidth::default_len(a.quick), a.reps)?;
            let kernel_fps = 1.0 / time_frames(threads, &raw, a.reps, None)?;
            let gbs = BYTES_PER_PX * (n * n) as f64 * kernel_fps / 1e9;
            println!(
                "radiograph {n}x{n} u16 -> REV g_S + eps_vol  threads={threads}  {kernel_fps:.1} frames/s (median of {})  \
                 {gbs:.2} GB/s moved = {:.2} of STREAM triad {:.1} GB/s",
                a.reps,
                gbs / bw.triad_gbs,
                bw.triad_gbs
            );
            // The synthetic frames have no fully solid pad, so the stage would warn about its
            // reference intensities on every repetition: the timing does not care.
            let was_quiet = crate::contract::quiet();
            crate::contract::set_quiet(true);
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
            let stage_fps = pool.install(|| time_stage(&raw, a.reps, None));
            let every_px_fps = pool.install(|| time_stage(&raw, a.reps, Some(1)));
            crate::contract::set_quiet(was_quiet);
            let (stage_fps, every_px_fps) = (stage_fps?, every_px_fps?);
            // The kernel as the stage runs it by default: the maps on the grid of cells.
            let step = lbdem_imaging::rev::map_step_auto(rev_side(n));
            let grid_fps = 1.0 / time_frames(threads, &raw, a.reps, Some(step))?;
            println!(
                "radiograph {n}x{n} u16 -> REV g_S + eps_vol on the {step} px grid of cells  threads={threads}  \
                 {grid_fps:.1} frames/s (median of {}): the stage runs at {:.2} of it",
                a.reps,
                stage_fps / grid_fps
            );
            println!(
                "radiograph stage {n}x{n}, 8 uncompressed u16 TIFF frames -> maps, grid and summary on disk  \
                 threads={threads}  {stage_fps:.1} frames/s (median of {}) = {:.2} of the kernel alone; \
                 maps on every pixel (map_step = 1): {every_px_fps:.1} frames/s = {:.2}",
                a.reps,
                stage_fps / kernel_fps,
                every_px_fps / kernel_fps
            );
            results.push(serde_json::json!({
                "size": n, "threads": threads, "frames_per_s": kernel_fps, "gb_per_s": gbs,
                "triad_gb_per_s": bw.triad_gbs, "ratio_to_triad": gbs / bw.triad_gbs,
                "bytes_per_px": BYTES_PER_PX, "stage_frames_per_s": stage_fps,
                "stage_ratio_to_kernel": stage_fps / kernel_fps, "reps": a.reps,
                "stage_every_pixel_frames_per_s": every_px_fps,
                "grid_kernel_frames_per_s": grid_fps, "map_step": step,
                "stage_ratio_to_grid_kernel": stage_fps / grid_fps,
            }));
        }
    }
    if let Some(p) = &a.json {
        lbdem_core::atomic::write_atomic(p, &serde_json::to_vec_pretty(&results)?)?;
    }
    Ok(())
}

/// Frames per second of `lbdem radiograph` on 8 frames written as TIFF (the two synthetic frames
/// alternating), from reading them to the last output file, median of `reps`, with the default
/// map grid or `map_step`; the frames and outputs live in a directory of the system's temporary
/// directory, removed afterwards.
fn time_stage(raw: &[Array2<u16>], reps: usize, map_step: Option<usize>) -> Result<f64> {
    let dir = std::env::temp_dir().join(format!("lbdem-bench-radiograph-{}", std::process::id()));
    let result = (|| {
        std::fs::create_dir_all(&dir)?;
        let (h, w) = raw[0].dim();
        let mut names = Vec::new();
        for k in 0..8 {
            let name = format!("frame_{k:03}.tif");
            crate::io::tiff::write_u16_stack(&dir.join(&name), &[raw[k % raw.len()].view()])?;
            names.push(toml::Value::String(name));
        }
        let roi = |r: Roi| {
            toml::Value::Array(
                [r.x, r.y, r.w, r.h]
                    .map(|v| toml::Value::Integer(v as i64))
                    .to_vec(),
            )
        };
        let liquid = Roi::new(16, h - h / 32, w - 32, h / 32 - 2);
        let solid_like = Roi::new(16, 2, w - 32, h / 32 - 2);
        let mut params = toml::Table::new();
        params.insert("frames".into(), toml::Value::Array(names));
        params.insert("i_s0_roi".into(), roi(solid_like));
        params.insert("i_l0_roi".into(), roi(liquid));
        params.insert("thickness_roi".into(), roi(liquid));
        params.insert("thickness".into(), "eq2".into());
        params.insert("mu_s".into(), 2147.85.into());
        params.insert("mu_l".into(), 10120.559.into());
        params.insert("l_alloy0".into(), 150e-6.into());
        params.insert("d_bar".into(), (30.0 * 6e-6).into());
        params.insert("pixel_size".into(), (6e-6 * 1024.0 / h as f64).into());
        params.insert("plots".into(), false.into());
        if let Some(k) = map_step {
            params.insert("map_step".into(), toml::Value::Integer(k as i64));
        }
        let mut per_frame = Vec::new();
        for r in 0..reps.max(1) {
            let out = dir.join(format!("out{r}"));
            let ctx = crate::contract::StageContext::new(out.clone(), "radiograph".into(), dir.clone());
            let prepared =
                crate::registry::find("radiograph")?.prepare(toml::Value::Table(params.clone()), &ctx)?;
            let t = Instant::now();
            crate::pipeline::execute(prepared, &ctx)?;
            per_frame.push(t.elapsed().as_secs_f64() / 8.0);
            std::fs::remove_dir_all(&out)?;
        }
        Ok(1.0 / median(&per_frame))
    })();
    let _ = std::fs::remove_dir_all(&dir);
    result
}
