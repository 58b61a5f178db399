//! REV averaging (Su et al. 2020, Eq. 4b's `< >_REV` and Eq. 1b's `< >_A`) with a
//! summed-area table: any window sum costs four loads, so the sliding-window REV map is
//! O(1) per pixel whatever the REV side, and tiled grids and area means come free.
//!
//! NaN pixels are masked: the table then also counts finite pixels, and a window's mean
//! is over its finite pixels; windows are clipped at the image border. A window with fewer
//! finite pixels than `min_valid` times a full REV gives NaN.
//!
//! Parallel passes split rows (row pass, window pass) or fixed 256-column strips (column
//! pass); every sum is formed in the same order for any thread count, so results are
//! bitwise identical for 1 or N threads.

use crate::{ImagingError, Result};
use ndarray::{Array2, ArrayView2, Axis, Zip};
use rayon::prelude::*;

const COL_STRIP: usize = 256;

/// Summed-area table `S[r, c]` = sum of the finite pixels of rows `< r`, columns `< c`.
#[derive(Clone, Debug, Default)]
pub struct Sat {
    s: Array2<f64>,
    /// Finite-pixel counts, only when the field had NaNs.
    count: Option<Array2<u32>>,
}

impl Sat {
    pub fn new() -> Self {
        Self::default()
    }

    /// Image shape (rows, cols) the table was built from.
    pub fn dim(&self) -> (usize, usize) {
        let (h, w) = self.s.dim();
        (h.saturating_sub(1), w.saturating_sub(1))
    }

    fn reset(&mut self, h: usize, w: usize, masked: bool) {
        if self.s.dim() != (h + 1, w + 1) {
            self.s = Array2::zeros((h + 1, w + 1));
        }
        self.count = if masked {
            match self.count.take() {
                Some(c) if c.dim() == (h + 1, w + 1) => Some(c),
                _ => Some(Array2::zeros((h + 1, w + 1))),
            }
        } else {
            None
        };
    }

    /// Build from a field with NaN-masked pixels.
    pub fn build(&mut self, f: ArrayView2<f64>) {
        let (h, w) = f.dim();
        let masked = f.iter().any(|v| !v.is_finite());
        self.reset(h, w, masked);
        let rows = self.s.axis_iter_mut(Axis(0)).into_par_iter().skip(1);
        match &mut self.count {
            None => rows.zip(f.axis_iter(Axis(0))).for_each(|(mut srow, frow)| {
                let mut acc = 0.0;
                srow[0] = 0.0;
                for (o, &v) in srow.iter_mut().skip(1).zip(frow) {
                    acc += v;
                    *o = acc;
                }
            }),
            Some(cnt) => rows
                .zip(cnt.axis_iter_mut(Axis(0)).into_par_iter().skip(1))
                .zip(f.axis_iter(Axis(0)))
                .for_each(|((mut srow, mut crow), frow)| {
                    let (mut acc, mut n) = (0.0, 0u32);
                    srow[0] = 0.0;
                    crow[0] = 0;
                    for ((o, c), &v) in srow.iter_mut().skip(1).zip(crow.iter_mut().skip(1)).zip(frow) {
                        if v.is_finite() {
                            acc += v;
                            n += 1;
                        }
                        *o = acc;
                        *c = n;
                    }
                }),
        }
        self.column_pass();
    }

