//! The fused stream-collide kernel over structure-of-arrays storage (two arrays, pull scheme):
//! each fluid node gathers f_i from x − c_i (Su Eq. 12 read backwards), applies halfway
//! bounce-back with the moving-wall term (Leonardi Eq. 19) or Zou-He where the upstream node is a
//! wall or outside the box, collides (a `collision::Collider`, monomorphised) and writes its own slot of the
//! destination. Rows are independent, so the result does not depend on how rows are spread over
//! threads. Interior runs take a branch-free path in blocks of `W` nodes that auto-vectorises.

use crate::collision::{Collider, Moments};
use crate::domain::{Domain, FLUID, Face, Motion};
use crate::lattice::{Lattice, QMAX};
use crate::plan::{Plan, Upstream, neighbour};
use crate::real::Real;
use crate::zouhe;
use lbdem_core::simd::{NATIVE_V4, Simd};

/// Block width of the fast path for values of `T`: two AVX-512 registers per quantity, 32 f32 or
/// 16 f64 nodes. One register per quantity (16 f32, 8 f64) or four (32 f64) ran 15-40 % slower in
/// cache (256x192, `examples/mlups.rs`): two independent chains hide the latency of the
/// arithmetic without spilling the 9 populations.
#[inline(always)]
pub const fn wide<T>() -> usize {
    if std::mem::size_of::<T>() == 4 { 32 } else { 16 }
}

/// Block width of the fast path in the copy compiled for instruction-set level `S`
/// (`lbdem_core::simd::dispatch`): [`wide`] in the AVX-512 copy (or any copy of a build for an
/// AVX-512 CPU) and for f64 in the AVX2 copy; two registers per quantity otherwise, 16 f32 in the
/// AVX2 copy and 8 f32 or 4 f64 in the portable one (docs/performance.md, "The portable copy's LBM
/// blocks are narrower", has the paired benchmark behind the AVX2 choices). A block's width sets how many nodes share an instruction, never
/// what a lane computes, so every copy still gives the same bits. At the wide blocks the portable
/// copies were half this crate's machine code (7.3 of 15 MB, mostly spills of 32-node blocks
/// into 16 SSE registers) and the largest part of its build time, for a path only CPUs without
/// AVX2 take.
///
/// A lattice of more than nine directions (D3Q19) takes one register per quantity where the copy
/// has 256-bit vectors or wider: 19 populations of two or four registers each do not fit 16 AVX2
/// (or 32 AVX-512) registers; the spills held D3Q19 at 17-45 % of its bound (docs/lbm.md,
/// "D3Q19's block width").
#[inline(always)]
pub const fn block_width<T, S: Simd>(q: usize) -> usize {
    let reg = if NATIVE_V4 {
        64
    } else {
        std::mem::size_of::<S::f32s>()
    };
    if q > 9 && reg >= 32 {
        reg / std::mem::size_of::<T>()
    } else if reg >= 64 {
        wide::<T>()
    } else if reg >= 32 && std::mem::size_of::<T>() == 8 {
        // AVX2 f64: four registers per quantity, as with AVX-512; two ran at half the rate
        wide::<T>()
    } else {
        // two registers per quantity: AVX2 f32 (16 nodes, 11-21 % faster than 32) and SSE
        2 * if reg < 16 { 16 } else { reg } / std::mem::size_of::<T>()
    }
}

/// Evaluate `$call` with the constant `$wb` = [`block_width`]`::<T, S>(L::Q)` in scope (it names the
/// kernel's block width, e.g. `run_w::<L, T, C, F, WB>`). The branches are resolved before LLVM
/// (`const { }`), so each copy holds the kernel at its own width only.
macro_rules! at_block_width {
    ($l:ty, $t:ty, $s:ty, $wb:ident => $call:expr) => {
        if const { $crate::kernel::block_width::<$t, $s>(<$l as $crate::lattice::Lattice>::Q) == 32 } {
            const $wb: usize = 32;
            $call
        } else if const { $crate::kernel::block_width::<$t, $s>(<$l as $crate::lattice::Lattice>::Q) == 16 } {
            const $wb: usize = 16;
            $call
        } else if const { $crate::kernel::block_width::<$t, $s>(<$l as $crate::lattice::Lattice>::Q) == 8 } {
            const $wb: usize = 8;
            $call
        } else {
            const $wb: usize = 4;
            $call
        }
    };
}
pub(crate) use at_block_width;

