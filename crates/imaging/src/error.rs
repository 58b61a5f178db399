//! Errors of the imaging kernels. Each message names the parameter, its value, the limit
//! and what to do about it.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum ImagingError {
    #[error(
        "{what}: size {got_h}x{got_w} (rows x cols) differs from the first frame's \
         {want_h}x{want_w}; all frames, dark and flat fields must have the same size"
    )]
    SizeMismatch {
        what: String,
        want_h: usize,
        want_w: usize,
        got_h: usize,
        got_w: usize,
    },
    #[error(
        "ROI '{name}' = [x={x}, y={y}, w={w}, h={h}] lies outside the {img_w}x{img_h} (w x h) image \
         or is empty; give x + w <= {img_w}, y + h <= {img_h}, w, h >= 1"
    )]
    RoiOutside {
        name: String,
        x: usize,
        y: usize,
        w: usize,
        h: usize,
        img_w: usize,
        img_h: usize,
    },
    #[error("ROI '{name}' has no finite pixels (all masked/NaN); move it onto valid pixels")]
    RoiEmpty { name: String },
    #[error(
        "reference intensities I_S^0 = {i_s} and I_L^0 = {i_l} are equal (or within 1e-9 in ln): \
         Eq. (1a) divides by ln I_S^0 - ln I_L^0; check the i_s0/i_l0 ROIs or values"
    )]
    EqualReferences { i_s: f64, i_l: f64 },
    #[error(
        "{what}: intensity {value} at pixel (row {row}, col {col}) is not positive after \
         correction; Beer-Lambert needs I > 0 (check dark/flat fields, or set \
         mask_nonpositive = true to treat such pixels as masked)"
    )]
    NonPositive {
        what: String,
        row: usize,
        col: usize,
        value: f64,
    },
    #[error(
        "REV side {side_px} px (rev_factor x d_bar / pixel_size) is larger than the {img_w}x{img_h} image; \
         use a smaller d_bar or rev_factor, or a larger field of view"
    )]
    RevTooLarge {
        side_px: usize,
        img_w: usize,
        img_h: usize,
    },
    #[error("parameter '{name}' = {value}: {reason}")]
    Invalid {
        name: String,
        value: String,
        reason: String,
    },
}

impl ImagingError {
    pub fn invalid(name: &str, value: impl std::fmt::Display, reason: &str) -> Self {
        Self::Invalid {
            name: name.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }
}
