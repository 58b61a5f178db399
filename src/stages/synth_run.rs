//! Stage `synth-run` (`lbdem synth run PARAMS.toml --out DIR`): radiographs of a simulation, so
//! that a run goes through the very `radiograph` stage an experiment goes through (Su et al. 2020
//! Eqs. 1-5) and its ε_vol from intensity (XIP) can be set beside its ε_xx + ε_yy from
//! triangulation (TRI) for the same snapshots (stage `compare`).
//!
//! Frame 0 is the reference grains (the run's start), frame k its k-th particle snapshot. Each
//! pixel integrates Beer-Lambert transmission through the sample's thickness L: solid where a
//! grain's circle covers it (a 2D grain spans the thickness: `grain_shape = "cylinder"`), liquid
//! elsewhere inside the sample (the polygon through the membrane grains' centroids, minus the
//! push-plate), nothing outside; then detector blur, Poisson noise and 16-bit counts
//! (`lbdem_imaging::synth`). Two reference strips sit above the field of view: 100 % solid
//! (rows 0..pad_px) and 100 % liquid (pad_px..2 pad_px), so `i_s0_roi = [4, 4, 32, pad_px - 8]`
//! and `i_l0_roi = [4, pad_px + 4, 32, pad_px - 8]` hold for any field of view.
//!
//! Writes `frames/frame_NNN.tif`, `truth/gs_pixel_NNN.tif` (the true pixel solid fraction, no
//! blur or noise), `fov.json` (the plate's corners in pixels, the pixel size, d̄, the step of each
//! frame) and `radiograph.toml` (parameters for `lbdem radiograph`).

use super::analyse::{ReferenceState, frame_of, reference};
use super::run_data::{self, Grains, Run};
use crate::contract::{Stage, StageContext, StageOutput};
use crate::io::tiff as tio;
use crate::report::plot::{self, Colormap, FieldPlot};
use anyhow::{Context, Result, bail};
use lbdem_analysis::volume;
use lbdem_imaging::Roi;
use lbdem_imaging::beer_lambert::mixture_mu;
use lbdem_imaging::synth::{self, Beam, Disk, GrainShape};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::PathBuf;

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// The run: an earlier `simulate` stage's name, or its output directory.
    pub run: String,
    #[serde(default)]
    pub scene: Option<PathBuf>,
    #[serde(default)]
    pub reference: ReferenceState,
    /// Mean grain diameter (m); default: the reference grains' mean equivalent diameter.
    #[serde(default)]
    pub d_bar: Option<f64>,
    /// Pixels per d̄ (Su et al. 2020: about 22, 5.5 µm pixels and d̄ ≈ 120 µm).
    #[serde(default = "d::ppd")]
    pub pixels_per_d: f64,
    /// Field of view [x0, x1, y0, y1] in d̄ from the middle of the plate's face; default: the
    /// sample's grains 2.5 d̄ in from their outline, above the plate's last position.
    #[serde(default)]
    pub fov: Option<[f64; 4]>,
    /// Sample thickness L (m) the beam crosses: Su et al. 2020 Fig. 1a, ~0.2 mm. (Not the
    /// scene's `[coupling] depth`, a modelling choice: through 1 mm of Al-Cu liquid almost no
    /// photon of 15 keV passes.)
    #[serde(default = "d::thickness")]
    pub thickness: f64,
    /// Open-beam counts per pixel.
    #[serde(default = "d::i0")]
    pub i0: f64,
    /// Linear attenuation of solid and liquid (1/m); default: NIST mass attenuation at 15 keV of
    /// α-Al (2700 kg/m³) and Al-33wt%Cu liquid (3400 kg/m³), as `synth-radiograph`.
    #[serde(default = "d::mu_s")]
    pub mu_s: f64,
    #[serde(default = "d::mu_l")]
    pub mu_l: f64,
    #[serde(default = "d::blur")]
    pub blur_sigma_px: f64,
    #[serde(default = "d::yes")]
    pub noise: bool,
    #[serde(default = "d::seed")]
    pub seed: u64,
    #[serde(default = "d::ss")]
    pub supersample: usize,
    #[serde(default = "d::cylinder")]
    pub grain_shape: GrainShape,
    /// Height of each reference strip (px).
    #[serde(default = "d::pad")]
    pub pad_px: usize,
    #[serde(default = "d::yes")]
    pub plots: bool,
}