    /// Build from raw 16-bit counts through a lookup table (e.g. [`crate::beer_lambert::FractionMap::lut_u16`]):
    /// the fast path for integer frames. NaN table entries are masked.
    pub fn build_u16(&mut self, raw: ArrayView2<u16>, lut: &[f64]) {
        assert_eq!(lut.len(), 1 << 16, "lookup table must cover every u16 count");
        let (h, w) = raw.dim();
        let masked = lut.iter().any(|v| !v.is_finite()) && raw.iter().any(|&c| !lut[c as usize].is_finite());
        if masked {
            let f = raw.mapv(|c| lut[c as usize]);
            return self.build(f.view());
        }
        self.reset(h, w, false);
        // One pass writing the table: per row, the total of each fixed 256-column strip
        // (a cheap read of the 2-byte counts) gives every strip its row-prefix offset, so
        // strips then run in parallel, each adding its row prefix to the row above (still
        // in L1) — the table is written once, with no separate column pass. Strips and
        // summation order are fixed, so the result does not depend on the thread count.
        let nstrip = w.div_ceil(COL_STRIP);
        let mut offsets = Array2::<f64>::zeros((h, nstrip));
        offsets
            .axis_iter_mut(Axis(0))
            .into_par_iter()
            .zip(raw.axis_iter(Axis(0)))
            .for_each(|(mut orow, rrow)| {
                let mut acc = 0.0;
                for (k, o) in orow.iter_mut().enumerate() {
                    *o = acc;
                    let end = ((k + 1) * COL_STRIP).min(w);
                    acc += (k * COL_STRIP..end).map(|c| lut[rrow[c] as usize]).sum::<f64>();
                }
            });
        let w1 = w + 1;
        let data = self.s.as_slice_mut().expect("standard layout");
        data[..w1].fill(0.0);
        for r in 0..=h {
            data[r * w1] = 0.0;
        }
        let strips: Vec<(usize, usize)> = (0..nstrip)
            .map(|k| (k * COL_STRIP, ((k + 1) * COL_STRIP).min(w)))
            .collect();
        // Each strip writes columns c0+1..=c1 of every row: hand out disjoint raw pointers.
        struct Ptr(*mut f64);
        unsafe impl Send for Ptr {}
        unsafe impl Sync for Ptr {}
        let base = Ptr(data.as_mut_ptr());
        strips.par_iter().enumerate().for_each(|(k, &(c0, c1))| {
            let base = &base;
            for r in 0..h {
                let rrow = raw.row(r);
                let mut acc = offsets[[r, k]];
                // SAFETY: rows r and r+1 of the (h+1) x (w+1) table, columns c0+1..=c1, are
                // touched only by strip k; strips are disjoint column ranges.
                unsafe {
                    let prev = base.0.add(r * w1);
                    let cur = base.0.add((r + 1) * w1);
                    for c in c0..c1 {
                        acc += lut[rrow[c] as usize];
                        *cur.add(c + 1) = *prev.add(c + 1) + acc;
                    }
                }
            }
        });
    }

    /// Running sum down each column, in fixed column strips.
    fn column_pass(&mut self) {
        let h1 = self.s.nrows();
        self.s
            .axis_chunks_iter_mut(Axis(1), COL_STRIP)
            .into_par_iter()
            .for_each(|mut strip| {
                for r in 1..h1 {
                    let (prev, mut cur) = strip.view_mut().split_at(Axis(0), r);
                    let prev = prev.row(r - 1);
                    cur.row_mut(0).zip_mut_with(&prev, |c, &p| *c += p);
                }
            });
        if let Some(cnt) = &mut self.count {
            cnt.axis_chunks_iter_mut(Axis(1), COL_STRIP)
                .into_par_iter()
                .for_each(|mut strip| {
                    for r in 1..h1 {
                        let (prev, mut cur) = strip.view_mut().split_at(Axis(0), r);
                        let prev = prev.row(r - 1);
                        cur.row_mut(0).zip_mut_with(&prev, |c, &p| *c += p);
                    }
                });
        }
    }

    /// Sum and finite-pixel count over rows `r0..r1`, columns `c0..c1`.
    #[inline]
    pub fn window(&self, r0: usize, c0: usize, r1: usize, c1: usize) -> (f64, usize) {
        let s = &self.s;
        let sum = s[[r1, c1]] - s[[r0, c1]] - s[[r1, c0]] + s[[r0, c0]];
        let n = match &self.count {
            Some(c) => (c[[r1, c1]] + c[[r0, c0]] - c[[r0, c1]] - c[[r1, c0]]) as usize,
            None => (r1 - r0) * (c1 - c0),
        };
        (sum, n)
    }

    /// Mean over a rectangle (Eq. 1b's area average, e.g. the global g_S^0 over near the
    /// field of view); NaN if it holds no finite pixel.
    pub fn area_mean(&self, roi: crate::Roi) -> Result<f64> {
        roi.check("area", self.dim())?;
        let (s, n) = self.window(roi.y, roi.x, roi.y + roi.h, roi.x + roi.w);
        Ok(if n == 0 { f64::NAN } else { s / n as f64 })
    }

