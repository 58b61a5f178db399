//! Stepper for the in-place AA kernel (`kernel_aa`): same physics and same results as `Stepper`
//! (bitwise, tested), half the memory traffic. It takes the `Fluid` in the canonical layout
//! (post-collision, slot i = f_i), keeps it in its own alternating layout while stepping, and gives
//! it back canonical with `finish` after an even number of steps. Zou-He faces are not supported
//! here (use `Stepper`). Forces are refreshed every step from whichever layout the array is in.
//!
//! The populations may be stored in a narrower form than the arithmetic type `T` (the third
//! parameter, `storage::Storage`; `T` itself by default). With `T` the array is the fluid's own
//! `f`, as before; with a narrower storage the stepper keeps the array and the fluid's `f` is
//! empty until `finish` (read the state with `canonical` or `export`).

use crate::LbmError;
use crate::bingham::{Bingham, BinghamRates};
use crate::collision::{CollideParams, Collider, LocalRates, NodeRates};
use crate::compiled::Place;
use crate::diagnosis::BadNode;
use crate::domain::{Face, Motion};
use crate::kernel::{MacroOut, SyncPtr};
use crate::kernel_aa::{self, Bad, CtxAa};
use crate::lattice::Lattice;
use crate::layout::Layout;
use crate::plan::Plan;
use crate::real::Real;
use crate::stepper::{Fluid, ForceTorque, Macro, Settings, make_local};
use crate::storage::Storage;
use lbdem_core::simd::{self, Simd, WithSimd};
use rayon::prelude::*;
use std::any::TypeId;
use std::marker::PhantomData;

const ROWS_PER_TASK: usize = 4;

/// How the rows of one step are spread over the rayon pool (results do not depend on it: every
/// node reads and writes only its own slots).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Partition {
    /// Tasks of this many rows, taken by whichever thread is free (work stealing).
    Rows(usize),
    /// One contiguous range of rows per thread of the pool (OpenMP `schedule(static)`).
    Contiguous,
}

pub struct StepperAa<L, T: Real, St: Storage<T> = T> {
    settings: Settings,
    params: CollideParams<T>,
    /// Per-node rates (`set_local_tau`) and the τ they came from (diagnosis).
    local: Option<(Vec<NodeRates<T>>, Vec<f64>)>,
    /// Bingham rheology (`set_bingham`) and τ per node of the last step that asked for output.
    bingham: Option<(Bingham, BinghamRates<T>)>,
    tau_field: Vec<f64>,
    /// Nodes of the lattice.
    nodes: usize,
    plan: Plan,
    /// Layout of `fluid.f` between `new` and `finish` (padded, see `layout`).
    layout: Layout,
    bad: Vec<Bad>,
    motions: Vec<Motion>,
    /// True when the array is in the reversed layout (next step is odd).
    reversed: bool,
    /// The population array when `St` is not `T` (else empty: the array is `fluid.f`).
    store: Vec<St>,
    /// Row partition over the pool (default `Rows(4)`).
    pub partition: Partition,
    pub forces: Vec<ForceTorque>,
    _l: PhantomData<L>,
}

/// Every row of one AA step with the collision `C`, spread over the pool by `partition`. The
/// tasks run `P::rows_aa` (`compiled::Place`: the codegen unit the kernel copies go to).
fn run_rows_aa<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>, P: Place>(
    bad: &mut [Bad],
    ctx: &CtxAa<T, C, St>,
    partition: Partition,
    odd: bool,
    forced: bool,
) {
    let work = |(c, flags): (usize, &mut [Bad]), rows: usize| {
        P::rows_aa::<L, T, St, C>(ctx, c * rows, flags, odd, forced)
    };
    match partition {
        Partition::Rows(k) => {
            let k = k.max(1);
            bad.par_chunks_mut(k).enumerate().for_each(|t| work(t, k));
        }
        Partition::Contiguous => {
            let k = bad.len().div_ceil(rayon::current_num_threads());
            bad.par_chunks_mut(k)
                .with_max_len(1)
                .enumerate()
                .for_each(|t| work(t, k));
        }
    }
}

