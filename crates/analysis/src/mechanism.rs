//! The deformation mechanism map of Su et al. (2020) Sect. 3.1 and Fig. 3j: every experiment or
//! run falls in one of four classes by its *net* behaviour, plotted against the initial solid
//! fraction g_S⁰ and the push-plate rate du_y/dt (log), with the transition lines between them.
//!
//! **The rule** ([`classify`]), in the order the paper's definitions need it:
//! 1. the grains do not form a percolating network → **suspension**;
//! 2. else, the liquid pressure change fell below Δp_c = −0.03 Pa on a liquid node during the run
//!    (Sect. 3.5, Fig. 10: a meniscus is drawn in) → **shear cracking**;
//! 3. else ε_vol^DEM (Eq. 18) at the end of the run > 0 → **shear-induced dilation**;
//! 4. else → **shear-induced contraction** (Fig. 8: black outline for ε_vol^DEM < 0).
//!
//! A run without liquid cannot crack by this criterion; step 2 is then skipped.
//!
//! The experimental datasets are those the text names with their class ([`PAPER_DATASETS`]); the
//! paper has 17 experiments, of which these 10 are identified in Sects. 2-3.5.

use serde::Serialize;

/// The four net behaviours of Sect. 3.1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Class {
    Suspension,
    Contraction,
    Dilation,
    Cracking,
}

impl Class {
    pub const ALL: [Class; 4] = [
        Class::Suspension,
        Class::Contraction,
        Class::Dilation,
        Class::Cracking,
    ];

    /// The paper's name of the class (Sect. 3.1).
    pub fn name(self) -> &'static str {
        match self {
            Class::Suspension => "suspension",
            Class::Contraction => "shear-induced contraction",
            Class::Dilation => "shear-induced dilation",
            Class::Cracking => "shear cracking",
        }
    }

    /// Fig. 3j's colours: grey, black, green, red (RGB).
    pub fn colour(self) -> (u8, u8, u8) {
        match self {
            Class::Suspension => (150, 150, 150),
            Class::Contraction => (0, 0, 0),
            Class::Dilation => (30, 150, 50),
            Class::Cracking => (210, 30, 30),
        }
    }
}

/// What a run shows, for [`classify`].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Evidence {
    /// The contact network spans the sample ([`crate::network`]).
    pub percolates: bool,
    /// Whether Δp < Δp_c happened on a liquid node (None: no liquid in the run).
    pub cracked: Option<bool>,
    /// ε_vol^DEM at the end of the run (Eq. 18).
    pub eps_vol_net: f64,
}

/// The net class of a run by the rule in the module documentation.
pub fn classify(e: &Evidence) -> Class {
    if !e.percolates {
        Class::Suspension
    } else if e.cracked == Some(true) {
        Class::Cracking
    } else if e.eps_vol_net > 0.0 {
        Class::Dilation
    } else {
        Class::Contraction
    }
}

/// The dynamic-dilatancy law, Eq. 21: f_S,pk^c(I) ≈ f_max − a I, with f_max ≈ 81 % and a ≈ 0.3
/// for ±20 % polydisperse circular grains with μ = 0.4 (Su's ref. [120]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct DynamicDilatancy {
    pub f_max: f64,
    pub a: f64,
}

impl Default for DynamicDilatancy {
    fn default() -> Self {
        Self { f_max: 0.81, a: 0.3 }
    }
}

impl DynamicDilatancy {
    /// Critical packing fraction at inertial number `i` (Eq. 21).
    pub fn critical(&self, i: f64) -> f64 {
        self.f_max - self.a * i
    }
    /// The net behaviour Eq. 21 predicts for an initial packing `f0` sheared at inertial number
    /// `i`: dilation above the critical packing, contraction below.
    pub fn predicts(&self, f0: f64, i: f64) -> Class {
        if f0 > self.critical(i) {
            Class::Dilation
        } else {
            Class::Contraction
        }
    }
    /// Whether a run's net volumetric strain ε_vol^DEM (Eq. 18) has the sign Eq. 21 predicts.
    /// The law is about net contraction against net dilation, so a run's class (where cracking
    /// takes precedence over the sign) is not what it is checked against.
    pub fn agrees(&self, f0: f64, i: f64, eps_vol_net: f64) -> bool {
        match self.predicts(f0, i) {
            Class::Dilation => eps_vol_net > 0.0,
            _ => eps_vol_net < 0.0,
        }
    }
}

