//! The experiment side of a comparison: what the radiograph stage's manifest says about its
//! frames, and Eq. 5 on the true solid fraction when the frames come from `synth-run`.

use crate::contract::{MANIFEST, StageRecord};
use crate::io::tiff as tio;
use anyhow::{Context, Result, bail};
use lbdem_imaging::rev::cell_centre;
use ndarray::Array2;
use std::path::{Path, PathBuf};

/// What the radiograph stage's manifest says about its frames.
pub(super) struct RadiographSide {
    pub(super) dir: PathBuf,
    pub(super) pixel_size: f64,
    pub(super) d_bar: f64,
    pub(super) rev_factor: f64,
    pub(super) min_valid: f64,
    pub(super) frames: usize,
    /// Pixels between the centres of the maps' cells (1 for runs from before the map grid).
    pub(super) map_step: usize,
    /// Frame size (rows, columns), px.
    pub(super) image: (usize, usize),
    /// The stage's REV side, px (absent in manifests from before it was recorded).
    pub(super) rev_side_px: Option<usize>,
    /// `fov.json` beside the frames (written by `synth-run`) and its directory.
    pub(super) fov: Option<serde_json::Value>,
    pub(super) fov_dir: Option<PathBuf>,
    pub(super) eps_min_gs: f64,
}

pub(super) fn radiograph_side(dir: &Path) -> Result<RadiographSide> {
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
            parent.join(crate::stages::synth_run::FOV),
            parent.parent()?.join(crate::stages::synth_run::FOV),
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
        map_step: rec.output.summary["map_step_px"].as_u64().unwrap_or(1).max(1) as usize,
        image: (
            rec.output.summary["image_rows"].as_u64().unwrap_or(0) as usize,
            rec.output.summary["image_cols"].as_u64().unwrap_or(0) as usize,
        ),
        rev_side_px: rec.output.summary["rev_side_px"].as_u64().map(|v| v as usize),
        fov,
        fov_dir: fov_path.and_then(|p| p.parent().map(Path::to_path_buf)),
        eps_min_gs: num("eps_min_gs")?,
    })
}

/// Eq. 5 on the true pixel solid fraction `synth-run` wrote for frame `fr` (REV of `side` px as
/// the radiograph stage), on the stage's map grid (the centre pixel of every `map_step` block),
/// or `None` for frames that do not come from `synth-run`.
pub(super) fn true_eq5(rs: &RadiographSide, fr: u64, side: usize) -> Result<Option<Array2<f64>>> {
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
    let eps = lbdem_imaging::beer_lambert::eps_vol_field(g0.view(), gn.view(), rs.eps_min_gs);
    let k = rs.map_step;
    let (h, w) = eps.dim();
    Ok(Some(Array2::from_shape_fn((h / k, w / k), |(i, j)| {
        eps[[cell_centre(i, k), cell_centre(j, k)]]
    })))
}
