//! Free-surface state as plain data (Leonardi et al. 2014 Sect. 5.2, Eq. 23): every node is
//! liquid, interface or gas (or a wall of the [`Domain`]), with a mass m and, for liquid and
//! interface nodes, populations. The fill fraction is ε = m/ρ: 1 in liquid, 0 in gas, between the
//! two at the interface.

use crate::LbmError;
use crate::collision::equilibrium;
use crate::domain::{Domain, FLUID};
use crate::lattice::Lattice;
use crate::plan::{Upstream, neighbour};
use std::marker::PhantomData;

/// Node type of the free surface (Eq. 23). Walls are the domain's solid and inactive nodes.
pub const GAS: u8 = 0;
pub const INTERFACE: u8 = 1;
pub const LIQUID: u8 = 2;
/// Solid or inactive node of the domain: bounce-back, no mass.
pub const WALL: u8 = 3;
/// Node inside a moving grain (Leonardi et al. 2014 Sect. 5.1): inactive like a wall, but links
/// into it bounce back with the grain's local velocity (Eq. 19), kept in `FreeSurface::solid_u`.
/// Nodes become and stop being grain nodes through [`super::solids`].
pub const GRAIN: u8 = 4;

/// The state of a free-surface run: all a step reads besides the settings, so a clone (or a
/// serde round trip) continues the run bit for bit.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound = "")]
pub struct FreeSurface<L: Lattice> {
    pub domain: Domain,
    /// Post-collision populations of the current time, `f[i * n + node]` (meaningless on gas
    /// and wall nodes).
    pub f: Vec<f64>,
    /// [`GAS`], [`INTERFACE`], [`LIQUID`], [`WALL`] or [`GRAIN`] per node.
    pub cell: Vec<u8>,
    /// Mass m per node (Eq. 23): ρ on liquid nodes, 0 < m < ρ on interface nodes, 0 on gas.
    pub mass: Vec<f64>,
    /// Density and velocity of the last collision (u = (Σ f c + F/2)/ρ, Leonardi Eq. 17) per
    /// node: the interface velocity of the reconstruction (Eq. 26) and of new interface nodes.
    pub rho: Vec<f64>,
    pub u: Vec<[f64; 3]>,
    /// Velocity of the grain surface at each [`GRAIN`] node (Leonardi Eq. 20, lattice units):
    /// what links into the node bounce back with (Eq. 19). Not read at other nodes.
    pub solid_u: Vec<[f64; 3]>,
    /// Excess mass of conversions that found no interface neighbour to take it (kept here so the
    /// total stays exact; normally zero).
    pub reservoir: f64,
    /// Completed steps.
    pub step: u64,
    #[serde(skip)]
    _l: PhantomData<L>,
}

impl<L: Lattice> FreeSurface<L> {
    /// Fill the fluid nodes of `domain` from `init(node) = (ε, ρ, u)`: ε = 1 liquid, 0 < ε < 1
    /// interface, ε = 0 gas, populations at equilibrium (Leonardi Eq. 13) and m = ε ρ. A liquid
    /// node with a gas neighbour becomes an interface node with ε = 1, so the interface is closed
    /// from the start (no liquid node touches a gas node). Refuses ε outside [0, 1] or ρ ≤ 0.
    pub fn new(domain: Domain, init: impl Fn([usize; 3]) -> (f64, f64, [f64; 3])) -> Result<Self, LbmError> {
        let n = domain.len();
        let mut s = Self {
            f: vec![0.0; L::Q * n],
            cell: vec![GAS; n],
            mass: vec![0.0; n],
            rho: vec![1.0; n],
            u: vec![[0.0; 3]; n],
            solid_u: vec![[0.0; 3]; n],
            reservoir: 0.0,
            step: 0,
            domain,
            _l: PhantomData,
        };
        for idx in 0..n {
            let p = s.domain.coords(idx);
            if s.domain.kind[idx] != FLUID {
                s.cell[idx] = WALL;
                continue;
            }
            let (fill, rho, u) = init(p);
            if !(0.0..=1.0).contains(&fill) {
                return Err(LbmError::FreeSurface(format!(
                    "fill fraction ε = {fill} at node {p:?} is outside [0, 1] (Leonardi et al. 2014 \
                     Eq. 23: 1 liquid, 0 gas, between at the interface); give a fill in [0, 1]"
                )));
            }
            if !(rho.is_finite() && rho > 0.0) || u.iter().any(|v| !v.is_finite()) {
                return Err(LbmError::FreeSurface(format!(
                    "density {rho} or velocity {u:?} at node {p:?} is not finite and positive; give \
                     ρ > 0 (lattice units, about 1) and a finite velocity"
                )));
            }
            s.cell[idx] = if fill == 1.0 {
                LIQUID
            } else if fill > 0.0 {
                INTERFACE
            } else {
                GAS
            };
            s.mass[idx] = fill * rho;
            s.rho[idx] = rho;
            s.u[idx] = u;
            s.set_equilibrium(idx, rho, u);
        }
        for idx in 0..n {
            if s.cell[idx] == LIQUID && s.neighbours(idx).any(|j| s.cell[j] == GAS) {
                s.cell[idx] = INTERFACE;
            }
        }
        Ok(s)
    }

    pub fn nodes(&self) -> usize {
        self.domain.len()
    }

    /// Populations of node `idx` at the equilibrium of (ρ, u).
    pub fn set_equilibrium(&mut self, idx: usize, rho: f64, u: [f64; 3]) {
        let n = self.nodes();
        let feq = equilibrium::<L>(rho, u);
        for i in 0..L::Q {
            self.f[i * n + idx] = feq[i];
        }
    }

    /// The lattice neighbours x + c_i (i ≥ 1) of node `idx` inside the box (periodic faces
    /// wrapped; none across a wall face).
    pub fn neighbours(&self, idx: usize) -> impl Iterator<Item = usize> + '_ {
        let p = self.domain.coords(idx);
        (1..L::Q).filter_map(move |i| match neighbour(&self.domain, p, L::C[i]) {
            Upstream::Node(j) => Some(j),
            Upstream::Face(_) => None,
        })
    }

    /// Fill fraction ε = m/ρ of node `idx` (Eq. 23): 1 on liquid, 0 on gas, walls and grains.
    pub fn fill(&self, idx: usize) -> f64 {
        match self.cell[idx] {
            LIQUID => 1.0,
            INTERFACE => self.mass[idx] / self.rho[idx],
            _ => 0.0,
        }
    }

    /// Total mass: Σ m over liquid and interface nodes plus the reservoir (the quantity the
    /// mass tracking conserves to round-off).
    pub fn total_mass(&self) -> f64 {
        let placed: f64 = self
            .cell
            .iter()
            .zip(&self.mass)
            .filter(|(c, _)| matches!(**c, LIQUID | INTERFACE))
            .map(|(_, m)| m)
            .sum();
        placed + self.reservoir
    }

    /// A liquid node that touches a gas node, with that gas node, if any: the interface is
    /// then not closed (it must never happen, Leonardi et al. 2014 Sect. 5.2).
    pub fn open_interface(&self) -> Option<([usize; 3], [usize; 3])> {
        (0..self.nodes())
            .filter(|&i| self.cell[i] == LIQUID)
            .find_map(|i| {
                self.neighbours(i)
                    .find(|&j| self.cell[j] == GAS)
                    .map(|j| (self.domain.coords(i), self.domain.coords(j)))
            })
    }

    /// Count of nodes of type `kind`.
    pub fn count(&self, kind: u8) -> usize {
        self.cell.iter().filter(|&&c| c == kind).count()
    }
}
