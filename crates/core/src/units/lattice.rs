//! SI <-> lattice units for the LBM (Su et al. 2020 Eqs. 15-16).
//! Owned by the LBM engine (issue 3).
//!
//! A scene gives the lattice spacing dx (m), the kinematic viscosity ν (m²/s), the fluid density
//! ρ (kg/m³), the largest velocity it expects (m/s), and either the time step dt (s) or the
//! relaxation time τ. From ν = c_s²(τ − ½) dx²/dt (Su Eq. 15, c_s² = 1/3) the other follows;
//! the Mach number Ma = u_max dt/dx / c_s (Su Eq. 16) must stay small: He et al. ask Ma < 0.1.
//! Parameter sets that cannot be stable (τ ≤ ½) or accurate (Ma above `mach_max`) are refused,
//! Ma above `mach_warn` gives a warning; every message names the parameter, its value, the limit
//! and the fix.

use serde::{Deserialize, Serialize};

/// c_s² in lattice units.
pub const CS2: f64 = 1.0 / 3.0;

/// How the time step is fixed.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TimeSpec {
    /// Time step in seconds.
    Dt(f64),
    /// Relaxation time τ (dimensionless); dt = c_s²(τ − ½) dx²/ν.
    Tau(f64),
}

/// Mach number above which a set-up is warned about (Su et al. 2020 Eq. 16, after He et al.):
/// the one default every scene and stepper refers to.
pub const MACH_WARN: f64 = 0.1;
/// Mach number above which a set-up is refused.
pub const MACH_MAX: f64 = 0.3;
/// Default cell Reynolds number u_max dx/ν above which a warning is given.
pub const RE_CELL_WARN: f64 = 10.0;
/// Default accepted range of a running lattice (`lbdem_lbm::Limits::default`): density within a
/// factor 2 of the reference 1 ...
pub const RHO_MIN: f64 = 0.5;
pub const RHO_MAX: f64 = 2.0;
/// ... and |u| < 0.4 in lattice units (Ma ≈ 0.69, far beyond any accurate run; Su Eq. 16 asks
/// Ma < 0.1): beyond it a run is stopped with a diagnosis.
pub const U_MAX: f64 = 0.4;

/// What a scene states in SI.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LatticeInput {
    /// Lattice spacing (m).
    pub dx: f64,
    /// Kinematic viscosity (m²/s).
    pub nu: f64,
    /// Fluid density (kg/m³).
    pub rho: f64,
    /// Largest velocity expected in the run (m/s), for the Mach check.
    pub u_max: f64,
    pub time: TimeSpec,
    /// Mach number above which a warning is given (default 0.1, Su et al. 2020 after He et al.).
    pub mach_warn: f64,
    /// Mach number above which the set-up is refused (default 0.3).
    pub mach_max: f64,
    /// Cell Reynolds number u_max dx/ν above which a warning is given (default 10): near τ = ½
    /// the flow is under-resolved and, with TRT, τ⁻ = ½ + Λ/(τ − ½) grows without bound (measured
    /// in `crates/lbm/tests/stability.rs`: Taylor-Green ν error 6 % at cell Re 30 with TRT Λ = ¼).
    pub re_cell_warn: f64,
}

impl LatticeInput {
    pub fn new(dx: f64, nu: f64, rho: f64, u_max: f64, time: TimeSpec) -> Self {
        Self {
            dx,
            nu,
            rho,
            u_max,
            time,
            mach_warn: MACH_WARN,
            mach_max: MACH_MAX,
            re_cell_warn: RE_CELL_WARN,
        }
    }
}