    /// One row `r` of the sliding-window REV mean (see [`Sat::rev_mean_into`]); `need` is the
    /// least number of finite pixels of a window with a mean.
    pub(crate) fn rev_row(&self, r: usize, side: usize, need: usize, orow: &mut [f64]) {
        let (h, w) = self.dim();
        let lo = side / 2;
        let hi = side - lo;
        // Columns whose window is not clipped: c - lo >= 0 and c + hi <= w.
        let (ci0, ci1) = (lo, (w + 1).saturating_sub(hi).max(lo));
        let r0 = r.saturating_sub(lo);
        let r1 = (r + hi).min(h);
        let slow = |c: usize| {
            let c0 = c.saturating_sub(lo);
            let c1 = (c + hi).min(w);
            let (s, n) = self.window(r0, c0, r1, c1);
            if n >= need { s / n as f64 } else { f64::NAN }
        };
        let rows = (self.s.row(r0).to_slice(), self.s.row(r1).to_slice());
        let (Some(top), Some(bot), None) = (rows.0, rows.1, &self.count) else {
            for (c, o) in orow.iter_mut().enumerate() {
                *o = slow(c);
            }
            return;
        };
        let n = (r1 - r0) * side;
        if n >= need && ci1 > ci0 {
            let inv = 1.0 / n as f64;
            let len = ci1 - ci0;
            let (tl, bl_) = (&top[..len], &bot[..len]);
            let (tr, br) = (&top[side..side + len], &bot[side..side + len]);
            for ((((o, &a), &b), &c), &d) in orow[ci0..ci1].iter_mut().zip(br).zip(tr).zip(bl_).zip(tl) {
                *o = (a - b - c + d) * inv;
            }
        } else {
            for (c, o) in orow.iter_mut().enumerate().take(ci1).skip(ci0) {
                *o = slow(c);
            }
        }
        // A window wider than the image leaves no interior: ci0 may exceed w.
        for c in (0..ci0.min(w)).chain(ci1..w) {
            orow[c] = slow(c);
        }
    }

    /// Sliding-window REV mean centred on every pixel (window rows `r - side/2 ..
    /// r - side/2 + side`, clipped to the image) into `out`. Interior columns of an
    /// unmasked table take a branch-free, vectorisable loop over contiguous rows.
    pub fn rev_mean_into(&self, side: usize, min_valid: f64, out: &mut Array2<f64>) -> Result<()> {
        let (h, w) = self.dim();
        check_side(side, h, w)?;
        if out.dim() != (h, w) || !out.is_standard_layout() {
            *out = Array2::zeros((h, w));
        }
        let need = (min_valid * (side * side) as f64).ceil().max(1.0) as usize;
        out.axis_iter_mut(Axis(0))
            .into_par_iter()
            .enumerate()
            .for_each(|(r, mut orow)| {
                self.rev_row(r, side, need, orow.as_slice_mut().expect("standard layout"));
            });
        Ok(())
    }

    /// [`Sat::rev_mean_into`] fused with Eq. (5): each REV row is turned into
    /// `eps_vol = g0 / g - 1` while still in cache (NaN where `g0 < min_gs`), saving a pass.
    pub fn rev_mean_eps_into(
        &self,
        side: usize,
        min_valid: f64,
        g0: ArrayView2<f64>,
        min_gs: f64,
        out: &mut Array2<f64>,
        eps: &mut Array2<f64>,
    ) -> Result<()> {
        let (h, w) = self.dim();
        check_side(side, h, w)?;
        for a in [&mut *out, &mut *eps] {
            if a.dim() != (h, w) || !a.is_standard_layout() {
                *a = Array2::zeros((h, w));
            }
        }
        if g0.dim() != (h, w) {
            return Err(ImagingError::invalid(
                "g0",
                format!("{:?}", g0.dim()),
                "must match the frame size",
            ));
        }
        let need = (min_valid * (side * side) as f64).ceil().max(1.0) as usize;
        out.axis_iter_mut(Axis(0))
            .into_par_iter()
            .zip(eps.axis_iter_mut(Axis(0)).into_par_iter())
            .zip(g0.axis_iter(Axis(0)).into_par_iter())
            .enumerate()
            .for_each(|(r, ((mut orow, mut erow), grow))| {
                let o = orow.as_slice_mut().expect("standard layout");
                self.rev_row(r, side, need, o);
                for ((e, &g), &a) in erow.iter_mut().zip(o.iter()).zip(grow) {
                    *e = if a >= min_gs {
                        crate::beer_lambert::eps_vol(a, g)
                    } else {
                        f64::NAN
                    };
                }
            });
        Ok(())
    }

