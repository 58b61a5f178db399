//! Per-grain measures from the label image: area, equivalent diameter, centroid and the
//! second moments, whose principal axes give the orientation and the aspect ratio
//! (the ellipse with the same second moments; Prokop & Reeves, CVGIP 54 (1992) 438).
//! Each pixel counts as a unit square, so its own variance 1/12 is added on each axis.

use ndarray::{Array2, ArrayView2};
use rayon::prelude::*;
use serde::Serialize;

/// Pixels of every grain, grouped: grain `g` (1-based label) owns
/// `pixels[start[g-1]..start[g]]`, flat indices `r * width + c` in raster order.
#[derive(Clone, Debug)]
pub struct GrainPixels {
    pub width: usize,
    pub height: usize,
    pub start: Vec<usize>,
    pub pixels: Vec<u32>,
}

impl GrainPixels {
    pub fn from_labels(labels: ArrayView2<u32>, n: usize) -> Self {
        let (height, width) = labels.dim();
        let mut count = vec![0usize; n + 1];
        for &l in labels.iter() {
            count[l as usize] += 1;
        }
        let mut start = vec![0usize; n + 1];
        for g in 1..=n {
            start[g] = start[g - 1] + count[g];
        }
        let mut fill = start.clone();
        let mut pixels = vec![0u32; start[n]];
        for (i, &l) in labels.iter().enumerate() {
            if l > 0 {
                let g = l as usize - 1;
                pixels[fill[g]] = i as u32;
                fill[g] += 1;
            }
        }
        Self {
            width,
            height,
            start,
            pixels,
        }
    }
    pub fn len(&self) -> usize {
        self.start.len() - 1
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Pixels of grain index `g` (0-based).
    pub fn of(&self, g: usize) -> &[u32] {
        &self.pixels[self.start[g]..self.start[g + 1]]
    }
}

/// What is measured on one grain, in pixel units (x right, y down).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct GrainMeasure {
    /// Label in the label image (1-based).
    pub label: u32,
    pub area_px: f64,
    /// Diameter of the disk of the same area.
    pub d_eq_px: f64,
    pub x: f64,
    pub y: f64,
    /// Angle of the major axis from +x, counter-clockwise seen with y up, in (-pi/2, pi/2].
    pub orientation: f64,
    /// Principal second moments about the centroid (variances), major >= minor.
    pub var_major: f64,
    pub var_minor: f64,
    /// sqrt(var_major / var_minor) >= 1.
    pub aspect: f64,
    /// Whether the grain touches the container edge (cut: left out of the statistics).
    pub at_edge: bool,
}

/// Measure every grain; `inside` is the container mask (a grain with a pixel next to an
/// outside pixel or the image edge is `at_edge`).
pub fn measure_all(px: &GrainPixels, inside: ArrayView2<bool>) -> Vec<GrainMeasure> {
    (0..px.len())
        .into_par_iter()
        .map(|g| measure_one(px, g, inside))
        .collect()
}

