//! The container (sample) mask: only pixels inside it count, so the walls, the push plate
//! and whatever lies outside the box never become grains.
//!
//! Coordinates here are pixel units, x to the right and y down from the image's top-left
//! corner; a pixel is inside when its centre (c + 0.5, r + 0.5) is.

use crate::threshold::otsu3;
use crate::{GrainsError, Result};
use imageproc::image::{GrayImage, Luma};
use imageproc::region_labelling::{Connectivity, connected_components};
use ndarray::{Array2, ArrayView2};
use serde::{Deserialize, Serialize};

/// Where the sample is.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", tag = "kind")]
pub enum Container {
    /// The whole image.
    #[default]
    Full,
    /// An axis-aligned rectangle [x0, x1) x [y0, y1) in pixels.
    Rect { x0: f64, y0: f64, x1: f64, y1: f64 },
    /// A closed polygon, vertices in pixels.
    Polygon { points: Vec<[f64; 2]> },
    /// A box detected from the image: the bright interior of a container seen against a
    /// dark surround (see [`detect_box`]); the whole image when none is found.
    AutoBox,
}

/// The mask and the outline it came from.
#[derive(Clone, Debug)]
pub struct ContainerMask {
    pub inside: Array2<bool>,
    /// Closed outline (pixel coordinates), for checking that fitted circles stay inside.
    pub outline: Vec<[f64; 2]>,
    /// What was used, in words (for the summary).
    pub description: String,
}

impl ContainerMask {
    pub fn count(&self) -> usize {
        self.inside.iter().filter(|&&b| b).count()
    }
    /// Whether the point (pixel coordinates) is inside the outline.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        point_in_polygon(&self.outline, x, y)
    }
    /// How far the circle reaches outside the outline (0 when it lies inside), in pixels,
    /// measured as the largest distance of a point of the circle beyond the nearest edge.
    pub fn protrusion(&self, x: f64, y: f64, r: f64) -> f64 {
        let d = signed_distance(&self.outline, x, y);
        (r - d).max(0.0)
    }
}

fn rect_outline(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

/// Even-odd rule.
pub fn point_in_polygon(poly: &[[f64; 2]], x: f64, y: f64) -> bool {
    let n = poly.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (xi, yi) = (poly[i][0], poly[i][1]);
        let (xj, yj) = (poly[j][0], poly[j][1]);
        if (yi > y) != (yj > y) && x < (xj - xi) * (y - yi) / (yj - yi) + xi {
            inside = !inside;
        }
        j = i;
    }
    inside
}

