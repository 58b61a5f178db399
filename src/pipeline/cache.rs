//! Content-hash cache: a stage is skipped when its kind, parameters, input bytes and the
//! code version hash to the key stored in its manifest and every output it listed exists.

pub use crate::contract::hash_file;
use crate::contract::{InputHash, MANIFEST, StageContext, StageRecord};
use crate::registry::Prepared;
use anyhow::{Context, Result};
use std::path::PathBuf;

/// Hash every input; a directory counts as all files in it (sorted, not recursive).
pub fn hash_inputs(paths: &[PathBuf]) -> Result<Vec<InputHash>> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut entries: Vec<PathBuf> = std::fs::read_dir(p)
                .with_context(|| format!("cannot list input directory {}", p.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.is_file())
                .collect();
            entries.sort();
            for e in entries {
                out.push(hash_file(&e)?);
            }
        } else {
            out.push(hash_file(p)?);
        }
    }
    Ok(out)
}

/// The key of a stage run: [`super::key_parts::KeyParts::key`] of its parts now.
pub fn cache_key(kind: &str, params: &serde_json::Value, inputs: &[InputHash]) -> String {
    super::key_parts::KeyParts::now(kind, params, inputs).key()
}

/// The stored record if the stage can be skipped.
pub fn reusable(prepared: &Prepared, ctx: &StageContext) -> Result<Option<StageRecord>> {
    let manifest = ctx.out_dir.join(MANIFEST);
    let Ok(text) = std::fs::read_to_string(&manifest) else {
        return Ok(None);
    };
    let Ok(old) = serde_json::from_str::<StageRecord>(&text) else {
        return Ok(None);
    };
    let inputs = hash_inputs(&prepared.inputs)?;
    let key = cache_key(&prepared.kind, &prepared.params_json, &inputs);
    let complete = old.output.files.iter().all(|f| ctx.out_dir.join(f).is_file());
    Ok((old.cache_key == key && complete).then_some(old))
}

/// Whether the stage's interrupted run (its `.partial` directory) was made with the same key,
/// so `lbdem run` can continue it instead of starting again.
pub fn resumable(prepared: &Prepared, ctx: &StageContext) -> Result<bool> {
    let partial = ctx.out_dir.join(super::PARTIAL);
    if !partial.join(crate::contract::CHECKPOINT).is_file() {
        return Ok(false); // killed before its first checkpoint: nothing to continue
    }
    let Ok(stored) = std::fs::read_to_string(partial.join(KEY_FILE)) else {
        return Ok(false);
    };
    let inputs = hash_inputs(&prepared.inputs)?;
    Ok(stored.trim() == cache_key(&prepared.kind, &prepared.params_json, &inputs))
}

/// The file in a resumable stage's working directory that holds the key of its run.
pub const KEY_FILE: &str = "run.key";
