//! The scene file: a set of sections, one type each, shared by every scene. What a scene
//! simulates follows from the sections it has: `[particles]` alone is a dry DEM run, `[fluid]`
//! with `[lattice]` alone a liquid run, both together a coupled LBM-DEM run. A section that the
//! scene's physics does not use is refused ("[lattice] is given but the scene has no [fluid]"),
//! so nothing is silently ignored. New physics is a new section here, not a new scene kind.
//!
//! Every section refuses unknown keys, and the error names the file, the line, the key and the
//! nearest valid name. Files of the earlier format (`[scene] kind = ...`, `[step]`, `[stop]`)
//! get an error that says how to convert them. Format: docs/scenes.md.

mod check;
mod coupling;
mod dem;
mod extruder;
mod fluid;
mod legacy;
mod packed_zone;
mod run;
mod shear_cell;
pub mod simplify;

pub use coupling::CouplingSection;
pub use dem::{
    BondsSection, CompressSection, DemSection, GenerateSection, HeldScale, MassScaleControl, MembraneSection,
    ParticlesSection, TemplateSection, WallSection,
};
pub use extruder::{ExtruderSection, NessLaw, SuspensionSection};
pub use fluid::{
    BoundariesSection, FaceSection, FluidSection, ForcingSection, LatticeSection, MaskSection,
    ObstacleSection,
};
pub use packed_zone::PackedZoneSection;
pub use run::{OutputSection, RunSection, SlowerOver, SlowerThan, TriggerSpec, WallMoved, WallRef, When};
pub use shear_cell::ShearCellSection;

use anyhow::{Context, Result, bail};
use lbdem_dem::Law;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `[scene]`: the name (default: the file's stem) and a free description.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Header {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub description: Option<String>,
    /// A scene file this one is written over (relative to this file): its sections and keys
    /// come first, this file's replace them key by key. For families of cases that differ in a
    /// few values (Su et al. 2020's 4 × 3 matrix).
    #[serde(default)]
    pub extends: Option<PathBuf>,
    /// Physics to switch off or simplify, by name (`"no-rolling+f32"` or a list; "none"):
    /// [`simplify::CATALOGUE`], docs/minimal.md.
    #[serde(default)]
    pub simplify: Option<toml::Value>,
    /// Apply every simplification the scene family's minimal-model table shows harmless.
    #[serde(default)]
    pub minimal: bool,
    /// That table, relative to this file (default `minimal.csv` beside it).
    #[serde(default)]
    pub minimal_table: Option<PathBuf>,
}

/// `[domain]`: the box (m), 2 or 3 entries per key, and which axes are periodic (for the grains
/// and the lattice alike). An `[extruder]` scene has none (its box follows from its geometry).
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct DomainSection {
    pub lo: Vec<f64>,
    pub hi: Vec<f64>,
    #[serde(default)]
    pub periodic: Vec<bool>,
}

impl DomainSection {
    pub fn dim(&self) -> usize {
        self.lo.len()
    }
    /// Whether axis `a` is periodic.
    pub fn is_periodic(&self, a: usize) -> bool {
        self.periodic.get(a).copied().unwrap_or(false)
    }
    pub fn size(&self, a: usize) -> f64 {
        self.hi[a] - self.lo[a]
    }
    /// The 2D box of the grains.
    pub fn lo2(&self) -> [f64; 2] {
        [self.lo[0], self.lo[1]]
    }
    pub fn hi2(&self) -> [f64; 2] {
        [self.hi[0], self.hi[1]]
    }
    pub fn periodic2(&self) -> [bool; 2] {
        [self.is_periodic(0), self.is_periodic(1)]
    }
}

