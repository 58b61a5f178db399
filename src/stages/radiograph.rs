//! Stage `radiograph`: TIFF frames to thickness-corrected solid fraction, REV maps and
//! volumetric strain (Su et al. 2020, Sect. 2.2, Eqs. 1-5), ROI profiles and the meniscus
//! line scan (Eqs. 2, 22, 23). Frame 0 is the reference (undeformed) frame.
//!
//! Everything that can be wrong with the input files' headers and the parameters (files, frame
//! count, sizes, sample types, ROIs, reference intensities, REV size) and with frame 0 is
//! checked before the first file is written. The later frames are then read, corrected and
//! processed one at a time, the next one read while the current one is processed, so a frame's
//! own pixels (not positive, a thickness that is not) can fail the run part-way: the pipeline
//! runs every stage in a staging directory that is removed on failure, so nothing is left.

use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::io::tiff as tio;
use crate::report::{plot, table};
use anyhow::{Context, Result, bail};
use lbdem_imaging::beer_lambert::{self as bl, FractionMap};
use lbdem_imaging::edge::{self, BulkPhase};
use lbdem_imaging::profile::{self, ProfileAxis};
use lbdem_imaging::rev::{self, Sat};
use lbdem_imaging::{Roi, correct};
use ndarray::{Array2, Zip, s};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::{Path, PathBuf};