/// One task's rows of an AA step, from row `first` (odd or even, forced or not): the body of
/// `Place::rows_aa`. One kernel variant per dispatched copy: a copy holding all four ran f32 9 %
/// slower. The per-node colliders (`Collider::FORCE_TERMS_ALWAYS`) are compiled with the force
/// terms only, so half as many copies of them are built.
#[inline(always)]
pub(crate) fn rows_aa<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>>(
    ctx: &CtxAa<T, C, St>,
    first: usize,
    flags: &mut [Bad],
    odd: bool,
    forced: bool,
) {
    // The constant is tested on its own (not `forced || C::FORCE_TERMS_ALWAYS`) so that rustc
    // drops the arms a collider cannot take before it compiles them.
    if C::FORCE_TERMS_ALWAYS {
        if odd {
            run_copy::<T, St, _>(RowsAa::<L, T, St, C, true, true>::new(ctx, first, flags))
        } else {
            run_copy::<T, St, _>(RowsAa::<L, T, St, C, false, true>::new(ctx, first, flags))
        }
    } else {
        match (odd, forced) {
            (true, true) => run_copy::<T, St, _>(RowsAa::<L, T, St, C, true, true>::new(ctx, first, flags)),
            (true, false) => run_copy::<T, St, _>(RowsAa::<L, T, St, C, true, false>::new(ctx, first, flags)),
            (false, true) => run_copy::<T, St, _>(RowsAa::<L, T, St, C, false, true>::new(ctx, first, flags)),
            (false, false) => {
                run_copy::<T, St, _>(RowsAa::<L, T, St, C, false, false>::new(ctx, first, flags))
            }
        }
    }
}

/// `op` through the storage's dispatch: with F16C for the binary16 storage (`Storage::F16C`).
#[inline(always)]
fn run_copy<T: Real, St: Storage<T>, Op: WithSimd>(op: Op) -> Op::Output {
    if St::F16C {
        simd::dispatch_f16c(op)
    } else {
        simd::dispatch(op)
    }
}

/// One task's rows of an AA step (odd or even, forced or not), compiled for each
/// instruction-set level (`lbdem_core::simd`).
struct RowsAa<'a, L, T, St, C, const ODD: bool, const F: bool> {
    ctx: &'a CtxAa<'a, T, C, St>,
    first: usize,
    flags: &'a mut [Bad],
    _l: PhantomData<L>,
}

impl<'a, L, T, St, C, const ODD: bool, const F: bool> RowsAa<'a, L, T, St, C, ODD, F> {
    fn new(ctx: &'a CtxAa<'a, T, C, St>, first: usize, flags: &'a mut [Bad]) -> Self {
        Self {
            ctx,
            first,
            flags,
            _l: PhantomData,
        }
    }
}

impl<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>, const ODD: bool, const F: bool> WithSimd
    for RowsAa<'_, L, T, St, C, ODD, F>
{
    type Output = ();
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) {
        for (k, b) in self.flags.iter_mut().enumerate() {
            let r = self.first + k;
            // SAFETY: every node touches only its own slots (kernel_aa module doc).
            *b = unsafe {
                if ODD {
                    kernel_aa::odd_row::<L, T, St, C, F, S>(self.ctx, r)
                } else {
                    kernel_aa::even_row::<L, T, St, C, F, S>(self.ctx, r)
                }
            };
        }
    }
}

fn swap_pairs<L: Lattice, T>(f: &mut [T], n: usize) {
    for &i in L::HALF {
        let o = L::OPP[i];
        let (lo, hi) = (i.min(o), i.max(o));
        let (a, b) = f.split_at_mut(hi * n);
        a[lo * n..(lo + 1) * n].swap_with_slice(&mut b[..n]);
    }
}

impl<L: Lattice, T: Real> StepperAa<L, T> {
    /// Take `fluid` (canonical layout) into the AA layout; populations stored as `T`.
    pub fn new(fluid: &mut Fluid<L, T>, settings: Settings) -> Result<Self, LbmError> {
        Self::with_storage(fluid, settings)
    }
}

impl<L: Lattice, T: Real, St: Storage<T>> StepperAa<L, T, St> {
    /// The narrower storages run the uniform collision only (BGK or TRT, with or without the
    /// body force): each collider is compiled once per storage, lattice and instruction-set
    /// level, and the build of this crate is the longest of CI already (README, "CI's cost").
    fn uniform_only(what: &str) -> Result<(), LbmError> {
        if St::SHIFTED {
            return Err(LbmError::Unsupported(format!(
                "{what} with population storage {}: use precision f64 or f32 (stored as themselves) for                  local relaxation times",
                St::NAME
            )));
        }
        Ok(())
    }