/// Distance from (x, y) to the polygon's boundary, positive inside, negative outside.
pub fn signed_distance(poly: &[[f64; 2]], x: f64, y: f64) -> f64 {
    let n = poly.len();
    let mut d2 = f64::INFINITY;
    for i in 0..n {
        let a = poly[i];
        let b = poly[(i + 1) % n];
        let (ex, ey) = (b[0] - a[0], b[1] - a[1]);
        let len2 = ex * ex + ey * ey;
        let t = if len2 > 0.0 {
            (((x - a[0]) * ex + (y - a[1]) * ey) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let (px, py) = (a[0] + t * ex - x, a[1] + t * ey - y);
        d2 = d2.min(px * px + py * py);
    }
    let d = d2.sqrt();
    if point_in_polygon(poly, x, y) { d } else { -d }
}

/// Build the mask of `container` for `image` (used only by [`Container::AutoBox`]).
pub fn build(container: &Container, image: ArrayView2<f64>) -> Result<ContainerMask> {
    let (h, w) = image.dim();
    let total = h * w;
    let (outline, description) = match container {
        Container::Full => (
            rect_outline(0.0, 0.0, w as f64, h as f64),
            "the whole image".to_string(),
        ),
        Container::Rect { x0, y0, x1, y1 } => (
            rect_outline(*x0, *y0, *x1, *y1),
            format!("rectangle x {x0}..{x1}, y {y0}..{y1} px (given)"),
        ),
        Container::Polygon { points } => {
            if points.len() < 3 {
                return Err(GrainsError::EmptyMask {
                    what: format!("a polygon of {} vertices", points.len()),
                    total,
                });
            }
            (
                points.clone(),
                format!("polygon of {} vertices (given)", points.len()),
            )
        }
        Container::AutoBox => match detect_box(image)? {
            Some([x0, y0, x1, y1]) => (
                rect_outline(x0, y0, x1, y1),
                format!("rectangle x {x0}..{x1}, y {y0}..{y1} px (detected box)"),
            ),
            None => (
                rect_outline(0.0, 0.0, w as f64, h as f64),
                "the whole image (no box detected)".to_string(),
            ),
        },
    };
    let inside = rasterise(&outline, h, w);
    let m = ContainerMask {
        inside,
        outline,
        description,
    };
    if m.count() == 0 {
        return Err(GrainsError::EmptyMask {
            what: m.description,
            total,
        });
    }
    Ok(m)
}

fn rasterise(outline: &[[f64; 2]], h: usize, w: usize) -> Array2<bool> {
    Array2::from_shape_fn((h, w), |(r, c)| {
        point_in_polygon(outline, c as f64 + 0.5, r as f64 + 0.5)
    })
}

/// Detect a box container: the interior (liquid and grains) is brighter than the dark
/// surround. A three-class Otsu split (outside < liquid < grains) gives the level between
/// the dark outside and the liquid inside the box. The largest
/// connected bright region is taken, and the box is the longest run of rows and of columns
/// that are at least half filled by it (thin walls and plates reaching beyond the box fill
/// too few pixels of a row to count). Returns `[x0, y0, x1, y1]` in pixels, or `None`
/// when the region is (nearly) the whole image.
pub fn detect_box(image: ArrayView2<f64>) -> Result<Option<[f64; 4]>> {
    let (h, w) = image.dim();
    let (t_dark, _) = otsu3(image.iter().copied())?;
    let bright = GrayImage::from_fn(w as u32, h as u32, |x, y| {
        let v = image[[y as usize, x as usize]];
        Luma([u8::from(v.is_finite() && v > t_dark)])
    });
    let labels = connected_components(&bright, Connectivity::Eight, Luma([0u8]));
    let mut sizes: Vec<usize> = Vec::new();
    for p in labels.pixels() {
        let l = p[0] as usize;
        if l >= sizes.len() {
            sizes.resize(l + 1, 0);
        }
        sizes[l] += 1;
    }
    let Some(biggest) = (1..sizes.len()).max_by_key(|&l| (sizes[l], std::cmp::Reverse(l))) else {
        return Ok(None);
    };
    let in_region = |r: usize, c: usize| labels.get_pixel(c as u32, r as u32)[0] as usize == biggest;
    let rows: Vec<usize> = (0..h)
        .map(|r| (0..w).filter(|&c| in_region(r, c)).count())
        .collect();
    let cols: Vec<usize> = (0..w)
        .map(|c| (0..h).filter(|&r| in_region(r, c)).count())
        .collect();
    let (Some((y0, y1)), Some((x0, x1))) = (longest_half_run(&rows), longest_half_run(&cols)) else {
        return Ok(None);
    };
    let area = ((x1 - x0) * (y1 - y0)) as f64;
    if area >= 0.98 * (w * h) as f64 {
        return Ok(None);
    }
    Ok(Some([x0 as f64, y0 as f64, x1 as f64, y1 as f64]))
}

/// Longest run of indices whose count is at least half the largest count; `[start, end)`.
fn longest_half_run(counts: &[usize]) -> Option<(usize, usize)> {
    let max = *counts.iter().max()?;
    if max == 0 {
        return None;
    }
    let (mut best, mut start) = (None::<(usize, usize)>, None::<usize>);
    for (i, &c) in counts.iter().chain(std::iter::once(&0)).enumerate() {
        if 2 * c >= max && c > 0 {
            start.get_or_insert(i);
        } else if let Some(s) = start.take()
            && best.is_none_or(|(a, b)| i - s > b - a)
        {
            best = Some((s, i));
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detects_a_bright_box_in_a_dark_frame() {
        let img = Array2::from_shape_fn((100, 120), |(r, c)| {
            let inside = (20..90).contains(&r) && (10..110).contains(&c);
            let grain = ((r as f64 - 50.0).powi(2) + (c as f64 - 60.0).powi(2)) < 400.0;
            if grain {
                1.0
            } else if inside {
                0.4
            } else {
                0.0
            }
        });
        let b = detect_box(img.view()).unwrap().unwrap();
        assert_eq!(b, [10.0, 20.0, 110.0, 90.0]);
    }

    #[test]
    fn signed_distance_of_a_square() {
        let sq = rect_outline(0.0, 0.0, 10.0, 10.0);
        assert!((signed_distance(&sq, 5.0, 2.0) - 2.0).abs() < 1e-12);
        assert!((signed_distance(&sq, -1.0, 5.0) + 1.0).abs() < 1e-12);
    }
}