/// A scene file, parsed.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    #[serde(default)]
    pub scene: Header,
    #[serde(default)]
    pub domain: DomainSection,
    #[serde(default)]
    pub particles: Option<ParticlesSection>,
    #[serde(default)]
    pub contact: Option<Law>,
    #[serde(default)]
    pub wall_contact: Option<Law>,
    #[serde(default)]
    pub walls: Vec<WallSection>,
    #[serde(default)]
    pub bonds: Option<BondsSection>,
    #[serde(default)]
    pub membrane: Option<MembraneSection>,
    #[serde(default)]
    pub dem: Option<DemSection>,
    #[serde(default)]
    pub compress: Option<CompressSection>,
    #[serde(default)]
    pub shear_cell: Option<ShearCellSection>,
    #[serde(default)]
    pub packed_zone: Option<PackedZoneSection>,
    #[serde(default)]
    pub fluid: Option<FluidSection>,
    #[serde(default)]
    pub lattice: Option<LatticeSection>,
    #[serde(default)]
    pub boundaries: Option<BoundariesSection>,
    #[serde(default)]
    pub forcing: Option<ForcingSection>,
    #[serde(default)]
    pub obstacles: Vec<ObstacleSection>,
    #[serde(default)]
    pub mask: Option<MaskSection>,
    #[serde(default)]
    pub coupling: Option<CouplingSection>,
    /// Ness et al. (2017)'s extruder (3D spheres): a scene of its own kind of grains.
    #[serde(default)]
    pub extruder: Option<ExtruderSection>,
    #[serde(default)]
    pub suspension: Option<SuspensionSection>,
    /// Leonardi et al. (2014)'s concrete incline (3D free-surface LBM-DEM): a scene of its own.
    #[serde(default)]
    pub incline: Option<lbdem_coupling::cases::incline::InclineSpec>,
    pub run: RunSection,
    #[serde(default)]
    pub output: OutputSection,
}

/// What a scene simulates, from its sections.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Physics {
    /// Grains only (DEM).
    Dry,
    /// Liquid only (LBM).
    Fluid,
    /// Grains in a liquid (LBM-DEM).
    Coupled,
    /// Ness et al. (2017)'s extruder: 3D lubricated spheres ([extruder], [suspension]).
    Extruder,
    /// Leonardi et al. (2014)'s incline: free-surface Bingham paste with pebbles ([incline]).
    Incline,
}

#[derive(Debug)]
/// A scene read from its file: the sections, the physics they name, where relative paths
/// resolve from, and the scene's name.
pub struct Loaded {
    pub scene: Scene,
    pub physics: Physics,
    pub base_dir: PathBuf,
    pub name: String,
    pub path: PathBuf,
    /// The files the scene was read from: itself, then what it extends.
    pub sources: Vec<PathBuf>,
    /// The simplifications applied (`[scene] simplify` and `minimal`), each with why.
    pub simplified: Vec<String>,
    /// The minimal-model table `minimal = true` read.
    pub minimal_table: Option<PathBuf>,
}

/// How many `extends` a scene may chain.
const MAX_EXTENDS: usize = 8;

/// The table of the scene file at `path` with what it extends merged under it, and the files
/// read (the scene first).
fn read_table(path: &Path, sources: &mut Vec<PathBuf>) -> Result<(toml::Table, String)> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read scene file {}", path.display()))?;
    let mut value: toml::Table =
        toml::from_str(&text).with_context(|| format!("scene file {} is not valid TOML", path.display()))?;
    legacy::refuse_old_format(&value, path)?;
    sources.push(path.to_path_buf());
    let base = value
        .get_mut("scene")
        .and_then(|s| s.as_table_mut())
        .and_then(|s| s.remove("extends"));
    let Some(base) = base else {
        return Ok((value, text));
    };
    let Some(rel) = base.as_str() else {
        bail!(
            "scene file {}: [scene] extends = {base}: give a file name in quotes",
            path.display()
        );
    };
    let base_path = path.parent().unwrap_or(Path::new(".")).join(rel);
    if sources.len() > MAX_EXTENDS || sources.contains(&base_path) {
        bail!(
            "scene file {}: [scene] extends = {rel:?} makes a chain of {} files or a loop ({}); \
             extend a file that does not extend this one",
            path.display(),
            sources.len(),
            sources
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(" -> ")
        );
    }
    let (mut merged, _) = read_table(&base_path, sources)
        .with_context(|| format!("scene file {} extends {rel:?}", path.display()))?;
    merge(&mut merged, &value);
    let text = toml::to_string(&merged)?;
    Ok((merged, text))
}

