//! PNG, JPEG and TIFF images through the `image` crate (the digitise stage's photographs, the
//! `[mask]` of fluid scenes), with decoding limits: whatever a header claims, decoding never
//! asks for more than [`MAX_IMAGE_BYTES`], and a bad file is an error naming it, never a panic.

use anyhow::{Context, Result, bail};
use image::{DynamicImage, ImageReader, Limits};
use std::io::Cursor;

/// The largest image side accepted (pixels): 16384, four times a 4k detector.
pub const MAX_SIDE: u32 = 16_384;

/// The most the decoder may allocate (bytes): the same 128 MiB as a TIFF frame
/// (`crate::io::tiff::MAX_FRAME_BYTES`), e.g. a 5800 × 5800 RGB photograph at 8 bits.
pub const MAX_IMAGE_BYTES: u64 = crate::io::tiff::MAX_FRAME_BYTES as u64;

/// Decode `bytes` (format guessed from the content), `name` being the file in errors.
pub fn decode(bytes: &[u8], name: &str) -> Result<DynamicImage> {
    if bytes.is_empty() {
        bail!("image file {name} is empty (0 bytes): give a PNG, JPEG or TIFF image");
    }
    let mut limits = Limits::default();
    limits.max_image_width = Some(MAX_SIDE);
    limits.max_image_height = Some(MAX_SIDE);
    limits.max_alloc = Some(MAX_IMAGE_BYTES);
    let mut reader = ImageReader::new(Cursor::new(bytes))
        .with_guessed_format()
        .with_context(|| format!("cannot read image file {name}"))?;
    reader.limits(limits);
    reader.decode().map_err(|e| match e {
        image::ImageError::Limits(l) => anyhow::anyhow!(
            "image file {name}: {l}; lbdem decodes images up to {MAX_SIDE} pixels a side and {} MiB; \
             crop or scale the image down",
            MAX_IMAGE_BYTES >> 20
        ),
        e => anyhow::anyhow!(
            "cannot decode image file {name}: {e}; give a PNG, JPEG or TIFF (8/16-bit, or 32-bit float grey)"
        ),
    })
}

/// Read and decode the image file at `path`.
pub fn open(path: &std::path::Path) -> Result<DynamicImage> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read image file {}", path.display()))?;
    decode(&bytes, &path.display().to_string())
}
