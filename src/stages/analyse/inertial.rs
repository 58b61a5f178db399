//! The inertial number of a run (Su et al. 2020 Eq. 20) read two ways, because the paper and
//! issue 13 item 7 read it differently: Su take one number per run, "taking the effective mean
//! stress acting on the solid, p', from the simulations as the pressure" (Sect. 3.4); a run
//! that "stays quasi-static" keeps every output's I under the bound. Eq. 20 at a fixed plate
//! rate and grain mass is I ∝ 1/√p', so the one-per-run number is each output's I scaled by
//! √(p'/p̄'), p̄' the mean over the outputs. A run whose mass scale follows I
//! (`[dem.mass_scale_control]`) records its scale per output; I/√scale is then the grains' own
//! I, and Su's reading is taken of that.

use super::frames::median;
use serde::Serialize;

/// Su's bound for a quasi-static run (Sect. 3.4: the 1 and 30 µm/s runs "all have I ≤ 0.002").
pub const QUASI_STATIC: f64 = 0.002;

/// The inertial number over the shear (outputs after any settling).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct InertialSummary {
    /// Outputs counted.
    pub outputs: usize,
    pub median: f64,
    pub max: f64,
    /// Share of the outputs above [`QUASI_STATIC`].
    pub share_above_bound: f64,
    /// The last plate displacement (in d̄) at which I was above the bound, if ever.
    pub last_above_bound_u_d: Option<f64>,
    /// One number for the run, Su's way: Eq. 20 with the mean of the outputs' mean stress, at
    /// the run's masses (meaningless when the scale changed during the run: see the next).
    pub at_mean_stress: f64,
    /// The same with the grains' own masses (each output's I over √ its mass scale), when the
    /// series records the scale (`mass_scale`, a run whose scale follows I); else None.
    pub at_mean_stress_unscaled: Option<f64>,
}

