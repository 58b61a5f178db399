//! Contact laws against analytic results (references cited per test).

use lbdem_dem::cases::head_on;
use lbdem_dem::contact::plastic::su_yield_force;
use lbdem_dem::contact::{Bond, BondParams, ContactInput, ElasticPlastic, HertzMindlin, LinearSpringDashpot};
use lbdem_dem::*;

/// A head-on collision of two disks (radius 0.5, density 1) at relative speed `v`
/// (`lbdem_dem::cases::head_on`); returns (relative speed after / before, contact duration).
fn collide<L: ContactLaw>(law: &L, v: f64, dt: f64) -> (f64, f64) {
    let c = head_on::run(law, v, dt, false, 10_000_000).unwrap();
    assert!(c.finished, "{c:?}");
    (c.restitution, c.duration)
}

/// REFERENCES.md (DEM, linear spring-dashpot): e = exp(−πζ/√(1−ζ²)) and
/// t_c = π/(√(k/m*)√(1−ζ²)) for the unclipped force, over ζ from 0.05 to 0.7.
#[test]
fn linear_restitution_and_duration_over_damping_ratios() {
    let k = 1.0e4;
    let m_eff = 0.5 * std::f64::consts::PI * 0.25;
    for zeta in [0.05, 0.1, 0.2, 0.4, 0.7] {
        let mut law = LinearSpringDashpot::new(k, 0.0, Damping::Ratio(zeta), 0.0);
        law.clip = false;
        let tc = std::f64::consts::PI / ((k / m_eff).sqrt() * (1.0 - zeta * zeta).sqrt());
        let (e, dur) = collide(&law, 0.1, tc / 4000.0);
        let e_exact = (-std::f64::consts::PI * zeta / (1.0 - zeta * zeta).sqrt()).exp();
        // Velocity Verlet evaluates the dashpot with the half-step velocity: first order in
        // ω dt (here 8e-4), so the tolerance is a few ω dt.
        assert!(
            (e - e_exact).abs() / e_exact < 5e-3,
            "zeta {zeta}: e = {e}, analytic {e_exact}"
        );
        assert!(
            (dur - tc).abs() / tc < 2e-3,
            "zeta {zeta}: t_c = {dur}, analytic {tc}"
        );
    }
}

/// REFERENCES.md (Hertz normal impact, F = (4/3)E*√R* δ^{3/2}): δ_max = (15 m* v²/(16 E*√R*))^{2/5},
/// t_c = 2.943275 δ_max / v. Leonardi et al. 2014 Eq. 5 with A = 0 has E* = Y/(2(1−ν²)).
#[test]
fn hertz_contact_duration() {
    let law = HertzMindlin {
        young: 1.0e6,
        poisson: 0.3,
        a_damp: 0.0,
        eta: 0.0,
        mu: 0.0,
        max_overlap: 0.05,
    };
    let v = 0.05;
    let m_eff = 0.5 * std::f64::consts::PI * 0.25;
    let e_star = law.young / (2.0 * (1.0 - law.poisson * law.poisson));
    let r_eff: f64 = 0.25;
    let dmax = (15.0 * m_eff * v * v / (16.0 * e_star * r_eff.sqrt())).powf(0.4);
    let tc = 2.943275 * dmax / v;
    let (e, dur) = collide(&law, v, tc / 5000.0);
    eprintln!(
        "Hertz: t_c error {:.2e}, restitution - 1 = {:.2e}",
        (dur - tc).abs() / tc,
        e - 1.0
    );
    // Measured: t_c exact to the step (dt = t_c / 5000, so one step is 2e-4); e - 1 = 7.07e-12.
    assert!((dur - tc).abs() / tc < 4e-4, "Hertz t_c = {dur}, analytic {tc}");
    assert!(
        (e - 1.0).abs() < 1.5e-11,
        "undamped Hertz must be elastic, e = {e}"
    );
}

/// Su et al. 2020 Eq. 6 reproduces the F_y − F_0 column of Table 1 (two significant figures):
/// 6.6e-10 N at 1 µm/s, 1.6e-9 N at 30 µm/s, 4.9e-9 N at 2150 µm/s.
#[test]
fn su_eq6_matches_table1() {
    for (rate, df) in [(1e-6, 6.6e-10), (30e-6, 1.6e-9), (2150e-6, 4.9e-9)] {
        let got = su_yield_force(0.0, rate);
        assert!(
            (got - df).abs() / df < 0.02,
            "rate {rate}: F_y - F_0 = {got}, Table 1 {df}"
        );
    }
}

