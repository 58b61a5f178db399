//! The particle file the DEM scenes read: `particles.csv` (grain_id, x, y, r; one row per
//! circle; SI metres; x to the right and y UP from the bottom-left corner of the image)
//! and `particles.json` beside it (the header: units, axes, pixel size, image size,
//! source, container, counts, d_bar).

use crate::report::table::{self, Col};
use anyhow::Result;
use serde::Serialize;
use std::path::Path;

/// One circle in SI, y up.
#[derive(Clone, Copy, Debug)]
pub struct Particle {
    pub grain_id: usize,
    pub x: f64,
    pub y: f64,
    pub r: f64,
}

#[derive(Serialize)]
pub struct Header<'a> {
    pub format: &'static str,
    pub version: u32,
    pub file: &'a str,
    pub columns: [&'static str; 4],
    pub units: &'static str,
    pub axes: &'static str,
    pub pixel_size_m: f64,
    pub image_width_px: usize,
    pub image_height_px: usize,
    pub width_m: f64,
    pub height_m: f64,
    pub source: String,
    /// Container outline, SI metres, y up.
    pub container_m: Vec<[f64; 2]>,
    pub assembly: &'a str,
    pub n_grains: usize,
    pub n_circles: usize,
    pub d_bar_m: f64,
    pub solid_fraction_fitted: f64,
}

/// Write the circles through polars (`report::table::write_table`, atomic).
pub fn write_particles(path: &Path, ps: &[Particle]) -> Result<()> {
    let id: Vec<u64> = ps.iter().map(|p| p.grain_id as u64).collect();
    let col = |f: fn(&Particle) -> f64| ps.iter().map(f).collect::<Vec<f64>>();
    let (x, y, r) = (col(|p| p.x), col(|p| p.y), col(|p| p.r));
    table::write_table(
        path,
        &[
            ("grain_id", Col::U64(&id)),
            ("x", Col::F64(&x)),
            ("y", Col::F64(&y)),
            ("r", Col::F64(&r)),
        ],
    )
}

pub fn write_header(path: &Path, h: &Header) -> Result<()> {
    lbdem_core::atomic::write_atomic(path, &serde_json::to_vec_pretty(h)?)?;
    Ok(())
}
