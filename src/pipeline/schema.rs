//! The pipeline file.
//!
//! ```toml
//! [pipeline]
//! name = "quickstart"
//! root = ".."                  # paths below resolve from here (relative to this file)
//! out = "reports/quickstart"
//!
//! [[stage]]
//! name = "radiograph"
//! kind = "radiograph"
//! [stage.params]
//! frames = ["data/synth/frame_000.tif"]
//! ```

use crate::registry;
use anyhow::{Context, Result, bail};
use serde::Deserialize;
use std::collections::HashSet;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    pipeline: Header,
    #[serde(default)]
    stage: Vec<StageSpec>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    name: String,
    #[serde(default)]
    root: Option<PathBuf>,
    out: PathBuf,
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSpec {
    pub name: String,
    pub kind: String,
    #[serde(default = "empty_table")]
    pub params: toml::Value,
}

fn empty_table() -> toml::Value {
    toml::Value::Table(Default::default())
}

#[derive(Debug)]
pub struct Pipeline {
    pub name: String,
    /// Directory that relative paths in the file resolve from.
    pub root: PathBuf,
    pub out: PathBuf,
    pub stages: Vec<StageSpec>,
}

/// Every string parameter that starts with `@` (a path in an earlier stage's output, see
/// `StageContext::resolve`), with its key.
fn at_references<'a>(v: &'a toml::Value, key: &str, out: &mut Vec<(String, &'a str)>) {
    match v {
        toml::Value::String(s) if s.starts_with('@') => out.push((key.to_string(), s)),
        toml::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                at_references(x, &format!("{key}[{i}]"), out);
            }
        }
        toml::Value::Table(t) => {
            for (k, x) in t {
                at_references(x, &format!("{key}.{k}"), out);
            }
        }
        _ => {}
    }
}

impl Pipeline {
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read pipeline file {}", path.display()))?;
        Self::parse(&text, path)
    }

    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let f: File =
            toml::from_str(text).with_context(|| format!("pipeline file {} is not valid", path.display()))?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let root = match f.pipeline.root {
            Some(r) if r.is_absolute() => r,
            Some(r) => dir.join(r),
            None => dir,
        };
        if f.stage.is_empty() {
            bail!("pipeline file {} has no [[stage]] entries", path.display());
        }
        let mut seen = HashSet::new();
        let mut earlier: Vec<&str> = Vec::new();
        for s in &f.stage {
            let mut refs = Vec::new();
            at_references(&s.params, "params", &mut refs);
            for (key, value) in refs {
                let name = value[1..].split('/').next().unwrap_or("");
                if !earlier.contains(&name) {
                    bail!(
                        "pipeline file {}: stage '{}' {key} = \"{value}\" reads the output of a stage \
                         '{name}', but no earlier stage has that name (earlier stages: {}); a stage \
                         reads only what the stages above it wrote: fix the name or move the stage",
                        path.display(),
                        s.name,
                        if earlier.is_empty() {
                            "none".to_string()
                        } else {
                            earlier.join(", ")
                        }
                    );
                }
            }
            earlier.push(&s.name);
            if !seen.insert(s.name.as_str()) {
                bail!(
                    "pipeline file {}: two stages are named '{}'; stage names must be unique",
                    path.display(),
                    s.name
                );
            }
            if registry::find(&s.kind).is_err() {
                bail!(
                    "pipeline file {}: stage '{}' has unknown kind '{}'; known kinds: {}",
                    path.display(),
                    s.name,
                    s.kind,
                    registry::kinds().join(", ")
                );
            }
        }
        Ok(Self {
            name: f.pipeline.name,
            root,
            out: f.pipeline.out,
            stages: f.stage,
        })
    }

    pub fn out_dir(&self) -> PathBuf {
        if self.out.is_absolute() {
            self.out.clone()
        } else {
            self.root.join(&self.out)
        }
    }
}
