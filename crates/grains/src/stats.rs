//! Statistics for the report: the mean grain size d_bar (Su et al. 2020, Table 2 gives
//! d_min : d_bar : d_max of each assembly; d_bar sets the push-plate displacement 10 d_bar
//! of Sect. 2.4 and the REV of the radiograph stage), and the solid area fraction of the
//! fitted assembly against the image's.

use crate::measure::GrainMeasure;
use crate::twocircle::FitCircle;
use ndarray::ArrayView2;
use serde::Serialize;

#[derive(Clone, Debug, Default, Serialize)]
pub struct SizeStats {
    /// Grains counted (not cut by the container edge).
    pub n: usize,
    pub d_mean_px: f64,
    pub d_std_px: f64,
    pub d_min_px: f64,
    pub d_max_px: f64,
    pub aspect_mean: f64,
}

/// Size statistics of the grains not cut by the container edge (all grains if every
/// grain is cut).
pub fn size_stats(grains: &[GrainMeasure]) -> SizeStats {
    let mut sel: Vec<&GrainMeasure> = grains.iter().filter(|g| !g.at_edge).collect();
    if sel.is_empty() {
        sel = grains.iter().collect();
    }
    let n = sel.len();
    if n == 0 {
        return SizeStats::default();
    }
    let nf = n as f64;
    let mean = sel.iter().map(|g| g.d_eq_px).sum::<f64>() / nf;
    let var = sel.iter().map(|g| (g.d_eq_px - mean).powi(2)).sum::<f64>() / nf;
    SizeStats {
        n,
        d_mean_px: mean,
        d_std_px: var.sqrt(),
        d_min_px: sel.iter().map(|g| g.d_eq_px).fold(f64::INFINITY, f64::min),
        d_max_px: sel.iter().map(|g| g.d_eq_px).fold(f64::NEG_INFINITY, f64::max),
        aspect_mean: sel.iter().map(|g| g.aspect).sum::<f64>() / nf,
    }
}

/// Fraction of the container's pixels (centres) covered by at least one circle.
pub fn covered_fraction(circles: &[FitCircle], inside: ArrayView2<bool>) -> f64 {
    let (h, w) = inside.dim();
    let mut cover = vec![false; h * w];
    for c in circles {
        let r0 = (c.y - c.r).floor().max(0.0) as usize;
        let r1 = ((c.y + c.r).ceil().max(0.0) as usize).min(h);
        let c0 = (c.x - c.r).floor().max(0.0) as usize;
        let c1 = ((c.x + c.r).ceil().max(0.0) as usize).min(w);
        for r in r0..r1 {
            let dy = r as f64 + 0.5 - c.y;
            for col in c0..c1 {
                let dx = col as f64 + 0.5 - c.x;
                if dx * dx + dy * dy < c.r * c.r {
                    cover[r * w + col] = true;
                }
            }
        }
    }
    let (mut n_in, mut n_cov) = (0usize, 0usize);
    for (i, &m) in inside.iter().enumerate() {
        if m {
            n_in += 1;
            n_cov += usize::from(cover[i]);
        }
    }
    n_cov as f64 / n_in.max(1) as f64
}