/// One experiment of Fig. 3j.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Dataset {
    /// "g_S⁰ - du_y/dt" as the paper names it.
    pub name: &'static str,
    /// Initial solid fraction g_S⁰ (-).
    pub g_s0: f64,
    /// Push-plate rate du_y/dt (µm/s); 0 for the heating experiment.
    pub rate_um_s: f64,
    pub class: Class,
    /// Where the paper names it.
    pub source: &'static str,
}

/// The experimental datasets of Fig. 3j that Su et al. (2020) name with their class in the text.
pub const PAPER_DATASETS: [Dataset; 10] = [
    Dataset {
        name: "38% - 0 µm/s",
        g_s0: 0.38,
        rate_um_s: 0.0,
        class: Class::Suspension,
        source: "Sects. 2.1, 3.2; Fig. 5a-d",
    },
    Dataset {
        name: "44% - 30 µm/s",
        g_s0: 0.44,
        rate_um_s: 30.0,
        class: Class::Contraction,
        source: "Fig. 3a, d, g; Sect. 3.3",
    },
    Dataset {
        name: "50% - 30 µm/s",
        g_s0: 0.50,
        rate_um_s: 30.0,
        class: Class::Contraction,
        source: "Sect. 3.3; Fig. 6c-d",
    },
    Dataset {
        name: "50% - 1310 µm/s",
        g_s0: 0.50,
        rate_um_s: 1310.0,
        class: Class::Contraction,
        source: "Sect. 3.3; Fig. 6e-f",
    },
    Dataset {
        name: "50% - 2870 µm/s",
        g_s0: 0.50,
        rate_um_s: 2870.0,
        class: Class::Dilation,
        source: "Sect. 3.3; Fig. 6g-h",
    },
    Dataset {
        name: "66% - 30 µm/s",
        g_s0: 0.66,
        rate_um_s: 30.0,
        class: Class::Dilation,
        source: "Sect. 3.3",
    },
    Dataset {
        name: "71% - 30 µm/s",
        g_s0: 0.71,
        rate_um_s: 30.0,
        class: Class::Dilation,
        source: "Sect. 3.3",
    },
    Dataset {
        name: "74% - 1 µm/s",
        g_s0: 0.74,
        rate_um_s: 1.0,
        class: Class::Dilation,
        source: "Fig. 3b, e, h; Fig. 4",
    },
    Dataset {
        name: "60% - 820 µm/s",
        g_s0: 0.60,
        rate_um_s: 820.0,
        class: Class::Cracking,
        source: "Fig. 3c, f, i",
    },
    Dataset {
        name: "57% - 2150 µm/s",
        g_s0: 0.57,
        rate_um_s: 2150.0,
        class: Class::Cracking,
        source: "Sect. 3.5; Fig. 12",
    },
];

/// The suspension-to-network transition of Fig. 3j: the vertical line at g_S⁰ = 38 % from the
/// 38 % - 0 µm/s heating experiment (Sect. 3.1, 3.2).
pub const PERCOLATION_G_S: f64 = 0.38;

/// Void ratio e⁰ = (1 − g_S⁰)/g_S⁰ (Fig. 3j, top axis).
pub fn void_ratio(g_s0: f64) -> f64 {
    (1.0 - g_s0) / g_s0
}

/// A straight line n · p = c in normalised plot coordinates, with `margin` its distance to the
/// nearest point of either set.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Line {
    pub normal: [f64; 2],
    pub offset: f64,
    pub margin: f64,
}

impl Line {
    /// Signed distance of `p` (positive on the side of the first set).
    pub fn side(&self, p: [f64; 2]) -> f64 {
        self.normal[0] * p[0] + self.normal[1] * p[1] - self.offset
    }
    /// The first coordinate on the line at second coordinate `v` (None if the line is parallel
    /// to the first axis).
    pub fn u_at(&self, v: f64) -> Option<f64> {
        (self.normal[0].abs() > 1e-12).then(|| (self.offset - self.normal[1] * v) / self.normal[0])
    }
}

