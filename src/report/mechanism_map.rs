//! The deformation mechanism map of Su et al. (2020) Fig. 3j: initial solid fraction g_S⁰ across,
//! push-plate rate du_y/dt up on a log axis, the void ratio e⁰ = (1 − g_S⁰)/g_S⁰ on the top
//! axis (labelled at the g_S⁰ ticks), the shear rate (du_y/dt over the sample width) on the right,
//! a colour per class, and the transition lines. A rate of 0 (the heating experiment) sits on
//! the bottom edge.

use super::plot::{FONT, de, render_png};
use anyhow::{Result, bail};
use plotters::prelude::*;
use std::path::Path;

/// How a point is drawn: experiments as filled circles, simulations as open squares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    Experiment,
    Simulation,
}

#[derive(Clone, Debug)]
pub struct MapPoint {
    pub label: String,
    pub g_s0: f64,
    /// µm/s (0: drawn on the bottom edge).
    pub rate_um_s: f64,
    pub colour: (u8, u8, u8),
    pub marker: Marker,
}

/// A line through (g_S⁰, rate µm/s) points.
#[derive(Clone, Debug)]
pub struct MapLine {
    pub label: String,
    pub points: Vec<(f64, f64)>,
    pub colour: (u8, u8, u8),
}

#[derive(Clone, Debug)]
pub struct MapAxes {
    pub title: String,
    pub g_range: (f64, f64),
    /// µm/s, log axis.
    pub rate_range: (f64, f64),
    /// Sample width for the right axis (m).
    pub width_m: f64,
    /// Legend entries: (text, colour, marker).
    pub legend: Vec<(String, (u8, u8, u8), Marker)>,
}

