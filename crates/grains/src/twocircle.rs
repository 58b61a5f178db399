//! A grain as two overlapping circles (Su et al. 2020, Sect. 2.3 and Fig. 1c-d): two equal
//! circles of radius r whose centres sit at +-s from the grain's centroid along its major
//! axis. With t = s / r in [0, 1], the union's area is r^2 a(t) and its principal variances
//! are r^2 v_major(t), r^2 v_minor(t); the fit takes t from the measured aspect ratio
//! sqrt(v_major / v_minor) and then r from the measured area, so area, centroid,
//! orientation and elongation are matched exactly (up to t = 1, two circles just touching,
//! aspect sqrt(5) = 2.236; more elongated grains get t = 1 and a fit error that says so).
//! A grain whose aspect ratio is below `round_aspect` is one circle of the same area.

use crate::measure::GrainMeasure;
use serde::Serialize;
use std::f64::consts::PI;
use std::sync::OnceLock;

/// One fitted circle, pixel coordinates (x right, y down).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FitCircle {
    pub x: f64,
    pub y: f64,
    pub r: f64,
}

/// The fitted circles of one grain (one or two).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Fit {
    pub circles: Vec<FitCircle>,
    /// s / r of the pair (0 for a single circle).
    pub t: f64,
    /// Area of the union of the circles, px^2.
    pub area_px: f64,
    /// Pixels of the grain not covered plus covered pixels not of the grain, over the
    /// grain's area (0 is a perfect fit).
    pub error: f64,
}

/// Shape functions of the two-circle union with r = 1: area, major and minor variance.
/// Lens (intersection) integrals by the substitution y = sin(phi), which keeps the
/// integrands smooth: half-width w = cos(phi) - t, dy = cos(phi) dphi.
pub fn shape(t: f64) -> (f64, f64, f64) {
    let t = t.clamp(0.0, 1.0);
    let ph = t.acos();
    let m = 256; // Simpson intervals (even)
    let dphi = 2.0 * ph / m as f64;
    let (mut lens, mut ixx, mut iyy) = (0.0, 0.0, 0.0);
    for k in 0..=m {
        let phi = -ph + k as f64 * dphi;
        let wgt = if k == 0 || k == m {
            1.0
        } else if k % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let (s, c) = phi.sin_cos();
        let wd = (c - t).max(0.0);
        lens += wgt * 2.0 * wd * c;
        ixx += wgt * (2.0 / 3.0) * wd.powi(3) * c;
        iyy += wgt * 2.0 * wd * s * s * c;
    }
    let f = dphi / 3.0;
    let (lens, ixx, iyy) = (lens * f, ixx * f, iyy * f);
    let area = 2.0 * PI - lens;
    let i_major = 2.0 * PI * (0.25 + t * t) - ixx;
    let i_minor = 2.0 * PI * 0.25 - iyy;
    (area, i_major / area, i_minor / area)
}

struct Table {
    t: Vec<f64>,
    aspect: Vec<f64>,
    area: Vec<f64>,
}

const TABLE_N: usize = 2001;

fn table() -> &'static Table {
    static T: OnceLock<Table> = OnceLock::new();
    T.get_or_init(|| {
        let t: Vec<f64> = (0..TABLE_N).map(|i| i as f64 / (TABLE_N - 1) as f64).collect();
        let (mut aspect, mut area) = (Vec::with_capacity(TABLE_N), Vec::with_capacity(TABLE_N));
        for &ti in &t {
            let (a, vmaj, vmin) = shape(ti);
            aspect.push((vmaj / vmin).sqrt());
            area.push(a);
        }
        Table { t, aspect, area }
    })
}

/// Largest aspect ratio two overlapping circles can have (t = 1): sqrt(5).
pub fn max_aspect() -> f64 {
    *table().aspect.last().expect("table")
}

/// t whose two-circle union has aspect ratio `aspect` (clamped to [0, 1]), and a(t).
pub fn t_for_aspect(aspect: f64) -> (f64, f64) {
    let tb = table();
    if aspect <= 1.0 {
        return (0.0, PI);
    }
    // The aspect ratio rises monotonically with t: binary search, then linear interpolation.
    let k = tb.aspect.partition_point(|&a| a < aspect);
    if k >= TABLE_N {
        return (1.0, tb.area[TABLE_N - 1]);
    }
    if k == 0 {
        return (0.0, PI);
    }
    let f = (aspect - tb.aspect[k - 1]) / (tb.aspect[k] - tb.aspect[k - 1]);
    let t = tb.t[k - 1] + f * (tb.t[k] - tb.t[k - 1]);
    let a = tb.area[k - 1] + f * (tb.area[k] - tb.area[k - 1]);
    (t, a)
}

