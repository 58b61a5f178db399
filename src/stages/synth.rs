//! Stage `synth-radiograph`: synthetic radiographs of a disk assembly in liquid with a
//! known answer (forward Beer-Lambert model, `lbdem_imaging::synth`). Frame 0 is the
//! reference; frame k of N carries `k/(N-1)` of the prescribed displacement field and of
//! the prescribed thickness change. The true pixel and REV solid fractions and the true
//! volumetric strain (Eq. 5 on the true REV maps) are written beside the frames.
//!
//! Layout (rows from the top): a fully solid pad (for `I_S^0` and Eq. 3), the disk
//! assembly, a fully liquid pad (for `I_L^0` and Eq. 2 with `L_S.min = 0`).
//!
//! Attenuation defaults: NIST mass attenuation coefficients at 15 keV (Hubbell & Seltzer,
//! NISTIR 5632): Al 7.955 cm^2/g, Cu 74.05 cm^2/g, mixed by weight
//! (`mu = rho sum w_i (mu/rho)_i`). Phase densities and compositions are explicit inputs;
//! the defaults (solid alpha-Al 2700 kg/m^3 with no Cu, as REFERENCES.md; liquid
//! Al-33wt%Cu at 3400 kg/m^3) are illustrative assumptions, not measured values.

use crate::contract::{Stage, StageContext, StageOutput};
use crate::io::tiff as tio;
use crate::report::{plot, table};
use anyhow::{Context, Result, bail};
use lbdem_imaging::Roi;
use lbdem_imaging::beer_lambert::{self as bl, mixture_mu};
use lbdem_imaging::rev::{self, Sat};
use lbdem_imaging::synth::{self, Beam, Displacement, GrainShape};
use ndarray::Array2;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::PathBuf;

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    #[serde(default = "d::seed")]
    pub seed: u64,
    /// Image size, px.
    #[serde(default = "d::size")]
    pub width: usize,
    #[serde(default = "d::size")]
    pub height: usize,
    /// Number of frames (>= 2); frame 0 is undeformed.
    #[serde(default = "d::frames")]
    pub frames: usize,
    /// Pixel size and mean grain diameter, m.
    #[serde(default = "d::pixel_size")]
    pub pixel_size: f64,
    #[serde(default = "d::d_bar")]
    pub d_bar: f64,
    /// Diameters uniform in `d_bar (1 +- spread)`.
    #[serde(default = "d::spread")]
    pub spread: f64,
    /// How grains fill the thickness (default: spheres squeezed between the windows).
    #[serde(default)]
    pub grain_shape: GrainShape,
    /// Disk area fraction aimed at by random sequential addition in the assembly band.
    #[serde(default = "d::target")]
    pub target_fraction: f64,
    /// REV side factor (Su et al. 2020: sqrt(10)) for the true REV maps.
    #[serde(default = "d::sqrt10")]
    pub rev_factor: f64,
    /// Clipped border windows need this fraction of a full REV (as the `radiograph` stage).
    #[serde(default = "d::half")]
    pub min_valid: f64,
    /// eps_vol is NaN where the reference REV g_S is below this (liquid), as in `radiograph`.
    #[serde(default = "d::eps_min_gs")]
    pub eps_min_gs: f64,
    /// Sample thickness of frame 0, m, and relative change at the last frame.
    #[serde(default = "d::thickness0")]
    pub thickness0: f64,
    #[serde(default = "d::thickness_change")]
    pub thickness_change: f64,
    /// Photon energy, keV (a label: the attenuation coefficients below are for it).
    #[serde(default = "d::energy")]
    pub energy_kev: f64,
    /// Mass attenuation coefficients of Al and Cu at `energy_kev`, m^2/kg (NIST, 15 keV).
    #[serde(default = "d::mass_al")]
    pub mass_atten_al: f64,
    #[serde(default = "d::mass_cu")]
    pub mass_atten_cu: f64,
    /// Phase densities (kg/m^3) and Cu weight fractions.
    #[serde(default = "d::rho_s")]
    pub solid_density: f64,
    #[serde(default)]
    pub solid_cu_wt: f64,
    #[serde(default = "d::rho_l")]
    pub liquid_density: f64,
    #[serde(default = "d::w_l")]
    pub liquid_cu_wt: f64,
    /// Override the computed linear attenuation coefficients (1/m).
    #[serde(default)]
    pub mu_s: Option<f64>,
    #[serde(default)]
    pub mu_l: Option<f64>,
    /// Open-beam counts per pixel.
    #[serde(default = "d::i0")]
    pub i0: f64,
    /// Gaussian detector blur, px (0 = none).
    #[serde(default = "d::blur")]
    pub blur_sigma_px: f64,
    /// Poisson counting noise (off: expected counts rounded).
    #[serde(default = "d::yes")]
    pub noise: bool,
    /// Sample points per pixel side for the pixel coverage.
    #[serde(default = "d::ss")]
    pub supersample: usize,
    /// Height of the solid (top) and liquid (bottom) pads, px; the gap between pad and
    /// assembly is liquid.
    #[serde(default = "d::pad")]
    pub pad_px: usize,
    /// Displacement of the last frame (px units for the bump sigma).
    #[serde(default = "d::displacement")]
    pub displacement: Displacement,
    /// Write the frames as one multi-page stack `frames.tif` instead of numbered files.
    #[serde(default)]
    pub stack: bool,
    #[serde(default = "d::yes")]
    pub plots: bool,
}

