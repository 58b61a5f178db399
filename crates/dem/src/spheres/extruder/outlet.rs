//! The open outlet (Ness et al. 2017: "The downstream end of the geometry is open, so particles
//! flowing out of the end of the die are removed from the simulation and subsequently omitted
//! from contact force and stress calculations"), and the check that no grain got through a
//! wall.

use super::error::ExtruderError;
use super::geometry::Geometry;
use crate::spheres::law::SphereLaw;
use crate::spheres::system::SphereSystem;

/// Remove the mobile grains (index `first` on) whose centre is past the outlet; returns how
/// many.
pub fn remove_past_outlet<L: SphereLaw>(
    g: &Geometry,
    law: &L,
    sys: &mut SphereSystem,
    first: usize,
) -> Result<u64, ExtruderError> {
    let x_out = g.outlet_x();
    let s = &sys.spheres;
    let gone: Vec<usize> = (first..s.len()).filter(|&k| s.pos[k].x > x_out).collect();
    if !gone.is_empty() {
        sys.remove_spheres(law, &gone)?;
    }
    Ok(gone.len() as u64)
}

/// Refuse a mobile grain (index `first` on) whose centre is outside the channel upstream of
/// the die's end: it went through a wall line.
pub fn check_no_leak(g: &Geometry, sys: &SphereSystem, first: usize) -> Result<(), ExtruderError> {
    let s = &sys.spheres;
    let end = g.die_end();
    match (first..s.len()).find(|&k| s.pos[k].x <= end && !g.inside(s.pos[k])) {
        Some(k) => Err(ExtruderError::Leak {
            grain: k,
            x: s.pos[k].x,
            y: s.pos[k].y,
            step: sys.step,
        }),
        None => Ok(()),
    }
}
