//! Reading the image digitise works on: a 32- or 64-bit float TIFF (the radiograph
//! stage's solid-fraction map, values 0..1, NaN outside the sample) through the one TIFF
//! reader (`crate::io::tiff`), anything else (PNG, JPEG, 8/16-bit TIFF) through `image`, reduced to one grey
//! channel in f64.

use anyhow::{Context, Result};
use ndarray::Array2;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Which grey value a colour image gives.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Channel {
    /// Rec. 601 luma 0.299 R + 0.587 G + 0.114 B.
    #[default]
    Luma,
    Red,
    Green,
    Blue,
}

/// The grey image and what it was.
pub struct Loaded {
    pub grey: Array2<f64>,
    /// "float" for a float TIFF (solid fraction), else the colour type read.
    pub kind: String,
}

pub fn load(path: &Path, channel: Channel) -> Result<Loaded> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read image file {}", path.display()))?;
    load_bytes(&bytes, &path.display().to_string(), channel)
}

/// [`load`] from the file's bytes, `name` being the file in errors.
pub fn load_bytes(bytes: &[u8], name: &str, channel: Channel) -> Result<Loaded> {
    let is_tiff = bytes.starts_with(b"II*\0") || bytes.starts_with(b"MM\0*");
    if is_tiff && let Some(l) = load_float_tiff(bytes, name) {
        return Ok(l);
    }
    let img = crate::io::image::decode(bytes, name)?;
    let kind = format!("{:?}", img.color());
    let (w, h) = (img.width() as usize, img.height() as usize);
    let is16 = matches!(
        img.color(),
        image::ColorType::L16 | image::ColorType::La16 | image::ColorType::Rgb16 | image::ColorType::Rgba16
    );
    let grey = if is16 {
        let rgb = img.to_rgb16();
        Array2::from_shape_fn((h, w), |(r, c)| {
            pick(rgb.get_pixel(c as u32, r as u32).0.map(f64::from), channel)
        })
    } else {
        let rgb = img.to_rgb8();
        Array2::from_shape_fn((h, w), |(r, c)| {
            pick(rgb.get_pixel(c as u32, r as u32).0.map(f64::from), channel)
        })
    };
    Ok(Loaded { grey, kind })
}

fn pick(p: [f64; 3], channel: Channel) -> f64 {
    match channel {
        Channel::Luma => 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2],
        Channel::Red => p[0],
        Channel::Green => p[1],
        Channel::Blue => p[2],
    }
}

/// A one-sample float TIFF (through the one TIFF reader, `crate::io::tiff`), or `None` for
/// any other TIFF (left to `image`, which also reads colour).
fn load_float_tiff(bytes: &[u8], name: &str) -> Option<Loaded> {
    let mut frames = crate::io::tiff::read_pages_from(std::io::Cursor::new(bytes), name).ok()?;
    if frames.is_empty() || !matches!(frames[0].bits, 32 | 64) {
        return None;
    }
    Some(Loaded {
        grey: frames.swap_remove(0).data,
        kind: "float".into(),
    })
}
