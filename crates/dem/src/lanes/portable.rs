//! The eight lanes as plain arrays the compiler vectorises: the portable lane type, compiled
//! into every instruction-set level of `lbdem_core::simd` (`crate::on_arrays`).

use super::W;
use crate::contact::History;
use crate::scratch::CircleState;

#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct F8([f64; W]);

/// Lane mask: all ones (true) or zero.
#[derive(Clone, Copy)]
#[repr(C, align(64))]
pub(crate) struct M8([u64; W]);

macro_rules! lanewise {
    ($tr:ident, $f:ident, $op:tt) => {
        impl std::ops::$tr for F8 {
            type Output = F8;
            #[inline(always)]
            fn $f(self, o: F8) -> F8 {
                F8(std::array::from_fn(|k| self.0[k] $op o.0[k]))
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

impl std::ops::Neg for F8 {
    type Output = F8;
    #[inline(always)]
    fn neg(self) -> F8 {
        F8(self.0.map(|v| -v))
    }
}

impl F8 {
    #[inline(always)]
    pub(crate) fn splat(v: f64) -> F8 {
        F8([v; W])
    }
    #[inline(always)]
    pub(crate) fn from_array(a: [f64; W]) -> F8 {
        F8(a)
    }
    #[inline(always)]
    pub(crate) fn to_array(self) -> [f64; W] {
        self.0
    }
    #[inline(always)]
    pub(crate) fn sqrt(self) -> F8 {
        F8(self.0.map(f64::sqrt))
    }
    #[inline(always)]
    pub(crate) fn abs(self) -> F8 {
        F8(self.0.map(f64::abs))
    }
    /// `f64::max(self, 0.0)` per lane.
    #[inline(always)]
    pub(crate) fn max0(self) -> F8 {
        F8(self.0.map(|v| v.max(0.0)))
    }
    /// Magnitude of self with the sign of `s`.
    #[inline(always)]
    pub(crate) fn copysign(self, s: F8) -> F8 {
        F8(std::array::from_fn(|k| self.0[k].copysign(s.0[k])))
    }
    #[inline(always)]
    pub(crate) fn lt(self, o: F8) -> M8 {
        M8(std::array::from_fn(|k| if self.0[k] < o.0[k] { !0 } else { 0 }))
    }
    #[inline(always)]
    pub(crate) fn gt(self, o: F8) -> M8 {
        M8(std::array::from_fn(|k| if self.0[k] > o.0[k] { !0 } else { 0 }))
    }
    #[inline(always)]
    pub(crate) fn ge(self, o: F8) -> M8 {
        M8(std::array::from_fn(|k| if self.0[k] >= o.0[k] { !0 } else { 0 }))
    }
    #[inline(always)]
    pub(crate) fn le(self, o: F8) -> M8 {
        M8(std::array::from_fn(|k| if self.0[k] <= o.0[k] { !0 } else { 0 }))
    }
    /// Lanes where self != o, NaN included (Rust's `!=`).
    #[inline(always)]
    pub(crate) fn ne(self, o: F8) -> M8 {
        M8(std::array::from_fn(|k| if self.0[k] != o.0[k] { !0 } else { 0 }))
    }
    /// Lanes that are not in [lo, hi) (NaN included).
    #[inline(always)]
    pub(crate) fn outside(self, lo: F8, hi: F8) -> M8 {
        M8(std::array::from_fn(|k| {
            if !(self.0[k] >= lo.0[k] && self.0[k] < hi.0[k]) {
                !0
            } else {
                0
            }
        }))
    }
}

/// x and y lanes of eight (x, y) pairs.
#[inline(always)]
pub(crate) fn deinterleave(p: &[[f64; 2]; W]) -> (F8, F8) {
    (F8(p.map(|q| q[0])), F8(p.map(|q| q[1])))
}

/// Inverse of [`deinterleave`].
#[inline(always)]
pub(crate) fn interleave(x: F8, y: F8, p: &mut [[f64; 2]; W]) {
    for (k, q) in p.iter_mut().enumerate() {
        *q = [x.0[k], y.0[k]];
    }
}

/// 8 x 8 transpose (lanes of column k become row k).
#[inline(always)]
pub(crate) fn transpose(r: [F8; W]) -> [[f64; W]; W] {
    std::array::from_fn(|k| std::array::from_fn(|f| r[f].0[k]))
}

impl M8 {
    /// `a` where the mask is set, else `b`.
    #[inline(always)]
    pub(crate) fn select(self, a: F8, b: F8) -> F8 {
        F8(std::array::from_fn(|k| {
            f64::from_bits((a.0[k].to_bits() & self.0[k]) | (b.0[k].to_bits() & !self.0[k]))
        }))
    }
    #[inline(always)]
    pub(crate) fn bit(self, k: usize) -> bool {
        self.0[k] != 0
    }
    /// Any lane set.
    #[inline(always)]
    pub(crate) fn any(self) -> bool {
        self.0.iter().any(|&m| m != 0)
    }
    #[inline(always)]
    pub(crate) fn and(self, o: M8) -> M8 {
        M8(std::array::from_fn(|k| self.0[k] & o.0[k]))
    }
    #[inline(always)]
    pub(crate) fn or(self, o: M8) -> M8 {
        M8(std::array::from_fn(|k| self.0[k] | o.0[k]))
    }
    #[inline(always)]
    pub(crate) fn not(self) -> M8 {
        M8(self.0.map(|m| !m))
    }
}

/// Columns 0..7 of the eight lines `cst[idx[k]]`.
#[inline(always)]
pub(crate) fn transpose8(cst: &[CircleState], idx: &[usize; W]) -> [F8; 8] {
    let rows: [[f64; W]; W] = std::array::from_fn(|k| cst[idx[k]].line());
    std::array::from_fn(|f| F8(std::array::from_fn(|k| rows[k][f])))
}

/// The sixteen columns of the eight sphere lines `lines[idx[k]]`.
#[inline(always)]
pub(crate) fn transpose16(lines: &[crate::spheres::hm_batched::SphereLine], idx: &[usize; W]) -> [F8; 16] {
    let rows: [&[f64; 16]; W] = std::array::from_fn(|k| &lines[idx[k]].0);
    std::array::from_fn(|f| F8(std::array::from_fn(|k| rows[k][f])))
}

/// x, y and z lanes of eight packed (x, y, z) records.
#[inline(always)]
pub(crate) fn load3(p: &[[f64; 3]; W]) -> [F8; 3] {
    std::array::from_fn(|c| F8(std::array::from_fn(|k| p[k][c])))
}

/// The inverse of [`load3`].
#[inline(always)]
pub(crate) fn store3(p: &mut [[f64; 3]; W], v: [F8; 3]) {
    for (k, rec) in p.iter_mut().enumerate() {
        *rec = [v[0].0[k], v[1].0[k], v[2].0[k]];
    }
}

/// Tangential elongations of eight histories, and their other two fields.
#[inline(always)]
pub(crate) fn hist_load(h: &[History; W]) -> (F8, F8, [F8; 2]) {
    (
        F8(std::array::from_fn(|k| h[k].xi_t.x)),
        F8(std::array::from_fn(|k| h[k].xi_t.y)),
        [
            F8(std::array::from_fn(|k| h[k].theta_r)),
            F8(std::array::from_fn(|k| h[k].delta_p)),
        ],
    )
}

/// Eight records of four f64 from four lane vectors (the inverse of [`hist_load`]).
#[inline(always)]
pub(crate) fn store4(h: &mut [[f64; 4]; W], v: [F8; 4]) {
    let v = v.map(|x| x.0);
    for (k, rec) in h.iter_mut().enumerate() {
        *rec = [v[0][k], v[1][k], v[2][k], v[3][k]];
    }
}
