//! State and stepper. `Fluid` is plain data (the domain, the post-collision populations f in
//! structure-of-arrays order `f[i * n + node]`, obstacle motions); `Stepper` is scratch (the second
//! population array, the row plan, per-row flags) plus the step loop: momentum-exchange forces,
//! fused stream-collide on a caller-chosen rayon pool, and the instability check.

use crate::LbmError;
use crate::bingham::{Bingham, BinghamRates};
use crate::collision::{CollideParams, Collider, Collision, LocalRates, NodeRates, equilibrium, local_rates};
use crate::compiled::Place;
use crate::diagnosis::BadNode;
use crate::domain::{Domain, FLUID, Face, Motion};
use crate::kernel::{self, Ctx, Limits, MacroOut, SyncPtr};
use crate::lattice::{Lattice, QMAX};
use crate::plan::Plan;
use crate::real::Real;
use lbdem_core::simd::{self, Simd, WithSimd};
use rayon::prelude::*;
use std::marker::PhantomData;

/// Hydrodynamic force and torque on one obstacle (lattice units, Leonardi Eq. 21).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct ForceTorque {
    pub force: [f64; 3],
    pub torque: [f64; 3],
}

/// Lattice state: plain data the coupling code may read and modify between steps. It is all a
/// step reads besides the settings (and per-node τ, if any), so serialising it (serde) and
/// stepping the restored copy continues the run bit for bit.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound = "")]
pub struct Fluid<L, T: Real> {
    pub domain: Domain,
    /// Post-collision populations of the current time, `f[i * n + node]`.
    pub f: Vec<T>,
    /// Rigid motion of each obstacle (index = obstacle id).
    pub obstacles: Vec<Motion>,
    /// Completed steps.
    pub step: u64,
    #[serde(skip)]
    _l: PhantomData<L>,
}

impl<L: Lattice, T: Real> Fluid<L, T> {
    /// Fluid at rest with density 1 on every node.
    pub fn new(domain: Domain, obstacles: Vec<Motion>) -> Self {
        let n = domain.len();
        let mut f = vec![T::default(); L::Q * n];
        for i in 0..L::Q {
            f[i * n..(i + 1) * n].fill(T::from_f64(L::W[i]));
        }
        Self {
            domain,
            f,
            obstacles,
            step: 0,
            _l: PhantomData,
        }
    }
    pub fn nodes(&self) -> usize {
        self.domain.len()
    }
    /// Set every fluid node to the equilibrium of `init(node) = (ρ, u)` (Su Eq. 7).
    pub fn init_equilibrium(&mut self, init: impl Fn([usize; 3]) -> (f64, [f64; 3])) {
        let n = self.nodes();
        for idx in 0..n {
            let (rho, u) = init(self.domain.coords(idx));
            let feq = equilibrium::<L>(rho, u);
            for (i, v) in feq.iter().enumerate().take(L::Q) {
                self.f[i * n + idx] = T::from_f64(*v);
            }
        }
    }
    /// Density and momentum Σ f c of node `idx` from the stored (post-collision) populations.
    pub fn moments(&self, idx: usize) -> (f64, [f64; 3]) {
        let n = self.nodes();
        let mut rho = 0.0;
        let mut j = [0.0; 3];
        for i in 0..L::Q {
            let v = self.f[i * n + idx].to_f64();
            rho += v;
            for (a, ja) in j.iter_mut().enumerate() {
                *ja += v * L::C[i][a] as f64;
            }
        }
        (rho, j)
    }
}

/// Macroscopic fields of the last step (written by the kernel when asked).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Macro {
    pub rho: Vec<f64>,
    /// Interleaved xyz.
    pub u: Vec<f64>,
}

/// Settings of a run that do not change from step to step.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Settings {
    pub collision: Collision,
    /// Uniform body-force density on fluid nodes (lattice units).
    pub force: [f64; 3],
    pub limits: Limits,
}

