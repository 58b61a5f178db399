//! The digitise chain on one image: container mask, smoothing, threshold, clean-up,
//! distance transform, watershed, measures, two-circle fits, templates and statistics.

use crate::binary::{fill_holes, remove_specks, threshold_mask};
use crate::edt::squared_distance_to_liquid;
use crate::mask::{self, Container, ContainerMask};
use crate::measure::{GrainMeasure, GrainPixels, drop_small, measure_all};
use crate::smooth::gaussian;
use crate::stats::{SizeStats, covered_fraction, size_stats};
use crate::templates::{Template, draw};
use crate::threshold::otsu;
use crate::twocircle::{Fit, fit_grain, max_aspect};
use crate::watershed::{WatershedParams, watershed};
use crate::{GrainsError, Result};
use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Smallest image side digitise accepts.
pub const MIN_SIDE: usize = 8;

/// Whether grains are brighter or darker than the liquid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Polarity {
    #[default]
    Bright,
    Dark,
}

#[derive(Clone, Debug, Serialize)]
pub struct Params {
    pub grains_are: Polarity,
    /// Grey level between liquid and grains; `None`: Otsu's.
    pub threshold: Option<f64>,
    /// Gaussian smoothing before the threshold, px (0: none).
    pub smooth_px: f64,
    pub container: Container,
    /// Smaller solid pieces are specks, not grains (dropped with a warning).
    pub min_grain_area_px: usize,
    /// Liquid pin-holes up to this area inside a grain are filled.
    pub max_hole_area_px: usize,
    pub watershed: WatershedParams,
    /// Below this aspect ratio a grain is one circle.
    pub round_aspect: f64,
    pub n_templates: usize,
}

impl Default for Params {
    fn default() -> Self {
        Self {
            grains_are: Polarity::Bright,
            threshold: None,
            smooth_px: 0.5,
            container: Container::Full,
            min_grain_area_px: 12,
            max_hole_area_px: 0,
            watershed: WatershedParams::default(),
            round_aspect: 1.1,
            n_templates: 20,
        }
    }
}

impl Params {
    fn check(&self) -> Result<()> {
        let bad = |name, value: f64, limit, fix| GrainsError::BadParameter {
            name,
            value: value.to_string(),
            limit,
            fix,
        };
        if !(self.smooth_px >= 0.0 && self.smooth_px <= 20.0) {
            return Err(bad(
                "smooth_px",
                self.smooth_px,
                "0 <= smooth_px <= 20",
                "give the blur in pixels, e.g. 1",
            ));
        }
        if !(self.watershed.h_rel > 0.0 && self.watershed.h_rel < 1.0) {
            return Err(bad(
                "h_rel",
                self.watershed.h_rel,
                "0 < h_rel < 1",
                "0.45 splits touching grains",
            ));
        }
        // Written to reject NaN too.
        if self.round_aspect.is_nan() || self.round_aspect < 1.0 {
            return Err(bad(
                "round_aspect",
                self.round_aspect,
                "round_aspect >= 1",
                "1.1 is the default",
            ));
        }
        if self.n_templates == 0 {
            return Err(bad("n_templates", 0.0, "n_templates >= 1", "Su et al. use 20"));
        }
        if let Some(t) = self.threshold
            && !t.is_finite()
        {
            return Err(bad("threshold", t, "a finite grey level", "omit it for Otsu's"));
        }
        Ok(())
    }
}

/// Everything digitise found.
#[derive(Clone, Debug)]
pub struct Digitised {
    pub threshold: f64,
    pub mask: ContainerMask,
    pub labels: Array2<u32>,
    pub grains: Vec<GrainMeasure>,
    /// One fit per grain (same order).
    pub fits: Vec<Fit>,
    pub templates: Vec<Template>,
    /// Template of each grain (`None` for grains cut by the container edge).
    pub template_of: Vec<Option<usize>>,
    pub size: SizeStats,
    /// Solid pixels of the segmentation over the container's pixels.
    pub solid_fraction_image: f64,
    /// Container pixels covered by the fitted circles over the container's pixels.
    pub solid_fraction_fitted: f64,
    /// Circles whose centre lies outside the container, and the largest distance a
    /// circle reaches beyond it (px).
    pub circles_outside: usize,
    pub max_protrusion_px: f64,
    pub warnings: Vec<String>,
}

