//! The three volumetric strains of Su et al. (2020) and how they relate. For a region whose area
//! changes from A₀ to A = J A₀ under a displacement gradient H (J = det(I + H)):
//!
//! - **Eq. 5 (XIP, from intensity)**: ε_vol = g_S⁰/gⁿ_S − 1. The grains keep their area, so the
//!   solid fraction of a material region falls as 1/J: ε_vol = J − 1, the engineering area strain.
//! - **Eq. 18 (ε_vol^DEM)**: ln(A_def/A₀) = ln J, the logarithmic area strain of the whole sample.
//! - **TRI (Figs. 6, 8, 11)**: ε_xx + ε_yy = tr H, the small-strain trace.
//!
//! They agree to first order and differ at second: J − 1 = tr H + det H exactly, and
//! ln J = (J − 1) − (J − 1)²/2 + … For an isotropic strain with tr H = e, det H = e²/4, so at the
//! paper's largest strains (e = −0.25 ahead of the plate, Fig. 11; +0.2 in the dilation band,
//! Fig. 6g-h) the three differ by 0.01-0.03 ([`isotropic`]; docs/analysis.md has the table).
//! A rigid rotation θ has J = 1 but tr H = 2(cos θ − 1): TRI reads rotation of a triangle as a
//! small contraction, which Eq. 5 and Eq. 18 do not.

use crate::P2;
use serde::Serialize;

/// Eq. 18: ε_vol^DEM = ln(A_def / A₀).
pub fn eps_vol_dem(a_def: f64, a0: f64) -> f64 {
    (a_def / a0).ln()
}

/// What Eq. 5 measures for an area ratio J (grains conserved): J − 1.
pub fn eq5_from_area_ratio(j: f64) -> f64 {
    j - 1.0
}

/// The three measures for an isotropic strain of trace `e` (H = e/2 I).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ThreeMeasures {
    /// ε_xx + ε_yy (TRI).
    pub trace: f64,
    /// J − 1 (Eq. 5).
    pub eq5: f64,
    /// ln J (Eq. 18).
    pub eq18: f64,
}

/// [`ThreeMeasures`] of the isotropic strain with ε_xx + ε_yy = `e`.
pub fn isotropic(e: f64) -> ThreeMeasures {
    let j = (1.0 + 0.5 * e).powi(2);
    ThreeMeasures {
        trace: e,
        eq5: j - 1.0,
        eq18: j.ln(),
    }
}

/// Area of a closed polygon (shoelace, absolute).
pub fn polygon_area(p: &[P2]) -> f64 {
    let n = p.len();
    if n < 3 {
        return 0.0;
    }
    0.5 * (0..n)
        .map(|i| {
            let (a, b) = (p[i], p[(i + 1) % n]);
            a[0] * b[1] - b[0] * a[1]
        })
        .sum::<f64>()
        .abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table in docs/analysis.md ("Three volumetric strains"): analytic, to 1e-4.
    #[test]
    fn the_three_measures_at_the_papers_strains() {
        let table = [
            (-0.25, -0.2344, -0.2671),
            (-0.18, -0.1719, -0.1886),
            (-0.05, -0.0494, -0.0506),
            (0.05, 0.0506, 0.0494),
            (0.2, 0.21, 0.1906),
        ];
        for (e, eq5, eq18) in table {
            let m = isotropic(e);
            assert!(
                (m.eq5 - eq5).abs() < 1e-4 && (m.eq18 - eq18).abs() < 1e-4,
                "{e}: {m:?}"
            );
            // J - 1 = tr H + det H exactly.
            assert!((m.eq5 - (e + e * e / 4.0)).abs() < 1e-15);
        }
        assert!((eps_vol_dem(1.1, 1.0) - 1.1f64.ln()).abs() < 1e-15);
        assert_eq!(eq5_from_area_ratio(0.9), 0.9 - 1.0);
    }

    #[test]
    fn polygon_area_either_orientation() {
        let sq = [[0.0, 0.0], [2.0, 0.0], [2.0, 3.0], [0.0, 3.0]];
        assert_eq!(polygon_area(&sq), 6.0);
        let mut r = sq;
        r.reverse();
        assert_eq!(polygon_area(&r), 6.0);
        assert_eq!(polygon_area(&sq[..2]), 0.0);
    }
}