mod d {
    use super::*;
    pub fn ppd() -> f64 {
        12.0
    }
    pub fn i0() -> f64 {
        30000.0
    }
    /// NIST (Hubbell & Seltzer) Al at 15 keV: 7.955 cm²/g; α-Al at 2700 kg/m³.
    pub fn mu_s() -> f64 {
        mixture_mu(2700.0, &[(1.0, 0.7955)])
    }
    /// Al-33wt%Cu liquid at 3400 kg/m³; Cu at 15 keV: 74.05 cm²/g.
    pub fn mu_l() -> f64 {
        mixture_mu(3400.0, &[(0.67, 0.7955), (0.33, 7.405)])
    }
    pub fn blur() -> f64 {
        0.7
    }
    pub fn yes() -> bool {
        true
    }
    pub fn seed() -> u64 {
        20200311
    }
    pub fn ss() -> usize {
        4
    }
    pub fn thickness() -> f64 {
        2e-4
    }
    pub fn cylinder() -> GrainShape {
        GrainShape::Cylinder
    }
    pub fn pad() -> usize {
        24
    }
}

pub struct SynthRun;

/// What `compare` reads beside the frames.
pub const FOV: &str = "fov.json";

impl Stage for SynthRun {
    const KIND: &'static str = "synth-run";
    const ABOUT: &'static str = "Radiographs of a simulation's snapshots (Beer-Lambert through grains and liquid), for the radiograph stage";
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
        render(p, &run, ctx)
    }
}

