//! Stage `radiograph` (work in progress on its issue branch).

use super::{Stage, StageContext, StageOutput};
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

#[derive(Debug, Serialize, Deserialize)]
pub struct Params {}

pub struct Radiograph;

impl Stage for Radiograph {
    const KIND: &'static str = "radiograph";
    type Params = Params;
    fn inputs(_: &Params, _: &StageContext) -> Vec<PathBuf> {
        Vec::new()
    }
    fn run(_: &Params, _: &StageContext) -> Result<StageOutput> {
        bail!("stage 'radiograph' is not built yet")
    }
}
