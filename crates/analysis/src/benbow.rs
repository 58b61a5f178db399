//! The Benbow-Bridgwater law of paste extrusion (Ness et al. 2017, Eq. 1):
//! ΔP = (σ_0 + α V^m) ln(A_0/A) + (τ_0 + β V^n) M L / A, fitted in its four-parameter form
//! (m = n = 1, which Ness's linear ΔP(V) supports, Fig. 9) from the die-entry and die pressure
//! drops measured at several die velocities V, each with its standard error; and the power of
//! ΔP against V on log axes (Ness: a gradient of unity).
//!
//! Two fits: the entry drop over ln(A_0/A) against V gives σ_0 (intercept) and α (slope), the
//! die drop over ML/A gives τ_0 and β; with the yield terms dropped (σ_0 = τ_0 = 0, Ness's
//! "no apparent bulk yield-stress behavior") α and β are slopes through the origin.

use crate::{AnalysisError, Result};
use nalgebra::{DMatrix, DVector};

/// y = intercept + slope x by least squares, with standard errors from the residual variance
/// (zero intercept, and no intercept error, for a fit through the origin).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct LineFit {
    pub intercept: f64,
    pub slope: f64,
    pub intercept_se: f64,
    pub slope_se: f64,
    pub points: usize,
}

/// Least-squares straight line with standard errors (`through_origin`: y = slope x). Needs one
/// more point than parameters for the errors (they are NaN otherwise) and at least two distinct
/// x.
pub fn line_fit(x: &[f64], y: &[f64], through_origin: bool) -> Result<LineFit> {
    let p = if through_origin { 1 } else { 2 };
    if x.len() != y.len() || x.len() < p || x.iter().chain(y).any(|v| !v.is_finite()) {
        return Err(AnalysisError::invalid(
            "fit points",
            x.len(),
            "need finite (x, y) pairs of equal length, at least one per parameter",
        ));
    }
    let n = x.len();
    // A line needs spread in x: refuse x all (nearly) equal, where the normal equations are
    // singular but round-off may leave a finite inverse.
    let mean = x.iter().sum::<f64>() / n as f64;
    let spread: f64 = x.iter().map(|v| (v - mean).powi(2)).sum();
    let scale: f64 = x.iter().map(|v| v * v).sum();
    if !through_origin && spread <= 1e-12 * scale || scale == 0.0 {
        return Err(AnalysisError::invalid(
            "fit points",
            n,
            "do not fix a line (all x the same, or all zero): give points at different velocities",
        ));
    }
    let a = DMatrix::from_fn(n, p, |i, j| if j + 1 == p { x[i] } else { 1.0 });
    let b = DVector::from_column_slice(y);
    let ata = a.transpose() * &a;
    let inv = ata
        .clone()
        .try_inverse()
        .filter(|m| m.iter().all(|v| v.is_finite()));
    let degenerate =
        || AnalysisError::invalid("fit points", n, "do not fix a line (all x the same, or all zero)");
    let inv = inv.ok_or_else(degenerate)?;
    let c = &inv * a.transpose() * &b;
    let resid = &b - &a * &c;
    let dof = n as f64 - p as f64;
    let s2 = if dof > 0.0 {
        resid.norm_squared() / dof
    } else {
        f64::NAN
    };
    let se = |j: usize| (s2 * inv[(j, j)]).sqrt();
    Ok(if through_origin {
        LineFit {
            intercept: 0.0,
            slope: c[0],
            intercept_se: 0.0,
            slope_se: se(0),
            points: n,
        }
    } else {
        LineFit {
            intercept: c[0],
            slope: c[1],
            intercept_se: se(0),
            slope_se: se(1),
            points: n,
        }
    })
}

/// The extruder's geometry factors of Eq. 1 for a slab periodic in z (per unit depth):
/// ln(A_0/A) = ln(W_barrel/W_die) and ML/A = 2 L_die / W_die (two die walls).
pub fn geometry_factors(barrel_width: f64, die_width: f64, die_length: f64) -> (f64, f64) {
    ((barrel_width / die_width).ln(), 2.0 * die_length / die_width)
}

/// Eq. 1 fitted: four-parameter form (σ_0, α, τ_0, β) and two-parameter form (α, β with the
/// yield terms zero), in Pa and Pa s/m.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct BenbowBridgwater {
    pub ln_area_ratio: f64,
    pub wall_factor: f64,
    /// σ_0 = intercept, α = slope of the entry drop / ln(A_0/A) against V.
    pub entry: LineFit,
    /// τ_0 = intercept, β = slope of the die drop / (ML/A) against V.
    pub die: LineFit,
    /// α and β through the origin.
    pub entry_no_yield: LineFit,
    pub die_no_yield: LineFit,
}

