//! In-place AA-pattern stream-collide (Bailey et al., ICPP 2009) over one structure-of-arrays
//! population array: half the memory traffic of the two-array pull kernel (no second array, no
//! write-allocate), the way lbmpy's fastest variant works.
//!
//! The array alternates between two layouts. "Reversed": slot `opp(i)` of node x holds the
//! post-collision f_i(x) (what the two-array kernel keeps in slot i). An odd step (`odd_row`)
//! gathers f_i(y) from slot `opp(i)` of y − c_i (or, across a wall, slot i of y itself plus the
//! moving-wall term of Leonardi Eq. 19), collides, and scatters f_i to slot i of y + c_i (or,
//! towards a wall, to slot opp(i) of y with the wall term): the array is then "natural", slot i of
//! x = pre-collision f_i(x). An even step (`even_row`) is purely local: read slot i, collide, write
//! slot opp(i): back to "reversed". Each node reads and writes exactly the same set of slots, so
//! nodes are independent and rows can run on any thread. The bounce-back arithmetic is written
//! exactly as in the two-array kernel, so both give bitwise-identical results.

use crate::collision::{Collider, Moments};
use crate::domain::{Domain, FLUID, Motion};
use crate::kernel::{LimitsT, MacroOut, SyncPtr, at_block_width, wrap};
use crate::lattice::{Lattice, QMAX};
use crate::layout::Layout;
use crate::plan::{Plan, Upstream, neighbour};
use crate::real::Real;
use crate::storage::Storage;
use lbdem_core::simd::Simd;

/// First node of a row that left the limits: (x, ρ, u).
pub type Bad = Option<(usize, f64, [f64; 3])>;

pub struct CtxAa<'a, T, C, St = T> {
    pub dom: &'a Domain,
    pub plan: &'a Plan,
    /// The single population array (read and written through raw pointers only), in `layout`,
    /// stored as `St` (`storage`: the values themselves or their shifted, narrower form).
    pub f: SyncPtr<St>,
    pub layout: Layout,
    /// The collision operator (uniform `CollideParams` or per-node `LocalRates`).
    pub coll: C,
    pub motions: &'a [Motion],
    pub limits: LimitsT<T>,
    pub out: Option<MacroOut>,
}

/// Range check of a block of `B` nodes starting at node `idx0` (and the macroscopic output).
#[inline(always)]
fn check<T: Real, C, St, const B: usize>(
    ctx: &CtxAa<T, C, St>,
    m: &Moments<T, B>,
    idx0: usize,
    bad: &mut Bad,
) {
    let bits = ctx.limits.bad_lanes(&m.rho, &m.usq);
    if bits != 0 {
        keep_lowest_x(bad, first_bad(ctx, m, idx0, bits));
    }
    if let Some(o) = ctx.out {
        for w in 0..B {
            let idx = idx0 + w;
            // SAFETY: node idx belongs to the calling row.
            unsafe {
                *o.rho.0.add(idx) = m.rho[w].to_f64();
                for a in 0..3 {
                    *o.u.0.add(3 * idx + a) = m.u[a][w].to_f64();
                }
            }
        }
    }
}

/// Keep the flagged node of lowest x of the row (rows are processed spans first, then periodic
/// edges, then general nodes): the node the two-array stepper's row scan reports.
#[cold]
#[inline(never)]
fn keep_lowest_x(bad: &mut Bad, cand: Bad) {
    if let Some(c) = cand
        && bad.is_none_or(|b| c.0 < b.0)
    {
        *bad = Some(c);
    }
}

/// The first node of a block flagged in `bits`, for the diagnosis (rare: kept out of line).
#[cold]
#[inline(never)]
fn first_bad<T: Real, C, St, const B: usize>(
    ctx: &CtxAa<T, C, St>,
    m: &Moments<T, B>,
    idx0: usize,
    bits: u32,
) -> Bad {
    let w = bits.trailing_zeros() as usize;
    let u = [m.u[0][w].to_f64(), m.u[1][w].to_f64(), m.u[2][w].to_f64()];
    Some(((idx0 + w) % ctx.dom.n[0], m.rho[w].to_f64(), u))
}

/// Even step of row `r`: local collide, slot i -> slot opp(i), over every fluid run of the row.
///
/// # Safety
/// `ctx.f` must hold Q `ctx.layout.stride` values; no other thread may touch the nodes of row `r`.
#[inline(always)] // into each instruction-set level's copy (`lbdem_core::simd`)
pub unsafe fn even_row<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>, const F: bool, S: Simd>(
    ctx: &CtxAa<T, C, St>,
    r: usize,
) -> Bad {
    let dom = ctx.dom;
    let nx = dom.n[0];
    let n = ctx.layout.stride;
    // node index of x = 0 (macroscopic output, diagnosis) and its slot in the padded array
    let row_off = r * nx;
    let slot_off = r * ctx.layout.nxp;
    let mut bad = None;
    let plan = ctx.plan;
    // slot i -> slot opp(i) of the same node
    let mut src = [0usize; QMAX];
    let mut dst = [0usize; QMAX];
    for i in 0..L::Q {
        src[i] = i * n + slot_off;
        dst[i] = L::OPP[i] * n + slot_off;
    }
    for &(x0, x1) in &plan.runs[plan.run_start[r] as usize..plan.run_start[r + 1] as usize] {
        unsafe { run::<L, T, St, C, F, S>(ctx, &src, &dst, x0 as usize, x1 as usize, row_off, &mut bad) };
    }
    bad
}

