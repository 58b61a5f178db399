//! `lbdem bench radiograph` (work in progress on its issue branch).

use super::BenchArgs;
use anyhow::{Result, bail};

pub fn run(_a: &BenchArgs) -> Result<()> {
    bail!("bench radiograph is not built yet")
}
