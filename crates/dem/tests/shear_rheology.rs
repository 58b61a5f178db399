//! Simple shear of a dense bidisperse suspension on Lees-Edwards boundaries with Ness et al.
//! (2017)'s model (lubrication Eqs. 3-5 + linear spring Eq. 6; d and 1.5 d, 1:1 by number), the
//! particle stress from the force dipoles (Eq. 7, `dipole_stress`), against the frictional
//! rheology of Boyer, Guazzelli & Pouliquen (2011), PRL 107, 188301: at fixed φ the viscous number
//! is I_v = (φ_m/φ − 1)² (from φ(I_v) = φ_m/(1 + I_v^{1/2})), so P/(η γ̇) = 1/I_v and
//! σ_xy/P = μ(I_v) = μ_1 + (μ_2 − μ_1)/(1 + I_0/I_v) + I_v + (5/2) φ_m I_v^{1/2}, with μ_1 = 0.32,
//! μ_2 = 0.7, I_0 = 0.005, φ_m = 0.585 (quoted from memory of the paper: no stored copy of it
//! was found to check them against).
//!
//! Units: small diameter d = 1, density ρ = 1, viscosity η = 1, so the shear rate is the Stokes
//! number St = ρ γ̇ d²/η. Quick (CI) and full (`#[ignore]`) runs; figures in `docs/dem3d.md`.
//!
//! Run: `cargo test -p lbdem-dem --test shear_rheology -- --nocapture` (CI case) and
//! `cargo test -p lbdem-dem --test shear_rheology -- --ignored --nocapture` (flow curve).

mod suspension;

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

/// Tolerances of the CI case (twice the measured deviations, `docs/dem3d.md`).
/// Measured (200 spheres, φ = 0.55, strain 1-3): μ 0.607 against 0.587 (+3.4 %), P/(η γ̇) 197
/// against 247 (−20 %); the same run averaged over strain 1-4 gave 0.550 (−6 %) and 229 (−7 %),
/// so a window of 2 strain units carries ±5-10 % of noise. Viscosity ratio 0.55/0.45: 21.4
/// (Boyer 10.8). The run is serial and seeded, so CI reproduces these figures bit for bit.
const TOL_MU: f64 = 0.07;
const TOL_P: f64 = 0.40;
const RATIO_MIN: f64 = 10.7;