/// The widest-gap straight line with every point of `a` on one side and every point of `b` on
/// the other (the hard-margin separator), or `None` if no line separates them. Found by a
/// search over the normal's direction (0.05° steps, then refined): for a unit normal n the gap
/// is min_a n·p − max_b n·p, and the line sits in its middle.
pub fn separating_line(a: &[[f64; 2]], b: &[[f64; 2]]) -> Option<Line> {
    if a.is_empty() || b.is_empty() {
        return None;
    }
    let gap = |th: f64| {
        let n = [th.cos(), th.sin()];
        let lo_a = a
            .iter()
            .map(|p| n[0] * p[0] + n[1] * p[1])
            .fold(f64::INFINITY, f64::min);
        let hi_b = b
            .iter()
            .map(|p| n[0] * p[0] + n[1] * p[1])
            .fold(f64::NEG_INFINITY, f64::max);
        (lo_a - hi_b, lo_a, hi_b)
    };
    let steps = 7200;
    let step = std::f64::consts::TAU / steps as f64;
    let best = (0..steps)
        .map(|k| k as f64 * step)
        .max_by(|&x, &y| gap(x).0.total_cmp(&gap(y).0))?;
    // Ternary search within one step either side (the gap is smooth near its maximum).
    let (mut lo, mut hi) = (best - step, best + step);
    for _ in 0..100 {
        let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
        if gap(m1).0 < gap(m2).0 {
            lo = m1;
        } else {
            hi = m2;
        }
    }
    let th = 0.5 * (lo + hi);
    let (g, lo_a, hi_b) = gap(th);
    (g > 0.0).then(|| Line {
        normal: [th.cos(), th.sin()],
        offset: 0.5 * (lo_a + hi_b),
        margin: 0.5 * g,
    })
}

/// The plot frame a transition line is fitted in: g_S⁰ over [g_lo, g_hi] and log₁₀ of the rate
/// (µm/s) over [l_lo, l_hi], each scaled to [0, 1], so "widest gap" means widest on the figure.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Frame {
    pub g_lo: f64,
    pub g_hi: f64,
    pub l_lo: f64,
    pub l_hi: f64,
}

impl Default for Frame {
    /// Fig. 3j's range: 30-90 % solid, 0.3-10⁴ µm/s.
    fn default() -> Self {
        Self {
            g_lo: 0.30,
            g_hi: 0.90,
            l_lo: -0.5,
            l_hi: 4.0,
        }
    }
}

impl Frame {
    pub fn to_plot(&self, g: f64, rate_um_s: f64) -> [f64; 2] {
        [
            (g - self.g_lo) / (self.g_hi - self.g_lo),
            (rate_um_s.log10() - self.l_lo) / (self.l_hi - self.l_lo),
        ]
    }
    /// (g_S⁰, rate µm/s) of a point in plot coordinates.
    pub fn from_plot(&self, p: [f64; 2]) -> (f64, f64) {
        (
            self.g_lo + p[0] * (self.g_hi - self.g_lo),
            10f64.powf(self.l_lo + p[1] * (self.l_hi - self.l_lo)),
        )
    }
}

