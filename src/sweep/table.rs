//! The sweep's tables, built and aggregated with polars and written as CSV and Parquet:
//! `results` (one row per finished case: its axis values, replica and declared results; no
//! wall times, so two runs of a sweep give the same bytes wherever their cases ran), `cases`
//! (every case with its status, wall time and error) and `ensemble` (per point of the axes:
//! the number of finished replicas, mean, standard deviation and 95 % confidence half-width of
//! each numeric result, Student's t with n − 1 degrees of freedom).

use super::cases::{Case, plain};
use super::local::Outcome;
use super::schema::ResultSpec;
use anyhow::{Context, Result};
use polars::prelude::*;
use statrs::distribution::{ContinuousCDF, StudentsT};
use std::path::{Path, PathBuf};

/// A column's values in the order of the rows, typed by what they all are.
enum Cells {
    Int(Vec<Option<i64>>),
    Float(Vec<Option<f64>>),
    Text(Vec<Option<String>>),
}

impl Cells {
    fn of_toml(v: &[&toml::Value]) -> Self {
        if v.iter().all(|x| x.is_integer()) {
            Cells::Int(v.iter().map(|x| x.as_integer()).collect())
        } else if v.iter().all(|x| x.is_integer() || x.is_float()) {
            Cells::Float(
                v.iter()
                    .map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                    .collect(),
            )
        } else {
            Cells::Text(v.iter().map(|x| Some(plain(x))).collect())
        }
    }

    fn of_json(v: &[&serde_json::Value]) -> Self {
        use serde_json::Value;
        if v.iter().all(|x| x.is_number() || x.is_null()) {
            Cells::Float(v.iter().map(|x| x.as_f64()).collect())
        } else {
            Cells::Text(
                v.iter()
                    .map(|x| match x {
                        Value::Null => None,
                        Value::String(s) => Some(s.clone()),
                        x => Some(x.to_string()),
                    })
                    .collect(),
            )
        }
    }

    fn column(self, name: &str) -> Column {
        match self {
            Cells::Int(v) => Column::new(name.into(), v),
            Cells::Float(v) => Column::new(name.into(), v),
            Cells::Text(v) => Column::new(name.into(), v),
        }
    }
}

/// The names of the numeric results (those the ensemble table and the charts use).
pub fn numeric_results(specs: &[ResultSpec], cases: &[Case], outcomes: &[Outcome]) -> Vec<usize> {
    (0..specs.len())
        .filter(|&r| {
            let mut any = false;
            for (_, o) in cases.iter().zip(outcomes) {
                if let Outcome::Done { values, .. } = o {
                    match &values[r] {
                        serde_json::Value::Number(_) => any = true,
                        serde_json::Value::Null => {}
                        _ => return false,
                    }
                }
            }
            any
        })
        .collect()
}

/// One row per finished case, in the sweep's order: `case`, `point` (the index of its point
/// of the axes), the axes, `replica` and `seed` (with replicas), the results.
pub fn results_frame(
    cases: &[Case],
    outcomes: &[Outcome],
    specs: &[ResultSpec],
    replicas: bool,
) -> Result<DataFrame> {
    let done: Vec<(&Case, &Vec<serde_json::Value>)> = cases
        .iter()
        .zip(outcomes)
        .filter_map(|(c, o)| match o {
            Outcome::Done { values, .. } => Some((c, values)),
            Outcome::Failed { .. } => None,
        })
        .collect();
    let per_point = |c: &Case| {
        c.replica
            .map_or(c.index, |_| c.index - c.replica.map_or(0, |r| r.0))
    };
    let mut cols = vec![
        Column::new(
            "case".into(),
            done.iter().map(|(c, _)| c.id.clone()).collect::<Vec<_>>(),
        ),
        Column::new(
            "point".into(),
            done.iter().map(|(c, _)| per_point(c) as i64).collect::<Vec<_>>(),
        ),
    ];
    let n_axes = cases.first().map_or(0, |c| c.axes.len());
    for a in 0..n_axes {
        let name = &cases[0].axes[a].0;
        let v: Vec<&toml::Value> = done.iter().map(|(c, _)| &c.axes[a].1).collect();
        cols.push(Cells::of_toml(&v).column(name));
    }
    if replicas {
        let r = |f: fn((usize, i64)) -> i64| -> Vec<i64> {
            done.iter().map(|(c, _)| c.replica.map_or(0, f)).collect()
        };
        cols.push(Column::new("replica".into(), r(|x| x.0 as i64)));
        cols.push(Column::new("seed".into(), r(|x| x.1)));
    }
    for (k, s) in specs.iter().enumerate() {
        let v: Vec<&serde_json::Value> = done.iter().map(|(_, v)| &v[k]).collect();
        cols.push(Cells::of_json(&v).column(&s.name));
    }
    Ok(DataFrame::new_infer_height(cols)?)
}

