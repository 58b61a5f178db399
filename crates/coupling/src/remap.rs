//! The solid map kept from one LBM step to the next, each grain's cover recomputed only when
//! the grain has moved (Su et al. 2020 Fig. 2 step 10 maps every grain every LBM step).
//!
//! In a quasi-static shear cell a grain moves about 1e-3 of a lattice cell per LBM step, yet
//! the exact cell-circle geometry of [`crate::overlap`] was most of a coupled step's cost
//! (docs/su2020.md, "Speed"). With `tolerance = 0` a grain is mapped again whenever any of its
//! circles moved at all, which gives the bits of [`crate::solid_fraction::solid_map`]; with a
//! tolerance δ > 0 (lattice cells) the liquid sees each grain where it was last mapped, at most
//! δ from where it is, while the velocities in the collision stay those of the present step.
//! The circles each grain was last mapped at are part of a coupled checkpoint, so a resumed
//! run maps the same grains at the same steps.

use crate::solid_fraction::{CellCover, GrainCircle, SolidMap, assemble, grain_cover};
use rayon::prelude::*;

/// Per-grain covers with the circles (scaled by r_hd) they were computed for.
#[derive(Clone, Debug, Default)]
pub struct SolidMapper {
    /// Largest displacement (lattice cells) of any circle centre before its grain is mapped
    /// again; 0 maps a grain whenever it moved.
    tolerance: f64,
    /// The circles each grain was last mapped at (scaled), grouped by body as given.
    mapped: Vec<GrainCircle>,
    /// `mapped[bounds[g]..bounds[g + 1]]` are the circles of grain group `g`.
    bounds: Vec<usize>,
    covers: Vec<Vec<CellCover>>,
    /// The lattice and boundaries the covers were computed for.
    grid: Option<(usize, usize, [bool; 2])>,
    /// Grains mapped again in the last call (for the run's statistics and tests).
    pub remapped: usize,
    /// Scratch of the counting sort (kept: a fresh lattice-sized buffer per step page-faults).
    start: Vec<u32>,
}

impl SolidMapper {
    /// A mapper that maps a grain again once it moved more than `tolerance` cells (≥ 0, finite;
    /// the scene checks it).
    pub fn new(tolerance: f64) -> Self {
        Self {
            tolerance,
            ..Self::default()
        }
    }

    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The circles (scaled by r_hd) each grain was last mapped at: what a checkpoint stores.
    pub fn mapped(&self) -> &[GrainCircle] {
        &self.mapped
    }

    /// Continue from circles returned by [`SolidMapper::mapped`]: the covers are recomputed
    /// from them, so the next [`SolidMapper::map`] gives what the uninterrupted run gave.
    pub fn restore(&mut self, mapped: Vec<GrainCircle>, nx: usize, ny: usize, periodic: [bool; 2]) {
        self.mapped = mapped;
        self.bounds = group_bounds(&self.mapped);
        self.covers = self
            .bounds
            .par_windows(2)
            .map(|w| grain_cover(&self.mapped[w[0]..w[1]], nx, ny, periodic))
            .collect();
        self.grid = Some((nx, ny, periodic));
    }

    /// Map `circles` (lattice units, grouped by body in ascending body order) with radii scaled
    /// by `r_hd` onto `map` (an `nx` × `ny` lattice), mapping again only the grains that moved
    /// more than the tolerance since they were last mapped.
    pub fn map(&mut self, circles: &[GrainCircle], r_hd: f64, periodic: [bool; 2], map: &mut SolidMap) {
        let (nx, ny) = (map.nx, map.ny);
        let scaled = circles.iter().map(|c| GrainCircle {
            radius: c.radius * r_hd,
            ..*c
        });
        let same_layout = self.grid == Some((nx, ny, periodic))
            && self.mapped.len() == circles.len()
            && self
                .mapped
                .iter()
                .zip(scaled.clone())
                .all(|(a, b)| a.body == b.body && a.radius == b.radius);
        if !same_layout {
            self.restore(scaled.collect(), nx, ny, periodic);
            self.remapped = self.covers.len();
        } else {
            let tol2 = self.tolerance * self.tolerance;
            let stale: Vec<bool> = self
                .bounds
                .windows(2)
                .map(|w| {
                    (w[0]..w[1]).any(|c| {
                        let (a, b) = (self.mapped[c].centre, circles[c].centre);
                        let d2 = (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2);
                        // At tolerance 0 any move; NaN positions are mapped again too (and
                        // refused downstream).
                        d2 > tol2 || d2.is_nan()
                    })
                })
                .collect();
            for (g, w) in self.bounds.windows(2).enumerate() {
                if stale[g] {
                    for c in w[0]..w[1] {
                        self.mapped[c].centre = circles[c].centre;
                    }
                }
            }
            let mapped = &self.mapped;
            let bounds = &self.bounds;
            self.covers
                .par_iter_mut()
                .enumerate()
                .filter(|(g, _)| stale[*g])
                .for_each(|(g, cover)| {
                    *cover = grain_cover(&mapped[bounds[g]..bounds[g + 1]], nx, ny, periodic);
                });
            self.remapped = stale.iter().filter(|&&s| s).count();
        }
        assemble(&self.covers, map, &mut self.start);
    }
}