/// The two inclined transition lines of Fig. 3j from classified points (g_S⁰, rate µm/s, class)
/// with a rate above zero: contraction | dilation (cracking samples dilate too, Sect. 3.5, so
/// they sit on the dilation side) and no cracking | cracking. Each is `None` when its classes
/// are missing or overlap.
pub fn transition_lines(points: &[(f64, f64, Class)], frame: &Frame) -> (Option<Line>, Option<Line>) {
    let pick = |f: &dyn Fn(Class) -> bool| -> Vec<[f64; 2]> {
        points
            .iter()
            .filter(|p| p.1 > 0.0 && f(p.2))
            .map(|p| frame.to_plot(p.0, p.1))
            .collect()
    };
    let dil = pick(&|c| matches!(c, Class::Dilation | Class::Cracking));
    let con = pick(&|c| c == Class::Contraction);
    let crack = pick(&|c| c == Class::Cracking);
    let intact = pick(&|c| matches!(c, Class::Contraction | Class::Dilation));
    (separating_line(&dil, &con), separating_line(&crack, &intact))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rule_goes_suspension_cracking_sign() {
        let e = |percolates, cracked, eps| {
            classify(&Evidence {
                percolates,
                cracked,
                eps_vol_net: eps,
            })
        };
        assert_eq!(e(false, Some(true), 0.1), Class::Suspension);
        assert_eq!(e(true, Some(true), -0.1), Class::Cracking);
        assert_eq!(e(true, Some(false), 0.01), Class::Dilation);
        assert_eq!(e(true, None, 0.01), Class::Dilation);
        assert_eq!(e(true, Some(false), -0.01), Class::Contraction);
        assert_eq!(e(true, None, 0.0), Class::Contraction);
    }

    /// Eq. 21 with Su's constants: f_c(0) = 81 %, f_c(0.1) = 78 %.
    #[test]
    fn dynamic_dilatancy_law() {
        let d = DynamicDilatancy::default();
        assert!((d.critical(0.0) - 0.81).abs() < 1e-15);
        assert!((d.critical(0.1) - 0.78).abs() < 1e-15);
        assert_eq!(d.predicts(0.84, 0.002), Class::Dilation);
        assert_eq!(d.predicts(0.80, 0.002), Class::Contraction);
        assert_eq!(d.predicts(0.80, 0.1), Class::Dilation);
        // A dense sample that contracted does not agree, whatever its class.
        assert!(d.agrees(0.84, 0.002, 0.01) && !d.agrees(0.84, 0.002, -0.016));
        assert!(d.agrees(0.80, 0.002, -0.03) && !d.agrees(0.80, 0.002, 0.01));
        assert!(!d.agrees(0.84, 0.002, f64::NAN) && !d.agrees(0.80, 0.002, f64::NAN));
    }

    /// The lines fitted to the paper's datasets say what Sect. 3.1 says of Fig. 3j: every named
    /// dataset on its own side; both lines inclined so that a higher rate moves the transition
    /// to a lower solid fraction ("higher du_y/dt encourages dilation"; cracking "at lower solid
    /// fraction at higher du_y/dt"); the cracking line to the right of the dilation line at
    /// every rate of the map.
    #[test]
    fn transition_lines_from_the_papers_datasets_match_its_description() {
        let pts: Vec<(f64, f64, Class)> = PAPER_DATASETS
            .iter()
            .map(|d| (d.g_s0, d.rate_um_s, d.class))
            .collect();
        let f = Frame::default();
        let (cd, crack) = transition_lines(&pts, &f);
        let (cd, crack) = (cd.unwrap(), crack.unwrap());
        for d in PAPER_DATASETS.iter().filter(|d| d.rate_um_s > 0.0) {
            let p = f.to_plot(d.g_s0, d.rate_um_s);
            let dilates = matches!(d.class, Class::Dilation | Class::Cracking);
            assert_eq!(cd.side(p) > 0.0, dilates, "{}", d.name);
            assert_eq!(crack.side(p) > 0.0, d.class == Class::Cracking, "{}", d.name);
        }
        // g on each line at 1 and 1000 µm/s.
        let g_at = |l: &Line, r: f64| f.from_plot([l.u_at(f.to_plot(0.5, r)[1]).unwrap(), 0.0]).0;
        for l in [&cd, &crack] {
            assert!(
                g_at(l, 1000.0) < g_at(l, 1.0),
                "{l:?} is not inclined the paper's way"
            );
        }
        for r in [1.0, 30.0, 1000.0, 3000.0] {
            assert!(g_at(&crack, r) > g_at(&cd, r), "at {r} µm/s");
        }
        // 38 % suspension sits left of every shear dataset.
        assert!(
            PAPER_DATASETS
                .iter()
                .all(|d| d.class == Class::Suspension || d.g_s0 > PERCOLATION_G_S)
        );
        assert!((void_ratio(0.5) - 1.0).abs() < 1e-15);
    }

    #[test]
    fn no_line_through_overlapping_sets() {
        let a = [[0.0, 0.0], [1.0, 1.0]];
        let b = [[1.0, 0.0], [0.0, 1.0]];
        assert!(separating_line(&a, &b).is_none());
        let l = separating_line(&[[1.0, 0.0]], &[[0.0, 0.0]]).unwrap();
        assert!((l.margin - 0.5).abs() < 1e-9 && (l.normal[0] - 1.0).abs() < 1e-9);
    }
}
