//! Stage `synth-radiograph` (work in progress on its issue branch).

use super::{Stage, StageContext, StageOutput};
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

#[derive(Debug, Serialize, Deserialize)]
pub struct Params {}

pub struct SynthRadiograph;

impl Stage for SynthRadiograph {
    const KIND: &'static str = "synth-radiograph";
    type Params = Params;
    fn inputs(_: &Params, _: &StageContext) -> Vec<PathBuf> {
        Vec::new()
    }
    fn run(_: &Params, _: &StageContext) -> Result<StageOutput> {
        bail!("stage 'synth-radiograph' is not built yet")
    }
}