    /// Whether the array is the fluid's own `f` (`St` is `T`).
    fn in_fluid() -> bool {
        TypeId::of::<St>() == TypeId::of::<T>()
    }

    /// Take `fluid` (canonical layout) into the AA layout with populations stored as `St`
    /// (`storage`); with a narrower storage `fluid.f` is emptied until `finish`.
    pub fn with_storage(fluid: &mut Fluid<L, T>, settings: Settings) -> Result<Self, LbmError> {
        // same checks as the two-array stepper
        crate::stepper::Stepper::<L, T>::new(fluid, settings)?;
        if fluid.domain.faces.iter().any(|f| f.is_zou_he()) {
            return Err(LbmError::Unsupported(
                "Zou-He faces with the AA kernel: use kernel = \"two-array\" (Stepper) for velocity or \
                 pressure faces"
                    .into(),
            ));
        }
        let n = fluid.nodes();
        swap_pairs::<L, T>(&mut fluid.f, n);
        let mut layout = Layout::padded::<St>(fluid.domain.n);
        let store = if Self::in_fluid() {
            fluid.f = layout.pack(&fluid.f, L::Q);
            Vec::new()
        } else {
            let f = std::mem::take(&mut fluid.f);
            layout.pack(&encode::<L, T, St>(&f, n), L::Q)
        };
        let dom = &fluid.domain;
        let mut motions = fluid.obstacles.clone();
        for fc in dom.faces {
            let velocity = match fc {
                Face::Wall { velocity } => velocity,
                _ => [0.0; 3],
            };
            motions.push(Motion {
                velocity,
                ..Default::default()
            });
        }
        Ok(Self {
            settings,
            params: CollideParams::new(&settings.collision, settings.force)?,
            local: None,
            bingham: None,
            tau_field: Vec::new(),
            nodes: n,
            plan: Plan::build::<L>(dom, fluid.obstacles.len()),
            layout,
            bad: vec![None; dom.n[1] * dom.n[2]],
            motions,
            reversed: true,
            store,
            partition: Partition::Rows(ROWS_PER_TASK),
            forces: vec![ForceTorque::default(); fluid.obstacles.len() + 6],
            _l: PhantomData,
        })
    }

    /// Give the fluid back in the canonical layout; only after an even number of steps.
    pub fn finish(self, fluid: &mut Fluid<L, T>) -> Result<(), LbmError> {
        if !self.reversed {
            return Err(LbmError::Unsupported(
                "AA stepper finished after an odd number of steps: take one more step first".into(),
            ));
        }
        fluid.f = self.canonical(fluid)?;
        Ok(())
    }

    /// The populations in the canonical layout of `Fluid::f` (post-collision, slot i = f_i, node
    /// order), without giving the fluid back: after an even number of steps only (at an odd one
    /// the array holds streamed, pre-collision values). A `Fluid` with these populations, the
    /// same domain, obstacles and `step`, taken by a new `StepperAa` (or a two-array `Stepper`)
    /// continues the run bit for bit: this is the state a checkpoint stores.
    pub fn canonical(&self, fluid: &Fluid<L, T>) -> Result<Vec<T>, LbmError> {
        if !self.reversed {
            return Err(LbmError::Unsupported(
                "AA state exported after an odd number of steps: take one more step first (the array \
                 then holds post-collision populations)"
                    .into(),
            ));
        }
        let n = fluid.nodes();
        let mut f = if Self::in_fluid() {
            self.layout.unpack(&fluid.f, L::Q, n)
        } else {
            decode::<L, T, St>(&self.layout.unpack(&self.store, L::Q, n), n)
        };
        swap_pairs::<L, T>(&mut f, n);
        Ok(f)
    }

    /// A copy of `fluid` in the canonical layout (see [`StepperAa::canonical`]): the plain data
    /// to serialise for a checkpoint.
    pub fn export(&self, fluid: &Fluid<L, T>) -> Result<Fluid<L, T>, LbmError> {
        let f = self.canonical(fluid)?;
        let mut out = Fluid::new(fluid.domain.clone(), fluid.obstacles.clone());
        out.f = f;
        out.step = fluid.step;
        Ok(out)
    }

