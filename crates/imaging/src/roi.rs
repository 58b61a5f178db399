//! Rectangular regions of interest in pixel coordinates (x = column, y = row, origin at
//! the top-left, as in an image viewer), checked against the image before use.

use crate::{ImagingError, Result};
use ndarray::{ArrayView2, s};
use serde::{Deserialize, Serialize};

/// `[x, y, w, h]` in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(from = "[usize; 4]", into = "[usize; 4]")]
pub struct Roi {
    pub x: usize,
    pub y: usize,
    pub w: usize,
    pub h: usize,
}

impl From<[usize; 4]> for Roi {
    fn from(a: [usize; 4]) -> Self {
        Self {
            x: a[0],
            y: a[1],
            w: a[2],
            h: a[3],
        }
    }
}

impl From<Roi> for [usize; 4] {
    fn from(r: Roi) -> Self {
        [r.x, r.y, r.w, r.h]
    }
}

impl Roi {
    pub fn new(x: usize, y: usize, w: usize, h: usize) -> Self {
        Self { x, y, w, h }
    }

    /// Error naming the ROI unless it is non-empty and inside an image of `shape` = (rows, cols).
    pub fn check(&self, name: &str, shape: (usize, usize)) -> Result<()> {
        let (img_h, img_w) = shape;
        let inside = self.w >= 1
            && self.h >= 1
            && self.x.checked_add(self.w).is_some_and(|e| e <= img_w)
            && self.y.checked_add(self.h).is_some_and(|e| e <= img_h);
        if inside {
            Ok(())
        } else {
            Err(ImagingError::RoiOutside {
                name: name.into(),
                x: self.x,
                y: self.y,
                w: self.w,
                h: self.h,
                img_w,
                img_h,
            })
        }
    }

    pub fn view<'a>(&self, a: ArrayView2<'a, f64>) -> ArrayView2<'a, f64> {
        a.slice_move(s![self.y..self.y + self.h, self.x..self.x + self.w])
    }

    /// Mean of the finite pixels inside the ROI (NaN marks masked pixels).
    pub fn mean(&self, name: &str, a: ArrayView2<f64>) -> Result<f64> {
        self.check(name, a.dim())?;
        let (mut sum, mut n) = (0.0, 0usize);
        for row in self.view(a).rows() {
            for &v in row {
                if v.is_finite() {
                    sum += v;
                    n += 1;
                }
            }
        }
        if n == 0 {
            return Err(ImagingError::RoiEmpty { name: name.into() });
        }
        Ok(sum / n as f64)
    }
}