/// Scratch and the step loop.
pub struct Stepper<L, T: Real> {
    settings: Settings,
    params: CollideParams<T>,
    /// Per-node rates (`set_local_tau`) and the τ they came from (diagnosis).
    local: Option<(Vec<NodeRates<T>>, Vec<f64>)>,
    /// Bingham rheology (`set_bingham`) and τ per node of the last step that asked for output.
    bingham: Option<(Bingham, BinghamRates<T>)>,
    tau_field: Vec<f64>,
    plan: Plan,
    other: Vec<T>,
    row_good: Vec<bool>,
    motions: Vec<Motion>,
    /// Forces of the last step on each obstacle, then on each of the six faces.
    pub forces: Vec<ForceTorque>,
    _l: PhantomData<L>,
}

/// Rows per rayon task: fixed, so work splitting is the same for every pool size.
const ROWS_PER_TASK: usize = 4;

/// Every row of one two-array step on the current rayon pool, with the collision `C`. The tasks
/// run `P::rows_two` (`compiled::Place`: the codegen unit the kernel copies go to).
fn run_rows<L: Lattice, T: Real, C: Collider<L, T>, P: Place>(
    row_good: &mut [bool],
    ctx: &Ctx<T, C>,
    forced: bool,
) {
    row_good
        .par_chunks_mut(ROWS_PER_TASK)
        .enumerate()
        .for_each(|(c, flags)| P::rows_two::<L, T, C>(ctx, c * ROWS_PER_TASK, flags, forced));
}

/// One task's rows of a two-array step, from row `first`: the body of `Place::rows_two`. One
/// kernel variant per dispatched copy, as the AA stepper (`stepper_aa::rows_aa`, also for
/// `Collider::FORCE_TERMS_ALWAYS`).
#[inline(always)]
pub(crate) fn rows_two<L: Lattice, T: Real, C: Collider<L, T>>(
    ctx: &Ctx<T, C>,
    first: usize,
    flags: &mut [bool],
    forced: bool,
) {
    if C::FORCE_TERMS_ALWAYS || forced {
        simd::dispatch(Rows::<L, T, C, true> {
            ctx,
            first,
            flags,
            _l: PhantomData,
        })
    } else {
        simd::dispatch(Rows::<L, T, C, false> {
            ctx,
            first,
            flags,
            _l: PhantomData,
        })
    }
}

/// One task's rows (forced or not), compiled for each instruction-set level
/// (`lbdem_core::simd`).
struct Rows<'a, L, T, C, const F: bool> {
    ctx: &'a Ctx<'a, T, C>,
    first: usize,
    flags: &'a mut [bool],
    _l: PhantomData<L>,
}

impl<L: Lattice, T: Real, C: Collider<L, T>, const F: bool> WithSimd for Rows<'_, L, T, C, F> {
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        for (k, g) in self.flags.iter_mut().enumerate() {
            // SAFETY: each row index belongs to exactly one chunk.
            *g = unsafe { kernel::row::<L, T, C, F, S>(self.ctx, self.first + k) };
        }
    }
}

/// Per-node rates from `tau` (shared by both steppers); sets `params.bgk` for the block path.
pub(crate) fn make_local<T: Real>(
    collision: &Collision,
    params: &mut CollideParams<T>,
    tau: Vec<f64>,
    nodes: usize,
) -> Result<(Vec<NodeRates<T>>, Vec<f64>), LbmError> {
    if tau.len() != nodes {
        return Err(LbmError::LocalTauLength {
            got: tau.len(),
            nodes,
        });
    }
    let (rates, bgk) = local_rates::<T>(collision, &tau)?;
    params.bgk = bgk;
    Ok((rates, tau))
}

impl<L: Lattice, T: Real> Stepper<L, T> {
    /// Check the settings against the domain and build the row plan.
    pub fn new(fluid: &Fluid<L, T>, settings: Settings) -> Result<Self, LbmError> {
        let params = CollideParams::<T>::new(&settings.collision, settings.force)?;
        Self::with_params(fluid, settings, params)
    }

