//! Stage `assemble`: the starting assembly of a Su et al. 2020 shear-cell case (Sect. 2.4).
//! Grains from the 20 templates (Table 2's sizes, or `lbdem digitise`'s `templates.csv`) are
//! inserted at random, or a digitised microstructure is taken where it lies; four servo walls
//! compress them isotropically to a 2D stress (Su: 500 N/m, k_n = 1e4 N/m); the compressed
//! assembly is fitted to the sample's box (7.5 × 10 mm) and brought to the target packing
//! fraction (%PK) by scaling the grains, deleting grains or adding small grains in interstices;
//! it relaxes inside the sample's walls until every grain is slower than 1e-7 m/s; then the
//! walls give way to the run's bonded membrane and push-plate, and F_0 (Table 1: the mean
//! contact force before deformation) is measured under the run's elastic law. In Su's order
//! (`[relax] inside = "membrane"`) the membrane goes on first, the grains relax inside it under
//! the run's law, and the %PK is reached in the relaxed membrane.
//!
//! Writes `assembly.csv` (grain_id,x,y,r per circle, m) with `assembly.json` (the header a scene
//! checks: grain set, packing fraction, sizes, F_0), `templates.csv` and `assembly.png`. Long
//! runs checkpoint and continue with `--resume` to the same bits. User guide: docs/su2020.md.

mod protocol;
mod templates;
#[cfg(test)]
mod tests;

use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::report::table::{Col, write_table};
use anyhow::{Context, Result, bail};
use lbdem_dem::Law;
use lbdem_dem::assembly::PackingMethod;
use lbdem_dem::contact::LinearSpringDashpot;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

pub use protocol::Record;

/// The recipe of an assembly (`lbdem assemble RECIPE.toml --out DIR`).
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// The run's scene: its density, `[[walls]]` (the push-plate), `[membrane]` and `[bonds]`
    /// are put on the assembly, and F_0 is measured with its `[contact]` law.
    pub scene: PathBuf,
    pub grains: GrainsParams,
    pub sample: SampleParams,
    #[serde(default)]
    pub compress: CompressParams,
    pub packing: PackingParams,
    #[serde(default)]
    pub relax: RelaxParams,
    /// rayon threads (0 = all); the assembly does not depend on it. (Run control, like the two
    /// below: not part of the recipe, its cache key or the header.)
    #[serde(default, skip_serializing)]
    pub threads: usize,
    /// Checkpoint every this many seconds of wall time.
    #[serde(default = "d_checkpoint", skip_serializing)]
    pub checkpoint_seconds: f64,
    /// Stop with a checkpoint after this many seconds of wall time (continue with `--resume`).
    #[serde(default, skip_serializing)]
    pub wall_clock: Option<f64>,
}

/// Where the grains come from: `count` grains of Table 2's sizes `d` (or of a digitised
/// `templates` file), or a digitised `microstructure` taken as it lies.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GrainsParams {
    /// Grains to insert (Su Table 2, N^DEM).
    #[serde(default)]
    pub count: Option<usize>,
    /// [d_min, d̄, d_max] equivalent diameters, m (Su Table 2).
    #[serde(default)]
    pub d: Option<[f64; 3]>,
    /// Range of the templates' aspect ratios (not in the paper; 1 to 1.6 by default).
    #[serde(default = "d_aspect")]
    pub aspect: [f64; 2],
    /// Number of templates (Su: 20).
    #[serde(default = "d_n_templates")]
    pub n_templates: usize,
    /// Templates less elongated than this are one circle (as the digitiser's `round_aspect`).
    #[serde(default = "d_round")]
    pub round_aspect: f64,
    /// `templates.csv` of `lbdem digitise` (scaled to d̄ when `d` is given).
    #[serde(default)]
    pub templates: Option<PathBuf>,
    /// `particles.csv` of `lbdem digitise`: the digitised grains where they lie.
    #[serde(default)]
    pub microstructure: Option<PathBuf>,
    /// Seed of the insertion (and of deleting or adding grains).
    #[serde(default = "d_seed")]
    pub seed: u64,
    /// Packing fraction of the random insertion, in a box of the sample's shape.
    #[serde(default = "d_insert")]
    pub insert_packing: f64,
}