/// Circles of the grain with measured area, centroid, orientation (y up) and aspect ratio.
pub fn fit_shape(
    area: f64,
    x: f64,
    y: f64,
    orientation: f64,
    aspect: f64,
    round_aspect: f64,
) -> (Vec<FitCircle>, f64) {
    if aspect < round_aspect {
        return (
            vec![FitCircle {
                x,
                y,
                r: (area / PI).sqrt(),
            }],
            0.0,
        );
    }
    let (t, a) = t_for_aspect(aspect);
    let r = (area / a).sqrt();
    let s = t * r;
    // Orientation is counter-clockwise with y up; in image axes (y down) the y step flips.
    let (ux, uy) = (orientation.cos(), -orientation.sin());
    let circles = vec![
        FitCircle {
            x: x - s * ux,
            y: y - s * uy,
            r,
        },
        FitCircle {
            x: x + s * ux,
            y: y + s * uy,
            r,
        },
    ];
    (circles, t)
}

/// Area of the union of one or two equal circles, in px^2.
pub fn union_area(circles: &[FitCircle]) -> f64 {
    match circles {
        [c] => PI * c.r * c.r,
        [a, b] => {
            let s = 0.5 * ((a.x - b.x).hypot(a.y - b.y));
            let (ar, _, _) = shape((s / a.r).min(1.0));
            if s >= a.r {
                2.0 * PI * a.r * a.r
            } else {
                ar * a.r * a.r
            }
        }
        _ => circles.iter().map(|c| PI * c.r * c.r).sum(),
    }
}

/// Fit grain `m` whose pixels are `pixels` (flat indices, width `w`) in the label image
/// `labels` (flat, same width), and measure the fit error on the pixel grid.
pub fn fit_grain(m: &GrainMeasure, pixels: &[u32], labels: &[u32], w: usize, round_aspect: f64) -> Fit {
    let (circles, t) = fit_shape(m.area_px, m.x, m.y, m.orientation, m.aspect, round_aspect);
    let h = labels.len() / w;
    let covered = |x: f64, y: f64| {
        circles
            .iter()
            .any(|c| (x - c.x).powi(2) + (y - c.y).powi(2) < c.r * c.r)
    };
    // Grain pixels outside the circles.
    let missed = pixels
        .iter()
        .filter(|&&i| !covered((i as usize % w) as f64 + 0.5, (i as usize / w) as f64 + 0.5))
        .count();
    // Pixels inside the circles that are not the grain's.
    let (mut x0, mut x1, mut y0, mut y1) =
        (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
    for c in &circles {
        x0 = x0.min(c.x - c.r);
        x1 = x1.max(c.x + c.r);
        y0 = y0.min(c.y - c.r);
        y1 = y1.max(c.y + c.r);
    }
    let c0 = x0.floor().max(0.0) as usize;
    let c1 = (x1.ceil().max(0.0) as usize).min(w);
    let r0 = y0.floor().max(0.0) as usize;
    let r1 = (y1.ceil().max(0.0) as usize).min(h);
    let mut extra = 0usize;
    for r in r0..r1 {
        for c in c0..c1 {
            if labels[r * w + c] != m.label && covered(c as f64 + 0.5, r as f64 + 0.5) {
                extra += 1;
            }
        }
    }
    let area_px = union_area(&circles);
    Fit {
        circles,
        t,
        area_px,
        error: (missed + extra) as f64 / m.area_px,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn shape_limits_are_one_disk_and_two_tangent_disks() {
        let (a0, vx0, vy0) = shape(0.0);
        assert_relative_eq!(a0, PI, max_relative = 1e-9);
        assert_relative_eq!(vx0, 0.25, max_relative = 1e-9);
        assert_relative_eq!(vy0, 0.25, max_relative = 1e-9);
        let (a1, vx1, vy1) = shape(1.0);
        assert_relative_eq!(a1, 2.0 * PI, max_relative = 1e-9);
        assert_relative_eq!(vx1, 1.25, max_relative = 1e-9);
        assert_relative_eq!(vy1, 0.25, max_relative = 1e-9);
        assert_relative_eq!(max_aspect(), 5f64.sqrt(), max_relative = 1e-9);
    }

    #[test]
    fn lens_area_matches_the_closed_form() {
        // Lens of two unit circles at distance 2t: 2 acos(t) - 2 t sqrt(1 - t^2).
        for &t in &[0.1, 0.4, 0.7, 0.95] {
            let (a, _, _) = shape(t);
            let lens = 2.0 * f64::acos(t) - 2.0 * t * (1.0 - t * t).sqrt();
            assert_relative_eq!(a, 2.0 * PI - lens, max_relative = 1e-8);
        }
    }

    #[test]
    fn aspect_inverts() {
        for &t in &[0.05, 0.3, 0.6, 0.9] {
            let (_, vx, vy) = shape(t);
            let (t2, _) = t_for_aspect((vx / vy).sqrt());
            assert!((t2 - t).abs() < 1e-4, "{t} -> {t2}");
        }
    }
}