/// Every case: id, label, status, wall time, whether it was reused or resumed, the error of a
/// failed case and the notes of missing results.
pub fn cases_frame(cases: &[Case], outcomes: &[Outcome]) -> Result<DataFrame> {
    let mut status = Vec::new();
    let mut wall = Vec::new();
    let mut cached = Vec::new();
    let mut resumed = Vec::new();
    let mut error = Vec::new();
    for o in outcomes {
        wall.push(o.wall_s());
        match o {
            Outcome::Done {
                notes,
                cached: c,
                resumed: r,
                ..
            } => {
                status.push("done");
                cached.push(*c);
                resumed.push(*r);
                error.push((!notes.is_empty()).then(|| notes.join("; ")));
            }
            Outcome::Failed { error: e, .. } => {
                status.push("failed");
                cached.push(false);
                resumed.push(false);
                error.push(Some(e.replace('\n', " ")));
            }
        }
    }
    Ok(DataFrame::new_infer_height(vec![
        Column::new(
            "case".into(),
            cases.iter().map(|c| c.id.clone()).collect::<Vec<_>>(),
        ),
        Column::new(
            "label".into(),
            cases.iter().map(|c| c.label()).collect::<Vec<_>>(),
        ),
        Column::new("status".into(), status),
        Column::new("wall_s".into(), wall),
        Column::new("reused".into(), cached),
        Column::new("resumed".into(), resumed),
        Column::new("error".into(), error),
    ])?)
}

/// 95 % confidence half-width of a mean of `n` samples with standard deviation `std`.
pub fn ci95(std: f64, n: usize) -> Option<f64> {
    if n < 2 || !std.is_finite() {
        return None;
    }
    let t = StudentsT::new(0.0, 1.0, (n - 1) as f64).ok()?.inverse_cdf(0.975);
    Some(t * std / (n as f64).sqrt())
}

/// Per point of the axes (group by `point`, in order): its axis values, and for each numeric
/// result `<r>_n`, `<r>_mean`, `<r>_std`, `<r>_ci95` over the finished replicas.
pub fn ensemble_frame(results: &DataFrame, axes: &[String], numeric: &[String]) -> Result<DataFrame> {
    let groups = results
        .group_by_stable(["point"])?
        .get_groups()
        .as_ref()
        .clone()
        .into_idx();
    let mut rows: Vec<DataFrame> = Vec::new();
    for idx in groups.all() {
        let take = IdxCa::from_vec("i".into(), idx.to_vec());
        rows.push(results.take(&take)?);
    }
    let mut cols = vec![Column::new(
        "point".into(),
        rows.iter()
            .map(|g| g.column("point").ok().and_then(|c| c.i64().ok()?.get(0)))
            .collect::<Vec<_>>(),
    )];
    for a in axes {
        let firsts: Vec<Column> = rows
            .iter()
            .map(|g| g.column(a).map(|c| c.head(Some(1))))
            .collect::<PolarsResult<_>>()?;
        let mut col = firsts
            .first()
            .cloned()
            .with_context(|| "no finished case to aggregate")?;
        for c in &firsts[1..] {
            col.append(c)?;
        }
        cols.push(col);
    }
    for r in numeric {
        let (mut n, mut mean, mut std, mut ci) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for g in &rows {
            let s = g.column(r)?.as_materialized_series().cast(&DataType::Float64)?;
            let ca = s.f64()?;
            let count = ca.len() - ca.null_count();
            let sd = ChunkVar::std(ca, 1);
            n.push(count as i64);
            mean.push(ca.mean());
            std.push(sd);
            ci.push(sd.and_then(|sd| ci95(sd, count)));
        }
        cols.push(Column::new(format!("{r}_n").into(), n));
        cols.push(Column::new(format!("{r}_mean").into(), mean));
        cols.push(Column::new(format!("{r}_std").into(), std));
        cols.push(Column::new(format!("{r}_ci95").into(), ci));
    }
    Ok(DataFrame::new_infer_height(cols)?)
}

/// Write `df` as `<stem>.csv` and `<stem>.parquet` in `dir` (each atomically); the file names.
pub fn write_both(dir: &Path, stem: &str, df: &mut DataFrame) -> Result<Vec<PathBuf>> {
    let csv = PathBuf::from(format!("{stem}.csv"));
    crate::report::table::write_frame(&dir.join(&csv), df)?;
    let pq = PathBuf::from(format!("{stem}.parquet"));
    let mut bytes = Vec::new();
    ParquetWriter::new(&mut bytes)
        .finish(df)
        .map_err(|e| anyhow::anyhow!("cannot encode {stem}.parquet: {e}"))?;
    lbdem_core::atomic::write_atomic(&dir.join(&pq), &bytes)
        .with_context(|| format!("cannot write {}", dir.join(&pq).display()))?;
    Ok(vec![csv, pq])
}