/// A sheared run's time averages.
#[derive(Debug, Clone, Copy)]
struct Flow {
    phi: f64,
    /// P/(η γ̇), P = tr σ/3.
    p: f64,
    /// Shear stress −σ_xy/(η γ̇) (compression-positive σ: the stress resisting the shear is
    /// negative there), the mean of the xy and yx entries.
    shear: f64,
    /// The hydrodynamic part of `shear`.
    shear_hydro: f64,
    /// μ = shear/P of the averages.
    mu: f64,
    /// Standard error of the mean of μ over blocks of one strain unit (spread/√blocks).
    mu_err: f64,
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
    let l = sys.domain.size();
    let vol = l.x * l.y * l.z;
    let steps = (strain / (rate * dt)).ceil() as usize;
    let first = (start / (rate * dt)).ceil() as usize;
    let every = 20;
    let per_block = (1.0 / (rate * dt)).ceil() as usize;
    let t0 = Instant::now();
    let (mut sum_p, mut sum_s, mut sum_h, mut samples) = (0.0, 0.0, 0.0, 0usize);
    let mut blocks: Vec<(f64, f64)> = Vec::new();
    let mut block = (0.0, 0.0);
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
        block.0 += pr;
        block.1 += sh;
        if (k - first) / per_block > blocks.len() {
            blocks.push(block);
            block = (0.0, 0.0);
        }
        for c in rec {
            if let lbdem_dem::spheres::Partner::Sphere(j) = c.j {
                let (i, j) = (c.i as usize, j as usize);
                let ov = sys.spheres.radius[i] + sys.spheres.radius[j] - c.branch.norm();
                max_overlap = max_overlap.max(ov);
            }
        }
    }
    let norm = ETA * rate * samples as f64;
    let (p_mean, s_mean) = (sum_p / norm, sum_s / norm);
    let mus: Vec<f64> = blocks.iter().map(|b| b.1 / b.0).collect();
    let m = mus.iter().sum::<f64>() / mus.len().max(1) as f64;
    let var = mus.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (mus.len().max(2) - 1) as f64;
    Flow {
        phi,
        p: p_mean,
        shear: s_mean,
        shear_hydro: sum_h / norm,
        mu: s_mean / p_mean,
        mu_err: (var / mus.len().max(1) as f64).sqrt(),
        max_overlap,
        slope: slope / samples as f64,
        steps,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

fn print_row(f: &Flow) {
    let iv = boyer_iv(f.phi);
    println!(
        "phi {:.3} | P/(eta g) {:8.2} (Boyer {:8.2}) | -s_xy/(eta g) {:8.2} (hydro {:6.2}; Boyer \
         {:8.2}) | mu {:.3} +- {:.3} (Boyer {:.3}) | max overlap {:.1e} d | profile slope {:.3} | {} steps, {:.1} s",
        f.phi,
        f.p,
        1.0 / iv,
        f.shear,
        f.shear_hydro,
        boyer_mu(iv) / iv,
        f.mu,
        f.mu_err,
        boyer_mu(iv),
        f.max_overlap,
        f.slope,
        f.steps,
        f.seconds
    );
}

/// CI: 200 spheres at φ = 0.55 (I_v = 4.1e-3 by Boyer's φ(I_v)), St = 0.1, k_n = 1e6 η γ̇ d,
/// μ_p = 0.5, time step 0.5 of the stability limit, sheared to a strain of 3 and averaged over
/// the last 2: the stress ratio μ = σ_xy/P and the particle pressure against Boyer et al.'s
/// μ(I_v) and 1/I_v; overlaps stay hard-sphere-like and the mean profile is the imposed one.
/// Then φ = 0.45, to a strain of 2 (averaged over the last 1): the shear viscosity must fall
/// by far.
#[test]
fn dense_suspension_shear_follows_boyer_et_al() {
    let dense = shear_run(200, 0.55, 0.1, 1e6, 0.5, 0.5, 3.0, 1.0, 1);
    print_row(&dense);
    let iv = boyer_iv(0.55);
    let (dev_mu, dev_p) = (dense.mu / boyer_mu(iv) - 1.0, dense.p * iv - 1.0);
    println!("deviations from Boyer: mu {dev_mu:+.3}, P {dev_p:+.3}");
    // Measured: see docs/dem3d.md (tolerances twice the measured deviations).
    assert!(dev_mu.abs() < TOL_MU, "mu {dev_mu}");
    assert!(dev_p.abs() < TOL_P, "P {dev_p}");
    // Measured 6.2e-3 d: hard-sphere-like.
    assert!(dense.max_overlap < 0.0124, "{}", dense.max_overlap);
    let loose = shear_run(200, 0.45, 0.1, 1e6, 0.5, 0.5, 2.0, 1.0, 1);
    print_row(&loose);
    let ratio = dense.shear / loose.shear;
    println!(
        "shear viscosity ratio 0.55 / 0.45: {ratio:.2} (Boyer {:.2})",
        (boyer_mu(iv) / iv) / (boyer_mu(boyer_iv(0.45)) / boyer_iv(0.45))
    );
    assert!(ratio > RATIO_MIN, "{ratio}");
}

/// The flow curve: 400 spheres at φ = 0.40-0.55, St = 0.1, strain 5 (averaged over 1.5-5); a
/// table of P/(η γ̇), σ_xy/(η γ̇) and μ against Boyer et al. (2011). Takes ~5-8 minutes.
/// Asserts what the model shows over the whole curve (measured 2026-11-26, docs/dem3d.md):
/// P/(η γ̇) and σ_xy/(η γ̇) rise with φ at every step (the smallest rise, 0.40 → 0.45, is 1.6×
/// in P and 1.4× in σ_xy), μ falls with φ (1.83 → 0.60), and near jamming (φ = 0.53, 0.55) μ sits
/// on Boyer's μ(I_v): measured −5.1 % and +2.4 %, tolerance 10 %. Below 0.53 the stresses are
/// 2-3× under Boyer's (nearest-neighbour lubrication only), so no level is asserted there.
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
            b.p > a.p && b.shear > a.shear,
            "stresses must rise from phi {} to {}",
            a.phi,
            b.phi
        );
        assert!(b.mu < a.mu, "mu must fall from phi {} to {}", a.phi, b.phi);
    }
    for f in curve.iter().filter(|f| f.phi > 0.52) {
        let dev = f.mu / boyer_mu(boyer_iv(f.phi)) - 1.0;
        assert!(
            dev.abs() < 0.10,
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
