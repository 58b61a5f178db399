//! Stage `compare` (`lbdem compare PARAMS.toml --out DIR`): a radiograph stack beside a
//! simulation run, as Su et al. (2020) Figs. 6-10 set experiments beside simulations.
//!
//! The experiment side is the output of a `radiograph` stage (any stack it reads: real beamtime
//! frames, `synth-radiograph`, or `synth-run` renderings of a run): its ε_vol maps (Eq. 5, XIP).
//! The simulation side is the run's strain by triangulation (TRI) painted on the radiograph's
//! own pixel grid and averaged by the same √10 d̄ REV. Both are aligned on the push-plate: x, y in
//! mean grain diameters of each side from the middle of the plate's face before it moves
//! (`plate_px` gives the face in the radiograph: its corners' columns and its row; `synth-run`
//! writes it in `fov.json`, which is read when `plate_px` is not given).
//!
//! Out: Fig. 6-style profiles (red ROI averaged along y, blue ROI along x), Figs. 8-10-style
//! panels (ε_vol XIP and TRI on one colour scale, ε_xy, Δp with Δp < Δp_c marked), the
//! difference XIP − TRI over the frames, and an agreement table (RMS of the map and profile
//! differences, correlation, whether the net behaviours have the same sign).

use super::analyse::{ReferenceState, eq18, frame_of, plate_shapes, reference};
use super::run_data::{self, Run};
use super::strain_fields::{Fields, Setup, StrainOptions, pressure_on_grid};
use crate::contract::{Figure, MANIFEST, Stage, StageContext, StageOutput, StageRecord, Table};
use crate::io::tiff as tio;
use crate::report::lines::{Line, LinesPlot, Reference, Style, lines_png};
use crate::report::panels::{Panel, PanelGrid, Shape, panels_png};
use crate::report::plot::Colormap;
use crate::report::table::{self, Col};
use anyhow::{Context, Result, bail};
use lbdem_analysis::cracking::DP_C;
use lbdem_analysis::raster::Grid;
use ndarray::Array2;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// The radiograph side: an earlier `radiograph` stage's name, or its output directory.
    pub radiograph: String,
    /// The simulation: an earlier `simulate` stage's name, or its output directory.
    pub run: String,
    #[serde(default)]
    pub scene: Option<PathBuf>,
    /// The push-plate's face in the radiograph's frame 0 (px): [column of its left corner,
    /// column of its right corner, row of its face]; the plate moves up (towards row 0).
    #[serde(default)]
    pub plate_px: Option<[f64; 3]>,
    /// Mean grain diameter of the radiographed sample (m); default: the radiograph stage's d_bar.
    #[serde(default)]
    pub d_bar_radiograph: Option<f64>,
    /// Mean grain diameter of the run (m); default: its grains' mean equivalent diameter.
    #[serde(default)]
    pub d_bar_run: Option<f64>,
    /// Pairs [radiograph frame, run particle-snapshot step] to compare; default: the frames'
    /// steps from `fov.json`, else the last frame with the last snapshot.
    #[serde(default)]
    pub pairs: Option<Vec<[u64; 2]>>,
    #[serde(default)]
    pub reference: ReferenceState,
    #[serde(default = "d::max_edge")]
    pub max_edge_d: f64,
    /// Red ROI of Fig. 6 [x0, x1, y0, y1] (d̄), averaged along y: the profile across the
    /// parting planes above the plate.
    #[serde(default = "d::red")]
    pub red_roi: [f64; 4],
    /// Blue ROI [x0, x1, y0, y1] (d̄), averaged along x: the profile ahead of the plate.
    #[serde(default = "d::blue")]
    pub blue_roi: [f64; 4],
    #[serde(default = "d::dp_c")]
    pub pressure_threshold: f64,
    /// The experiment's net class if known (e.g. from the paper), else the sign of its mean ε_vol.
    #[serde(default)]
    pub experiment_label: Option<String>,
    /// The radiograph's field of view [x, y, w, h] (px): only these pixels are compared (default:
    /// `fov.json`'s rows when the frames come from `synth-run`, else the whole image).
    #[serde(default)]
    pub fov_px: Option<[usize; 4]>,
}

mod d {
    pub fn max_edge() -> f64 {
        super::super::strain_fields::d::max_edge()
    }
    pub fn red() -> [f64; 4] {
        [-8.0, 8.0, 2.0, 6.0]
    }
    pub fn blue() -> [f64; 4] {
        [-1.5, 1.5, 0.0, 16.0]
    }
    pub fn dp_c() -> f64 {
        lbdem_analysis::cracking::DP_C
    }
}