/// The summary of the outputs `i` (inertial number), `p` (mean stress), `u_d` (plate
/// displacement in d̄), keeping those whose `settling` flag is 0 (all if there is none) and
/// whose I and p' are finite and positive; `scale`, the mass scale of each output when the run
/// records it. `None` if no output is left.
pub fn summarise(
    i: &[f64],
    p: &[f64],
    u_d: &[f64],
    settling: Option<&[f64]>,
    scale: Option<&[f64]>,
) -> Option<InertialSummary> {
    let keep: Vec<usize> = (0..i.len().min(p.len()).min(u_d.len()))
        .filter(|&k| settling.is_none_or(|s| s.get(k) == Some(&0.0)))
        .filter(|&k| i[k].is_finite() && i[k] > 0.0 && p[k].is_finite() && p[k] > 0.0)
        .collect();
    if keep.is_empty() {
        return None;
    }
    let n = keep.len() as f64;
    let kept: Vec<f64> = keep.iter().map(|&k| i[k]).collect();
    let mean_p = keep.iter().map(|&k| p[k]).sum::<f64>() / n;
    // I √p' is the same at every output (the rate and the mass are fixed): its mean over the
    // outputs, divided by √p̄'.
    let i_sqrt_p = keep.iter().map(|&k| i[k] * p[k].sqrt()).sum::<f64>() / n;
    // I ∝ √m: the grains' own I is each output's over √ its scale.
    let unscaled = scale.map(|m| {
        keep.iter()
            .map(|&k| i[k] / m.get(k).copied().unwrap_or(f64::NAN).sqrt() * p[k].sqrt())
            .sum::<f64>()
            / n
            / mean_p.sqrt()
    });
    Some(InertialSummary {
        outputs: keep.len(),
        median: median(&kept),
        max: kept.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        share_above_bound: keep.iter().filter(|&&k| i[k] > QUASI_STATIC).count() as f64 / n,
        last_above_bound_u_d: keep.iter().rev().find(|&&k| i[k] > QUASI_STATIC).map(|&k| u_d[k]),
        at_mean_stress: i_sqrt_p / mean_p.sqrt(),
        at_mean_stress_unscaled: unscaled,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sample that stiffens: p' grows tenfold over the shear at a fixed rate, so I = c/√p'
    /// falls by √10. The two readings differ as the module says, and the settling outputs
    /// (flag 1) are left out.
    #[test]
    fn the_two_readings_of_the_inertial_number() {
        let c = 1e-6;
        let p: Vec<f64> = (0..11).map(|k| 1e-6 * (1.0 + 0.9 * k as f64)).collect();
        let mut i: Vec<f64> = p.iter().map(|p| c / p.sqrt()).collect();
        let u: Vec<f64> = (0..11).map(|k| k as f64).collect();
        let mut settling = vec![0.0; 11];
        // A settling output with a huge I must not count.
        settling[0] = 1.0;
        i[0] = 1.0;
        let s = summarise(&i, &p, &u, Some(&settling), None).unwrap();
        assert_eq!(s.outputs, 10);
        assert_eq!(s.at_mean_stress_unscaled, None);
        // I = 1e-6 / sqrt(p): 1e-3 / sqrt(1.9) = 7.25e-4 at k = 1 down to 3.16e-4 at k = 10.
        assert!((s.max - c / p[1].sqrt()).abs() < 1e-15);
        assert_eq!(s.share_above_bound, 0.0);
        assert_eq!(s.last_above_bound_u_d, None);
        // Su's reading: c / sqrt(mean p) over k = 1..10 (mean 5.95e-6): 4.10e-4.
        let mean_p = p[1..].iter().sum::<f64>() / 10.0;
        assert!((s.at_mean_stress - c / mean_p.sqrt()).abs() < 1e-15 * s.at_mean_stress.max(1.0));
        assert!(s.at_mean_stress < s.max && s.at_mean_stress > s.median * 0.5);
        // Raise the rate fourfold: the early outputs pass the bound and the last one above it
        // is named.
        let fast: Vec<f64> = i.iter().map(|x| 4.0 * x).collect();
        let s = summarise(&fast, &p, &u, Some(&settling), None).unwrap();
        // 4e-6 / sqrt(p) > 0.002 while p < 4e-6: k = 1, 2, 3 (p = 1.9, 2.8, 3.7e-6).
        assert_eq!(s.last_above_bound_u_d, Some(3.0));
        assert!((s.share_above_bound - 0.3).abs() < 1e-12);
        // Without a settling column every output counts.
        assert_eq!(summarise(&i, &p, &u, None, None).unwrap().outputs, 11);
        // Nothing usable: None.
        assert_eq!(summarise(&[f64::NAN], &[1.0], &[0.0], None, None), None);
    }

    /// A run whose mass scale followed I: the same grains' own I = c/√p', recorded at scales
    /// that change from output to output. Su's reading at the grains' own masses comes back
    /// whatever the scales were; the scaled reading does not.
    #[test]
    fn a_changing_mass_scale_is_taken_out_of_su_s_reading() {
        let c = 1e-6;
        let p: Vec<f64> = (0..10).map(|k| 1e-6 * (1.0 + 0.9 * k as f64)).collect();
        let scale: Vec<f64> = (0..10).map(|k| 10.0 + 10.0 * k as f64).collect();
        let i: Vec<f64> = p
            .iter()
            .zip(&scale)
            .map(|(p, m)| c * m.sqrt() / p.sqrt())
            .collect();
        let u: Vec<f64> = (0..10).map(|k| k as f64).collect();
        let s = summarise(&i, &p, &u, None, Some(&scale)).unwrap();
        let mean_p = p.iter().sum::<f64>() / 10.0;
        let own = s.at_mean_stress_unscaled.unwrap();
        assert!((own - c / mean_p.sqrt()).abs() < 1e-12 * own, "{own}");
        // The scaled reading mixes the scales: above the grains' own by √(a mean scale).
        assert!(s.at_mean_stress > 3.0 * own, "{s:?}");
    }
}
