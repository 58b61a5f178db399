//! X-y plots where the style of a line carries meaning: measured (XIP) solid, simulated (TRI)
//! dash-dot as in Su et al. (2020) Fig. 6, markers for discrete points, and labelled horizontal
//! or vertical reference lines (a threshold such as Δp_c, a displacement such as 10 d̄).

use super::legend;
use super::plot::{FONT, SERIES_COLOURS, de, finite_range, log_tick_label, render_png, tick_label};
use anyhow::{Result, bail};
use plotters::prelude::*;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Style {
    Solid,
    Dashed,
    Points,
    /// A line with a marker at each point.
    LinePoints,
}

/// One series.
#[derive(Clone, Debug)]
pub struct Line<'a> {
    pub label: &'a str,
    pub x: &'a [f64],
    pub y: &'a [f64],
    pub style: Style,
    /// Colour (default: the series palette by position).
    pub colour: Option<(u8, u8, u8)>,
}

/// A labelled reference line at a fixed value.
#[derive(Clone, Debug)]
pub struct Reference<'a> {
    pub value: f64,
    pub label: &'a str,
}

#[derive(Clone, Debug, Default)]
pub struct LinesPlot<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub log_x: bool,
    pub log_y: bool,
    /// Horizontal lines y = value.
    pub h_refs: Vec<Reference<'a>>,
    /// Vertical lines x = value.
    pub v_refs: Vec<Reference<'a>>,
    /// Fixed y range (default: the data's, padded).
    pub y_range: Option<(f64, f64)>,
}

fn padded(lo: f64, hi: f64, log: bool) -> (f64, f64) {
    if log {
        return (lo / 1.3, hi * 1.3);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        lo.abs().max(1e-12) * 0.05 + 1e-12
    };
    (lo - pad, hi + pad)
}

fn axis_label(v: f64, log: bool) -> String {
    if log { log_tick_label(v) } else { tick_label(v) }
}