    /// As [`Stepper::new`] but running a τ < ½ that `new` refuses (see
    /// [`Collision::rates_past_tau_check`]): only for the stability maps, to show by running that
    /// the refusal was right. The run still stops at the first node leaving `settings.limits`.
    pub fn new_past_tau_check(fluid: &Fluid<L, T>, settings: Settings) -> Result<Self, LbmError> {
        let (wp, wm) = settings.collision.rates_past_tau_check()?;
        Self::with_params(
            fluid,
            settings,
            CollideParams::<T>::from_rates(wp, wm, settings.force),
        )
    }

    fn with_params(
        fluid: &Fluid<L, T>,
        settings: Settings,
        params: CollideParams<T>,
    ) -> Result<Self, LbmError> {
        let dom = &fluid.domain;
        if (L::D == 2) != (dom.n[2] == 1) {
            return Err(LbmError::Unsupported(format!(
                "lattice {} on a box of {}x{}x{} nodes: use nz = 1 with D2Q9 and nz > 1 with D3Q19",
                L::NAME,
                dom.n[0],
                dom.n[1],
                dom.n[2]
            )));
        }
        for (k, fc) in dom.faces.iter().enumerate() {
            if fc.is_zou_he() && (L::D != 2 || k >= 4) {
                return Err(LbmError::Unsupported(format!(
                    "Zou-He {:?} on face {k} with {}: only D2Q9 x/y faces are implemented; use a wall, \
                     periodic faces or a body force",
                    fc,
                    L::NAME
                )));
            }
            let opp = k ^ 1;
            if fc.is_periodic() != dom.faces[opp].is_periodic() {
                return Err(LbmError::Unsupported(format!(
                    "face {k} is {:?} but the opposite face is not periodic: make both periodic or neither",
                    fc
                )));
            }
        }
        if dom
            .obstacle
            .iter()
            .any(|&o| o != u16::MAX && o as usize >= fluid.obstacles.len())
        {
            return Err(LbmError::Unsupported(
                "a node is marked with an obstacle id that has no motion entry; push a Motion per obstacle"
                    .into(),
            ));
        }
        let mut s = Self {
            settings,
            params,
            local: None,
            bingham: None,
            tau_field: Vec::new(),
            plan: Plan::default(),
            other: vec![T::default(); fluid.f.len()],
            row_good: vec![true; dom.n[1] * dom.n[2]],
            motions: Vec::new(),
            forces: Vec::new(),
            _l: PhantomData,
        };
        s.rebuild(fluid);
        Ok(s)
    }

    /// Rebuild the plan after the geometry (node kinds) changed.
    pub fn rebuild(&mut self, fluid: &Fluid<L, T>) {
        self.plan = Plan::build::<L>(&fluid.domain, fluid.obstacles.len());
        self.forces = vec![ForceTorque::default(); fluid.obstacles.len() + 6];
    }

    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// Relax node x with τ⁺ = `tau[x]` (node order) instead of the settings' τ, keeping the kind
    /// of collision (BGK, or TRT with its magic Λ): the seam of local-τ rheology (Bingham,
    /// Leonardi et al. 2014 Eq. 8). May be called between any two steps; equal values everywhere
    /// give the uniform run bit for bit. Refuses a τ ≤ ½ or a length other than the node count.
    /// Replaces Bingham rheology if it was on.
    pub fn set_local_tau(&mut self, tau: Vec<f64>) -> Result<(), LbmError> {
        let nodes = self.other.len() / L::Q;
        self.local = Some(make_local::<T>(
            &self.settings.collision,
            &mut self.params,
            tau,
            nodes,
        )?);
        self.bingham = None;
        Ok(())
    }

    /// Bingham plastic rheology from the next step on (`Some`), or back to the settings' τ
    /// (`None`): every node's τ from its own shear rate every step, inside the kernel
    /// (`bingham`, Leonardi et al. 2014 Eqs. 27-30), BGK or TRT as the settings say. Replaces
    /// per-node τ if it was set. No state is added: a checkpoint of the `Fluid` still resumes bit
    /// for bit (set the same Bingham on the new stepper).
    pub fn set_bingham(&mut self, bingham: Option<Bingham>) -> Result<(), LbmError> {
        self.bingham = match bingham {
            Some(b) => Some((
                b,
                BinghamRates::new(&b, &self.settings.collision, self.settings.force)?,
            )),
            None => None,
        };
        self.clear_local_tau();
        Ok(())
    }

