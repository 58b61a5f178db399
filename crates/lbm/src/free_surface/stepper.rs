//! The free-surface step (Leonardi et al. 2014 Sect. 5.2): per node, gather the populations
//! (pull streaming; bounce-back at walls, Eq. 26 from gas), add up the mass exchange of Eqs.
//! 24-25, collide (any [`Collider`]: BGK, TRT, or the Bingham collider with its local τ) with
//! gravity as a Guo body force (Leonardi Eqs. 15-17); then convert the interface nodes whose
//! mass left the band ([`convert`]).
//!
//! Each node writes only its own populations, mass and moments and reads only the previous state
//! (a gather, not a scatter), so the sweep is independent of the order nodes are visited in: it
//! runs in blocks of nodes on rayon's threads, and the conversions run sequentially in node
//! order, so a run gives the same bits on any number of threads.

use super::cells::{FreeSurface, GAS, GRAIN, INTERFACE, LIQUID, WALL};
use super::convert::{Conversions, ConvertScratch, convert};
use super::creep::ClampCreep;
use super::flips::FlipFlops;
use super::mass::{link_exchange, link_weight};
use super::reconstruct::{atmosphere, from_gas};
use crate::LbmError;
use crate::bingham::{Bingham, BinghamRates};
use crate::collision::{CollideParams, Collider};
use crate::diagnosis::BadNode;
use crate::domain::Face;
use crate::kernel::SyncPtr;
use crate::lattice::{Lattice, QMAX};
use crate::plan::{Upstream, neighbour};
use crate::stepper::Settings;
use rayon::prelude::*;
use std::marker::PhantomData;

/// No neighbour (across a wall face) in the link table.
pub const NONE: u32 = u32::MAX;

/// Parameters of the free surface.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct FreeSurfaceParams {
    /// Atmospheric density ρ_A of Eq. 26 (the gas pressure is c_s² ρ_A): 1, the reference
    /// density of the liquid, so that the pressure is hydrostatic relative to the gas.
    pub rho_atm: f64,
    /// Conversion margin κ (module `convert`): interface nodes fill at m > (1 + κ)ρ and empty
    /// at m < −κρ. Körner et al. (2005) use 1e-3.
    pub kappa: f64,
    /// Lonely-node threshold θ (module `convert`; 0: off, the paper's rules): an interface node
    /// with no liquid neighbour empties below m = θρ, one with no gas neighbour fills above
    /// m = (1 − θ)ρ (Thürey 2007; OpenLB's LONELY_THRESHOLD). The coarse inclines use 1.
    #[serde(default)]
    pub lonely: f64,
}

impl Default for FreeSurfaceParams {
    fn default() -> Self {
        Self {
            rho_atm: 1.0,
            kappa: 1e-3,
            lonely: 0.0,
        }
    }
}

/// Scratch and the step loop of a free-surface run.
pub struct FreeSurfaceStepper<L: Lattice> {
    settings: Settings,
    params: FreeSurfaceParams,
    coll: CollideParams<f64>,
    bingham: Option<BinghamRates<f64>>,
    /// x + c_i of every node, `links[i * n + x]`, [`NONE`] across a wall face.
    links: Vec<u32>,
    f_new: Vec<f64>,
    mass_new: Vec<f64>,
    rho_new: Vec<f64>,
    u_new: Vec<[f64; 3]>,
    scratch: ConvertScratch,
    /// τ of the last Bingham collision per node, when recording (`record_tau`).
    tau: Option<Vec<f64>>,
    /// The creep of the paste at τ_max (`monitor_creep`).
    creep: Option<ClampCreep>,
    /// Cells converting back and forth (always counted: the failure diagnosis reads it).
    flips: FlipFlops,
    _l: PhantomData<L>,
}