/// PNG of `lines` (800 × 560) with reference lines; a line's label goes in the legend.
pub fn lines_png(path: &Path, lines: &[Line], opts: &LinesPlot) -> Result<()> {
    for l in lines {
        if l.x.len() != l.y.len() {
            bail!(
                "series '{}' has {} x values and {} y values",
                l.label,
                l.x.len(),
                l.y.len()
            );
        }
    }
    let keep = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    let xs = lines
        .iter()
        .flat_map(|l| l.x.iter().copied())
        .chain(opts.v_refs.iter().map(|r| r.value))
        .filter(|&v| keep(v, opts.log_x));
    let ys = lines
        .iter()
        .flat_map(|l| l.y.iter().copied())
        .chain(opts.h_refs.iter().map(|r| r.value))
        .filter(|&v| keep(v, opts.log_y));
    let (Some((x0, x1)), Some((y0, y1))) = (finite_range(xs), finite_range(ys)) else {
        bail!("cannot plot '{}': no finite data points", opts.title);
    };
    let (x0, x1) = padded(x0, x1, opts.log_x);
    let (y0, y1) = opts.y_range.unwrap_or_else(|| padded(y0, y1, opts.log_y));
    let labels = lines
        .iter()
        .map(|l| l.label)
        .chain(opts.h_refs.iter().chain(&opts.v_refs).map(|r| r.label));
    let corner = legend::quietest_corner(
        &legend::Frame::new((x0, x1), (y0, y1), (opts.log_x, opts.log_y), labels),
        lines
            .iter()
            .flat_map(|l| l.x.iter().copied().zip(l.y.iter().copied())),
        &opts.h_refs.iter().map(|r| r.value).collect::<Vec<_>>(),
    );
    render_png(path, (800, 560), None, |root| {
        root.fill(&WHITE).map_err(de)?;
        let mut b = ChartBuilder::on(root);
        b.caption(opts.title, (FONT, 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(75);
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart.map_err(de)?;
                chart
                    .configure_mesh()
                    .x_desc(opts.x_label)
                    .y_desc(opts.y_label)
                    .x_label_formatter(&|v| axis_label(*v, opts.log_x))
                    .y_label_formatter(&|v| axis_label(*v, opts.log_y))
                    .label_style((FONT, 13))
                    .light_line_style(RGBColor(235, 235, 235))
                    .draw()
                    .map_err(de)?;
                let grey = RGBColor(110, 110, 110);
                for r in &opts.h_refs {
                    let a = chart.draw_series(DashedLineSeries::new(
                        vec![(x0, r.value), (x1, r.value)],
                        6,
                        4,
                        grey.stroke_width(1),
                    ));
                    let a = a.map_err(de)?;
                    if !r.label.is_empty() {
                        a.label(r.label)
                            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], grey));
                    }
                }
                for r in &opts.v_refs {
                    let a = chart
                        .draw_series(DashedLineSeries::new(
                            vec![(r.value, y0), (r.value, y1)],
                            6,
                            4,
                            grey.stroke_width(1),
                        ))
                        .map_err(de)?;
                    if !r.label.is_empty() {
                        a.label(r.label)
                            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], grey));
                    }
                }
                for (i, l) in lines.iter().enumerate() {
                    let c = l
                        .colour
                        .map(|(r, g, b)| RGBColor(r, g, b))
                        .unwrap_or(SERIES_COLOURS[i % SERIES_COLOURS.len()]);
                    let pts: Vec<(f64, f64)> =
                        l.x.iter()
                            .zip(l.y)
                            .map(|(&x, &y)| (x, y))
                            .filter(|&(x, y)| keep(x, opts.log_x) && keep(y, opts.log_y))
                            .collect();
                    let anno = match l.style {
                        Style::Solid => chart.draw_series(LineSeries::new(pts, c.stroke_width(2))),
                        Style::Dashed => {
                            chart.draw_series(DashedLineSeries::new(pts, 9, 5, c.stroke_width(2)))
                        }
                        Style::Points => chart.draw_series(
                            pts.iter()
                                .map(|&p| plotters::element::Circle::new(p, 4, c.filled())),
                        ),
                        Style::LinePoints => {
                            chart
                                .draw_series(LineSeries::new(pts.clone(), c.stroke_width(2)))
                                .map_err(de)?;
                            chart.draw_series(
                                pts.iter()
                                    .map(|&p| plotters::element::Circle::new(p, 3, c.filled())),
                            )
                        }
                    }
                    .map_err(de)?;
                    if !l.label.is_empty() {
                        let w = if l.style == Style::Points { 5 } else { 2 };
                        anno.label(l.label).legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(w))
                        });
                    }
                }
                if lines.iter().any(|l| !l.label.is_empty())
                    || opts
                        .h_refs
                        .iter()
                        .chain(&opts.v_refs)
                        .any(|r| !r.label.is_empty())
                {
                    chart
                        .configure_series_labels()
                        .position(corner.clone())
                        .background_style(WHITE.mix(0.85))
                        .border_style(BLACK)
                        .label_font((FONT, 13))
                        .draw()
                        .map_err(de)?;
                }
            }};
        }
        match (opts.log_x, opts.log_y) {
            (false, false) => draw!(b.build_cartesian_2d(x0..x1, y0..y1)),
            (true, false) => draw!(b.build_cartesian_2d((x0..x1).log_scale(), y0..y1)),
            (false, true) => draw!(b.build_cartesian_2d(x0..x1, (y0..y1).log_scale())),
            (true, true) => draw!(b.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())),
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn styled_lines_and_references_draw_and_mismatches_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("l.png");
        let x = [0.0, 1.0, 2.0];
        let (a, b) = ([0.0, -0.1, 0.05], [0.01, -0.08, 0.02]);
        let lines = [
            Line {
                label: "XIP",
                x: &x,
                y: &a,
                style: Style::Solid,
                colour: Some((200, 0, 0)),
            },
            Line {
                label: "TRI",
                x: &x,
                y: &b,
                style: Style::Dashed,
                colour: None,
            },
            Line {
                label: "pts",
                x: &x,
                y: &b,
                style: Style::Points,
                colour: None,
            },
        ];
        let opts = LinesPlot {
            title: "t",
            x_label: "x (d)",
            y_label: "eps (-)",
            h_refs: vec![Reference {
                value: -0.03,
                label: "threshold",
            }],
            v_refs: vec![Reference {
                value: 1.5,
                label: "",
            }],
            ..Default::default()
        };
        lines_png(&p, &lines, &opts).unwrap();
        assert_eq!(image::open(&p).unwrap().width(), 800);
        let bad = [Line {
            label: "bad",
            x: &x,
            y: &a[..2],
            style: Style::Solid,
            colour: None,
        }];
        assert!(lines_png(&p, &bad, &opts).is_err());
    }
}