    /// The REV mean at one pixel `(r, c)`, with the same arithmetic as [`Sat::rev_row`] gives
    /// that pixel (an unclipped window of an unmasked table: sum times the inverse count;
    /// otherwise the window's finite mean), so a map sampled on a grid holds the full map's bits.
    #[inline]
    fn rev_at(&self, r: usize, c: usize, side: usize, need: usize) -> f64 {
        let (h, w) = self.dim();
        let lo = side / 2;
        let hi = side - lo;
        let (r0, r1) = (r.saturating_sub(lo), (r + hi).min(h));
        let interior = c >= lo && c + hi <= w;
        let n = (r1 - r0) * side;
        if self.count.is_none() && interior && n >= need {
            let (s, _) = self.window(r0, c - lo, r1, c + hi);
            return s * (1.0 / n as f64);
        }
        let (s, n) = self.window(r0, c.saturating_sub(lo), r1, (c + hi).min(w));
        if n >= need { s / n as f64 } else { f64::NAN }
    }

    /// The REV map sampled at the centre pixel of every `step` x `step` block: element `(i, j)`
    /// is the full map's pixel `(i step + step/2, j step + step/2)`, bit for bit, and the map is
    /// `h / step` x `w / step` (a remainder strip narrower than a block is left out). An REV
    /// map is a window mean `side` px across, so a step well under the side loses nothing the
    /// window resolves, and the work and bytes fall by `step²` (issue 18 item 5). `eps` with
    /// `g0` (the reference map on the same grid) also fills Eq. (5), NaN where `g0 < min_gs`.
    pub fn rev_grid_into(
        &self,
        side: usize,
        min_valid: f64,
        step: usize,
        out: &mut Array2<f64>,
        eps: Option<(ArrayView2<f64>, f64, &mut Array2<f64>)>,
    ) -> Result<()> {
        let (h, w) = self.dim();
        check_side(side, h, w)?;
        if step == 0 || step > h || step > w {
            return Err(ImagingError::invalid(
                "map_step",
                step,
                "must be at least 1 px and at most the image side",
            ));
        }
        let dims = (h / step, w / step);
        if out.dim() != dims || !out.is_standard_layout() {
            *out = Array2::zeros(dims);
        }
        let need = (min_valid * (side * side) as f64).ceil().max(1.0) as usize;
        out.axis_iter_mut(Axis(0))
            .into_par_iter()
            .enumerate()
            .for_each(|(i, mut orow)| {
                for (j, o) in orow.iter_mut().enumerate() {
                    *o = self.rev_at(cell_centre(i, step), cell_centre(j, step), side, need);
                }
            });
        if let Some((g0, min_gs, e)) = eps {
            if g0.dim() != dims {
                return Err(ImagingError::invalid(
                    "g0",
                    format!("{:?}", g0.dim()),
                    "must match the map grid",
                ));
            }
            if e.dim() != dims {
                *e = Array2::zeros(dims);
            }
            crate::beer_lambert::eps_vol_into(g0, out.view(), min_gs, e);
        }
        Ok(())
    }

    pub fn rev_mean(&self, side: usize, min_valid: f64) -> Result<Array2<f64>> {
        let mut out = Array2::zeros(self.dim());
        self.rev_mean_into(side, min_valid, &mut out)?;
        Ok(out)
    }

    /// Means over a grid of non-overlapping `side` x `side` tiles starting at the top-left
    /// corner (a remainder strip narrower than a tile is left out).
    pub fn tiles(&self, side: usize, min_valid: f64) -> Result<Array2<f64>> {
        let (h, w) = self.dim();
        check_side(side, h, w)?;
        let need = (min_valid * (side * side) as f64).ceil().max(1.0) as usize;
        Ok(Array2::from_shape_fn((h / side, w / side), |(i, j)| {
            let (s, n) = self.window(i * side, j * side, (i + 1) * side, (j + 1) * side);
            if n >= need { s / n as f64 } else { f64::NAN }
        }))
    }
}

fn check_side(side: usize, h: usize, w: usize) -> Result<()> {
    if side == 0 || side > h || side > w {
        return Err(ImagingError::RevTooLarge {
            side_px: side,
            img_w: w,
            img_h: h,
        });
    }
    Ok(())
}