/// The derived lattice units.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LatticeUnits {
    pub dx: f64,
    pub dt: f64,
    pub tau: f64,
    /// Reference density (kg/m³) = lattice density 1.
    pub rho: f64,
    /// Viscosity in lattice units.
    pub nu_lu: f64,
    /// Mach number of `u_max`.
    pub mach: f64,
    pub warnings: Vec<String>,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum UnitsError {
    #[error("{name} = {value} must be a positive finite number ({what}); fix the scene's value")]
    NotPositive {
        name: &'static str,
        value: f64,
        what: &'static str,
    },
    #[error(
        "relaxation time tau = {tau} is <= 0.5 (limit: tau > 0.5, Su et al. 2020 Eq. 15: the viscosity \
         would be zero or negative); raise tau, or raise dt / lower dx so that tau = 0.5 + 3 nu dt/dx^2 > 0.5"
    )]
    Tau { tau: f64 },
    #[error(
        "LBM-DEM time-step ratio dt_lbm / dt_dem = {ratio} must be a whole number >= 1 \
         (Su et al. 2020 Table 3); set dt_dem = dt_lbm / N for a whole N"
    )]
    Ratio { ratio: f64 },
    #[error(
        "Mach number Ma = {mach:.3} (u_max = {u_max} m/s, dt = {dt:e} s, dx = {dx:e} m, Su et al. 2020 \
         Eq. 16) is above the limit {limit}; lower dt (tau closer to 0.5) or coarsen dx so that \
         u_max dt/dx < {limit} c_s, i.e. dt < {dt_fix:e} s"
    )]
    Mach {
        mach: f64,
        u_max: f64,
        dt: f64,
        dx: f64,
        limit: f64,
        dt_fix: f64,
    },
}

fn positive(name: &'static str, value: f64, what: &'static str) -> Result<(), UnitsError> {
    if value > 0.0 && value.is_finite() {
        Ok(())
    } else {
        Err(UnitsError::NotPositive { name, value, what })
    }
}