/// Raw pointer that may cross threads; every use writes only rows that one task owns.
#[derive(Clone, Copy)]
pub struct SyncPtr<T>(pub *mut T);
unsafe impl<T> Send for SyncPtr<T> {}
unsafe impl<T> Sync for SyncPtr<T> {}

impl<T> SyncPtr<T> {
    /// Write `v` at offset `k`. Taking `self` whole keeps closures capturing the wrapper (which
    /// may cross threads) rather than its raw pointer field.
    ///
    /// # Safety
    /// `k` is inside the allocation, and no other thread reads or writes offset `k` meanwhile.
    #[inline(always)]
    pub unsafe fn write(self, k: usize, v: T) {
        unsafe { *self.0.add(k) = v };
    }
}

/// v + d on a periodic axis of n nodes, d in {-1, 0, 1} (compares, not a division: this runs
/// 2Q times per row).
#[inline(always)]
pub fn wrap(v: usize, d: i32, n: usize) -> usize {
    let s = v as isize + d as isize;
    if s < 0 {
        (s + n as isize) as usize
    } else if s >= n as isize {
        (s - n as isize) as usize
    } else {
        s as usize
    }
}

/// Accepted range of the macroscopic fields; outside it the run is stopped (see `Stepper`).
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Limits {
    pub rho_min: f64,
    pub rho_max: f64,
    pub u_max: f64,
}

impl Default for Limits {
    /// |u| < 0.4 (Ma ≈ 0.69): far beyond any accurate run (Su Eq. 16 asks Ma < 0.1); density
    /// within a factor 2 of the reference 1 (the constants of `lbdem_core::units::lattice`).
    fn default() -> Self {
        use lbdem_core::units::lattice::{RHO_MAX, RHO_MIN, U_MAX};
        Self {
            rho_min: RHO_MIN,
            rho_max: RHO_MAX,
            u_max: U_MAX,
        }
    }
}

impl Limits {
    /// True when a node of density `rho` and velocity `u` (f64) is within the limits and finite:
    /// the check of every code path that works in f64 (diagnosis, PSM lattice).
    #[inline]
    pub fn accepts(&self, rho: f64, u: [f64; 3]) -> bool {
        let speed = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
        rho.is_finite() && speed.is_finite() && rho > self.rho_min && rho < self.rho_max && speed < self.u_max
    }

    /// The limits in the storage precision: the per-node check is then three vector compares on
    /// ρ and |u|² as the collision computed them (a NaN fails every compare, so it is caught).
    pub fn in_precision<T: Real>(&self) -> LimitsT<T> {
        LimitsT {
            rho_min: T::from_f64(self.rho_min),
            rho_max: T::from_f64(self.rho_max),
            usq_max: T::from_f64(self.u_max * self.u_max),
        }
    }
}

/// `Limits` rounded to the storage precision (see `Limits::in_precision`).
#[derive(Clone, Copy, Debug)]
pub struct LimitsT<T> {
    pub rho_min: T,
    pub rho_max: T,
    pub usq_max: T,
}

impl<T: Real> LimitsT<T> {
    /// True when the node is within the limits (false for NaN).
    #[inline(always)]
    pub fn within(&self, rho: T, usq: T) -> bool {
        (rho > self.rho_min) & (rho < self.rho_max) & (usq < self.usq_max)
    }

    /// Bit w set when node w of a block (B <= 32) is outside the limits or not finite.
    #[inline(always)]
    pub fn bad_lanes<const B: usize>(&self, rho: &[T; B], usq: &[T; B]) -> u32 {
        T::bad_block(rho, usq, self.rho_min, self.rho_max, self.usq_max)
    }
}

/// Where the kernel writes ρ and u (f64, node order; u interleaved xyz) when asked.
#[derive(Clone, Copy)]
pub struct MacroOut {
    pub rho: SyncPtr<f64>,
    pub u: SyncPtr<f64>,
}

/// Everything a row needs, borrowed for one step.
pub struct Ctx<'a, T, C> {
    pub dom: &'a Domain,
    pub plan: &'a Plan,
    pub src: &'a [T],
    pub dst: SyncPtr<T>,
    /// The collision operator (uniform `CollideParams` or per-node `LocalRates`).
    pub coll: C,
    /// Motion of each obstacle, then of the six faces (velocity only).
    pub motions: &'a [Motion],
    pub limits: LimitsT<T>,
    pub out: Option<MacroOut>,
}

