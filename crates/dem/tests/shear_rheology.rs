//! Simple shear of a dense bidisperse suspension on Lees-Edwards boundaries with Ness et al.
//! (2017)'s model (lubrication Eqs. 3-5 + linear spring Eq. 6; d and 1.5 d, 1:1 by number), the
//! particle stress from the force dipoles (Eq. 7, `dipole_stress`), against the frictional
//! rheology of Boyer, Guazzelli & Pouliquen (2011), PRL 107, 188301: at fixed φ the viscous number
//! is I_v = (φ_m/φ − 1)² (from φ(I_v) = φ_m/(1 + I_v^{1/2})), so P/(η γ̇) = 1/I_v and
//! τ/P = μ(I_v) = μ_1 + (μ_2 − μ_1)/(1 + I_0/I_v) + I_v + (5/2) φ_m I_v^{1/2}, with μ_1 = 0.32,
//! μ_2 = 0.7, I_0 = 0.005, φ_m = 0.585 (quoted from memory of the paper: no stored copy of it
//! was found to check them against). Boyer's τ is the whole shear stress, the solvent's η γ̇
//! included (the `+ I_v` term), and P the particles' normal stress across the gradient (σ_yy); the
//! simulated stress is the particles' alone, so μ is compared as (−σ_xy + η γ̇)/σ_yy, with
//! −σ_xy/(tr σ/3) printed beside it.
//!
//! Units: small diameter d = 1, density ρ = 1, viscosity η = 1, so the shear rate is the Stokes
//! number St = ρ γ̇ d²/η. Quick (CI) and full (`#[ignore]`) runs; figures in `docs/dem3d.md`.
//!
//! Run: `cargo test -p lbdem-dem --test dem shear_rheology:: -- --nocapture` (CI case) and
//! `cargo test -p lbdem-dem --test dem shear_rheology:: -- --ignored --nocapture` (flow curve).

use crate::suspension;

use lbdem_dem::Vector;
use lbdem_dem::spheres::{SphereLaw, SphereStepParams, SphereStepper, dipole_stress};
use std::time::Instant;
use suspension::{ETA, ness_law, sheared};

/// Boyer et al. (2011)'s constants.
const MU_1: f64 = 0.32;
const MU_2: f64 = 0.7;
const I_0: f64 = 0.005;
const PHI_M: f64 = 0.585;

/// The viscous number of Boyer's φ(I_v) at volume fraction `phi`.
fn boyer_iv(phi: f64) -> f64 {
    (PHI_M / phi - 1.0).powi(2)
}

/// Boyer's μ(I_v).
fn boyer_mu(iv: f64) -> f64 {
    MU_1 + (MU_2 - MU_1) / (1.0 + I_0 / iv) + iv + 2.5 * PHI_M * iv.sqrt()
}

/// Tolerances of the CI case: 2 × (|deviation| + 2 standard errors) of the measured run, so a
/// reordering of the sums (which re-rolls the trajectory) stays inside them; figures in
/// `docs/dem3d.md` and in the comments at the assertions. The run is serial and seeded, so CI
/// reproduces its figures bit for bit.
/// Measured 2026-11-26 (μ and P as Boyer define them, blocks of half a strain unit): μ −1.1 %
/// (SE 4.1 %), σ_yy −15.7 % (SE 12.6 %): the 2-strain window of 200 spheres is noisy, and these
/// bounds say so; the flow curve (400 spheres, 3.5 strain units) is the tighter check.
const TOL_MU: f64 = 0.19;
const TOL_P: f64 = 0.82;
/// Mean v_x(y) slope over γ̇: measured 1.035.
const TOL_SLOPE: f64 = 0.07;
/// Whole shear viscosity 0.55/0.45 at least Boyer's 10.8 (it rises at least as steeply) and
/// within a factor 2.9 of it: measured 18.3, 1.69× Boyer's, the factor twice that in log.
const RATIO_MIN: f64 = 10.7;
const RATIO_MAX_OVER_BOYER: f64 = 2.9;