/// How `L_alloy^n` of frame n is found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Thickness {
    /// `L^n = L^0` (no correction: only for a sample whose thickness cannot change).
    #[default]
    None,
    /// Eq. (2) over `thickness_roi`, a negligibly deformed or fully liquid region
    /// (`L_S.min^n = L_S.min^0`).
    Eq2,
    /// Eq. (3) over `thickness_roi`, a region of nearly 100% solid.
    Eq3,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Gamma {
    /// Median window side (odd, px).
    #[serde(default = "three")]
    pub size: usize,
    /// Outlier threshold in robust standard deviations.
    #[serde(default = "six")]
    pub threshold: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProfileSpec {
    pub name: String,
    /// `[x, y, w, h]` in pixels.
    pub roi: Roi,
    pub axis: ProfileAxis,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LineScan {
    /// Column of the vertical line (px) and its row range `y0..y1` (Fig. 12f).
    pub x: usize,
    pub y0: usize,
    pub y1: usize,
    /// Half-width (m) of the window around the thinnest point fitted by a parabola;
    /// 0 skips the meniscus fit.
    #[serde(default)]
    pub fit_half_width: f64,
    /// Liquid-air interfacial energy, J/m^2 (Su et al. 2020 take 0.7 for Al-Cu, ref. [123]).
    #[serde(default = "gamma_alcu")]
    pub gamma: f64,
}

/// Flagging the REVs that reach a bulk phase (`lbdem_imaging::edge`): a liquid gap, a
/// container wall, a solid pad, where eps_vol is less accurate than inside the assembly.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EdgeFlag {
    /// Write the flags (`near_edge_NNN.tif`, grid and profile columns, summary figures).
    #[serde(default = "yes")]
    pub enabled: bool,
    /// Side of the window that decides "bulk", in units of `d_bar` (two grains: liquid pockets
    /// of one grain inside a packing are not bulk).
    #[serde(default = "two")]
    pub window_d: f64,
    /// Window-mean pixel g_S below which a pixel is bulk liquid, above which bulk solid.
    #[serde(default = "bulk_liquid")]
    pub liquid_below: f64,
    #[serde(default = "bulk_solid")]
    pub solid_above: f64,
}

impl Default for EdgeFlag {
    fn default() -> Self {
        Self {
            enabled: true,
            window_d: 2.0,
            liquid_below: bulk_liquid(),
            solid_above: bulk_solid(),
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Frame files, multi-page stacks or directories of numbered frames; the first frame is
    /// the reference (n = 0).
    pub frames: Vec<PathBuf>,
    /// Dark-current frame (a stack is averaged).
    #[serde(default)]
    pub dark: Option<PathBuf>,
    /// Open-beam (flat-field) frame (a stack is averaged).
    #[serde(default)]
    pub flat: Option<PathBuf>,
    /// Gamma-spot removal, applied to frames, dark and flat before correction.
    #[serde(default)]
    pub gamma_spots: Option<Gamma>,
    /// Open-beam region for dose normalisation of every frame (`[x, y, w, h]`, px).
    #[serde(default)]
    pub open_roi: Option<Roi>,
    /// Treat pixels that are not positive after correction as masked instead of failing.
    #[serde(default)]
    pub mask_nonpositive: bool,
    /// `I_L^0`, through 100% liquid: a value (corrected intensity units) or an ROI of frame 0.
    #[serde(default)]
    pub i_l0: Option<f64>,
    #[serde(default)]
    pub i_l0_roi: Option<Roi>,
    /// `I_S^0`, through 100% solid: a value or an ROI of frame 0.
    #[serde(default)]
    pub i_s0: Option<f64>,
    #[serde(default)]
    pub i_s0_roi: Option<Roi>,
    /// Linear attenuation coefficients of solid and liquid, 1/m.
    pub mu_s: f64,
    pub mu_l: f64,
    /// Initial sample thickness `L_alloy^0`, m.
    pub l_alloy0: f64,
    #[serde(default)]
    pub thickness: Thickness,
    #[serde(default)]
    pub thickness_roi: Option<Roi>,
    /// Mean grain size `d_bar` and pixel size, m.
    pub d_bar: f64,
    pub pixel_size: f64,
    /// REV side = `rev_factor * d_bar` (Su et al. 2020: sqrt(10)).
    #[serde(default = "sqrt10")]
    pub rev_factor: f64,
    /// A REV with fewer finite pixels than this fraction of a full window is NaN.
    #[serde(default = "half")]
    pub min_valid: f64,
    /// eps_vol (Eq. 5) is NaN where the reference REV holds less solid than this (liquid:
    /// the ratio g^0/g^n of two near-zero fractions means nothing).
    #[serde(default = "eps_min_gs")]
    pub eps_min_gs: f64,
    /// Area of the global `g_S` average (Eq. 1b); the whole image by default.
    #[serde(default)]
    pub global_area: Option<Roi>,
    #[serde(default)]
    pub profiles: Vec<ProfileSpec>,
    #[serde(default)]
    pub line_scan: Option<LineScan>,
    /// PNG maps and plots (off for batch runs that only need the fields).
    #[serde(default = "yes")]
    pub plots: bool,
    /// Also write per-pixel fields (corrected intensity, pixel `L_S/L`).
    #[serde(default)]
    pub write_pixel_maps: bool,
    /// REVs near a bulk phase, flagged in the outputs (on by default).
    #[serde(default)]
    pub edge_flag: EdgeFlag,
    /// The REV, eps_vol and edge-flag maps hold the REV centred on the middle pixel of every
    /// `map_step` x `map_step` block (odd, px; 1 = every pixel). Default: the largest odd step
    /// at most a sixteenth of the REV side (`lbdem_imaging::rev::map_step_auto`; 11 px for a
    /// 190 px REV), so a 2048² frame writes 0.3 MB of maps instead of 36 MB.
    #[serde(default)]
    pub map_step: Option<usize>,
}

fn three() -> usize {
    3
}
fn six() -> f64 {
    6.0
}
fn gamma_alcu() -> f64 {
    0.7
}
fn sqrt10() -> f64 {
    10f64.sqrt()
}
fn eps_min_gs() -> f64 {
    0.1
}
fn half() -> f64 {
    0.5
}
fn two() -> f64 {
    2.0
}
fn bulk_liquid() -> f64 {
    0.05
}
fn bulk_solid() -> f64 {
    0.95
}
fn yes() -> bool {
    true
}

pub struct Radiograph;

impl Stage for Radiograph {
    const KIND: &'static str = "radiograph";
    const ABOUT: &'static str =
        "Radiographs to thickness-corrected solid fraction, REV maps and volumetric strain";
    type Params = Params;
    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        let frames: Vec<PathBuf> = p.frames.iter().map(|f| ctx.resolve(f)).collect();
        let mut v = tio::expand_paths(&frames).unwrap_or(frames);
        v.extend(p.dark.iter().chain(&p.flat).map(|f| ctx.resolve(f)));
        v
    }
    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        let prepared = prepare(p, ctx)?;
        write_outputs(p, ctx, prepared)
    }
}

/// Everything validated, frame 0 read and corrected and the references found; the later
/// frames are read and corrected one at a time on a thread of their own while the frame before
/// is processed ([`FrameSource`]), so a sequence of any length needs a few frames' memory (all
/// frames were held as f64 before: 32 MB per 2048² frame, 16 GB for 500 frames) and reading is
/// overlapped with the REV passes (issue 18 item 5).
pub struct Prepared {
    /// Every frame's label (`file` or `file#page`), from the headers.
    pub labels: Vec<String>,
    /// (rows, columns) of every frame.
    pub shape: (usize, usize),
    pub rev_side: usize,
    /// Pixels between the centres of the maps' cells (`Params::map_step` or its default).
    pub map_step: usize,
    /// Each profile's ROI as cells of the maps, in `Params::profiles` order.
    profile_cells: Vec<Roi>,
    pub i_l0: f64,
    pub i_s0: f64,
    /// Frame 0's mean corrected intensity over `thickness_roi` (NaN without one).
    troi0: f64,
    /// Eq. (1a) of frame 0.
    map0: FractionMap,
    pub warnings: Vec<String>,
    /// The bulk-phase rule of `edge_flag`, if enabled.
    pub bulk: Option<BulkPhase>,
    /// Every frame is 16-bit counts that no correction changes (no dark, flat, gamma spots or
    /// dose normalisation): frames stay 16-bit and go through a lookup table.
    pub counts: bool,
    /// Frame 0, corrected.
    first: Corrected,
    /// The frames after it, still to be read.
    source: FrameSource,
    dark: Option<Array2<f64>>,
    flat: Option<Array2<f64>>,
}

/// One frame after correction.
struct Corrected {
    label: String,
    /// The frame as 16-bit counts (a count of 0 is masked), when no correction changes them...
    counts: Option<Array2<u16>>,
    /// ...else its corrected intensity (NaN = masked).
    intensity: Option<Array2<f64>>,
    gamma_replaced: usize,
    dose: f64,
    masked: usize,
}

impl Corrected {
    /// The intensity as f64 (counts of 0 as NaN), borrowed when there is one.
    fn intensity(&self) -> std::borrow::Cow<'_, Array2<f64>> {
        match (&self.intensity, &self.counts) {
            (Some(i), _) => std::borrow::Cow::Borrowed(i),
            (None, Some(c)) => {
                std::borrow::Cow::Owned(c.mapv(|v| if v == 0 { f64::NAN } else { f64::from(v) }))
            }
            (None, None) => unreachable!("a corrected frame holds counts or an intensity"),
        }
    }

    /// Mean intensity over `roi` (masked pixels left out), without converting the whole frame.
    fn roi_mean(&self, name: &str, roi: Roi) -> Result<f64> {
        match (&self.intensity, &self.counts) {
            (Some(i), _) => Ok(roi.mean(name, i.view())?),
            (None, Some(c)) => {
                roi.check(name, c.dim())?;
                let sub = c.slice(s![roi.y..roi.y + roi.h, roi.x..roi.x + roi.w]);
                let sub = sub.mapv(|v| if v == 0 { f64::NAN } else { f64::from(v) });
                Ok(Roi::new(0, 0, roi.w, roi.h).mean(name, sub.view())?)
            }
            (None, None) => unreachable!("a corrected frame holds counts or an intensity"),
        }
    }

    /// Column `x`, rows `y0..y1`, as intensities (the line scan).
    fn column(&self, x: usize, y0: usize, y1: usize) -> Array2<f64> {
        match (&self.intensity, &self.counts) {
            (Some(i), _) => i.slice(s![y0..y1, x..x + 1]).to_owned(),
            (None, Some(c)) => c
                .slice(s![y0..y1, x..x + 1])
                .mapv(|v| if v == 0 { f64::NAN } else { f64::from(v) }),
            (None, None) => unreachable!("a corrected frame holds counts or an intensity"),
        }
    }
}

/// The frames of the input files in order, one page at a time (a stack's pages one by one).
struct FrameSource {
    files: std::vec::IntoIter<PathBuf>,
    pages: Option<tio::Pages<std::io::BufReader<std::fs::File>>>,
}

impl FrameSource {
    fn new(files: Vec<PathBuf>) -> Self {
        Self {
            files: files.into_iter(),
            pages: None,
        }
    }
}