fn measure_one(px: &GrainPixels, g: usize, inside: ArrayView2<bool>) -> GrainMeasure {
    let w = px.width;
    let pix = px.of(g);
    let n = pix.len() as f64;
    // Centre the sums on the first pixel for accuracy.
    let (r0, c0) = ((pix[0] as usize / w) as f64, (pix[0] as usize % w) as f64);
    let (mut sx, mut sy, mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    let mut at_edge = false;
    for &i in pix {
        let (r, c) = (i as usize / w, i as usize % w);
        let (x, y) = (c as f64 - c0, r as f64 - r0);
        sx += x;
        sy += y;
        sxx += x * x;
        syy += y * y;
        sxy += x * y;
        if !at_edge {
            at_edge = r == 0
                || c == 0
                || r + 1 == px.height
                || c + 1 == w
                || !inside[[r - 1, c]]
                || !inside[[r + 1, c]]
                || !inside[[r, c - 1]]
                || !inside[[r, c + 1]];
        }
    }
    let (mx, my) = (sx / n, sy / n);
    let cxx = sxx / n - mx * mx + 1.0 / 12.0;
    let cyy = syy / n - my * my + 1.0 / 12.0;
    let cxy = sxy / n - mx * my;
    // Principal axes of the pixel covariance (the 2x2 symmetric eigenproblem).
    let eig = nalgebra::SymmetricEigen::new(nalgebra::Matrix2::new(cxx, cxy, cxy, cyy));
    let major = if eig.eigenvalues[0] >= eig.eigenvalues[1] {
        0
    } else {
        1
    };
    let (l1, l2) = (eig.eigenvalues[major], eig.eigenvalues[1 - major].max(1e-12));
    let v = eig.eigenvectors.column(major);
    // Angle of the major axis in image axes (y down), then flipped to y up, in (-pi/2, pi/2];
    // a round grain (no major axis) gets 0.
    let theta_down = if l1 - l2 <= 1e-12 * l1.abs() {
        0.0
    } else {
        v[1].atan2(v[0])
    };
    let mut orientation = -theta_down;
    while orientation <= -std::f64::consts::FRAC_PI_2 {
        orientation += std::f64::consts::PI;
    }
    while orientation > std::f64::consts::FRAC_PI_2 {
        orientation -= std::f64::consts::PI;
    }
    GrainMeasure {
        label: g as u32 + 1,
        area_px: n,
        d_eq_px: (4.0 * n / std::f64::consts::PI).sqrt(),
        x: c0 + mx + 0.5,
        y: r0 + my + 0.5,
        orientation,
        var_major: l1,
        var_minor: l2,
        aspect: (l1 / l2).sqrt(),
        at_edge,
    }
}

/// Relabel `labels` keeping grains whose area is at least `min_area`, renumbered 1..=n in
/// order; returns the new count and the dropped grains' (label, area, x, y).
pub fn drop_small(
    labels: &mut Array2<u32>,
    n: usize,
    min_area: usize,
) -> (usize, Vec<(u32, usize, f64, f64)>) {
    let w = labels.dim().1;
    let mut area = vec![0usize; n + 1];
    let mut sx = vec![0.0; n + 1];
    let mut sy = vec![0.0; n + 1];
    for (i, &l) in labels.iter().enumerate() {
        area[l as usize] += 1;
        sx[l as usize] += (i % w) as f64 + 0.5;
        sy[l as usize] += (i / w) as f64 + 0.5;
    }
    let mut new_id = vec![0u32; n + 1];
    let mut dropped = Vec::new();
    let mut k = 0u32;
    for l in 1..=n {
        if area[l] >= min_area {
            k += 1;
            new_id[l] = k;
        } else if area[l] > 0 {
            dropped.push((l as u32, area[l], sx[l] / area[l] as f64, sy[l] / area[l] as f64));
        }
    }
    if !dropped.is_empty() {
        labels.mapv_inplace(|l| new_id[l as usize]);
    }
    (k as usize, dropped)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// One filled ellipse (semi-axes `a` >= `b`, px) in a `h` x `w` label image, its major axis
    /// at `theta` from +x counter-clockwise seen with y up; pixels whose centre lies inside.
    fn ellipse(h: usize, w: usize, (cx, cy): (f64, f64), a: f64, b: f64, theta: f64) -> GrainMeasure {
        let labels = Array2::from_shape_fn((h, w), |(r, c)| {
            let dx = c as f64 + 0.5 - cx;
            let up = -(r as f64 + 0.5 - cy);
            let u = dx * theta.cos() + up * theta.sin();
            let v = -dx * theta.sin() + up * theta.cos();
            u32::from((u / a).powi(2) + (v / b).powi(2) <= 1.0)
        });
        let px = GrainPixels::from_labels(labels.view(), 1);
        let inside = Array2::from_elem((h, w), true);
        measure_all(&px, inside.view())[0]
    }

    /// Difference of two axis angles, modulo pi (an axis at pi/2 is the one at -pi/2).
    fn axis_diff(a: f64, b: f64) -> f64 {
        ((a - b + FRAC_PI_2).rem_euclid(PI) - FRAC_PI_2).abs()
    }

    /// The principal axes from nalgebra's SymmetricEigen, on ellipses rasterised at +30, -60
    /// and 90 degrees, and along +x (aspect 2.5, 20 px x 8 px semi-axes, centre off the pixel grid): the
    /// orientation is the drawn one to within the pixel discretisation, with the sign of the
    /// y-up convention, and the aspect ratio is the drawn one.
    #[test]
    fn ellipse_orientation_and_aspect() {
        let mut worst = (0.0f64, 0.0f64);
        for deg in [30.0f64, -60.0, 90.0, 0.0] {
            let theta = deg.to_radians();
            let m = ellipse(80, 90, (45.3, 39.6), 20.0, 8.0, theta);
            let (dth, dasp) = (axis_diff(m.orientation, theta), (m.aspect - 2.5).abs() / 2.5);
            println!(
                "{deg} deg: orientation {:.4} deg, aspect {:.4}",
                m.orientation.to_degrees(),
                m.aspect
            );
            worst = (worst.0.max(dth), worst.1.max(dasp));
            // In (-pi/2, pi/2], the convention of GrainMeasure::orientation.
            assert!(m.orientation > -FRAC_PI_2 && m.orientation <= FRAC_PI_2);
            assert!(
                dth < ORIENT_TOL,
                "{deg} deg: got {} deg",
                m.orientation.to_degrees()
            );
            assert!(dasp < ASPECT_TOL, "{deg} deg: aspect {}", m.aspect);
            assert!(!m.at_edge);
        }
        println!(
            "worst: orientation {:.2e} rad, aspect {:.2e} relative",
            worst.0, worst.1
        );
    }

    // Measured (the four angles above, largest): orientation 1.21e-3 rad (30 deg drawn, 29.931
    // found), aspect 9.6e-3 relative (0 deg: 2.524 for 2.5); tolerances twice that.
    const ORIENT_TOL: f64 = 2.4e-3;
    const ASPECT_TOL: f64 = 1.9e-2;

    /// A rasterised disk has equal principal moments (its 4-fold symmetry makes them equal up
    /// to round-off), so it has no major axis: aspect 1 and, by the code's convention for a
    /// round grain, orientation 0.
    #[test]
    fn disk_has_no_major_axis() {
        for centre in [(40.5, 40.5), (40.0, 40.0)] {
            let m = ellipse(80, 80, centre, 15.0, 15.0, 0.7);
            println!(
                "disk at {centre:?}: var {} / {}, orientation {}",
                m.var_major, m.var_minor, m.orientation
            );
            assert!((m.aspect - 1.0).abs() < 1e-12, "aspect {}", m.aspect);
            assert_eq!(m.orientation, 0.0);
        }
    }
}
