//! Stage `analyse` (`lbdem analyse PARAMS.toml --out DIR`): what Su et al. (2020) measure on a
//! simulation, from the files a run wrote (`run = "DIR"` or the name of an earlier `simulate`
//! stage):
//!
//! - strain by triangulation between the reference grains and every particle snapshot
//!   (Sect. 2.5): ε_xx + ε_yy, ε_xy and the rotation on the √10 d̄ REV, as maps (Figs. 8, 9) and
//!   REV-tile tables, in mean grain diameters from the push-plate;
//! - ε_vol^DEM of Eq. 18 from each snapshot's membrane polygon minus the plate's penetration,
//!   beside the run's own series and the mesh's ln J;
//! - the liquid pressure change field (Eq. 19, Fig. 10) with the cells below Δp_c marked; the
//!   first crossing of Δp_c (u_y,min) and its site relative to the plate's corners (Sect. 3.5);
//! - the inertial number (Eq. 20) and the dynamic-dilatancy prediction (Eq. 21); the inertial
//!   number over the shear per output and as Su's one number per run (`inertial.rs`);
//! - the net class by the rule of `lbdem_analysis::mechanism` (suspension, contraction,
//!   dilation, cracking), and the packed-zone fraction over time when the run has one (Fig. 5h).
//!
//! Writes `analysis.json` for the `compare`, `mechanism-map` and `matrix` stages.

use super::run_data::{self, Run};
use super::strain_fields::{Setup, StrainOptions, pressure_on_grid};
use crate::contract::{Stage, StageContext, StageOutput, Table};
use crate::report::table::{self, Col};
use anyhow::{Context, Result, bail};
use lbdem_analysis::P2;
use lbdem_analysis::cracking::{self, DP_C};
use lbdem_analysis::mechanism::{Class, DynamicDilatancy, Evidence, classify};
use lbdem_analysis::network::{near_pairs, network};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::{Path, PathBuf};

mod figures;
mod frames;
mod inertial;
mod packed;

use figures::{draw_maps, series_figures};
use frames::median;
pub use frames::{eq18, frame_of, packing_fraction, plate_shapes, reference, solid_fraction};

/// Which grains the strain is measured from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ReferenceState {
    /// The state the run started from: the scene's particle file when it holds the same clumps,
    /// else the first particle snapshot.
    #[default]
    Initial,
    /// The first particle snapshot.
    FirstSnapshot,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// The run: an earlier `simulate` stage's name, or its output directory.
    pub run: String,
    /// The run's scene file, when it moved since the run (default: the one its manifest names).
    #[serde(default)]
    pub scene: Option<PathBuf>,
    /// A name for the run in figures and on the mechanism map (default: the scene's name).
    #[serde(default)]
    pub label: Option<String>,
    #[serde(default)]
    pub reference: ReferenceState,
    #[serde(default, flatten)]
    pub strain: StrainOptions,
    /// Mean grain diameter (m); default: the mean equivalent-area diameter of the reference's
    /// non-membrane grains.
    #[serde(default)]
    pub d_bar: Option<f64>,
    /// Field of view [x0, x1, y0, y1] in d̄ from the middle of the plate's face (default: all
    /// reference grains).
    #[serde(default)]
    pub fov: Option<[f64; 4]>,
    /// Δp_c (Pa): Su et al. 2020 Sect. 3.5 take −0.03 Pa.
    #[serde(default = "dp_c")]
    pub pressure_threshold: f64,
    /// A cluster spans the sample when it comes within this many d̄ of the lowest and highest
    /// grain edges.
    #[serde(default = "one")]
    pub percolation_reach_d: f64,
    /// Two grains belong to one network when their circles are closer than this many d̄ (in a
    /// liquid, grains bear load without overlapping, so the contact list undercounts it).
    #[serde(default = "touch_gap")]
    pub touch_gap_d: f64,
    /// The g_S⁰ this run stands for on the mechanism map (e.g. 0.5 for Simulations I-III, made
    /// from the 50 % datasets); default: its measured initial 2D packing fraction.
    #[serde(default)]
    pub g_s0: Option<f64>,
    /// Eq. 21's constants (Su's ref. [120]: 0.81 and 0.3).
    #[serde(default = "dilatancy")]
    pub dilatancy: Dilatancy,
    /// Draw maps for at most this many snapshots (the last ones); tables cover all.
    #[serde(default = "three")]
    pub max_maps: usize,
    /// A Float run's packed zone by displacement: grains that moved less than
    /// `packed_moved_less_than` (m) in `packed_window` (s) are still (Su Sect. 3.2: 2 µm in 10 s).
    #[serde(default = "ten")]
    pub packed_window: f64,
    #[serde(default = "two_um")]
    pub packed_moved_less_than: f64,
}

