//! The one list of stage kinds. The runner reads it to parse a pipeline's stages, and the CLI
//! reads it to make one subcommand per stage; adding a stage is one file in `stages/` and one
//! line in [`STAGES`].

use crate::contract::{Stage, StageContext, StageOutput};
use crate::stages;
use anyhow::{Context, Result, bail};
use std::path::PathBuf;

/// How a stage's subcommand takes its parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CliShape {
    /// `lbdem <cmd> PARAMS.toml --out DIR [--set key=value]`: the TOML file holds the stage's
    /// parameters (the same keys as a pipeline's `[stage.params]`).
    ParamsFile,
    /// `lbdem simulate SCENE.toml [--out DIR] [--resume] [--set key=value]`: the file is a
    /// scene; the stage's parameters are `scene = PATH` and the overrides.
    SceneFile,
}

/// One stage kind: its name, its CLI shape and how to parse its parameters.
pub struct StageKind {
    pub kind: &'static str,
    pub about: &'static str,
    /// Subcommand path (`["synth", "radiograph"]` is `lbdem synth radiograph`).
    pub cli: &'static [&'static str],
    pub shape: CliShape,
    pub resumable: bool,
    prepare: fn(toml::Value, &StageContext) -> Result<Prepared>,
}

const fn entry<S: Stage + 'static>(cli: &'static [&'static str], shape: CliShape) -> StageKind {
    StageKind {
        kind: S::KIND,
        about: S::ABOUT,
        cli,
        shape,
        resumable: S::RESUMABLE,
        prepare: prepare_as::<S>,
    }
}

/// Every stage kind, in the order `lbdem --help` lists them.
pub static STAGES: &[StageKind] = &[
    entry::<stages::radiograph::Radiograph>(&["radiograph"], CliShape::ParamsFile),
    entry::<stages::synth::SynthRadiograph>(&["synth", "radiograph"], CliShape::ParamsFile),
    entry::<stages::digitise::Digitise>(&["digitise"], CliShape::ParamsFile),
    entry::<stages::assemble::Assemble>(&["assemble"], CliShape::ParamsFile),
    entry::<stages::simulate::Simulate>(&["simulate"], CliShape::SceneFile),
    entry::<stages::settling_study::SettlingStudy>(&["settling-study"], CliShape::ParamsFile),
    entry::<stages::stability_map::StabilityMap>(&["stability-map"], CliShape::ParamsFile),
    entry::<stages::stability_map::dem::DemStepMap>(&["dem-step-map"], CliShape::ParamsFile),
    entry::<stages::stability_map::bingham::BinghamMap>(&["bingham-map"], CliShape::ParamsFile),
    entry::<stages::stability_map::bingham_floor::BinghamFloorMap>(
        &["bingham-floor-map"],
        CliShape::ParamsFile,
    ),
    entry::<stages::stability_map::free_surface::FreeSurfaceMap>(&["free-surface-map"], CliShape::ParamsFile),
    entry::<stages::stability_map::interior_liquid::InteriorLiquidMap>(
        &["interior-liquid-map"],
        CliShape::ParamsFile,
    ),
    entry::<stages::stability_map::dense_psm::DensePsmMap>(&["dense-psm-map"], CliShape::ParamsFile),
    entry::<stages::report::Report>(&["report"], CliShape::ParamsFile),
    entry::<stages::analyse::Analyse>(&["analyse"], CliShape::ParamsFile),
    entry::<stages::synth_run::SynthRun>(&["synth", "run"], CliShape::ParamsFile),
    entry::<stages::compare::Compare>(&["compare"], CliShape::ParamsFile),
    entry::<stages::mechanism_map::MechanismMap>(&["mechanism-map"], CliShape::ParamsFile),
    entry::<stages::incline_outlines::InclineOutlines>(&["incline-outlines"], CliShape::ParamsFile),
    entry::<stages::matrix::Matrix>(&["matrix"], CliShape::ParamsFile),
    entry::<stages::tradeoffs::Tradeoffs>(&["tradeoffs"], CliShape::ParamsFile),
    entry::<stages::minimal_models::MinimalModels>(&["minimal-models"], CliShape::ParamsFile),
    entry::<stages::extrusion::Extrusion>(&["extrusion"], CliShape::ParamsFile),
    entry::<stages::extrusion::flow::ExtrusionFlow>(&["extrusion-flow"], CliShape::ParamsFile),
];