impl<L: Lattice> FreeSurfaceStepper<L> {
    /// Check the settings and the box. Faces must be periodic or stationary walls (moving walls
    /// and Zou-He faces are not done with a free surface); solid nodes of the domain are
    /// stationary walls, [`GRAIN`] nodes moving ones.
    pub fn new(s: &FreeSurface<L>, settings: Settings, params: FreeSurfaceParams) -> Result<Self, LbmError> {
        let coll = CollideParams::<f64>::new(&settings.collision, settings.force)?;
        if !(params.rho_atm.is_finite() && params.rho_atm > 0.0) {
            return Err(LbmError::FreeSurface(format!(
                "atmospheric density rho_atm = {} must be finite and > 0 (Leonardi et al. 2014 Eq. 26); \
                 use 1, the reference density",
                params.rho_atm
            )));
        }
        if !(params.kappa.is_finite() && (0.0..0.1).contains(&params.kappa)) {
            return Err(LbmError::FreeSurface(format!(
                "conversion margin kappa = {} must be in [0, 0.1); Körner et al. (2005) use 1e-3",
                params.kappa
            )));
        }
        if !(params.lonely.is_finite() && (0.0..=1.0).contains(&params.lonely)) {
            return Err(LbmError::FreeSurface(format!(
                "lonely-node threshold lonely = {} must be in [0, 1]; 0 is off (the paper's rules), the coarse inclines use 1",
                params.lonely
            )));
        }
        let dom = &s.domain;
        if (L::D == 2) != (dom.n[2] == 1) {
            return Err(LbmError::Unsupported(format!(
                "lattice {} on a box of {:?} nodes: use nz = 1 with D2Q9 and nz > 1 with D3Q19",
                L::NAME,
                dom.n
            )));
        }
        for (k, fc) in dom.faces.iter().enumerate() {
            let ok = match fc {
                Face::Periodic => dom.faces[k ^ 1].is_periodic(),
                Face::Wall { velocity } => {
                    velocity.iter().all(|&v| v == 0.0) && !dom.faces[k ^ 1].is_periodic()
                }
                _ => false,
            };
            if !ok {
                return Err(LbmError::Unsupported(format!(
                    "face {k} is {fc:?} (opposite {:?}): a free-surface run takes periodic pairs or \
                     stationary walls only",
                    dom.faces[k ^ 1]
                )));
            }
        }
        let n = s.nodes();
        let mut links = vec![NONE; L::Q * n];
        for x in 0..n {
            let p = dom.coords(x);
            for i in 0..L::Q {
                if let Upstream::Node(j) = neighbour(dom, p, L::C[i]) {
                    links[i * n + x] = j as u32;
                }
            }
        }
        Ok(Self {
            settings,
            params,
            coll,
            bingham: None,
            links,
            f_new: vec![0.0; s.f.len()],
            mass_new: vec![0.0; n],
            rho_new: vec![0.0; n],
            u_new: vec![[0.0; 3]; n],
            scratch: ConvertScratch::default(),
            tau: None,
            creep: None,
            flips: FlipFlops::new(n),
            _l: PhantomData,
        })
    }

    /// Bingham plastic rheology (local τ per node, `bingham`) from the next step on, or the
    /// settings' uniform τ (`None`).
    pub fn set_bingham(&mut self, bingham: Option<Bingham>) -> Result<(), LbmError> {
        if bingham.is_some() && self.tau.is_none() {
            // recorded whenever the rheology is on: the failure diagnosis reads it
            self.tau = Some(vec![f64::NAN; self.f_new.len() / L::Q]);
        }
        self.bingham = match bingham {
            Some(b) => Some(BinghamRates::new(
                &b,
                &self.settings.collision,
                self.settings.force,
            )?),
            None => None,
        };
        Ok(())
    }

    /// Record the local relaxation time of every liquid and interface node at each step of a
    /// Bingham run ([`Self::tau`]; Leonardi et al. 2014 Fig. 8 plots the viscosity it gives and
    /// stops the incline when 95 % of the liquid is at τ_max). On from `set_bingham` (the
    /// failure diagnosis reads it); `false` stops it, unless the creep monitor reads it
    /// ([`Self::monitor_creep`]), which keeps it on until the monitor is stopped.
    pub fn record_tau(&mut self, on: bool, nodes: usize) {
        self.tau = (on || self.creep.is_some()).then(|| vec![f64::NAN; nodes]);
    }

