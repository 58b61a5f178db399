//! The sweep's charts: each numeric result against each axis, one series per combination of
//! the other axes' values; with replicas the points are the ensemble means and the bars their
//! 95 % confidence intervals. A sweep of replicas alone shows each result against the seed,
//! with the mean and its interval as lines.

use crate::contract::Figure;
use crate::report::plot::{ErrSeries, Series, XyPlot, xy_err_png, xy_png};
use anyhow::Result;
use polars::prelude::*;
use std::path::{Path, PathBuf};

/// One line of a chart: its label, x, y and error half-widths.
type Group = (String, Vec<f64>, Vec<f64>, Vec<f64>);

/// A column as numbers (`None` if it is text).
fn numbers(df: &DataFrame, name: &str) -> Option<Vec<f64>> {
    let c = df.column(name).ok()?;
    if !c.dtype().is_primitive_numeric() {
        return None;
    }
    let s = c.as_materialized_series().cast(&DataType::Float64).ok()?;
    Some(s.f64().ok()?.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
}

/// A column as text, one entry per row.
fn texts(df: &DataFrame, name: &str) -> Vec<String> {
    df.column(name)
        .ok()
        .and_then(|c| c.as_materialized_series().cast(&DataType::String).ok())
        .map(|s| {
            s.str()
                .map(|ca| ca.iter().map(|v| v.unwrap_or("").to_string()).collect())
                .unwrap_or_default()
        })
        .unwrap_or_default()
}

/// Draw every chart into `dir/figures/`; the figures and files written (relative to `dir`).
pub fn draw(
    dir: &Path,
    results: &DataFrame,
    ensemble: Option<&DataFrame>,
    axes: &[String],
    numeric: &[(String, Option<String>)],
) -> Result<(Vec<Figure>, Vec<PathBuf>)> {
    let mut figures = Vec::new();
    let mut files = Vec::new();
    if results.height() == 0 {
        return Ok((figures, files));
    }
    std::fs::create_dir_all(dir.join("figures"))?;
    let src = ensemble.unwrap_or(results);
    for (r, unit) in numeric {
        let y_label = match unit {
            Some(u) => format!("{r} ({u})"),
            None => r.clone(),
        };
        if axes.is_empty() {
            // Replicas only: each replica's value against its seed, the mean and its interval.
            let (Some(seed), Some(y)) = (numbers(results, "seed"), numbers(results, r)) else {
                continue;
            };
            let e = ensemble.and_then(|e| {
                Some((
                    numbers(e, &format!("{r}_mean"))?,
                    numbers(e, &format!("{r}_ci95"))?,
                ))
            });
            let (lo, hi) = (
                seed.iter().copied().fold(f64::INFINITY, f64::min),
                seed.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            );
            let ends = [lo, hi];
            let mut lines: Vec<(String, [f64; 2])> = Vec::new();
            if let Some((m, ci)) = &e
                && let (Some(&m), Some(&ci)) = (m.first(), ci.first())
            {
                lines.push((
                    format!("mean {}", crate::stages::report::format_number(m)),
                    [m, m],
                ));
                if ci.is_finite() {
                    lines.push(("mean ± 95 % CI".into(), [m - ci, m - ci]));
                    lines.push((String::new(), [m + ci, m + ci]));
                }
            }
            let mut series = vec![Series {
                label: "replicas",
                x: &seed,
                y: &y,
                points: true,
            }];
            for (label, v) in &lines {
                series.push(Series {
                    label,
                    x: &ends,
                    y: v,
                    points: false,
                });
            }
            let file = PathBuf::from(format!("figures/{r}_replicas.png"));
            xy_png(
                &dir.join(&file),
                &series,
                &XyPlot {
                    title: &format!("{r} over {} replicas", y.len()),
                    x_label: "seed",
                    y_label: &y_label,
                    ..Default::default()
                },
            )?;
            figures.push(Figure {
                path: file.clone(),
                caption: format!(
                    "{r} of each replica (random realisation) against its seed, with the ensemble mean and its 95 % \
                     confidence interval (Student's t)."
                ),
            });
            files.push(file);
            continue;
        }
        let (ycol, ecol) = match ensemble {
            Some(_) => (format!("{r}_mean"), Some(format!("{r}_ci95"))),
            None => (r.clone(), None),
        };
        let Some(y) = numbers(src, &ycol) else { continue };
        let err = ecol
            .and_then(|c| numbers(src, &c))
            .unwrap_or_else(|| vec![f64::NAN; y.len()]);
        for a in axes {
            let labels = texts(src, a);
            let (x, ticks) = match numbers(src, a) {
                Some(x) => (x, None),
                None => {
                    // Text values: their position in the order they first appear.
                    let mut seen: Vec<String> = Vec::new();
                    let x = labels
                        .iter()
                        .map(|l| {
                            let k = seen.iter().position(|s| s == l).unwrap_or_else(|| {
                                seen.push(l.clone());
                                seen.len() - 1
                            });
                            (k + 1) as f64
                        })
                        .collect();
                    (x, Some(seen))
                }
            };
            // One series per combination of the other axes.
            let others: Vec<&String> = axes.iter().filter(|b| *b != a).collect();
            let other_text: Vec<Vec<String>> = others.iter().map(|b| texts(src, b)).collect();
            let key = |i: usize| -> String {
                others
                    .iter()
                    .zip(&other_text)
                    .map(|(b, t)| format!("{b}={}", t.get(i).map_or("", String::as_str)))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            let mut groups: Vec<(String, Vec<usize>)> = Vec::new();
            for i in 0..y.len() {
                let k = key(i);
                match groups.iter_mut().find(|g| g.0 == k) {
                    Some(g) => g.1.push(i),
                    None => groups.push((k, vec![i])),
                }
            }
            let pick = |idx: &[usize], v: &[f64]| idx.iter().map(|&i| v[i]).collect::<Vec<f64>>();
            let data: Vec<Group> = groups
                .iter()
                .map(|(k, idx)| (k.clone(), pick(idx, &x), pick(idx, &y), pick(idx, &err)))
                .collect();
            let series: Vec<ErrSeries> = data
                .iter()
                .map(|(k, x, y, e)| ErrSeries {
                    label: k,
                    x,
                    y,
                    err: e,
                })
                .collect();
            let x_label = match &ticks {
                Some(t) => format!(
                    "{a}: {}",
                    t.iter()
                        .enumerate()
                        .map(|(k, s)| format!("{} = {s}", k + 1))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
                None => a.clone(),
            };
            let file = PathBuf::from(format!("figures/{r}_vs_{a}.png"));
            if xy_err_png(
                &dir.join(&file),
                &series,
                &XyPlot {
                    title: &format!("{r} against {a}"),
                    x_label: &x_label,
                    y_label: &y_label,
                    ..Default::default()
                },
            )
            .is_err()
            {
                continue; // no finite value of this result: nothing to draw
            }
            let what = if ensemble.is_some() {
                "ensemble mean over the finished replicas, bars the 95 % confidence interval (Student's t)"
            } else {
                "one point per finished case"
            };
            figures.push(Figure {
                path: file.clone(),
                caption: format!("{r} against {a}: {what}; one line per value of the other axes."),
            });
            files.push(file);
        }
    }
    Ok((figures, files))
}