impl Iterator for FrameSource {
    type Item = Result<tio::Page>;
    fn next(&mut self) -> Option<Result<tio::Page>> {
        loop {
            if let Some(page) = self.pages.as_mut().and_then(Iterator::next) {
                return Some(page);
            }
            let file = self.files.next()?;
            match tio::pages(&file) {
                Ok(p) => self.pages = Some(p),
                Err(e) => return Some(Err(e)),
            }
        }
    }
}

/// Correct one frame (gamma spots, dark and flat fields, dose, positivity), as its own job:
/// `counts` keeps 16-bit frames as they are.
fn correct_frame(
    p: &Params,
    page: tio::Page,
    dark: Option<&Array2<f64>>,
    flat: Option<&Array2<f64>>,
    counts: bool,
) -> Result<Corrected> {
    let label = page.label;
    if counts && let tio::Pixels::U16(c) = page.pixels {
        let zeros = c.par_iter().filter(|&&v| v == 0).count();
        if zeros > 0 && !p.mask_nonpositive {
            // The same refusal as a corrected frame's, naming the first such pixel.
            let mut i = c.mapv(f64::from);
            correct::check_positive(&mut i, &format!("frame {label}"), false)?;
        }
        return Ok(Corrected {
            label,
            counts: Some(c),
            intensity: None,
            gamma_replaced: 0,
            dose: 1.0,
            masked: zeros,
        });
    }
    let mut raw = page.pixels.into_f64();
    let mut n_g = 0;
    if let Some(g) = &p.gamma_spots {
        (raw, n_g) = correct::remove_gamma_spots(raw.view(), g.size, g.threshold)?;
    }
    // Without dark and flat fields the frame is its own corrected intensity: no copy.
    let mut i = if dark.is_none() && flat.is_none() {
        raw
    } else {
        correct::flat_dark(raw.view(), dark.map(|d| d.view()), flat.map(|d| d.view()))
    };
    let dose = match p.open_roi {
        Some(r) => correct::dose_normalise(&mut i, r).with_context(|| format!("frame {label}"))?,
        None => 1.0,
    };
    let masked = correct::check_positive(&mut i, &format!("frame {label}"), p.mask_nonpositive)?;
    Ok(Corrected {
        label,
        counts: None,
        intensity: Some(i),
        gamma_replaced: n_g,
        dose,
        masked,
    })
}

/// `L_alloy^n` of a later frame by the chosen method, and its Eq. (4) map.
fn thickness_and_map(
    p: &Params,
    i_l0: f64,
    troi0: f64,
    n: usize,
    f: &Corrected,
) -> Result<(f64, FractionMap)> {
    let l = match (p.thickness, p.thickness_roi) {
        (Thickness::None, _) | (_, None) => p.l_alloy0,
        (Thickness::Eq2, Some(r)) => {
            let m = f.roi_mean("thickness_roi", r)?;
            bl::thickness_eq2(p.l_alloy0, p.mu_s, p.mu_l, troi0, m, 0.0, 0.0)
        }
        (Thickness::Eq3, Some(r)) => {
            let m = f.roi_mean("thickness_roi", r)?;
            bl::thickness_eq3(p.l_alloy0, p.mu_s, troi0, m)
        }
    };
    if !(l > 0.0 && l.is_finite()) {
        bail!(
            "frame {}: thickness L_alloy^{n} = {l} m from {:?} over thickness_roi is not positive; \
             check thickness_roi (fully liquid for eq2, fully solid for eq3) and mu_s/mu_l",
            f.label,
            p.thickness
        );
    }
    let map = FractionMap::eq4(i_l0, p.mu_s, p.mu_l, p.l_alloy0, l)
        .map_err(|e| anyhow::anyhow!("frame {}: {e}", f.label))?;
    Ok((l, map))
}

/// A rectangle of pixels as the cells of a map of `step` px cells (`dims` cells): the cells whose
/// centre pixel `k step + step/2` lies inside it, refused if none does.
fn on_map(roi: Roi, step: usize, dims: (usize, usize)) -> Result<Roi> {
    let first = |px: usize| (px + step - 1 - step / 2) / step;
    let span = |from: usize, len: usize, n: usize| {
        let (a, b) = (first(from).min(n), first(from + len).min(n));
        (a, b.saturating_sub(a))
    };
    let (x, w) = span(roi.x, roi.w, dims.1);
    let (y, h) = span(roi.y, roi.h, dims.0);
    if w == 0 || h == 0 {
        bail!(
            "the rectangle {:?} (px) holds the centre of no {step} px map cell",
            <[usize; 4]>::from(roi)
        );
    }
    Ok(Roi::new(x, y, w, h))
}

fn positive(name: &str, v: f64) -> Result<()> {
    if !(v > 0.0 && v.is_finite()) {
        bail!("parameter '{name}' = {v} must be positive and finite (SI units)");
    }
    Ok(())
}

fn one_of(name: &str, value: Option<f64>, roi: Option<Roi>) -> Result<()> {
    match (value, roi) {
        (Some(_), None) | (None, Some(_)) => Ok(()),
        _ => bail!(
            "give exactly one of '{name}' (a value) and '{name}_roi' (a rectangle [x, y, w, h] of frame 0)"
        ),
    }
}

