//! Flagging the REVs that reach a bulk phase: a region of pure liquid or pure solid at least a
//! grain across (a liquid gap, a container wall, a solid pad, a large grain), where the REV
//! strain of Eq. (5) is less accurate than inside the grain assembly.
//!
//! Why there: the detector averages intensity, not its logarithm, so a blurred pixel across a
//! sharp solid/liquid edge reads too much solid (Jensen's inequality). Inside an assembly the
//! bias is much the same in the reference and the deformed frame and cancels in `g0 / g`; an
//! REV that reaches a bulk phase has a lower or steeper `g_S` and the bias, divided by it, does
//! not cancel. Measured on synthetic radiographs (`tests/it/radiograph_edge_flag.rs`): the REV
//! strain error reached 0.008 within one REV of the liquid pad and stayed below 0.005 elsewhere.
//!
//! The rule: a pixel is bulk when the mean pixel solid fraction over a window of a few grains
//! (two by default in the stage) centred on it is below `liquid_below` or above `solid_above`;
//! an REV is flagged when its window holds a bulk pixel. Inside a packing such a window mixes
//! phases (a disk fills at most pi/4 of its bounding square; a liquid pocket of one grain is
//! averaged with its neighbours), so only regions larger than the window are bulk.

use crate::rev::{Sat, cell_centre};
use crate::{ImagingError, Result};
use ndarray::{Array2, Axis};
use rayon::prelude::*;

/// Margin by which the window mean is widened towards "bulk": the summed-area differences carry
/// round-off (about 1e-13 on a 2048² frame's window means), and a pixel that the exact rule
/// calls bulk must never be missed for it.
const ROUND_OFF: f64 = 1e-9;

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

    /// Whether a window mean is bulk (a NaN mean, too few finite pixels, is not).
    #[inline]
    fn is_bulk(&self, m: f64) -> bool {
        m < self.liquid_below + ROUND_OFF || m > self.solid_above - ROUND_OFF
    }
}

/// The bulk-phase flags of a sequence of frames, kept on a grid of blocks an eighth of the bulk
/// window across and read back per pixel. Conservative: a block is bulk when any of its pixels
/// is bulk by the exact per-pixel rule (window means from the frame's summed-area table), and a
/// block is flagged when the REV window of any of its pixels reaches a bulk block. So every REV
/// the per-pixel rule flags is flagged, and a flag's border lies at most two blocks less one
/// pixel beyond the per-pixel one (a quarter of the bulk window). The blocks keep the reach
/// (a dilation by the REV) cheap. Measured on a 2048² field of 60 px grains (window 120 px,
/// REV 190 px), 2 threads of a loaded 2-core EPYC, median of 11 (`examples/flag_timing.rs`):
/// `frame` 4.7 ms (the exact per-pixel window means are most of it), `near_u8` 0.3 ms, `tiles`
/// 0.01 ms. The former block rule took 0.4 ms in `frame` but 84 ms in its per-pixel
/// `near_u8`, not "a few milliseconds".
#[derive(Clone, Debug)]
pub struct Flagger {
    rule: BulkPhase,
    rev_side: usize,
    /// Block side, px.
    block: usize,
    /// Bulk blocks of the reference frame.
    bulk0: Option<Array2<u8>>,
    /// Bulk blocks of the reference or the current frame.
    bulk: Array2<u8>,
    /// Blocks holding a pixel whose REV window reaches a bulk block.
    near: Array2<u8>,
    /// Image shape of the reference frame, px.
    dim0: Option<(usize, usize)>,
}

/// Blocks (of `k` px along an axis of `n` px) that the REV windows (side `side`, `side / 2`
/// before the centre, clipped to the image) of the pixels of block `b` reach: `lo..hi`.
fn reach(b: usize, k: usize, n: usize, side: usize) -> (usize, usize) {
    let lo = side / 2;
    let first = b * k;
    let last = ((b + 1) * k).min(n) - 1;
    let from = first.saturating_sub(lo);
    let to = (last + side - lo).min(n);
    (from / k, to.div_ceil(k))
}

impl Flagger {
    pub fn new(rule: BulkPhase, rev_side: usize) -> Result<Self> {
        rule.validate()?;
        if rev_side == 0 {
            return Err(ImagingError::invalid("REV side", 0, "must be at least one pixel"));
        }
        Ok(Self {
            rule,
            rev_side,
            block: (rule.window_px / 8).max(1),
            bulk0: None,
            bulk: Array2::zeros((0, 0)),
            near: Array2::zeros((0, 0)),
            dim0: None,
        })
    }

