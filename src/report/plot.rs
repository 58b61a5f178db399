//! Plots every stage uses. Fields are `ndarray` views indexed `[row, col]` = `[y, x]`
//! with row 0 at the top, as in an image.

use anyhow::{Result, bail};
use ndarray::ArrayView2;
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Colormap {
    /// Sequential (solid fraction, thickness, intensity).
    Viridis,
    /// Blue-white-red, centred on zero (strain, pressure change).
    Diverging,
    Gray,
}

/// Options of a field map. NaN pixels are drawn grey (masked).
#[derive(Clone, Debug)]
pub struct FieldPlot<'a> {
    pub title: &'a str,
    /// Colour-bar label with units, e.g. "g_S (-)".
    pub label: &'a str,
    pub cmap: Colormap,
    /// Colour range; `None` takes the finite min/max (symmetric about 0 for Diverging).
    pub range: Option<(f64, f64)>,
    /// Pixel size in metres: axes in mm when given, in pixels otherwise.
    pub pixel_size: Option<f64>,
}

/// One line (or point set) of an x-y plot.
#[derive(Clone, Debug)]
pub struct Series<'a> {
    pub label: &'a str,
    pub x: &'a [f64],
    pub y: &'a [f64],
    /// Draw markers instead of a line (measured data).
    pub points: bool,
}

#[derive(Clone, Debug, Default)]
pub struct XyPlot<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub log_x: bool,
    pub log_y: bool,
}

/// A circle to draw over an image, in pixel coordinates; `class` picks the colour.
#[derive(Clone, Copy, Debug)]
pub struct Circle {
    pub x: f64,
    pub y: f64,
    pub r: f64,
    pub class: usize,
}

/// PNG map of a field with a colour bar.
pub fn field_png(_path: &Path, _field: ArrayView2<f64>, _opts: &FieldPlot) -> Result<()> {
    bail!("plot::field_png is being written")
}

/// PNG x-y plot of one or more series.
pub fn xy_png(_path: &Path, _series: &[Series], _opts: &XyPlot) -> Result<()> {
    bail!("plot::xy_png is being written")
}

/// PNG histogram.
pub fn histogram_png(
    _path: &Path,
    _values: &[f64],
    _bins: usize,
    _title: &str,
    _x_label: &str,
) -> Result<()> {
    bail!("plot::histogram_png is being written")
}

/// PNG of a grey image with circles drawn over it (same pixel size as the image).
pub fn circles_overlay_png(_path: &Path, _image: ArrayView2<f64>, _circles: &[Circle]) -> Result<()> {
    bail!("plot::circles_overlay_png is being written")
}