/// Gather `B` consecutive nodes from slots `src[i] + x`, collide, scatter to `dst[i] + x`, check.
///
/// # Safety
/// The slots must be in bounds and belong to nodes of the calling row (module doc).
#[inline(always)]
unsafe fn block<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>, const B: usize, const F: bool>(
    ctx: &CtxAa<T, C, St>,
    f: &mut [[T; B]; QMAX],
    src: &[usize; QMAX],
    dst: &[usize; QMAX],
    x: usize,
    node: usize,
    bad: &mut Bad,
) {
    unsafe { St::gather::<L, B>(ctx.f.0, src, x, f) };
    let m = C::collide::<B, F>(&ctx.coll, f, node);
    unsafe { St::scatter::<L, B>(ctx.f.0, dst, x, f) };
    check::<T, C, St, B>(ctx, &m, node, bad);
}

/// Nodes [x0, x1) of a row in blocks of `kernel::block_width::<T, S>(L::Q)` nodes (one to four
/// registers per quantity, by lattice and level), the rest in one block each
/// of 16, 8, 4, 2 and 1 nodes at most (narrower vectors instead of up to 31 scalar nodes).
///
/// # Safety
/// As `block`.
#[inline(always)]
unsafe fn run<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>, const F: bool, S: Simd>(
    ctx: &CtxAa<T, C, St>,
    src: &[usize; QMAX],
    dst: &[usize; QMAX],
    x0: usize,
    x1: usize,
    node_off: usize,
    bad: &mut Bad,
) {
    unsafe {
        at_block_width!(L, T, S, WB => run_w::<L, T, St, C, F, WB>(ctx, src, dst, x0, x1, node_off, bad))
    }
}