#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dilatancy {
    pub f_max: f64,
    pub a: f64,
}

fn dilatancy() -> Dilatancy {
    let d = DynamicDilatancy::default();
    Dilatancy {
        f_max: d.f_max,
        a: d.a,
    }
}
fn dp_c() -> f64 {
    DP_C
}
fn one() -> f64 {
    1.0
}
fn touch_gap() -> f64 {
    0.05
}
fn ten() -> f64 {
    10.0
}
fn two_um() -> f64 {
    2.0e-6
}
fn three() -> usize {
    3
}

pub struct Analyse;

/// The file the downstream stages read.
pub const ANALYSIS: &str = "analysis.json";

impl Stage for Analyse {
    const KIND: &'static str = "analyse";
    const ABOUT: &'static str =
        "Strain by triangulation, Eq. 18, Δp and cracking, inertial number and net class of a run";
    type Params = Params;
    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = run_data::manifest_input(&p.run, ctx).into_iter().collect();
        v.extend(p.scene.as_ref().map(|s| ctx.resolve(s)));
        v
    }
    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        let run = Run::open(
            &run_data::locate(&p.run, ctx),
            p.scene.as_ref().map(|s| ctx.resolve(s)).as_deref(),
        )?;
        analyse(p, &run, ctx)
    }
}

