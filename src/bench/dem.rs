//! `lbdem bench dem` (work in progress on its issue branch).

use super::BenchArgs;
use anyhow::{Result, bail};

pub fn run(_a: &BenchArgs) -> Result<()> {
    bail!("bench dem is not built yet")
}
