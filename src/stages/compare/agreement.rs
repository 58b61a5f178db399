//! The agreement measures of a comparison: map statistics of a frame-snapshot pair, RMS of
//! profile differences, ROI profiles on the common grid.

use lbdem_analysis::raster::Grid;
use ndarray::Array2;

/// Statistics of one frame-snapshot pair.
#[derive(Default)]
pub(super) struct Agreement {
    pub(super) frame: Vec<u64>,
    pub(super) step: Vec<u64>,
    pub(super) u_d: Vec<f64>,
    pub(super) mean_xip: Vec<f64>,
    pub(super) mean_tri: Vec<f64>,
    pub(super) mean_area: Vec<f64>,
    pub(super) rms: Vec<f64>,
    pub(super) rms_area: Vec<f64>,
    pub(super) corr: Vec<f64>,
    pub(super) rms_red: Vec<f64>,
    pub(super) rms_blue: Vec<f64>,
    pub(super) eps_dem: Vec<f64>,
    pub(super) same_sign: Vec<u64>,
    pub(super) overlap: Vec<u64>,
    /// With `synth-run` frames: Eq. 5 on the true solid fraction (no blur or noise).
    pub(super) mean_true: Vec<f64>,
    pub(super) rms_xip_true: Vec<f64>,
    pub(super) rms_true_area: Vec<f64>,
}

pub(super) fn stats(a: &Array2<f64>, b: &Array2<f64>) -> (f64, f64, f64, f64, usize) {
    let pairs: Vec<(f64, f64)> = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| (*x, *y))
        .collect();
    let n = pairs.len();
    if n == 0 {
        return (f64::NAN, f64::NAN, f64::NAN, f64::NAN, 0);
    }
    let nf = n as f64;
    let (ma, mb) = pairs
        .iter()
        .fold((0.0, 0.0), |s, p| (s.0 + p.0 / nf, s.1 + p.1 / nf));
    let rms = (pairs.iter().map(|p| (p.0 - p.1).powi(2)).sum::<f64>() / nf).sqrt();
    let (sab, saa, sbb) = pairs.iter().fold((0.0, 0.0, 0.0), |s, p| {
        let (x, y) = (p.0 - ma, p.1 - mb);
        (s.0 + x * y, s.1 + x * x, s.2 + y * y)
    });
    (ma, mb, rms, sab / (saa * sbb).sqrt(), n)
}

pub(super) fn rms_diff(a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| (x - y).powi(2))
        .collect();
    if d.is_empty() {
        f64::NAN
    } else {
        (d.iter().sum::<f64>() / d.len() as f64).sqrt()
    }
}

/// Mean of `f` over the ROI [x0, x1, y0, y1] (d̄) of `grid`, along `axis` ('x': profile in x,
/// averaged over y; 'y': profile in y): (positions in d̄, means).
pub(super) fn roi_profile(
    f: &Array2<f64>,
    grid: &Grid,
    roi: [f64; 4],
    along_x: bool,
) -> (Vec<f64>, Vec<f64>) {
    let [x0, x1, y0, y1] = roi;
    let cols: Vec<usize> = (0..grid.nx)
        .filter(|&c| {
            let x = grid.centre(0, c)[0];
            x >= x0 && x <= x1
        })
        .collect();
    let rows: Vec<usize> = (0..grid.ny)
        .filter(|&r| {
            let y = grid.centre(r, 0)[1];
            y >= y0 && y <= y1
        })
        .collect();
    let mean = |it: &mut dyn Iterator<Item = f64>| {
        let (s, n) = it
            .filter(|v| v.is_finite())
            .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
        if n == 0 { f64::NAN } else { s / n as f64 }
    };
    if along_x {
        let pos = cols.iter().map(|&c| grid.centre(0, c)[0]).collect();
        let val = cols
            .iter()
            .map(|&c| mean(&mut rows.iter().map(|&r| f[[r, c]])))
            .collect();
        (pos, val)
    } else {
        // Bottom to top.
        let pos = rows.iter().rev().map(|&r| grid.centre(r, 0)[1]).collect();
        let val = rows
            .iter()
            .rev()
            .map(|&r| mean(&mut cols.iter().map(|&c| f[[r, c]])))
            .collect();
        (pos, val)
    }
}