#[allow(clippy::too_many_lines)]
fn analyse(p: &Params, run: &Run, ctx: &StageContext) -> Result<StageOutput> {
    if !(p.pressure_threshold.is_finite() && p.percolation_reach_d > 0.0 && p.touch_gap_d >= 0.0) {
        bail!(
            "parameters 'pressure_threshold' = {} (Pa) must be finite, 'percolation_reach_d' = {} positive and \
             'touch_gap_d' = {} not negative",
            p.pressure_threshold,
            p.percolation_reach_d,
            p.touch_gap_d
        );
    }
    let out = &ctx.out_dir;
    // A run with one particle snapshot and no initial file has no strain to measure; its series
    // (Eq. 18, Δp, the packed zone of Fig. 5h) are still analysed.
    let mut notes: Vec<String> = Vec::new();
    let (reference, ref_step, steps) = match (reference(run, p.reference), run.particle_steps().as_slice()) {
        (Ok(r), _) => r,
        (Err(_), [only]) => {
            notes.push(format!(
                "one particle snapshot (step {only}) and no initial particle file with the same grains: no strain by \
                 triangulation; the series are analysed"
            ));
            (run.grains(*only)?, Some(*only), Vec::new())
        }
        (Err(e), _) => return Err(e),
    };
    let d_bar = match p.d_bar {
        Some(d) if d > 0.0 && d.is_finite() => d,
        Some(d) => bail!("parameter 'd_bar' = {d} m must be positive"),
        None => reference.d_bar(),
    };
    let frame = frame_of(run, &reference, d_bar);
    let setup = Setup::new(&reference, frame, p.fov, &p.strain)?;
    let label = p.label.clone().unwrap_or_else(|| run.scene.name.clone());
    let (mut files, mut figures, mut tables) = (Vec::<PathBuf>::new(), Vec::new(), Vec::new());
    let liquid = run.scene.physics == crate::scenes::schema::Physics::Coupled
        && run.scene.scene.coupling.as_ref().is_none_or(|c| c.liquid);

    // Per snapshot: strain fields, Eq. 18, pressure.
    let pb = ctx.progress_bar(steps.len() as u64, "analyse");
    let mut rows = SnapshotRows::default();
    let map_from = steps.len().saturating_sub(p.max_maps.max(1));
    let mut last_fields = None;
    let mut last_u = 0.0;
    for (k, &step) in steps.iter().enumerate() {
        let g = run.grains(step)?;
        if !g.same_grains(&reference) {
            bail!(
                "run {}: the particle snapshot at step {step} holds other grains than the reference \
                 ({} vs {} clumps); strain needs the same grains in both",
                run.dir.display(),
                g.len(),
                reference.len()
            );
        }
        let t = run.time_of(step);
        let u = run.plate_displacement(t);
        let f = setup.fields(&g)?;
        let dp = pressure_on_grid(run, step, &setup)?;
        let (area, e18) = eq18(run, &reference, &g, u).unwrap_or((f64::NAN, f64::NAN));
        rows.step.push(step);
        rows.time.push(t);
        rows.u_d.push(u / d_bar);
        rows.eq18_snapshot.push(e18);
        rows.sample_area.push(area);
        rows.eq18_series
            .push(run.series_at("eps_vol_dem", t).unwrap_or(f64::NAN));
        rows.mesh_ln_j.push(f.mesh_area_ratio.ln());
        rows.mean_eps_vol.push(f.mean.eps_vol());
        rows.mean_eps_xy.push(f.mean.eps_xy());
        rows.mean_rotation.push(f.mean.rotation());
        rows.rev_eps_vol_min.push(
            f.eps_vol
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .fold(f64::NAN, f64::min),
        );
        rows.rev_eps_vol_max.push(
            f.eps_vol
                .iter()
                .copied()
                .filter(|v| v.is_finite())
                .fold(f64::NAN, f64::max),
        );
        let (dpmin, below) = match &dp {
            Some(d) => (
                d.iter()
                    .copied()
                    .filter(|v| v.is_finite())
                    .fold(f64::NAN, f64::min),
                d.iter().filter(|&&v| v < p.pressure_threshold).count() as f64
                    * (setup.grid.dx * d_bar).powi(2),
            ),
            None => (f64::NAN, f64::NAN),
        };
        rows.dp_min.push(dpmin);
        rows.area_below.push(below);
        // REV tiles as a table, every snapshot.
        let tiles = |a: &ndarray::Array2<f64>| -> Result<Vec<f64>> {
            // The sliding REV map's values at tile centres (one value per REV).
            let side = setup.rev_side;
            let (th, tw) = (setup.grid.ny / side, setup.grid.nx / side);
            Ok((0..th * tw)
                .map(|q| a[[(q / tw) * side + side / 2, (q % tw) * side + side / 2]])
                .collect())
        };
        let side = setup.rev_side;
        let (th, tw) = (setup.grid.ny / side, setup.grid.nx / side);
        let centre = |q: usize| {
            setup
                .grid
                .centre((q / tw) * side + side / 2, (q % tw) * side + side / 2)
        };
        let xd: Vec<f64> = (0..th * tw).map(|q| centre(q)[0]).collect();
        let yd: Vec<f64> = (0..th * tw).map(|q| centre(q)[1]).collect();
        let name = format!("strain_{step:09}.csv");
        let (ev, exy, rot, ea) = (
            tiles(&f.eps_vol)?,
            tiles(&f.eps_xy)?,
            tiles(&f.rotation)?,
            tiles(&f.eps_area)?,
        );
        let dpt = match &dp {
            Some(d) => tiles(d)?,
            None => vec![f64::NAN; xd.len()],
        };
        table::write_table(
            &out.join(&name),
            &[
                ("x_d", Col::F64(&xd)),
                ("y_d", Col::F64(&yd)),
                ("eps_vol_tri", Col::F64(&ev)),
                ("eps_xy", Col::F64(&exy)),
                ("rotation", Col::F64(&rot)),
                ("eps_area", Col::F64(&ea)),
                ("dp", Col::F64(&dpt)),
            ],
        )?;
        files.push(name.clone().into());
        if k + 1 == steps.len() {
            tables.push(Table {
                path: name.into(),
                caption: format!(
                    "Strain by triangulation of snapshot {step} (u_y = {:.2} d̄) against the reference, at the \
                     centre of each √10 d̄ REV (one row per REV): ε_xx + ε_yy, ε_xy = γ_xy/2, rotation (rad), \
                     the area strain J − 1 (what Eq. 5 measures) and Δp (Pa) at the node there; x, y in d̄ from \
                     the middle of the plate's face.",
                    u / d_bar
                ),
            });
        }
        if k >= map_from {
            draw_maps(
                p,
                run,
                &setup,
                &f,
                dp.as_ref(),
                step,
                u,
                &label,
                out,
                &mut figures,
                &mut files,
            )?;
        }
        if k + 1 == steps.len() {
            // The last snapshot's REV maps, for the `matrix` stage's grids of runs.
            for (name, a) in [("eps_vol", &f.eps_vol), ("eps_xy", &f.eps_xy)] {
                let file = format!("last_{name}.tif");
                crate::io::tiff::write_f32(&out.join(&file), a.view())?;
                files.push(file.into());
            }
            if let Some(d) = &dp {
                crate::io::tiff::write_f32(&out.join("last_dp.tif"), d.view())?;
                files.push("last_dp.tif".into());
            }
            // The microstructure (Su Fig. 7): the grains' solid fraction per pixel, liquid 0.
            let gs = solid_fraction(&setup, &g);
            crate::io::tiff::write_f32(&out.join("last_gs.tif"), gs.view())?;
            files.push("last_gs.tif".into());
            last_u = u;
            last_fields = Some(f);
        }
        pb.inc(1);
    }
    pb.finish_and_clear();
    rows.write(out, "snapshots.csv")?;
    files.push("snapshots.csv".into());
    tables.push(Table {
        path: "snapshots.csv".into(),
        caption: "Per snapshot: plate displacement u_y (d̄); ε_vol^DEM by Eq. 18 from the snapshot's membrane \
                  polygon and from the run's series, and ln J of the triangulated region; the mesh's mean \
                  ε_xx + ε_yy, ε_xy and rotation; the extremes of the REV ε_xx + ε_yy map; Δp_min and the area \
                  below Δp_c on the grid."
            .into(),
    });

    // Series: cracking, inertial number, ε_vol^DEM over time.
    let series_u = run
        .series("plate_displacement")
        .map(|v| v.iter().map(|x| x / d_bar).collect::<Vec<_>>());
    let time = run.series("time").unwrap_or_default();
    let dp_min = run.series("dp_min");
    let crossing = match &dp_min {
        Some(d) if liquid => {
            let u = series_u.clone().unwrap_or_else(|| vec![f64::NAN; time.len()]);
            cracking::first_crossing(&time, &u, d, p.pressure_threshold)
        }
        _ => None,
    };
    let site = crossing.and_then(|c| crossing_site(run, c, d_bar, p.pressure_threshold));
    let inertial = run.series("inertial_number").map(|v| median(&v));
    // Over the shear, per output and Su's one number per run (`inertial.rs`).
    let inertial_shear = match (
        run.series("inertial_number"),
        run.series("mean_stress"),
        series_u.as_ref(),
    ) {
        (Some(i), Some(p), Some(u)) => inertial::summarise(
            &i,
            &p,
            u,
            run.series("settling").as_deref(),
            run.series("mass_scale").as_deref(),
        ),
        _ => None,
    };
    let eps_net = run
        .series("eps_vol_dem")
        .and_then(|v| v.last().copied())
        .or_else(|| rows.eq18_snapshot.last().copied())
        .unwrap_or(f64::NAN);

    // Percolation at the start: grains closer than touch_gap_d d̄ form the network.
    let circles: Vec<(usize, [f64; 3])> = reference
        .circles
        .iter()
        .enumerate()
        .flat_map(|(k, cs)| cs.iter().map(move |c| (k, *c)))
        .collect();
    let pairs = near_pairs(&circles, p.touch_gap_d * d_bar);
    let net = network(
        reference.len(),
        &reference.y_lo,
        &reference.y_hi,
        &pairs,
        p.percolation_reach_d * d_bar,
    );
    let evidence = Evidence {
        percolates: net.percolates,
        cracked: liquid.then_some(crossing.is_some()),
        eps_vol_net: eps_net,
    };
    // The four classes describe push-plate (shear-cell) runs.
    let class = run.plate.map(|_| classify(&evidence));
    let f0 = packing_fraction(&reference);
    let law = DynamicDilatancy {
        f_max: p.dilatancy.f_max,
        a: p.dilatancy.a,
    };
    let prediction = match (f0, inertial) {
        (Some(f), Some(i)) if i.is_finite() => Some(json!({
            "inertial_number_median": i,
            "critical_packing": law.critical(i),
            "initial_packing": f,
            "predicts": law.predicts(f, i),
            "agrees_with_run": run.plate.map(|_| law.agrees(f, i, eps_net)),
        })),
        _ => None,
    };
    series_figures(p, run, &rows, crossing, d_bar, out, &mut figures, &mut files)?;
    let packed_zone = packed::analyse(p, run, out, &mut figures, &mut files, &mut tables)?;

    let rate = run.plate.map(|pl| pl.velocity[0].hypot(pl.velocity[1]));
    let last = last_fields.as_ref();
    let summary = json!({
        "label": label,
        "run": run.dir,
        "scene": run.scene.path,
        "liquid": liquid,
        "d_bar_m": d_bar,
        "reference": match ref_step { Some(s) => format!("snapshot at step {s}"), None => "the scene's particle file (step 0)".into() },
        "snapshots": steps.len(),
        "packed_zone": packed_zone,
        "triangles": setup.mesh.len(),
        "rev_side_px": setup.rev_side,
        "pixel_d": setup.grid.dx,
        "fov_d": setup.extent(),
        "grid": setup.grid,
        "last_maps": { "eps_vol": "last_eps_vol.tif", "eps_xy": "last_eps_xy.tif", "dp": "last_dp.tif",
                       "gs": "last_gs.tif",
                       "u_y_m": last_u, "plate": run.plate.map(|pl| { let (l, r) = pl.corners(last_u);
                           [frame.from_scene(l), frame.from_scene(r)] }) },
        "plate_rate_m_s": rate,
        "plate_rate_um_s": rate.map(|r| r * 1e6),
        "u_y_final_d": rows.u_d.last(),
        "eps_vol_dem_final": eps_net,
        "eps_vol_dem_snapshot_final": rows.eq18_snapshot.last(),
        "mesh_ln_j_final": rows.mesh_ln_j.last(),
        "mean_eps_vol_tri_final": last.map(|f| f.mean.eps_vol()),
        "mean_eps_xy_final": last.map(|f| f.mean.eps_xy()),
        "initial_packing_fraction": f0,
        "g_s0": p.g_s0.or(f0),
        "network": net,
        "pressure_threshold_pa": p.pressure_threshold,
        "cracking": crossing.map(|c| json!({
            "time_s": c.time, "u_y_min_d": c.u_d, "u_y_before_d": c.u_d_before, "dp_pa": c.dp, "site": site,
        })),
        "dynamic_dilatancy": prediction,
        "inertial_number": inertial_shear,
        "class": class,
        "class_name": class.map(Class::name),
        "evidence": evidence,
        "warnings": notes.into_iter().chain(warnings(&rows, liquid, &crossing, site.is_none(), run.plate.is_some())).collect::<Vec<_>>(),
    });
    lbdem_core::atomic::write_atomic(&out.join(ANALYSIS), &serde_json::to_vec_pretty(&summary)?)
        .with_context(|| format!("cannot write {}", out.join(ANALYSIS).display()))?;
    files.push(ANALYSIS.into());
    Ok(StageOutput {
        summary,
        figures,
        tables,
        files,
    })
}

