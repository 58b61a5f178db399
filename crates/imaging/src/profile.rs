//! Profiles over ROIs, least-squares fits, and the meniscus line scan of Su et al. (2020)
//! Fig. 12g-h: thickness `L_alloy^n(y)` along a line (Eq. 2), surface `z = +-L/2`
//! (Eq. 22), its radius of curvature `R` from a parabola fitted at the thinnest point, and
//! the Young-Laplace pressure drop `dp = -2 gamma / R` (Eq. 23).

use crate::{ImagingError, Result, Roi};
use nalgebra::{DMatrix, DVector};
use ndarray::ArrayView2;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ProfileAxis {
    /// Position along x (columns); each value averages the ROI's rows.
    X,
    /// Position along y (rows); each value averages the ROI's columns.
    Y,
}

/// Mean of the finite pixels of `roi` at each position along `axis`: (pixel centres, means).
pub fn roi_profile(
    f: ArrayView2<f64>,
    roi: Roi,
    axis: ProfileAxis,
    name: &str,
) -> Result<(Vec<f64>, Vec<f64>)> {
    roi.check(name, f.dim())?;
    let v = roi.view(f);
    let (lanes, offset) = match axis {
        ProfileAxis::X => (v.columns(), roi.x),
        ProfileAxis::Y => (v.rows(), roi.y),
    };
    let mut pos = Vec::new();
    let mut val = Vec::new();
    for (i, lane) in lanes.into_iter().enumerate() {
        let (mut s, mut n) = (0.0, 0usize);
        for &x in lane {
            if x.is_finite() {
                s += x;
                n += 1;
            }
        }
        pos.push((offset + i) as f64 + 0.5);
        val.push(if n > 0 { s / n as f64 } else { f64::NAN });
    }
    Ok((pos, val))
}

/// Straight-line least-squares fit `y = slope x + intercept` with its coefficient of determination.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LinearFit {
    pub slope: f64,
    pub intercept: f64,
    pub r2: f64,
}

pub fn linear_fit(x: &[f64], y: &[f64]) -> Result<LinearFit> {
    if x.len() != y.len() || x.len() < 2 {
        return Err(ImagingError::invalid(
            "fit points",
            x.len(),
            "need at least two (x, y) pairs of equal length",
        ));
    }
    let n = x.len() as f64;
    let mx = x.iter().sum::<f64>() / n;
    let my = y.iter().sum::<f64>() / n;
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let syy: f64 = y.iter().map(|b| (b - my).powi(2)).sum();
    let slope = sxy / sxx;
    let intercept = my - slope * mx;
    let ss_res: f64 = x
        .iter()
        .zip(y)
        .map(|(a, b)| (b - slope * a - intercept).powi(2))
        .sum();
    Ok(LinearFit {
        slope,
        intercept,
        r2: 1.0 - ss_res / syy,
    })
}

/// Least-squares parabola `y = c0 + c1 (x - x0) + c2 (x - x0)^2` (centred for conditioning).
pub fn quadratic_fit(x: &[f64], y: &[f64], x0: f64) -> Result<[f64; 3]> {
    if x.len() != y.len() || x.len() < 3 {
        return Err(ImagingError::invalid(
            "fit points",
            x.len(),
            "need at least three (x, y) pairs",
        ));
    }
    // The design matrix [1, u, u^2] with u = t / max|t| solved in the least-squares sense by
    // SVD (rank-revealing: points at fewer than three distinct x cannot fix a parabola). The
    // scaling makes the relative rank tolerance mean the same in metres as in pixels: with t
    // itself, t^2 of a scan in 10 nm steps fell below 1e-12 of the largest singular value.
    let scale = x.iter().map(|&v| (v - x0).abs()).fold(0.0, f64::max);
    let degenerate = || {
        ImagingError::invalid(
            "fit points",
            x.len(),
            "are degenerate (fewer than three distinct x)",
        )
    };
    if !(scale > 0.0 && scale.is_finite()) {
        return Err(degenerate());
    }
    let a = DMatrix::from_fn(x.len(), 3, |i, j| ((x[i] - x0) / scale).powi(j as i32));
    let b = DVector::from_column_slice(y);
    let svd = a.svd(true, true);
    let tol = 1e-12 * svd.singular_values.max();
    if svd.rank(tol) < 3 {
        return Err(degenerate());
    }
    let c = svd
        .solve(&b, tol)
        .map_err(|e| ImagingError::invalid("fit points", x.len(), e))?;
    Ok([c[0], c[1] / scale, c[2] / (scale * scale)])
}

/// Result of the meniscus fit along a thickness line scan.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct MeniscusFit {
    /// Position (m) and thickness (m) of the thinnest point.
    pub y_min: f64,
    pub l_min: f64,
    /// Radius of curvature of the surface `z = L/2` (Eq. 22) at the thinnest point, m.
    pub radius: f64,
    /// Young-Laplace pressure change, Pa (Eq. 23).
    pub dp: f64,
}

