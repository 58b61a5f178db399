//! Gaussian smoothing before thresholding, so that detector noise does not make a ragged
//! grain boundary or specks in the liquid.

use imageproc::filter::gaussian_blur_f32;
use imageproc::image::{ImageBuffer, Luma};
use ndarray::{Array2, ArrayView2};

/// Gaussian blur with standard deviation `sigma_px` (pixels); `sigma_px <= 0` copies.
/// Non-finite pixels are replaced by `fill` first (they lie outside the mask anyway).
pub fn gaussian(image: ArrayView2<f64>, sigma_px: f64, fill: f64) -> Array2<f64> {
    let (h, w) = image.dim();
    let clean = |v: f64| if v.is_finite() { v } else { fill };
    if sigma_px <= 0.0 {
        return image.mapv(clean);
    }
    let buf: ImageBuffer<Luma<f32>, Vec<f32>> = ImageBuffer::from_fn(w as u32, h as u32, |x, y| {
        Luma([clean(image[[y as usize, x as usize]]) as f32])
    });
    let out = gaussian_blur_f32(&buf, sigma_px as f32);
    Array2::from_shape_fn((h, w), |(r, c)| out.get_pixel(c as u32, r as u32)[0] as f64)
}
