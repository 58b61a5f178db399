//! Scenes: a simulation set-up in SI units read from a TOML file. The `[scene] kind`
//! names the physics it uses (`fluid`, `dry`, `coupled`), and only that physics
//! is built: a dry assembly pays nothing for a lattice.

pub mod coupled;
pub mod dry;
pub mod fluid;

use crate::stages::{Stage, StageContext, StageOutput};
use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// Where a scene run writes, and whether it continues from a checkpoint.
pub struct SimContext {
    pub out_dir: PathBuf,
    pub resume: bool,
    /// Directory of the scene file: relative paths in it resolve from here.
    pub base_dir: PathBuf,
}

#[derive(Deserialize)]
struct Header {
    scene: SceneKind,
}

#[derive(Deserialize)]
struct SceneKind {
    kind: String,
    #[serde(default)]
    name: Option<String>,
}

/// Run the scene file at `path`; returns what the run wrote.
pub fn run_scene(path: &Path, out: Option<&Path>, resume: bool) -> Result<StageOutput> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read scene file {}", path.display()))?;
    let value: toml::Value =
        toml::from_str(&text).with_context(|| format!("scene file {} is not valid TOML", path.display()))?;
    let header: Header = value.clone().try_into().with_context(|| {
        format!(
            "scene file {}: needs a [scene] table with kind = \"fluid\", \"dry\" or \"coupled\"",
            path.display()
        )
    })?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    let name = header.scene.name.unwrap_or(stem);
    let out_dir = out
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("out").join(&name));
    let ctx = SimContext {
        out_dir,
        resume,
        base_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
    };
    match header.scene.kind.as_str() {
        "fluid" => fluid::run(&value, &ctx),
        "dry" => dry::run(&value, &ctx),
        "coupled" => coupled::run(&value, &ctx),
        other => bail!(
            "scene file {}: [scene] kind = \"{other}\" is not known; use \"fluid\", \"dry\" or \"coupled\"",
            path.display()
        ),
    }
}

/// `lbdem simulate SCENE.toml`.
pub fn simulate(path: &Path, out: Option<&Path>, resume: bool) -> Result<()> {
    let t0 = std::time::Instant::now();
    let o = run_scene(path, out, resume)?;
    eprintln!(
        "simulate: wrote {} files in {:.2} s",
        o.files.len(),
        t0.elapsed().as_secs_f64()
    );
    Ok(())
}

/// The pipeline stage `simulate`: `scene = "scenes/x.toml"`.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulateParams {
    pub scene: PathBuf,
}

pub struct SimulateStage;

impl Stage for SimulateStage {
    const KIND: &'static str = "simulate";
    type Params = SimulateParams;
    fn inputs(p: &SimulateParams, ctx: &StageContext) -> Vec<PathBuf> {
        vec![ctx.resolve(&p.scene)]
    }
    fn run(p: &SimulateParams, ctx: &StageContext) -> Result<StageOutput> {
        run_scene(&ctx.resolve(&p.scene), Some(&ctx.out_dir), false)
    }
}