/// Read and check the scene file at `path`, with `overrides` (a TOML table of sections and
/// keys, e.g. from `--set run.steps=100`) merged over it.
pub fn load(path: &Path, overrides: &toml::Table) -> Result<Loaded> {
    let mut sources = Vec::new();
    let (mut value, text) = read_table(path, &mut sources)?;
    merge(&mut value, overrides);
    let simplify::Applied {
        names: simplified,
        table: minimal_table,
    } = simplify::apply(&mut value, path)?;
    let own = std::fs::read_to_string(path).unwrap_or_default();
    check::values(&value, path, &own, overrides)?;
    // Parse from text so that errors point at the line (overrides and simplifications are
    // re-serialised).
    let text = if overrides.is_empty() && simplified.is_empty() {
        text
    } else {
        toml::to_string(&value)?
    };
    let scene: Scene = toml::from_str(&text).map_err(|e| explain(e, path))?;
    let physics = scene
        .physics()
        .and_then(|p| check::consistency(&scene).map(|()| p))
        .with_context(|| format!("scene file {}", path.display()))?;
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "scene".into());
    Ok(Loaded {
        name: scene.scene.name.clone().unwrap_or(stem),
        physics,
        base_dir: path.parent().map(Path::to_path_buf).unwrap_or_default(),
        path: path.to_path_buf(),
        sources,
        simplified,
        minimal_table,
        scene,
    })
}

/// The scene file at `path` as one TOML table, with what it extends merged under it (unchecked):
/// a sweep resolves keys inside arrays (`walls.plate.velocity`) against it.
pub fn merged_table(path: &Path) -> Result<toml::Table> {
    Ok(read_table(path, &mut Vec::new())?.0)
}

/// The scene's name (`[scene] name`, else the file's stem), without checking the rest.
pub fn scene_name(path: &Path) -> Result<String> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read scene file {}", path.display()))?;
    let value: toml::Table =
        toml::from_str(&text).with_context(|| format!("scene file {} is not valid TOML", path.display()))?;
    let name = value
        .get("scene")
        .and_then(|s| s.get("name"))
        .and_then(|n| n.as_str())
        .map(str::to_string);
    Ok(name.unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "scene".into())
    }))
}

/// Merge `over` into `base`, table by table.
fn merge(base: &mut toml::Table, over: &toml::Table) {
    for (k, v) in over {
        match (base.get_mut(k), v) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            _ => {
                base.insert(k.clone(), v.clone());
            }
        }
    }
}

/// A parse error with the file name and, for an unknown key, the nearest valid name.
fn explain(e: toml::de::Error, path: &Path) -> anyhow::Error {
    let msg = e.to_string();
    let hint = suggestion(&msg).map_or(String::new(), |(bad, good)| {
        format!("\n`{bad}` is not a key here; did you mean `{good}`?")
    });
    anyhow::anyhow!(
        "scene file {}: {msg}{hint}\n(every key: docs/scenes.md)",
        path.display()
    )
}

/// From serde's "unknown field `x`, expected one of `a`, `b`" (or "expected `a` or `b`", or
/// "unknown variant"), the bad key and the valid one nearest to it.
fn suggestion(msg: &str) -> Option<(String, String)> {
    let start = msg
        .find("unknown field `")
        .map(|i| i + 15)
        .or_else(|| msg.find("unknown variant `").map(|i| i + 17))?;
    let bad_end = msg[start..].find('`')? + start;
    let bad = &msg[start..bad_end];
    let rest = &msg[bad_end..];
    let candidates: Vec<&str> = rest.split('`').skip(2).step_by(2).collect();
    let best = candidates
        .iter()
        .map(|c| (strsim::damerau_levenshtein(bad, c), *c))
        .min()?;
    (best.0 <= bad.len().max(3) / 2 + 1).then(|| (bad.to_string(), best.1.to_string()))
}

