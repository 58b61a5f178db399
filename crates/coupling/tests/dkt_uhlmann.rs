//! Drafting, kissing and tumbling of two disks against published trajectories: Uhlmann (J. Comput.
//! Phys. 209 (2005) 448, Figs. 6a and 7a) and Koblitz et al. (J. Comput. Phys. 343 (2017) 414,
//! Figs. 10a and 10c) of the same case (set-up in `lbdem_coupling::cases::dkt`), digitised in
//! `tests/data/` (see the READMEs there).
//!
//! After the kiss the motion is unstable, and the two publications part: the test measures
//! agreement against their difference, computed from the stored curves, instead of a fixed
//! tolerance. Through the first tumble (the pair's line of centres turning past 45° from the
//! vertical), the run must:
//! - follow Uhlmann's depths up to the kiss (t ≤ 0.18 s) to within 0.1 d RMS (the published
//!   curves differ from each other by 0.05 d RMS there, printed);
//! - tumble within the two publications' tumble times, widened on each side by their difference.
//!
//! It also measures how far the depths stray, up to the later of the two tumble times, outside the
//! envelope of the two publications' depths; the allowance is the publications' own largest
//! depth difference over that time (0.24 d). That is met only where the lattice resolves the
//! kissing pair: its drag falls with resolution (the pair's mean depth falls at most at 16.9,
//! 17.7, 18.2 and 18.4 cm/s at 24, 32, 48 and 64 cells per diameter, Koblitz et al. 18.3, Uhlmann
//! 19.1), so at 24 cells per diameter the pair strays 0.48 d outside the envelope (guarded against
//! getting worse), at 32 cells 0.33 d, at 48 cells 0.10 d and at 64 cells 0.07 d (asserted).
//!
//! The tumble time depends on the seed of the instability, the initial lateral offset (d/250
//! either way here): at 16 cells per diameter offsets of d/500, d/250 and d/125 tumble at 0.282,
//! 0.260 and 0.240 s, and 16 cells sits 2 ms inside the band. CI therefore runs 24 cells per
//! diameter (tumble 14 ms inside the band; about 30 s). `cargo test --release -p lbdem-coupling
//! --test coupling dkt_uhlmann:: -- --ignored --nocapture` runs 16 cells per diameter with the variants
//! without the interior-liquid correction and with BGK (to show what each choice does), and the
//! resolution series at 32 and 48 cells per diameter (about 4 minutes on two cores) and at 64
//! (about 13 minutes).

use lbdem_coupling::cases::dkt::{DktResult, DktSpec, interpolate, run};

const D: f64 = 2.5e-3;
/// t_ref = d / √(π d (ρ_p/ρ_f − 1) g / 2) of Koblitz et al. (s).
fn t_ref() -> f64 {
    D / (std::f64::consts::PI * D * 0.5 * 9.81 / 2.0).sqrt()
}
const T_KISS: f64 = 0.18;

/// Two columns of numbers, each mapped.
fn series(text: &str, ft: impl Fn(f64) -> f64, fx: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<f64>) {
    text.lines()
        .filter(|l| !l.trim().is_empty())
        .map(|l| {
            let mut it = l.split_whitespace().map(|v| v.parse::<f64>().expect("number"));
            (ft(it.next().expect("t")), fx(it.next().expect("x")))
        })
        .unzip()
}

/// Depth and lateral position of the trailing (0) and leading (1) disk over time (SI).
struct Trajectory {
    depth: [(Vec<f64>, Vec<f64>); 2],
    lateral: [(Vec<f64>, Vec<f64>); 2],
}