/// Fit Eq. 1 to the die velocities `v` and the entry and die pressure drops measured at them.
pub fn fit(
    v: &[f64],
    dp_entry: &[f64],
    dp_die: &[f64],
    ln_area_ratio: f64,
    wall_factor: f64,
) -> Result<BenbowBridgwater> {
    if !(ln_area_ratio > 0.0 && wall_factor > 0.0) {
        return Err(AnalysisError::invalid(
            "geometry factors",
            format!("ln(A0/A) = {ln_area_ratio}, ML/A = {wall_factor}"),
            "both must be positive (a die narrower than the barrel, of positive length)",
        ));
    }
    let e: Vec<f64> = dp_entry.iter().map(|p| p / ln_area_ratio).collect();
    let d: Vec<f64> = dp_die.iter().map(|p| p / wall_factor).collect();
    Ok(BenbowBridgwater {
        ln_area_ratio,
        wall_factor,
        entry: line_fit(v, &e, false)?,
        die: line_fit(v, &d, false)?,
        entry_no_yield: line_fit(v, &e, true)?,
        die_no_yield: line_fit(v, &d, true)?,
    })
}

impl BenbowBridgwater {
    /// ΔP of the four-parameter form at die velocity `v`.
    pub fn pressure_drop(&self, v: f64) -> f64 {
        (self.entry.intercept + self.entry.slope * v) * self.ln_area_ratio
            + (self.die.intercept + self.die.slope * v) * self.wall_factor
    }
}

/// The power of y against x on log axes (slope of ln y on ln x) with its standard error; points
/// with a non-positive value are refused.
pub fn log_slope(x: &[f64], y: &[f64]) -> Result<LineFit> {
    if x.iter().chain(y).any(|&v| v <= 0.0) {
        return Err(AnalysisError::invalid(
            "log-log fit points",
            x.len(),
            "every x and y must be positive (a run that did not flow, or a pressure that did not drop?)",
        ));
    }
    let lx: Vec<f64> = x.iter().map(|v| v.ln()).collect();
    let ly: Vec<f64> = y.iter().map(|v| v.ln()).collect();
    line_fit(&lx, &ly, false)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eq. 1 with m = n = 1 sampled exactly: the fit returns its four parameters to round-off.
    #[test]
    fn exact_data_return_the_four_parameters() {
        let (l, w) = geometry_factors(100.0, 20.0, 200.0);
        assert!((l - 5f64.ln()).abs() < 1e-15 && w == 20.0);
        let (s0, a, t0, b) = (2.0e4, 3.0e6, 150.0, 4.0e4);
        let v = [0.01, 0.02, 0.05, 0.1, 0.2];
        let e: Vec<f64> = v.iter().map(|v| (s0 + a * v) * l).collect();
        let d: Vec<f64> = v.iter().map(|v| (t0 + b * v) * w).collect();
        let f = fit(&v, &e, &d, l, w).unwrap();
        for (got, want) in [
            (f.entry.intercept, s0),
            (f.entry.slope, a),
            (f.die.intercept, t0),
            (f.die.slope, b),
        ] {
            // Measured: 1e-12 relative at worst (the intercepts, from sums of ~1e5).
            assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
        }
        assert!(f.entry.slope_se < 1e-6 * a);
        let total = f.pressure_drop(0.07);
        let want = (s0 + a * 0.07) * l + (t0 + b * 0.07) * w;
        assert!((total - want).abs() < 1e-9 * want);
    }

    /// Standard errors against the textbook formula SE(slope) = s / √Σ(x − x̄)² on scattered
    /// points, and the fit through the origin against Σxy / Σx².
    #[test]
    fn standard_errors_follow_the_closed_forms() {
        let x = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let y = [2.1, 3.9, 6.2, 7.8, 10.3, 11.9];
        let f = line_fit(&x, &y, false).unwrap();
        let n = x.len() as f64;
        let mx = x.iter().sum::<f64>() / n;
        let my = y.iter().sum::<f64>() / n;
        let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
        let slope = x.iter().zip(&y).map(|(a, b)| (a - mx) * (b - my)).sum::<f64>() / sxx;
        let icpt = my - slope * mx;
        let s2 = x
            .iter()
            .zip(&y)
            .map(|(a, b)| (b - icpt - slope * a).powi(2))
            .sum::<f64>()
            / (n - 2.0);
        assert!((f.slope - slope).abs() < 1e-12 && (f.intercept - icpt).abs() < 1e-12);
        assert!((f.slope_se - (s2 / sxx).sqrt()).abs() < 1e-12);
        assert!((f.intercept_se - (s2 * (1.0 / n + mx * mx / sxx)).sqrt()).abs() < 1e-12);
        let o = line_fit(&x, &y, true).unwrap();
        let sxy: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
        let sxx0: f64 = x.iter().map(|a| a * a).sum();
        assert!((o.slope - sxy / sxx0).abs() < 1e-12 && o.intercept == 0.0);
    }

    #[test]
    fn a_power_law_has_its_exponent_as_log_slope() {
        let v = [1e-3, 3e-3, 1e-2, 3e-2];
        let dp: Vec<f64> = v.iter().map(|v: &f64| 7e7 * v.powf(1.3)).collect();
        let f = log_slope(&v, &dp).unwrap();
        assert!((f.slope - 1.3).abs() < 1e-12);
        assert!(log_slope(&[1.0, 2.0], &[1.0, -1.0]).is_err());
        assert!(line_fit(&[1.0, 1.0, 1.0], &[1.0, 2.0, 3.0], false).is_err());
        // Equal x that round-off leaves a finite inverse for.
        assert!(line_fit(&[0.07, 0.07, 0.07], &[1.0, 2.0, 3.0], false).is_err());
        assert!(fit(&v, &dp, &dp, 0.0, 1.0).is_err());
    }
}