impl Scene {
    /// What the scene simulates, checking that every section it has is used by that physics.
    pub fn physics(&self) -> Result<Physics> {
        if self.incline.is_some() {
            return self.incline_physics();
        }
        if self.extruder.is_some() {
            return self.extruder_physics();
        }
        if self.suspension.is_some() {
            bail!(
                "[suspension] is given but the scene has no [extruder]; add [extruder] or remove [suspension]"
            );
        }
        let d = &self.domain;
        if !(d.lo.len() == 2 || d.lo.len() == 3) || d.hi.len() != d.lo.len() {
            bail!(
                "[domain] lo and hi need 2 (2D) or 3 (3D) numbers each; got {} and {}",
                d.lo.len(),
                d.hi.len()
            );
        }
        if !d.periodic.is_empty() && d.periodic.len() != d.lo.len() {
            bail!(
                "[domain] periodic has {} entries for a {}D box; give one true/false per axis",
                d.periodic.len(),
                d.lo.len()
            );
        }
        for a in 0..d.dim() {
            if d.hi[a] <= d.lo[a] || !d.lo[a].is_finite() || !d.hi[a].is_finite() {
                bail!(
                    "[domain] axis {a}: hi = {} must be above lo = {}",
                    d.hi[a],
                    d.lo[a]
                );
            }
        }
        let grains = self.particles.is_some();
        let liquid = self.fluid.is_some();
        if self.lattice.is_some() && !liquid {
            bail!("[lattice] is given but the scene has no [fluid]; add [fluid] or remove [lattice]");
        }
        if liquid && self.lattice.is_none() {
            bail!("[fluid] needs a [lattice] section (dx and dt or tau)");
        }
        if let Some(sc) = &self.shear_cell {
            if self.membrane.is_none() {
                bail!("[shear_cell] measures the sample inside its membrane: add [membrane] (and [bonds])");
            }
            if !(sc.shear_length > 0.0 && sc.shear_length.is_finite()) {
                bail!(
                    "[shear_cell] shear_length = {}: must be a positive length in m (Su: 0.01)",
                    sc.shear_length
                );
            }
            if let Some(r) = &sc.settle_until_rest
                && r.max_time < sc.settle
            {
                bail!(
                    "[shear_cell] settle_until_rest.max_time = {} s is shorter than settle = {} s, the shortest \
                     hold; make max_time at least settle",
                    r.max_time,
                    sc.settle
                );
            }
        }
        let grain_only: [(&str, bool); 9] = [
            ("[packed_zone]", self.packed_zone.is_some()),
            ("[contact]", self.contact.is_some()),
            ("[wall_contact]", self.wall_contact.is_some()),
            ("[[walls]]", !self.walls.is_empty()),
            ("[bonds]", self.bonds.is_some()),
            ("[membrane]", self.membrane.is_some()),
            ("[dem]", self.dem.is_some()),
            ("[compress]", self.compress.is_some()),
            ("[shear_cell]", self.shear_cell.is_some()),
        ];
        let liquid_only: [(&str, bool); 2] = [
            ("[boundaries]", self.boundaries.is_some()),
            ("[forcing]", self.forcing.is_some()),
        ];
        if !grains {
            if let Some((s, _)) = grain_only.iter().find(|(_, on)| *on) {
                bail!("{s} is given but the scene has no [particles]; add [particles] or remove {s}");
            }
            if self.run.until_slower_than.is_some() || self.run.until_wall_moved.is_some() {
                bail!("[run] until_slower_than / until_wall_moved need grains ([particles])");
            }
        }
        if !liquid {
            if let Some((s, _)) = liquid_only.iter().find(|(_, on)| *on) {
                bail!("{s} is given but the scene has no [fluid]; add [fluid] and [lattice] or remove {s}");
            }
            if self.run.until_steady.is_some() {
                bail!("[run] until_steady needs a liquid ([fluid])");
            }
        }
        if self.coupling.is_some() && !(grains && liquid) {
            bail!("[coupling] is given but the scene does not have both [particles] and [fluid]");
        }
        let physics = match (grains, liquid) {
            (true, false) => Physics::Dry,
            (false, true) => Physics::Fluid,
            // The liquid switched off: the grains alone (Su Fig. 11, right column).
            (true, true) if self.coupling.as_ref().is_some_and(|c| !c.liquid) => Physics::Dry,
            (true, true) => Physics::Coupled,
            (false, false) => {
                bail!("the scene has neither [particles] nor [fluid]: nothing to simulate (docs/scenes.md)")
            }
        };
        if grains {
            if self.contact.is_none() {
                bail!("[particles] needs a [contact] law (law = \"linear\", \"hertz\" or \"plastic\")");
            }
            if self.dem.is_none() {
                bail!("[particles] needs a [dem] section (dt, skin)");
            }
            if d.dim() != 2 {
                bail!("[particles]: the grains are 2D; give [domain] lo and hi with 2 numbers");
            }
        }
        if physics != Physics::Fluid && (!self.obstacles.is_empty() || self.mask.is_some()) {
            bail!("[[obstacles]] and [mask] are for liquid-only scenes; the grains are the solids here");
        }
        if self.bonds.is_some() && self.membrane.is_none() {
            bail!("[bonds] bond the membrane grains: add a [membrane] section");
        }
        self.check_run(grains, liquid)?;
        Ok(physics)
    }