/// The sample's box (Su Fig. 1a: 7.5 × 10 mm), m.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SampleParams {
    pub lo: [f64; 2],
    pub hi: [f64; 2],
}

/// The isotropic servo compression (Su Sect. 2.4).
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompressParams {
    /// The law during compression (Su: "initial k_n = 1e4 N/m").
    #[serde(default = "d_compress_law")]
    pub contact: Law,
    /// Target 2D stress on the four walls, N/m (Su: 500).
    #[serde(default = "d_stress")]
    pub target_stress: f64,
    /// Fraction of the stress error the servo closes per step.
    #[serde(default = "d_alpha")]
    pub alpha: f64,
    /// Fastest wall speed, in mean grain diameters per critical time step.
    #[serde(default = "d_v_max")]
    pub v_max: f64,
    /// Settled when every wall is within this relative error of the target stress...
    #[serde(default = "d_tol")]
    pub tolerance: f64,
    /// ...and every grain is slower than this, in mean diameters per critical time step.
    #[serde(default = "d_settle")]
    pub settle_speed: f64,
    /// Grain masses times this during compression (quasi-static: the geometry is what is kept).
    #[serde(default = "d_mass_scale")]
    pub mass_scale: f64,
    /// Time step as a fraction of the critical one.
    #[serde(default = "d_dt_factor")]
    pub dt_factor: f64,
    /// Local (Cundall) damping during compression.
    #[serde(default = "d_local_damping")]
    pub local_damping: f64,
    #[serde(default = "d_max_steps")]
    pub max_steps: u64,
}

impl Default for CompressParams {
    fn default() -> Self {
        Self {
            contact: d_compress_law(),
            target_stress: d_stress(),
            alpha: d_alpha(),
            v_max: d_v_max(),
            tolerance: d_tol(),
            settle_speed: d_settle(),
            mass_scale: d_mass_scale(),
            dt_factor: d_dt_factor(),
            local_damping: d_local_damping(),
            max_steps: d_max_steps(),
        }
    }
}

/// The target packing fraction (Su's %PK / 100) and how it is reached.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PackingParams {
    pub target: f64,
    #[serde(default)]
    pub method: PackingMethod,
    /// `auto`: the largest size scaling before grains are deleted or added.
    #[serde(default = "d_max_change")]
    pub max_size_change: f64,
    /// Size of an added grain relative to the smallest template (Su: "smaller grains").
    #[serde(default = "d_small")]
    pub small_grain: f64,
}

/// The relaxation until every grain is at rest (Su Sect. 2.4): inside the sample's walls with
/// the compression's law and step, or inside the membrane under the run's (`inside`).
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RelaxParams {
    /// Done when every grain is slower than this, m/s (Su: 1e-7).
    #[serde(default = "d_threshold")]
    pub threshold: f64,
    #[serde(default = "d_max_steps")]
    pub max_steps: u64,
    /// Local (Cundall) damping while relaxing (default 0: against the push-plate's and the
    /// bonds' static forces it switches sign with the velocity every step and kept the reduced
    /// assembly vibrating at 1e-2 m/s; the viscous damping below settles it).
    #[serde(default)]
    pub local_damping: f64,
    /// Viscous damping rate γ (1/s; F −= γ m v) while relaxing; default 1e-3 per step (1e-3/dt).
    /// Local damping stops grains that push on something; a grain left free keeps its speed
    /// until it hits a neighbour, and this stops it.
    #[serde(default)]
    pub viscous_damping: Option<f64>,
    /// Where the assembly relaxes (`"walls"` by default).
    #[serde(default, skip_serializing_if = "Inside::is_walls")]
    pub inside: Inside,
}

/// Where the assembly relaxes before the run (Su Sect. 2.4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Inside {
    /// Inside the sample's walls, with the compression's law and step, the target packing
    /// fraction reached before and the membrane put on after (the sample then starts with an
    /// unstressed membrane and the contact forces the target left).
    #[default]
    Walls,
    /// Su's order: the membrane and push-plate put on the compressed sample, relaxation under
    /// the run's law and step until every grain is slower than `threshold`, then the target
    /// packing fraction reached inside the relaxed membrane (its area as it is then).
    Membrane,
}

