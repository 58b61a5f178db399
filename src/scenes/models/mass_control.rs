//! Mass scaling that follows the run (issue 13 item 7, `[dem.mass_scale_control]`).
//!
//! Scaling every mass by M lets the DEM step grow by √M (the critical step goes with √m), and
//! scales the inertial number of Eq. 20 by √M too (I = γ̇ d̄ √(ρ/p')). One fixed scale cannot
//! serve Simulation I: at the start of the shear the grains carry little stress and the scaled
//! I is highest (mass scale 16: 2.5e-3, 100: 5.1e-3), while from a few d̄ on p' is large enough
//! that 100 keeps I under Su's quasi-static 0.002 (docs/su2020.md, "The inertial number at mass
//! scale 16"). So the scale follows the measured I: every `every` LBM steps the run takes the
//! largest scale on its ladder that keeps the scaled I under the target.
//!
//! The ladder is the whole DEM-LBM ratios r from the scene's r_0 (its `[lattice] dt` over its
//! `[dem] dt`) up to where the scale reaches `smallest`; the scale at r is M_0 (r_0/r)², so the
//! DEM step δt/r keeps the scene's margin to the critical step on every rung, and the scaled I
//! at r is I(r) = I(r_now) r_now / r. A lighter scale is taken at once when I is over the
//! target; a heavier one only when I at it stays under [`RAISE_BELOW`] of the target, so that
//! the run does not hop between two rungs on the noise of p'.
//!
//! The decision reads the grains' state alone (the contact forces of the last DEM step), so a
//! run resumed from a checkpoint takes the same decisions.

use crate::scenes::schema::{HeldScale, MassScaleControl};
use anyhow::{Result, bail};

/// A heavier scale is taken only while the scaled I would stay under this share of the target.
pub const RAISE_BELOW: f64 = 0.8;

/// The rungs of the ladder and how the choice is made.
#[derive(Clone, Debug)]
pub struct MassControl {
    /// The scene's ratio r_0 and mass scale M_0: the top of the ladder.
    top_ratio: u32,
    top_scale: f64,
    /// The largest ratio (the smallest scale).
    bottom_ratio: u32,
    target: f64,
    pub every: u64,
    held: HeldScale,
}

impl MassControl {
    /// The ladder of a scene whose `[dem]` gives `mass_scale` = `top_scale` at `top_ratio` DEM
    /// steps per LBM step.
    pub fn new(c: &MassScaleControl, top_scale: f64, top_ratio: u32) -> Result<Self> {
        if c.smallest > top_scale {
            bail!(
                "[dem.mass_scale_control] smallest = {}: above [dem] mass_scale = {top_scale}, the top of the \
                 ladder; give a smaller one (1 = the grains' own masses)",
                c.smallest
            );
        }
        if c.every == 0 {
            bail!("[dem.mass_scale_control] every = 0: give the LBM steps between two choices (20)");
        }
        // M(r) >= smallest for r <= r_0 sqrt(M_0 / smallest); the rounding guards an exact rung.
        let bottom = (f64::from(top_ratio) * (top_scale / c.smallest).sqrt() * (1.0 + 1e-12)).floor();
        if bottom > f64::from(u32::MAX) {
            bail!(
                "[dem.mass_scale_control] smallest = {}: the ladder would need {bottom} DEM steps per LBM step; \
                 give a larger smallest scale",
                c.smallest
            );
        }
        let bottom_ratio = bottom as u32;
        if bottom_ratio <= top_ratio {
            bail!(
                "[dem.mass_scale_control] smallest = {}: with [dem] mass_scale = {top_scale} at {top_ratio} DEM \
                 steps per LBM step the ladder has no other rung (the next, {} steps, is a scale of {:.3}); \
                 give a smaller smallest scale or drop the control",
                c.smallest,
                top_ratio + 1,
                top_scale * (f64::from(top_ratio) / f64::from(top_ratio + 1)).powi(2)
            );
        }
        Ok(Self {
            top_ratio,
            top_scale,
            bottom_ratio,
            target: c.inertial_number,
            every: c.every,
            held: c.held,
        })
    }