pub struct Compare;

impl Stage for Compare {
    const KIND: &'static str = "compare";
    const ABOUT: &'static str =
        "A radiograph stack beside a simulation run: XIP vs TRI profiles, fields, Δp and agreement";
    type Params = Params;
    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = [&p.radiograph, &p.run]
            .into_iter()
            .filter_map(|s| run_data::manifest_input(s, ctx))
            .collect();
        v.extend(p.scene.as_ref().map(|s| ctx.resolve(s)));
        v
    }
    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        compare(p, ctx)
    }
}

/// What the radiograph stage's manifest says about its frames.
struct RadiographSide {
    dir: PathBuf,
    pixel_size: f64,
    d_bar: f64,
    rev_factor: f64,
    min_valid: f64,
    frames: usize,
    /// `fov.json` beside the frames (written by `synth-run`) and its directory.
    fov: Option<serde_json::Value>,
    fov_dir: Option<PathBuf>,
    eps_min_gs: f64,
}

fn radiograph_side(dir: &Path) -> Result<RadiographSide> {
    let m = dir.join(MANIFEST);
    let text = std::fs::read_to_string(&m).with_context(|| {
        format!(
            "{} is not a finished radiograph stage: no {MANIFEST} (run `lbdem radiograph PARAMS --out DIR` first)",
            dir.display()
        )
    })?;
    let rec: StageRecord =
        serde_json::from_str(&text).with_context(|| format!("{} is not a manifest", m.display()))?;
    if rec.kind != "radiograph" {
        bail!(
            "{} was written by a '{}' stage, not by 'radiograph'",
            dir.display(),
            rec.kind
        );
    }
    let num = |k: &str| -> Result<f64> {
        rec.params[k]
            .as_f64()
            .with_context(|| format!("{}: params.{k} is missing", m.display()))
    };
    let frames = rec.output.summary["frames"].as_u64().unwrap_or(0) as usize;
    if frames < 2 {
        bail!(
            "radiograph stage {} has {frames} frame(s): a strain needs a reference and a deformed frame",
            dir.display()
        );
    }
    // fov.json next to the first frame, or one directory up (synth-run writes frames/).
    let fov_path = rec.inputs.first().and_then(|i| {
        let parent = i.path.parent()?;
        [
            parent.join(super::synth_run::FOV),
            parent.parent()?.join(super::synth_run::FOV),
        ]
        .into_iter()
        .find(|p| p.is_file())
    });
    let fov = fov_path
        .as_ref()
        .and_then(|p| serde_json::from_str(&std::fs::read_to_string(p).ok()?).ok());
    Ok(RadiographSide {
        dir: dir.to_path_buf(),
        pixel_size: num("pixel_size")?,
        d_bar: num("d_bar")?,
        rev_factor: num("rev_factor")?,
        min_valid: num("min_valid")?,
        frames,
        fov,
        fov_dir: fov_path.and_then(|p| p.parent().map(Path::to_path_buf)),
        eps_min_gs: num("eps_min_gs")?,
    })
}

/// Statistics of one frame-snapshot pair.
#[derive(Default)]
struct Agreement {
    frame: Vec<u64>,
    step: Vec<u64>,
    u_d: Vec<f64>,
    mean_xip: Vec<f64>,
    mean_tri: Vec<f64>,
    mean_area: Vec<f64>,
    rms: Vec<f64>,
    rms_area: Vec<f64>,
    corr: Vec<f64>,
    rms_red: Vec<f64>,
    rms_blue: Vec<f64>,
    eps_dem: Vec<f64>,
    same_sign: Vec<u64>,
    overlap: Vec<u64>,
    /// With `synth-run` frames: Eq. 5 on the true solid fraction (no blur or noise).
    mean_true: Vec<f64>,
    rms_xip_true: Vec<f64>,
    rms_true_area: Vec<f64>,
}