impl Inside {
    fn is_walls(&self) -> bool {
        *self == Inside::Walls
    }
}

impl Default for RelaxParams {
    fn default() -> Self {
        Self {
            threshold: d_threshold(),
            max_steps: d_max_steps(),
            local_damping: 0.0,
            viscous_damping: None,
            inside: Inside::Walls,
        }
    }
}

fn d_checkpoint() -> f64 {
    600.0
}
fn d_aspect() -> [f64; 2] {
    [1.0, 1.6]
}
fn d_n_templates() -> usize {
    20
}
fn d_round() -> f64 {
    1.1
}
fn d_seed() -> u64 {
    1
}
fn d_insert() -> f64 {
    0.45
}
fn d_compress_law() -> Law {
    // Su Sect. 2.4: k_n = 1e4 N/m; kappa = 2 and mu = 0.05 as Table 1.
    let mut l = LinearSpringDashpot::new(1.0e4, 5.0e3, lbdem_dem::Damping::Ratio(0.5), 0.05);
    l.rolling = None;
    Law::Linear(l)
}
fn d_stress() -> f64 {
    500.0
}
fn d_alpha() -> f64 {
    // The wall's measured stress includes the contacts' dashpots, which answer the wall's own
    // speed at once: a larger gain makes the walls chatter at v_max (seen at 0.2 and 0.02).
    0.005
}
fn d_v_max() -> f64 {
    0.001
}
fn d_tol() -> f64 {
    0.02
}
fn d_settle() -> f64 {
    1e-4
}
fn d_mass_scale() -> f64 {
    1.0
}
fn d_dt_factor() -> f64 {
    // sqrt(m_min/k_max) counts one contact; a two-circle grain in a dense packing has up to
    // eight, with lever arms, and damping lowers Verlet's limit further: at 0.2 the compressed
    // reduced assembly heated up to 0.6 m/s, at 0.05 and 0.1 it stayed below 1e-8 m/s.
    0.1
}
fn d_local_damping() -> f64 {
    0.7
}
fn d_max_steps() -> u64 {
    2_000_000
}
fn d_max_change() -> f64 {
    0.03
}
fn d_small() -> f64 {
    0.5
}
fn d_threshold() -> f64 {
    1e-7
}

pub struct Assemble;

impl Stage for Assemble {
    const KIND: &'static str = "assemble";
    const ABOUT: &'static str = "build a shear-cell assembly (Su 2020 Sect. 2.4): insert, servo-compress, reach %PK, relax, membrane; measures F_0";
    const RESUMABLE: bool = true;
    type Params = Params;

    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        let scene = ctx.resolve(&p.scene);
        let mut v = vec![scene.clone()];
        if let Ok(l) = crate::scenes::schema::load(&scene, &Default::default()) {
            v.extend(l.sources.iter().skip(1).cloned());
        }
        v.extend(p.grains.templates.iter().map(|t| ctx.resolve(t)));
        v.extend(p.grains.microstructure.iter().map(|t| ctx.resolve(t)));
        v
    }

    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        check(p)?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(p.threads)
            .build()
            .context("cannot start the worker threads")?;
        let done = pool.install(|| protocol::run(p, ctx))?;
        write_outputs(p, ctx, done)
    }
}

