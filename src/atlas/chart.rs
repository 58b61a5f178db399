//! One Pareto chart: error against wall time, a marker series per setting and the
//! non-dominated settings joined by a line.

use super::Point;
use crate::report::plot::{Series, XyPlot, xy_png};
use anyhow::Result;
use std::path::Path;

/// Axes of a chart: log-log unless a point sits at zero error (the reference itself).
pub struct Axes<'a> {
    pub title: &'a str,
    pub error_label: &'a str,
    pub log: bool,
}

pub fn pareto_png(path: &Path, points: &[Point], front: &[bool], axes: &Axes) -> Result<()> {
    let mut settings: Vec<&str> = Vec::new();
    for p in points {
        if !settings.contains(&p.setting.as_str()) {
            settings.push(&p.setting);
        }
    }
    let floor = |v: f64| if axes.log { v.max(1e-16) } else { v };
    let data: Vec<(String, Vec<f64>, Vec<f64>)> = settings
        .iter()
        .map(|s| {
            let sel: Vec<&Point> = points.iter().filter(|p| p.setting == *s).collect();
            (
                s.to_string(),
                sel.iter().map(|p| p.wall_seconds).collect(),
                sel.iter().map(|p| floor(p.error)).collect(),
            )
        })
        .collect();
    let mut on_front: Vec<&Point> = points
        .iter()
        .zip(front)
        .filter(|(_, f)| **f)
        .map(|(p, _)| p)
        .collect();
    on_front.sort_by(|a, b| a.wall_seconds.total_cmp(&b.wall_seconds));
    let (fx, fy): (Vec<f64>, Vec<f64>) = on_front.iter().map(|p| (p.wall_seconds, floor(p.error))).unzip();
    xy_png(
        path,
        &markers_and_line(&data, ("non-dominated", &fx, &fy)),
        &XyPlot {
            title: axes.title,
            x_label: "wall time per run (s)",
            y_label: axes.error_label,
            log_x: axes.log,
            log_y: axes.log,
        },
    )
}

/// One marker series per labelled (x, y) set, then one line (a front, a tolerance).
pub fn markers_and_line<'a>(
    data: &'a [(String, Vec<f64>, Vec<f64>)],
    line: (&'a str, &'a [f64], &'a [f64]),
) -> Vec<Series<'a>> {
    let mut series: Vec<Series> = data
        .iter()
        .map(|(l, x, y)| Series {
            label: l,
            x,
            y,
            points: true,
        })
        .collect();
    series.push(Series {
        label: line.0,
        x: line.1,
        y: line.2,
        points: false,
    });
    series
}