/// Read, validate and correct every input; no file is written here.
pub fn prepare(p: &Params, ctx: &StageContext) -> Result<Prepared> {
    for (n, v) in [
        ("mu_s", p.mu_s),
        ("mu_l", p.mu_l),
        ("l_alloy0", p.l_alloy0),
        ("d_bar", p.d_bar),
        ("pixel_size", p.pixel_size),
        ("rev_factor", p.rev_factor),
    ] {
        positive(n, v)?;
    }
    if !(p.min_valid > 0.0 && p.min_valid <= 1.0) {
        bail!("parameter 'min_valid' = {} must be in (0, 1]", p.min_valid);
    }
    if p.mu_s == p.mu_l {
        bail!(
            "parameters 'mu_s' and 'mu_l' are both {}: with no contrast no solid fraction can be measured",
            p.mu_s
        );
    }
    if p.frames.is_empty() {
        bail!("parameter 'frames' is empty: list at least one TIFF file, stack or directory");
    }
    one_of("i_l0", p.i_l0, p.i_l0_roi)?;
    one_of("i_s0", p.i_s0, p.i_s0_roi)?;
    let bulk = if p.edge_flag.enabled {
        positive("edge_flag.window_d", p.edge_flag.window_d)?;
        let rule = BulkPhase {
            window_px: ((p.edge_flag.window_d * p.d_bar / p.pixel_size).round() as usize).max(1),
            liquid_below: p.edge_flag.liquid_below,
            solid_above: p.edge_flag.solid_above,
        };
        rule.validate()?;
        Some(rule)
    } else {
        None
    };
    if p.thickness != Thickness::None && p.thickness_roi.is_none() {
        bail!(
            "thickness = \"{:?}\" needs 'thickness_roi' = [x, y, w, h]",
            p.thickness
        );
    }

    let paths: Vec<PathBuf> = p.frames.iter().map(|f| ctx.resolve(f)).collect();
    // Every page's header first: the number of frames and their sizes and sample types are
    // checked before a pixel is decoded; the pixels are read one frame at a time later.
    let files = tio::expand_paths(&paths)?;
    let heads: Vec<Result<Vec<tio::PageInfo>>> = files.par_iter().map(|f| tio::probe_pages(f)).collect();
    let mut infos = Vec::new();
    for h in heads {
        infos.extend(h?);
    }
    // 16-bit counts that no correction changes stay 16-bit and go through a lookup table (one
    // load per pixel instead of a logarithm) in `write_outputs`.
    let counts = infos.iter().all(|f| f.bits == 16)
        && p.dark.is_none()
        && p.flat.is_none()
        && p.gamma_spots.is_none()
        && p.open_roi.is_none();
    let shape = (infos[0].rows, infos[0].cols);
    for f in &infos[1..] {
        if (f.rows, f.cols) != shape {
            bail!(
                "frame {} is {}x{} (rows x cols) but the first frame {} is {}x{}; all frames must have one size",
                f.label,
                f.rows,
                f.cols,
                infos[0].label,
                shape.0,
                shape.1
            );
        }
    }
    let read_ref = |o: &Option<PathBuf>, what: &str| -> Result<Option<Array2<f64>>> {
        let Some(path) = o else { return Ok(None) };
        let f = tio::read_mean(&ctx.resolve(path)).with_context(|| format!("parameter '{what}'"))?;
        if f.data.dim() != shape {
            bail!(
                "{what} field {} is {}x{} but the frames are {}x{}",
                f.label,
                f.data.nrows(),
                f.data.ncols(),
                shape.0,
                shape.1
            );
        }
        Ok(Some(f.data))
    };
    let mut dark = read_ref(&p.dark, "dark")?;
    let mut flat = read_ref(&p.flat, "flat")?;

    let rev_side = rev::rev_side_px(p.rev_factor, p.d_bar, p.pixel_size)?;
    if rev_side > shape.0 || rev_side > shape.1 {
        bail!(
            "REV side {rev_side} px (rev_factor {} x d_bar {} m / pixel_size {} m) is larger than the {}x{} image; \
             lower d_bar or rev_factor, or use a larger field of view",
            p.rev_factor,
            p.d_bar,
            p.pixel_size,
            shape.1,
            shape.0
        );
    }
    let map_step = p.map_step.unwrap_or_else(|| rev::map_step_auto(rev_side));
    if map_step == 0 || (map_step > 1 && map_step.is_multiple_of(2)) || map_step > rev_side {
        bail!(
            "parameter 'map_step' = {map_step} px: must be odd (each map value is the REV at the \
             centre pixel of its block), at least 1 and at most the REV side {rev_side} px; \
             leave it out for the default {}",
            rev::map_step_auto(rev_side)
        );
    }
    let mut rois: Vec<(&str, Roi)> = Vec::new();
    rois.extend(p.open_roi.map(|r| ("open_roi", r)));
    rois.extend(p.i_l0_roi.map(|r| ("i_l0_roi", r)));
    rois.extend(p.i_s0_roi.map(|r| ("i_s0_roi", r)));
    rois.extend(p.thickness_roi.map(|r| ("thickness_roi", r)));
    rois.extend(p.global_area.map(|r| ("global_area", r)));
    for pr in &p.profiles {
        rois.push(("profiles.roi", pr.roi));
    }
    for (name, r) in &rois {
        r.check(name, shape)
            .map_err(|e| anyhow::anyhow!("parameter '{name}': {e}"))?;
    }
    let profile_cells = p
        .profiles
        .iter()
        .map(|pr| {
            on_map(pr.roi, map_step, (shape.0 / map_step, shape.1 / map_step)).map_err(|e| {
                anyhow::anyhow!("profile '{}': {e}; widen its 'roi' or lower 'map_step'", pr.name)
            })
        })
        .collect::<Result<Vec<Roi>>>()?;
    if let Some(ls) = &p.line_scan {
        if ls.x >= shape.1 || ls.y0 + 3 > ls.y1 || ls.y1 > shape.0 {
            bail!(
                "line_scan x = {}, y0 = {}, y1 = {} is outside the {}x{} image or shorter than 3 px; \
                 need x < {} and y0 + 3 <= y1 <= {}",
                ls.x,
                ls.y0,
                ls.y1,
                shape.1,
                shape.0,
                shape.1,
                shape.0
            );
        }
        if ls.fit_half_width < 0.0 || !ls.gamma.is_finite() {
            bail!("line_scan.fit_half_width must be >= 0 m and line_scan.gamma finite (J/m^2)");
        }
    }

    // Corrections.
    if let Some(g) = &p.gamma_spots {
        for f in [&mut dark, &mut flat].into_iter().flatten() {
            *f = correct::remove_gamma_spots(f.view(), g.size, g.threshold)?.0;
        }
    }
    let mut source = FrameSource::new(files);
    let page0 = source
        .next()
        .context("no frame to read: the frame files hold no pages")??;
    let first = correct_frame(p, page0, dark.as_ref(), flat.as_ref(), counts)?;

    // Reference intensities and Eq. (1a).
    let i_l0 = match (p.i_l0, p.i_l0_roi) {
        (Some(v), _) => v,
        (_, Some(r)) => first.roi_mean("i_l0_roi", r)?,
        _ => unreachable!("checked by one_of"),
    };
    let i_s0 = match (p.i_s0, p.i_s0_roi) {
        (Some(v), _) => v,
        (_, Some(r)) => first.roi_mean("i_s0_roi", r)?,
        _ => unreachable!("checked by one_of"),
    };
    let map0 = FractionMap::eq1(i_l0, i_s0).map_err(|e| anyhow::anyhow!("parameters 'i_l0'/'i_s0': {e}"))?;
    let mut warnings = Vec::new();
    let dmu_ref = (i_s0.ln() - i_l0.ln()) / p.l_alloy0;
    let dmu = p.mu_l - p.mu_s;
    if ((dmu_ref - dmu) / dmu).abs() > 0.1 {
        warnings.push(format!(
            "the reference intensities give mu_L - mu_S = (ln I_S^0 - ln I_L^0) / L^0 = {dmu_ref:.4e} 1/m but \
             mu_l - mu_s = {dmu:.4e} 1/m: frame 0 (Eq. 1a) and later frames (Eq. 4b) disagree in scale, so \
             eps_vol is biased; check mu_s, mu_l, l_alloy0 and the reference ROIs"
        ));
    }
    let troi0 = match (p.thickness, p.thickness_roi) {
        (Thickness::None, _) | (_, None) => f64::NAN,
        (_, Some(r)) => first.roi_mean("thickness_roi", r)?,
    };
    Ok(Prepared {
        labels: infos.into_iter().map(|i| i.label).collect(),
        shape,
        rev_side,
        map_step,
        profile_cells,
        i_l0,
        i_s0,
        troi0,
        map0,
        warnings,
        bulk,
        counts,
        first,
        source,
        dark,
        flat,
    })
}