/// Refuse what cannot work before anything runs, naming the key, the value and the fix.
fn check(p: &Params) -> Result<()> {
    let g = &p.grains;
    match (&g.microstructure, g.count) {
        (Some(_), Some(_)) => bail!(
            "[grains]: count is for inserted grains; a microstructure brings its own grains — remove one of them"
        ),
        (None, None) => bail!("[grains]: give count (Su Table 2, N^DEM) and d, or a microstructure file"),
        (None, Some(0)) => bail!("[grains] count = 0: give the number of grains (Su Table 2, N^DEM)"),
        _ => {}
    }
    if g.microstructure.is_none() && g.templates.is_none() && g.d.is_none() {
        bail!("[grains]: give d = [d_min, d_mean, d_max] (Su Table 2) or templates = \"templates.csv\"");
    }
    if g.microstructure.is_some() && g.templates.is_some() {
        bail!("[grains]: give templates or microstructure, not both");
    }
    if !(g.insert_packing > 0.05 && g.insert_packing < 0.7) {
        bail!(
            "[grains] insert_packing = {}: random insertion works between 0.05 and 0.7 (default 0.45)",
            g.insert_packing
        );
    }
    let [x0, y0] = p.sample.lo;
    let [x1, y1] = p.sample.hi;
    if !(x1 > x0 && y1 > y0 && [x0, y0, x1, y1].iter().all(|v| v.is_finite())) {
        bail!(
            "[sample] lo = {:?}, hi = {:?}: hi must exceed lo on both axes (m)",
            p.sample.lo,
            p.sample.hi
        );
    }
    let c = &p.compress;
    for (name, v) in [
        ("target_stress", c.target_stress),
        ("alpha", c.alpha),
        ("v_max", c.v_max),
        ("tolerance", c.tolerance),
        ("settle_speed", c.settle_speed),
        ("mass_scale", c.mass_scale),
        ("dt_factor", c.dt_factor),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            bail!("[compress] {name} = {v}: must be positive and finite");
        }
    }
    if c.dt_factor > 1.0 {
        bail!(
            "[compress] dt_factor = {}: the step would exceed the critical one; give at most 1 (default 0.2)",
            c.dt_factor
        );
    }
    if !(0.0..1.0).contains(&c.local_damping) || !(0.0..1.0).contains(&p.relax.local_damping) {
        bail!("local_damping must lie in [0, 1) (Cundall's alpha; 0.7 is PFC's default)");
    }
    let k = &p.packing;
    if !(k.target > 0.0 && k.target < 1.0) {
        bail!(
            "[packing] target = {}: a packing fraction in (0, 1), e.g. 0.81 for 81 %PK",
            k.target
        );
    }
    if !(k.max_size_change >= 0.0 && k.max_size_change < 0.5 && k.small_grain > 0.0 && k.small_grain <= 1.0) {
        bail!("[packing] max_size_change must lie in [0, 0.5) and small_grain in (0, 1]");
    }
    let r = &p.relax;
    if !(r.threshold > 0.0 && r.threshold.is_finite()) {
        bail!(
            "[relax] threshold = {}: a positive speed in m/s (Su: 1e-7)",
            r.threshold
        );
    }
    if let Some(g) = r.viscous_damping
        && !(g >= 0.0 && g.is_finite())
    {
        bail!("[relax] viscous_damping = {g}: a non-negative rate in 1/s");
    }
    if p.checkpoint_seconds.is_nan() || p.checkpoint_seconds <= 0.0 {
        bail!("checkpoint_seconds = {}: must be positive", p.checkpoint_seconds);
    }
    Ok(())
}