/// Elastic-plastic loop (Su et al. 2020 Sect. 2.3, Table 1 stiffnesses): elastic k_e to F_y,
/// plastic slope k_p beyond, elastic unloading leaving δ_p = δ_max − F_max/k_e; the loop's area
/// equals the analytic dissipated work.
#[test]
fn elastic_plastic_loading_unloading_loop() {
    let f0 = 7.20e-9; // Table 1, 84%PK
    let law = ElasticPlastic {
        k_e: 4e-3,
        k_p: 1e-7,
        f_y: su_yield_force(f0, 30e-6),
        k_t: 2e-3,
        damping: Damping::Ratio(0.0),
        mu: 0.0,
        rolling: None,
    };
    let uy = law.f_y / law.k_e;
    let dmax = 3.0 * uy;
    let mut h = History::default();
    let n = 3000;
    let (mut work, mut prev_d, mut prev_f) = (0.0, 0.0, 0.0);
    let mut fmax = 0.0;
    for k in 0..=2 * n {
        let d = if k <= n {
            dmax * k as f64 / n as f64
        } else {
            dmax * (2 * n - k) as f64 / n as f64
        };
        let f = law.normal(d, &mut h);
        if k <= n {
            let expect = if d <= uy {
                law.k_e * d
            } else {
                law.f_y + law.k_p * (d - uy)
            };
            assert!(
                (f - expect).abs() <= 1e-12 * law.f_y,
                "loading at {d}: {f} vs {expect}"
            );
            fmax = f;
        } else {
            let expect = (fmax - law.k_e * (dmax - d)).max(0.0);
            assert!(
                (f - expect).abs() <= 1e-9 * law.f_y,
                "unloading at {d}: {f} vs {expect}"
            );
        }
        work += 0.5 * (f + prev_f) * (d - prev_d);
        prev_d = d;
        prev_f = f;
    }
    let dp = dmax - fmax / law.k_e;
    assert!((h.delta_p - dp).abs() < 1e-12 * dmax);
    let w_exact = 0.5 * law.k_e * uy * uy + law.f_y * (dmax - uy) + 0.5 * law.k_p * (dmax - uy).powi(2)
        - fmax * fmax / (2.0 * law.k_e);
    assert!(
        (work - w_exact).abs() / w_exact < 1e-3,
        "loop work {work}, analytic {w_exact}"
    );
}

/// Parallel bond (Potyondy & Cundall 2004): pulled apart at constant speed, the normal force grows
/// as k̄_n A u and the bond breaks when F_n/A reaches σ_c, i.e. at u = σ_c/k̄_n; sheared, it breaks
/// when |F_s|/A reaches the cohesion c, at u_s = c/k̄_s.
#[test]
fn bond_breaks_at_its_strength() {
    // Su et al. 2020 Table 1: k̄_n = 13 N/m², κ = 2, λ̄ = 0.5; strengths chosen to break in range.
    let p = BondParams {
        k_n: 13.0,
        k_s: 6.5,
        sigma_c: 2e-4,
        cohesion: 1e-4,
        lambda: 0.5,
        damping: 0.0,
    };
    let (r, dt, v) = (30e-6, 1e-3, 1e-6);
    for shear in [false, true] {
        let mut b = Bond::new(0, 1);
        let n = Vec2::new(1.0, 0.0);
        let v_rel = if shear {
            Vec2::new(0.0, v)
        } else {
            Vec2::new(-v, 0.0)
        };
        let c = ContactInput {
            delta: 0.0,
            n,
            v_rel,
            w_rel: 0.0,
            r_eff: 0.5 * r,
            m_eff: 0.0,
            dt,
        };
        let mut u = 0.0;
        while !b.broken && u < 1.0 {
            let (f, _) = b.update(&p, &c, r, r);
            if !b.broken {
                let area = 2.0 * p.lambda * r;
                let expect = if shear { p.k_s } else { p.k_n } * area * (u + v * dt);
                let got = if shear { -f.y } else { f.x };
                assert!((got - expect).abs() <= 1e-9 * expect, "force {got} vs {expect}");
            }
            u += v * dt;
        }
        let u_break = if shear {
            p.cohesion / p.k_s
        } else {
            p.sigma_c / p.k_n
        };
        assert!(b.broken);
        assert!(
            (u - u_break).abs() <= v * dt * 1.0001,
            "broke at u = {u}, analytic {u_break}"
        );
    }
}

