//! Wall contacts of a resting clump: is one leapfrog step stable for the grain pressed against a
//! wall? A contact's spring and dashpot act at the contact point, off the centroid, so they
//! drive the body's rotation as well as its translation, and the law sets its dashpot from the
//! body's mass m while the contact point moves like a lighter mass, 1/(1/m + ℓ²/I) for a lever ℓ
//! (a quarter of m for a two-circle grain). The step that keeps a lone disk's contact stable can
//! therefore overshoot on a clump, every step: friction then caps the swing, and the grain
//! rattles against the wall or creeps along it without end. Su's reduced Float case at Table 1's
//! step (6.66e-6 s, grain-wall 31.1 N/m, damping ratio 0.5) slid a grain lying on the top wall by
//! both circles along it at 4e-7 m/s for ever; at half the step, or with the damping ratio at
//! 0.25 or 0.1, every grain stopped (docs/stability.md, "Wall contacts of clumps").
//!
//! The check linearises the sticking contacts: generalised coordinates (x, y, ρθ), ρ the radius
//! of gyration, so that all three carry the mass m; each contact adds k g gᵀ to the stiffness and
//! c g gᵀ to the damping for its normal and tangential rows g,
//! and the step maps (q, h v) by the 6 × 6 matrix of the kick-drift-kick scheme with the dashpot
//! reading the half-step velocity (as [`lbdem_core::units::dem::damped_step_limit`] for one
//! spring). A step is stable when that matrix's spectral radius is at most 1. Each body is
//! checked lying on a wall by two circles at once (both touching, the resting state of an
//! elongated grain) and on one circle at the two extreme levers, wherever that circle is the
//! outermost one.

use crate::contact::SpringDashpots;
use crate::vector::{Vec2, Vector};
use nalgebra::{Matrix3, Matrix6};

/// Contact points (relative to the centroid, in a frame whose y axis points into the wall) of
/// one way a body can rest on a wall.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Resting {
    arms: Vec<Vec2>,
}

/// Every way the body of circles (`offsets`, `radii`, body frame) can rest on a flat wall that
/// the check looks at: by each feasible pair of circles, and by each outermost circle with its
/// offset along the wall normal or across it.
pub(crate) fn resting_ways(offsets: &[Vec2], radii: &[f64]) -> Vec<Resting> {
    let support = |d: Vec2, i: usize| offsets[i].dot(d) + radii[i];
    let outermost = |d: Vec2, touching: &[usize]| {
        let s = touching
            .iter()
            .map(|&i| support(d, i))
            .fold(f64::NEG_INFINITY, f64::max);
        (0..offsets.len()).all(|j| touching.contains(&j) || support(d, j) <= s + 1e-12 * radii[j])
    };
    // In the wall frame: y along d (towards the wall), x along the tangent.
    let frame = |d: Vec2, a: Vec2| Vec2::new(a.dot(Vec2::new(d.y, -d.x)), a.dot(d));
    let mut ways = Vec::new();
    let n = offsets.len();
    for i in 0..n {
        let s = offsets[i];
        let along = if s.norm() > 0.0 {
            s * (1.0 / s.norm())
        } else {
            Vec2::new(0.0, 1.0)
        };
        for d in [along, along.perp(), -along.perp()] {
            if outermost(d, &[i]) {
                ways.push(Resting {
                    arms: vec![frame(d, s + d * radii[i])],
                });
            }
        }
        for j in (i + 1)..n {
            let e = offsets[i] - offsets[j];
            let (l, dr) = (e.norm(), radii[j] - radii[i]);
            if l == 0.0 || dr.abs() > l {
                continue;
            }
            // (s_i − s_j)·d = r_j − r_i: d at angle ±acos(dr/l) from e.
            let (c, sn) = (dr / l, (1.0 - (dr / l).powi(2)).max(0.0).sqrt());
            let u = e * (1.0 / l);
            let d = Vec2::new(c * u.x - sn * u.y, sn * u.x + c * u.y);
            if outermost(d, &[i, j]) {
                ways.push(Resting {
                    arms: vec![
                        frame(d, offsets[i] + d * radii[i]),
                        frame(d, offsets[j] + d * radii[j]),
                    ],
                });
            }
        }
    }
    ways
}