impl Trajectory {
    fn uhlmann() -> Self {
        let cm = |x: f64| x * 1e-2;
        let id = |t: f64| t;
        Self {
            depth: [
                series(include_str!("data/uhlmann2005/fig6a-trailing.txt"), id, cm),
                series(include_str!("data/uhlmann2005/fig6a-leading.txt"), id, cm),
            ],
            lateral: [
                series(include_str!("data/uhlmann2005/fig7a-trailing.txt"), id, cm),
                series(include_str!("data/uhlmann2005/fig7a-leading.txt"), id, cm),
            ],
        }
    }
    fn koblitz() -> Self {
        let t = |s: f64| s * t_ref();
        let depth = |x: f64| -x * D;
        let lateral = |x: f64| (x - 4.0) * D;
        Self {
            depth: [
                series(include_str!("data/koblitz2017/fig10c-trailing.txt"), t, depth),
                series(include_str!("data/koblitz2017/fig10c-leading.txt"), t, depth),
            ],
            lateral: [
                series(include_str!("data/koblitz2017/fig10a-trailing.txt"), t, lateral),
                series(include_str!("data/koblitz2017/fig10a-leading.txt"), t, lateral),
            ],
        }
    }
    fn simulated(r: &DktResult) -> Self {
        let ts: Vec<f64> = r.samples.iter().map(|s| s.t).collect();
        let col = |f: &dyn Fn(usize, &lbdem_coupling::cases::dkt::DktSample) -> f64, k| {
            (ts.clone(), r.samples.iter().map(|s| f(k, s)).collect::<Vec<_>>())
        };
        let depth = |k: usize, s: &lbdem_coupling::cases::dkt::DktSample| s.depth[k];
        let lateral = |k: usize, s: &lbdem_coupling::cases::dkt::DktSample| s.lateral[k];
        Self {
            depth: [col(&depth, 0), col(&depth, 1)],
            lateral: [col(&lateral, 0), col(&lateral, 1)],
        }
    }
    fn depth_at(&self, k: usize, t: f64) -> f64 {
        interpolate(&self.depth[k].0, &self.depth[k].1, t)
    }
    fn lateral_at(&self, k: usize, t: f64) -> f64 {
        interpolate(&self.lateral[k].0, &self.lateral[k].1, t)
    }
    /// First time after the kiss at which the line of centres is more horizontal than vertical.
    fn tumble_time(&self) -> Option<f64> {
        (0..=300).map(|i| T_KISS + 0.0004 * i as f64).find(|&t| {
            let dz = self.depth_at(1, t) - self.depth_at(0, t);
            let dl = self.lateral_at(1, t) - self.lateral_at(0, t);
            dl.abs() > dz.abs()
        })
    }
    /// Largest depth difference (in d) to `other` of either disk at `other`'s sample times in (t0, t1].
    fn max_depth_difference(&self, other: &Self, t0: f64, t1: f64) -> f64 {
        let mut m = 0.0f64;
        for k in 0..2 {
            for (&t, &x) in other.depth[k].0.iter().zip(&other.depth[k].1) {
                if t > t0 && t <= t1 {
                    m = m.max((self.depth_at(k, t) - x).abs() / D);
                }
            }
        }
        m
    }
    /// Largest distance (in d) of either disk's depth outside the envelope of `a` and `b`, at
    /// every millisecond in (0, t1].
    fn max_outside(&self, a: &Self, b: &Self, t1: f64) -> f64 {
        let mut m = 0.0f64;
        for k in 0..2 {
            for i in 1..=(t1 * 1e3) as usize {
                let t = i as f64 * 1e-3;
                let (x, y) = (a.depth_at(k, t), b.depth_at(k, t));
                let ours = self.depth_at(k, t);
                m = m.max((x.min(y) - ours).max(ours - x.max(y)).max(0.0) / D);
            }
        }
        m
    }
    /// Fastest fall (m/s) of the mean depth of the two disks in [t0, t1], and when, by central
    /// differences over ±5 ms: the digitised curves are 5.5-9 ms apart there. Koblitz et al.'s
    /// peak hardly depends on the width (18.34-18.38 cm/s for ±2-5 ms), Uhlmann's does (19.35 at
    /// ±2-3 ms, 19.14 at ±5 ms).
    fn peak_mean_fall_speed(&self, t0: f64, t1: f64) -> (f64, f64) {
        let mean = |t: f64| 0.5 * (self.depth_at(0, t) + self.depth_at(1, t));
        let h = 5e-3;
        (0..=((t1 - t0) * 1e3).round() as usize)
            .map(|i| {
                let t = t0 + i as f64 * 1e-3;
                ((mean(t + h) - mean(t - h)) / (2.0 * h), t)
            })
            .fold((f64::NEG_INFINITY, t0), |a, b| if b.0 > a.0 { b } else { a })
    }
    /// Angle (degrees) of the line of centres from the vertical at time `t`.
    fn angle(&self, t: f64) -> f64 {
        let dz = self.depth_at(1, t) - self.depth_at(0, t);
        let dl = self.lateral_at(1, t) - self.lateral_at(0, t);
        dl.abs().atan2(dz).to_degrees()
    }
    /// Largest difference (degrees) of the line of centres' angle to `other`'s, every 5 ms in
    /// [t0, t1]: how alike the two pairs tumble.
    fn max_angle_difference(&self, other: &Self, t0: f64, t1: f64) -> f64 {
        (0..=((t1 - t0) / 5e-3).round() as usize)
            .map(|i| t0 + i as f64 * 5e-3)
            .map(|t| (self.angle(t) - other.angle(t)).abs())
            .fold(0.0, f64::max)
    }
    /// RMS depth difference (in d) to `other` at `other`'s sample times up to `t1`.
    fn rms_depth_difference(&self, other: &Self, t1: f64) -> f64 {
        let (mut sq, mut n) = (0.0, 0usize);
        for k in 0..2 {
            for (&t, &x) in other.depth[k].0.iter().zip(&other.depth[k].1) {
                if t <= t1 {
                    sq += ((self.depth_at(k, t) - x) / D).powi(2);
                    n += 1;
                }
            }
        }
        (sq / n as f64).sqrt()
    }
}