/// Fit the meniscus: parabola to `L(y)` within `half_width` (m) of the thinnest point;
/// `z = L/2` gives `z'' = c2`, so `R = 1 / c2`, and `dp = -2 gamma / R` (Eq. 23).
pub fn meniscus_fit(y: &[f64], l: &[f64], half_width: f64, gamma: f64) -> Result<MeniscusFit> {
    let (imin, _) = l
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .min_by(|a, b| a.1.total_cmp(b.1))
        .ok_or_else(|| ImagingError::invalid("line_scan", "all NaN", "has no finite thickness"))?;
    let y0 = y[imin];
    let (xs, ys): (Vec<f64>, Vec<f64>) = y
        .iter()
        .zip(l)
        .filter(|(a, b)| (**a - y0).abs() <= half_width && b.is_finite())
        .map(|(a, b)| (*a, *b))
        .unzip();
    let c = quadratic_fit(&xs, &ys, y0)?;
    if c[2].is_nan() || c[2] <= 0.0 {
        return Err(ImagingError::invalid(
            "line_scan.fit_half_width",
            half_width,
            "the thickness has no minimum (curvature <= 0) in this window; widen it or move the line",
        ));
    }
    // Vertex of the fitted parabola, a sub-pixel thinnest point.
    let t = -c[1] / (2.0 * c[2]);
    let radius = 1.0 / c[2];
    Ok(MeniscusFit {
        y_min: y0 + t,
        l_min: c[0] + c[1] * t + c[2] * t * t,
        radius,
        dp: -2.0 * gamma / radius,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_fit_exact_line() {
        let x = [0.0, 1.0, 2.0, 3.0];
        let y = [1.0, 3.0, 5.0, 7.0];
        let f = linear_fit(&x, &y).unwrap();
        assert!(
            (f.slope - 2.0).abs() < 1e-12 && (f.intercept - 1.0).abs() < 1e-12 && (f.r2 - 1.0).abs() < 1e-12
        );
    }

    #[test]
    fn quadratic_fit_exact_and_degenerate() {
        let x: Vec<f64> = (0..7).map(|i| i as f64 * 0.3).collect();
        let y: Vec<f64> = x
            .iter()
            .map(|t| 2.0 - 0.5 * (t - 1.0) + 3.0 * (t - 1.0).powi(2))
            .collect();
        let c = quadratic_fit(&x, &y, 1.0).unwrap();
        for (got, want) in c.iter().zip([2.0, -0.5, 3.0]) {
            assert!((got - want).abs() < 1e-12, "{c:?}");
        }
        // Two distinct x cannot fix a parabola.
        let err = quadratic_fit(&[1.0, 1.0, 2.0, 2.0], &[0.0, 0.1, 1.0, 1.1], 0.0).unwrap_err();
        assert!(err.to_string().contains("degenerate"), "{err}");
    }

    /// Line scans in metres: pixels of 1 um (t = x - x0 from 1e-6 to 1e-4 m) and of 10 nm
    /// (1e-8 to 1e-6 m), so the columns of [1, t, t^2] span eight to sixteen decades. The rank
    /// test must not call that degenerate (before t was scaled, the 10 nm scan was refused:
    /// its t^2 column's singular value fell below 1e-12 of the largest), and the coefficients
    /// come back to round-off.
    #[test]
    fn quadratic_fit_in_metres() {
        for (dx, c1, c2, tol) in [(1e-6, -2.0e-3, 5.0e3, 2.5e-12), (1e-8, 3.0e-2, 4.0e5, 2.5e-11)] {
            let (c0, x0) = (1.4e-4, 3.2e-3);
            let x: Vec<f64> = (1..=100).map(|i| x0 + i as f64 * dx).collect();
            let y: Vec<f64> = x
                .iter()
                .map(|&x| c0 + c1 * (x - x0) + c2 * (x - x0).powi(2))
                .collect();
            let c = quadratic_fit(&x, &y, x0).unwrap();
            let rel: Vec<f64> = c
                .iter()
                .zip([c0, c1, c2])
                .map(|(got, want)| ((got - want) / want).abs())
                .collect();
            println!("spacing {dx:e} m: relative errors {rel:?}");
            // Measured, largest (the slope): 1.1e-12 at 1 um, 1.0e-11 at 10 nm; x - x0 itself
            // carries a relative round-off of about 1e-16 x0 / (x - x0), which c1 inherits.
            assert!(rel.iter().all(|&e| e < tol), "{c:?}: {rel:?}");
            // Points at two x only are degenerate at this scale too.
            let err = quadratic_fit(&[x0, x0, x0 + dx, x0 + dx], &[0.0, dx, dx, 2.0 * dx], x0);
            assert!(err.unwrap_err().to_string().contains("degenerate"));
        }
    }

    /// Su et al. (2020) Sect. 4.4: R ~ 100 um with gamma ~ 0.7 J/m^2 gives dp ~ -14.00 kPa (Eq. 23).
    #[test]
    fn circular_meniscus_gives_papers_pressure_drop() {
        let (r, lmin) = (100e-6, 140e-6);
        let y: Vec<f64> = (-200..=200).map(|i| i as f64 * 0.5e-6).collect();
        // Both faces are circular arcs of radius R: L = L_min + 2 (R - sqrt(R^2 - y^2)).
        let l: Vec<f64> = y
            .iter()
            .map(|y| lmin + 2.0 * (r - (r * r - y * y).max(0.0).sqrt()))
            .collect();
        let f = meniscus_fit(&y, &l, 15e-6, 0.7).unwrap();
        // z = L/2 is one face: its radius is R.
        assert!((f.radius - r).abs() / r < 0.02, "R = {}", f.radius);
        assert!((f.dp - (-14.0e3)).abs() < 0.3e3, "dp = {}", f.dp);
        assert!(f.y_min.abs() < 1e-7 && (f.l_min - lmin).abs() < 1e-8);
    }
}