fn warnings(
    rows: &SnapshotRows,
    liquid: bool,
    crossing: &Option<cracking::Crossing>,
    no_site: bool,
    plate: bool,
) -> Vec<String> {
    let mut w = Vec::new();
    // Eq. 18 from the snapshots and from the series should agree where both exist.
    for k in 0..rows.step.len() {
        let (a, b) = (rows.eq18_snapshot[k], rows.eq18_series[k]);
        if a.is_finite() && b.is_finite() && (a - b).abs() > 1e-3 + 0.05 * b.abs() {
            w.push(format!(
                "step {}: ε_vol^DEM from the snapshot's membrane polygon ({a:.4e}) and from the series ({b:.4e}) \
                 differ; the series is sampled at other times or the membrane ring changed order",
                rows.step[k]
            ));
            break;
        }
    }
    if liquid && crossing.is_some() && no_site && plate {
        w.push(
            "the first Δp < Δp_c crossing has no site: the run recorded no dp_min_x/dp_min_y and no fluid snapshot \
             follows the crossing"
                .into(),
        );
    }
    w
}

/// Where the first crossing happened: the series' location of Δp_min at that row when the run
/// recorded it, else the lowest node of the first fluid snapshot at or after it.
fn crossing_site(run: &Run, c: cracking::Crossing, d_bar: f64, threshold: f64) -> Option<serde_json::Value> {
    let pl = run.plate?;
    let u = run.plate_displacement(c.time);
    let (l, r) = pl.corners(u);
    let from_series = run
        .series("dp_min_x")
        .zip(run.series("dp_min_y"))
        .and_then(|(x, y)| Some([*x.get(c.index)?, *y.get(c.index)?]))
        .filter(|p| p[0].is_finite() && p[1].is_finite());
    let (at, source): (P2, &str) = match from_series {
        Some(p) => (p, "series dp_min_x, dp_min_y"),
        None => {
            let step = run
                .snapshots
                .iter()
                .filter(|s| s.kind == "fluid" && s.time >= c.time)
                .map(|s| s.step)
                .min()?;
            let path = run.file("fluid", step)?;
            let df = crate::report::table::read_table(&path).ok()?;
            let col = |n: &str| crate::report::table::f64_column(&df, n, &path).ok();
            let (x, y, pr) = (col("x")?, col("y")?, col("pressure")?);
            let k = (0..pr.len())
                .filter(|&k| pr[k] < threshold)
                .min_by(|&a, &b| pr[a].total_cmp(&pr[b]))?;
            (
                [x[k], y[k]],
                "lowest node of the first fluid snapshot after the crossing",
            )
        }
    };
    let s = cracking::site(at, l, r, d_bar);
    Some(json!({"x_m": at[0], "y_m": at[1], "relative": s, "source": source}))
}

