//! Flagging the REVs that reach a bulk phase: a region of pure liquid or pure solid at least a
//! grain across (a liquid gap, a container wall, a solid pad, a large grain), where the REV
//! strain of Eq. (5) is less accurate than inside the grain assembly.
//!
//! Why there: the detector averages intensity, not its logarithm, so a blurred pixel across a
//! sharp solid/liquid edge reads too much solid (Jensen's inequality). Inside an assembly the
//! bias is much the same in the reference and the deformed frame and cancels in `g0 / g`; an
//! REV that reaches a bulk phase has a lower or steeper `g_S` and the bias, divided by it, does
//! not cancel. Measured on synthetic radiographs (`tests/radiograph_edge_flag.rs`): the REV
//! strain error reached 0.008 within one REV of the liquid pad and stayed below 0.005 elsewhere.
//!
//! The rule: a pixel is bulk when the mean pixel solid fraction over a window of a few grains
//! (two by default in the stage) centred on it is below `liquid_below` or above `solid_above`;
//! an REV is flagged when its window holds a bulk pixel. Inside a packing such a window mixes
//! phases (a disk fills at most pi/4 of its bounding square; a liquid pocket of one grain is
//! averaged with its neighbours), so only regions larger than the window are bulk.

use crate::rev::Sat;
use crate::{ImagingError, Result};
use ndarray::Array2;

/// Thresholds of the bulk-phase rule (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BulkPhase {
    /// Side of the window, px (a few mean grain diameters).
    pub window_px: usize,
    /// Window mean solid fraction below which a pixel is bulk liquid.
    pub liquid_below: f64,
    /// Window mean solid fraction above which a pixel is bulk solid.
    pub solid_above: f64,
}

impl BulkPhase {
    /// Refuses a zero window or thresholds that are not finite and ordered.
    pub fn validate(&self) -> Result<()> {
        if self.window_px == 0 {
            return Err(ImagingError::invalid(
                "edge_flag.window",
                0,
                "must be at least one pixel",
            ));
        }
        if !(self.liquid_below.is_finite()
            && self.solid_above.is_finite()
            && self.liquid_below < self.solid_above)
        {
            return Err(ImagingError::invalid(
                "edge_flag.liquid_below / solid_above",
                format!("{} / {}", self.liquid_below, self.solid_above),
                "must be finite with liquid_below < solid_above (e.g. 0.05 and 0.95)",
            ));
        }
        Ok(())
    }
}

/// The bulk-phase flags of a sequence of frames, computed on a grid of blocks an eighth of the
/// bulk window across and read back per pixel: the flags are smooth at the grain scale, so a
/// block grid moves a flag's border by less than a block (an eighth of the window) and costs
/// a 2048² frame a few milliseconds instead of four full-resolution passes.
#[derive(Clone, Debug)]
pub struct Flagger {
    rule: BulkPhase,
    rev_side: usize,
    /// Block side, px.
    block: usize,
    /// Bulk blocks of the reference frame.
    bulk0: Option<Array2<f64>>,
    /// Bulk blocks of the reference or the current frame.
    bulk: Array2<f64>,
    /// Blocks whose REV window holds a bulk block.
    near: Array2<f64>,
    /// Image shape, px.
    dim: (usize, usize),
}

impl Flagger {
    pub fn new(rule: BulkPhase, rev_side: usize) -> Result<Self> {
        rule.validate()?;
        Ok(Self {
            rule,
            rev_side,
            block: (rule.window_px / 8).max(1),
            bulk0: None,
            bulk: Array2::zeros((0, 0)),
            near: Array2::zeros((0, 0)),
            dim: (0, 0),
        })
    }

