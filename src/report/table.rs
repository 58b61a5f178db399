//! CSV tables, written atomically.

use anyhow::{Result, bail};
use std::path::Path;

/// Write equal-length named columns as CSV.
pub fn write_csv(_path: &Path, _columns: &[(&str, &[f64])]) -> Result<()> {
    bail!("table::write_csv is being written")
}
