//! Starting the provenance record of a pipeline run (the type is in `crate::contract`).

use super::{hash_file, schema::Pipeline};
use crate::contract::{Provenance, code_version};
use anyhow::Result;
use std::path::Path;

pub fn start(path: &Path, pipeline: &Pipeline) -> Result<Provenance> {
    let started = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs())
        .unwrap_or(0);
    Ok(Provenance {
        pipeline_name: pipeline.name.clone(),
        code_version: code_version(),
        pipeline_file: hash_file(path)?,
        started_unix_s: started,
        threads: rayon::current_num_threads(),
        simd: lbdem_core::simd::level().name().to_string(),
        stages: Vec::new(),
        total_wall_s: 0.0,
    })
}