    /// Flag the REVs of the next frame from the summed-area table of its pixel solid fraction.
    /// The first frame is the reference; later frames are flagged where they or the reference
    /// reach a bulk phase (Eq. 5 compares the two).
    pub fn frame(&mut self, g: &Sat) -> Result<()> {
        let (h, w) = g.dim();
        let k = self.block;
        let (bh, bw) = (h.div_ceil(k), w.div_ceil(k));
        let means = Array2::from_shape_fn((bh, bw), |(i, j)| {
            let (s, n) = g.window(i * k, j * k, ((i + 1) * k).min(h), ((j + 1) * k).min(w));
            if n == 0 { f64::NAN } else { s / n as f64 }
        });
        let side = |px: usize| ((px as f64 / k as f64).round() as usize).clamp(1, bh.min(bw));
        let mut sat = Sat::new();
        sat.build(means.view());
        let window = sat.rev_mean(side(self.rule.window_px), 0.5)?;
        let (lo, hi) = (self.rule.liquid_below, self.rule.solid_above);
        let mut bulk = window.mapv(|m| {
            if m.is_finite() && (m < lo || m > hi) {
                1.0
            } else {
                0.0
            }
        });
        match &self.bulk0 {
            None => self.bulk0 = Some(bulk.clone()),
            Some(b0) if b0.dim() == bulk.dim() => bulk.zip_mut_with(b0, |a, &b| *a = a.max(b)),
            Some(b0) => {
                return Err(ImagingError::invalid(
                    "frame size",
                    format!("{h}x{w}"),
                    &format!("differs from the reference frame's blocks {:?}", b0.dim()),
                ));
            }
        }
        sat.build(bulk.view());
        // min_valid 0: clipped border windows are judged on what they hold.
        self.near = sat.rev_mean(side(self.rev_side), 0.0)?;
        self.near.mapv_inplace(|m| if m > 0.0 { 1.0 } else { 0.0 });
        self.bulk = bulk;
        self.dim = (h, w);
        Ok(())
    }

    /// Per pixel: 1 where the REV window centred on it holds a bulk region of the last frame
    /// (to within a block), else 0.
    pub fn near_u8(&self) -> Array2<u8> {
        let k = self.block;
        Array2::from_shape_fn(self.dim, |(r, c)| self.near[[r / k, c / k]] as u8)
    }

    /// Per tile of the non-overlapping REV grid of [`Sat::tiles`]: 1.0 where the tile overlaps
    /// a bulk block of the last frame.
    pub fn tiles(&self) -> Array2<f64> {
        let (h, w) = self.dim;
        let (s, k) = (self.rev_side, self.block);
        Array2::from_shape_fn((h / s.max(1), w / s.max(1)), |(i, j)| {
            let rows = (i * s) / k..((i + 1) * s).div_ceil(k).min(self.bulk.nrows());
            let cols = (j * s) / k..((j + 1) * s).div_ceil(k).min(self.bulk.ncols());
            let hit = rows
                .clone()
                .any(|a| cols.clone().any(|b| self.bulk[[a, b]] > 0.0));
            if hit { 1.0 } else { 0.0 }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule(window_px: usize) -> BulkPhase {
        BulkPhase {
            window_px,
            liquid_below: 0.05,
            solid_above: 0.95,
        }
    }

    /// A checkerboard of half-grain squares is never bulk; a solid band of two grains is,
    /// and the REVs within half a side of it are flagged, the others not.
    #[test]
    fn texture_is_not_bulk_a_band_is() {
        let d = 10;
        let f = Array2::from_shape_fn((100, 80), |(r, c)| {
            if r < 2 * d {
                1.0
            } else if ((r / 5) + (c / 5)) % 2 == 0 {
                0.6
            } else {
                0.0
            }
        });
        let mut sat = Sat::new();
        sat.build(f.view());
        // A window of 16 px: blocks of 2 px.
        let mut flag = Flagger::new(rule(16), 30).unwrap();
        flag.frame(&sat).unwrap();
        // Bulk rows: window rows r-8..r+8 inside the band, r <= 12 (blocks 0..6); a 30-px REV
        // (15 blocks, centred window blocks b-7..b+8) reaches them up to block 13, rows 26-27.
        let near = flag.near_u8();
        assert_eq!(near[[27, 40]], 1);
        assert_eq!(near[[28, 40]], 0);
        assert_eq!(flag.tiles().column(0).to_vec(), vec![1.0, 0.0, 0.0]);
        // The texture is never bulk: nothing beyond the band's reach is flagged.
        assert!((28..100).all(|r| near.row(r).iter().all(|&v| v == 0)));
        // A later frame without the band is still flagged where the reference had it.
        let mut g1 = f.clone();
        g1.slice_mut(ndarray::s![..20, ..]).fill(0.3);
        sat.build(g1.view());
        flag.frame(&sat).unwrap();
        assert_eq!(flag.near_u8()[[27, 40]], 1);
        assert_eq!(flag.near_u8()[[28, 40]], 0);
    }

    #[test]
    fn bad_thresholds_are_refused() {
        let mut r = rule(3);
        r.liquid_below = 0.9;
        r.solid_above = 0.1;
        assert!(Flagger::new(r, 9).is_err());
        assert!(Flagger::new(rule(0), 9).is_err());
        assert!(Flagger::new(rule(3), 9).is_ok());
    }
}
