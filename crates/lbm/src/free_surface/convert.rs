//! Node conversions of the mass-tracking free surface (Leonardi et al. 2014 Sect. 5.2, after
//! Körner et al. 2005), run after every stream-collide-exchange sweep.
//!
//! An interface node is *filled* when m > (1 + κ) ρ and *emptied* when m < −κ ρ (the paper's
//! m = ρ and m = 0, with the small margin κ of Körner et al. that stops nodes from flipping back
//! and forth on round-off). An interface node with no liquid or interface neighbour (a droplet of
//! one node, left behind by a splash) is emptied whatever its mass: alone it cannot move (mass
//! only crosses links to liquid and interface nodes) while gravity keeps accelerating its
//! populations, so it would stop the run at the Mach limit (seen in the dam break before this
//! rule). **Lonely nodes** (optional, a threshold θ > 0; Thürey 2007, as OpenLB has it): an interface node with no liquid neighbour is emptied already below m = θρ, and one
//! with no gas neighbour filled above m = (1 − θ)ρ. A film or a falling sheet one node thick is
//! made of interface nodes only; mass crosses between them in proportion to their fills, so a node
//! drained to a small fill keeps its populations, and gravity goes on accelerating them until the
//! Mach limit (the incline's coarse lattices, docs/free_surface.md). Then, in this order,
//! sequentially in node order (deterministic):
//! 1. every gas neighbour of a filled node becomes a new interface node (m = 0) with the
//!    populations at the equilibrium of the mean (ρ, u) of its liquid and interface neighbours
//!    (Leonardi Eq. 13; Sect. 5.1 initialises nodes uncovered by grains the same way); an interface
//!    node about to be emptied next to a filled node stays interface instead (otherwise the
//!    filled node would touch gas);
//! 2. every liquid neighbour of an emptied node becomes interface (its mass stays, ε ≈ 1);
//! 3. filled nodes become liquid with m = ρ, emptied nodes gas with m = 0, and the excess mass
//!    (m − ρ, respectively m) is shared **equally** among the interface neighbours the node has
//!    after the conversions. Equal shares are the paper's rule ("the surplus of mass is equally
//!    distributed to the neighboring interface nodes"); Körner et al. weight them by the surface
//!    normal instead, which moves the excess towards the gas (fill) or the liquid (empty) and
//!    needs the fill gradient. Either conserves mass; the equal rule needs no normal, so it is the
//!    same in 2D and 3D and on a one-node-thick film. A node with no interface neighbour left puts
//!    its excess into the state's `reservoir`;
//! 4. the reservoir, if not empty, is shared equally among all interface nodes (node order), so
//!    mass lost to droplets returns to the liquid at its surface and the total Σ m stays exact to
//!    round-off.

use super::cells::{FreeSurface, GAS, INTERFACE, LIQUID};
use super::stepper::NONE;
use crate::lattice::Lattice;

/// What the conversions of one step did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Conversions {
    pub filled: usize,
    pub emptied: usize,
    /// Gas nodes that became interface.
    pub new_interface: usize,
    /// Excess mass put into the reservoir this step.
    pub to_reservoir: f64,
    /// Interface nodes before the conversions.
    pub interface: usize,
}

/// Scratch lists of the conversions (reused from step to step).
#[derive(Clone, Debug, Default)]
pub struct ConvertScratch {
    filled: Vec<usize>,
    emptied: Vec<usize>,
    new_interface: Vec<usize>,
    /// Liquid nodes that became interface beside an emptied one.
    demoted: Vec<usize>,
    /// Per node: 1 filled, 2 emptied, 4 new interface.
    flag: Vec<u8>,
}

impl ConvertScratch {
    /// Every node the last [`convert`] changed, as (node, kind before, kind after).
    pub fn changes(&self) -> impl Iterator<Item = (usize, u8, u8)> + '_ {
        self.filled
            .iter()
            .map(|&x| (x, INTERFACE, LIQUID))
            .chain(self.emptied.iter().map(|&x| (x, INTERFACE, GAS)))
            .chain(self.new_interface.iter().map(|&x| (x, GAS, INTERFACE)))
            .chain(self.demoted.iter().map(|&x| (x, LIQUID, INTERFACE)))
    }
}

const FILL: u8 = 1;
const EMPTY: u8 = 2;
const NEW: u8 = 4;

/// The neighbours x + c_i (i ≥ 1) of `x` from the link table (`links[i * n + x]`, [`NONE`]
/// across a wall face).
fn nbrs<L: Lattice>(links: &[u32], n: usize, x: usize) -> impl Iterator<Item = usize> + '_ {
    (1..L::Q).filter_map(move |i| {
        let j = links[i * n + x];
        (j != NONE).then_some(j as usize)
    })
}