pub fn mechanism_map_png(path: &Path, points: &[MapPoint], lines: &[MapLine], ax: &MapAxes) -> Result<()> {
    let (g0, g1) = ax.g_range;
    let (r0, r1) = ax.rate_range;
    if !(g1 > g0 && r1 > r0 && r0 > 0.0 && ax.width_m > 0.0) {
        bail!(
            "mechanism map: bad axes g {:?}, rate {:?} µm/s, width {} m",
            ax.g_range,
            ax.rate_range,
            ax.width_m
        );
    }
    // Right axis: shear rate (1/s) = rate (µm/s) × 1e-6 / width.
    let s = |r: f64| r * 1e-6 / ax.width_m;
    render_png(path, (1150, 680), None, |root| {
        root.fill(&WHITE).map_err(de)?;
        // The legend gets its own column so that it hides no point.
        let (root, side) = root.split_horizontally(880);
        draw_legend(&side, lines, &ax.legend)?;
        let mut chart = ChartBuilder::on(&root)
            .caption(&ax.title, (FONT, 20))
            .margin(15)
            .x_label_area_size(45)
            .top_x_label_area_size(45)
            .y_label_area_size(75)
            .right_y_label_area_size(80)
            .build_cartesian_2d(g0..g1, (r0..r1).log_scale())
            .map_err(de)?
            .set_secondary_coord(g0..g1, (s(r0)..s(r1)).log_scale());
        chart
            .configure_mesh()
            .x_desc("initial solid fraction g_S⁰ (-)")
            .y_desc("push-plate rate du_y/dt (µm/s)")
            .label_style((FONT, 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(de)?;
        let void = |g: &f64| format!("{:.2}", (1.0 - g) / g);
        let sci = |v: &f64| format!("{v:.0e}");
        chart
            .configure_secondary_axes()
            .x_desc("void ratio e⁰ = (1 − g_S⁰)/g_S⁰ (-)")
            .y_desc("shear rate (1/s)")
            .x_label_formatter(&void)
            .y_label_formatter(&sci)
            .label_style((FONT, 13))
            .draw()
            .map_err(de)?;
        for l in lines {
            let c = RGBColor(l.colour.0, l.colour.1, l.colour.2);
            let pts: Vec<(f64, f64)> = l
                .points
                .iter()
                .map(|&(g, r)| (g.clamp(g0, g1), r.clamp(r0, r1)))
                .collect();
            chart
                .draw_series(DashedLineSeries::new(pts, 10, 5, c.stroke_width(2)))
                .map_err(de)?;
        }
        let at_of = |p: &MapPoint| (p.g_s0.clamp(g0, g1), p.rate_um_s.clamp(r0, r1));
        let px: Vec<(i32, i32)> = points.iter().map(|p| chart.backend_coord(&at_of(p))).collect();
        for (i, p) in points.iter().enumerate() {
            let c = RGBColor(p.colour.0, p.colour.1, p.colour.2);
            let at = at_of(p);
            match p.marker {
                Marker::Experiment => chart
                    .draw_series(std::iter::once(Circle::new(at, 6, c.filled())))
                    .map_err(de)?,
                Marker::Simulation => chart
                    .draw_series(std::iter::once(
                        EmptyElement::at(at) + Rectangle::new([(-6, -6), (6, 6)], c.stroke_width(3)),
                    ))
                    .map_err(de)?,
            };
            chart
                .draw_series(std::iter::once(
                    EmptyElement::at(at)
                        + Text::new(
                            p.label.clone(),
                            label_offset(i, &p.label, &px),
                            (FONT, 11).into_font().color(&RGBColor(60, 60, 60)),
                        ),
                ))
                .map_err(de)?;
        }
        Ok(())
    })
}

/// Where point `i`'s label goes, in pixels from the point: above and to the right, else below,
/// else to the left, whichever box holds no other point (66 % and 71 % at 30 µm/s, or 50 % at
/// 2870 µm/s and 57 % at 2150 µm/s, would overlap otherwise).
fn label_offset(i: usize, label: &str, px: &[(i32, i32)]) -> (i32, i32) {
    // The embedded font at 11 px is about 6 px per character and 12 px high; markers are 6 px.
    let (w, h, r) = (6 * label.chars().count() as i32, 12, 7);
    let (x, y) = px[i];
    let free = |(dx, dy): (i32, i32)| {
        let (x0, y0) = (x + dx, y + dy);
        !px.iter()
            .enumerate()
            .any(|(j, &(xj, yj))| j != i && xj + r > x0 && xj - r < x0 + w && yj + r > y0 && yj - r < y0 + h)
    };
    let candidates = [(9, -14), (9, 8), (-9 - w, -14), (-9 - w, 8)];
    candidates.into_iter().find(|&c| free(c)).unwrap_or(candidates[0])
}

/// The legend column: each line as a dashed stroke, each point kind as its marker.
fn draw_legend(
    area: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    lines: &[MapLine],
    entries: &[(String, (u8, u8, u8), Marker)],
) -> Result<()> {
    let font = (FONT, 13).into_font();
    let mut y = 70;
    for l in lines {
        let c = RGBColor(l.colour.0, l.colour.1, l.colour.2);
        area.draw(&PathElement::new(vec![(8, y), (20, y)], c.stroke_width(3)))
            .map_err(de)?;
        area.draw(&PathElement::new(vec![(24, y), (34, y)], c.stroke_width(3)))
            .map_err(de)?;
        area.draw(&Text::new(l.label.clone(), (42, y - 7), font.clone()))
            .map_err(de)?;
        y += 24;
    }
    y += 8;
    for (text, col, m) in entries {
        let c = RGBColor(col.0, col.1, col.2);
        match m {
            Marker::Experiment => area.draw(&Circle::new((21, y), 6, c.filled())),
            Marker::Simulation => area.draw(&Rectangle::new([(15, y - 6), (27, y + 6)], c.stroke_width(3))),
        }
        .map_err(de)?;
        area.draw(&Text::new(text.clone(), (42, y - 7), font.clone()))
            .map_err(de)?;
        y += 24;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_draws_points_lines_and_refuses_bad_axes() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("map.png");
        let pts = vec![
            MapPoint {
                label: "38% - 0".into(),
                g_s0: 0.38,
                rate_um_s: 0.0,
                colour: (150, 150, 150),
                marker: Marker::Experiment,
            },
            MapPoint {
                label: "sim".into(),
                g_s0: 0.6,
                rate_um_s: 30.0,
                colour: (0, 0, 0),
                marker: Marker::Simulation,
            },
        ];
        let lines = vec![MapLine {
            label: "percolation".into(),
            points: vec![(0.38, 0.3), (0.38, 1e4)],
            colour: (120, 120, 120),
        }];
        let mut ax = MapAxes {
            title: "map".into(),
            g_range: (0.3, 0.9),
            rate_range: (0.3, 1e4),
            width_m: 7.5e-3,
            legend: vec![("experiment".into(), (0, 0, 0), Marker::Experiment)],
        };
        mechanism_map_png(&p, &pts, &lines, &ax).unwrap();
        assert_eq!(image::open(&p).unwrap().width(), 1150);
        ax.rate_range = (0.0, 1.0);
        assert!(mechanism_map_png(&p, &pts, &lines, &ax).is_err());
    }

    #[test]
    fn a_label_moves_off_a_neighbouring_point() {
        // 66 % and 71 % at 30 µm/s are about 50 px apart on the default map.
        let px = [(400, 300), (450, 300), (700, 300), (400, 100), (440, 112)];
        assert_eq!(label_offset(0, "66% - 30 µm/s", &px), (9, 8));
        assert_eq!(label_offset(1, "71% - 30 µm/s", &px), (9, -14));
        assert_eq!(label_offset(2, "74% - 1 µm/s", &px), (9, -14));
        // A neighbour above-right and below-right: the label goes to the left.
        let px = [(400, 300), (450, 290), (460, 312)];
        assert_eq!(label_offset(0, "50% - 2870 µm/s", &px), (-9 - 6 * 15, -14));
    }
}