    /// Block side, px.
    pub fn block(&self) -> usize {
        self.block
    }

    /// Flag the REVs of the next frame from the summed-area table of its pixel solid fraction.
    /// The first frame is the reference; later frames are flagged where they or the reference
    /// reach a bulk phase (Eq. 5 compares the two).
    pub fn frame(&mut self, g: &Sat) -> Result<()> {
        let (h, w) = g.dim();
        match self.dim0 {
            None => self.dim0 = Some((h, w)),
            Some((h0, w0)) if (h0, w0) != (h, w) => {
                return Err(ImagingError::SizeMismatch {
                    what: "edge flag: frame".into(),
                    want_h: h0,
                    want_w: w0,
                    got_h: h,
                    got_w: w,
                });
            }
            Some(_) => {}
        }
        if h == 0 || w == 0 {
            return Err(ImagingError::invalid("edge flag: frame", "0 px", "is empty"));
        }
        let k = self.block;
        let (bh, bw) = (h.div_ceil(k), w.div_ceil(k));
        let win = self.rule.window_px;
        // The window mean needs half a full window of finite pixels (as the REV maps).
        let need = ((0.5 * (win * win) as f64).ceil() as usize).max(1);
        let rule = self.rule;
        let mut bulk = Array2::<u8>::zeros((bh, bw));
        bulk.axis_iter_mut(Axis(0))
            .into_par_iter()
            .enumerate()
            .for_each(|(i, mut brow)| {
                let mut row = vec![0.0; w];
                for r in i * k..((i + 1) * k).min(h) {
                    g.rev_row(r, win, need, &mut row);
                    for (b, chunk) in brow.iter_mut().zip(row.chunks(k)) {
                        if *b == 0 && chunk.iter().any(|&m| rule.is_bulk(m)) {
                            *b = 1;
                        }
                    }
                }
            });
        match &self.bulk0 {
            None => self.bulk0 = Some(bulk.clone()),
            Some(b0) => bulk.zip_mut_with(b0, |a, &b| *a |= b),
        }
        // The reach of the REVs, separable: along the columns, then along the rows.
        let s = self.rev_side;
        let mut across = Array2::<u8>::zeros((bh, bw));
        for j in 0..bw {
            let (c0, c1) = reach(j, k, w, s);
            for i in 0..bh {
                across[[i, j]] = u8::from((c0..c1).any(|c| bulk[[i, c]] > 0));
            }
        }
        let mut near = Array2::<u8>::zeros((bh, bw));
        for i in 0..bh {
            let (r0, r1) = reach(i, k, h, s);
            for j in 0..bw {
                near[[i, j]] = u8::from((r0..r1).any(|r| across[[r, j]] > 0));
            }
        }
        self.near = near;
        self.bulk = bulk;
        Ok(())
    }

    /// Per pixel: 1 where the REV window centred on it may hold a bulk pixel of the last frame
    /// or the reference (always where it does; see [`Flagger`]), else 0.
    pub fn near_u8(&self) -> Array2<u8> {
        let (h, w) = self.dim0.unwrap_or((0, 0));
        let k = self.block;
        let mut out = Array2::<u8>::zeros((h, w));
        out.axis_chunks_iter_mut(Axis(0), k)
            .into_par_iter()
            .zip(self.near.axis_iter(Axis(0)).into_par_iter())
            .for_each(|(mut rows, flags)| {
                let mut pattern = vec![0u8; w];
                for (chunk, &f) in pattern.chunks_mut(k).zip(flags.iter()) {
                    chunk.fill(f);
                }
                for mut row in rows.axis_iter_mut(Axis(0)) {
                    match row.as_slice_mut() {
                        Some(r) => r.copy_from_slice(&pattern),
                        None => row.iter_mut().zip(&pattern).for_each(|(o, &p)| *o = p),
                    }
                }
            });
        out
    }

    /// [`Flagger::near_u8`] at the centre pixel of every `step` x `step` block, the grid of
    /// [`Sat::rev_grid_into`]: element `(i, j)` is the flag of pixel `(i step + step/2,
    /// j step + step/2)`.
    pub fn near_grid_u8(&self, step: usize) -> Array2<u8> {
        let (h, w) = self.dim0.unwrap_or((0, 0));
        let (k, step) = (self.block, step.max(1));
        Array2::from_shape_fn((h / step, w / step), |(i, j)| {
            self.near[[cell_centre(i, step) / k, cell_centre(j, step) / k]]
        })
    }

