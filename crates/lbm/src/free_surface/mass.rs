//! The mass exchange of the mass-tracking free surface (Leonardi et al. 2014 Eqs. 24-25,
//! after Körner et al. 2005).
//!
//! Along the link from x to its neighbour x + c_i, x gains f_ī(x + c_i, t) − f_i(x, t) (the
//! population coming in minus the one going out, both post-collision) times a weight α_i
//! (Eq. 25) set by the two node types. The weight is symmetric in the two nodes and the
//! difference is antisymmetric, so what x gains its neighbour loses, bit for bit: the total mass is
//! conserved to the round-off of the sum.
//!
//! Eq. 25 is written in the paper with the masses m_f of the two nodes; as in Körner et al. (2005)
//! it is their fill fractions ε = m/ρ that weight an interface-interface link here (½(ε(x) +
//! ε(x + c_i))): with masses the weight would carry the density (≈ 1, so the difference is of the
//! order of the compressibility error), with fills it is the fraction of the link's cross section
//! that is wet, and the weight is 1 in the liquid limit as the liquid-liquid weight is.

use super::cells::{INTERFACE, LIQUID};

/// α_i of Eq. 25 for a link between a node of type `a` with fill `fill_a` and a node of type `b`
/// with fill `fill_b`: 1 if both are liquid or one is liquid and the other interface, the mean
/// fill if both are interface, 0 if either is gas or a wall (no mass crosses).
#[inline]
pub fn link_weight(a: u8, fill_a: f64, b: u8, fill_b: f64) -> f64 {
    match (a, b) {
        (LIQUID, LIQUID) | (LIQUID, INTERFACE) | (INTERFACE, LIQUID) => 1.0,
        (INTERFACE, INTERFACE) => 0.5 * (fill_a + fill_b),
        _ => 0.0,
    }
}

/// The mass x gains along one link (Eq. 24, one term): α (f_in − f_out), with f_in the population
/// streaming into x from the neighbour and f_out the one x sends to it.
#[inline]
pub fn link_exchange(alpha: f64, f_in: f64, f_out: f64) -> f64 {
    alpha * (f_in - f_out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::free_surface::cells::{GAS, WALL};

    #[test]
    fn weights_are_symmetric_and_follow_eq_25() {
        let kinds = [GAS, INTERFACE, LIQUID, WALL];
        for &a in &kinds {
            for &b in &kinds {
                assert_eq!(link_weight(a, 0.3, b, 0.9), link_weight(b, 0.9, a, 0.3));
            }
        }
        assert_eq!(link_weight(INTERFACE, 0.25, INTERFACE, 0.75), 0.5);
        assert_eq!(link_weight(LIQUID, 1.0, INTERFACE, 0.1), 1.0);
        assert_eq!(link_weight(INTERFACE, 0.5, GAS, 0.0), 0.0);
        assert_eq!(link_weight(LIQUID, 1.0, WALL, 0.0), 0.0);
    }

    #[test]
    fn exchange_is_antisymmetric_bit_for_bit() {
        let (fa, fb) = (0.1234567891, 0.0987654321);
        let alpha = link_weight(INTERFACE, 0.37, INTERFACE, 0.81);
        assert_eq!(link_exchange(alpha, fa, fb), -link_exchange(alpha, fb, fa));
    }
}
