//! Zou-He velocity and pressure boundaries (Zou & He, Phys. Fluids 9 (1997) 1591) for D2Q9 on the
//! nodes of a box face, written for any face: the populations entering from outside are rebuilt
//! from the known ones by bouncing back their non-equilibrium part plus a tangential correction.

use crate::domain::Face;
use crate::lattice::{Lattice, QMAX};
use crate::real::Real;

/// Rebuild the populations marked in `missing` at a node of face `face_id` (0..4 = x-, x+, y-, y+).
/// `f[i][0]` holds the known pulled populations. For an inward normal n along axis a:
/// velocity BC: ρ = (Σ_{c_a=0} f + 2 Σ_{c_a=-n} f)/(1 − n u_a);
/// pressure BC: u_a = n(1 − (Σ_{c_a=0} f + 2 Σ_{c_a=-n} f)/ρ), tangential u = 0;
/// then f_i = f_ī + 6 w_i ρ c_i·u − ½ c_{i,t}(Σ_{c_a=0} f_j c_{j,t} − ⅔ ρ u_t) for each unknown i.
pub fn apply<L: Lattice, T: Real>(f: &mut [[T; 1]; QMAX], face_id: usize, face: &Face, missing: u32) {
    let a = face_id / 2;
    let t = 1 - a; // tangential axis (2D)
    let n: i32 = if face_id.is_multiple_of(2) { 1 } else { -1 };
    let (mut sum_t, mut sum_o, mut mom_t) = (0.0, 0.0, 0.0);
    for i in 0..L::Q {
        let c = L::C[i];
        let v = f[i][0].to_f64();
        if c[a] == 0 {
            sum_t += v;
            mom_t += v * c[t] as f64;
        } else if c[a] == -n {
            sum_o += v;
        }
    }
    let (rho, u) = match *face {
        Face::Velocity { velocity } => {
            let ua = velocity[a];
            ((sum_t + 2.0 * sum_o) / (1.0 - n as f64 * ua), velocity)
        }
        Face::Pressure { rho } => {
            let mut u = [0.0; 3];
            u[a] = n as f64 * (1.0 - (sum_t + 2.0 * sum_o) / rho);
            (rho, u)
        }
        _ => return,
    };
    for i in 0..L::Q {
        if missing & (1 << i) == 0 {
            continue;
        }
        let c = L::C[i];
        let o = L::OPP[i];
        if c[a] != n {
            // an edge/corner population that is not this face's unknown: plain bounce-back
            f[i][0] = f[o][0];
            continue;
        }
        let cu = c[0] as f64 * u[0] + c[1] as f64 * u[1];
        let corr = -0.5 * c[t] as f64 * (mom_t - 2.0 / 3.0 * rho * u[t]);
        f[i][0] = T::from_f64(f[o][0].to_f64() + 6.0 * L::W[i] * rho * cu + corr);
    }
}