fn stats(a: &Array2<f64>, b: &Array2<f64>) -> (f64, f64, f64, f64, usize) {
    let pairs: Vec<(f64, f64)> = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| (*x, *y))
        .collect();
    let n = pairs.len();
    if n == 0 {
        return (f64::NAN, f64::NAN, f64::NAN, f64::NAN, 0);
    }
    let nf = n as f64;
    let (ma, mb) = pairs
        .iter()
        .fold((0.0, 0.0), |s, p| (s.0 + p.0 / nf, s.1 + p.1 / nf));
    let rms = (pairs.iter().map(|p| (p.0 - p.1).powi(2)).sum::<f64>() / nf).sqrt();
    let (sab, saa, sbb) = pairs.iter().fold((0.0, 0.0, 0.0), |s, p| {
        let (x, y) = (p.0 - ma, p.1 - mb);
        (s.0 + x * y, s.1 + x * x, s.2 + y * y)
    });
    (ma, mb, rms, sab / (saa * sbb).sqrt(), n)
}

/// Eq. 5 on the true pixel solid fraction `synth-run` wrote for frame `fr` (REV of `side` px as
/// the radiograph stage), or `None` for frames that do not come from `synth-run`.
fn true_eq5(rs: &RadiographSide, fr: u64, side: usize) -> Result<Option<Array2<f64>>> {
    let Some(dir) = &rs.fov_dir else {
        return Ok(None);
    };
    let (p0, pn) = (
        dir.join("truth/gs_pixel_000.tif"),
        dir.join(format!("truth/gs_pixel_{fr:03}.tif")),
    );
    if !(p0.is_file() && pn.is_file()) {
        return Ok(None);
    }
    let g0 = lbdem_analysis::raster::rev_mean(&tio::read_pages(&p0)?.remove(0).data, side, rs.min_valid)?;
    let gn = lbdem_analysis::raster::rev_mean(&tio::read_pages(&pn)?.remove(0).data, side, rs.min_valid)?;
    Ok(Some(lbdem_imaging::beer_lambert::eps_vol_field(
        g0.view(),
        gn.view(),
        rs.eps_min_gs,
    )))
}

fn rms_diff(a: &[f64], b: &[f64]) -> f64 {
    let d: Vec<f64> = a
        .iter()
        .zip(b)
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .map(|(x, y)| (x - y).powi(2))
        .collect();
    if d.is_empty() {
        f64::NAN
    } else {
        (d.iter().sum::<f64>() / d.len() as f64).sqrt()
    }
}

/// Mean of `f` over the ROI [x0, x1, y0, y1] (d̄) of `grid`, along `axis` ('x': profile in x,
/// averaged over y; 'y': profile in y): (positions in d̄, means).
fn roi_profile(f: &Array2<f64>, grid: &Grid, roi: [f64; 4], along_x: bool) -> (Vec<f64>, Vec<f64>) {
    let [x0, x1, y0, y1] = roi;
    let cols: Vec<usize> = (0..grid.nx)
        .filter(|&c| {
            let x = grid.centre(0, c)[0];
            x >= x0 && x <= x1
        })
        .collect();
    let rows: Vec<usize> = (0..grid.ny)
        .filter(|&r| {
            let y = grid.centre(r, 0)[1];
            y >= y0 && y <= y1
        })
        .collect();
    let mean = |it: &mut dyn Iterator<Item = f64>| {
        let (s, n) = it
            .filter(|v| v.is_finite())
            .fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
        if n == 0 { f64::NAN } else { s / n as f64 }
    };
    if along_x {
        let pos = cols.iter().map(|&c| grid.centre(0, c)[0]).collect();
        let val = cols
            .iter()
            .map(|&c| mean(&mut rows.iter().map(|&r| f[[r, c]])))
            .collect();
        (pos, val)
    } else {
        // Bottom to top.
        let pos = rows.iter().rev().map(|&r| grid.centre(r, 0)[1]).collect();
        let val = rows
            .iter()
            .rev()
            .map(|&r| mean(&mut cols.iter().map(|&c| f[[r, c]])))
            .collect();
        (pos, val)
    }
}

