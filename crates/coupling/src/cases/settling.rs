//! A disk settling midway between the walls of a closed 2D box at low Reynolds number, against
//! the Stokes drag of a cylinder moving parallel to two plane walls (Faxén 1946, as quoted by
//! Happel & Brenner, "Low Reynolds Number Hydrodynamics", 1965, and Ben Richou, Ambari & Naciri,
//! Chem. Eng. Sci. 59 (2004) 3215):
//!
//! F / (μ U) = 4π / (ln(1/k) − 0.9157 + 1.7244 k² − 1.7302 k⁴ + 2.4056 k⁶ − 4.5913 k⁸),
//! k = d / W (diameter over wall gap), accurate for k up to about 0.5.
//!
//! At terminal velocity the drag balances the buoyant weight (ρ_p − ρ_f) g π d²/4, which
//! gives U_t. The fluid of the Glowinski et al. (2001) disk cases of REFERENCES.md is used
//! (ρ_f = 1000 kg/m³, ν = 1e-6 m²/s, d = 2 mm) with a density excess small enough for
//! Re = U d / ν ≈ 0.06, in a box 4 d wide and 20 d tall (its closed ends are 10 d away).

use crate::driver::Coupled;
use crate::error::CouplingError;
use crate::hydro::{Hydro, Method};
use crate::psm::PsmFluid;
use crate::{PsmSettings, bounce::BounceFluid};

use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::{Bodies, ClumpShape, Damping, Law, StepParams, System, Vec2};
use lbdem_lbm::{Limits, Real};
use std::time::Instant;

/// F/(μU) of a cylinder midway between two walls, k = d/W (Faxén 1946).
pub fn faxen_drag(k: f64) -> f64 {
    let k2 = k * k;
    4.0 * std::f64::consts::PI
        / ((1.0 / k).ln() - 0.9157 + 1.7244 * k2 - 1.7302 * k2 * k2 + 2.4056 * k2 * k2 * k2
            - 4.5913 * k2 * k2 * k2 * k2)
}

/// The physical set-up (SI).
#[derive(Clone, Copy, Debug)]
pub struct SettlingSpec {
    pub diameter: f64,
    /// Box width in diameters (k = 1 / this).
    pub width: f64,
    /// Box height in diameters.
    pub height: f64,
    pub rho_f: f64,
    pub rho_p: f64,
    pub nu: f64,
    pub g: f64,
    /// Lattice cells per diameter.
    pub cells_per_diameter: usize,
    pub tau: f64,
    pub method: Method,
    /// Simulated time in units of the viscous time W²/ν.
    pub duration: f64,
    /// The interior-liquid correction ([`Coupled::with_interior_liquid_correction`]), PSM only.
    pub interior_liquid_correction: bool,
    /// Switch it on even below the density ratio the run-time check refuses (stability maps).
    pub force_past_refusal: bool,
}

impl Default for SettlingSpec {
    fn default() -> Self {
        Self {
            diameter: 2e-3,
            width: 4.0,
            height: 20.0,
            rho_f: 1000.0,
            rho_p: 1000.02,
            nu: 1e-6,
            g: 9.81,
            cells_per_diameter: 10,
            tau: 1.0,
            method: Method::Psm,
            duration: 0.6,
            interior_liquid_correction: false,
            force_past_refusal: false,
        }
    }
}

impl SettlingSpec {
    /// Terminal velocity from the Faxén drag (m/s, positive downward).
    pub fn reference_velocity(&self) -> f64 {
        let a = 0.5 * self.diameter;
        let mu = self.nu * self.rho_f;
        (self.rho_p - self.rho_f) * self.g * std::f64::consts::PI * a * a
            / (mu * faxen_drag(1.0 / self.width))
    }
}

#[derive(Clone, Debug)]
pub struct SettlingResult {
    /// Settling velocity (m/s, downward positive) averaged over the last sixth of the run
    /// (bounce-back makes it flicker as the disk crosses nodes).
    pub velocity: f64,
    /// The same over the sixth before, to show the run has reached its terminal value.
    pub velocity_earlier: f64,
    pub reference: f64,
    /// (velocity − reference) / reference.
    pub error: f64,
    pub reynolds: f64,
    /// Lateral drift of the centre over the run (m).
    pub drift: f64,
    pub lbm_steps: u64,
    pub nodes: usize,
    pub wall_seconds: f64,
}

/// Run the case with populations stored in `T`.
pub fn run<T: Real>(spec: &SettlingSpec) -> Result<SettlingResult, CouplingError> {
    let d = spec.diameter;
    let dx = d / spec.cells_per_diameter as f64;
    let (w, h) = (spec.width * d, spec.height * d);
    let u_ref = spec.reference_velocity();
    let b = super::closed_box([w, h], dx, spec.nu, spec.rho_f, 2.0 * u_ref.abs(), spec.tau, 1)?;
    let (dt, units, domain) = (b.dt, b.units, b.domain);
    let limits = Limits::default();
    let hydro = match spec.method {
        Method::Psm => Hydro::psm(PsmFluid::<T>::new(
            &domain,
            PsmSettings {
                collision: lbdem_lbm::Collision::Bgk { tau: spec.tau },
                force: [0.0; 2],
                limits,
            },
        )?),
        Method::BounceBack => Hydro::BounceBack(Box::new(BounceFluid::<T>::new(
            domain, spec.tau, [0.0; 2], limits,
        )?)),
    };

    let mut bodies = Bodies::new();
    bodies.add(
        &ClumpShape::disk(0.5 * d),
        spec.rho_p,
        Vec2::new(0.5 * w, 0.6 * h),
        0.0,
    )?;
    let sys = System::new(bodies, lbdem_dem::Domain::open(Vec2::ZERO, Vec2::new(w, h)));
    // No contacts happen; the stiffness only has to allow the DEM step (= the LBM step).
    let m = spec.rho_p * std::f64::consts::PI * 0.25 * d * d;
    let k_n = 0.01 * m / (dt * dt);
    let law = Law::Linear(LinearSpringDashpot::new(k_n, 0.5 * k_n, Damping::Ratio(0.1), 0.0));
    let mut params = StepParams::new(dt, 0.1 * d);
    params.gravity = Vec2::new(0.0, -spec.g);
    params.gravity_factor = 1.0 - spec.rho_f / spec.rho_p;
    let mut run = Coupled::new(hydro, sys, law.clone(), law, params, units, 1.0)?;
    if spec.interior_liquid_correction {
        run = if spec.force_past_refusal {
            run.force_interior_liquid_correction()?
        } else {
            run.with_interior_liquid_correction()?
        };
    }

    let steps = (spec.duration * w * w / spec.nu / dt).ceil() as u64;
    let window = (steps / 6).max(1);
    let x0 = run.sys.bodies.pos[0].x;
    let (mut earlier, mut v) = (0.0, 0.0);
    let start = Instant::now();
    for s in 1..=steps {
        run.step()?;
        let vy = -run.sys.bodies.vel[0].y;
        if s > steps - window {
            v += vy / window as f64;
        } else if s > steps - 2 * window {
            earlier += vy / window as f64;
        }
    }
    let wall_seconds = start.elapsed().as_secs_f64();
    Ok(SettlingResult {
        velocity: v,
        velocity_earlier: earlier,
        reference: u_ref,
        error: (v - u_ref) / u_ref,
        reynolds: v * d / spec.nu,
        drift: run.sys.bodies.pos[0].x - x0,
        lbm_steps: steps,
        nodes: b.nodes,
        wall_seconds,
    })
}