    /// The Bingham parameters in use, if any.
    pub fn bingham(&self) -> Option<&Bingham> {
        self.bingham.as_ref().map(|(b, _)| b)
    }

    /// τ of every node on the last step that was given a `Macro` to fill, with Bingham on
    /// (node order; solid and inactive nodes NaN). `None` before such a step.
    pub fn bingham_tau(&self) -> Option<&[f64]> {
        (self.bingham.is_some() && !self.tau_field.is_empty()).then_some(self.tau_field.as_slice())
    }

    /// Back to the settings' uniform τ (Bingham stays on if set).
    pub fn clear_local_tau(&mut self) {
        self.local = None;
        self.params.bgk = self
            .settings
            .collision
            .rates()
            .map(|(p, m)| p == m)
            .unwrap_or(true);
    }

    /// The per-node τ in use, if any.
    pub fn local_tau(&self) -> Option<&[f64]> {
        self.local.as_ref().map(|(_, t)| t.as_slice())
    }

    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// Advance one step on the current rayon pool. Forces on obstacles and walls are left in
    /// `self.forces`; if `out` is given it receives ρ and u of every fluid node. (The kernels are
    /// compiled in this crate: `compiled`.)
    pub fn step(&mut self, fluid: &mut Fluid<L, T>, out: Option<&mut Macro>) -> Result<(), LbmError> {
        T::step_two(self, fluid, out)
    }

