//! Errors of the digitise kernels. Each message names the input or parameter, its value,
//! the limit and what to change.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum GrainsError {
    #[error(
        "the image is empty ({width} x {height} pixels): digitise needs at least {min} x {min} pixels; \
         check that the input file holds an image"
    )]
    EmptyImage { width: usize, height: usize, min: usize },

    #[error(
        "the image has no finite pixel inside the container ({inside} pixels inside, all NaN or infinite); \
         check the input file or the container"
    )]
    NoFinitePixels { inside: usize },

    #[error(
        "the image is uniform inside the container (every pixel = {value}): grains cannot be told from \
         liquid; check the input file, or give `threshold` explicitly"
    )]
    UniformImage { value: f64 },

    #[error(
        "the container mask covers nothing: {what} leaves 0 of {total} pixels inside; give the container \
         in pixel coordinates (x to the right, y down from the top-left corner) within the image"
    )]
    EmptyMask { what: String, total: usize },

    #[error(
        "no grains found: threshold {threshold:.4} leaves {solid} solid pixels of {inside} inside the \
         container, and no connected grain of at least min_grain_area_px = {min_area} pixels; lower \
         `threshold`, set `grains_are` = \"{other}\" if grains are darker than the liquid, or check the container"
    )]
    NoGrains {
        threshold: f64,
        solid: usize,
        inside: usize,
        min_area: usize,
        other: &'static str,
    },

    #[error(
        "threshold {threshold:.4} makes every pixel inside the container solid ({inside} pixels), so no \
         liquid is left to separate grains; raise `threshold` or check `grains_are`"
    )]
    AllSolid { threshold: f64, inside: usize },

    #[error("parameter `{name}` = {value} is out of range: {limit}; {fix}")]
    BadParameter {
        name: &'static str,
        value: String,
        limit: &'static str,
        fix: &'static str,
    },
}