#[inline(always)]
unsafe fn run_w<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>, const F: bool, const WB: usize>(
    ctx: &CtxAa<T, C, St>,
    src: &[usize; QMAX],
    dst: &[usize; QMAX],
    x0: usize,
    x1: usize,
    node_off: usize,
    bad: &mut Bad,
) {
    // block scratch, reused (zeroing it per block would cost more than the loads)
    let mut f = [[T::default(); WB]; QMAX];
    let mut x = x0;
    while x + WB <= x1 {
        unsafe { block::<L, T, St, C, WB, F>(ctx, &mut f, src, dst, x, node_off + x, bad) };
        x += WB;
    }
    macro_rules! tail {
        ($b:literal) => {
            // not compiled at all where the block is narrower (`const { }`)
            if const { $b < WB } && $b <= x1 - x {
                let mut g = [[T::default(); $b]; QMAX];
                unsafe { block::<L, T, St, C, $b, F>(ctx, &mut g, src, dst, x, node_off + x, bad) };
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
}

/// Odd step of row `r`: gather from neighbours, collide, scatter to neighbours.
///
/// # Safety
/// As `even_row`; the slots a node touches are its own (see the module doc), so rows may run
/// concurrently.
#[inline(always)] // into each instruction-set level's copy (`lbdem_core::simd`)
pub unsafe fn odd_row<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>, const F: bool, S: Simd>(
    ctx: &CtxAa<T, C, St>,
    r: usize,
) -> Bad {
    let dom = ctx.dom;
    let [nx, ny, nz] = dom.n;
    let n = ctx.layout.stride;
    let nxp = ctx.layout.nxp;
    let (y, z) = (r % ny, r / ny);
    let row_off = r * nx;
    let mut bad = None;
    let mut up = [0usize; QMAX];
    let mut down = [0usize; QMAX];
    // the same without the x offset (periodic-edge nodes add their wrapped x)
    let mut up_row = [0usize; QMAX];
    let mut down_row = [0usize; QMAX];
    for i in 0..L::Q {
        let c = L::C[i];
        let row_of = |s: i32| (wrap(y, s * c[1], ny) + ny * wrap(z, s * c[2], nz)) * nxp;
        // read slot opp(i) of y - c_i; write slot i of y + c_i
        up_row[i] = L::OPP[i] * n + row_of(-1);
        down_row[i] = i * n + row_of(1);
        up[i] = up_row[i].wrapping_sub(c[0] as isize as usize);
        down[i] = down_row[i].wrapping_add(c[0] as isize as usize);
    }
    let plan = ctx.plan;
    for &(x0, x1) in &plan.spans[plan.span_start[r] as usize..plan.span_start[r + 1] as usize] {
        unsafe { run::<L, T, St, C, F, S>(ctx, &up, &down, x0 as usize, x1 as usize, row_off, &mut bad) };
    }
    for &x in &plan.wraps[plan.wrap_start[r] as usize..plan.wrap_start[r + 1] as usize] {
        let x = x as usize;
        let mut f = [[T::default(); 1]; QMAX];
        for (i, fi) in f.iter_mut().enumerate().take(L::Q) {
            fi[0] = unsafe { St::load::<L>(ctx.f.0, up_row[i] + wrap(x, -L::C[i][0], nx), L::OPP[i]) };
        }
        let m = C::collide::<1, F>(&ctx.coll, &mut f, row_off + x);
        for (i, fi) in f.iter().enumerate().take(L::Q) {
            unsafe { St::store::<L>(ctx.f.0, down_row[i] + wrap(x, L::C[i][0], nx), i, fi[0]) };
        }
        check::<T, C, St, 1>(ctx, &m, row_off + x, &mut bad);
    }
    for &x in &plan.gens[plan.gen_start[r] as usize..plan.gen_start[r + 1] as usize] {
        unsafe { odd_general::<L, T, St, C, F>(ctx, [x as usize, y, z], &mut bad) };
    }
    bad
}

/// Wall velocity at the link midpoint p + s c/2 towards a solid node `s_idx` (obstacle or inactive).
fn wall_velocity<T: Real, C, St>(
    ctx: &CtxAa<T, C, St>,
    p: [usize; 3],
    c: [i32; 3],
    sign: f64,
    s_idx: usize,
) -> [f64; 3] {
    let dom = ctx.dom;
    let id = dom.obstacle[s_idx] as usize;
    if id < ctx.motions.len() - 6 {
        let m = &ctx.motions[id];
        let mid = [0, 1, 2].map(|a| p[a] as f64 + sign * 0.5 * c[a] as f64);
        m.velocity_at(dom.offset(m.centre, mid))
    } else {
        [0.0; 3]
    }
}

unsafe fn odd_general<L: Lattice, T: Real, St: Storage<T>, C: Collider<L, T>, const F: bool>(
    ctx: &CtxAa<T, C, St>,
    p: [usize; 3],
    bad: &mut Bad,
) {
    let dom = ctx.dom;
    let lay = &ctx.layout;
    let idx = dom.index(p[0], p[1], p[2]);
    let n_obst = ctx.motions.len() - 6;
    let dotw = |i: usize, u: [f64; 3]| {
        let c = L::C[i];
        6.0 * L::W[i] * (c[0] as f64 * u[0] + c[1] as f64 * u[1] + c[2] as f64 * u[2])
    };
    let face_velocity = |fc: usize| ctx.motions[n_obst + fc].velocity;
    let mut f = [[T::default(); 1]; QMAX];
    for (i, fi) in f.iter_mut().enumerate().take(L::Q) {
        let c = L::C[i];
        // SAFETY (all raw accesses): indices in bounds; slots owned by this node.
        fi[0] = match neighbour(dom, p, [-c[0], -c[1], -c[2]]) {
            Upstream::Node(s) if dom.kind[s] == FLUID => unsafe {
                St::load::<L>(ctx.f.0, lay.slot(L::OPP[i], s), L::OPP[i])
            },
            Upstream::Node(s) => {
                let uw = wall_velocity(ctx, p, c, -1.0, s);
                unsafe { St::load::<L>(ctx.f.0, lay.slot(i, idx), i) + T::from_f64(dotw(i, uw)) }
            }
            Upstream::Face(fc) => unsafe {
                St::load::<L>(ctx.f.0, lay.slot(i, idx), i) + T::from_f64(dotw(i, face_velocity(fc)))
            },
        };
    }
    let m = C::collide::<1, F>(&ctx.coll, &mut f, idx);
    for (i, fi) in f.iter().enumerate().take(L::Q) {
        let c = L::C[i];
        let o = L::OPP[i];
        match neighbour(dom, p, c) {
            Upstream::Node(s) if dom.kind[s] == FLUID => unsafe {
                St::store::<L>(ctx.f.0, lay.slot(i, s), i, fi[0])
            },
            Upstream::Node(s) => {
                let uw = wall_velocity(ctx, p, c, 1.0, s);
                unsafe { St::store::<L>(ctx.f.0, lay.slot(o, idx), o, fi[0] + T::from_f64(dotw(o, uw))) }
            }
            Upstream::Face(fc) => unsafe {
                St::store::<L>(
                    ctx.f.0,
                    lay.slot(o, idx),
                    o,
                    fi[0] + T::from_f64(dotw(o, face_velocity(fc))),
                )
            },
        }
    }
    check::<T, C, St, 1>(ctx, &m, idx, bad);
}
