//! Set-ups of the free-surface validation cases (pure: state and stepper, no I/O).

use super::cells::{FreeSurface, INTERFACE, LIQUID};
use super::stepper::{FreeSurfaceParams, FreeSurfaceStepper};
use crate::LbmError;
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
    let wall = Face::Wall { velocity: [0.0; 3] };
    let dom = Domain::new(
        [nx, ny, 1],
        [
            Face::Periodic,
            Face::Periodic,
            wall,
            wall,
            Face::Periodic,
            Face::Periodic,
        ],
    );
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
