//! Euclidean distance from each solid pixel to the nearest liquid (or outside) pixel:
//! the exact transform of Felzenszwalb & Huttenlocher (Theory of Computing 8 (2012) 415),
//! as implemented by `imageproc`. Its ridges are the grains' medial axes and its maxima
//! their centres, which is what the watershed floods.

use imageproc::distance_transform::euclidean_squared_distance_transform;
use imageproc::image::{GrayImage, Luma};
use ndarray::Array2;

/// Squared distance (pixels^2) of every pixel to the nearest non-solid pixel; 0 on liquid.
/// The image is padded by one liquid pixel all round, so a grain cut by the image edge
/// ends there.
pub fn squared_distance_to_liquid(solid: &Array2<bool>) -> Array2<f64> {
    let (h, w) = solid.dim();
    let img = GrayImage::from_fn(w as u32 + 2, h as u32 + 2, |x, y| {
        let inner = x >= 1 && y >= 1 && (x as usize) <= w && (y as usize) <= h;
        let s = inner && solid[[y as usize - 1, x as usize - 1]];
        Luma([u8::from(!s)])
    });
    let d = euclidean_squared_distance_transform(&img);
    Array2::from_shape_fn((h, w), |(r, c)| d.get_pixel(c as u32 + 1, r as u32 + 1)[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_inside_a_square_is_to_its_nearest_side() {
        let solid = Array2::from_shape_fn((9, 9), |(r, c)| (2..7).contains(&r) && (2..7).contains(&c));
        let d = squared_distance_to_liquid(&solid);
        assert_eq!(d[[4, 4]], 9.0);
        assert_eq!(d[[2, 4]], 1.0);
        assert_eq!(d[[0, 0]], 0.0);
    }
}