/// Spectral radius of one step `h` for a body of mass `m` and moment of inertia `i` resting as
/// `way`, every contact with the springs and dashpots `sd`.
pub(crate) fn step_radius(way: &Resting, m: f64, i: f64, sd: &SpringDashpots, h: f64) -> f64 {
    // Coordinates (x, y, g θ) with g = √(I/m), the radius of gyration, so that all three carry
    // the mass m: the step matrix is then of order one throughout (in (x, y, θ) its rotation
    // entries are 1e14 times the others for these grains, and the eigenvalue solver's round-off
    // alone would split the free direction's double eigenvalue 1 by 1e-5).
    let g = (i / m).sqrt();
    let mut k = Matrix3::<f64>::zeros();
    let mut c = Matrix3::<f64>::zeros();
    for a in &way.arms {
        // Velocity of the contact point along the normal (y) and the tangent (x).
        let rows = [
            (nalgebra::Vector3::new(0.0, 1.0, a.x / g), sd.normal),
            (nalgebra::Vector3::new(1.0, 0.0, -a.y / g), sd.tangential),
        ];
        for (row, (ks, cs)) in rows {
            let outer = row * row.transpose();
            k += outer * ks;
            c += outer * cs;
        }
    }
    let eye = Matrix3::<f64>::identity();
    let (wk, damp) = (k * (h * h / m), eye - c * (h / m));
    let mut step = Matrix6::<f64>::zeros();
    // (q', u') from (q, u), u = h v: u' = damp u − h² K/m q; q' = q + u'.
    step.fixed_view_mut::<3, 3>(0, 0).copy_from(&(eye - wk));
    step.fixed_view_mut::<3, 3>(0, 3).copy_from(&damp);
    step.fixed_view_mut::<3, 3>(3, 0).copy_from(&(-wk));
    step.fixed_view_mut::<3, 3>(3, 3).copy_from(&damp);
    step.complex_eigenvalues()
        .iter()
        .map(|z| z.norm())
        .fold(0.0, f64::max)
}

/// Whether step `h` is stable for every resting way. One contact leaves the body a free
/// direction, a double eigenvalue 1 that round-off splits by about √ε ≈ 1.5e-8, so a radius up
/// to 1 + 1e-6 counts as stable (a mode growing that slowly needs 10⁶ steps to grow e-fold).
pub(crate) fn stable(ways: &[Resting], m: f64, i: f64, sd: &SpringDashpots, h: f64) -> bool {
    ways.iter().all(|w| step_radius(w, m, i, sd, h) <= 1.0 + 1e-6)
}

