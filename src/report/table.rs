//! CSV tables through polars' eager API, written atomically.

use anyhow::{Context, Result, bail};
use polars::prelude::*;
use std::path::Path;

/// Equal-length named columns as a data frame.
pub fn frame(columns: &[(&str, &[f64])]) -> Result<DataFrame> {
    let height = columns.first().map_or(0, |c| c.1.len());
    if let Some((name, c)) = columns.iter().find(|c| c.1.len() != height) {
        bail!(
            "table column '{name}' has {} rows, the first column has {height}",
            c.len()
        );
    }
    let cols = columns
        .iter()
        .map(|(n, v)| Column::new((*n).into(), *v))
        .collect();
    Ok(DataFrame::new(height, cols)?)
}

/// Write a data frame as CSV (header row, full precision).
pub fn write_frame(path: &Path, df: &mut DataFrame) -> Result<()> {
    let mut bytes = Vec::new();
    CsvWriter::new(&mut bytes).include_header(true).finish(df)?;
    lbdem_core::atomic::write_atomic(path, &bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// Write equal-length named columns as CSV.
pub fn write_csv(path: &Path, columns: &[(&str, &[f64])]) -> Result<()> {
    write_frame(path, &mut frame(columns)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_round_trip_and_length_check() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        write_csv(&p, &[("x", &[0.0, 0.5]), ("g_s", &[0.25, 1e-17])]).unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        let rows: Vec<&str> = text.lines().collect();
        assert_eq!(rows[0], "x,g_s");
        assert_eq!(rows.len(), 3);
        let back: f64 = rows[2].split(',').nth(1).unwrap().parse().unwrap();
        assert_eq!(back, 1e-17);
        assert!(write_csv(&p, &[("a", &[1.0]), ("b", &[1.0, 2.0])]).is_err());
    }
}