    /// The mass scale at `ratio` DEM steps per LBM step.
    pub fn scale(&self, ratio: u32) -> f64 {
        self.top_scale * (f64::from(self.top_ratio) / f64::from(ratio)).powi(2)
    }

    /// The smallest mass scale of the ladder.
    pub fn smallest_scale(&self) -> f64 {
        self.scale(self.bottom_ratio)
    }

    /// The ratio to stand on while the plate is held, if the scene names one (`held =
    /// "smallest"`); with `"top"` the ratio the run has (the scene's, before the shear).
    pub fn held_ratio(&self) -> Option<u32> {
        match self.held {
            HeldScale::Top => None,
            HeldScale::Smallest => Some(self.bottom_ratio),
        }
    }

    /// The smallest ratio on the ladder at which I, measured as `inertial` at `ratio`, stays
    /// under `bound` (the bottom rung if none does).
    fn ratio_under(&self, inertial: f64, ratio: u32, bound: f64) -> u32 {
        let need = (inertial * f64::from(ratio) / bound).ceil();
        need.clamp(f64::from(self.top_ratio), f64::from(self.bottom_ratio)) as u32
    }

    /// The ratio to take next, given the scaled inertial number measured at `ratio` (NaN while
    /// the grains carry no stress: the ratio stays).
    pub fn choose(&self, ratio: u32, inertial: f64) -> u32 {
        if !(inertial.is_finite() && inertial > 0.0) {
            return ratio;
        }
        let lighter = self.ratio_under(inertial, ratio, self.target);
        if lighter > ratio {
            return lighter;
        }
        self.ratio_under(inertial, ratio, RAISE_BELOW * self.target)
            .min(ratio)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ladder(smallest: f64) -> Result<MassControl> {
        let c = MassScaleControl {
            inertial_number: 0.002,
            smallest,
            every: 20,
            held: HeldScale::Top,
        };
        // sim1-quick.toml: mass scale 100 at 10 DEM steps per LBM step
        MassControl::new(&c, 100.0, 10)
    }

    #[test]
    fn the_ladder_runs_from_the_scene_scale_to_the_smallest() {
        let m = ladder(1.0).unwrap();
        assert_eq!(m.bottom_ratio, 100, "Su Table 3's own ratio at the real masses");
        assert_eq!(m.scale(10), 100.0);
        assert!((m.scale(25) - 16.0).abs() < 1e-12);
        assert!((m.smallest_scale() - 1.0).abs() < 1e-12);
        // smallest 10: ratio 31 is scale 10.4, 32 would be 9.77
        assert_eq!(ladder(10.0).unwrap().bottom_ratio, 31);
        assert!(ladder(200.0).is_err(), "above the top");
        assert!(ladder(90.0).is_err(), "no second rung: 11 steps is 82.6");
    }

    #[test]
    fn the_scale_drops_at_once_and_rises_only_well_under_the_target() {
        let m = ladder(1.0).unwrap();
        // Mass scale 100 (ratio 10) measuring 5.1e-3 (sim1-quick at the start of the shear):
        // the first rung under 0.002 is ratio 26 (I = 5.1e-3 x 10/26 = 1.96e-3, scale 14.8).
        assert_eq!(m.choose(10, 5.1e-3), 26);
        // At ratio 26, I = 1.9e-3 is under the target but not under 0.8 x: it stays.
        assert_eq!(m.choose(26, 1.9e-3), 26);
        // At ratio 26, I = 1.0e-3: heavier up to I 1.6e-3, ratio ceil(26 / 1.6) = 17.
        assert_eq!(m.choose(26, 1.0e-3), 17);
        // Far under the target the top rung; far over it the bottom one.
        assert_eq!(m.choose(26, 1e-5), 10);
        assert_eq!(m.choose(10, 1.0), 100);
        // No stress yet: no change.
        assert_eq!(m.choose(26, f64::NAN), 26);
    }
}