/// Update row `r` (y + ny z). Returns false if a node left the limits (or is not finite).
///
/// # Safety
/// `ctx.dst` (and `ctx.out`) must point to arrays of the right length, and no other thread may
/// write row `r` during the call.
#[inline(always)] // into each instruction-set level's copy (`lbdem_core::simd`)
pub unsafe fn row<L: Lattice, T: Real, C: Collider<L, T>, const F: bool, S: Simd>(
    ctx: &Ctx<T, C>,
    r: usize,
) -> bool {
    let dom = ctx.dom;
    let [nx, ny, _] = dom.n;
    let n = dom.len();
    let (y, z) = (r % ny, r / ny);
    let row_off = r * nx;
    let mut good = true;
    // upstream row offset of each direction (valid for fast spans only)
    let mut up_off = [0usize; QMAX];
    for (i, off) in up_off.iter_mut().enumerate().take(L::Q) {
        let c = L::C[i];
        let ys = wrap(y, -c[1], ny);
        let zs = wrap(z, -c[2], dom.n[2]);
        *off = i * n + (ys + ny * zs) * nx;
    }
    let plan = ctx.plan;
    // pull from x - c_i of the upstream row, write slot i of this row
    let mut src = [0usize; QMAX];
    let mut dst = [0usize; QMAX];
    for i in 0..L::Q {
        src[i] = up_off[i].wrapping_sub(L::C[i][0] as isize as usize);
        dst[i] = i * n + row_off;
    }
    for &(x0, x1) in &plan.spans[plan.span_start[r] as usize..plan.span_start[r + 1] as usize] {
        good &= unsafe {
            at_block_width!(L, T, S, WB => span::<L, T, C, F, WB>(ctx, &src, &dst, x0 as usize, x1 as usize, row_off))
        };
    }
    // periodic x edges with only fluid neighbours: the fast path with a wrapped x
    for &x in &plan.wraps[plan.wrap_start[r] as usize..plan.wrap_start[r + 1] as usize] {
        let x = x as usize;
        let mut f = [[T::default(); 1]; QMAX];
        for i in 0..L::Q {
            f[i][0] = ctx.src[up_off[i] + wrap(x, -L::C[i][0], nx)];
        }
        let m = C::collide::<1, F>(&ctx.coll, &mut f, row_off + x);
        for i in 0..L::Q {
            // SAFETY: row r is ours.
            unsafe { *ctx.dst.0.add(i * n + row_off + x) = f[i][0] };
        }
        good &= finish_block::<T, C, 1>(ctx, &m, row_off + x);
    }
    for &x in &plan.gens[plan.gen_start[r] as usize..plan.gen_start[r + 1] as usize] {
        good &= unsafe { general_node::<L, T, C, F>(ctx, [x as usize, y, z]) };
    }
    good
}

/// Nodes [x0, x1) of a fast span in blocks of `WB`, the rest in one block each of 16, 8, 4, 2, 1
/// nodes at most (those narrower than `WB`; as `kernel_aa::run`).
///
/// # Safety
/// As `block`.
#[inline(always)]
unsafe fn span<L: Lattice, T: Real, C: Collider<L, T>, const F: bool, const WB: usize>(
    ctx: &Ctx<T, C>,
    src: &[usize; QMAX],
    dst: &[usize; QMAX],
    x0: usize,
    x1: usize,
    row_off: usize,
) -> bool {
    let mut good = true;
    // block scratch, reused (zeroing it per block would cost more than the loads)
    let mut f = [[T::default(); WB]; QMAX];
    let mut x = x0;
    while x + WB <= x1 {
        good &= unsafe { block::<L, T, C, WB, F>(ctx, &mut f, src, dst, x, row_off + x) };
        x += WB;
    }
    macro_rules! tail {
        ($b:literal) => {
            // not compiled at all where the block is narrower (`const { }`)
            if const { $b < WB } && $b <= x1 - x {
                let mut g = [[T::default(); $b]; QMAX];
                good &= unsafe { block::<L, T, C, $b, F>(ctx, &mut g, src, dst, x, row_off + x) };
                x += $b;
            }
        };
    }
    tail!(16);
    tail!(8);
    tail!(4);
    tail!(2);
    tail!(1);
    debug_assert_eq!(x, x1);
    good
}