/// Run the chain on `image` (grey levels or solid fraction; NaN pixels count as outside).
pub fn digitise(image: ArrayView2<f64>, p: &Params) -> Result<Digitised> {
    p.check()?;
    let (h, w) = image.dim();
    if h < MIN_SIDE || w < MIN_SIDE {
        return Err(GrainsError::EmptyImage {
            width: w,
            height: h,
            min: MIN_SIDE,
        });
    }
    let mut mask = mask::build(&p.container, image)?;
    let in_container = mask.count();
    ndarray::Zip::from(&mut mask.inside)
        .and(image)
        .for_each(|m, &v| *m &= v.is_finite());
    let inside_n = mask.count();
    if inside_n == 0 {
        return Err(GrainsError::NoFinitePixels { inside: in_container });
    }
    let mut warnings = Vec::new();
    let mean_inside = ndarray::Zip::from(image)
        .and(&mask.inside)
        .fold(0.0, |a, &v, &m| if m { a + v } else { a })
        / inside_n as f64;
    let smooth = gaussian(image, p.smooth_px, mean_inside);
    let inside_vals = || {
        smooth
            .iter()
            .zip(mask.inside.iter())
            .filter(|(_, m)| **m)
            .map(|(v, _)| *v)
    };
    let threshold = match p.threshold {
        Some(t) => t,
        None => otsu(inside_vals())?,
    };
    let bright = p.grains_are == Polarity::Bright;
    let mut solid = threshold_mask(smooth.view(), mask.inside.view(), threshold, bright);
    let specks = remove_specks(&mut solid, p.min_grain_area_px);
    if !specks.is_empty() {
        let s = &specks[0];
        warnings.push(format!(
            "dropped {} solid speck(s) smaller than min_grain_area_px = {} (largest: {} px at x = {:.1}, y = {:.1} px); \
             raise smooth_px if these are noise, or lower min_grain_area_px if they are grains",
            specks.len(),
            p.min_grain_area_px,
            s.area_px,
            s.x,
            s.y
        ));
    }
    fill_holes(&mut solid, mask.inside.view(), p.max_hole_area_px);
    let solid_n = solid.iter().filter(|&&s| s).count();
    let other = if bright { "dark" } else { "bright" };
    if solid_n == 0 {
        return Err(GrainsError::NoGrains {
            threshold,
            solid: 0,
            inside: inside_n,
            min_area: p.min_grain_area_px,
            other,
        });
    }
    if solid_n == inside_n {
        return Err(GrainsError::AllSolid {
            threshold,
            inside: inside_n,
        });
    }
    let sqd = squared_distance_to_liquid(&solid);
    let (mut labels, n0) = watershed(&sqd, p.watershed);
    let (n, dropped) = drop_small(&mut labels, n0, p.min_grain_area_px);
    for (l, a, x, y) in &dropped {
        warnings.push(format!(
            "grain piece {l} at x = {x:.1}, y = {y:.1} px has {a} px, fewer than min_grain_area_px = {}: dropped",
            p.min_grain_area_px
        ));
    }
    if n == 0 {
        return Err(GrainsError::NoGrains {
            threshold,
            solid: solid_n,
            inside: inside_n,
            min_area: p.min_grain_area_px,
            other,
        });
    }
    let px = GrainPixels::from_labels(labels.view(), n);
    let grains = measure_all(&px, mask.inside.view());
    let flat = labels.as_slice().expect("standard layout");
    let fits: Vec<Fit> = (0..n)
        .into_par_iter()
        .map(|g| fit_grain(&grains[g], px.of(g), flat, w, p.round_aspect))
        .collect();
    let too_long = grains.iter().filter(|g| g.aspect > max_aspect()).count();
    if too_long > 0 {
        warnings.push(format!(
            "{too_long} grain(s) are more elongated than two touching circles (aspect ratio > {:.3}); fitted with \
             touching circles, see their fit_error",
            max_aspect()
        ));
    }
    let (templates, template_of) = draw(&grains, p.n_templates, p.round_aspect);
    let size = size_stats(&grains);
    if templates.len() < p.n_templates {
        warnings.push(format!(
            "only {} grains not cut by the container edge: {} templates instead of n_templates = {}",
            size.n,
            templates.len(),
            p.n_templates
        ));
    }
    let all_circles: Vec<_> = fits.iter().flat_map(|f| f.circles.iter().copied()).collect();
    let solid_fraction_image = px.pixels.len() as f64 / inside_n as f64;
    let solid_fraction_fitted = covered_fraction(&all_circles, mask.inside.view());
    let circles_outside = all_circles.iter().filter(|c| !mask.contains(c.x, c.y)).count();
    let max_protrusion_px = all_circles
        .iter()
        .map(|c| mask.protrusion(c.x, c.y, c.r))
        .fold(0.0, f64::max);
    if circles_outside > 0 {
        warnings.push(format!(
            "{circles_outside} fitted circle(s) have their centre outside the container"
        ));
    }
    Ok(Digitised {
        threshold,
        mask,
        labels,
        grains,
        fits,
        templates,
        template_of,
        size,
        solid_fraction_image,
        solid_fraction_fitted,
        circles_outside,
        max_protrusion_px,
        warnings,
    })
}