#[allow(clippy::too_many_lines)]
fn compare(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
    let rs = radiograph_side(&run_data::locate(&p.radiograph, ctx))?;
    let run = Run::open(
        &run_data::locate(&p.run, ctx),
        p.scene.as_ref().map(|s| ctx.resolve(s)).as_deref(),
    )?;
    let plate_px = match (p.plate_px, &rs.fov) {
        (Some(v), _) => v,
        (None, Some(f)) => {
            let v: Vec<f64> = f["plate_px"]
                .as_array()
                .map(|a| a.iter().filter_map(|x| x.as_f64()).collect())
                .unwrap_or_default();
            if v.len() != 3 {
                bail!("fov.json beside the radiograph's frames has no plate_px = [left, right, row]");
            }
            [v[0], v[1], v[2]]
        }
        (None, None) => bail!(
            "give 'plate_px' = [left column, right column, face row] of the push-plate in the radiograph's \
             frame 0 (px): the two sides are aligned on it"
        ),
    };
    if plate_px[1] <= plate_px[0] || !plate_px.iter().all(|v| v.is_finite()) {
        bail!("plate_px = {plate_px:?}: the right corner's column must exceed the left one's");
    }
    let d_exp = p.d_bar_radiograph.unwrap_or(rs.d_bar);
    let (reference_grains, _, steps) = reference(&run, p.reference)?;
    let d_run = p.d_bar_run.unwrap_or_else(|| reference_grains.d_bar());
    for (n, v) in [("d_bar_radiograph", d_exp), ("d_bar_run", d_run)] {
        if !(v > 0.0 && v.is_finite()) {
            bail!("parameter '{n}' = {v} m must be positive");
        }
    }
    // The radiograph's pixel grid in d̄ of the experiment, origin at the middle of the plate face.
    let first = tio::read_pages(&rs.dir.join("eps_vol_001.tif"))
        .with_context(|| format!("radiograph stage {}: its eps_vol maps", rs.dir.display()))?;
    let (h, w) = first[0].data.dim();
    let s = rs.pixel_size / d_exp;
    let mid = 0.5 * (plate_px[0] + plate_px[1]);
    let grid = Grid {
        x0: -mid * s,
        y0: (plate_px[2] - h as f64) * s,
        dx: s,
        nx: w,
        ny: h,
    };
    let fov_px = match (p.fov_px, &rs.fov) {
        (Some(f), _) => f,
        (None, Some(f)) => {
            let rows: Vec<usize> = f["fov_rows"]
                .as_array()
                .map(|a| a.iter().filter_map(|x| x.as_u64().map(|v| v as usize)).collect())
                .unwrap_or_default();
            match rows.as_slice() {
                [r0, r1] if r1 > r0 => [0, *r0, w, r1 - r0],
                _ => [0, 0, w, h],
            }
        }
        (None, None) => [0, 0, w, h],
    };
    if fov_px[2] == 0 || fov_px[3] == 0 || fov_px[0] + fov_px[2] > w || fov_px[1] + fov_px[3] > h {
        bail!("fov_px = {fov_px:?} is empty or outside the {w} x {h} radiographs");
    }
    let in_fov = |a: &mut Array2<f64>| {
        for ((r, c), v) in a.indexed_iter_mut() {
            if c < fov_px[0] || c >= fov_px[0] + fov_px[2] || r < fov_px[1] || r >= fov_px[1] + fov_px[3] {
                *v = f64::NAN;
            }
        }
    };
    let frame = frame_of(&run, &reference_grains, d_run);
    let opts = StrainOptions {
        max_edge_d: p.max_edge_d,
        pixels_per_d: 1.0 / s,
        rev_factor: rs.rev_factor,
        min_valid: rs.min_valid,
        ..Default::default()
    };
    let setup = Setup::on_grid(&reference_grains, frame, grid, &opts)?;
    let pairs: Vec<[u64; 2]> = match (&p.pairs, &rs.fov) {
        (Some(v), _) => v.clone(),
        (None, Some(f)) => f["frames"]
            .as_array()
            .map(|a| {
                a.iter()
                    .filter_map(|x| Some([x["frame"].as_u64()?, x["step"].as_u64()?]))
                    .collect()
            })
            .unwrap_or_default(),
        (None, None) => match steps.last() {
            Some(&last) => vec![[rs.frames as u64 - 1, last]],
            None => Vec::new(),
        },
    };
    if pairs.is_empty() {
        bail!("no [frame, step] pair to compare; give 'pairs'");
    }
    for &[fr, st] in &pairs {
        if fr == 0 || fr as usize >= rs.frames {
            bail!(
                "pairs: frame {fr} is not a deformed frame of the radiograph stage (frames 1..{})",
                rs.frames - 1
            );
        }
        if !steps.contains(&st) {
            bail!("pairs: the run has no particle snapshot at step {st}; its steps: {steps:?}");
        }
    }
    let out = &ctx.out_dir;
    let (mut files, mut figures, mut tables) = (Vec::<PathBuf>::new(), Vec::new(), Vec::new());
    let mut agg = Agreement::default();
    let pb = ctx.progress_bar(pairs.len() as u64, "compare");
    let mut last = None;
    for (k, &[fr, st]) in pairs.iter().enumerate() {
        let mut xip = tio::read_pages(&rs.dir.join(format!("eps_vol_{fr:03}.tif")))?
            .remove(0)
            .data;
        if xip.dim() != (h, w) {
            bail!(
                "eps_vol_{fr:03}.tif is {:?}, eps_vol_001.tif {:?}",
                xip.dim(),
                (h, w)
            );
        }
        in_fov(&mut xip);
        let g = run.grains(st)?;
        let mut f = setup.fields(&g)?;
        for a in [&mut f.eps_vol, &mut f.eps_xy, &mut f.rotation, &mut f.eps_area] {
            in_fov(a);
        }
        let t = run.time_of(st);
        let u = run.plate_displacement(t);
        let (ma, mb, rms, corr, n) = stats(&xip, &f.eps_vol);
        let (_, mc, rms_area, _, _) = stats(&xip, &f.eps_area);
        let (_, red_x) = roi_profile(&xip, &setup.grid, p.red_roi, true);
        let (_, red_t) = roi_profile(&f.eps_vol, &setup.grid, p.red_roi, true);
        let (_, blue_x) = roi_profile(&xip, &setup.grid, p.blue_roi, false);
        let (_, blue_t) = roi_profile(&f.eps_vol, &setup.grid, p.blue_roi, false);
        let e_dem = eq18(&run, &reference_grains, &g, u).map_or(f64::NAN, |v| v.1);
        let truth = true_eq5(&rs, fr, setup.rev_side)?.map(|mut t| {
            in_fov(&mut t);
            t
        });
        let (mt, rxt, rta) = match &truth {
            Some(t) => {
                let (_, mt, rxt, _, _) = stats(&xip, t);
                let (_, _, rta, _, _) = stats(t, &f.eps_area);
                (mt, rxt, rta)
            }
            None => (f64::NAN, f64::NAN, f64::NAN),
        };
        agg.mean_true.push(mt);
        agg.rms_xip_true.push(rxt);
        agg.rms_true_area.push(rta);
        let net_sim = if e_dem.is_finite() {
            e_dem
        } else {
            f.mean.eps_vol()
        };
        agg.frame.push(fr);
        agg.step.push(st);
        agg.u_d.push(u / d_run);
        agg.mean_xip.push(ma);
        agg.mean_tri.push(mb);
        agg.mean_area.push(mc);
        agg.rms.push(rms);
        agg.rms_area.push(rms_area);
        agg.corr.push(corr);
        agg.rms_red.push(rms_diff(&red_x, &red_t));
        agg.rms_blue.push(rms_diff(&blue_x, &blue_t));
        agg.eps_dem.push(e_dem);
        agg.same_sign.push(u64::from((ma > 0.0) == (net_sim > 0.0)));
        agg.overlap.push(n as u64);
        if k + 1 == pairs.len() {
            last = Some((fr, st, xip, f, u));
        }
        pb.inc(1);
    }
    pb.finish_and_clear();
    let Some((fr, st, xip, f, u)) = last else {
        bail!("nothing compared");
    };
    let ud = u / d_run;
    let src = format!(
        "radiographs {} (frame {fr}) and run {} (step {st}, u_y = {ud:.2} d̄)",
        rs.dir.display(),
        run.dir.display()
    );
    profiles(
        p,
        &setup,
        &xip,
        &f,
        out,
        &src,
        &mut figures,
        &mut tables,
        &mut files,
    )?;
    maps(
        p,
        &run,
        &setup,
        &xip,
        &f,
        st,
        u,
        out,
        &src,
        &mut figures,
        &mut files,
    )?;
    agreement_outputs(&agg, out, &src, &mut figures, &mut tables, &mut files)?;
    let lastk = agg.frame.len() - 1;
    let exp_net = p.experiment_label.clone().unwrap_or_else(|| {
        if agg.mean_xip[lastk] > 0.0 {
            "net dilation (mean XIP ε_vol > 0)".into()
        } else {
            "net contraction (mean XIP ε_vol ≤ 0)".into()
        }
    });
    let summary = json!({
        "radiograph": rs.dir,
        "run": run.dir,
        "plate_px": plate_px,
        "d_bar_radiograph_m": d_exp,
        "d_bar_run_m": d_run,
        "pixel_d": s,
        "fov_px": fov_px,
        "rev_side_px": setup.rev_side,
        "pairs": pairs.len(),
        "last": {
            "frame": fr, "step": st, "u_y_d": ud,
            "mean_eps_vol_xip": agg.mean_xip[lastk], "mean_eps_vol_tri": agg.mean_tri[lastk],
            "mean_area_strain_tri": agg.mean_area[lastk],
            "rms_xip_minus_tri": agg.rms[lastk], "rms_xip_minus_area_strain": agg.rms_area[lastk],
            "correlation": agg.corr[lastk],
            "rms_profile_red": agg.rms_red[lastk], "rms_profile_blue": agg.rms_blue[lastk],
            "eps_vol_dem": agg.eps_dem[lastk],
            "experiment_net": exp_net,
            "net_signs_agree": agg.same_sign[lastk] == 1,
            "overlap_px": agg.overlap[lastk],
            "mean_eps_vol_true_eq5": agg.mean_true[lastk],
            "rms_xip_minus_true_eq5": agg.rms_xip_true[lastk],
            "rms_true_eq5_minus_area_strain": agg.rms_true_area[lastk],
        },
    });
    lbdem_core::atomic::write_atomic(
        &out.join("comparison.json"),
        &serde_json::to_vec_pretty(&summary)?,
    )?;
    files.push("comparison.json".into());
    Ok(StageOutput {
        summary,
        figures,
        tables,
        files,
    })
}