impl LatticeUnits {
    pub fn derive(inp: &LatticeInput) -> Result<Self, UnitsError> {
        positive("dx", inp.dx, "lattice spacing in m")?;
        positive("viscosity", inp.nu, "kinematic viscosity in m^2/s")?;
        positive("density", inp.rho, "fluid density in kg/m^3")?;
        if !(inp.u_max >= 0.0 && inp.u_max.is_finite()) {
            return Err(UnitsError::NotPositive {
                name: "u_max",
                value: inp.u_max,
                what: "largest expected velocity in m/s, >= 0",
            });
        }
        let (dt, tau) = match inp.time {
            TimeSpec::Dt(dt) => {
                positive("dt", dt, "time step in s")?;
                (dt, 0.5 + inp.nu * dt / (CS2 * inp.dx * inp.dx))
            }
            TimeSpec::Tau(tau) => {
                if tau.is_nan() || tau <= 0.5 || !tau.is_finite() {
                    return Err(UnitsError::Tau { tau });
                }
                (CS2 * (tau - 0.5) * inp.dx * inp.dx / inp.nu, tau)
            }
        };
        if tau.is_nan() || tau <= 0.5 {
            return Err(UnitsError::Tau { tau });
        }
        let cs = CS2.sqrt();
        let mach = inp.u_max * dt / inp.dx / cs;
        let dt_for = |limit: f64| limit * cs * inp.dx / inp.u_max;
        if mach > inp.mach_max {
            return Err(UnitsError::Mach {
                mach,
                u_max: inp.u_max,
                dt,
                dx: inp.dx,
                limit: inp.mach_max,
                dt_fix: dt_for(inp.mach_max),
            });
        }
        let mut warnings = Vec::new();
        if mach > inp.mach_warn {
            warnings.push(format!(
                "Mach number Ma = {mach:.3} is above {} (Su et al. 2020 Eq. 16, He et al.): compressibility \
                 errors of order Ma^2; use dt < {:e} s for Ma < {}",
                inp.mach_warn,
                dt_for(inp.mach_warn),
                inp.mach_warn
            ));
        }
        let re_cell = inp.u_max * inp.dx / inp.nu;
        if re_cell > inp.re_cell_warn {
            warnings.push(format!(
                "cell Reynolds number u_max dx/nu = {re_cell:.1} is above {} (tau = {tau:.4}): the flow is \
                 under-resolved and accuracy degrades near tau = 0.5; refine dx to below {:e} m",
                inp.re_cell_warn,
                inp.re_cell_warn * inp.nu / inp.u_max.max(f64::MIN_POSITIVE)
            ));
        }
        Ok(Self {
            dx: inp.dx,
            dt,
            tau,
            rho: inp.rho,
            nu_lu: CS2 * (tau - 0.5),
            mach,
            warnings,
        })
    }
    /// m/s -> lattice.
    pub fn velocity_to_lattice(&self, u: f64) -> f64 {
        u * self.dt / self.dx
    }
    pub fn velocity_to_si(&self, u: f64) -> f64 {
        u * self.dx / self.dt
    }
    /// Acceleration (m/s², e.g. gravity) -> lattice force density at ρ_lu = 1.
    pub fn acceleration_to_lattice(&self, g: f64) -> f64 {
        g * self.dt * self.dt / self.dx
    }
    /// Pressure (Pa) -> lattice density offset, p = ρ c_s² (Su Eq. 17).
    pub fn pressure_to_density(&self, p: f64) -> f64 {
        p / self.rho * self.dt * self.dt / (self.dx * self.dx) / CS2
    }
    /// Lattice density -> pressure relative to the reference (Pa), Su Eq. 17.
    pub fn density_to_pressure(&self, rho_lu: f64) -> f64 {
        (rho_lu - 1.0) * CS2 * self.rho * self.dx * self.dx / (self.dt * self.dt)
    }
    /// Lattice force -> N (3D) or N per metre of depth (2D: `dim` = 2).
    pub fn force_to_si(&self, f: f64, dim: usize) -> f64 {
        f * self.rho * self.dx.powi(dim as i32 + 1) / (self.dt * self.dt)
    }
    /// Lattice torque -> N m (3D) or N m per metre (2D).
    pub fn torque_to_si(&self, t: f64, dim: usize) -> f64 {
        self.force_to_si(t, dim) * self.dx
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn water(time: TimeSpec, u: f64) -> LatticeInput {
        LatticeInput::new(1e-4, 1e-6, 1000.0, u, time)
    }

    #[test]
    fn tau_and_dt_are_inverse() {
        let a = LatticeUnits::derive(&water(TimeSpec::Tau(0.8), 0.01)).unwrap();
        // Su Eq. 15: nu = dt cs^2 (tau - 1/2) dx^2/dt^2 -> dt = 0.1 * 1e-8 / 1e-6 = 1e-3 s
        assert!((a.dt - 1e-3).abs() < 1e-15);
        let b = LatticeUnits::derive(&water(TimeSpec::Dt(a.dt), 0.01)).unwrap();
        assert!((b.tau - 0.8).abs() < 1e-12);
    }

    #[test]
    fn refuses_tau_at_or_below_one_half_naming_it() {
        for tau in [0.5, 0.4, f64::NAN] {
            let e = LatticeUnits::derive(&water(TimeSpec::Tau(tau), 0.0)).unwrap_err();
            assert!(matches!(e, UnitsError::Tau { .. }));
            let msg = e.to_string();
            assert!(
                msg.contains("tau") && msg.contains("0.5") && msg.contains("raise"),
                "{msg}"
            );
        }
    }

    #[test]
    fn mach_walk_warns_then_refuses() {
        // dt = 1e-3 s, dx = 1e-4 m: Ma = u * 10 / 0.577
        let mut seen_warn = false;
        let mut refused_at = None;
        for k in 1..=40 {
            let u = 0.0005 * k as f64;
            match LatticeUnits::derive(&water(TimeSpec::Tau(0.8), u)) {
                Ok(l) => {
                    assert!(l.mach <= 0.3);
                    let mach_warned = l.warnings.iter().any(|w| w.contains("Mach"));
                    assert_eq!(mach_warned, l.mach > 0.1, "Ma {}", l.mach);
                    seen_warn |= !l.warnings.is_empty();
                }
                Err(e) => {
                    let msg = e.to_string();
                    assert!(
                        msg.contains("Mach") && msg.contains("0.3") && msg.contains("lower dt"),
                        "{msg}"
                    );
                    refused_at.get_or_insert(u);
                }
            }
        }
        assert!(seen_warn);
        let u = refused_at.expect("refused somewhere");
        assert!(u * 10.0 / CS2.sqrt() > 0.3);
    }

    #[test]
    fn mach_limits_are_configurable() {
        let mut inp = water(TimeSpec::Tau(0.8), 0.02); // Ma = 0.346
        assert!(LatticeUnits::derive(&inp).is_err());
        inp.mach_max = 0.4;
        assert!(LatticeUnits::derive(&inp).is_ok());
    }
}
