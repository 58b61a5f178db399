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

/// One column of a mixed table.
pub enum Col<'a> {
    U64(&'a [u64]),
    I64(&'a [i64]),
    F64(&'a [f64]),
    Str(&'a [String]),
}

impl Col<'_> {
    fn len(&self) -> usize {
        match self {
            Col::U64(v) => v.len(),
            Col::I64(v) => v.len(),
            Col::F64(v) => v.len(),
            Col::Str(v) => v.len(),
        }
    }
}

/// Write equal-length named columns of mixed types as CSV (full precision: every f64 reads
/// back to the same bits).
pub fn write_table(path: &Path, columns: &[(&str, Col)]) -> Result<()> {
    let height = columns.first().map_or(0, |c| c.1.len());
    if let Some((name, c)) = columns.iter().find(|c| c.1.len() != height) {
        bail!(
            "table {}: column '{name}' has {} rows, the first column has {height}",
            path.display(),
            c.len()
        );
    }
    let cols = columns
        .iter()
        .map(|(n, c)| match c {
            Col::U64(v) => Column::new((*n).into(), *v),
            Col::I64(v) => Column::new((*n).into(), *v),
            Col::F64(v) => Column::new((*n).into(), *v),
            Col::Str(v) => Column::new((*n).into(), *v),
        })
        .collect();
    write_frame(path, &mut DataFrame::new(height, cols)?)
}

/// A table of one row per item of `rows`, built column by column (a name and what to take from
/// a row), then written by [`write_table`]: the stages that tabulate their points (the stability
/// maps) say which columns they want, not how to collect them.
pub struct RowTable<'a, R> {
    rows: &'a [R],
    cols: Vec<(&'static str, Owned)>,
}

/// A collected column of a [`RowTable`].
enum Owned {
    U64(Vec<u64>),
    F64(Vec<f64>),
    Str(Vec<String>),
}

impl<'a, R> RowTable<'a, R> {
    pub fn new(rows: &'a [R]) -> Self {
        Self {
            rows,
            cols: Vec::new(),
        }
    }
    pub fn f64(mut self, name: &'static str, f: impl Fn(&R) -> f64) -> Self {
        self.cols
            .push((name, Owned::F64(self.rows.iter().map(f).collect())));
        self
    }
    pub fn u64(mut self, name: &'static str, f: impl Fn(&R) -> u64) -> Self {
        self.cols
            .push((name, Owned::U64(self.rows.iter().map(f).collect())));
        self
    }
    pub fn str<S: ToString>(mut self, name: &'static str, f: impl Fn(&R) -> S) -> Self {
        let v = self.rows.iter().map(|r| f(r).to_string()).collect();
        self.cols.push((name, Owned::Str(v)));
        self
    }
    pub fn write(&self, path: &Path) -> Result<()> {
        let cols: Vec<(&str, Col)> = self
            .cols
            .iter()
            .map(|(n, c)| {
                let col = match c {
                    Owned::U64(v) => Col::U64(v),
                    Owned::F64(v) => Col::F64(v),
                    Owned::Str(v) => Col::Str(v),
                };
                (*n, col)
            })
            .collect();
        write_table(path, &cols)
    }
}

/// Read a CSV table written by [`write_table`] (or any CSV with a header row).
pub fn read_table(path: &Path) -> Result<DataFrame> {
    CsvReadOptions::default()
        .with_has_header(true)
        .with_infer_schema_length(None)
        .try_into_reader_with_file_path(Some(path.to_path_buf()))
        .and_then(|r| r.finish())
        .map_err(|e| anyhow::anyhow!("cannot read table {}: {e}", path.display()))
}

/// Column `name` of `df` as f64 (integers are converted), with the file in the error.
pub fn f64_column(df: &DataFrame, name: &str, path: &Path) -> Result<Vec<f64>> {
    let c = df
        .column(name)
        .map_err(|_| anyhow::anyhow!("table {} has no column '{name}'", path.display()))?
        .cast(&DataType::Float64)?;
    Ok(c.f64()?.iter().map(|v| v.unwrap_or(f64::NAN)).collect())
}

/// Column `name` of `df` as f64, every cell a finite number: a cell that is not a number, an
/// empty cell or a NaN is an error naming the file, the column and the data row (where
/// [`f64_column`] would give NaN, which a comparison can then pass by accident).
pub fn finite_f64_column(df: &DataFrame, name: &str, path: &Path) -> Result<Vec<f64>> {
    let c = df
        .column(name)
        .map_err(|_| anyhow::anyhow!("table {} has no column '{name}'", path.display()))?
        .strict_cast(&DataType::Float64)
        .map_err(|e| {
            anyhow::anyhow!(
                "table {}: column '{name}' is not all numbers: {e}",
                path.display()
            )
        })?;
    c.f64()?
        .iter()
        .enumerate()
        .map(|(k, v)| match v {
            Some(x) if x.is_finite() => Ok(x),
            _ => bail!(
                "table {}: column '{name}', data row {}: {v:?}, not a finite number",
                path.display(),
                k + 1
            ),
        })
        .collect()
}

/// Column `name` of `df` as text (numbers are printed; empty cells become "").
pub fn str_column(df: &DataFrame, name: &str, path: &Path) -> Result<Vec<String>> {
    let c = df
        .column(name)
        .map_err(|_| anyhow::anyhow!("table {} has no column '{name}'", path.display()))?
        .cast(&DataType::String)?;
    Ok(c.str()?.iter().map(|v| v.unwrap_or("").to_string()).collect())
}

/// Column `name` of `df` as u64.
pub fn u64_column(df: &DataFrame, name: &str, path: &Path) -> Result<Vec<u64>> {
    let c = df
        .column(name)
        .map_err(|_| anyhow::anyhow!("table {} has no column '{name}'", path.display()))?
        .cast(&DataType::UInt64)?;
    c.u64()?
        .iter()
        .map(|v| v.with_context(|| format!("table {}: empty cell in column '{name}'", path.display())))
        .collect()
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

    #[test]
    fn mixed_table_reads_back_to_the_same_bits() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.csv");
        // Values whose shortest decimal form needs all 17 digits, and extremes.
        let x = [0.1 + 0.2, 1.0 / 3.0, -2.2250738585072014e-308, 6.02214076e23, 0.0];
        let ids = [0u64, 1, 2, 3, u64::from(u32::MAX)];
        let names: Vec<String> = (0..5).map(|k| format!("n{k}")).collect();
        write_table(
            &p,
            &[
                ("id", Col::U64(&ids)),
                ("x", Col::F64(&x)),
                ("name", Col::Str(&names)),
            ],
        )
        .unwrap();
        let df = read_table(&p).unwrap();
        let back = f64_column(&df, "x", &p).unwrap();
        for (a, b) in x.iter().zip(&back) {
            assert_eq!(a.to_bits(), b.to_bits(), "{a} read back as {b}");
        }
        assert_eq!(u64_column(&df, "id", &p).unwrap(), ids);
        let e = f64_column(&df, "nope", &p).unwrap_err().to_string();
        assert!(e.contains("m.csv") && e.contains("nope"), "{e}");
    }
}