#[derive(Default)]
pub(super) struct SnapshotRows {
    step: Vec<u64>,
    time: Vec<f64>,
    u_d: Vec<f64>,
    eq18_snapshot: Vec<f64>,
    eq18_series: Vec<f64>,
    sample_area: Vec<f64>,
    mesh_ln_j: Vec<f64>,
    mean_eps_vol: Vec<f64>,
    mean_eps_xy: Vec<f64>,
    mean_rotation: Vec<f64>,
    rev_eps_vol_min: Vec<f64>,
    rev_eps_vol_max: Vec<f64>,
    dp_min: Vec<f64>,
    area_below: Vec<f64>,
}

impl SnapshotRows {
    fn write(&self, out: &Path, name: &str) -> Result<()> {
        table::write_table(
            &out.join(name),
            &[
                ("step", Col::U64(&self.step)),
                ("time", Col::F64(&self.time)),
                ("u_y_d", Col::F64(&self.u_d)),
                ("eps_vol_dem_snapshot", Col::F64(&self.eq18_snapshot)),
                ("eps_vol_dem_series", Col::F64(&self.eq18_series)),
                ("sample_area", Col::F64(&self.sample_area)),
                ("mesh_ln_j", Col::F64(&self.mesh_ln_j)),
                ("mean_eps_vol_tri", Col::F64(&self.mean_eps_vol)),
                ("mean_eps_xy", Col::F64(&self.mean_eps_xy)),
                ("mean_rotation", Col::F64(&self.mean_rotation)),
                ("rev_eps_vol_min", Col::F64(&self.rev_eps_vol_min)),
                ("rev_eps_vol_max", Col::F64(&self.rev_eps_vol_max)),
                ("dp_min", Col::F64(&self.dp_min)),
                ("area_below_threshold", Col::F64(&self.area_below)),
            ],
        )
    }
}
