//! The provenance block of every report: code version, pipeline file and its hash, the
//! SHA-256 of every input and the wall time of every stage.

use super::{InputHash, StageRecord, code_version, hash_file, schema::Pipeline};
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StageProvenance {
    pub name: String,
    pub kind: String,
    pub wall_s: f64,
    pub cached: bool,
    pub out_dir: PathBuf,
    pub inputs: Vec<InputHash>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Provenance {
    pub pipeline_name: String,
    pub code_version: String,
    pub pipeline_file: InputHash,
    /// Seconds since the Unix epoch when the run started.
    pub started_unix_s: u64,
    pub threads: usize,
    pub stages: Vec<StageProvenance>,
    pub total_wall_s: f64,
}

pub const FILE: &str = "provenance.json";

impl Provenance {
    pub fn start(path: &Path, pipeline: &Pipeline) -> Result<Self> {
        let started = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs())
            .unwrap_or(0);
        Ok(Self {
            pipeline_name: pipeline.name.clone(),
            code_version: code_version(),
            pipeline_file: hash_file(path)?,
            started_unix_s: started,
            threads: rayon::current_num_threads(),
            stages: Vec::new(),
            total_wall_s: 0.0,
        })
    }

    pub fn add(&mut self, r: &StageRecord, out_dir: &Path) {
        self.stages.push(StageProvenance {
            name: r.name.clone(),
            kind: r.kind.clone(),
            wall_s: r.wall_s,
            cached: r.cached,
            out_dir: out_dir.to_path_buf(),
            inputs: r.inputs.clone(),
        });
    }

    pub fn write(&self, out: &Path) -> Result<()> {
        lbdem_core::atomic::write_atomic(&out.join(FILE), &serde_json::to_vec_pretty(self)?)?;
        Ok(())
    }

    pub fn load(out: &Path) -> Option<Self> {
        serde_json::from_str(&std::fs::read_to_string(out.join(FILE)).ok()?).ok()
    }
}