/// The summary's means of one frame, from one pass over its maps: the finite REV g_S, the
/// finite eps_vol, and of those how many are flagged near a bulk phase and the mean of the rest.
/// Rows are summed in parallel and the row totals added in row order, so the figures do not
/// depend on the number of threads (it was three serial passes over each 2048² map).
#[derive(Default, Clone, Copy)]
struct FrameStats {
    g_sum: f64,
    g_n: usize,
    eps_sum: f64,
    eps_n: usize,
    flagged: usize,
    away_sum: f64,
}

impl FrameStats {
    fn of(g: &Array2<f64>, eps: Option<&Array2<f64>>, near: Option<&Array2<u8>>) -> Self {
        let rows: Vec<FrameStats> = (0..g.nrows())
            .into_par_iter()
            .map(|r| {
                let mut st = FrameStats::default();
                for &v in g.row(r).iter().filter(|v| v.is_finite()) {
                    st.g_sum += v;
                    st.g_n += 1;
                }
                if let Some(eps) = eps {
                    let flags = near.map(|f| f.row(r));
                    for (c, &e) in eps.row(r).iter().enumerate() {
                        if !e.is_finite() {
                            continue;
                        }
                        st.eps_sum += e;
                        st.eps_n += 1;
                        match flags.map(|f| f[c] > 0) {
                            Some(true) => st.flagged += 1,
                            _ => st.away_sum += e,
                        }
                    }
                }
                st
            })
            .collect();
        rows.iter().fold(FrameStats::default(), |a, b| FrameStats {
            g_sum: a.g_sum + b.g_sum,
            g_n: a.g_n + b.g_n,
            eps_sum: a.eps_sum + b.eps_sum,
            eps_n: a.eps_n + b.eps_n,
            flagged: a.flagged + b.flagged,
            away_sum: a.away_sum + b.away_sum,
        })
    }

    fn ratio(sum: f64, n: usize) -> f64 {
        if n == 0 { f64::NAN } else { sum / n as f64 }
    }

    fn g_mean(&self) -> f64 {
        Self::ratio(self.g_sum, self.g_n)
    }

    fn eps_mean(&self) -> f64 {
        Self::ratio(self.eps_sum, self.eps_n)
    }

    /// The share of the REVs with an eps_vol that are flagged.
    fn near_fraction(&self) -> f64 {
        Self::ratio(self.flagged as f64, self.eps_n)
    }

    fn eps_away_mean(&self) -> f64 {
        Self::ratio(self.away_sum, self.eps_n - self.flagged)
    }
}

/// One profile of one frame: positions (px), REV g_S, and eps_vol (frames n >= 1).
/// Position, g_S, eps_vol and the fraction of the ROI's REVs flagged near a bulk phase.
type ProfileOut = (Vec<f64>, Vec<f64>, Option<Vec<f64>>, Option<Vec<f64>>);

/// Per-frame results kept for the tables.
struct FrameOut {
    gs_tiles: Array2<f64>,
    eps_tiles: Option<Array2<f64>>,
    /// Tiles holding a bulk-phase pixel of frame 0 or this frame (eps frames only).
    edge_tiles: Option<Array2<f64>>,
    profiles: Vec<ProfileOut>,
}

/// A map waiting to be written: a field (32-bit float TIFF) or a flag (8-bit).
enum Map {
    F32(Array2<f64>),
    U8(Array2<u8>),
}

/// The float maps encoded and written on a second thread while the next frame is computed:
/// writing them was half of the stage's time on 2048² frames (issue 18 item 5). At most two maps
/// wait; dropping the writer (an error in the loop) waits for the maps already sent, so nothing
/// is written into the stage's directory after the stage returned.
struct MapWriter {
    tx: Option<std::sync::mpsc::SyncSender<(PathBuf, Map)>>,
    handle: Option<std::thread::JoinHandle<Result<()>>>,
    /// Float maps written, handed back for the next frame: a fresh 2048² buffer costs its page
    /// faults on first touch and its unmapping when dropped (`munmap` alone was a fifth of the
    /// time in system calls of `bench radiograph`, by `strace -c -f`).
    spare: std::sync::mpsc::Receiver<Array2<f64>>,
}

impl MapWriter {
    fn new() -> Self {
        let (tx, rx) = std::sync::mpsc::sync_channel::<(PathBuf, Map)>(2);
        let (back, spare) = std::sync::mpsc::sync_channel::<Array2<f64>>(4);
        let handle = std::thread::spawn(move || {
            for (path, map) in rx {
                match map {
                    Map::F32(m) => {
                        tio::write_f32(&path, m.view())?;
                        let _ = back.try_send(m);
                    }
                    Map::U8(m) => tio::write_u8(&path, m.view())?,
                }
            }
            Ok(())
        });
        Self {
            tx: Some(tx),
            handle: Some(handle),
            spare,
        }
    }

    /// A buffer of `shape` for the next map: one the writer is done with, else a new one. Its
    /// contents are stale; the REV passes overwrite every element.
    fn buffer(&self, shape: (usize, usize)) -> Array2<f64> {
        self.spare
            .try_recv()
            .ok()
            .filter(|a| a.dim() == shape && a.is_standard_layout())
            .unwrap_or_else(|| Array2::zeros(shape))
    }

    fn write(&mut self, path: PathBuf, map: Array2<f64>) -> Result<()> {
        self.send(path, Map::F32(map))
    }