#[allow(clippy::too_many_arguments)]
fn profiles(
    p: &Params,
    s: &Setup,
    xip: &Array2<f64>,
    f: &Fields,
    out: &Path,
    src: &str,
    figures: &mut Vec<Figure>,
    tables: &mut Vec<Table>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    for (name, roi, along_x, colour) in [
        ("red", p.red_roi, true, (200, 30, 30)),
        ("blue", p.blue_roi, false, (30, 60, 200)),
    ] {
        let (pos, a) = roi_profile(xip, &s.grid, roi, along_x);
        let (_, b) = roi_profile(&f.eps_vol, &s.grid, roi, along_x);
        let (_, c) = roi_profile(&f.eps_area, &s.grid, roi, along_x);
        if pos.is_empty() || !a.iter().chain(&b).any(|v| v.is_finite()) {
            bail!(
                "the {name} ROI {roi:?} (d̄) holds no pixel where both sides have a strain; the common field of \
                 view is x {:.1}..{:.1}, y {:.1}..{:.1} d̄: move '{name}_roi'",
                s.grid.x0,
                s.grid.x0 + s.grid.nx as f64 * s.grid.dx,
                s.grid.y0,
                s.grid.y1()
            );
        }
        let diff: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
        let axis = if along_x { "x" } else { "y" };
        let csv = format!("profile_{name}.csv");
        table::write_table(
            &out.join(&csv),
            &[
                (if along_x { "x_d" } else { "y_d" }, Col::F64(&pos)),
                ("eps_vol_xip", Col::F64(&a)),
                ("eps_vol_tri", Col::F64(&b)),
                ("area_strain_tri", Col::F64(&c)),
                ("xip_minus_tri", Col::F64(&diff)),
            ],
        )?;
        files.push(csv.clone().into());
        tables.push(Table {
            path: csv.into(),
            caption: format!(
                "Profile along {axis} (d̄) of the {name} ROI {roi:?}: ε_vol by intensity (Eq. 5, XIP), ε_xx + ε_yy by \
                 triangulation (TRI), the triangles' area strain J − 1, and XIP − TRI. {src}."
            ),
        });
        let png = format!("profile_{name}.png");
        let title = format!("{name} ROI: ε_vol along {axis} (Su Fig. 6)");
        lines_png(
            &out.join(&png),
            &[
                Line {
                    label: "XIP (Eq. 5)",
                    x: &pos,
                    y: &a,
                    style: Style::Solid,
                    colour: Some(colour),
                },
                Line {
                    label: "TRI ε_xx + ε_yy",
                    x: &pos,
                    y: &b,
                    style: Style::Dashed,
                    colour: Some((20, 20, 20)),
                },
            ],
            &LinesPlot {
                title: &title,
                x_label: &format!("{axis} (d_bar from the plate)"),
                y_label: "volumetric strain (-)",
                h_refs: vec![Reference {
                    value: 0.0,
                    label: "",
                }],
                ..Default::default()
            },
        )?;
        figures.push(Figure {
            path: png.clone().into(),
            caption: format!(
                "Volumetric strain in the {name} ROI [x0, x1, y0, y1] = {roi:?} d̄, averaged along {}: from \
                 intensity (XIP, solid) and from triangulation (TRI, dashed), both on the √10 d̄ REV (RMS difference \
                 {:.3e}). {src}.",
                if along_x { "y" } else { "x" },
                rms_diff(&a, &b)
            ),
        });
        files.push(png.into());
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
fn maps(
    p: &Params,
    run: &Run,
    s: &Setup,
    xip: &Array2<f64>,
    f: &Fields,
    step: u64,
    u: f64,
    out: &Path,
    src: &str,
    figures: &mut Vec<Figure>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    let mut shapes = plate_shapes(run, &s.frame, u);
    let [rx0, rx1, ry0, ry1] = p.red_roi;
    let [bx0, bx1, by0, by1] = p.blue_roi;
    shapes.push(Shape::rect(rx0, ry0, rx1, ry1, (210, 30, 30)));
    shapes.push(Shape::rect(bx0, by0, bx1, by1, (30, 60, 210)));
    let grid = |title: &'static str, label: &'static str| PanelGrid {
        title,
        cols: 2,
        label,
        cmap: Colormap::Diverging,
        range: None,
        extent: s.extent(),
        x_label: "x (d_bar)",
        y_label: "y (d_bar)",
        mark_label: None,
    };
    // XIP beside TRI on one colour scale, over the pixels where both are defined.
    let both = |a: &Array2<f64>, b: &Array2<f64>| {
        let mut a = a.clone();
        a.zip_mut_with(b, |x, y| {
            if !y.is_finite() {
                *x = f64::NAN;
            }
        });
        a
    };
    let (xb, tb) = (both(xip, &f.eps_vol), both(&f.eps_vol, xip));
    let panels = vec![
        Panel {
            title: "radiographs: ε_vol (Eq. 5, XIP)".into(),
            field: xb.view(),
            marked: None,
            shapes: shapes.clone(),
            frame: None,
        },
        Panel {
            title: "run: ε_xx + ε_yy (TRI)".into(),
            field: tb.view(),
            marked: None,
            shapes: shapes.clone(),
            frame: None,
        },
    ];
    let file = "eps_vol_side_by_side.png";
    let (lo, hi) = panels_png(
        &out.join(file),
        &panels,
        &grid(
            "volumetric strain, radiographs | simulation",
            "volumetric strain (-)",
        ),
    )?;
    figures.push(Figure {
        path: file.into(),
        caption: format!(
            "Volumetric strain from intensity (left, Eq. 5 on the √10 d̄ REV) and by triangulation of the run's grains \
             (right, ε_xx + ε_yy on the same pixels and REV), one colour scale ({lo:.3e} to {hi:.3e}); grey where either \
             side has none. Red and blue boxes: the ROIs of the profiles; dark outline: the push-plate. {src}."
        ),
    });
    files.push(file.into());
    let mut single = |file: String,
                      title: &'static str,
                      label: &'static str,
                      field: &Array2<f64>,
                      marked: Option<&Array2<bool>>,
                      caption: String|
     -> Result<()> {
        let mut g = grid(title, label);
        g.cols = 1;
        let mark = format!("Δp < {} Pa", p.pressure_threshold);
        if marked.is_some() {
            g.mark_label = Some(&mark);
        }
        let (lo, hi) = panels_png(
            &out.join(&file),
            &[Panel {
                title: format!("run, u_y = {:.2} d_bar", u / s.frame.d_bar),
                field: field.view(),
                marked: marked.map(|m| m.view()),
                shapes: shapes.clone(),
                frame: None,
            }],
            &g,
        )?;
        figures.push(Figure {
            path: file.clone().into(),
            caption: format!("{caption} Colour scale {lo:.3e} to {hi:.3e}. {src}."),
        });
        files.push(file.into());
        Ok(())
    };
    single(
        "eps_xy_tri.png".into(),
        "shear strain ε_xy by triangulation (Su Fig. 9)",
        "ε_xy (-)",
        &f.eps_xy,
        None,
        "Shear strain ε_xy = γ_xy/2 of the run by triangulation on the radiograph's grid (no radiograph \
         counterpart: intensity gives only the volumetric strain)."
            .into(),
    )?;
    if let Some(dp) = pressure_on_grid(run, step, s)? {
        let marked = dp.mapv(|v| v < p.pressure_threshold);
        single(
            "dp.png".into(),
            "liquid pressure change Δp (Su Fig. 10)",
            "Δp (Pa)",
            &dp,
            Some(&marked),
            format!(
                "Liquid pressure change Δp (Eq. 19) of the run on the same field of view; yellow: Δp below Δp_c = {} Pa \
                 (the cracking criterion, Sect. 3.5; Su take {DP_C} Pa).",
                p.pressure_threshold
            ),
        )?;
    }
    Ok(())
}

fn agreement_outputs(
    a: &Agreement,
    out: &Path,
    src: &str,
    figures: &mut Vec<Figure>,
    tables: &mut Vec<Table>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    table::write_table(
        &out.join("agreement.csv"),
        &[
            ("frame", Col::U64(&a.frame)),
            ("step", Col::U64(&a.step)),
            ("u_y_d", Col::F64(&a.u_d)),
            ("mean_eps_vol_xip", Col::F64(&a.mean_xip)),
            ("mean_eps_vol_tri", Col::F64(&a.mean_tri)),
            ("mean_area_strain_tri", Col::F64(&a.mean_area)),
            ("rms_xip_minus_tri", Col::F64(&a.rms)),
            ("rms_xip_minus_area_strain", Col::F64(&a.rms_area)),
            ("correlation", Col::F64(&a.corr)),
            ("rms_profile_red", Col::F64(&a.rms_red)),
            ("rms_profile_blue", Col::F64(&a.rms_blue)),
            ("eps_vol_dem", Col::F64(&a.eps_dem)),
            ("net_signs_agree", Col::U64(&a.same_sign)),
            ("overlap_px", Col::U64(&a.overlap)),
            ("mean_eps_vol_true", Col::F64(&a.mean_true)),
            ("rms_xip_minus_true", Col::F64(&a.rms_xip_true)),
            ("rms_true_minus_area_strain", Col::F64(&a.rms_true_area)),
        ],
    )?;
    files.push("agreement.csv".into());
    tables.push(Table {
        path: "agreement.csv".into(),
        caption: format!(
            "Agreement of every frame-snapshot pair over the pixels both sides cover: means of XIP ε_vol, TRI ε_xx + ε_yy \
             and TRI J − 1, RMS of XIP − TRI and XIP − (J − 1), their correlation, RMS of the red and blue profile \
             differences, ε_vol^DEM (Eq. 18) and whether the mean XIP and ε_vol^DEM have the same sign; with frames from \
             synth-run, also Eq. 5 on the true solid fraction (no blur, no noise) and its RMS differences from XIP and \
             from J − 1, which split XIP − TRI into what the imaging adds and what the two definitions differ by. {src}."
        ),
    });
    let f = "difference.png";
    lines_png(
        &out.join(f),
        &[
            Line {
                label: "mean XIP ε_vol",
                x: &a.u_d,
                y: &a.mean_xip,
                style: Style::LinePoints,
                colour: Some((200, 30, 30)),
            },
            Line {
                label: "mean TRI ε_xx + ε_yy",
                x: &a.u_d,
                y: &a.mean_tri,
                style: Style::Dashed,
                colour: Some((20, 20, 20)),
            },
            Line {
                label: "RMS(XIP − TRI)",
                x: &a.u_d,
                y: &a.rms,
                style: Style::LinePoints,
                colour: Some((30, 60, 200)),
            },
            Line {
                label: "ε_vol^DEM (Eq. 18)",
                x: &a.u_d,
                y: &a.eps_dem,
                style: Style::Points,
                colour: Some((30, 150, 50)),
            },
        ],
        &LinesPlot {
            title: "intensity (XIP) vs triangulation (TRI) over the run",
            x_label: "push-plate displacement u_y (d_bar)",
            y_label: "strain (-)",
            h_refs: vec![Reference {
                value: 0.0,
                label: "",
            }],
            ..Default::default()
        },
    )?;
    figures.push(Figure {
        path: f.into(),
        caption: format!(
            "The two strain operators on the same snapshots, frame by frame: field-of-view means of ε_vol from \
             intensity (Eq. 5) and of ε_xx + ε_yy from triangulation, the RMS of their difference per pixel, and the \
             sample's ε_vol^DEM (Eq. 18). {src}."
        ),
    });
    files.push(f.into());
    Ok(())
}