/// REV side in pixels: `rev_factor * d_bar / pixel_size` rounded (Su et al. 2020 take
/// `rev_factor = sqrt(10)`), at least 1.
pub fn rev_side_px(rev_factor: f64, d_bar: f64, pixel_size: f64) -> Result<usize> {
    for (n, v) in [
        ("rev_factor", rev_factor),
        ("d_bar", d_bar),
        ("pixel_size", pixel_size),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            return Err(ImagingError::invalid(
                n,
                v,
                "must be positive and finite (SI units: metres)",
            ));
        }
    }
    Ok(((rev_factor * d_bar / pixel_size).round() as usize).max(1))
}

/// The pixel (row or column) at the centre of cell `i` of a grid of `step` px cells (`step` odd):
/// where [`Sat::rev_grid_into`] evaluates the REV and every reader of such a map places it.
#[inline]
pub fn cell_centre(i: usize, step: usize) -> usize {
    i * step + step / 2
}

/// The default step of the REV maps' grid ([`Sat::rev_grid_into`]): the largest odd number of
/// pixels at most a sixteenth of the REV side, at least 1. Odd, so each value sits at the centre
/// pixel of its block; a sixteenth, so an REV spans 16 map cells and a profile or a field figure
/// loses nothing the window resolves (`docs/radiograph.md`, "The map grid").
pub fn map_step_auto(rev_side: usize) -> usize {
    let s = (rev_side / 16).max(1);
    if s.is_multiple_of(2) { s - 1 } else { s }
}