/// A sheared run's time averages.
#[derive(Debug, Clone, Copy)]
struct Flow {
    phi: f64,
    /// P/(η γ̇), P = tr σ/3.
    p: f64,
    /// The particles' σ_yy/(η γ̇): Boyer's P (the normal stress across the gradient).
    p_yy: f64,
    /// Shear stress −σ_xy/(η γ̇) (compression-positive σ: the stress resisting the shear is
    /// negative there), the mean of the xy and yx entries.
    shear: f64,
    /// The hydrodynamic part of `shear`.
    shear_hydro: f64,
    /// μ as Boyer measure it, (shear + 1)/p_yy of the averages (η γ̇ = 1 in these units).
    mu: f64,
    /// −σ_xy/(tr σ/3) of the averages (the particles' stress ratio).
    mu_trace: f64,
    /// Standard error of `mu` over blocks of half a strain unit (spread/√blocks); NaN with fewer
    /// than four blocks.
    mu_err: f64,
    /// Standard error of `p_yy` over the same blocks.
    p_err: f64,
    /// Largest overlap seen in the averaging window (in units of d).
    max_overlap: f64,
    /// Slope of the mean v_x against y over γ̇ (1: the imposed affine profile), averaged.
    slope: f64,
    steps: usize,
    seconds: f64,
}

