//! Populations streaming from gas nodes (Leonardi et al. 2014 Eq. 26, after Körner et al. 2005).
//!
//! Gas nodes carry no populations. An interface node x whose neighbour x − c_i is gas would pull
//! f_i from it; instead it takes
//!
//! f_i(x, t + 1) = f_i^eq(ρ_A, u) + f_ī^eq(ρ_A, u) − f_ī(x, t),
//!
//! with ρ_A the atmospheric density (the gas pressure p_A = c_s² ρ_A), u the velocity of x
//! and f_ī(x, t) the post-collision population x sends towards the gas. The pair (f_i, f_ī)
//! then sums to the equilibrium pair at (ρ_A, u): the gas imposes its pressure and moves with the
//! interface (Sect. 5.2: "gas nodes have the same macroscopic velocity as the connected
//! interface nodes").

use crate::lattice::{Lattice, QMAX};

/// Equilibria f^eq(ρ_A, u) of one interface node (Leonardi Eq. 13), computed once per node.
#[inline]
pub fn atmosphere<L: Lattice>(rho_a: f64, u: [f64; 3]) -> [f64; QMAX] {
    crate::collision::equilibrium::<L>(rho_a, u)
}

/// f_i of Eq. 26 from the atmosphere's equilibria `feq` and the outgoing f_ī (`f_out`).
#[inline]
pub fn from_gas<L: Lattice>(feq: &[f64; QMAX], i: usize, f_out: f64) -> f64 {
    feq[i] + feq[L::OPP[i]] - f_out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::D2Q9;

    #[test]
    fn a_node_at_equilibrium_with_the_atmosphere_is_unchanged() {
        let u = [0.01, -0.02, 0.0];
        let feq = atmosphere::<D2Q9>(1.0, u);
        for i in 1..9 {
            let o = D2Q9::OPP[i];
            assert!((from_gas::<D2Q9>(&feq, i, feq[o]) - feq[i]).abs() < 1e-16);
        }
    }
}
