//! Per-contact forces for stress sums (issue 19: Ness et al. 2017 coarse-grain the stress from
//! the force dipoles, Eq. 7): the stepper records every interaction that exerted a force in its
//! last force evaluation as a [`ContactForce`] ([`super::SphereStepper::contacts`]), and
//! [`dipole_stress`] sums them into σ = −(1/V) Σ r ⊗ F.
//!
//! Branch vectors: for a pair, r = x_j − x_i (minimum image) and F the force on i, so r ⊗ F is
//! the pair's dipole whichever sphere is called i (F_ji = −F_ij, r_ji = −r_ij); for a plane wall
//! (or any body outside the assembly), r is i's arm to the contact point. With that choice the
//! sum over all records is Σ_c (x_c − x_i) ⊗ F_c over every sphere's contacts, which for an
//! assembly in equilibrium equals Σ_walls x_c ⊗ F_c: the wall loads (the check in
//! `crates/dem/tests/stress.rs`). Sign: compression positive, as Ness's Eq. 7 convention.

use crate::vector::Vec3;

/// What the other side of an interaction is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Partner {
    /// Sphere j (j > i).
    Sphere(u32),
    /// Plane wall w.
    Wall(u32),
}

/// One interaction of the last force evaluation, seen from sphere i.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactForce {
    /// Sphere i.
    pub i: u32,
    /// The other side.
    pub j: Partner,
    /// Contact point (m): i's centre plus its arm, halfway into the overlap (or across the gap);
    /// not wrapped into a periodic box.
    pub point: Vec3,
    /// Branch vector (m): x_j − x_i (minimum image) for a pair, i's arm to the contact point
    /// for a wall.
    pub branch: Vec3,
    /// Total force on i (N): normal, tangential and lubrication (j receives its negative).
    pub force: Vec3,
    /// The hydrodynamic (lubrication) part of `force` (N).
    pub hydro: Vec3,
}

/// σ = −(1/V) Σ r ⊗ F over `contacts` (Ness et al. 2017, Eq. 7 summed over the spheres, divided
/// by the volume `volume`), as rows σ[a][b] = −(1/V) Σ r_a F_b; `hydro_only` keeps F^h (Eq. 7a)
/// alone. Compression is positive.
pub fn dipole_stress(contacts: &[ContactForce], volume: f64, hydro_only: bool) -> [[f64; 3]; 3] {
    let mut s = [[0.0; 3]; 3];
    for c in contacts {
        let f = if hydro_only { c.hydro } else { c.force };
        let (r, f) = ([c.branch.x, c.branch.y, c.branch.z], [f.x, f.y, f.z]);
        for (row, ra) in s.iter_mut().zip(r) {
            for (x, fb) in row.iter_mut().zip(f) {
                *x -= ra * fb / volume;
            }
        }
    }
    s
}