    /// Relax node x with τ⁺ = `tau[x]` (node order); see `Stepper::set_local_tau`. Replaces
    /// Bingham rheology if it was on.
    pub fn set_local_tau(&mut self, tau: Vec<f64>) -> Result<(), LbmError> {
        Self::uniform_only("per-node relaxation times (set_local_tau)")?;
        let nodes = self.nodes;
        self.local = Some(make_local::<T>(
            &self.settings.collision,
            &mut self.params,
            tau,
            nodes,
        )?);
        self.bingham = None;
        Ok(())
    }

    /// Bingham plastic rheology from the next step on, or back to the settings' τ; see
    /// `Stepper::set_bingham` (same kernel arithmetic: both steppers give the same bits). No
    /// state is added: `export` after an even number of steps is still the whole state.
    pub fn set_bingham(&mut self, bingham: Option<Bingham>) -> Result<(), LbmError> {
        if bingham.is_some() {
            Self::uniform_only("Bingham rheology (set_bingham)")?;
        }
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

    /// Back to the settings' uniform τ.
    pub fn clear_local_tau(&mut self) {
        self.local = None;
        self.params.bgk = self
            .settings
            .collision
            .rates()
            .map(|(p, m)| p == m)
            .unwrap_or(true);
    }

    /// The padded layout the array is kept in between `new` and `finish`.
    pub fn layout(&self) -> Layout {
        self.layout
    }

    /// Obstacle motions may change between steps (coupling); geometry changes need a new stepper.
    pub fn set_motions(&mut self, fluid: &Fluid<L, T>) {
        let n_obst = fluid.obstacles.len();
        self.motions[..n_obst].copy_from_slice(&fluid.obstacles);
    }

    /// One step (the kernels are compiled in this crate: `compiled`).
    pub fn step(&mut self, fluid: &mut Fluid<L, T>, out: Option<&mut Macro>) -> Result<(), LbmError> {
        St::step_aa(self, fluid, out)
    }

    /// The body of [`StepperAa::step`], instantiated by `compiled` only.
    pub(crate) fn step_generic<P: Place>(
        &mut self,
        fluid: &mut Fluid<L, T>,
        out: Option<&mut Macro>,
    ) -> Result<(), LbmError> {
        self.exchange_forces(fluid);
        let n = fluid.nodes();
        let out = out.map(|m| {
            m.rho.resize(n, 0.0);
            m.u.resize(3 * n, 0.0);
            MacroOut {
                rho: SyncPtr(m.rho.as_mut_ptr()),
                u: SyncPtr(m.u.as_mut_ptr()),
            }
        });
        let limits = self.settings.limits.in_precision::<T>();
        let base = self.layout.base;
        let f = if Self::in_fluid() {
            // SAFETY: `St` is `T` (`in_fluid`), so this is a pointer to the array's own type.
            SyncPtr(fluid.f[base..].as_mut_ptr().cast::<St>())
        } else {
            SyncPtr(self.store[base..].as_mut_ptr())
        };
        let odd = self.reversed;
        let forced = self.settings.force.iter().any(|&x| x != 0.0);
        let (dom, plan, motions, layout, partition) = (
            &fluid.domain,
            &self.plan,
            &self.motions,
            self.layout,
            self.partition,
        );
        let tau_out = match (&self.bingham, &out) {
            (Some(_), Some(_)) => {
                self.tau_field.clear();
                self.tau_field.resize(n, f64::NAN);
                Some(SyncPtr(self.tau_field.as_mut_ptr()))
            }
            _ => None,
        };
        // `St::SHIFTED` is a constant: for the narrower storages only the uniform arm is compiled
        // (`uniform_only`; the others cannot be reached)
        let uniform = St::SHIFTED || (self.bingham.is_none() && self.local.is_none());
        if uniform {
            let ctx = CtxAa {
                dom,
                plan,
                f,
                layout,
                coll: self.params,
                motions,
                limits,
                out,
            };
            run_rows_aa::<L, T, St, _, P>(&mut self.bad, &ctx, partition, odd, forced);
        } else {
            match (&self.bingham, &self.local) {
                (Some((_, rates)), _) => {
                    let ctx = CtxAa {
                        dom,
                        plan,
                        f,
                        layout,
                        coll: BinghamRates {
                            tau: tau_out,
                            ..*rates
                        },
                        motions,
                        limits,
                        out,
                    };
                    run_rows_aa::<L, T, St, _, P>(&mut self.bad, &ctx, partition, odd, forced);
                }
                (None, Some((rates, _))) => {
                    let ctx = CtxAa {
                        dom,
                        plan,
                        // slot 0 of the layout (the kernel's offsets do not include `base`)
                        f,
                        layout,
                        coll: LocalRates {
                            base: self.params,
                            rates,
                        },
                        motions,
                        limits,
                        out,
                    };
                    run_rows_aa::<L, T, St, _, P>(&mut self.bad, &ctx, partition, odd, forced);
                }
                (None, None) => unreachable!("the uniform arm above"),
            }
        }
        self.reversed = !self.reversed;
        fluid.step += 1;
        if let Some((r, Some((x, rho, u)))) = self.bad.iter().enumerate().find(|(_, b)| b.is_some()) {
            let ny = fluid.domain.n[1];
            let node = [*x, r % ny, r / ny];
            let tau = match (&self.local, &self.bingham) {
                (Some((_, t)), _) => t[fluid.domain.index(node[0], node[1], node[2])],
                // the smallest τ the clamp allows (as `Stepper::diagnose`)
                (None, Some((b, _))) => b.tau_min,
                (None, None) => self.settings.collision.tau(),
            };
            return Err(BadNode {
                step: fluid.step,
                node,
                rho: *rho,
                u: *u,
                tau,
            }
            .into_error(&self.settings.limits));
        }
        Ok(())
    }

    /// Leonardi Eq. 21 on every link, from the post-collision value heading into the wall: in the
    /// reversed layout it sits in slot opp(i) of the fluid node; in the natural layout slot opp(i)
    /// holds it already bounced, so the wall term is taken off again.
    fn exchange_forces(&mut self, fluid: &Fluid<L, T>) {
        let dom = &fluid.domain;
        let n_obst = fluid.obstacles.len();
        self.forces.iter_mut().for_each(|f| *f = ForceTorque::default());
        for l in &self.plan.links {
            if l.target == u16::MAX {
                continue;
            }
            let i = l.dir as usize;
            let o = L::OPP[i];
            let c = L::C[i];
            let p = dom.coords(l.node as usize);
            let mid = [0, 1, 2].map(|a| p[a] as f64 + 0.5 * c[a] as f64);
            let t = l.target as usize;
            let (uw, r) = if t < n_obst {
                let m = &self.motions[t];
                let r = dom.offset(m.centre, mid);
                (m.velocity_at(r), r)
            } else {
                (self.motions[t].velocity, [0.0; 3])
            };
            let cu = c[0] as f64 * uw[0] + c[1] as f64 * uw[1] + c[2] as f64 * uw[2];
            let k = self.layout.base + self.layout.slot(o, l.node as usize);
            let stored = if Self::in_fluid() {
                fluid.f[k].to_f64()
            } else {
                // SAFETY: k is a slot of the array (the links are the plan's).
                unsafe { St::load::<L>(self.store.as_ptr(), k, o) }.to_f64()
            };
            let post = if self.reversed {
                stored
            } else {
                stored + 6.0 * L::W[i] * cu
            };
            let mag = 2.0 * post - 6.0 * L::W[i] * cu;
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
}

/// The stored form of canonical populations `f[i * n + node]` (shifted by w_i where `St` is).
fn encode<L: Lattice, T: Real, St: Storage<T>>(f: &[T], n: usize) -> Vec<St> {
    let mut out = vec![St::default(); f.len()];
    for i in 0..L::Q {
        for k in 0..n {
            // SAFETY: k + i n < Q n = len.
            unsafe { St::store::<L>(out.as_mut_ptr(), i * n + k, i, f[i * n + k]) };
        }
    }
    out
}

/// Inverse of `encode` (to the stored precision).
fn decode<L: Lattice, T: Real, St: Storage<T>>(s: &[St], n: usize) -> Vec<T> {
    let mut out = vec![T::default(); s.len()];
    for i in 0..L::Q {
        for k in 0..n {
            // SAFETY: as in `encode`.
            out[i * n + k] = unsafe { St::load::<L>(s.as_ptr(), i * n + k, i) };
        }
    }
    out
}
