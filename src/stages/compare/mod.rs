//! Stage `compare` (`lbdem compare PARAMS.toml --out DIR`): a radiograph stack beside a
//! simulation run, as Su et al. (2020) Figs. 6-10 set experiments beside simulations.
//!
//! The experiment side is the output of a `radiograph` stage (any stack it reads: real beamtime
//! frames, `synth-radiograph`, or `synth-run` renderings of a run): its ε_vol maps (Eq. 5, XIP).
//! The simulation side is the run's strain by triangulation (TRI) painted on the radiograph's
//! own map grid (its pixels, or its `map_step` cells) and averaged by the √10 d̄ REV rounded to
//! whole cells (`rev_side_tri_px` in `comparison.json`: within half a cell of the radiograph's).
//! Both are aligned on the push-plate: x, y in mean grain diameters of each side from the middle
//! of the plate's face before it moves (`plate_px` gives the face in the radiograph: its
//! corners' columns and its row; `synth-run` writes it in `fov.json`, which is read when
//! `plate_px` is not given).
//!
//! Out: Fig. 6-style profiles (red ROI averaged along y, blue ROI along x), Figs. 8-10-style
//! panels (ε_vol XIP and TRI on one colour scale, ε_xy, Δp with Δp < Δp_c marked), the
//! difference XIP − TRI over the frames, and an agreement table (RMS of the map and profile
//! differences, correlation, whether the net behaviours have the same sign).

use super::analyse::{ReferenceState, eq18, frame_of, reference};
use super::run_data::{self, Run};
use super::strain_fields::{Setup, StrainOptions};
use crate::contract::{Stage, StageContext, StageOutput};
use crate::io::tiff as tio;
use anyhow::{Context, Result, bail};
use lbdem_analysis::raster::Grid;
use lbdem_imaging::rev::cell_centre;
use ndarray::Array2;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::PathBuf;

mod agreement;
mod figures;
mod radiograph_side;

use agreement::{Agreement, rms_diff, roi_profile, stats};
use figures::{agreement_outputs, maps, profiles};
use radiograph_side::{radiograph_side, true_eq5};

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
    // Map cell (r, c) holds the REV centred on pixel (r k + k/2, c k + k/2), k = map_step (odd):
    // the centre of the k x k block of pixels it stands for, so the grid's cells are the blocks.
    let (h, w) = first[0].data.dim();
    let k = rs.map_step;
    if k.is_multiple_of(2) && k > 1 || (rs.image.0 > 0 && (h, w) != (rs.image.0 / k, rs.image.1 / k)) {
        bail!(
            "radiograph stage {}: eps_vol_001.tif is {h} x {w} cells, but its summary gives {} x {} px frames \
             and map_step_px = {k} (odd, frames / step cells expected): rerun the radiograph stage",
            rs.dir.display(),
            rs.image.0,
            rs.image.1
        );
    }
    let (h_px, w_px) = if rs.image.0 > 0 { rs.image } else { (h * k, w * k) };
    let s = rs.pixel_size / d_exp;
    let mid = 0.5 * (plate_px[0] + plate_px[1]);
    let grid = Grid {
        x0: -mid * s,
        y0: (plate_px[2] - (h * k) as f64) * s,
        dx: s * k as f64,
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
                [r0, r1] if r1 > r0 => [0, *r0, w_px, r1 - r0],
                _ => [0, 0, w_px, h_px],
            }
        }
        (None, None) => [0, 0, w_px, h_px],
    };
    if fov_px[2] == 0 || fov_px[3] == 0 || fov_px[0] + fov_px[2] > w_px || fov_px[1] + fov_px[3] > h_px {
        bail!("fov_px = {fov_px:?} is empty or outside the {w_px} x {h_px} radiographs");
    }
    // A map cell is in the field of view when its centre pixel is.
    let in_fov = |a: &mut Array2<f64>| {
        for ((r, c), v) in a.indexed_iter_mut() {
            let (r, c) = (cell_centre(r, k), cell_centre(c, k));
            if c < fov_px[0] || c >= fov_px[0] + fov_px[2] || r < fov_px[1] || r >= fov_px[1] + fov_px[3] {
                *v = f64::NAN;
            }
        }
    };
    let frame = frame_of(&run, &reference_grains, d_run);
    let opts = StrainOptions {
        max_edge_d: p.max_edge_d,
        pixels_per_d: 1.0 / (s * k as f64),
        rev_factor: rs.rev_factor,
        min_valid: rs.min_valid,
        ..Default::default()
    };
    let setup = Setup::on_grid(&reference_grains, frame, grid, &opts)?;
    // The true Eq. 5 is formed on the pixels, with the radiograph stage's REV side.
    let rev_side_px = match rs.rev_side_px {
        Some(v) => v,
        None => lbdem_analysis::raster::rev_side(rs.rev_factor, 1.0, s)?,
    };
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
        let truth = true_eq5(&rs, fr, rev_side_px)?.map(|mut t| {
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
        "map_step_px": k,
        "cell_d": setup.grid.dx,
        "fov_px": fov_px,
        "rev_side_px": rev_side_px,
        "rev_side_cells": setup.rev_side,
        "rev_side_tri_px": setup.rev_side * k,
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
            "overlap_cells": agg.overlap[lastk],
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