    /// Measure the creep of the paste held at τ_max every `every` steps of a Bingham run
    /// ([`ClampCreep`]: the Bingham clamp at low shear rate, an accuracy failure no blow-up
    /// shows); `None` stops it. Starts τ recording (the monitor reads it).
    pub fn monitor_creep(&mut self, every: Option<u64>) {
        self.creep = every.map(ClampCreep::new);
        if every.is_some() && self.tau.is_none() {
            self.tau = Some(vec![f64::NAN; self.f_new.len() / L::Q]);
        }
    }

    /// The creep monitor, if on (for the series, the checkpoint and the end-of-run warning).
    pub fn creep(&self) -> Option<&ClampCreep> {
        self.creep.as_ref()
    }

    /// Put back a monitor's state from a checkpoint (kept off when the monitor is off).
    pub fn restore_creep(&mut self, state: ClampCreep) {
        if self.creep.is_some() {
            self.creep = Some(state);
        }
    }

    /// The flip counter ([`FlipFlops`]: cells converting back and forth at the surface).
    pub fn flips(&self) -> &FlipFlops {
        &self.flips
    }

    /// Put back a flip counter from a checkpoint (one of the same box).
    pub fn restore_flips(&mut self, state: FlipFlops) {
        self.flips = state;
    }

    /// The surface named as flip-flopping, when its rate over the run passed
    /// [`super::flips::FLIP_LIMIT`].
    pub fn flip_warning(&self) -> Option<String> {
        FlipFlops::describe(self.flips.rate(), self.params.kappa, self.params.lonely)
    }

    /// The creep of the paste at τ_max named, when it passed [`super::creep::CREEP_LIMIT`].
    pub fn creep_warning(&self) -> Option<String> {
        let b = self.bingham.as_ref()?;
        self.creep.as_ref()?.warning(1.0 / b.omega_lo)
    }