/// The stage kind named `kind`, or an error listing the known ones.
pub fn find(kind: &str) -> Result<&'static StageKind> {
    STAGES
        .iter()
        .find(|k| k.kind == kind)
        .with_context(|| format!("unknown stage kind '{kind}'; known kinds: {}", kinds().join(", ")))
}

/// The names of every stage kind.
pub fn kinds() -> Vec<&'static str> {
    STAGES.iter().map(|k| k.kind).collect()
}

impl StageKind {
    /// Parse `params` for this kind (defaults filled in), ready to hash or run.
    pub fn prepare(&self, params: toml::Value, ctx: &StageContext) -> Result<Prepared> {
        (self.prepare)(params, ctx)
    }
}

/// A stage's work, deferred until the runner decides it must run.
type RunFn = Box<dyn FnOnce(&StageContext) -> Result<StageOutput>>;

/// A stage with its parameters already parsed, ready to hash or run.
pub struct Prepared {
    pub kind: String,
    pub resumable: bool,
    /// Canonical JSON of the parsed parameters (defaults filled in), for the cache key.
    pub params_json: serde_json::Value,
    pub inputs: Vec<PathBuf>,
    run: RunFn,
}

impl Prepared {
    /// A prepared stage from parts (the runner's own tests use this with a closure).
    #[cfg(test)]
    pub(crate) fn from_parts(
        kind: &str,
        params_json: serde_json::Value,
        inputs: Vec<PathBuf>,
        run: impl FnOnce(&StageContext) -> Result<StageOutput> + 'static,
    ) -> Self {
        Self {
            kind: kind.into(),
            resumable: false,
            params_json,
            inputs,
            run: Box::new(run),
        }
    }

    pub fn run(self, ctx: &StageContext) -> Result<StageOutput> {
        (self.run)(ctx)
    }
}

fn prepare_as<S: Stage + 'static>(params: toml::Value, ctx: &StageContext) -> Result<Prepared> {
    let p: S::Params = params
        .try_into()
        .with_context(|| format!("parameters of stage '{}' (kind '{}')", ctx.name, S::KIND))?;
    let params_json = serde_json::to_value(&p)?;
    let inputs = S::inputs(&p, ctx);
    Ok(Prepared {
        kind: S::KIND.into(),
        resumable: S::RESUMABLE,
        params_json,
        inputs,
        run: Box::new(move |c| S::run(&p, c)),
    })
}

/// Apply `--set key=value` overrides (dotted keys reach into sub-tables) under `prefix`
/// (e.g. `overrides` for a scene), or at the top of the parameters when it is empty.
pub fn apply_overrides(params: &mut toml::Value, prefix: &[&str], sets: &[String]) -> Result<()> {
    for s in sets {
        let (key, raw) = s
            .split_once('=')
            .with_context(|| format!("--set '{s}': expected KEY=VALUE, e.g. --set rev_factor=3.16"))?;
        let value: toml::Value = match toml::from_str::<toml::Table>(&format!("v = {raw}")) {
            Ok(mut t) => t.remove("v").unwrap_or(toml::Value::String(raw.into())),
            Err(_) => toml::Value::String(raw.into()),
        };
        let mut cur = &mut *params;
        let parts: Vec<&str> = prefix.iter().copied().chain(key.trim().split('.')).collect();
        if parts.iter().any(|p| p.is_empty()) {
            bail!("--set '{s}': empty key part; write e.g. --set run.steps=100");
        }
        for (i, part) in parts.iter().enumerate() {
            let table = cur
                .as_table_mut()
                .with_context(|| format!("--set '{s}': '{part}' is inside a value that is not a table"))?;
            if i + 1 == parts.len() {
                table.insert((*part).into(), value.clone());
                break;
            }
            cur = table
                .entry(*part)
                .or_insert_with(|| toml::Value::Table(Default::default()));
        }
    }
    Ok(())
}
