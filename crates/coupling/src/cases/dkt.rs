//! Drafting, kissing and tumbling of two disks settling in a closed 2D channel: the case of
//! Uhlmann (J. Comput. Phys. 209 (2005) 448, Sect. 5.3, Figs. 6-8), itself the 2D case of
//! Glowinski et al. (J. Comput. Phys. 169 (2001) 363): a channel 2 cm wide and 6 cm tall,
//! disks of d = 0.25 cm and ρ_p/ρ_f = 1.5 in a liquid of ν = 0.01 cm²/s, released at rest
//! on the centreline 1.0 cm (trailing) and 1.5 cm (leading) below the top, with a lateral
//! offset of d/250 either way (as in Ghigo's Basilisk reproduction of the case) to break the
//! symmetry. The terminal Reynolds number is a few hundred, so the lattice runs at τ close to
//! ½ with the TRT liquid collision, and the grains are 1.5 times denser than the liquid, so
//! the interior-liquid correction is on (both can be switched off to see why they are there).

use crate::driver::Coupled;
use crate::error::CouplingError;
use crate::hydro::Hydro;
use crate::psm::{PsmFluid, PsmSettings};
use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::{Bodies, ClumpShape, Damping, Law, StepParams, System, Vec2, Vector, generate};
use lbdem_lbm::{Limits, Real};
use std::time::Instant;

/// The physical set-up (SI) and the numerical choices.
#[derive(Clone, Copy, Debug)]
pub struct DktSpec {
    pub diameter: f64,
    pub width: f64,
    pub height: f64,
    pub rho_f: f64,
    pub rho_p: f64,
    pub nu: f64,
    pub g: f64,
    /// Depth below the top of the trailing and of the leading disk's centre.
    pub start_depth: [f64; 2],
    /// Lateral offset of the trailing disk from the centreline (the leading one gets minus this).
    pub offset: f64,
    pub duration: f64,
    pub cells_per_diameter: usize,
    pub tau: f64,
    /// TRT magic parameter, or `None` for BGK.
    pub trt_magic: Option<f64>,
    pub interior_liquid_correction: bool,
    /// Range ζ of the disk-disk and disk-wall contact, in lattice cells: the DEM sees each disk
    /// ζ/2 larger than the liquid does (r_hd = d / (d + ζ)), with the mass and inertia of the
    /// true disk, so the disks stop ζ apart, as with the short-range repulsion of Glowinski et
    /// al. and Uhlmann (ζ = 2 grid cells). 0: the DEM and liquid radii are the same.
    pub contact_range_cells: f64,
    /// DEM sub-steps per LBM step.
    pub ratio: u32,
    /// Output interval (s).
    pub sample: f64,
}

impl Default for DktSpec {
    fn default() -> Self {
        let d = 2.5e-3;
        Self {
            diameter: d,
            width: 0.02,
            height: 0.06,
            rho_f: 1000.0,
            rho_p: 1500.0,
            nu: 1e-6,
            g: 9.81,
            start_depth: [0.01, 0.015],
            offset: d / 250.0,
            duration: 0.3,
            cells_per_diameter: 16,
            tau: 0.51,
            trt_magic: Some(0.25),
            interior_liquid_correction: true,
            contact_range_cells: 2.0,
            ratio: 4,
            sample: 2e-3,
        }
    }
}

impl DktSpec {
    /// Speed bound for the Mach check: twice Uhlmann's reference velocity
    /// u_ref = √(π d (ρ_p/ρ_f − 1) g / 2), above the disks' peak speeds.
    pub fn velocity_scale(&self) -> f64 {
        2.0 * (std::f64::consts::PI * self.diameter * (self.rho_p / self.rho_f - 1.0) * self.g / 2.0).sqrt()
    }

    /// The τ at which [`Self::velocity_scale`] is `u_lattice` in lattice units at this resolution
    /// (dt = u_lattice dx / u, τ = ½ + 3 ν dt / dx²).
    pub fn tau_for(&self, u_lattice: f64) -> f64 {
        let dx = self.diameter / self.cells_per_diameter as f64;
        0.5 + 3.0 * self.nu * u_lattice / (self.velocity_scale() * dx)
    }
}

/// One sample of the trajectories: time (s), and per disk (trailing, leading) the depth of the
/// centre below the top and its lateral offset from the centreline (m).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DktSample {
    pub t: f64,
    pub depth: [f64; 2],
    pub lateral: [f64; 2],
    /// Velocity along gravity (downward positive) and lateral velocity (m/s).
    pub fall_speed: [f64; 2],
    pub lateral_speed: [f64; 2],
}

