//! The shear-cracking criterion of Su et al. (2020) Sect. 3.5 and Fig. 10: a meniscus is drawn in
//! (a crack starts) the first time the liquid pressure change Δp (Eq. 19) on a liquid node falls
//! below Δp_c = −0.03 Pa. Reported: when (time, push-plate displacement u_y,min in d̄) and where,
//! relative to the push-plate's corners (Su: "adjacent to or above the top-right corner",
//! in agreement with the experiments' first cracks, Fig. 12j).
//!
//! Only liquid nodes count: nodes without liquid carry NaN and never cross (the runs write Δp
//! statistics over liquid nodes only).

use crate::P2;
use serde::Serialize;

/// Su et al. 2020 Sect. 3.5: Δp_c = −0.03 Pa for the 2D LBM.
pub const DP_C: f64 = -0.03;

/// The first sampled instant at which the minimum Δp is below the threshold.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Crossing {
    /// Row of the series.
    pub index: usize,
    pub time: f64,
    /// Push-plate displacement at that row (in d̄): u_y,min of Fig. 10.
    pub u_d: f64,
    /// The displacement of the row before (in d̄; the crossing happened in between).
    pub u_d_before: f64,
    /// Δp_min at that row (Pa).
    pub dp: f64,
}

/// The first row where `dp_min[i] < threshold` (NaN rows are skipped: no liquid node).
pub fn first_crossing(time: &[f64], u_d: &[f64], dp_min: &[f64], threshold: f64) -> Option<Crossing> {
    let n = time.len().min(u_d.len()).min(dp_min.len());
    let i = (0..n).find(|&i| dp_min[i] < threshold)?;
    Some(Crossing {
        index: i,
        time: time[i],
        u_d: u_d[i],
        u_d_before: if i > 0 { u_d[i - 1] } else { u_d[i] },
        dp: dp_min[i],
    })
}

/// Where a point lies relative to the push-plate's top corners, in units of d̄.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Site {
    /// "left" or "right": the nearer top corner.
    pub corner: &'static str,
    /// Offset from that corner (d̄): x to the right, y up (above the plate's face is positive).
    pub dx_d: f64,
    pub dy_d: f64,
    /// Distance to that corner (d̄).
    pub distance_d: f64,
    /// Whether the point is above the plate's face (y above the corners' line).
    pub above: bool,
}

/// The site `p` relative to the plate's top-left and top-right corners (current positions).
pub fn site(p: P2, left: P2, right: P2, d_bar: f64) -> Site {
    let dl = (p[0] - left[0]).hypot(p[1] - left[1]);
    let dr = (p[0] - right[0]).hypot(p[1] - right[1]);
    let (corner, c, d) = if dr <= dl {
        ("right", right, dr)
    } else {
        ("left", left, dl)
    };
    // Height above the face: the line through both corners.
    let (tx, ty) = (right[0] - left[0], right[1] - left[1]);
    let cross = tx * (p[1] - left[1]) - ty * (p[0] - left[0]);
    Site {
        corner,
        dx_d: (p[0] - c[0]) / d_bar,
        dy_d: (p[1] - c[1]) / d_bar,
        distance_d: d / d_bar,
        above: cross > 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_crossing_skips_dry_rows_and_reports_the_bracket() {
        let t = [0.0, 1.0, 2.0, 3.0, 4.0];
        let u = [0.0, 0.5, 1.0, 1.5, 2.0];
        let dp = [0.0, f64::NAN, -0.02, -0.031, -0.5];
        let c = first_crossing(&t, &u, &dp, DP_C).unwrap();
        assert_eq!(
            (c.index, c.time, c.u_d, c.u_d_before, c.dp),
            (3, 3.0, 1.5, 1.0, -0.031)
        );
        assert!(first_crossing(&t, &u, &[0.0, -0.03, -0.01, f64::NAN, 0.0], DP_C).is_none());
    }

    #[test]
    fn site_names_the_nearer_corner_and_whether_it_is_above() {
        let (l, r) = ([2.0, 1.0], [4.0, 1.0]);
        let s = site([4.5, 2.0], l, r, 0.5);
        assert_eq!(s.corner, "right");
        assert!(s.above && (s.dx_d - 1.0).abs() < 1e-15 && (s.dy_d - 2.0).abs() < 1e-15);
        let s = site([1.0, 0.5], l, r, 0.5);
        assert_eq!(s.corner, "left");
        assert!(!s.above);
        assert!((s.distance_d - (1.25f64).sqrt() / 0.5).abs() < 1e-15);
    }
}