/// Fraction of the typical grain's area that separates specks and pin-holes from grains and
/// pores when the sizes follow from the image ([`sizes_from_first_pass`]). 5 %: the pore that
/// three equal touching disks enclose is (sqrt(3) - pi/2) r^2 = 5.1 % of a disk, so it stays
/// liquid; the dark fringes inside the PeGS photoelastic disks (data/real) are 2.4-4.8 % of a
/// small disk (with a limit of 2.4 % one remains and splits a disk; at 4.8 % none).
pub const FIRST_PASS_AREA_FRACTION: f64 = 0.05;

/// Speck and pin-hole sizes that follow from the image rather than from fixed pixel counts.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct FirstPassSizes {
    /// Median area of the grains the first pass found, px.
    pub median_area_px: f64,
    /// Grains found by the first pass.
    pub n_grains: usize,
    /// [`FIRST_PASS_AREA_FRACTION`] of the median area (at least `p.min_grain_area_px`).
    pub min_grain_area_px: usize,
    /// [`FIRST_PASS_AREA_FRACTION`] of the median area (at least `p.max_hole_area_px`).
    pub max_hole_area_px: usize,
}

/// A first pass of the chain with `p` gives the typical grain area; a solid piece or a liquid
/// hole under [`FIRST_PASS_AREA_FRACTION`] of it is a speck or a pin-hole. Scale-free, so the
/// same defaults serve a 30 px grain and a 100 px one (fixed pixel counts cannot).
pub fn sizes_from_first_pass(image: ArrayView2<f64>, p: &Params) -> Result<FirstPassSizes> {
    let first = digitise(image, p)?;
    let mut areas: Vec<f64> = first.grains.iter().map(|g| g.area_px).collect();
    areas.sort_by(f64::total_cmp);
    let n = areas.len();
    // digitise returns at least one grain or an error.
    let median_area_px = if n % 2 == 1 {
        areas[n / 2]
    } else {
        0.5 * (areas[n / 2 - 1] + areas[n / 2])
    };
    let a = (FIRST_PASS_AREA_FRACTION * median_area_px).floor() as usize;
    Ok(FirstPassSizes {
        median_area_px,
        n_grains: n,
        min_grain_area_px: a.max(p.min_grain_area_px),
        max_hole_area_px: a.max(p.max_hole_area_px),
    })
}

/// Grey image of the labels' boundaries over the input, for a quick look (1 on a boundary).
pub fn boundaries(labels: ArrayView2<u32>) -> Array2<bool> {
    let (h, w) = labels.dim();
    Array2::from_shape_fn((h, w), |(r, c)| {
        let l = labels[[r, c]];
        l > 0
            && ((r > 0 && labels[[r - 1, c]] != l)
                || (c > 0 && labels[[r, c - 1]] != l)
                || (r + 1 < h && labels[[r + 1, c]] != l)
                || (c + 1 < w && labels[[r, c + 1]] != l))
    })
}