fn write_outputs(p: &Params, ctx: &StageContext, done: protocol::Done) -> Result<StageOutput> {
    use crate::scenes::build::assembly_file::{AssemblyHeader, FORMAT, GrainSet};
    let dir = &ctx.out_dir;
    let sys = &done.sys;
    let b = &sys.bodies;
    let (mut gid, mut x, mut y, mut r) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for k in 0..b.len() {
        for c in b.circle_start[k]..b.circle_start[k + 1] {
            let q = b.circle_pos(c);
            gid.push(k as u64);
            x.push(q.x);
            y.push(q.y);
            r.push(b.circle_r[c]);
        }
    }
    write_table(
        &dir.join("assembly.csv"),
        &[
            ("grain_id", Col::U64(&gid)),
            ("x", Col::F64(&x)),
            ("y", Col::F64(&y)),
            ("r", Col::F64(&r)),
        ],
    )?;
    let stats = lbdem_dem::assembly::size_stats(b);
    let header = AssemblyHeader {
        format: FORMAT.into(),
        units: "m".into(),
        grain_set: GrainSet {
            count: done.record.requested,
            d: p.grains.d,
            source: done.record.source.clone(),
        },
        grains: b.len(),
        circles: b.n_circles(),
        sample: [p.sample.lo[0], p.sample.lo[1], p.sample.hi[0], p.sample.hi[1]],
        packing_fraction: done.record.packing_fraction,
        d_min: stats.d_min,
        d_mean: stats.d_mean,
        d_max: stats.d_max,
        f_0: done.record.f_0,
        contacts: done.record.contacts,
        membrane_grains: done.record.membrane_grains,
        recipe: serde_json::to_value(p)?,
    };
    lbdem_core::atomic::write_atomic(&dir.join("assembly.json"), &serde_json::to_vec_pretty(&header)?)?;
    let t = &done.templates;
    let ids: Vec<u64> = (1..=t.len() as u64).collect();
    let cols = |f: &dyn Fn(&templates::Template) -> f64| t.iter().map(f).collect::<Vec<f64>>();
    let (w, d, a, nc) = (
        cols(&|t| t.weight),
        cols(&|t| t.d_eq),
        cols(&|t| t.aspect),
        cols(&|t| t.shape.balls.len() as f64),
    );
    let rr = cols(&|t| t.shape.balls[0].r);
    let off = cols(&|t| t.shape.balls.last().map_or(0.0, |b| b.centre.x.abs()));
    write_table(
        &dir.join("templates.csv"),
        &[
            ("template_id", Col::U64(&ids)),
            ("weight", Col::F64(&w)),
            ("d_eq_m", Col::F64(&d)),
            ("aspect_ratio", Col::F64(&a)),
            ("r_m", Col::F64(&rr)),
            ("offset_m", Col::F64(&off)),
            ("n_circles", Col::F64(&nc)),
        ],
    )?;
    let discs: Vec<crate::report::plot::Disc> = (0..b.n_circles())
        .map(|c| {
            let q = b.circle_pos(c);
            crate::report::plot::Disc {
                x: q.x,
                y: q.y,
                r: b.circle_r[c],
                class: b.tag[b.circle_body[c] as usize].min(1) as usize,
            }
        })
        .collect();
    let margin = 0.05 * (p.sample.hi[0] - p.sample.lo[0]);
    crate::report::plot::grains_png(
        &dir.join("assembly.png"),
        &discs,
        (p.sample.lo[0] - margin, p.sample.lo[1] - margin),
        (p.sample.hi[0] + margin, p.sample.hi[1] + margin),
        &format!(
            "{} grains, packing {:.1} %, d = {:.0}:{:.0}:{:.0} um, F_0 = {:.2e} N",
            b.len(),
            100.0 * done.record.packing_fraction,
            stats.d_min * 1e6,
            stats.d_mean * 1e6,
            stats.d_max * 1e6,
            done.record.f_0
        ),
    )?;
    let summary = serde_json::json!({
        "grains": b.len(),
        "circles": b.n_circles(),
        "packing_fraction": done.record.packing_fraction,
        "d_min_m": stats.d_min,
        "d_mean_m": stats.d_mean,
        "d_max_m": stats.d_max,
        "d_table_m": p.grains.d,
        "f_0_n": done.record.f_0,
        "contacts": done.record.contacts,
        "membrane_grains": done.record.membrane_grains,
        "record": done.record,
    });
    Ok(StageOutput {
        summary,
        figures: vec![Figure {
            path: "assembly.png".into(),
            caption: format!(
                "The assembly as the run starts (Su et al. 2020 Fig. 1b): {} grains in the {:.1} × {:.1} mm sample, \
                 packing fraction {:.3}, membrane grains red; made from {}.",
                b.len(),
                (p.sample.hi[0] - p.sample.lo[0]) * 1e3,
                (p.sample.hi[1] - p.sample.lo[1]) * 1e3,
                done.record.packing_fraction,
                done.record.source
            ),
        }],
        tables: vec![
            Table {
                path: "assembly.csv".into(),
                caption: "The assembly: one row per circle (grain_id, x, y, r in m); assembly.json beside it is \
                          the header a scene checks."
                    .into(),
            },
            Table {
                path: "templates.csv".into(),
                caption: "The grain templates the assembly was made of (equivalent diameter, aspect ratio, two-circle shape)."
                    .into(),
            },
        ],
        files: vec![
            "assembly.csv".into(),
            "assembly.json".into(),
            "templates.csv".into(),
            "assembly.png".into(),
        ],
    })
}