struct Verdict {
    rms_drafting: f64,
    tumble: f64,
    tumble_band: (f64, f64),
    /// Largest distance outside the envelope of the two publications' depths up to the later
    /// tumble (d), and the allowance: the publications' own largest depth difference over the
    /// same time.
    outside: f64,
    allowance: f64,
    /// Fastest fall of the pair's mean depth (m/s): the kissing doublet's drag.
    peak_fall: f64,
}

fn judge(label: &str, spec: &DktSpec) -> Verdict {
    let r = run::<f64>(spec).expect("stable run");
    let ours = Trajectory::simulated(&r);
    let (u, k) = (Trajectory::uhlmann(), Trajectory::koblitz());
    let (tu, tk) = (
        u.tumble_time().expect("Uhlmann's pair tumbles"),
        k.tumble_time().expect("Koblitz's pair tumbles"),
    );
    let spread = (tu - tk).abs();
    let band = (tu.min(tk) - spread, tu.max(tk) + spread);
    let t_end = tu.max(tk);
    let published_drafting = k.rms_depth_difference(&u, T_KISS);
    let (peak, t_peak) = ours.peak_mean_fall_speed(0.15, 0.25);
    let v = Verdict {
        rms_drafting: ours.rms_depth_difference(&u, T_KISS),
        tumble: ours.tumble_time().unwrap_or(f64::INFINITY),
        tumble_band: band,
        outside: ours.max_outside(&u, &k, t_end),
        allowance: k.max_depth_difference(&u, 0.0, t_end),
        peak_fall: peak,
    };
    eprintln!(
        "DKT {label}: {} cells/d, tau {:.4}, TRT {:?}, interior-liquid correction {}, contact range {} cells:\n  \
         depth RMS vs Uhlmann to the kiss ({T_KISS} s) {:.3} d (limit 0.1; Koblitz et al. vs Uhlmann \
         {published_drafting:.3} d)\n  \
         tumble (45°) at {:.4} s; Uhlmann {tu:.4} s, Koblitz et al. {tk:.4} s, band [{:.4}, {:.4}]\n  \
         up to {t_end:.4} s: largest depth difference to Uhlmann {:.3} d (Koblitz et al.'s: {:.3} d), \
         largest distance outside the two publications' envelope {:.3} d (allowance, asserted at 48 and 64 cells/d only: \
         the publications' own difference, {:.3} d)\n  \
         fastest fall of the pair's mean depth in [0.15, 0.25] s {:.2} cm/s at {t_peak:.3} s (Uhlmann {:.2}, Koblitz et al. {:.2})\n  \
         line of centres, 0.20-0.25 s: largest angle difference to Koblitz et al. {:.1}° (Uhlmann's: {:.1}°)\n  \
         smallest gap {:.3} d; {} steps of {} nodes in {:.1} s",
        spec.cells_per_diameter,
        spec.tau,
        spec.trt_magic,
        spec.interior_liquid_correction,
        spec.contact_range_cells,
        v.rms_drafting,
        v.tumble,
        band.0,
        band.1,
        ours.max_depth_difference(&u, 0.0, t_end),
        v.allowance,
        v.outside,
        v.allowance,
        1e2 * peak,
        1e2 * u.peak_mean_fall_speed(0.15, 0.25).0,
        1e2 * k.peak_mean_fall_speed(0.15, 0.25).0,
        ours.max_angle_difference(&k, 0.20, 0.25),
        u.max_angle_difference(&k, 0.20, 0.25),
        r.min_gap / D,
        r.lbm_steps,
        r.nodes,
        r.wall_seconds,
    );
    v
}