/// Defaults (see the module documentation for their sources).
mod d {
    pub fn seed() -> u64 {
        20200311
    }
    pub fn size() -> usize {
        512
    }
    pub fn frames() -> usize {
        2
    }
    /// 5.1-5.6 mm FOV on 1024 px (Su et al. 2020 Sect. 2.1) is 5-5.5 um/px.
    pub fn pixel_size() -> f64 {
        6e-6
    }
    /// Su et al. (2020) Sect. 2.1: d_bar < 200 um.
    pub fn d_bar() -> f64 {
        180e-6
    }
    pub fn eps_min_gs() -> f64 {
        0.1
    }
    pub fn half() -> f64 {
        0.5
    }
    pub fn spread() -> f64 {
        0.2
    }
    pub fn target() -> f64 {
        0.5
    }
    pub fn sqrt10() -> f64 {
        10f64.sqrt()
    }
    /// Su et al. (2020) Fig. 12h: L_alloy^0 ~ 150 um.
    pub fn thickness0() -> f64 {
        150e-6
    }
    pub fn thickness_change() -> f64 {
        -0.05
    }
    pub fn energy() -> f64 {
        15.0
    }
    /// NIST (Hubbell & Seltzer) Al at 15 keV: 7.955 cm^2/g = 0.7955 m^2/kg.
    pub fn mass_al() -> f64 {
        0.7955
    }
    /// NIST (Hubbell & Seltzer) Cu at 15 keV: 74.05 cm^2/g = 7.405 m^2/kg.
    pub fn mass_cu() -> f64 {
        7.405
    }
    pub fn rho_s() -> f64 {
        2700.0
    }
    pub fn rho_l() -> f64 {
        3400.0
    }
    pub fn w_l() -> f64 {
        0.33
    }
    pub fn i0() -> f64 {
        30000.0
    }
    pub fn blur() -> f64 {
        0.7
    }
    pub fn yes() -> bool {
        true
    }
    pub fn ss() -> usize {
        4
    }
    pub fn pad() -> usize {
        48
    }
    pub fn displacement() -> super::Displacement {
        super::Displacement {
            strain_xx: 0.0,
            strain_yy: 0.01,
            bump_amplitude: 0.05,
            bump_sigma_px: 60.0,
        }
    }
}

pub struct SynthRadiograph;

/// Where the synthetic layout puts its pads and assembly.
pub struct Layout {
    pub solid_pad: Roi,
    pub liquid_pad: Roi,
    pub assembly: Roi,
    /// ROIs inset from the pads' edges (blur), for reference intensities and thickness.
    pub solid_ref: Roi,
    pub liquid_ref: Roi,
}

pub fn layout(p: &Params) -> Result<Layout> {
    let (w, h, pad) = (p.width, p.height, p.pad_px);
    let gap = pad / 3;
    let inset = 8.min(pad / 4).max(1);
    if pad < 8 || h < 2 * (pad + gap) + 16 || w < 4 * inset + 16 {
        bail!(
            "width x height = {w} x {h} px with pad_px = {pad} leaves no room for the assembly; \
             need pad_px >= 8 and height >= 2 (pad_px + pad_px/3) + 16"
        );
    }
    let solid_pad = Roi::new(0, 0, w, pad);
    let liquid_pad = Roi::new(0, h - pad, w, pad);
    let assembly = Roi::new(0, pad + gap, w, h - 2 * (pad + gap));
    Ok(Layout {
        solid_pad,
        liquid_pad,
        assembly,
        solid_ref: Roi::new(2 * inset, inset, w - 4 * inset, pad - 2 * inset),
        liquid_ref: Roi::new(2 * inset, h - pad + inset, w - 4 * inset, pad - 2 * inset),
    })
}