/// The step below which every resting way is stable: the first instability met scanning up
/// from a tenth of Verlet's limit for the stiffest spring on the body's mass in steps of 2 %,
/// then bisected to a relative 1e-6. Stability need not be monotonic in the step once dashpots
/// couple rotation and translation (a way can be unstable in a window and stable above it), so
/// the first onset, not a bisection over the whole range, is the step that is safe to advise.
pub(crate) fn largest_stable_step(ways: &[Resting], m: f64, i: f64, sd: &SpringDashpots) -> f64 {
    let k_max = sd.normal.0.max(sd.tangential.0);
    if ways.is_empty() || k_max <= 0.0 {
        return f64::INFINITY;
    }
    let mut lo = 0.2 * (m / k_max).sqrt();
    if !stable(ways, m, i, sd, lo) {
        lo = 0.0;
    }
    let mut hi = if lo > 0.0 {
        lo * 1.02
    } else {
        0.2 * (m / k_max).sqrt()
    };
    while stable(ways, m, i, sd, hi) {
        lo = hi;
        hi *= 1.02;
        if hi > 1e3 * (m / k_max).sqrt() {
            return f64::INFINITY;
        }
    }
    while hi - lo > 1e-6 * hi {
        let mid = 0.5 * (lo + hi);
        if stable(ways, m, i, sd, mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo
}

#[cfg(test)]
mod tests {
    use super::*;

    fn linear(k_n: f64, zeta: f64, m: f64) -> SpringDashpots {
        let c = 2.0 * zeta * (k_n * m).sqrt();
        SpringDashpots {
            normal: (k_n, c),
            tangential: (0.5 * k_n, 0.5 * c),
        }
    }

    /// A disk on one contact without its tangential spring is the scalar spring-dashpot: the
    /// same limit as the closed form, to the bisection's 1e-6.
    #[test]
    fn a_disk_without_friction_has_the_closed_form_limit() {
        let (m, k, zeta) = (2.0e-9_f64, 31.1_f64, 0.5);
        let c = 2.0 * zeta * (k * m).sqrt();
        let sd = SpringDashpots {
            normal: (k, c),
            tangential: (0.0, 0.0),
        };
        let ways = resting_ways(&[Vec2::ZERO], &[3.0e-5]);
        let got = largest_stable_step(&ways, m, 0.5 * m * 9.0e-10, &sd);
        let want = lbdem_core::units::dem::damped_step_limit(k, c, m);
        assert!((got / want - 1.0).abs() < 2e-6, "{got} vs {want}");
    }

    /// The grain of the reduced Float case that crept along the top wall (body 82 at step
    /// 450 450: circles r = 35 and 30 µm, 34.6 µm apart, both on the wall; m = 2.910e-9 kg,
    /// I = 2.814e-18 kg m² by integrating its area at 0.5268 kg/m²): unstable at Table 1's
    /// 6.66e-6 s with damping ratio 0.5, stable at half that step and at ratio 0.25 and 0.1,
    /// as the runs were. An independent time-stepping of the same linear system
    /// (`scripts/wall-mode-timestep.py`) put the limit at 5.759e-6 s (ratio 0.5), 8.124e-6 s
    /// (0.25) and 1.024e-5 s (0.1); the eigenvalue form agrees within 5e-4 (measured 2.5e-4 at
    /// most: the script's four digits and its finite-run bisection against the spectral radius).
    #[test]
    fn the_creeping_float_grain_is_unstable_at_table_1s_step_and_stable_at_half() {
        let (m, i) = (2.910_140_25e-9, 2.813_667_7e-18);
        let centroid = Vec2::new(0.000_440_745_1, 0.001_166_957_8);
        let circles = [
            (0.000_427_193, 0.001_165, 35e-6),
            (0.000_461_834, 0.001_17, 30e-6),
        ];
        let offsets: Vec<Vec2> = circles.iter().map(|c| Vec2::new(c.0, c.1) - centroid).collect();
        let radii: Vec<f64> = circles.iter().map(|c| c.2).collect();
        let ways = resting_ways(&offsets, &radii);
        assert!(ways.iter().any(|w| w.arms.len() == 2), "{ways:?}");
        for (zeta, python) in [(0.5, 5.759e-6), (0.25, 8.124e-6), (0.1, 1.024e-5)] {
            let sd = linear(31.1, zeta, m);
            let two: Vec<Resting> = ways.iter().filter(|w| w.arms.len() == 2).cloned().collect();
            let got = largest_stable_step(&two, m, i, &sd);
            assert!(
                (got / python - 1.0).abs() < 5e-4,
                "zeta {zeta}: {got} vs {python}"
            );
        }
        assert!(!stable(&ways, m, i, &linear(31.1, 0.5, m), 6.66e-6));
        assert!(stable(&ways, m, i, &linear(31.1, 0.5, m), 3.33e-6));
        assert!(stable(&ways, m, i, &linear(31.1, 0.25, m), 6.66e-6));
    }
}