#[allow(clippy::too_many_lines)]
fn render(p: &Params, run: &Run, ctx: &StageContext) -> Result<StageOutput> {
    for (n, v) in [
        ("pixels_per_d", p.pixels_per_d),
        ("i0", p.i0),
        ("mu_s", p.mu_s),
        ("mu_l", p.mu_l),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            bail!("parameter '{n}' = {v} must be positive and finite");
        }
    }
    if p.i0 > 65535.0 {
        bail!("parameter 'i0' = {} exceeds the 16-bit range 65535", p.i0);
    }
    if p.pad_px < 16 {
        bail!(
            "parameter 'pad_px' = {} must be at least 16 (the reference ROIs are 8 px inside it)",
            p.pad_px
        );
    }
    let (reference_grains, _, steps) = reference(run, p.reference)?;
    let d_bar = match p.d_bar {
        Some(d) if d > 0.0 && d.is_finite() => d,
        Some(d) => bail!("parameter 'd_bar' = {d} m must be positive"),
        None => reference_grains.d_bar(),
    };
    let thickness = p.thickness;
    if !(thickness > 0.0 && thickness.is_finite()) {
        bail!("parameter 'thickness' = {thickness} m must be positive");
    }
    let frame = frame_of(run, &reference_grains, d_bar);
    let px = d_bar / p.pixels_per_d;
    let u_last = steps
        .last()
        .map_or(0.0, |&s| run.plate_displacement(run.time_of(s)));
    let [x0, x1, y0, y1] = match p.fov {
        Some(f) => f,
        None => {
            let pts: Vec<[f64; 2]> = reference_grains
                .centroid
                .iter()
                .map(|&c| frame.from_scene(c))
                .collect();
            let (lo, hi) = pts
                .iter()
                .fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), q| {
                    (
                        [lo[0].min(q[0]), lo[1].min(q[1])],
                        [hi[0].max(q[0]), hi[1].max(q[1])],
                    )
                });
            let bottom = if run.plate.is_some() {
                u_last / d_bar + 0.75
            } else {
                lo[1] + 2.5
            };
            [lo[0] + 2.5, hi[0] - 2.5, bottom.max(lo[1] + 2.5), hi[1] - 2.5]
        }
    };
    let rev = 10f64.sqrt();
    if !(x1 - x0 > 2.0 * rev && y1 - y0 > 2.0 * rev) {
        bail!(
            "field of view [x0, x1, y0, y1] = [{x0:.2}, {x1:.2}, {y0:.2}, {y1:.2}] d̄ is smaller than two REVs \
             ({:.2} d̄) across; give a larger 'fov' or a larger sample",
            2.0 * rev
        );
    }
    let w = ((x1 - x0) * p.pixels_per_d).round() as usize;
    let hf = ((y1 - y0) * p.pixels_per_d).round() as usize;
    let (pad, gap) = (p.pad_px, p.pad_px / 2);
    let top = 2 * pad + gap;
    let h = top + hf;
    if w < 40 {
        bail!("the field of view is {w} px wide: need at least 40 (raise pixels_per_d or widen fov)");
    }
    // Pixel coordinates (col, row; centre of pixel (0, 0) at (0.5, 0.5)) of a point in d̄.
    let to_px = |q: [f64; 2]| {
        [
            (q[0] - x0) * p.pixels_per_d,
            top as f64 + (y1 - q[1]) * p.pixels_per_d,
        ]
    };
    let solid_pad = Roi::new(0, 0, w, pad);
    let liquid_pad = Roi::new(0, pad, w, pad + gap);
    let beam = Beam {
        i0: p.i0,
        mu_s: p.mu_s,
        mu_l: p.mu_l,
    };
    let out = &ctx.out_dir;
    for sub in ["frames", "truth"] {
        std::fs::create_dir_all(out.join(sub))
            .with_context(|| format!("cannot create {}", out.join(sub).display()))?;
    }
    let mut files: Vec<PathBuf> = Vec::new();
    let mut figures = Vec::new();
    let mut frames_json = Vec::new();
    let states: Vec<(Option<u64>, f64)> = std::iter::once((None, 0.0))
        .chain(steps.iter().map(|&s| (Some(s), run.time_of(s))))
        .collect();
    let pb = ctx.progress_bar(states.len() as u64, "synth-run");
    for (k, &(step, t)) in states.iter().enumerate() {
        let g: Grains = match step {
            None => reference_grains.clone(),
            Some(s) => run.grains(s)?,
        };
        let u = if step.is_some() {
            run.plate_displacement(t)
        } else {
            0.0
        };
        let mut disks = Vec::new();
        for cs in &g.circles {
            for c in cs {
                let q = to_px(frame.from_scene([c[0], c[1]]));
                let r = c[2] / d_bar * p.pixels_per_d;
                // Only circles that reach the field of view's rows.
                if q[1] + r >= top as f64 && q[0] + r >= 0.0 && q[0] - r <= w as f64 {
                    disks.push(Disk { x: q[0], y: q[1], r });
                }
            }
        }
        let (coverage, mut counts) = synth::render(
            h,
            w,
            &disks,
            p.supersample,
            p.grain_shape,
            thickness / px,
            thickness,
            &beam,
            &[solid_pad],
            &[liquid_pad],
        );
        // Outside the sample (the membrane polygon minus the plate): no alloy in the beam.
        let ring: Vec<[f64; 2]> = g
            .membrane_ring(&reference_grains)
            .iter()
            .map(|&c| to_px(frame.from_scene(c)))
            .collect();
        let plate: Option<[[f64; 2]; 4]> = run.plate.map(|pl| {
            let (l, r) = pl.corners(u);
            let q = volume::behind_plate(l, r, pl.dir(), 1.0);
            q.map(|c| to_px(frame.from_scene(c)))
        });
        let mut outside = 0usize;
        for r in top..h {
            for c in 0..w {
                let q = [c as f64 + 0.5, r as f64 + 0.5];
                let in_ring = ring.len() < 3 || inside(&ring, q);
                let behind = plate.is_some_and(|pq| inside(&pq, q));
                if !in_ring || behind {
                    counts[[r, c]] = p.i0;
                    outside += 1;
                }
            }
        }
        // The true pixel solid fraction L_S/L (no blur, no noise): what Eq. 1 should return.
        let mut truth = coverage;
        for r in top..h {
            for c in 0..w {
                if counts[[r, c]] == p.i0 {
                    truth[[r, c]] = f64::NAN;
                }
            }
        }
        let tname = format!("truth/gs_pixel_{k:03}.tif");
        tio::write_f32(&out.join(&tname), truth.view())?;
        files.push(tname.into());
        let blurred = synth::gaussian_blur(counts.view(), p.blur_sigma_px);
        let img = if p.noise {
            synth::noisy_u16(blurred.view(), p.seed.wrapping_add(k as u64))?
        } else {
            blurred.mapv(|v| v.round().clamp(1.0, 65535.0) as u16)
        };
        let name = format!("frames/frame_{k:03}.tif");
        tio::write_u16(&out.join(&name), img.view())?;
        files.push(name.into());
        if p.plots && (k == 0 || k + 1 == states.len()) {
            plot::field_figure(
                out,
                format!("frame_{k:03}.png"),
                img.mapv(f64::from).view(),
                &FieldPlot {
                    title: &format!("synthetic radiograph of the run, frame {k}"),
                    label: "counts",
                    cmap: Colormap::Gray,
                    range: None,
                    pixel_size: Some(px),
                },
                format!(
                    "Beer-Lambert radiograph of run {} at {} (u_y = {:.2} d̄): 100 % solid strip (top), 100 % liquid \
                     strip, then the field of view; L = {:.0} µm, µ_S = {:.4e} 1/m, µ_L = {:.4e} 1/m, blur {} px, \
                     Poisson noise {}.",
                    run.dir.display(),
                    step.map_or("the start".to_string(), |s| format!("step {s}")),
                    u / d_bar,
                    thickness * 1e6,
                    p.mu_s,
                    p.mu_l,
                    p.blur_sigma_px,
                    p.noise
                ),
                &mut figures,
                &mut files,
            )?;
        }
        frames_json.push(json!({
            "frame": k, "step": step, "time_s": t, "u_y_d": u / d_bar, "circles": disks.len(),
            "pixels_outside_sample": outside,
        }));
        pb.inc(1);
    }
    pb.finish_and_clear();
    // The plate's face at frame 0, in pixels: columns of its corners, row of its face.
    let (pl_l, pl_r) = match run.plate {
        Some(pl) => {
            let (l, r) = pl.corners(0.0);
            (to_px(frame.from_scene(l)), to_px(frame.from_scene(r)))
        }
        None => (to_px([-0.5, 0.0]), to_px([0.5, 0.0])),
    };
    let solid_ref = [4usize, 4, 32, pad - 8];
    let liquid_ref = [4usize, pad + 4, 32, pad - 8];
    let fov = json!({
        "run": run.dir,
        "d_bar_m": d_bar,
        "pixel_size_m": px,
        "thickness_m": thickness,
        "mu_s": p.mu_s,
        "mu_l": p.mu_l,
        "plate_px": [pl_l[0], pl_r[0], pl_l[1]],
        "fov_d": [x0, x1, y0, y1],
        "fov_rows": [top, h],
        "solid_ref_roi": solid_ref,
        "liquid_ref_roi": liquid_ref,
        "i_s0_expected": p.i0 * (-p.mu_s * thickness).exp(),
        "i_l0_expected": p.i0 * (-p.mu_l * thickness).exp(),
        "frames": frames_json,
    });
    lbdem_core::atomic::write_atomic(&out.join(FOV), &serde_json::to_vec_pretty(&fov)?)?;
    files.push(FOV.into());
    let params = format!(
        "# Parameters for `lbdem radiograph` on these frames (written by synth-run).\n\
         frames = [\"frames\"]\n\
         i_s0_roi = {solid_ref:?}\n\
         i_l0_roi = {liquid_ref:?}\n\
         mu_s = {}\nmu_l = {}\nl_alloy0 = {thickness:e}\nd_bar = {d_bar:e}\npixel_size = {px:e}\n",
        p.mu_s, p.mu_l
    );
    lbdem_core::atomic::write_atomic(&out.join("radiograph.toml"), params.as_bytes())?;
    files.push("radiograph.toml".into());
    Ok(StageOutput {
        summary: json!({
            "frames": states.len(), "image_rows": h, "image_cols": w, "pixel_size_m": px, "d_bar_m": d_bar,
            "thickness_m": thickness, "plate_px": [pl_l[0], pl_r[0], pl_l[1]], "fov_d": [x0, x1, y0, y1],
        }),
        figures,
        tables: Vec::new(),
        files,
    })
}

/// Even-odd point-in-polygon test.
fn inside(poly: &[[f64; 2]], p: [f64; 2]) -> bool {
    let n = poly.len();
    let mut c = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) {
            c = !c;
        }
    }
    c
}