/// Naive O(side^2) reference of [`Sat::rev_mean`], for tests.
pub fn rev_mean_naive(f: ArrayView2<f64>, side: usize, min_valid: f64) -> Array2<f64> {
    let (h, w) = f.dim();
    let lo = side / 2;
    let need = (min_valid * (side * side) as f64).ceil().max(1.0) as usize;
    let mut out = Array2::zeros((h, w));
    Zip::indexed(&mut out).for_each(|(r, c), o| {
        let (mut s, mut n) = (0.0, 0);
        for rr in r.saturating_sub(lo)..(r + side - lo).min(h) {
            for cc in c.saturating_sub(lo)..(c + side - lo).min(w) {
                let v = f[[rr, cc]];
                if v.is_finite() {
                    s += v;
                    n += 1;
                }
            }
        }
        *o = if n >= need { s / n as f64 } else { f64::NAN };
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sat_matches_naive_with_mask_and_borders() {
        let mut f = Array2::from_shape_fn((37, 300), |(r, c)| ((r * 7 + c * 13) % 17) as f64 * 0.1);
        f[[3, 4]] = f64::NAN;
        f[[20, 290]] = f64::NAN;
        let mut sat = Sat::new();
        sat.build(f.view());
        let fast = sat.rev_mean(9, 0.3).unwrap();
        let slow = rev_mean_naive(f.view(), 9, 0.3);
        for (a, b) in fast.iter().zip(&slow) {
            assert!((a.is_nan() && b.is_nan()) || (a - b).abs() < 1e-9, "{a} vs {b}");
        }
        let t = sat.tiles(9, 0.5).unwrap();
        assert_eq!(t.dim(), (4, 33));
    }

    #[test]
    fn unmasked_fast_path_matches_naive() {
        let f = Array2::from_shape_fn((41, 333), |(r, c)| ((r * 5 + c * 11) % 23) as f64 * 0.07);
        let mut sat = Sat::new();
        sat.build(f.view());
        for side in [1, 8, 9, 41] {
            let fast = sat.rev_mean(side, 0.5).unwrap();
            let slow = rev_mean_naive(f.view(), side, 0.5);
            for (a, b) in fast.iter().zip(&slow) {
                assert!(
                    (a.is_nan() && b.is_nan()) || (a - b).abs() < 1e-9,
                    "side {side}: {a} vs {b}"
                );
            }
        }
    }

    #[test]
    fn u16_strip_pass_matches_float_build() {
        let raw = Array2::from_shape_fn((23, 600), |(r, c)| (100 + (r * 131 + c * 17) % 5000) as u16);
        let lut: Vec<f64> = (0..=u16::MAX as u32).map(|c| (c.max(1) as f64).ln()).collect();
        let f = raw.mapv(|c| lut[c as usize]);
        let (mut a, mut b) = (Sat::new(), Sat::new());
        a.build_u16(raw.view(), &lut);
        b.build(f.view());
        let (ra, rb) = (a.rev_mean(9, 0.5).unwrap(), b.rev_mean(9, 0.5).unwrap());
        // Corner windows hold too few pixels for min_valid and are NaN in both.
        let same = |x: f64, y: f64| (x.is_nan() && y.is_nan()) || (x - y).abs() < 1e-9;
        assert!(ra.iter().zip(&rb).all(|(x, y)| same(*x, *y)));
        assert!(ra.iter().filter(|v| v.is_finite()).count() > ra.len() / 2);
        // Reusing the table gives the same bits.
        a.build_u16(raw.view(), &lut);
        assert!(
            a.rev_mean(9, 0.5)
                .unwrap()
                .iter()
                .zip(&ra)
                .all(|(x, y)| x.to_bits() == y.to_bits())
        );
    }

    #[test]
    fn fused_eps_matches_separate_passes() {
        let f0 = Array2::from_shape_fn((30, 70), |(r, c)| 0.3 + ((r * 3 + c * 7) % 11) as f64 * 0.03);
        let f1 = f0.mapv(|v| v * 0.97 + 0.01);
        let mut sat = Sat::new();
        sat.build(f0.view());
        let g0 = sat.rev_mean(7, 0.5).unwrap();
        sat.build(f1.view());
        let g1 = sat.rev_mean(7, 0.5).unwrap();
        let (mut g, mut e) = (Array2::zeros((0, 0)), Array2::zeros((0, 0)));
        sat.rev_mean_eps_into(7, 0.5, g0.view(), 0.1, &mut g, &mut e)
            .unwrap();
        let e_ref = crate::beer_lambert::eps_vol_field(g0.view(), g1.view(), 0.1);
        assert!(g.iter().zip(&g1).all(|(a, b)| a.to_bits() == b.to_bits()));
        assert!(e.iter().zip(&e_ref).all(|(a, b)| a.to_bits() == b.to_bits()));
    }

    #[test]
    fn a_map_on_a_grid_holds_the_full_maps_bits_at_its_block_centres() {
        let f = Array2::from_shape_fn((47, 301), |(r, c)| ((r * 5 + c * 11) % 23) as f64 * 0.07);
        let mut masked = f.clone();
        masked[[20, 150]] = f64::NAN;
        for field in [&f, &masked] {
            let mut sat = Sat::new();
            sat.build(field.view());
            for (side, step) in [(9, 1), (9, 3), (12, 5), (41, 7)] {
                let full = sat.rev_mean(side, 0.5).unwrap();
                let e0 = full.mapv(|v| v * 0.9 + 0.05);
                let mut g = Array2::zeros((0, 0));
                let mut g0 = Array2::zeros((0, 0));
                let mut e = Array2::zeros((0, 0));
                sat.rev_grid_into(side, 0.5, step, &mut g0, None).unwrap();
                let g0 = g0.mapv(|v| v * 0.9 + 0.05);
                sat.rev_grid_into(side, 0.5, step, &mut g, Some((g0.view(), 0.1, &mut e)))
                    .unwrap();
                assert_eq!(g.dim(), (47 / step, 301 / step));
                let e_full = crate::beer_lambert::eps_vol_field(e0.view(), full.view(), 0.1);
                for ((i, j), v) in g.indexed_iter() {
                    let (r, c) = (i * step + step / 2, j * step + step / 2);
                    let same = |a: f64, b: f64| a.to_bits() == b.to_bits();
                    assert!(
                        same(*v, full[[r, c]]),
                        "side {side} step {step} ({r}, {c}): {v} vs {}",
                        full[[r, c]]
                    );
                    assert!(same(e[[i, j]], e_full[[r, c]]), "eps at ({r}, {c})");
                }
            }
        }
        let mut sat = Sat::new();
        sat.build(f.view());
        let mut g = Array2::zeros((0, 0));
        assert!(sat.rev_grid_into(9, 0.5, 0, &mut g, None).is_err());
        let auto: Vec<usize> = [1, 31, 32, 47, 48, 64, 95, 190].map(map_step_auto).to_vec();
        assert_eq!(auto, [1, 1, 1, 1, 3, 3, 5, 11]);
    }

    #[test]
    fn rev_larger_than_image_is_refused() {
        let f = Array2::<f64>::zeros((10, 20));
        let mut sat = Sat::new();
        sat.build(f.view());
        assert!(matches!(
            sat.rev_mean(11, 0.5),
            Err(ImagingError::RevTooLarge { side_px: 11, .. })
        ));
    }
}