    /// τ per node of the last step (NaN where no Bingham collision ran since recording began),
    /// if recording.
    pub fn tau(&self) -> Option<&[f64]> {
        self.tau.as_deref()
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    pub fn params(&self) -> &FreeSurfaceParams {
        &self.params
    }

    /// The link table: x + c_i at `links()[i * n + x]`, [`NONE`] across a wall face.
    pub fn links(&self) -> &[u32] {
        &self.links
    }

    /// Advance one step; the conversions it made. Stops with a diagnosis at the first liquid or
    /// interface node outside `settings.limits`.
    pub fn step(&mut self, s: &mut FreeSurface<L>) -> Result<Conversions, LbmError> {
        let forced = self.settings.force.iter().any(|&v| v != 0.0);
        let mut bingham = self.bingham;
        if let (Some(b), Some(t)) = (bingham.as_mut(), self.tau.as_mut())
            && t.len() == s.nodes()
        {
            b.tau = Some(SyncPtr(t.as_mut_ptr()));
        }
        let (bad, from_walls) = match (bingham, forced) {
            (Some(b), true) => self.sweep::<_, true>(s, &b),
            (Some(b), false) => self.sweep::<_, false>(s, &b),
            (None, true) => self.sweep::<_, true>(s, &self.coll.clone()),
            (None, false) => self.sweep::<_, false>(s, &self.coll.clone()),
        };
        // what moving grain walls pushed into (or drew from) the liquid's populations, booked
        // in m at the nodes beside them, comes out of the reservoir: Σ m + reservoir is kept
        s.reservoir -= from_walls;
        std::mem::swap(&mut s.f, &mut self.f_new);
        std::mem::swap(&mut s.mass, &mut self.mass_new);
        std::mem::swap(&mut s.rho, &mut self.rho_new);
        std::mem::swap(&mut s.u, &mut self.u_new);
        s.step += 1;
        if let Some(x) = bad {
            return Err(self.diagnose(s, x));
        }
        let conversions = convert(
            s,
            &self.links,
            self.params.kappa,
            self.params.lonely,
            &mut self.scratch,
        );
        for (x, from, to) in self.scratch.changes() {
            self.flips.record(s.step, x, from, to);
        }
        self.flips.end_step(s.step, conversions.interface);
        if let (Some(c), Some(b), Some(t)) = (self.creep.as_mut(), &bingham, &self.tau)
            && s.step.is_multiple_of(c.every)
            && t.len() == s.nodes()
        {
            c.sample(
                |x| matches!(s.cell[x], LIQUID | INTERFACE),
                |x| s.fill(x),
                t,
                1.0 / b.omega_lo,
            );
        }
        Ok(conversions)
    }

    /// The failure at node `x`, named (issue 20 item 6): the engine's cause (τ near ½, Mach,
    /// density) with the node's own τ, and whether it sits at the free surface (an interface node
    /// or next to one: a falling or spreading front) and, with the Bingham rheology, whether its τ
    /// was at the floor τ_min (fast shear: the clamp's high-shear end) or at τ_max.
    fn diagnose(&self, s: &FreeSurface<L>, x: usize) -> LbmError {
        let local = self.tau.as_ref().map(|t| t[x]).filter(|t| t.is_finite());
        let tau = match (&self.bingham, local) {
            (Some(_), Some(t)) => t,
            (Some(b), None) => 1.0 / b.omega_hi,
            (None, _) => self.settings.collision.tau(),
        };
        let mut err = BadNode {
            step: s.step,
            node: s.domain.coords(x),
            rho: s.rho[x],
            u: s.u[x],
            tau,
        }
        .into_error(&self.settings.limits);
        if let LbmError::Unstable { cause, .. } = &mut err {
            let surface = |j: usize| matches!(s.cell[j], INTERFACE | GAS);
            if s.cell[x] == INTERFACE || s.neighbours(x).any(surface) {
                cause.push_str(
                    "; at the free surface (an interface node or next to one: a falling or spreading \
                     front, where the liquid is fastest and thinnest)",
                );
            }
            let flips = self.flips.rate().max(self.flips.recent_rate());
            if let Some(w) = FlipFlops::describe(flips, self.params.kappa, self.params.lonely) {
                cause.push_str("; ");
                cause.push_str(&w);
            }
            if let (Some(b), Some(t)) = (&self.bingham, local) {
                let (lo, hi) = (1.0 / b.omega_hi, 1.0 / b.omega_lo);
                if t <= lo * (1.0 + 1e-9) {
                    cause.push_str(&format!(
                        "; the Bingham τ there is at its floor τ_min = {lo} (fast shear): raise \
                         τ_min (e.g. 0.52, which raises the viscosity of fast-sheared liquid) or the \
                         time step (τ_pl moves away from ½)"
                    ));
                } else if t >= hi * (1.0 - 1e-9) {
                    cause.push_str(&format!(
                        "; the Bingham τ there is at its ceiling τ_max = {hi} (unyielded liquid)"
                    ));
                }
            }
        }
        err
    }

    /// Stream, exchange mass and collide every liquid and interface node into the `*_new`
    /// arrays; the first node outside the limits, if any, and the mass the moving grain walls
    /// gave the nodes beside them. Blocks of nodes run on rayon's threads; each node reads only
    /// the previous state and writes only its own entries, the first bad node is the lowest over
    /// the blocks and the blocks' wall masses are summed in block order, so the result is the
    /// serial sweep's on any number of threads.
    ///
    /// A link into a [`GRAIN`] node bounces back with the wall's term 6 w_i ρ u_w·c_i (Eq. 19),
    /// which changes the node's populations, so its density, by that much: the node's mass m
    /// takes the same change (weighted by its fill, as an exchange with a full neighbour would
    /// be), or m and ρ part wherever a wall recedes from the liquid or advances into it (a
    /// lifted box: m rose 10 % above ρ in 0.35 s before this).
    fn sweep<C: Collider<L, f64> + Sync, const F: bool>(
        &mut self,
        s: &FreeSurface<L>,
        coll: &C,
    ) -> (Option<usize>, f64) {
        let n = s.nodes();
        let limits = self.settings.limits;
        let (links, rho_atm) = (&self.links[..], self.params.rho_atm);
        let f_new = SyncPtr(self.f_new.as_mut_ptr());
        self.mass_new
            .par_chunks_mut(NODE_BLOCK)
            .zip(self.rho_new.par_chunks_mut(NODE_BLOCK))
            .zip(self.u_new.par_chunks_mut(NODE_BLOCK))
            .enumerate()
            .map(|(b, ((mass_new, rho_new), u_new))| {
                let mut bad = None;
                let mut from_walls = 0.0;
                for (k, ((mass_out, rho_out), u_out)) in mass_new
                    .iter_mut()
                    .zip(rho_new.iter_mut())
                    .zip(u_new.iter_mut())
                    .enumerate()
                {
                    let x = b * NODE_BLOCK + k;
                    let kind = s.cell[x];
                    if kind != LIQUID && kind != INTERFACE {
                        *mass_out = 0.0;
                        *rho_out = s.rho[x];
                        *u_out = s.u[x];
                        continue;
                    }
                    let fill_x = s.fill(x);
                    let atm = if kind == INTERFACE {
                        atmosphere::<L>(rho_atm, s.u[x])
                    } else {
                        [0.0; QMAX]
                    };
                    let mut f = [[0.0f64; 1]; QMAX];
                    f[0][0] = s.f[x];
                    let mut dm = 0.0;
                    let mut wall_dm = 0.0;
                    for i in 1..L::Q {
                        let o = L::OPP[i];
                        // upstream node x − c_i = x + c_ī, and the population x sends to it
                        let up = links[o * n + x];
                        let f_out = s.f[o * n + x];
                        f[i][0] = if up == NONE {
                            f_out
                        } else {
                            let up = up as usize;
                            match s.cell[up] {
                                WALL => f_out,
                                // moving bounce-back (Leonardi Eq. 19 for the outgoing direction
                                // ī: f_i = f_ī − 6 w_ī ρ u_w·c_ī = f_ī + 6 w_i ρ u_w·c_i)
                                GRAIN => {
                                    let w = moving_wall::<L>(i, s.rho[x], s.solid_u[up]);
                                    let dw = if kind == LIQUID { w } else { fill_x * w };
                                    dm += dw;
                                    wall_dm += dw;
                                    f_out + w
                                }
                                GAS => from_gas::<L>(&atm, i, f_out),
                                k => {
                                    let f_in = s.f[i * n + up];
                                    dm +=
                                        link_exchange(link_weight(kind, fill_x, k, s.fill(up)), f_in, f_out);
                                    f_in
                                }
                            }
                        };
                    }
                    let m = coll.collide::<1, F>(&mut f, x);
                    for (i, fi) in f.iter().enumerate().take(L::Q) {
                        // SAFETY: index i·n + x with x in this block only: no other task writes
                        // it, and nothing reads `f_new` during the sweep.
                        unsafe { f_new.write(i * n + x, fi[0]) };
                    }
                    let (rho, u) = (m.rho[0], [m.u[0][0], m.u[1][0], m.u[2][0]]);
                    *rho_out = rho;
                    *u_out = u;
                    *mass_out = s.mass[x] + dm;
                    from_walls += wall_dm;
                    if bad.is_none() && !limits.accepts(rho, u) {
                        bad = Some(x);
                    }
                }
                (bad, from_walls)
            })
            .collect::<Vec<_>>()
            .into_iter()
            .fold((None, 0.0), |(a, m), (b, w)| {
                let bad = match (a, b) {
                    (Some(a), Some(b)) => Some(a.min(b)),
                    (a, b) => a.or(b),
                };
                (bad, m + w)
            })
    }
}

/// The moving-wall term 6 w_i ρ u_w·c_i of Leonardi Eq. 19 for a population arriving along c_i
/// from a grain node moving at `u_w`.
#[inline]
pub fn moving_wall<L: Lattice>(i: usize, rho: f64, u_w: [f64; 3]) -> f64 {
    let c = L::C[i];
    6.0 * L::W[i] * rho * (u_w[0] * c[0] as f64 + u_w[1] * c[1] as f64 + u_w[2] * c[2] as f64)
}

/// Nodes per parallel task of the free-surface sweep.
const NODE_BLOCK: usize = 2048;

/// True when no liquid node touches a gas node (the interface is closed).
pub fn is_closed<L: Lattice>(s: &FreeSurface<L>) -> bool {
    s.open_interface().is_none()
}
