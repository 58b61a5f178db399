//! Nodes that moving grains cover and uncover in a free-surface run (Leonardi et al. 2014
//! Sect. 5.1: "fluid nodes are created (deleted) in the wake (front) of moving particles").
//!
//! A covered node ([`cover`]) becomes a [`GRAIN`] node: inactive, its links bounced back with the
//! grain's velocity (Eq. 19). The liquid it held leaves the lattice: its mass goes to the state's
//! `reservoir` (which the conversions share out over the interface, so the volume a grain takes
//! in the liquid raises the surface), and its populations' momentum is returned so the coupling
//! can give it to the grain.
//!
//! An uncovered node ([`uncover`]) becomes, in this order of rules,
//! - gas, when none of its neighbours is liquid or interface (the grain left it in the gas);
//! - interface with no mass, when one of them is gas (the liquid flows into it by the mass
//!   exchange; a liquid node must never touch gas);
//! - liquid otherwise, with m = ρ taken from the reservoir (the surface falls by the volume the
//!   grain left).
//!
//! A liquid or interface node gets the populations at the equilibrium (Eq. 13) of the mean density
//! and velocity of its liquid and interface neighbours, as the paper initialises them. So Σ m plus
//! the reservoir is kept to round-off whatever the grains do, and the momentum the liquid loses
//! or gains here is known exactly; the paper drops it ("small variations ... negligible"), the
//! coupling can instead hand it to the grains (Aidun, Lu & Ding 1998), so that liquid and grains
//! together conserve momentum.

use super::cells::{FreeSurface, GAS, GRAIN, INTERFACE, LIQUID, WALL};
use crate::lattice::Lattice;

/// Mass and population momentum Σ_i f_i c_i (lattice units) the liquid lost to a covering grain
/// ([`cover`]) or gained from an uncovering one ([`uncover`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Exchanged {
    pub mass: f64,
    pub momentum: [f64; 3],
}

/// Σ_i f_i c_i of node `x`.
fn momentum<L: Lattice>(s: &FreeSurface<L>, x: usize) -> [f64; 3] {
    let n = s.nodes();
    let mut p = [0.0; 3];
    for i in 1..L::Q {
        let f = s.f[i * n + x];
        for (a, pa) in p.iter_mut().enumerate() {
            *pa += f * L::C[i][a] as f64;
        }
    }
    p
}

/// Make node `x` a [`GRAIN`] node whose surface moves at `u_w` (lattice units); a grain node
/// only takes the new velocity. Walls of the domain stay walls (nothing is exchanged). Returns
/// what the liquid lost (module doc).
pub fn cover<L: Lattice>(s: &mut FreeSurface<L>, x: usize, u_w: [f64; 3]) -> Exchanged {
    let out = match s.cell[x] {
        WALL => return Exchanged::default(),
        LIQUID | INTERFACE => {
            let out = Exchanged {
                mass: s.mass[x],
                momentum: momentum(s, x),
            };
            s.reservoir += s.mass[x];
            out
        }
        _ => Exchanged::default(),
    };
    s.cell[x] = GRAIN;
    s.mass[x] = 0.0;
    s.solid_u[x] = u_w;
    out
}

/// Make the [`GRAIN`] node `x` gas, interface or liquid by the rules of the module doc; any
/// other node is left alone. Returns what the liquid gained.
pub fn uncover<L: Lattice>(s: &mut FreeSurface<L>, x: usize) -> Exchanged {
    if s.cell[x] != GRAIN {
        return Exchanged::default();
    }
    let (mut rho, mut u, mut wet, mut gas) = (0.0, [0.0; 3], 0usize, false);
    for j in s.neighbours(x) {
        match s.cell[j] {
            LIQUID | INTERFACE => {
                rho += s.rho[j];
                for (a, ua) in u.iter_mut().enumerate() {
                    *ua += s.u[j][a];
                }
                wet += 1;
            }
            GAS => gas = true,
            _ => {}
        }
    }
    s.solid_u[x] = [0.0; 3];
    if wet == 0 {
        s.cell[x] = GAS;
        s.mass[x] = 0.0;
        return Exchanged::default();
    }
    let inv = 1.0 / wet as f64;
    let (rho, u) = (rho * inv, u.map(|v| v * inv));
    s.set_equilibrium(x, rho, u);
    s.rho[x] = rho;
    s.u[x] = u;
    let mass = if gas { 0.0 } else { rho };
    s.cell[x] = if gas { INTERFACE } else { LIQUID };
    s.mass[x] = mass;
    s.reservoir -= mass;
    Exchanged {
        mass,
        momentum: momentum(s, x),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lattice::D3Q19;

    fn pool(n: [usize; 3], level: usize) -> FreeSurface<D3Q19> {
        // walls below and above, periodic in x and z
        let dom = crate::cases::poiseuille::channel_box(n);
        FreeSurface::<D3Q19>::new(dom, |p| {
            (if p[1] < level { 1.0 } else { 0.0 }, 1.0, [0.01, 0.0, 0.0])
        })
        .expect("valid pool")
    }

    #[test]
    fn covering_and_uncovering_keep_the_mass_and_return_the_momentum() {
        let mut s = pool([6, 10, 6], 5);
        let m0 = s.total_mass();
        let deep = s.domain.index(2, 1, 2);
        let lost = cover(&mut s, deep, [0.0, -0.02, 0.0]);
        assert_eq!(s.cell[deep], GRAIN);
        assert_eq!(lost.mass, 1.0);
        // at equilibrium with u = (0.01, 0, 0) and ρ = 1: momentum ρu
        assert!((lost.momentum[0] - 0.01).abs() < 1e-15 && lost.momentum[1].abs() < 1e-15);
        assert!(
            (s.total_mass() - m0).abs() < 1e-13,
            "{} against {m0}",
            s.total_mass()
        );
        let back = uncover(&mut s, deep);
        assert_eq!(s.cell[deep], LIQUID, "deep in the liquid it comes back liquid");
        assert_eq!(back.mass, 1.0);
        assert!((s.total_mass() - m0).abs() < 1e-13);
        // a node in the gas comes back gas, one under the surface with a gas neighbour interface
        let high = s.domain.index(2, 8, 2);
        cover(&mut s, high, [0.0; 3]);
        assert_eq!(uncover(&mut s, high), Exchanged::default());
        assert_eq!(s.cell[high], GAS);
        let top = s.domain.index(3, 5, 3);
        assert_eq!(s.cell[top], GAS);
        let under = s.domain.index(3, 4, 3);
        assert_eq!(s.cell[under], INTERFACE);
        cover(&mut s, under, [0.0; 3]);
        let back = uncover(&mut s, under);
        assert_eq!((s.cell[under], back.mass), (INTERFACE, 0.0));
        assert!((s.total_mass() - m0).abs() < 1e-13);
        assert!(s.open_interface().is_none());
    }
}
