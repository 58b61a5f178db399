//! Where a chart's legend goes: the place that hides the fewest data points. A legend fixed at
//! the upper right covered the line a figure is about when the data ended high (the Float case's
//! packed fraction at 0.807 in `packed_zone.png`).

use plotters::prelude::SeriesLabelPosition;

/// The plotting area's data ranges and the legend's entries, in the chart's own scale.
pub struct Frame {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub log_x: bool,
    pub log_y: bool,
    /// Legend entries: their count and the longest label (characters).
    pub entries: usize,
    pub longest: usize,
    /// Plotting area in pixels (width, height), for the legend's share of it.
    pub area_px: (f64, f64),
}

impl Frame {
    /// A chart's frame on ranges `x` and `y` ((lo, hi), `log` per axis) and an 800 × 560 PNG's
    /// plotting area, with the legend's entries counted from their `labels` (empty ones have none).
    pub fn new<'a>(
        x: (f64, f64),
        y: (f64, f64),
        log: (bool, bool),
        labels: impl Iterator<Item = &'a str> + Clone,
    ) -> Self {
        let labels = labels.filter(|l| !l.is_empty());
        Self {
            x,
            y,
            log_x: log.0,
            log_y: log.1,
            entries: labels.clone().count(),
            longest: labels.map(|l| l.chars().count()).max().unwrap_or(0),
            area_px: (695.0, 460.0),
        }
    }
}

/// Fraction of the axis from its low end, in the axis's scale.
fn along(v: f64, (lo, hi): (f64, f64), log: bool) -> f64 {
    if log {
        (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
    } else {
        (v - lo) / (hi - lo)
    }
}

/// The place whose legend-sized box holds the fewest of `points`: a corner (upper right first
/// on ties, then upper left, lower right, lower left), else the middle of a side or the centre
/// (a line along the top and one along the bottom leave only the middle free). Horizontal
/// reference lines count as many points where they cross the box's height.
pub fn quietest_corner(
    f: &Frame,
    points: impl Iterator<Item = (f64, f64)>,
    h_lines: &[f64],
) -> SeriesLabelPosition {
    // plotters draws 13 px labels about 7 px per character after an 18 px stroke and margins.
    let w = ((f.longest as f64 * 7.0 + 40.0) / f.area_px.0).min(1.0);
    let h = ((f.entries as f64 * 18.0 + 12.0) / f.area_px.1).min(1.0);
    let (right, left, centre) = ((1.0 - w, 1.0), (0.0, w), (0.5 - w / 2.0, 0.5 + w / 2.0));
    let (upper, lower, middle) = ((1.0 - h, 1.0), (0.0, h), (0.5 - h / 2.0, 0.5 + h / 2.0));
    let corners = [
        (SeriesLabelPosition::UpperRight, right, upper),
        (SeriesLabelPosition::UpperLeft, left, upper),
        (SeriesLabelPosition::LowerRight, right, lower),
        (SeriesLabelPosition::LowerLeft, left, lower),
        (SeriesLabelPosition::MiddleRight, right, middle),
        (SeriesLabelPosition::MiddleLeft, left, middle),
        (SeriesLabelPosition::UpperMiddle, centre, upper),
        (SeriesLabelPosition::LowerMiddle, centre, lower),
        (SeriesLabelPosition::MiddleMiddle, centre, middle),
    ];
    let inside = |(a, b): (f64, f64), v: f64| v >= a && v <= b;
    let mut counts = [0usize; 9];
    for (x, y) in points {
        let (u, v) = (along(x, f.x, f.log_x), along(y, f.y, f.log_y));
        if !(u.is_finite() && v.is_finite()) {
            continue;
        }
        for (k, (_, cu, cv)) in corners.iter().enumerate() {
            counts[k] += usize::from(inside(*cu, u) && inside(*cv, v));
        }
    }
    // A reference line under the box weighs as much as a line of data across it.
    const WEIGHT: usize = 20;
    for &y in h_lines {
        let v = along(y, f.y, f.log_y);
        for (k, (_, _, cv)) in corners.iter().enumerate() {
            counts[k] += WEIGHT * usize::from(inside(*cv, v));
        }
    }
    let best = (0..corners.len()).min_by_key(|&k| counts[k]).unwrap_or(0);
    corners
        .into_iter()
        .nth(best)
        .map_or(SeriesLabelPosition::UpperRight, |c| c.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        Frame {
            x: (0.0, 10.0),
            y: (0.0, 1.0),
            log_x: false,
            log_y: false,
            entries: 3,
            longest: 30,
            area_px: (700.0, 480.0),
        }
    }

    fn name(p: SeriesLabelPosition) -> &'static str {
        match p {
            SeriesLabelPosition::UpperRight => "upper right",
            SeriesLabelPosition::UpperLeft => "upper left",
            SeriesLabelPosition::LowerRight => "lower right",
            SeriesLabelPosition::LowerLeft => "lower left",
            SeriesLabelPosition::MiddleRight => "middle right",
            _ => "other",
        }
    }

    #[test]
    fn a_line_ending_high_sends_the_legend_below_it_and_an_empty_chart_keeps_the_upper_right() {
        // The Float case's shape: nothing, then a plateau near the top from x = 3 on.
        let plateau = (30..100).map(|k| (k as f64 / 10.0, 0.95));
        let p = quietest_corner(&frame(), plateau, &[]);
        assert_eq!(name(p), "lower right");
        // Falling from the upper left to the lower right: the upper right is free.
        let falling = (0..100).map(|k| (k as f64 / 10.0, 1.0 - k as f64 / 100.0));
        assert_eq!(name(quietest_corner(&frame(), falling, &[])), "upper right");
        assert_eq!(
            name(quietest_corner(&frame(), std::iter::empty(), &[])),
            "upper right"
        );
    }

    #[test]
    fn a_reference_line_near_the_top_counts_against_the_upper_corners() {
        // Data fill the lower left only; a reference line at 0.97 rules out both upper corners.
        let low_left = (0..20).map(|k| (k as f64 / 10.0, 0.05));
        let p = quietest_corner(&frame(), low_left, &[0.97]);
        assert_eq!(name(p), "lower right");
    }

    #[test]
    fn lines_along_the_top_and_the_bottom_leave_the_middle() {
        // The Float chart: the packed fraction along the top, the box's along the bottom.
        let top = (0..100).map(|k| (k as f64 / 10.0, 0.97));
        let bottom = (0..100).map(|k| (k as f64 / 10.0, 0.03));
        assert_eq!(
            name(quietest_corner(&frame(), top.chain(bottom), &[])),
            "middle right"
        );
    }

    #[test]
    fn log_axes_are_judged_in_their_own_scale() {
        let f = Frame {
            x: (1.0, 1e4),
            log_x: true,
            ..frame()
        };
        // x = 5e3 is at 0.92 of a log axis (upper right's box), 0.5 of a linear one's.
        let pts = (0..50).map(|_| (5e3, 0.95));
        assert_eq!(name(quietest_corner(&f, pts, &[])), "upper left");
    }
}
