//! Body-force-driven plane Poiseuille flow of a Bingham fluid between two walls (Leonardi et al.
//! 2014 Sect. 5.3, Eqs. 27-30, Fig. 4), against the analytic Bingham profile (Bird, Dai &
//! Yarusso, Rev. Chem. Eng. 1 (1983) 1; for a force density G between walls at y = ±h: plug
//! half-width y₀ = σ_y/G, plug velocity u_p = G (h − y₀)² / (2 μ_pl), u(y) = G [(h² − y²) −
//! 2 y₀ (h − |y|)] / (2 μ_pl) for y₀ ≤ |y| ≤ h) and against the exact profile of the clamped
//! (tri-viscosity, Fig. 4) law the kernel applies, which separates the clamp's error from the
//! lattice's. Run by `tests/bingham.rs` and by the `bingham-map` stability stage. No I/O.

use crate::{Bingham, Collision, Fluid, Lattice, LbmError, Limits, Macro, Settings, StepperAa};

/// One Bingham channel case: `h_nodes` fluid rows between halfway bounce-back walls (half-width
/// h = h_nodes/2), plastic viscosity from τ_pl, plug half-width `y0_frac` h, plug velocity `u_p`.
#[derive(Clone, Copy, Debug)]
pub struct Case {
    pub h_nodes: usize,
    pub tau_pl: f64,
    /// The clamp [τ_min, τ_max] of the relaxation time (Fig. 4; paper: 0.501, 3.5).
    pub tau_min: f64,
    pub tau_max: f64,
    pub y0_frac: f64,
    pub u_p: f64,
    /// Smagorinsky constant of the eddy viscosity (`Bingham::smagorinsky`; 0: none).
    pub smagorinsky: f64,
}

impl Case {
    pub fn h(&self) -> f64 {
        self.h_nodes as f64 / 2.0
    }
    pub fn mu_pl(&self) -> f64 {
        (self.tau_pl - 0.5) / 3.0
    }
    pub fn y0(&self) -> f64 {
        self.y0_frac * self.h()
    }
    /// Force density from u_p = G (h − y₀)² / (2 μ_pl).
    pub fn g(&self) -> f64 {
        2.0 * self.mu_pl() * self.u_p / (self.h() - self.y0()).powi(2)
    }
    pub fn yield_stress(&self) -> f64 {
        self.y0() * self.g()
    }
    pub fn bingham(&self) -> Bingham {
        Bingham {
            mu_pl: self.mu_pl(),
            yield_stress: self.yield_stress(),
            rho: 1.0,
            tau_min: self.tau_min,
            tau_max: self.tau_max,
            smagorinsky: self.smagorinsky,
        }
    }
    /// Distance of row y from the channel centre (walls at y = −½ and h_nodes − ½).
    pub fn yc(&self, y: usize) -> f64 {
        y as f64 + 0.5 - self.h()
    }
    /// The analytic Bingham profile (module doc).
    pub fn bingham_u(&self, y: f64) -> f64 {
        let (h, y0, g, mu) = (self.h(), self.y0(), self.g(), self.mu_pl());
        let a = y.abs().max(y0);
        g * ((h * h - a * a) - 2.0 * y0 * (h - a)) / (2.0 * mu)
    }
    /// The analytic profile of a Newtonian fluid (σ_y = 0) with the eddy viscosity ν_t = C² γ̇
    /// of `Bingham::smagorinsky`, unclamped: the shear stress G|y| = ρ (ν_pl + C² s) s with
    /// s = |du/dy| gives s(t) = (√(ν_pl² + 4C²G t) − ν_pl) / (2C²) (ρ = 1), and
    /// u(y) = ∫_|y|^h s dt = [((ν_pl² + 4C²Gh)^{3/2} − (ν_pl² + 4C²G|y|)^{3/2}) / (6C²G)
    /// − ν_pl (h − |y|)] / (2C²); the Newtonian parabola when C = 0.
    pub fn smagorinsky_u(&self, y: f64) -> f64 {
        let (h, g, nu, c2) = (self.h(), self.g(), self.mu_pl(), self.smagorinsky.powi(2));
        let a = y.abs();
        if c2 == 0.0 {
            return g * (h * h - a * a) / (2.0 * nu);
        }
        let p = |t: f64| (nu * nu + 4.0 * c2 * g * t).powf(1.5);
        ((p(h) - p(a)) / (6.0 * c2 * g) - nu * (h - a)) / (2.0 * c2)
    }
    /// The shear rate of [`Self::smagorinsky_u`] at distance `y` from the centre.
    pub fn smagorinsky_rate(&self, y: f64) -> f64 {
        let (g, nu, c2) = (self.g(), self.mu_pl(), self.smagorinsky.powi(2));
        if c2 == 0.0 {
            return g * y.abs() / nu;
        }
        ((nu * nu + 4.0 * c2 * g * y.abs()).sqrt() - nu) / (2.0 * c2)
    }
    /// Exact profile of the clamped law (Fig. 4): u(y) = ∫_|y|^h γ̇(G s) ds with γ̇(σ) = σ/μ_max
    /// below σ_c = σ_y μ_max/(μ_max − μ_pl), (σ − σ_y)/μ_pl above it, σ/μ_min above
    /// σ_d = σ_y μ_min/(μ_min − μ_pl) when μ_min > μ_pl. γ̇ is piecewise linear in s and
    /// continuous, so the trapezoid rule between the break points is exact.
    pub fn clamped_u(&self, y: f64) -> f64 {
        let b = self.bingham();
        let (mu_pl, sy, g) = (self.mu_pl(), self.yield_stress(), self.g());
        let mu_max = (b.tau_max - 0.5) / 3.0;
        let mu_min = (b.tau_min - 0.5) / 3.0;
        let s_c = sy * mu_max / (mu_max - mu_pl) / g;
        let s_d = if mu_min > mu_pl {
            sy * mu_min / (mu_min - mu_pl) / g
        } else {
            f64::INFINITY
        };
        let rate = |s: f64| {
            let sigma = g * s;
            if s <= s_c {
                sigma / mu_max
            } else if s <= s_d {
                (sigma - sy) / mu_pl
            } else {
                sigma / mu_min
            }
        };
        let mut pts = vec![y.abs(), self.h()];
        for s in [s_c, s_d] {
            if s > y.abs() && s < self.h() {
                pts.push(s);
            }
        }
        pts.sort_by(f64::total_cmp);
        pts.windows(2)
            .map(|w| (w[1] - w[0]) * 0.5 * (rate(w[0]) + rate(w[1])))
            .sum()
    }
    /// Half-width of the clamped core, y_c = y₀ μ_max/(μ_max − μ_pl) (module doc of `bingham`).
    pub fn y_c(&self) -> f64 {
        let mu_max = (self.tau_max - 0.5) / 3.0;
        self.y0() * mu_max / (mu_max - self.mu_pl())
    }
}