/// A damped bond (`BondParams::damping` = ζ) rings down as a damped oscillator: a circle of
/// mass m bonded to a fixed one and released stretched has successive displacement peaks in
/// the ratio exp(−2πζ/√(1 − ζ²)), the logarithmic decrement of a linear spring-dashpot. Without
/// damping the peaks stay (the bond's incremental spring conserves the energy of the step).
#[test]
fn a_damped_bond_rings_down_at_its_damping_ratio() {
    let r = 150e-6;
    for zeta in [0.0, 0.05, 0.2, 0.4] {
        let p = BondParams {
            k_n: 1e5,
            k_s: 5e4,
            sigma_c: 1e30,
            cohesion: 1e30,
            lambda: 0.5,
            damping: zeta,
        };
        let m = 4e-7;
        let k = p.k_n * 2.0 * p.lambda * r;
        let w0 = (k / m).sqrt();
        let dt = 0.005 / w0;
        let mut b = Bond::new(0, 1);
        // Start stretched by x0: the spring's force is what the increments built up.
        let x0 = 1e-6;
        b.f_n = k * x0;
        let (mut x, mut v) = (-x0, 0.0f64);
        let mut peaks = Vec::new();
        let mut last = (x.abs(), x.abs());
        for _ in 0..(40.0 * std::f64::consts::TAU / (w0 * dt)) as usize {
            let c = ContactInput {
                delta: 0.0,
                n: Vec2::new(1.0, 0.0),
                v_rel: Vec2::new(v, 0.0),
                w_rel: 0.0,
                r_eff: 0.5 * r,
                m_eff: m,
                dt,
            };
            let (f, _) = b.update(&p, &c, r, r);
            v += f.x / m * dt;
            x += v * dt;
            // A peak of x (i displaced towards −x, the bond stretched).
            if last.1 > last.0 && last.1 > x.abs() && x < 0.0 {
                peaks.push(last.1);
            }
            last = (last.1, x.abs());
        }
        assert!(peaks.len() >= 3, "ζ = {zeta}: {} peaks", peaks.len());
        let decrement = (peaks[0] / peaks[1]).ln();
        let exact = std::f64::consts::TAU * zeta / (1.0 - zeta * zeta).sqrt();
        // Measured: relative errors 1.2e-4, 5.2e-4 and 1.2e-3 at ζ = 0.05, 0.2, 0.4 (ω0 Δt =
        // 0.005), 4e-7 at ζ = 0.
        assert!(
            (decrement - exact).abs() < 2.5e-3 * exact + 1e-6,
            "ζ = {zeta}: logarithmic decrement {decrement}, analytic {exact}"
        );
    }
}

/// A scene gives the rate-sensitive yield force as F_0 and the plate's rate (Su Eq. 6, Table 1
/// rows "Simulation I, II and III" and "30 µm/s"): it reads back as F_0 + 1.6e-9 N; a negative
/// rate is refused.
#[test]
fn rate_sensitive_yield_force_reads_from_f0_and_rate() {
    let law: lbdem_dem::Law = serde_json::from_str(
        r#"{"law": "plastic", "k_e": 4e-3, "k_p": 1e-7, "f_y": {"f_0": 2.52e-9, "rate": 30e-6},
            "k_t": 2e-3, "damping": {"ratio": 0.1}, "mu": 0.05}"#,
    )
    .expect("valid law");
    let lbdem_dem::Law::Plastic(p) = law else {
        panic!("not the plastic law: {law:?}")
    };
    assert!(
        (p.f_y - (2.52e-9 + 1.6e-9)).abs() < 0.02 * 1.6e-9,
        "F_y = {}",
        p.f_y
    );
    let bad = serde_json::from_str::<lbdem_dem::Law>(
        r#"{"law": "plastic", "k_e": 4e-3, "k_p": 1e-7, "f_y": {"f_0": 2.52e-9, "rate": -1.0},
            "k_t": 2e-3, "damping": {"ratio": 0.1}, "mu": 0.05}"#,
    );
    assert!(bad.is_err());
}
