//! Set-ups of the free-surface validation cases (pure: state and stepper, no I/O).

use super::cells::{FreeSurface, INTERFACE, LIQUID};
use super::stepper::{FreeSurfaceParams, FreeSurfaceStepper};
use crate::LbmError;
use crate::cases::{Verdict, setup_verdict};
use crate::collision::Collision;
use crate::domain::{Domain, Face};
use crate::kernel::Limits;
use crate::lattice::{CS2, D2Q9, D3Q19, Lattice};
use crate::stepper::Settings;

/// The 2D dam break of Martin & Moyce (1952): a column `a` nodes wide and `2a` high against the
/// left wall of a box `nx` × `ny` with walls on all four sides, released at rest under gravity
/// `g` (lattice units, along −y). The column starts hydrostatic (ρ = ρ_A + 3 g (2a − y), Leonardi
/// Eq. 18 with p = c_s² ρ) so the first steps see no pressure wave from the initial state.
pub fn dam_break(
    a: usize,
    nx: usize,
    ny: usize,
    g: f64,
    collision: Collision,
) -> Result<(FreeSurface<D2Q9>, FreeSurfaceStepper<D2Q9>), LbmError> {
    dam_break_in::<D2Q9>(a, [nx, ny, 1], g, collision)
}

/// The dam break on D3Q19 in a box of `n` nodes, periodic in z: the same column, walls
/// and hydrostatic start as [`dam_break`], every z-layer alike. What the free-surface benchmark
/// runs (`lbdem bench free-surface`): a 3D box whose liquid, interface and gas all change.
pub fn dam_break_3d(
    a: usize,
    n: [usize; 3],
    g: f64,
    collision: Collision,
) -> Result<(FreeSurface<D3Q19>, FreeSurfaceStepper<D3Q19>), LbmError> {
    dam_break_in::<D3Q19>(a, n, g, collision)
}

/// The dam break on lattice `L` in a box of `n` nodes (walls on x and y, periodic in z).
fn dam_break_in<L: Lattice>(
    a: usize,
    n: [usize; 3],
    g: f64,
    collision: Collision,
) -> Result<(FreeSurface<L>, FreeSurfaceStepper<L>), LbmError> {
    let wall = Face::Wall { velocity: [0.0; 3] };
    let dom = Domain::new(n, [wall, wall, wall, wall, Face::Periodic, Face::Periodic]);
    let params = FreeSurfaceParams::default();
    let h = (2 * a) as f64;
    let s = FreeSurface::<L>::new(dom, |p| {
        let inside = p[0] < a && p[1] < 2 * a;
        let rho = params.rho_atm + g / CS2 * (h - 0.5 - p[1] as f64).max(0.0);
        (if inside { 1.0 } else { 0.0 }, rho, [0.0; 3])
    })?;
    let settings = Settings {
        collision,
        force: [0.0, -g, 0.0],
        limits: Limits::default(),
    };
    let st = FreeSurfaceStepper::new(&s, settings, params)?;
    Ok((s, st))
}

/// Position of the surge front of a dam break, in lattice units from the left wall (the halfway
/// wall, half a node left of node 0): the far face x + 1 of the last node of the bottom row whose
/// fill is at least ½.
pub fn front_position(s: &FreeSurface<D2Q9>) -> f64 {
    let nx = s.domain.n[0];
    (0..nx)
        .rev()
        .find(|&x| s.fill(x) >= 0.5 && matches!(s.cell[x], LIQUID | INTERFACE))
        .map(|x| x as f64 + 1.0)
        .unwrap_or(0.0)
}

/// A periodic layer of liquid of mean depth `h` nodes (over a wall at the bottom, under a wall at
/// the top of an `ny`-node box), with a surface displaced by `amp` cos(2π x / nx), at rest and
/// hydrostatic, under gravity `g` along −y. With `amp = 0` the layer is flat (at rest forever);
/// otherwise it is a standing wave of wavenumber k = 2π/nx.
pub fn layer(
    nx: usize,
    ny: usize,
    h: f64,
    amp: f64,
    g: f64,
    collision: Collision,
) -> Result<(FreeSurface<D2Q9>, FreeSurfaceStepper<D2Q9>), LbmError> {
    // walls below and above, periodic in x: the channel's box
    let dom = crate::cases::poiseuille::channel_box([nx, ny, 1]);
    let params = FreeSurfaceParams::default();
    let k = 2.0 * std::f64::consts::PI / nx as f64;
    // heights from the halfway bottom wall: node y spans [y, y + 1], its centre is at y + ½
    let s = FreeSurface::<D2Q9>::new(dom, |p| {
        let eta = h + amp * (k * p[0] as f64).cos();
        let (lo, hi) = (p[1] as f64, p[1] as f64 + 1.0);
        let fill = ((eta - lo) / (hi - lo)).clamp(0.0, 1.0);
        let rho = params.rho_atm + g / CS2 * (eta - (p[1] as f64 + 0.5)).max(0.0);
        (fill, rho, [0.0; 3])
    })?;
    let settings = Settings {
        collision,
        force: [0.0, -g, 0.0],
        limits: Limits::default(),
    };
    let st = FreeSurfaceStepper::new(&s, settings, params)?;
    Ok((s, st))
}