/// Result of one channel run.
#[derive(Debug)]
pub struct Outcome {
    /// u per row (x = 0) at the end.
    pub u: Vec<f64>,
    /// τ per row from the kernel (`bingham_tau`) at the end.
    pub tau: Vec<f64>,
    pub steps: usize,
    /// Whether the largest change of u over 1000 steps fell below 1e-11 u_p before `max_steps`.
    pub converged: bool,
    /// The engine's diagnosis when a node left its limits ([`LbmError::Unstable`]); `u` and
    /// `tau` are then empty.
    pub stopped: Option<LbmError>,
}

/// Run the channel on the AA stepper (the default kernel) from rest to a steady state (the
/// largest change of u over 1000 steps below 1e-11 u_p) or `max_steps`. Errors are set-up
/// refusals; a node leaving the limits ends the run with `stopped`.
pub fn run_channel<L: Lattice>(
    case: &Case,
    collision: Collision,
    nx: usize,
    nz: usize,
    max_steps: usize,
) -> Result<Outcome, LbmError> {
    let dom = super::poiseuille::channel_box([nx, case.h_nodes, if L::D == 2 { 1 } else { nz }]);
    let mut fl = Fluid::<L, f64>::new(dom, Vec::new());
    let settings = Settings {
        collision,
        force: [case.g(), 0.0, 0.0],
        limits: Limits::default(),
    };
    let mut st = StepperAa::new(&mut fl, settings)?;
    st.set_bingham(Some(case.bingham()))?;
    let mut m = Macro::default();
    let mut prev: Vec<f64> = Vec::new();
    let mut steps = 0;
    let every = 1000;
    let converged = loop {
        for k in 0..every {
            if let Err(e) = st.step(&mut fl, if k + 1 == every { Some(&mut m) } else { None }) {
                return Ok(Outcome {
                    u: Vec::new(),
                    tau: Vec::new(),
                    steps: steps + k + 1,
                    converged: false,
                    stopped: Some(e),
                });
            }
        }
        steps += every;
        if !prev.is_empty() {
            let d =
                m.u.iter()
                    .zip(&prev)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0.0, f64::max);
            if d < 1e-11 * case.u_p {
                break true;
            }
            if steps >= max_steps {
                break false;
            }
        }
        prev.clone_from(&m.u);
    };
    let tau_all = st.bingham_tau().unwrap_or(&[]);
    let row = |y: usize| y * nx;
    Ok(Outcome {
        u: (0..case.h_nodes).map(|y| m.u[3 * row(y)]).collect(),
        tau: (0..case.h_nodes)
            .map(|y| tau_all.get(row(y)).copied().unwrap_or(f64::NAN))
            .collect(),
        steps,
        converged,
        stopped: None,
    })
}

/// The figures of one run against the analytic profiles.
#[derive(Debug)]
pub struct Errors {
    /// |u_num − u_p| / u_p at the row next to the centre (Bingham plug velocity).
    pub plug: f64,
    /// L2 error of the profile against the Bingham profile, relative to its L2 norm.
    pub l2: f64,
    /// The same two against the exact clamped (tri-viscosity) profile: the lattice's own error.
    pub plug_clamped: f64,
    pub l2_clamped: f64,
    /// Rows with τ = τ_max (the clamped core) and the count the clamped law predicts.
    pub core_rows: usize,
    pub core_rows_exact: usize,
}

/// The run's errors against both profiles; `None` for a run the engine stopped (no profile).
pub fn errors(case: &Case, out: &Outcome) -> Option<Errors> {
    let n = case.h_nodes;
    if out.u.len() != n {
        return None;
    }
    let mid = n / 2; // the row at y_c = +½
    let u_p = case.u_p;
    let l2 = |exact: &dyn Fn(f64) -> f64| {
        let (mut e, mut s) = (0.0, 0.0);
        for y in 0..n {
            let want = exact(case.yc(y));
            e += (out.u[y] - want).powi(2);
            s += want * want;
        }
        (e / s).sqrt()
    };
    let core_rows = out.tau.iter().filter(|&&t| t == case.tau_max).count();
    let core_rows_exact = (0..n).filter(|&y| case.yc(y).abs() < case.y_c()).count();
    Some(Errors {
        plug: (out.u[mid] - u_p).abs() / u_p,
        l2: l2(&|y| case.bingham_u(y)),
        plug_clamped: (out.u[mid] - case.clamped_u(case.yc(mid))).abs() / u_p,
        l2_clamped: l2(&|y| case.clamped_u(y)),
        core_rows,
        core_rows_exact,
    })
}