/// Start of each run of circles of one body, and the end.
fn group_bounds(circles: &[GrainCircle]) -> Vec<usize> {
    let mut b: Vec<usize> = (0..circles.len())
        .filter(|&c| c == 0 || circles[c].body != circles[c - 1].body)
        .collect();
    b.push(circles.len());
    b
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solid_fraction::solid_map;

    fn grains(shift: f64) -> Vec<GrainCircle> {
        (0..60u32)
            .flat_map(|k| {
                let (x, y) = (
                    (k % 10) as f64 * 4.1 + 2.0 + shift * k as f64,
                    (k / 10) as f64 * 4.3 + 2.0,
                );
                [
                    GrainCircle {
                        body: k,
                        centre: [x, y],
                        radius: 1.3,
                    },
                    GrainCircle {
                        body: k,
                        centre: [x + 0.9, y + 0.4],
                        radius: 1.1,
                    },
                ]
            })
            .collect()
    }

    fn empty(nx: usize, ny: usize) -> SolidMap {
        SolidMap {
            nx,
            ny,
            covers: Vec::new(),
            total: Vec::new(),
        }
    }

    #[test]
    fn at_tolerance_zero_it_gives_the_bits_of_a_fresh_map() {
        let mut m = SolidMapper::new(0.0);
        let mut out = empty(48, 30);
        for step in 0..4 {
            let c = grains(1e-3 * step as f64);
            m.map(&c, 0.8, [true, false], &mut out);
            assert_eq!(out, solid_map(&c, 0.8, 48, 30, [true, false]), "step {step}");
        }
        // Grain 0 does not move with this shift; every other grain does.
        assert_eq!(m.remapped, 59);
    }

    #[test]
    fn a_grain_is_mapped_again_only_past_the_tolerance() {
        let mut m = SolidMapper::new(0.05);
        let mut out = empty(48, 30);
        m.map(&grains(0.0), 0.8, [false; 2], &mut out);
        assert_eq!(m.remapped, 60);
        // Grain k moves by 1e-3 k cells: grains 51..59 pass 0.05.
        m.map(&grains(1e-3), 0.8, [false; 2], &mut out);
        assert_eq!(m.remapped, 9);
        // The map is the fresh map of the positions each grain was mapped at.
        assert_eq!(out, solid_map(m.mapped(), 1.0, 48, 30, [false; 2]));
        // A resumed mapper maps the same grains at the next step as the uninterrupted one.
        let mut r = SolidMapper::new(0.05);
        r.restore(m.mapped().to_vec(), 48, 30, [false; 2]);
        let (mut a, mut b) = (empty(48, 30), empty(48, 30));
        m.map(&grains(1.5e-3), 0.8, [false; 2], &mut a);
        r.map(&grains(1.5e-3), 0.8, [false; 2], &mut b);
        assert_eq!((m.remapped, &a), (r.remapped, &b));
        assert_eq!(
            m.remapped, 17,
            "grains 34..50 have now passed 0.05 too, 51..59 not again"
        );
    }

    #[test]
    fn a_changed_grain_set_is_mapped_afresh() {
        let mut m = SolidMapper::new(0.5);
        let mut out = empty(48, 30);
        m.map(&grains(0.0), 0.8, [false; 2], &mut out);
        let fewer = &grains(0.0)[..100];
        m.map(fewer, 0.8, [false; 2], &mut out);
        assert_eq!(out, solid_map(fewer, 0.8, 48, 30, [false; 2]));
    }
}
