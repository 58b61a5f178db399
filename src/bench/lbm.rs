//! `lbdem bench lbm` (work in progress on its issue branch).

use super::BenchArgs;
use anyhow::{Result, bail};

pub fn run(_a: &BenchArgs) -> Result<()> {
    bail!("bench lbm is not built yet")
}
