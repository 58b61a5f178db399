//! Velocity sets: D2Q9 (Su et al. 2020 Eq. 8) and D3Q19 (Leonardi et al. 2014 Eq. 14) behind
//! one trait of constants, so that every kernel is written once and monomorphised per lattice.

use crate::compiled::Compiled;

/// A discrete velocity set. Directions come in opposite pairs: `C[OPP[i]] == -C[i]`, direction 0
/// is the rest population, and `HALF` lists one direction of every moving pair (used by the TRT
/// split into symmetric and antisymmetric parts).
/// [`Compiled`] holds the concrete steps of each lattice (compiled in this crate).
pub trait Lattice: Compiled + Copy + Send + Sync + Default + 'static {
    const NAME: &'static str;
    /// Spatial dimension (2 or 3).
    const D: usize;
    /// Number of velocities.
    const Q: usize;
    /// Velocities in lattice units, always three components (z = 0 in 2D).
    const C: &'static [[i32; 3]];
    /// Weights w_i.
    const W: &'static [f64];
    /// Opposite direction of each direction.
    const OPP: &'static [usize];
    /// One direction of each opposite pair (never 0).
    const HALF: &'static [usize];
}

/// Squared lattice sound speed c_s^2 = 1/3 (both lattices).
pub const CS2: f64 = 1.0 / 3.0;

/// The largest Q of the supported lattices (size of stack scratch).
pub const QMAX: usize = 19;

/// D2Q9, numbered as in Su et al. (2020) Eq. 8: 1-4 axis directions counter-clockwise from +x,
/// 5-8 diagonals counter-clockwise from (+1,+1).
#[derive(Clone, Copy, Debug, Default)]
pub struct D2Q9;

impl Lattice for D2Q9 {
    const NAME: &'static str = "D2Q9";
    const D: usize = 2;
    const Q: usize = 9;
    const C: &'static [[i32; 3]] = &[
        [0, 0, 0],
        [1, 0, 0],
        [0, 1, 0],
        [-1, 0, 0],
        [0, -1, 0],
        [1, 1, 0],
        [-1, 1, 0],
        [-1, -1, 0],
        [1, -1, 0],
    ];
    const W: &'static [f64] = &[
        4.0 / 9.0,
        1.0 / 9.0,
        1.0 / 9.0,
        1.0 / 9.0,
        1.0 / 9.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
    ];
    const OPP: &'static [usize] = &[0, 3, 4, 1, 2, 7, 8, 5, 6];
    const HALF: &'static [usize] = &[1, 2, 5, 6];
}

/// D3Q19 (Leonardi et al. 2014 Fig. 2 and Eq. 14): rest, 6 axis, 12 edge-diagonal directions.
#[derive(Clone, Copy, Debug, Default)]
pub struct D3Q19;

impl Lattice for D3Q19 {
    const NAME: &'static str = "D3Q19";
    const D: usize = 3;
    const Q: usize = 19;
    const C: &'static [[i32; 3]] = &[
        [0, 0, 0],
        [1, 0, 0],
        [-1, 0, 0],
        [0, 1, 0],
        [0, -1, 0],
        [0, 0, 1],
        [0, 0, -1],
        [1, 1, 0],
        [-1, -1, 0],
        [1, -1, 0],
        [-1, 1, 0],
        [1, 0, 1],
        [-1, 0, -1],
        [1, 0, -1],
        [-1, 0, 1],
        [0, 1, 1],
        [0, -1, -1],
        [0, 1, -1],
        [0, -1, 1],
    ];
    const W: &'static [f64] = &[
        1.0 / 3.0,
        1.0 / 18.0,
        1.0 / 18.0,
        1.0 / 18.0,
        1.0 / 18.0,
        1.0 / 18.0,
        1.0 / 18.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
        1.0 / 36.0,
    ];
    const OPP: &'static [usize] = &[0, 2, 1, 4, 3, 6, 5, 8, 7, 10, 9, 12, 11, 14, 13, 16, 15, 18, 17];
    const HALF: &'static [usize] = &[1, 3, 5, 7, 9, 11, 13, 15, 17];
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check<L: Lattice>() {
        assert_eq!(L::C.len(), L::Q);
        assert_eq!(L::W.len(), L::Q);
        let wsum: f64 = L::W.iter().sum();
        assert!((wsum - 1.0).abs() < 1e-15);
        for i in 0..L::Q {
            let o = L::OPP[i];
            for a in 0..3 {
                assert_eq!(L::C[o][a], -L::C[i][a]);
            }
            assert_eq!(L::W[o], L::W[i]);
        }
        // isotropy: sum w c_a c_b = cs2 delta_ab
        for a in 0..3 {
            for b in 0..3 {
                let s: f64 = (0..L::Q)
                    .map(|i| L::W[i] * (L::C[i][a] * L::C[i][b]) as f64)
                    .sum();
                let want = if a == b && a < L::D { CS2 } else { 0.0 };
                assert!((s - want).abs() < 1e-15, "{} {a}{b}", L::NAME);
            }
        }
        assert_eq!(2 * L::HALF.len() + 1, L::Q);
        let mut seen = vec![false; L::Q];
        for &h in L::HALF {
            seen[h] = true;
            seen[L::OPP[h]] = true;
        }
        assert!(seen[1..].iter().all(|&s| s));
    }

    #[test]
    fn velocity_sets_are_consistent() {
        check::<D2Q9>();
        check::<D3Q19>();
    }
}
