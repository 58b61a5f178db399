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

use crate::vector::{Vec3, Vector};

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

/// One sphere's share of the force dipoles (Ness et al. 2017, Eq. 7), as rows
/// w[a][b] = −Σ r_a F_b (N m; compression positive), total and its hydrodynamic part (Eq. 7a).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SphereDipole {
    pub total: [[f64; 3]; 3],
    pub hydro: [[f64; 3]; 3],
}

/// Each sphere's share of the dipoles of `contacts` (one share per entry of `frozen` and
/// `radius`): a pair's −r ⊗ F split half to each sphere (the pair's dipole is the same seen from
/// either side); a contact with a plane wall gives its sphere −a ⊗ F with a the arm to the
/// contact point (the record's branch), and a contact with a frozen (wall) grain gives the
/// mobile sphere the same, −(a_i/|r|) r ⊗ F with a_i = (r_i − r_j + |r|)/2 its arm to the
/// contact point, so the walls' grains carry none and a paste grain at a wall of grains is
/// counted as at a plane wall.
/// Binned (Ness's coarse-graining: a sphere's share goes to the bin holding its centre) and
/// divided by the bin volume, this is the bin's stress; summed over every sphere it is
/// [`dipole_stress`] times the volume when no partner is frozen (a frozen partner's share is
/// the part of the branch beyond the contact point, left out). Records naming a sphere past the
/// table are skipped.
pub fn sphere_dipoles(contacts: &[ContactForce], frozen: &[bool], radius: &[f64]) -> Vec<SphereDipole> {
    let n = frozen.len().min(radius.len());
    let mut w = vec![SphereDipole::default(); n];
    let mut add = |k: usize, share: f64, c: &ContactForce| {
        if let Some(d) = w.get_mut(k) {
            let r = [c.branch.x, c.branch.y, c.branch.z];
            let (f, fh) = (
                [c.force.x, c.force.y, c.force.z],
                [c.hydro.x, c.hydro.y, c.hydro.z],
            );
            for ((row, hrow), ra) in d.total.iter_mut().zip(d.hydro.iter_mut()).zip(r) {
                for ((x, xh), (fb, fhb)) in row.iter_mut().zip(hrow.iter_mut()).zip(f.iter().zip(&fh)) {
                    *x -= share * ra * fb;
                    *xh -= share * ra * fhb;
                }
            }
        }
    };
    for c in contacts {
        match c.j {
            Partner::Sphere(j) => {
                let (i, j) = (c.i as usize, j as usize);
                let fixed = |k: usize| frozen.get(k).copied().unwrap_or(false);
                // The mobile sphere's arm to the contact point over the centre distance.
                let arm = |k: usize, o: usize| {
                    let (rk, ro) = (radius.get(k).copied(), radius.get(o).copied());
                    let d = c.branch.norm();
                    rk.zip(ro).map_or(0.5, |(rk, ro)| 0.5 * (rk - ro + d) / d)
                };
                match (fixed(i), fixed(j)) {
                    (false, true) => add(i, arm(i, j), c),
                    (true, false) => add(j, arm(j, i), c),
                    _ => {
                        add(i, 0.5, c);
                        add(j, 0.5, c);
                    }
                }
            }
            Partner::Wall(_) => add(c.i as usize, 1.0, c),
        }
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pair record between sphere 0 (radius 1) and a frozen wall grain 1 (radius ½) one
    /// apart (an overlap of ½) gives sphere 0 the dipole of its arm to the contact point, 3/4 of
    /// the branch (as a plane wall would); between two mobile spheres each gets half.
    #[test]
    fn a_frozen_partner_leaves_the_mobile_sphere_its_arms_share() {
        let rec = [ContactForce {
            i: 0,
            j: Partner::Sphere(1),
            point: Vec3::new(0.5, 0.0, 0.0),
            branch: Vec3::new(1.0, 0.0, 0.0),
            force: Vec3::new(-2.0, 0.5, 0.0),
            hydro: Vec3::new(-0.5, 0.0, 0.0),
        }];
        let r = [1.0, 0.5];
        let mobile = sphere_dipoles(&rec, &[false, false], &r);
        let wall = sphere_dipoles(&rec, &[false, true], &r);
        assert_eq!(mobile[0].total[0][0], 1.0);
        assert_eq!(mobile[1].total[0][1], -0.25);
        let sigma = dipole_stress(&rec, 1.0, false);
        assert_eq!(mobile[0].total[0][0] + mobile[1].total[0][0], sigma[0][0]);
        // Arm (1 + 1 − 0.5)/2 = 0.75 of the unit branch.
        assert_eq!(wall[0].total[0][0], 0.75 * 2.0);
        assert_eq!(wall[0].hydro[0][0], 0.75 * 0.5);
        assert_eq!(wall[1], SphereDipole::default());
    }
}
