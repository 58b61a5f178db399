//! `fluid` scenes (work in progress on its issue branch).

use super::SimContext;
use crate::stages::StageOutput;
use anyhow::{Result, bail};

pub fn run(_scene: &toml::Value, _ctx: &SimContext) -> Result<StageOutput> {
    bail!("fluid scenes are not built yet")
}
