//! Grain templates drawn from the measured distribution, as Su et al. (2020, Sect. 2.4)
//! define 20 templates "by measuring the grain size and shape distribution" of an
//! experiment. The grains (those not cut by the container) are sorted by equivalent
//! diameter and split into N groups of (nearly) equal count, so each template stands for
//! the same share of the grains; a template has its group's mean area and mean aspect
//! ratio, and its two-circle shape.

use crate::measure::GrainMeasure;
use crate::twocircle::{FitCircle, fit_shape};
use serde::Serialize;

#[derive(Clone, Debug, Serialize)]
pub struct Template {
    pub id: usize,
    /// Share of the measured grains it stands for.
    pub weight: f64,
    pub count: usize,
    pub area_px: f64,
    pub d_eq_px: f64,
    pub aspect: f64,
    /// Circles in the template's own frame (centroid at 0, major axis along +x), px.
    pub circles: Vec<FitCircle>,
}

/// `n` templates from `grains`, and for each grain (same order) the template it belongs
/// to (`None` for grains left out: `at_edge`).
pub fn draw(grains: &[GrainMeasure], n: usize, round_aspect: f64) -> (Vec<Template>, Vec<Option<usize>>) {
    let mut idx: Vec<usize> = (0..grains.len()).filter(|&i| !grains[i].at_edge).collect();
    idx.sort_by(|&a, &b| grains[a].area_px.total_cmp(&grains[b].area_px).then(a.cmp(&b)));
    let m = idx.len();
    let n = n.min(m).max(usize::from(m > 0));
    let mut templates = Vec::with_capacity(n);
    let mut of = vec![None; grains.len()];
    for k in 0..n {
        let (lo, hi) = (k * m / n, (k + 1) * m / n);
        let group = &idx[lo..hi];
        let cnt = group.len() as f64;
        let area = group.iter().map(|&i| grains[i].area_px).sum::<f64>() / cnt;
        let aspect = group.iter().map(|&i| grains[i].aspect).sum::<f64>() / cnt;
        let (circles, _) = fit_shape(area, 0.0, 0.0, 0.0, aspect, round_aspect);
        for &i in group {
            of[i] = Some(k);
        }
        templates.push(Template {
            id: k + 1,
            weight: cnt / m as f64,
            count: group.len(),
            area_px: area,
            d_eq_px: (4.0 * area / std::f64::consts::PI).sqrt(),
            aspect,
            circles,
        });
    }
    (templates, of)
}