/// Pull `B` consecutive nodes from `src[i] + x`, collide, write `dst[i] + x`; false if a node left
/// the limits.
///
/// # Safety
/// `src[i] + x + B <= Q n` (fast spans only) and the destination nodes belong to the calling row.
#[inline(always)]
unsafe fn block<L: Lattice, T: Real, C: Collider<L, T>, const B: usize, const F: bool>(
    ctx: &Ctx<T, C>,
    f: &mut [[T; B]; QMAX],
    src: &[usize; QMAX],
    dst: &[usize; QMAX],
    x: usize,
    node: usize,
) -> bool {
    for i in 0..L::Q {
        let s = src[i].wrapping_add(x);
        f[i].copy_from_slice(&ctx.src[s..s + B]);
    }
    let m = C::collide::<B, F>(&ctx.coll, f, node);
    for i in 0..L::Q {
        // SAFETY: caller's contract.
        unsafe { std::ptr::copy_nonoverlapping(f[i].as_ptr(), ctx.dst.0.add(dst[i] + x), B) };
    }
    finish_block::<T, C, B>(ctx, &m, node)
}

#[inline(always)]
fn finish_block<T: Real, C, const B: usize>(ctx: &Ctx<T, C>, m: &Moments<T, B>, idx0: usize) -> bool {
    let good = ctx.limits.bad_lanes(&m.rho, &m.usq) == 0;
    if let Some(o) = ctx.out {
        for w in 0..B {
            let idx = idx0 + w;
            // SAFETY: node idx is in this task's row.
            unsafe {
                *o.rho.0.add(idx) = m.rho[w].to_f64();
                for a in 0..3 {
                    *o.u.0.add(3 * idx + a) = m.u[a][w].to_f64();
                }
            }
        }
    }
    good
}

/// One node next to a wall, an obstacle, a non-periodic face or a periodic x edge.
unsafe fn general_node<L: Lattice, T: Real, C: Collider<L, T>, const F: bool>(
    ctx: &Ctx<T, C>,
    p: [usize; 3],
) -> bool {
    let dom = ctx.dom;
    let n = dom.len();
    let idx = dom.index(p[0], p[1], p[2]);
    let mut f = [[T::default(); 1]; QMAX];
    let mut missing = 0u32;
    let n_obst = ctx.motions.len() - 6;
    for i in 0..L::Q {
        let c = L::C[i];
        let bounce = |wall_u: [f64; 3]| {
            // Leonardi Eq. 19 in pull form, reference density 1
            let cu = c[0] as f64 * wall_u[0] + c[1] as f64 * wall_u[1] + c[2] as f64 * wall_u[2];
            ctx.src[L::OPP[i] * n + idx] + T::from_f64(6.0 * L::W[i] * cu)
        };
        match neighbour(dom, p, [-c[0], -c[1], -c[2]]) {
            Upstream::Node(s) if dom.kind[s] == FLUID => f[i][0] = ctx.src[i * n + s],
            Upstream::Node(s) => {
                let id = dom.obstacle[s];
                let uw = if (id as usize) < n_obst {
                    let m = &ctx.motions[id as usize];
                    let mid = [
                        p[0] as f64 - 0.5 * c[0] as f64,
                        p[1] as f64 - 0.5 * c[1] as f64,
                        p[2] as f64 - 0.5 * c[2] as f64,
                    ];
                    m.velocity_at(dom.offset(m.centre, mid))
                } else {
                    [0.0; 3]
                };
                f[i][0] = bounce(uw);
            }
            Upstream::Face(fc) => match dom.faces[fc] {
                Face::Wall { velocity } => f[i][0] = bounce(velocity),
                _ => missing |= 1 << i,
            },
        }
    }
    if missing != 0 {
        let face = (0..4usize).find(|&fc| {
            let a = fc / 2;
            let on = if fc.is_multiple_of(2) {
                p[a] == 0
            } else {
                p[a] + 1 == dom.n[a]
            };
            on && dom.faces[fc].is_zou_he()
        });
        match face {
            Some(fc) => zouhe::apply::<L, T>(&mut f, fc, &dom.faces[fc], missing),
            None => {
                for i in 0..L::Q {
                    if missing & (1 << i) != 0 {
                        f[i][0] = f[L::OPP[i]][0];
                    }
                }
            }
        }
    }
    let m = C::collide::<1, F>(&ctx.coll, &mut f, idx);
    for i in 0..L::Q {
        unsafe { *ctx.dst.0.add(i * n + idx) = f[i][0] };
    }
    finish_block::<T, C, 1>(ctx, &m, idx)
}