#[derive(Clone, Debug)]
pub struct DktResult {
    pub samples: Vec<DktSample>,
    pub lbm_steps: u64,
    pub nodes: usize,
    pub wall_seconds: f64,
    /// Smallest surface gap between the disks over the run (m; negative = DEM overlap).
    pub min_gap: f64,
}

/// Run the case with populations stored in `T`.
pub fn run<T: Real>(spec: &DktSpec) -> Result<DktResult, CouplingError> {
    let d = spec.diameter;
    let dx = d / spec.cells_per_diameter as f64;
    let (w, h) = (spec.width, spec.height);
    let b = super::closed_box(
        [w, h],
        dx,
        spec.nu,
        spec.rho_f,
        spec.velocity_scale(),
        spec.tau,
        spec.ratio,
    )?;
    let (dt, units, domain) = (b.dt, b.units, b.domain);
    let mut fluid = PsmFluid::<T>::new(
        &domain,
        PsmSettings {
            collision: lbdem_lbm::Collision::Bgk { tau: spec.tau },
            force: [0.0; 2],
            limits: Limits::default(),
        },
    )?;
    if let Some(m) = spec.trt_magic {
        fluid = fluid.with_trt(m)?;
    }

    let mut bodies = Bodies::new();
    let centre = 0.5 * w;
    let zeta = spec.contact_range_cells * dx;
    let (mass, inertia) = {
        let m = spec.rho_p * std::f64::consts::PI * 0.25 * d * d;
        (m, m * d * d / 8.0)
    };
    for (k, depth) in spec.start_depth.iter().enumerate() {
        let side = if k == 0 { 1.0 } else { -1.0 };
        let b = bodies.add(
            &ClumpShape::disk(0.5 * (d + zeta)),
            spec.rho_p,
            Vec2::new(centre + side * spec.offset, h - depth),
            0.0,
        )?;
        bodies.mass[b] = mass;
        bodies.inertia[b] = inertia;
    }
    let r_hd = d / (d + zeta);
    let mut sys = System::new(bodies, lbdem_dem::Domain::open(Vec2::ZERO, Vec2::new(w, h)));
    sys.walls.extend(generate::box_walls(Vec2::ZERO, Vec2::new(w, h)));
    // A stiff contact (overlap about 1 % of d at the kiss's approach speed) resolved by about 20
    // DEM steps; the lattice cannot resolve the lubrication film, so the contact stands in for it.
    let m = spec.rho_p * std::f64::consts::PI * 0.25 * d * d;
    let k_n = (0.5 * m) * (std::f64::consts::PI / (20.0 * units.dt_dem)).powi(2);
    let law = Law::Linear(LinearSpringDashpot::new(k_n, 0.5 * k_n, Damping::Ratio(0.5), 0.0));
    let mut params = StepParams::new(units.dt_dem, 0.1 * d);
    params.gravity = Vec2::new(0.0, -spec.g);
    params.gravity_factor = 1.0 - spec.rho_f / spec.rho_p;
    let mut run = Coupled::new(Hydro::psm(fluid), sys, law.clone(), law, params, units, r_hd)?;
    if spec.interior_liquid_correction {
        run = run.with_interior_liquid_correction()?;
    }

    let steps = (spec.duration / dt).ceil() as u64;
    let every = ((spec.sample / dt).round() as u64).max(1);
    let sample = |run: &Coupled<T>, t: f64| {
        let (p, v) = (&run.sys.bodies.pos, &run.sys.bodies.vel);
        DktSample {
            t,
            depth: [h - p[0].y, h - p[1].y],
            lateral: [p[0].x - centre, p[1].x - centre],
            fall_speed: [-v[0].y, -v[1].y],
            lateral_speed: [v[0].x, v[1].x],
        }
    };
    let mut samples = vec![sample(&run, 0.0)];
    let mut min_gap = f64::INFINITY;
    let start = Instant::now();
    for s in 1..=steps {
        run.step()?;
        let p = &run.sys.bodies.pos;
        min_gap = min_gap.min((p[0] - p[1]).norm() - d);
        if s % every == 0 || s == steps {
            samples.push(sample(&run, s as f64 * dt));
        }
    }
    Ok(DktResult {
        samples,
        lbm_steps: steps,
        nodes: b.nodes,
        wall_seconds: start.elapsed().as_secs_f64(),
        min_gap,
    })
}

/// Linear interpolation of a sampled series at time `t` (clamped at the ends).
pub fn interpolate(ts: &[f64], vs: &[f64], t: f64) -> f64 {
    match ts.iter().position(|&x| x >= t) {
        None => *vs.last().unwrap_or(&f64::NAN),
        Some(0) => vs[0],
        Some(i) => {
            let a = (t - ts[i - 1]) / (ts[i] - ts[i - 1]);
            vs[i - 1] + a * (vs[i] - vs[i - 1])
        }
    }
}