/// Height of the liquid in column `x`: Σ_y ε(x, y) (nodes above the halfway bottom wall).
pub fn column_height(s: &FreeSurface<D2Q9>, x: usize) -> f64 {
    let [nx, ny, _] = s.domain.n;
    (0..ny).map(|y| s.fill(x + nx * y)).sum()
}

/// Martin & Moyce (1952), column width a, height 2a: (T, Z) with T = t √(2g/a), Z = x/a,
/// digitised for a = 2.25 in (REFERENCES.md, "Dam break"; a few percent reading uncertainty, and
/// the early points are delayed by the opening of the gate).
pub const MARTIN_MOYCE: [(f64, f64); 13] = [
    (0.832, 1.217),
    (1.219, 1.474),
    (1.997, 2.292),
    (2.547, 2.995),
    (3.345, 4.134),
    (4.034, 4.944),
    (4.418, 5.881),
    (5.091, 6.980),
    (5.685, 7.945),
    (6.306, 8.966),
    (6.822, 9.986),
    (7.439, 10.963),
    (8.031, 11.977),
];

/// The speed of an ideal dam-break front on a dry bed, 2 √(g h₀) for a column of height h₀
/// (Ritter 1892; shallow-water theory): the largest speed the collapse can reach, so the
/// `u_max` a set-up check of the dam break is asked about.
pub fn ritter_front_speed(g: f64, h0: f64) -> f64 {
    2.0 * (g * h0).sqrt()
}

/// What the set-up check scenes use says of a dam break of column width `a` (height 2a) under
/// gravity `g` with `collision`: u_max is Ritter's front speed.
pub fn dam_break_verdict(a: usize, g: f64, collision: Collision) -> Verdict {
    setup_verdict(collision, ritter_front_speed(g, (2 * a) as f64))
}

/// How a dam break against Martin & Moyce ended ([`dam_break_fronts`]).
#[derive(Debug)]
pub struct DamBreakRun {
    /// (T, Z simulated, Z of Martin & Moyce) at each reference time reached.
    pub fronts: Vec<(f64, f64, f64)>,
    /// Largest relative change of the total mass (nodes and reservoir) over the run.
    pub mass_drift: f64,
    /// Interface nodes filled or emptied over the run.
    pub conversions: usize,
    /// Steps run: to the stop, or the whole run.
    pub steps: u64,
    /// The engine's diagnosis when a node left its limits ([`LbmError::Unstable`]).
    pub stopped: Option<LbmError>,
    /// The first step after which a liquid node touched a gas node (the interface opened).
    pub opened: Option<u64>,
}

impl DamBreakRun {
    /// Largest |Z − Z_ref| / Z_ref over the fronts reached; `None` if the run was stopped or
    /// its interface opened.
    pub fn worst_front_error(&self) -> Option<f64> {
        if self.stopped.is_some() || self.opened.is_some() {
            return None;
        }
        Some(
            self.fronts
                .iter()
                .map(|&(_, z, z_ref)| ((z - z_ref) / z_ref).abs())
                .fold(0.0, f64::max),
        )
    }
}

/// The dam break of column width `a` in a box `nx` wide and 2a + 4 high, run to each Martin &
/// Moyce time up to `t_end` (T = t √(2g/a)) with the interface checked closed after every step.
/// A node leaving the engine's limits ends the run early (`stopped`), not with an error; errors
/// are set-up refusals.
pub fn dam_break_fronts(
    a: usize,
    nx: usize,
    g: f64,
    collision: Collision,
    t_end: f64,
) -> Result<DamBreakRun, LbmError> {
    let (mut s, mut st) = dam_break(a, nx, 2 * a + 4, g, collision)?;
    let t_scale = (2.0 * g / a as f64).sqrt();
    let m0 = s.total_mass();
    let mut run = DamBreakRun {
        fronts: Vec::new(),
        mass_drift: 0.0,
        conversions: 0,
        steps: 0,
        stopped: None,
        opened: None,
    };
    for &(t_ref, z_ref) in MARTIN_MOYCE.iter().filter(|p| p.0 <= t_end) {
        let until = (t_ref / t_scale).round() as u64;
        while s.step < until {
            match st.step(&mut s) {
                Ok(c) => run.conversions += c.filled + c.emptied,
                Err(e) => {
                    run.stopped = Some(e);
                    run.steps = s.step;
                    return Ok(run);
                }
            }
            if run.opened.is_none() && s.open_interface().is_some() {
                run.opened = Some(s.step);
            }
            run.mass_drift = run.mass_drift.max(((s.total_mass() - m0) / m0).abs());
        }
        run.fronts
            .push((s.step as f64 * t_scale, front_position(&s) / a as f64, z_ref));
    }
    run.steps = s.step;
    Ok(run)
}