    /// Per tile of the non-overlapping REV grid of [`Sat::tiles`]: 1.0 where the tile overlaps
    /// a bulk block of the last frame or the reference (so every tile holding a bulk pixel).
    pub fn tiles(&self) -> Array2<f64> {
        let (h, w) = self.dim0.unwrap_or((0, 0));
        let (s, k) = (self.rev_side, self.block);
        Array2::from_shape_fn((h / s, w / s), |(i, j)| {
            let rows = (i * s) / k..((i + 1) * s).div_ceil(k).min(self.bulk.nrows());
            let cols = (j * s) / k..((j + 1) * s).div_ceil(k).min(self.bulk.ncols());
            let hit = rows.clone().any(|a| cols.clone().any(|b| self.bulk[[a, b]] > 0));
            if hit { 1.0 } else { 0.0 }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rev::rev_mean_naive;
    use rand::{RngExt, SeedableRng};

    fn rule(window_px: usize) -> BulkPhase {
        BulkPhase {
            window_px,
            liquid_below: 0.05,
            solid_above: 0.95,
        }
    }

    /// The per-pixel rule written out: a pixel is bulk when the mean of the finite pixels of the
    /// window centred on it (half a full window at least, clipped at the border) is outside the
    /// thresholds; an REV is flagged when its (clipped) window holds a bulk pixel of any frame.
    fn naive(frames: &[&Array2<f64>], rule: BulkPhase, side: usize) -> Array2<u8> {
        let (h, w) = frames[0].dim();
        let mut bulk = Array2::<bool>::from_elem((h, w), false);
        for f in frames {
            let m = rev_mean_naive(f.view(), rule.window_px, 0.5);
            bulk.zip_mut_with(&m, |b, &v| {
                *b |= v.is_finite() && (v < rule.liquid_below || v > rule.solid_above)
            });
        }
        let lo = side / 2;
        Array2::from_shape_fn((h, w), |(r, c)| {
            let rows = r.saturating_sub(lo)..(r + side - lo).min(h);
            let cols = c.saturating_sub(lo)..(c + side - lo).min(w);
            u8::from(rows.clone().any(|a| cols.clone().any(|b| bulk[[a, b]])))
        })
    }

    /// Misses (pixels the naive rule flags and the flagger does not) and the largest
    /// Chebyshev distance, px, from a pixel flagged only by the flagger to a naively flagged one.
    fn compare(fast: &Array2<u8>, slow: &Array2<u8>) -> (usize, usize) {
        let (h, w) = fast.dim();
        let misses = fast.iter().zip(slow).filter(|(f, s)| **s > 0 && **f == 0).count();
        let flagged: Vec<(usize, usize)> = slow
            .indexed_iter()
            .filter(|(_, v)| **v > 0)
            .map(|(p, _)| p)
            .collect();
        let mut extra = 0;
        for r in 0..h {
            for c in 0..w {
                if fast[[r, c]] > 0 && slow[[r, c]] == 0 {
                    let d = flagged
                        .iter()
                        .map(|&(a, b)| a.abs_diff(r).max(b.abs_diff(c)))
                        .min()
                        .unwrap_or(usize::MAX);
                    extra = extra.max(d);
                }
            }
        }
        (misses, extra)
    }

    fn run(frames: &[&Array2<f64>], rule: BulkPhase, side: usize) -> Flagger {
        let mut flag = Flagger::new(rule, side).unwrap();
        let mut sat = Sat::new();
        for f in frames {
            sat.build(f.view());
            flag.frame(&sat).unwrap();
        }
        flag
    }

    /// The band case of the review: row 13 is bulk by the per-pixel rule ((15 + 0.3) / 16 =
    /// 0.956 > 0.95), so the 30 px REVs reach it down to row 28; the old block rounding stopped
    /// at row 27. The texture is never bulk.
    #[test]
    fn band_matches_the_per_pixel_rule_without_misses() {
        let f = Array2::from_shape_fn((100, 80), |(r, c)| {
            if r < 20 {
                1.0
            } else if ((r / 5) + (c / 5)) % 2 == 0 {
                0.6
            } else {
                0.0
            }
        });
        let flag = run(&[&f], rule(16), 30);
        let near = flag.near_u8();
        let slow = naive(&[&f], rule(16), 30);
        assert_eq!(slow[[28, 40]], 1);
        assert_eq!(slow[[29, 40]], 0);
        let (misses, extra) = compare(&near, &slow);
        println!(
            "band: {misses} misses, {extra} px extra with {} px blocks",
            flag.block()
        );
        // Measured: no miss, 1 px extra (row 29: its block also holds row 28); bound 3 px.
        assert_eq!(misses, 0);
        assert!(extra < 2 * flag.block(), "extra {extra} px");
        assert!((31..100).all(|r| near.row(r).iter().all(|&v| v == 0)));
        assert_eq!(flag.tiles().column(0).to_vec(), vec![1.0, 0.0, 0.0]);
        // On a map grid, each flag is the full map's at its block's centre pixel.
        for step in [1, 3, 7] {
            let g = flag.near_grid_u8(step);
            assert_eq!(g.dim(), (100 / step, 80 / step));
            let centre = |i: usize| i * step + step / 2;
            assert!(
                g.indexed_iter()
                    .all(|((i, j), &v)| v == near[[centre(i), centre(j)]])
            );
        }
        // A later frame without the band is still flagged where the reference had it.
        let mut g1 = f.clone();
        g1.slice_mut(ndarray::s![..20, ..]).fill(0.3);
        let flag = run(&[&f, &g1], rule(16), 30);
        assert_eq!(compare(&flag.near_u8(), &slow).0, 0);
        assert_eq!(flag.near_u8()[[28, 40]], 1);
    }

    /// Random blobs of liquid and solid in a texture, windows and REVs that the block does not
    /// divide, a NaN patch, two frames: never a miss against the per-pixel rule, and at most two
    /// blocks less one pixel of extra width.
    #[test]
    fn random_fields_never_miss() {
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(5);
        let mut worst = 0.0f64;
        for case in 0..12 {
            let (h, w) = (rng.random_range(40..90), rng.random_range(40..90));
            let win = rng.random_range(5..30);
            let side = rng.random_range(3..40.min(h).min(w));
            let mut frames = Vec::new();
            for _ in 0..2 {
                let mut f = Array2::from_shape_fn((h, w), |_| rng.random_range(0.2..0.8));
                for _ in 0..3 {
                    let (r0, c0) = (rng.random_range(0..h), rng.random_range(0..w));
                    let (bh, bw) = (rng.random_range(3..h / 2), rng.random_range(3..w / 2));
                    let v = if rng.random_bool(0.5) { 1.0 } else { 0.0 };
                    f.slice_mut(ndarray::s![r0..(r0 + bh).min(h), c0..(c0 + bw).min(w)])
                        .fill(v);
                }
                if case % 3 == 0 {
                    let (r0, c0) = (rng.random_range(0..h - 4), rng.random_range(0..w - 4));
                    f.slice_mut(ndarray::s![r0..r0 + 4, c0..c0 + 4]).fill(f64::NAN);
                }
                frames.push(f);
            }
            let refs: Vec<&Array2<f64>> = frames.iter().collect();
            let flag = run(&refs, rule(win), side);
            let slow = naive(&refs, rule(win), side);
            let (misses, extra) = compare(&flag.near_u8(), &slow);
            let k = flag.block();
            assert_eq!(misses, 0, "case {case}: {h}x{w}, window {win}, REV {side}");
            // Measured: at most 1.00 block over the twelve cases; the bound is 2 blocks less 1 px.
            assert!(extra < 2 * k, "case {case}: {extra} px extra with {k} px blocks");
            worst = worst.max(extra as f64 / k as f64);
        }
        println!("largest extra width {worst:.2} blocks");
    }

    /// Frames of another size are refused, naming both sizes, even when their block grids are
    /// the same (40 and 39 rows both give 20 blocks of 2 px; the old check compared blocks).
    #[test]
    fn frames_of_another_size_are_refused_naming_both() {
        let mut flag = Flagger::new(rule(16), 9).unwrap();
        let mut sat = Sat::new();
        sat.build(Array2::<f64>::zeros((40, 50)).view());
        flag.frame(&sat).unwrap();
        sat.build(Array2::<f64>::zeros((39, 50)).view());
        let err = flag.frame(&sat).unwrap_err().to_string();
        assert!(err.contains("39x50") && err.contains("40x50"), "{err}");
    }

    #[test]
    fn bad_thresholds_are_refused() {
        let mut r = rule(3);
        r.liquid_below = 0.9;
        r.solid_above = 0.1;
        assert!(Flagger::new(r, 9).is_err());
        assert!(Flagger::new(rule(0), 9).is_err());
        assert!(Flagger::new(rule(3), 0).is_err());
        assert!(Flagger::new(rule(3), 9).is_ok());
    }
}