    /// The body of [`Stepper::step`], instantiated by `compiled` only.
    pub(crate) fn step_generic<P: Place>(
        &mut self,
        fluid: &mut Fluid<L, T>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError> {
        self.exchange_forces(fluid);
        let n = fluid.nodes();
        self.motions.clear();
        self.motions.extend_from_slice(&fluid.obstacles);
        for fc in fluid.domain.faces {
            let velocity = match fc {
                Face::Wall { velocity } => velocity,
                _ => [0.0; 3],
            };
            self.motions.push(Motion {
                velocity,
                ..Default::default()
            });
        }
        let out = out.map(|m| {
            m.rho.resize(n, 0.0);
            m.u.resize(3 * n, 0.0);
            MacroOut {
                rho: SyncPtr(m.rho.as_mut_ptr()),
                u: SyncPtr(m.u.as_mut_ptr()),
            }
        });
        let limits = self.settings.limits.in_precision::<T>();
        let forced = self.settings.force.iter().any(|&x| x != 0.0);
        let dst = SyncPtr(self.other.as_mut_ptr());
        let tau_out = match (&self.bingham, &out) {
            (Some(_), Some(_)) => {
                self.tau_field.clear();
                self.tau_field.resize(n, f64::NAN);
                Some(SyncPtr(self.tau_field.as_mut_ptr()))
            }
            _ => None,
        };
        let (dom, plan, motions) = (&fluid.domain, &self.plan, &self.motions);
        match (&self.bingham, &self.local) {
            (Some((_, rates)), _) => {
                let ctx = Ctx {
                    dom,
                    plan,
                    src: &fluid.f,
                    dst,
                    coll: BinghamRates {
                        tau: tau_out,
                        ..*rates
                    },
                    motions,
                    limits,
                    out,
                };
                run_rows::<L, T, _, P>(&mut self.row_good, &ctx, forced);
            }
            (None, None) => {
                let ctx = Ctx {
                    dom,
                    plan,
                    src: &fluid.f,
                    dst,
                    coll: self.params,
                    motions,
                    limits,
                    out,
                };
                run_rows::<L, T, _, P>(&mut self.row_good, &ctx, forced);
            }
            (None, Some((rates, _))) => {
                let ctx = Ctx {
                    dom,
                    plan,
                    src: &fluid.f,
                    dst,
                    coll: LocalRates {
                        base: self.params,
                        rates,
                    },
                    motions,
                    limits,
                    out,
                };
                run_rows::<L, T, _, P>(&mut self.row_good, &ctx, forced);
            }
        }
        std::mem::swap(&mut fluid.f, &mut self.other);
        fluid.step += 1;
        if let Some(r) = self.row_good.iter().position(|g| !g) {
            return Err(self.diagnose(fluid, r));
        }
        Ok(())
    }

    /// Momentum exchange on every boundary link from the post-collision populations about to be
    /// bounced back: F = Σ (2 f_i − 6 w_i ρ u_w·c_i) c_i (Leonardi Eq. 21), torque Σ r × F with r
    /// from the obstacle centre to the link midpoint. Sequential in link order (deterministic).
    fn exchange_forces(&mut self, fluid: &Fluid<L, T>) {
        let n = fluid.nodes();
        let dom = &fluid.domain;
        let n_obst = fluid.obstacles.len();
        self.forces.iter_mut().for_each(|f| *f = ForceTorque::default());
        for l in &self.plan.links {
            if l.target == u16::MAX {
                continue;
            }
            let i = l.dir as usize;
            let c = L::C[i];
            let p = dom.coords(l.node as usize);
            let mid = [0, 1, 2].map(|a| p[a] as f64 + 0.5 * c[a] as f64);
            let t = l.target as usize;
            let (uw, r) = if t < n_obst {
                let m = &fluid.obstacles[t];
                let r = dom.offset(m.centre, mid);
                (m.velocity_at(r), r)
            } else {
                let uw = match dom.faces[t - n_obst] {
                    Face::Wall { velocity } => velocity,
                    _ => [0.0; 3],
                };
                (uw, [0.0; 3])
            };
            let cu = c[0] as f64 * uw[0] + c[1] as f64 * uw[1] + c[2] as f64 * uw[2];
            let mag = 2.0 * fluid.f[i * n + l.node as usize].to_f64() - 6.0 * L::W[i] * cu;
            let fl = c.map(|ca| mag * ca as f64);
            let ft = &mut self.forces[t];
            for a in 0..3 {
                ft.force[a] += fl[a];
            }
            ft.torque[0] += r[1] * fl[2] - r[2] * fl[1];
            ft.torque[1] += r[2] * fl[0] - r[0] * fl[2];
            ft.torque[2] += r[0] * fl[1] - r[1] * fl[0];
        }
    }

    /// Find the first bad node of row `r` and name the likely cause (`diagnosis`).
    fn diagnose(&self, fluid: &Fluid<L, T>, r: usize) -> LbmError {
        let dom = &fluid.domain;
        let [nx, ny, _] = dom.n;
        let (y, z) = (r % ny, r / ny);
        let lim = self.settings.limits;
        for x in 0..nx {
            let idx = dom.index(x, y, z);
            if dom.kind[idx] != FLUID {
                continue;
            }
            // recompute the macroscopic state of this node from the new post-collision values:
            // ρ is unchanged by collision, u = (Σ f c − F/2)/ρ undoes the Guo half-force.
            let (rho, j) = fluid.moments(idx);
            let u = [0, 1, 2].map(|a| (j[a] - 0.5 * self.settings.force[a]) / rho);
            if lim.accepts(rho, u) {
                continue;
            }
            let tau = match (&self.local, &self.bingham) {
                (Some((_, t)), _) => t[idx],
                // the smallest τ the clamp allows: the one a blow-up is likeliest to come from
                (None, Some((b, _))) => b.tau_min,
                (None, None) => self.settings.collision.tau(),
            };
            return BadNode {
                step: fluid.step,
                node: [x, y, z],
                rho,
                u,
                tau,
            }
            .into_error(&lim);
        }
        LbmError::Unstable {
            step: fluid.step,
            node: [0, y, z],
            rho: f64::NAN,
            u: [f64::NAN; 3],
            cause: "row flagged but no bad node found (internal)".into(),
        }
    }
}

/// Populations of one node in f64 (for tests and coupling code).
pub fn node_populations<L: Lattice, T: Real>(fluid: &Fluid<L, T>, idx: usize) -> [f64; QMAX] {
    let n = fluid.nodes();
    let mut out = [0.0; QMAX];
    for (i, o) in out.iter_mut().enumerate().take(L::Q) {
        *o = fluid.f[i * n + idx].to_f64();
    }
    out
}
