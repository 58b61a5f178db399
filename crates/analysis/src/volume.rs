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

/// The part of `subject` on the left of the directed line a → b (one Sutherland-Hodgman pass).
fn clip_left(subject: &[P2], a: P2, b: P2) -> Vec<P2> {
    let side = |p: P2| (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]);
    let n = subject.len();
    let mut out = Vec::with_capacity(n + 2);
    for i in 0..n {
        let (p, q) = (subject[i], subject[(i + 1) % n]);
        let (sp, sq) = (side(p), side(q));
        if sp >= 0.0 {
            out.push(p);
        }
        if (sp >= 0.0) != (sq >= 0.0) {
            let t = sp / (sp - sq);
            out.push([p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1])]);
        }
    }
    out
}

/// Area of `subject ∩ clip` for a simple polygon `subject` and a convex polygon `clip` (either
/// orientation). For a concave subject the clipped ring may hold zero-width bridges, which add
/// no area.
pub fn intersection_area(subject: &[P2], clip: &[P2]) -> f64 {
    let signed = |p: &[P2]| {
        let n = p.len();
        0.5 * (0..n)
            .map(|i| p[i][0] * p[(i + 1) % n][1] - p[(i + 1) % n][0] * p[i][1])
            .sum::<f64>()
    };
    let mut c = clip.to_vec();
    if signed(&c) < 0.0 {
        c.reverse();
    }
    let mut poly = subject.to_vec();
    for i in 0..c.len() {
        if poly.is_empty() {
            return 0.0;
        }
        poly = clip_left(&poly, c[i], c[(i + 1) % c.len()]);
    }
    polygon_area(&poly)
}

/// The region behind a push-plate's face (`left` → `right`, moving along `dir`): the face swept
/// back by `depth`, a quadrilateral. Su's A_def (Eq. 18) is the membrane polygon's area minus
/// its overlap with this region (the plate's penetration).
pub fn behind_plate(left: P2, right: P2, dir: P2, depth: f64) -> [P2; 4] {
    let back = |p: P2| [p[0] - depth * dir[0], p[1] - depth * dir[1]];
    [left, right, back(right), back(left)]
}

/// A_def of Eq. 18: the area of the polygon through the membrane grains' centroids minus the
/// plate's penetration.
pub fn sample_area(ring: &[P2], plate: Option<[P2; 4]>) -> f64 {
    polygon_area(ring) - plate.map_or(0.0, |q| intersection_area(ring, &q))
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

    /// A 2 × 3 sample with a plate face at y = 0.5 pushed in from below between x = 0.5 and 1.5:
    /// the plate takes 1 × 0.5 of it.
    #[test]
    fn plate_penetration_is_taken_off_the_sample_area() {
        let ring = [[0.0, 0.0], [2.0, 0.0], [2.0, 3.0], [0.0, 3.0]];
        let q = behind_plate([0.5, 0.5], [1.5, 0.5], [0.0, 1.0], 10.0);
        assert!((intersection_area(&ring, &q) - 0.5).abs() < 1e-15);
        assert!((sample_area(&ring, Some(q)) - 5.5).abs() < 1e-15);
        assert_eq!(sample_area(&ring, None), 6.0);
        // A concave (L-shaped) sample: the overlap counts only the material.
        let l = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [1.0, 1.0],
            [1.0, 2.0],
            [0.0, 2.0],
        ];
        let q = behind_plate([0.0, 1.5], [2.0, 1.5], [0.0, 1.0], 10.0);
        assert!((intersection_area(&l, &q) - 2.5).abs() < 1e-15);
    }
}
