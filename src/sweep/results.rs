//! A finished case's declared scalar results, read from its files: a value of a stage's
//! `stage.json` summary, or one number from a column of one of its tables (the last row, a
//! reduction, or the value where another column first reaches a level, e.g. ε_vol^DEM at
//! u_y = 10 d̄).

use super::schema::{At, Reduce, ResultSpec};
use crate::contract::{MANIFEST, StageRecord};
use crate::report::table::{f64_column, read_table};
use anyhow::{Context, Result, bail};
use serde_json::Value;
use std::path::Path;

/// The stage a result reads by default: the last one that is not a report.
pub fn default_stage(stages: &[(String, String)]) -> Option<&str> {
    stages
        .iter()
        .rev()
        .find(|(_, kind)| kind != "report")
        .map(|(n, _)| n.as_str())
}

/// One result of the case in `case_dir` (stages in `<case_dir>/<stage>/`). `Ok(None)` with a
/// note when the run finished without it (a condition never reached, a key it did not write).
pub fn extract(spec: &ResultSpec, case_dir: &Path, stages: &[(String, String)]) -> Result<Value> {
    let stage = match &spec.stage {
        Some(s) => {
            if !stages.iter().any(|(n, _)| n == s) {
                bail!(
                    "result '{}': stage = \"{s}\" is not a stage of the case; stages: {:?}",
                    spec.name,
                    stages.iter().map(|(n, _)| n).collect::<Vec<_>>()
                );
            }
            s.as_str()
        }
        None => default_stage(stages).context("the case has no stage to read results from")?,
    };
    let dir = case_dir.join(stage);
    if let Some(path) = &spec.summary {
        let manifest = dir.join(MANIFEST);
        let rec: StageRecord = serde_json::from_str(
            &std::fs::read_to_string(&manifest)
                .with_context(|| format!("cannot read {}", manifest.display()))?,
        )
        .with_context(|| format!("{} is not a stage manifest", manifest.display()))?;
        return summary_value(&rec.output.summary, path)
            .with_context(|| format!("result '{}' in {}", spec.name, manifest.display()));
    }
    let column = spec
        .column
        .as_deref()
        .context("a result needs summary or column")?;
    let table = dir.join(
        spec.table
            .clone()
            .unwrap_or_else(|| crate::scenes::observers::SERIES_FILE.into()),
    );
    // A run's series without the shear cell's settling rows, as the analysis reads it.
    let df = if table.file_name() == Some(std::ffi::OsStr::new(crate::scenes::observers::SERIES_FILE)) {
        crate::stages::run_data::read_series(&table)?
    } else {
        read_table(&table)?
    };
    let y = f64_column(&df, column, &table)?;
    let v = match &spec.at {
        Some(At { column: xc, value }) => {
            let x = f64_column(&df, xc, &table)?;
            crossing(&x, &y, *value).with_context(|| {
                format!(
                    "result '{}': {xc} in {} never reaches {value} (its range: {})",
                    spec.name,
                    table.display(),
                    range_text(&x)
                )
            })?
        }
        None => reduce(&y, spec.reduce.unwrap_or_default()).with_context(|| {
            format!(
                "result '{}': column {column} of {} has no finite value",
                spec.name,
                table.display()
            )
        })?,
    };
    Ok(serde_json::json!(v))
}

fn range_text(x: &[f64]) -> String {
    let f: Vec<f64> = x.iter().copied().filter(|v| v.is_finite()).collect();
    match (
        f.iter().copied().reduce(f64::min),
        f.iter().copied().reduce(f64::max),
    ) {
        (Some(a), Some(b)) => format!("{a:e} to {b:e}"),
        _ => "no finite values".into(),
    }
}

/// A value at a dotted path of a summary (`a.b.0.c`: objects by key, arrays by index).
pub fn summary_value(summary: &Value, path: &str) -> Result<Value> {
    let mut cur = summary;
    for part in path.split('.') {
        cur = match cur {
            Value::Object(m) => m.get(part).with_context(|| {
                format!(
                    "the summary has no '{part}' (of \"{path}\"); keys there: {:?}",
                    m.keys().collect::<Vec<_>>()
                )
            })?,
            Value::Array(a) => part
                .parse::<usize>()
                .ok()
                .and_then(|i| a.get(i))
                .with_context(|| {
                    format!(
                        "'{part}' (of \"{path}\") is not an index of a list of {}",
                        a.len()
                    )
                })?,
            _ => bail!("'{part}' (of \"{path}\") is inside a value that is neither an object nor a list"),
        };
    }
    match cur {
        Value::Number(_) | Value::String(_) | Value::Bool(_) => Ok(cur.clone()),
        Value::Null => bail!("\"{path}\" is null in the summary"),
        _ => bail!("\"{path}\" is not one value (a number, text or true/false) but {cur}"),
    }
}

/// `y` where `x` first reaches `level` (from either side), interpolated linearly between the
/// two rows around the crossing; exactly at a row, that row's value.
pub fn crossing(x: &[f64], y: &[f64], level: f64) -> Option<f64> {
    let rows: Vec<(f64, f64)> = x
        .iter()
        .zip(y)
        .map(|(&a, &b)| (a, b))
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .collect();
    let (first, _) = *rows.first()?;
    if first == level {
        return Some(rows[0].1);
    }
    let below = first < level;
    rows.windows(2).find_map(|w| {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        let reached = if below { x1 >= level } else { x1 <= level };
        reached.then(|| {
            if x1 == x0 {
                y1
            } else {
                y0 + (y1 - y0) * (level - x0) / (x1 - x0)
            }
        })
    })
}

/// One number from a column (finite values only).
pub fn reduce(y: &[f64], how: Reduce) -> Option<f64> {
    let f: Vec<f64> = y.iter().copied().filter(|v| v.is_finite()).collect();
    match how {
        Reduce::Last => f.last().copied(),
        Reduce::First => f.first().copied(),
        Reduce::Min => f.iter().copied().reduce(f64::min),
        Reduce::Max => f.iter().copied().reduce(f64::max),
        Reduce::Mean => (!f.is_empty()).then(|| f.iter().sum::<f64>() / f.len() as f64),
    }
}