impl Params {
    /// `(mu_S, mu_L)` in 1/m: overrides, else NIST mass attenuation mixed by weight.
    pub fn mus(&self) -> (f64, f64) {
        let mu = |rho: f64, w_cu: f64| {
            mixture_mu(
                rho,
                &[(1.0 - w_cu, self.mass_atten_al), (w_cu, self.mass_atten_cu)],
            )
        };
        (
            self.mu_s
                .unwrap_or_else(|| mu(self.solid_density, self.solid_cu_wt)),
            self.mu_l
                .unwrap_or_else(|| mu(self.liquid_density, self.liquid_cu_wt)),
        )
    }
}

impl Stage for SynthRadiograph {
    const KIND: &'static str = "synth-radiograph";
    const ABOUT: &'static str =
        "Forward Beer-Lambert radiographs of a disk assembly with known g_S and eps_vol";
    type Params = Params;
    fn inputs(_: &Params, _: &StageContext) -> Vec<PathBuf> {
        Vec::new()
    }
    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        for (n, v) in [
            ("pixel_size", p.pixel_size),
            ("d_bar", p.d_bar),
            ("thickness0", p.thickness0),
            ("i0", p.i0),
            ("rev_factor", p.rev_factor),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                bail!("parameter '{n}' = {v} must be positive and finite (SI units)");
            }
        }
        if p.frames < 2 {
            bail!(
                "parameter 'frames' = {} must be at least 2 (a reference and a deformed frame)",
                p.frames
            );
        }
        if !(p.thickness_change > -0.9 && p.thickness_change < 1.0) {
            bail!(
                "parameter 'thickness_change' = {} must be in (-0.9, 1)",
                p.thickness_change
            );
        }
        if p.i0 > 65535.0 {
            bail!("parameter 'i0' = {} exceeds the 16-bit range 65535", p.i0);
        }
        let lay = layout(p)?;
        let (mu_s, mu_l) = p.mus();
        let beam = Beam { i0: p.i0, mu_s, mu_l };
        let rev_side = rev::rev_side_px(p.rev_factor, p.d_bar, p.pixel_size)?;
        if rev_side > p.width.min(p.height) {
            bail!(
                "REV side {rev_side} px is larger than the {}x{} image",
                p.width,
                p.height
            );
        }
        let d_px = p.d_bar / p.pixel_size;
        let disks0 = synth::pack_disks(lay.assembly, d_px, p.spread, p.target_fraction, p.seed)?;
        let centre = (
            lay.assembly.x as f64 + 0.5 * lay.assembly.w as f64,
            lay.assembly.y as f64 + 0.5 * lay.assembly.h as f64,
        );
        let out = &ctx.out_dir;
        let mut files: Vec<PathBuf> = Vec::new();
        let mut figures = Vec::new();
        let mut frames_u16 = Vec::new();
        let mut truth_rev0 = Array2::zeros((p.height, p.width));
        let mut per_frame = Vec::new();
        let pb = ctx.progress_bar(p.frames as u64, "synth");
        let mut sat = Sat::new();
        for k in 0..p.frames {
            let t = k as f64 / (p.frames - 1) as f64;
            let disp = Displacement {
                strain_xx: t * p.displacement.strain_xx,
                strain_yy: t * p.displacement.strain_yy,
                bump_amplitude: t * p.displacement.bump_amplitude,
                bump_sigma_px: p.displacement.bump_sigma_px,
            };
            let disks = disp.apply(&disks0, centre);
            let thickness = p.thickness0 * (1.0 + t * p.thickness_change);
            let (cov, expected) = synth::render(
                p.height,
                p.width,
                &disks,
                p.supersample,
                p.grain_shape,
                thickness / p.pixel_size,
                thickness,
                &beam,
                &[lay.solid_pad],
                &[lay.liquid_pad],
            );
            let blurred = synth::gaussian_blur(expected.view(), p.blur_sigma_px);
            let frame = if p.noise {
                synth::noisy_u16(blurred.view(), p.seed.wrapping_add(1 + k as u64))?
            } else {
                blurred.mapv(|v| v.round().clamp(1.0, 65535.0) as u16)
            };
            sat.build(cov.view());
            let rev_map = sat.rev_mean(rev_side, p.min_valid)?;
            let true_gs_global = cov.mean().unwrap_or(f64::NAN);
            tio::write_f32(&out.join(format!("true_gs_pixel_{k:03}.tif")), cov.view())?;
            tio::write_f32(&out.join(format!("true_gs_rev_{k:03}.tif")), rev_map.view())?;
            files.push(format!("true_gs_pixel_{k:03}.tif").into());
            files.push(format!("true_gs_rev_{k:03}.tif").into());
            let mut eps_mean = serde_json::Value::Null;
            if k == 0 {
                truth_rev0 = rev_map;
            } else {
                let eps = bl::eps_vol_field(truth_rev0.view(), rev_map.view(), p.eps_min_gs);
                let fin: Vec<f64> = eps.iter().copied().filter(|v| v.is_finite()).collect();
                eps_mean = json!(fin.iter().sum::<f64>() / fin.len().max(1) as f64);
                tio::write_f32(&out.join(format!("true_eps_vol_{k:03}.tif")), eps.view())?;
                files.push(format!("true_eps_vol_{k:03}.tif").into());
                if p.plots && k + 1 == p.frames {
                    let f = format!("true_eps_vol_{k:03}.png");
                    crate::report::plot::field_figure(
                        out,
                        f,
                        eps.view(),
                        &plot::FieldPlot {
                            title: &format!("True eps_vol, frame {k}"),
                            label: "eps_vol (-)",
                            cmap: plot::Colormap::Diverging,
                            range: None,
                            pixel_size: Some(p.pixel_size),
                        },
                        format!(
                            "Prescribed (true) volumetric strain of synthetic frame {k} (Eq. 5 on the true REV maps)."
                        ),
                        &mut figures,
                        &mut files,
                    )?;
                }
            }
            let xs: Vec<f64> = disks.iter().map(|d| d.x).collect();
            let ys: Vec<f64> = disks.iter().map(|d| d.y).collect();
            let rs: Vec<f64> = disks.iter().map(|d| d.r).collect();
            let dname = format!("disks_{k:03}.csv");
            table::write_csv(&out.join(&dname), &[("x_px", &xs), ("y_px", &ys), ("r_px", &rs)])?;
            files.push(dname.into());
            if p.plots && (k == 0 || k + 1 == p.frames) {
                let f = format!("frame_{k:03}.png");
                let ff = frame.mapv(f64::from);
                crate::report::plot::field_figure(
                    out,
                    f,
                    ff.view(),
                    &plot::FieldPlot {
                        title: &format!("Synthetic radiograph, frame {k}"),
                        label: "counts",
                        cmap: plot::Colormap::Gray,
                        range: None,
                        pixel_size: Some(p.pixel_size),
                    },
                    format!(
                        "Synthetic 16-bit radiograph {k}: solid pad (top), disk assembly, liquid pad (bottom); \
                         L = {:.1} um, blur {} px, Poisson noise {}.",
                        thickness * 1e6,
                        p.blur_sigma_px,
                        p.noise
                    ),
                    &mut figures,
                    &mut files,
                )?;
            }
            per_frame.push(json!({
                "frame": k,
                "thickness_m": thickness,
                "disks": disks.len(),
                "true_gs_global": true_gs_global,
                "true_eps_vol_mean": eps_mean,
            }));
            frames_u16.push(frame);
            pb.inc(1);
        }
        pb.finish_and_clear();
        if p.stack {
            let views: Vec<_> = frames_u16.iter().map(|f| f.view()).collect();
            tio::write_u16_stack(&out.join("frames.tif"), &views)?;
            files.push("frames.tif".into());
        } else {
            for (k, f) in frames_u16.iter().enumerate() {
                tio::write_u16(&out.join(format!("frame_{k:03}.tif")), f.view())?;
                files.push(format!("frame_{k:03}.tif").into());
            }
        }
        let summary = json!({
            "mu_s": mu_s,
            "mu_l": mu_l,
            "energy_kev": p.energy_kev,
            "rev_side_px": rev_side,
            "solid_ref_roi": lay.solid_ref,
            "liquid_ref_roi": lay.liquid_ref,
            "assembly_roi": lay.assembly,
            "i_s0_expected": p.i0 * (-mu_s * p.thickness0).exp(),
            "i_l0_expected": p.i0 * (-mu_l * p.thickness0).exp(),
            "per_frame": per_frame,
            "params": p,
        });
        lbdem_core::atomic::write_atomic(&out.join("truth.json"), &serde_json::to_vec_pretty(&summary)?)
            .with_context(|| format!("cannot write {}", out.join("truth.json").display()))?;
        files.push("truth.json".into());
        Ok(StageOutput {
            summary,
            figures,
            tables: Vec::new(),
            files,
        })
    }
}