    /// A 0/1 flag map, as 8-bit (a quarter of the bytes of a float map).
    fn write_u8(&mut self, path: PathBuf, map: Array2<u8>) -> Result<()> {
        self.send(path, Map::U8(map))
    }

    fn send(&mut self, path: PathBuf, map: Map) -> Result<()> {
        let sent = self.tx.as_ref().is_some_and(|tx| tx.send((path, map)).is_ok());
        if sent { Ok(()) } else { self.finish() }
    }

    /// Wait for every map sent; the first write error, if any.
    fn finish(&mut self) -> Result<()> {
        drop(self.tx.take());
        match self.handle.take() {
            Some(h) => h
                .join()
                .map_err(|_| anyhow::anyhow!("the thread writing the float maps panicked"))?,
            None => Ok(()),
        }
    }
}

impl Drop for MapWriter {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}

fn write_outputs(p: &Params, ctx: &StageContext, pr: Prepared) -> Result<StageOutput> {
    let out = &ctx.out_dir;
    let mut files: Vec<PathBuf> = Vec::new();
    let mut figures = Vec::new();
    let mut tables = Vec::new();
    let nf = pr.labels.len();
    let shape = pr.shape;
    let area = p.global_area.unwrap_or(Roi::new(0, 0, shape.1, shape.0));
    let png_frame = |n: usize| p.plots && (nf <= 8 || n == 0 || n + 1 == nf);
    let mm = |px: f64| px * p.pixel_size * 1e3;

    // The later frames are read and corrected on their own thread, one ahead of the frame being
    // processed. If this loop stops on an error the channel closes and the reader stops too; it
    // only reads, so nothing is left in the stage's directory.
    let mut frames = {
        let (tx, rx) = std::sync::mpsc::sync_channel::<Result<Corrected>>(1);
        let (params, source, counts) = (p.clone(), pr.source, pr.counts);
        let (dark, flat) = (pr.dark, pr.flat);
        std::thread::spawn(move || {
            for page in source {
                let c = page.and_then(|pg| {
                    if pg.pixels.dim() != shape {
                        let (r, c) = pg.pixels.dim();
                        bail!(
                            "frame {} is {r}x{c} (rows x cols) but its header and the first frame say {}x{}",
                            pg.label,
                            shape.0,
                            shape.1
                        );
                    }
                    correct_frame(&params, pg, dark.as_ref(), flat.as_ref(), counts)
                });
                let failed = c.is_err();
                if tx.send(c).is_err() || failed {
                    break;
                }
            }
        });
        let mut first = Some(pr.first);
        move |n: usize| -> Result<Corrected> {
            match first.take() {
                Some(f) if n == 0 => Ok(f),
                _ => rx.recv().map_err(|_| {
                    anyhow::anyhow!(
                        "frame {n}: the thread reading the frames stopped before it (the files changed?)"
                    )
                })?,
            }
        }
    };
    let pb = ctx.progress_bar(nf as u64, "radiograph");
    let mut sat = Sat::new();
    let step = pr.map_step;
    let mshape = (shape.0 / step, shape.1 / step);
    let mut g0_rev = Array2::zeros(mshape);
    let mut g_rev = Array2::zeros(mshape);
    let mut frames_json = Vec::new();
    let mut outs = Vec::new();
    let mut maps = MapWriter::new();
    let mut flagger = pr.bulk.map(|b| edge::Flagger::new(b, pr.rev_side)).transpose()?;
    let mut eps_buf = Array2::zeros(mshape);
    let mut lines = Vec::new();
    for n in 0..nf {
        let fr = frames(n)?;
        let (thickness, map) = if n == 0 {
            (p.l_alloy0, pr.map0)
        } else {
            thickness_and_map(p, pr.i_l0, pr.troi0, n, &fr)?
        };
        if let Some(ls) = &p.line_scan {
            lines.push(fr.column(ls.x, ls.y0, ls.y1));
        }
        match (&fr.counts, p.write_pixel_maps) {
            // The pixel fraction of every count from a table, straight into the summed-area
            // table: no logarithm per pixel and no pixel-fraction field (issue 18 item 5).
            (Some(c), false) => sat.build_u16(c.view(), &map.lut_u16()),
            _ => {
                let intensity = fr.intensity();
                let gpix = map.field(intensity.view());
                sat.build(gpix.view());
                if p.write_pixel_maps {
                    for (name, f) in [("intensity", intensity.into_owned()), ("gs_pixel", gpix)] {
                        let fname = format!("{name}_{n:03}.tif");
                        maps.write(out.join(&fname), f)?;
                        files.push(fname.into());
                    }
                }
            }
        }
        let global = sat.area_mean(area)?;
        // REV map on the map grid and, for later frames, Eq. (5) in the same pass.
        if n == 0 {
            sat.rev_grid_into(pr.rev_side, p.min_valid, step, &mut g0_rev, None)?;
        } else {
            sat.rev_grid_into(
                pr.rev_side,
                p.min_valid,
                step,
                &mut g_rev,
                Some((g0_rev.view(), p.eps_min_gs, &mut eps_buf)),
            )?;
        }
        let gs_tiles = sat.tiles(pr.rev_side, p.min_valid)?;
        let gname = format!("gs_rev_{n:03}");
        let gmap = if n == 0 { &g0_rev } else { &g_rev };
        files.push(format!("{gname}.tif").into());
        if let Some(f) = flagger.as_mut() {
            f.frame(&sat)?;
        }
        let near_owned = flagger.as_ref().filter(|_| n > 0).map(|f| f.near_grid_u8(step));
        let near = near_owned.as_ref();
        let mut eps_json = serde_json::Value::Null;
        let mut eps_away_json = serde_json::Value::Null;
        let mut near_json = serde_json::Value::Null;
        let mut edge_tiles = None;
        let mut eps_tiles = None;
        let eps = (n > 0).then_some(&eps_buf);
        let stats = FrameStats::of(gmap, eps, near);
        if let Some(eps) = eps {
            let ename = format!("eps_vol_{n:03}");
            files.push(format!("{ename}.tif").into());
            eps_json = json!(stats.eps_mean());
            if let (Some(_), Some(flagger)) = (near, &flagger) {
                files.push(format!("near_edge_{n:03}.tif").into());
                near_json = json!(stats.near_fraction());
                eps_away_json = json!(stats.eps_away_mean());
                edge_tiles = Some(flagger.tiles());
            }
            let g0t = outs
                .first()
                .map(|o: &FrameOut| o.gs_tiles.clone())
                .unwrap_or_default();
            eps_tiles = Some(bl::eps_vol_field(g0t.view(), gs_tiles.view(), p.eps_min_gs));
            if png_frame(n) {
                let f = format!("{ename}.png");
                crate::report::plot::field_figure(
                    out,
                    f,
                    eps.view(),
                    &plot::FieldPlot {
                        title: &format!("eps_vol, frame {n} (Eq. 5)"),
                        label: "eps_vol (-)",
                        cmap: plot::Colormap::Diverging,
                        range: None,
                        pixel_size: Some(p.pixel_size * step as f64),
                    },
                    format!(
                        "Volumetric strain eps_vol = g_S.REV^0 / g_S.REV^{n} - 1 (Eq. 5) of frame {n} ({}); \
                         positive = dilation. REV {} px.",
                        pr.labels[n], pr.rev_side
                    ),
                    &mut figures,
                    &mut files,
                )?;
            }
        }
        if png_frame(n) {
            let f = format!("{gname}.png");
            crate::report::plot::field_figure(
                out,
                f,
                gmap.view(),
                &plot::FieldPlot {
                    title: &format!("g_S.REV, frame {n}"),
                    label: "g_S (-)",
                    cmap: plot::Colormap::Viridis,
                    range: None,
                    pixel_size: Some(p.pixel_size * step as f64),
                },
                format!(
                    "REV-averaged solid fraction g_S.REV of frame {n} ({}), Eq. ({}), REV side {} px = {:.3} x d_bar.",
                    pr.labels[n],
                    if n == 0 { "1" } else { "4b" },
                    pr.rev_side,
                    p.rev_factor
                ),
                &mut figures,
                &mut files,
            )?;
        }
        let mut profs = Vec::new();
        for (spec, &roi) in p.profiles.iter().zip(&pr.profile_cells) {
            // The ROI's map cells; positions back in pixels (a cell's centre, Sat::rev_grid_into).
            let (pos, g) = profile::roi_profile(gmap.view(), roi, spec.axis, "profiles.roi")?;
            let pos = pos.iter().map(|&k| k * step as f64).collect();
            let e = match eps {
                Some(e) => Some(profile::roi_profile(e.view(), roi, spec.axis, "profiles.roi")?.1),
                None => None,
            };
            // The flag's share across the ROI: the profile of the ROI's flags alone, over the
            // REVs with an eps_vol (as the summary's near_edge_fraction): an REV without one is
            // neither near an edge nor away from it, so its flag is NaN and left out.
            let f = match (near, eps) {
                (Some(f), Some(e)) => {
                    roi.check("profiles.roi", f.dim())?;
                    let r = roi;
                    let win = s![r.y..r.y + r.h, r.x..r.x + r.w];
                    let sub = Zip::from(f.slice(win))
                        .and(e.slice(win))
                        .map_collect(|&f, &e| if e.is_finite() { f64::from(f) } else { f64::NAN });
                    let whole = Roi::new(0, 0, roi.w, roi.h);
                    Some(profile::roi_profile(sub.view(), whole, spec.axis, "profiles.roi")?.1)
                }
                _ => None,
            };
            profs.push((pos, g, e, f));
        }
        frames_json.push(json!({
            "frame": n,
            "label": pr.labels[n],
            "thickness_m": thickness,
            "i_l_n": pr.i_l0 * (-p.mu_l * (thickness - p.l_alloy0)).exp(),
            "g_s_global": global,
            "g_s_rev_mean": stats.g_mean(),
            "eps_vol_mean": eps_json,
            "near_edge_fraction": near_json,
            "eps_vol_mean_away_from_edges": eps_away_json,
            "dose_divisor": fr.dose,
            "gamma_spots_replaced": fr.gamma_replaced,
            "masked_pixels": fr.masked,
        }));
        outs.push(FrameOut {
            gs_tiles,
            eps_tiles,
            edge_tiles,
            profiles: profs,
        });
        // The maps go to the writer thread by move, not copy; fresh buffers take their place.
        let gpath = out.join(format!("{gname}.tif"));
        if n == 0 {
            maps.write(gpath, g0_rev.clone())?;
        } else {
            let (g_next, e_next) = (maps.buffer(mshape), maps.buffer(mshape));
            maps.write(gpath, std::mem::replace(&mut g_rev, g_next))?;
            let epath = out.join(format!("eps_vol_{n:03}.tif"));
            maps.write(epath, std::mem::replace(&mut eps_buf, e_next))?;
        }
        if let Some(near) = near_owned {
            maps.write_u8(out.join(format!("near_edge_{n:03}.tif")), near)?;
        }
        pb.inc(1);
    }
    maps.finish()?;
    pb.finish_and_clear();

    // Tiled grid: one row per tile.
    let (th, tw) = outs[0].gs_tiles.dim();
    let side = pr.rev_side as f64;
    let mut cols: Vec<(String, Vec<f64>)> = vec![
        (
            "x_mm".into(),
            (0..th * tw).map(|k| mm(((k % tw) as f64 + 0.5) * side)).collect(),
        ),
        (
            "y_mm".into(),
            (0..th * tw).map(|k| mm(((k / tw) as f64 + 0.5) * side)).collect(),
        ),
    ];
    for (n, o) in outs.iter().enumerate() {
        cols.push((format!("g_s_{n:03}"), o.gs_tiles.iter().copied().collect()));
        if let Some(e) = &o.eps_tiles {
            cols.push((format!("eps_vol_{n:03}"), e.iter().copied().collect()));
        }
        if let Some(t) = &o.edge_tiles {
            cols.push((format!("near_edge_{n:03}"), t.iter().copied().collect()));
        }
    }
    write_table(out, "grid.csv", &cols)?;
    files.push("grid.csv".into());
    tables.push(Table {
        path: "grid.csv".into(),
        caption: format!(
            "Tiled REV grid ({th} x {tw} tiles of {} px): tile centres (mm), g_S of every frame and eps_vol (Eq. 5); \
             near_edge = 1 where the tile reaches a bulk liquid or solid region (eps_vol less accurate there, docs/radiograph.md).",
            pr.rev_side
        ),
    });

    // Profiles.
    for (k, spec) in p.profiles.iter().enumerate() {
        let pos: Vec<f64> = outs[0].profiles[k].0.iter().map(|&x| mm(x)).collect();
        let axis = match spec.axis {
            ProfileAxis::X => "x",
            ProfileAxis::Y => "y",
        };
        let mut cols: Vec<(String, Vec<f64>)> = vec![(format!("{axis}_mm"), pos.clone())];
        for (n, o) in outs.iter().enumerate() {
            cols.push((format!("g_s_{n:03}"), o.profiles[k].1.clone()));
            if let Some(e) = &o.profiles[k].2 {
                cols.push((format!("eps_vol_{n:03}"), e.clone()));
            }
            if let Some(f) = &o.profiles[k].3 {
                cols.push((format!("near_edge_fraction_{n:03}"), f.clone()));
            }
        }
        let name = format!("profile_{}.csv", spec.name);
        write_table(out, &name, &cols)?;
        files.push(name.clone().into());
        tables.push(Table {
            path: name.into(),
            caption: format!(
                "Profile '{}' along {axis} over ROI {:?} (px): REV g_S and eps_vol averaged across the ROI; \
                 near_edge_fraction = share of those REVs flagged near a bulk phase.",
                spec.name,
                <[usize; 4]>::from(spec.roi)
            ),
        });
        if p.plots {
            for (what, label) in [("g_s", "g_S (-)"), ("eps_vol", "eps_vol (-)")] {
                let series: Vec<(String, Vec<f64>)> = cols
                    .iter()
                    .skip(1)
                    .filter(|(c, _)| c.starts_with(what))
                    .map(|(c, v)| (format!("frame {}", &c[c.len() - 3..]), v.clone()))
                    .collect();
                if series.is_empty() {
                    continue;
                }
                let s: Vec<plot::Series> = series
                    .iter()
                    .map(|(l, v)| plot::Series {
                        label: l,
                        x: &pos,
                        y: v,
                        points: false,
                    })
                    .collect();
                let f = format!("profile_{}_{what}.png", spec.name);
                plot::xy_png(
                    &out.join(&f),
                    &s,
                    &plot::XyPlot {
                        title: &format!("{what} profile '{}'", spec.name),
                        x_label: &format!("{axis} (mm)"),
                        y_label: label,
                        ..Default::default()
                    },
                )?;
                figures.push(Figure {
                    path: f.clone().into(),
                    caption: format!(
                        "{label} along {axis} in profile ROI '{}', every frame.",
                        spec.name
                    ),
                });
                files.push(f.into());
            }
        }
    }

    // Line scan and meniscus (Eqs. 2, 22, 23).
    let mut meniscus = Vec::new();
    if let Some(ls) = &p.line_scan {
        let y: Vec<f64> = (ls.y0..ls.y1).map(|r| (r as f64 + 0.5) * p.pixel_size).collect();
        let mut cols: Vec<(String, Vec<f64>)> = vec![("y_mm".into(), y.iter().map(|v| v * 1e3).collect())];
        let mut series = Vec::new();
        for (n, line) in lines.iter().enumerate() {
            let l = bl::thickness_field_eq2(p.l_alloy0, p.mu_l, lines[0].view(), line.view());
            let l: Vec<f64> = l.iter().copied().collect();
            if n > 0 && ls.fit_half_width > 0.0 {
                match profile::meniscus_fit(&y, &l, ls.fit_half_width, ls.gamma) {
                    Ok(m) => meniscus.push(json!({"frame": n, "fit": m})),
                    Err(e) => meniscus.push(json!({"frame": n, "error": e.to_string()})),
                }
            }
            cols.push((format!("z_top_um_{n:03}"), l.iter().map(|v| 0.5e6 * v).collect()));
            cols.push((format!("l_alloy_um_{n:03}"), l.iter().map(|v| 1e6 * v).collect()));
            series.push((
                format!("frame {n}"),
                l.iter().map(|v| 0.5e6 * v).collect::<Vec<f64>>(),
            ));
        }
        write_table(out, "line_scan.csv", &cols)?;
        files.push("line_scan.csv".into());
        tables.push(Table {
            path: "line_scan.csv".into(),
            caption: format!(
                "Line scan at x = {} px, y = {}..{} px: thickness L_alloy^n (Eq. 2 per pixel) and surface z = L/2 (Eq. 22).",
                ls.x, ls.y0, ls.y1
            ),
        });
        if p.plots {
            let ymm: Vec<f64> = y.iter().map(|v| v * 1e3).collect();
            let s: Vec<plot::Series> = series
                .iter()
                .map(|(l, v)| plot::Series {
                    label: l,
                    x: &ymm,
                    y: v,
                    points: false,
                })
                .collect();
            plot::xy_png(
                &out.join("line_scan.png"),
                &s,
                &plot::XyPlot {
                    title: "Meniscus line scan, z = L_alloy/2 (Eq. 22)",
                    x_label: "y (mm)",
                    y_label: "z (um)",
                    ..Default::default()
                },
            )?;
            figures.push(Figure {
                path: "line_scan.png".into(),
                caption: "Sample surface z = L_alloy^n / 2 along the line scan (Eqs. 2, 22), every frame (cf. Fig. 12h)."
                    .into(),
            });
            files.push("line_scan.png".into());
        }
    }

    if !crate::contract::quiet() {
        for w in &pr.warnings {
            eprintln!("radiograph: warning: {w}");
        }
    }
    let summary = json!({
        "frames": nf,
        "image_rows": shape.0,
        "image_cols": shape.1,
        "rev_side_px": pr.rev_side,
        "rev_side_m": pr.rev_side as f64 * p.pixel_size,
        "map_step_px": step,
        "map_rows": mshape.0,
        "map_cols": mshape.1,
        "i_l0": pr.i_l0,
        "i_s0": pr.i_s0,
        "mu_s": p.mu_s,
        "mu_l": p.mu_l,
        "l_alloy0_m": p.l_alloy0,
        "thickness_method": p.thickness,
        "global_area": p.global_area.unwrap_or(area),
        "per_frame": frames_json,
        "meniscus": meniscus,
        "warnings": pr.warnings,
    });
    lbdem_core::atomic::write_atomic(&out.join("summary.json"), &serde_json::to_vec_pretty(&summary)?)
        .with_context(|| format!("cannot write {}", out.join("summary.json").display()))?;
    files.push("summary.json".into());
    Ok(StageOutput {
        summary,
        figures,
        tables,
        files,
    })
}

fn write_table(dir: &Path, name: &str, cols: &[(String, Vec<f64>)]) -> Result<()> {
    let c: Vec<(&str, &[f64])> = cols.iter().map(|(n, v)| (n.as_str(), v.as_slice())).collect();
    table::write_csv(&dir.join(name), &c)
}