/// Convert the interface nodes of `s` whose mass left (−κρ, (1 + κ)ρ) (module doc).
pub fn convert<L: Lattice>(
    s: &mut FreeSurface<L>,
    links: &[u32],
    kappa: f64,
    lonely: f64,
    scratch: &mut ConvertScratch,
) -> Conversions {
    let n = s.nodes();
    let sc = scratch;
    sc.filled.clear();
    sc.emptied.clear();
    sc.new_interface.clear();
    sc.demoted.clear();
    sc.flag.clear();
    sc.flag.resize(n, 0);
    let mut interface = 0;
    for x in 0..n {
        if s.cell[x] != INTERFACE {
            continue;
        }
        interface += 1;
        let isolated = !nbrs::<L>(links, n, x).any(|j| matches!(s.cell[j], LIQUID | INTERFACE));
        let (mut fill_lonely, mut empty_lonely) = (false, false);
        if lonely > 0.0 {
            let (m, rho) = (s.mass[x], s.rho[x]);
            fill_lonely = m > (1.0 - lonely) * rho && !nbrs::<L>(links, n, x).any(|j| s.cell[j] == GAS);
            empty_lonely = m < lonely * rho && !nbrs::<L>(links, n, x).any(|j| s.cell[j] == LIQUID);
        }
        if s.mass[x] > (1.0 + kappa) * s.rho[x] || fill_lonely {
            sc.filled.push(x);
            sc.flag[x] = FILL;
        } else if s.mass[x] < -kappa * s.rho[x] || isolated || empty_lonely {
            sc.emptied.push(x);
            sc.flag[x] = EMPTY;
        }
    }
    let mut out = Conversions {
        interface,
        ..Conversions::default()
    };
    if sc.filled.is_empty() && sc.emptied.is_empty() {
        spread_reservoir(s);
        return out;
    }
    // 1. gas neighbours of filled nodes become interface; emptied neighbours stay interface
    for &x in &sc.filled {
        for j in nbrs::<L>(links, n, x) {
            if s.cell[j] == GAS && sc.flag[j] & NEW == 0 {
                sc.flag[j] |= NEW;
                sc.new_interface.push(j);
            } else if sc.flag[j] == EMPTY {
                sc.flag[j] = 0;
            }
        }
    }
    for &x in &sc.filled {
        s.cell[x] = LIQUID;
    }
    for &j in &sc.new_interface {
        let (mut rho, mut u, mut k) = (0.0, [0.0; 3], 0usize);
        for m in nbrs::<L>(links, n, j) {
            if matches!(s.cell[m], LIQUID | INTERFACE) && sc.flag[m] & NEW == 0 {
                rho += s.rho[m];
                for a in 0..3 {
                    u[a] += s.u[m][a];
                }
                k += 1;
            }
        }
        // k >= 1: the filled node that made j is a liquid neighbour
        let inv = 1.0 / k as f64;
        let (rho, u) = (rho * inv, u.map(|v| v * inv));
        s.set_equilibrium(j, rho, u);
        s.rho[j] = rho;
        s.u[j] = u;
        s.mass[j] = 0.0;
    }
    for &j in &sc.new_interface {
        s.cell[j] = INTERFACE;
    }
    // 2. liquid neighbours of emptied nodes become interface
    sc.emptied.retain(|&x| sc.flag[x] == EMPTY);
    for &x in &sc.emptied {
        for j in nbrs::<L>(links, n, x) {
            if s.cell[j] == LIQUID {
                s.cell[j] = INTERFACE;
                sc.demoted.push(j);
            }
        }
        s.cell[x] = GAS;
    }
    // 3. excess mass to the interface neighbours, equal shares
    let mut reservoir = 0.0;
    let mut share = |s: &mut FreeSurface<L>, x: usize, excess: f64| {
        let k = nbrs::<L>(links, n, x).filter(|&j| s.cell[j] == INTERFACE).count();
        if k == 0 {
            reservoir += excess;
            return;
        }
        let part = excess / k as f64;
        for j in nbrs::<L>(links, n, x) {
            if s.cell[j] == INTERFACE {
                s.mass[j] += part;
            }
        }
    };
    for &x in &sc.filled {
        let excess = s.mass[x] - s.rho[x];
        s.mass[x] = s.rho[x];
        share(s, x, excess);
    }
    for &x in &sc.emptied {
        let excess = s.mass[x];
        s.mass[x] = 0.0;
        share(s, x, excess);
    }
    s.reservoir += reservoir;
    spread_reservoir(s);
    out.filled = sc.filled.len();
    out.emptied = sc.emptied.len();
    out.new_interface = sc.new_interface.len();
    out.to_reservoir = reservoir;
    out
}

/// Give the reservoir back to the liquid: equal shares to every interface node (node order),
/// when there is one; otherwise it waits in the reservoir.
fn spread_reservoir<L: Lattice>(s: &mut FreeSurface<L>) {
    if s.reservoir == 0.0 {
        return;
    }
    let k = s.cell.iter().filter(|&&c| c == INTERFACE).count();
    if k == 0 {
        return;
    }
    let part = s.reservoir / k as f64;
    for (c, m) in s.cell.iter().zip(s.mass.iter_mut()) {
        if *c == INTERFACE {
            *m += part;
        }
    }
    s.reservoir = 0.0;
}