fn spec(cells: usize) -> DktSpec {
    let mut s = DktSpec {
        cells_per_diameter: cells,
        ..DktSpec::default()
    };
    s.tau = s.tau_for(0.15);
    s
}

fn assert_follows(v: &Verdict) {
    assert!(v.rms_drafting < 0.1, "drafting: RMS {:.3} d", v.rms_drafting);
    assert!(
        v.tumble >= v.tumble_band.0 && v.tumble <= v.tumble_band.1,
        "tumble at {} s outside {:?}",
        v.tumble,
        v.tumble_band
    );
    // The envelope (v.outside <= v.allowance) is asserted only at 48 and 64 cells per diameter.
}

/// At 24 cells per diameter the kissing pair falls too slowly (see the module doc): recorded on
/// 2026-11-22, 0.48 d outside the envelope. A regression guard on that figure, not agreement
/// with the publications: a change that makes the kissing phase worse fails here.
const RECORDED_OUTSIDE_24: f64 = 0.48;

#[test]
fn two_disks_draft_like_the_publications_and_tumble_within_their_band() {
    let v = judge("CI", &spec(24));
    assert_follows(&v);
    assert!(
        v.outside <= RECORDED_OUTSIDE_24 + 0.05,
        "the kissing phase got worse: {:.3} d outside the envelope (recorded {RECORDED_OUTSIDE_24} d)",
        v.outside
    );
}

#[test]
#[ignore]
fn coarser_lattice_and_the_variants() {
    assert_follows(&judge("coarser", &spec(16)));
    // Without the interior-liquid correction the disks fall as if they weighed ρ_p + ρ_f.
    let mut s = spec(16);
    s.interior_liquid_correction = false;
    let v = judge("no interior-liquid correction", &s);
    assert!(
        v.rms_drafting > 0.1,
        "the correction should matter: RMS {:.3} d",
        v.rms_drafting
    );
    let mut s = spec(16);
    s.trt_magic = None;
    judge("BGK", &s);
    let mut s = spec(16);
    s.contact_range_cells = 0.0;
    judge("contact at the surfaces", &s);
}

/// 32 and 48 cells per diameter at u_lattice 0.08 (at 0.15 the gap flow at the kiss goes unstable
/// at 32 cells): about 1 and 3 minutes in release on two cores. From 32 to 48 cells the kissing
/// pair must fall faster (its drag is what the coarse lattices get wrong) and stray less from the
/// publications, and at 48 cells stray from their envelope by no more than they differ from each
/// other, through the first tumble.
#[test]
#[ignore]
fn finer_lattices_converge_into_the_published_envelope() {
    let fine = |cells| {
        let mut s = spec(cells);
        s.tau = s.tau_for(0.08);
        s
    };
    let v32 = judge("finer", &fine(32));
    assert_follows(&v32);
    let v48 = judge("finest", &fine(48));
    assert_follows(&v48);
    assert!(
        v48.peak_fall > v32.peak_fall && v48.outside < v32.outside,
        "no convergence from 32 to 48 cells/d: fastest fall {:.4} -> {:.4} m/s, outside the \
         envelope {:.3} -> {:.3} d",
        v32.peak_fall,
        v48.peak_fall,
        v32.outside,
        v48.outside
    );
    assert!(
        v48.outside <= v48.allowance,
        "at 48 cells/d the pair strays {:.3} d outside the publications' envelope (allowance {:.3} d)",
        v48.outside,
        v48.allowance
    );
}

/// 64 cells per diameter, the third point of the series. u_lattice 0.05: at 0.08 the density in
/// the gap falls to 0.5 as the kissing pair opens (t ≈ 0.21 s) and the run stops. About 13
/// minutes in release on two quiet cores (42,636 steps of 786,432 nodes); alone:
/// `cargo test --release -p lbdem-coupling --test coupling dkt_uhlmann::finest_lattice -- --ignored --nocapture`.
#[test]
#[ignore]
fn finest_lattice_stays_in_the_published_envelope() {
    let mut s = spec(64);
    s.tau = s.tau_for(0.05);
    let v = judge("64 cells", &s);
    assert_follows(&v);
    assert!(
        v.outside <= v.allowance,
        "at 64 cells/d the pair strays {:.3} d outside the publications' envelope (allowance {:.3} d)",
        v.outside,
        v.allowance
    );
}