    /// The 2D engine's and the liquid's sections, each with whether the scene gives it: what a
    /// 3D scene with its own box (`[extruder]`, `[incline]`) must not have.
    fn planar_sections(&self) -> [(&'static str, bool); 18] {
        [
            (
                "[domain]",
                !self.domain.lo.is_empty() || !self.domain.hi.is_empty(),
            ),
            ("[particles]", self.particles.is_some()),
            ("[contact]", self.contact.is_some()),
            ("[wall_contact]", self.wall_contact.is_some()),
            ("[[walls]]", !self.walls.is_empty()),
            ("[bonds]", self.bonds.is_some()),
            ("[membrane]", self.membrane.is_some()),
            ("[dem]", self.dem.is_some()),
            ("[compress]", self.compress.is_some()),
            ("[shear_cell]", self.shear_cell.is_some()),
            ("[packed_zone]", self.packed_zone.is_some()),
            ("[fluid]", self.fluid.is_some()),
            ("[lattice]", self.lattice.is_some()),
            ("[boundaries]", self.boundaries.is_some()),
            ("[forcing]", self.forcing.is_some()),
            ("[[obstacles]]", !self.obstacles.is_empty()),
            ("[mask]", self.mask.is_some()),
            ("[coupling]", self.coupling.is_some()),
        ]
    }

    /// Refuse the 2D stop conditions and output triggers in a 3D scene of kind `kind`, which
    /// stops as `stops` says.
    fn refuse_planar_stops(&self, kind: &str, stops: &str) -> Result<()> {
        let r = &self.run;
        if r.until_slower_than.is_some() || r.until_wall_moved.is_some() || r.until_steady.is_some() {
            bail!("[run] until_slower_than / until_wall_moved / until_steady are for 2D scenes; {stops}");
        }
        if self.output.series.when.is_some() || self.output.snapshots.when.is_some() {
            bail!(
                "[output] when = {{...}} triggers read 2D quantities; use every, count or at in an {kind} scene"
            );
        }
        Ok(())
    }

    /// An `[incline]` scene: its own lattice, paste, pebbles and box, so no other physics
    /// section.
    fn incline_physics(&self) -> Result<Physics> {
        let others = self.planar_sections().into_iter().chain([
            ("[extruder]", self.extruder.is_some()),
            ("[suspension]", self.suspension.is_some()),
        ]);
        if let Some((s, _)) = others.into_iter().find(|(_, on)| *on) {
            bail!(
                "{s} is given in an [incline] scene, which builds its own lattice, paste, pebbles and \
                 box from [incline]; remove {s}"
            );
        }
        self.refuse_planar_stops(
            "incline",
            "an incline stops when [incline] stop_share of its paste is at tau_max",
        )?;
        if let Some(i) = &self.incline {
            i.check().map_err(|e| anyhow::anyhow!("[incline]: {e}"))?;
        }
        self.check_run(true, true)?;
        Ok(Physics::Incline)
    }

    /// An `[extruder]` scene: 3D spheres with their own box, so none of the 2D engine's or the
    /// liquid's sections.
    fn extruder_physics(&self) -> Result<Physics> {
        if let Some((s, _)) = self.planar_sections().iter().find(|(_, on)| *on) {
            bail!(
                "{s} is given in an [extruder] scene, which builds its own box and 3D grains \
                 ([extruder] and [suspension]); remove {s}"
            );
        }
        let (Some(e), Some(s)) = (&self.extruder, &self.suspension) else {
            bail!("[extruder] needs a [suspension] section (diameters, density, viscosity, k_n, mu_p, mu_w)");
        };
        self.refuse_planar_stops(
            "extruder",
            "an extruder stops at its mass balance with [extruder] stop_when_steady = true",
        )?;
        extruder::check(e, s)?;
        self.check_run(true, false)?;
        Ok(Physics::Extruder)
    }

    /// The `[run]` length and the `[output]` triggers.
    fn check_run(&self, grains: bool, liquid: bool) -> Result<()> {
        match (self.run.steps, self.run.time) {
            (Some(0), _) => bail!("[run] steps = 0: give at least 1"),
            (Some(_), None) => {}
            (None, Some(t)) if t > 0.0 && t.is_finite() => {}
            (None, Some(t)) => bail!("[run] time = {t}: give a positive number of seconds"),
            _ => bail!("[run]: give exactly one of steps or time (s)"),
        }
        for (what, t) in [
            ("series", &self.output.series),
            ("snapshots", &self.output.snapshots),
            ("checkpoints", &self.output.checkpoints),
        ] {
            check_trigger(what, t)?;
        }
        if self.output.checkpoints.when.is_some() {
            bail!(
                "[output] checkpoints: when = {{...}} is for series and snapshots; use every, count, at or wall_seconds"
            );
        }
        for (what, t) in [
            ("series", &self.output.series),
            ("snapshots", &self.output.snapshots),
        ] {
            if let Some(w) = &t.when {
                let ok = match w.quantity.as_str() {
                    "mean_liquid_speed" => liquid,
                    _ => grains,
                };
                if !ok {
                    bail!(
                        "[output] {what}: when quantity = \"{}\" needs {} in the scene",
                        w.quantity,
                        if grains {
                            "a liquid ([fluid])"
                        } else {
                            "grains ([particles])"
                        }
                    );
                }
            }
        }
        if self.output.series.wall_seconds.is_some() || self.output.snapshots.wall_seconds.is_some() {
            bail!(
                "[output]: wall_seconds is for checkpoints only (series and snapshots must not depend on the machine's speed)"
            );
        }
        Ok(())
    }
}

fn check_trigger(what: &str, t: &TriggerSpec) -> Result<()> {
    let given = usize::from(t.every.is_some())
        + usize::from(t.count.is_some())
        + usize::from(t.at.is_some())
        + usize::from(t.wall_seconds.is_some())
        + usize::from(t.when.is_some())
        + usize::from(t.never);
    if given != 1 {
        bail!(
            "[output] {what}: give exactly one of every = N (steps), count = N, at = [times in s], \
             when = {{ quantity, crosses }}, wall_seconds = S or never = true"
        );
    }
    if t.every == Some(0) || t.count == Some(0) {
        bail!("[output] {what}: every / count must be at least 1 (use never = true to switch it off)");
    }
    if let Some(w) = &t.when {
        match (w.quantity.as_str(), &w.wall) {
            ("wall_displacement", Some(_)) | ("max_grain_speed" | "mean_liquid_speed", None) => {}
            ("wall_displacement", None) => {
                bail!("[output] {what}: when quantity = \"wall_displacement\" needs wall = index or name")
            }
            ("max_grain_speed" | "mean_liquid_speed", Some(_)) => {
                bail!(
                    "[output] {what}: when quantity = \"{}\" takes no wall",
                    w.quantity
                )
            }
            (q, _) => bail!(
                "[output] {what}: when quantity = \"{q}\" is not known; use \"wall_displacement\", \
                 \"max_grain_speed\" or \"mean_liquid_speed\""
            ),
        }
        if w.crosses.is_empty() || w.crosses.iter().any(|c| !c.is_finite()) {
            bail!(
                "[output] {what}: when crosses = {:?}: give one or more finite values",
                w.crosses
            );
        }
    }
    if let Some(s) = t.wall_seconds
        && !(s > 0.0 && s.is_finite())
    {
        bail!("[output] {what}: wall_seconds = {s} must be a positive number of seconds");
    }
    Ok(())
}