/// Shear `n` spheres at `phi` and Stokes number `st` to the strain `strain`, averaging the
/// stress from strain `start` on (a sample every `every` steps).
#[allow(clippy::too_many_arguments)]
fn shear_run(
    n: usize,
    phi: f64,
    st: f64,
    k_hat: f64,
    mu_p: f64,
    fraction: f64,
    strain: f64,
    start: f64,
    seed: u64,
) -> Flow {
    let rate = st * ETA; // ρ = d = 1
    let mut law = ness_law(k_hat * ETA * rate, mu_p);
    law.lubrication.stability_fraction = fraction;
    law.contact.stability_fraction = fraction;
    let mut sys = sheared(n, phi, rate, seed);
    let small = (0..sys.spheres.len())
        .map(|k| law.max_time_step(sys.spheres.radius[k], sys.spheres.mass[k]).dt)
        .fold(f64::INFINITY, f64::min);
    let dt = small;
    let p = SphereStepParams::new(dt, 0.1);
    let mut stepper = SphereStepper::new();
    stepper.record_contacts(true);
    let l = sys.domain.size();
    let vol = l.x * l.y * l.z;
    let steps = (strain / (rate * dt)).ceil() as usize;
    let first = (start / (rate * dt)).ceil() as usize;
    let every = 20;
    let per_block = (0.5 / (rate * dt)).ceil() as usize;
    let t0 = Instant::now();
    let (mut sum_p, mut sum_s, mut sum_h, mut sum_yy, mut samples) = (0.0, 0.0, 0.0, 0.0, 0usize);
    // Blocks of half a strain unit: (Σ σ_yy, Σ shear, samples) each; the sample's block is known
    // before it is added, and the last (possibly partial) block is kept.
    let mut blocks: Vec<(f64, f64, usize)> = Vec::new();
    let mut max_overlap = 0.0f64;
    let mut slope = 0.0;
    for k in 1..=steps {
        stepper.step(&p, &law, &mut sys).unwrap();
        if k < first || k % every != 0 {
            continue;
        }
        let rec = stepper.contacts();
        let sp = &sys.spheres;
        let nn = sp.len() as f64;
        let (ym, vm) = (
            sp.pos.iter().map(|p| p.y).sum::<f64>() / nn,
            sp.vel.iter().map(|v| v.x).sum::<f64>() / nn,
        );
        let (mut sxy, mut syy) = (0.0, 0.0);
        for (p, v) in sp.pos.iter().zip(&sp.vel) {
            sxy += (p.y - ym) * (v.x - vm);
            syy += (p.y - ym) * (p.y - ym);
        }
        slope += sxy / syy / rate;
        let s = dipole_stress(rec, vol, false);
        let h = dipole_stress(rec, vol, true);
        let pr = (s[0][0] + s[1][1] + s[2][2]) / 3.0;
        let sh = -0.5 * (s[0][1] + s[1][0]);
        sum_p += pr;
        sum_s += sh;
        sum_h += -0.5 * (h[0][1] + h[1][0]);
        samples += 1;
        sum_yy += s[1][1];
        let b = (k - first) / per_block;
        if b >= blocks.len() {
            blocks.resize(b + 1, (0.0, 0.0, 0));
        }
        blocks[b].0 += s[1][1];
        blocks[b].1 += sh;
        blocks[b].2 += 1;
        for c in rec {
            if let lbdem_dem::spheres::Partner::Sphere(j) = c.j {
                let (i, j) = (c.i as usize, j as usize);
                let ov = sys.spheres.radius[i] + sys.spheres.radius[j] - c.branch.norm();
                max_overlap = max_overlap.max(ov);
            }
        }
    }
    let norm = ETA * rate * samples as f64;
    let (p_mean, s_mean, yy_mean) = (sum_p / norm, sum_s / norm, sum_yy / norm);
    let blocks: Vec<(f64, f64)> = blocks
        .iter()
        .filter(|b| b.2 > 0)
        .map(|b| {
            let n = ETA * rate * b.2 as f64;
            (b.0 / n, b.1 / n)
        })
        .collect();
    let mus: Vec<f64> = blocks.iter().map(|b| (b.1 + 1.0) / b.0).collect();
    let yys: Vec<f64> = blocks.iter().map(|b| b.0).collect();
    Flow {
        phi,
        p: p_mean,
        p_yy: yy_mean,
        shear: s_mean,
        shear_hydro: sum_h / norm,
        mu: (s_mean + 1.0) / yy_mean,
        mu_trace: s_mean / p_mean,
        mu_err: standard_error(&mus),
        p_err: standard_error(&yys),
        max_overlap,
        slope: slope / samples as f64,
        steps,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

/// Standard error of the mean of `x` (spread/√n); NaN below four values, which say too little.
fn standard_error(x: &[f64]) -> f64 {
    if x.len() < 4 {
        return f64::NAN;
    }
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
    (var / n).sqrt()
}

fn print_row(f: &Flow) {
    let iv = boyer_iv(f.phi);
    println!(
        "phi {:.3} | s_yy/(eta g) {:8.2} +- {:.2} (tr/3 {:8.2}; Boyer P {:8.2}) | -s_xy/(eta g) {:8.2} (hydro {:6.2}; Boyer \
         {:8.2}) | mu {:.3} +- {:.3} (-s_xy/(tr/3) {:.3}; Boyer {:.3}) | max overlap {:.1e} d | profile slope {:.3} | {} steps, {:.1} s",
        f.phi,
        f.p_yy,
        f.p_err,
        f.p,
        1.0 / iv,
        f.shear,
        f.shear_hydro,
        boyer_mu(iv) / iv - 1.0,
        f.mu,
        f.mu_err,
        f.mu_trace,
        boyer_mu(iv),
        f.max_overlap,
        f.slope,
        f.steps,
        f.seconds
    );
}

/// CI: 200 spheres at φ = 0.55 (I_v = 4.1e-3 by Boyer's φ(I_v)), St = 0.1, k_n = 1e6 η γ̇ d,
/// μ_p = 0.5, time step 0.5 of the stability limit, sheared to a strain of 3 and averaged over
/// the last 2: μ = (−σ_xy + η γ̇)/σ_yy and the particle pressure σ_yy against Boyer et al.'s
/// μ(I_v) and 1/I_v; overlaps stay hard-sphere-like and the mean profile is the imposed one.
/// Then φ = 0.45, to a strain of 2 (averaged over the last 1): the shear viscosity must fall
/// steeply.
#[test]
fn dense_suspension_shear_follows_boyer_et_al() {
    let dense = shear_run(200, 0.55, 0.1, 1e6, 0.5, 0.5, 3.0, 1.0, 1);
    print_row(&dense);
    let iv = boyer_iv(0.55);
    let (dev_mu, dev_p) = (dense.mu / boyer_mu(iv) - 1.0, dense.p_yy * iv - 1.0);
    let (se_mu, se_p) = (dense.mu_err / boyer_mu(iv), dense.p_err * iv);
    println!(
        "deviations from Boyer: mu {dev_mu:+.3} (SE {se_mu:.3}), P {dev_p:+.3} (SE {se_p:.3}); \
         tolerances 2 (|dev| + 2 SE): {:.3}, {:.3}",
        2.0 * (dev_mu.abs() + 2.0 * se_mu),
        2.0 * (dev_p.abs() + 2.0 * se_p)
    );
    assert!(
        se_mu.is_finite() && se_p.is_finite(),
        "too few blocks for an error bar"
    );
    assert!(dev_mu.abs() < TOL_MU, "mu {dev_mu}");
    assert!(dev_p.abs() < TOL_P, "P {dev_p}");
    // The mean profile is the imposed one.
    assert!(
        (dense.slope - 1.0).abs() < TOL_SLOPE,
        "profile slope {}",
        dense.slope
    );
    // Measured 6.2e-3 d: hard-sphere-like.
    assert!(dense.max_overlap < 0.0124, "{}", dense.max_overlap);
    let loose = shear_run(200, 0.45, 0.1, 1e6, 0.5, 0.5, 2.0, 1.0, 1);
    print_row(&loose);
    // Whole shear viscosities (particles + solvent), as Boyer's μ/I_v.
    let ratio = (dense.shear + 1.0) / (loose.shear + 1.0);
    let boyer = (boyer_mu(iv) / iv) / (boyer_mu(boyer_iv(0.45)) / boyer_iv(0.45));
    println!("shear viscosity ratio 0.55 / 0.45: {ratio:.2} (Boyer {boyer:.2})");
    assert!(
        ratio > RATIO_MIN && ratio < RATIO_MAX_OVER_BOYER * boyer,
        "{ratio}"
    );
}

/// μ against Boyer at φ = 0.53 and 0.55 (flow curve): measured −8.6 % (SE 5.0 %) and +1.4 %
/// (SE 8.5 %); the bound is twice the larger deviation, about 2 SE at 0.55.
const TOL_FLOW_MU: f64 = 0.2;

/// The flow curve: 400 spheres at φ = 0.40-0.55, St = 0.1, strain 5 (averaged over 1.5-5); a
/// table of P/(η γ̇), σ_xy/(η γ̇) and μ against Boyer et al. (2011). Takes ~5-8 minutes.
/// Asserts what the model shows over the whole curve (measured 2026-11-26, docs/dem3d.md; μ and
/// P as Boyer define them): σ_yy/(η γ̇) and −σ_xy/(η γ̇) rise with φ at every step (the smallest
/// rise, 0.40 → 0.45, is 1.5× in σ_yy and 1.4× in σ_xy), μ falls from the loose to the dense
/// side (1.49, 1.31 → 0.68, 0.68, 0.60), and near jamming (φ = 0.53, 0.55) μ sits on Boyer's
/// μ(I_v) within TOL_FLOW_MU. σ_yy is 17-47 % under Boyer's P at every φ, so no level of it is
/// asserted.
#[test]
#[ignore]
fn flow_curve_against_boyer_et_al() {
    let curve: Vec<Flow> = [0.40, 0.45, 0.50, 0.53, 0.55]
        .into_iter()
        .map(|phi| {
            let f = shear_run(400, phi, 0.1, 1e6, 0.5, 0.5, 5.0, 1.5, 2);
            print_row(&f);
            f
        })
        .collect();
    for w in curve.windows(2) {
        let (a, b) = (&w[0], &w[1]);
        assert!(
            b.p_yy > a.p_yy && b.shear > a.shear,
            "stresses must rise from phi {} to {}",
            a.phi,
            b.phi
        );
    }
    // μ falls from the loose side (0.40, 0.45) to the dense side (0.50-0.55) by more than 2
    // combined standard errors for every pair (measured: 0.63 at the closest, 6 SE); between
    // neighbours it need not (0.682 ± 0.061 at 0.50, 0.678 ± 0.037 at 0.53).
    for a in curve.iter().filter(|f| f.phi < 0.47) {
        for b in curve.iter().filter(|f| f.phi > 0.47) {
            let se = a.mu_err.hypot(b.mu_err);
            assert!(
                a.mu - b.mu > 2.0 * se,
                "mu at {} ({}) vs {} ({})",
                a.phi,
                a.mu,
                b.phi,
                b.mu
            );
        }
    }
    for f in curve.iter().filter(|f| f.phi > 0.52) {
        let mu_b = boyer_mu(boyer_iv(f.phi));
        let (dev, se) = (f.mu / mu_b - 1.0, f.mu_err / mu_b);
        println!("phi {}: mu off Boyer by {dev:+.3} (SE {se:.3})", f.phi);
        assert!(
            dev.abs() < TOL_FLOW_MU,
            "phi {}: mu {} off Boyer by {dev:+.3}",
            f.phi,
            f.mu
        );
    }
}

/// The simplifications of the CI case checked at φ = 0.55 (200 spheres): the time step at 0.2
/// of the stability limit instead of 0.5, and St = 0.03 instead of 0.1.
#[test]
#[ignore]
fn ci_case_against_smaller_step_and_stokes_number() {
    for (st, fraction, strain) in [(0.1, 0.5, 3.0), (0.1, 0.2, 3.0), (0.03, 0.5, 3.0)] {
        let f = shear_run(200, 0.55, st, 1e6, 0.5, fraction, strain, 1.0, 1);
        println!("St {st}, step fraction {fraction}:");
        print_row(&f);
    }
}
