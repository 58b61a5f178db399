//! The opening half kick, drift, periodic wrap and circle lines of eight disks at a time (the
//! all-disk path of the stepper). The same IEEE operations in the same order as the scalar loop
//! in `stepper/kick.rs` (same bits); a batch in which a disk left the box by more than one length is
//! left to that loop.

use crate::domain::Domain;
use crate::lanes::W;
use crate::scratch::CircleState;
use crate::vector::Vec2;
use lbdem_core::simd::Simd;
#[cfg(test)]
use lbdem_core::simd::{self, WithSimd};

/// Box constants of one pass.
pub(crate) struct DiskKick {
    pub(crate) dt: f64,
    pub(crate) lo: [f64; 2],
    pub(crate) hi: [f64; 2],
    pub(crate) len: [f64; 2],
    /// Half box length on periodic axes, infinite on open ones (no minimum-image shift).
    pub(crate) half: [f64; 2],
    pub(crate) periodic: [bool; 2],
}

/// The state of eight disks the pass reads and writes.
pub(crate) struct Eight<'a> {
    pub x: &'a mut [Vec2; W],
    pub v: &'a mut [Vec2; W],
    pub a: &'a mut [f64; W],
    pub w: &'a mut [f64; W],
    pub st: &'a mut [CircleState; W],
    pub f: &'a [Vec2; W],
    pub t: &'a [f64; W],
    pub r: &'a [f64; W],
    pub m: &'a [f64; W],
    pub refp: &'a [Vec2; W],
    /// h/m and h/I of the eight disks.
    pub hm: [f64; W],
    pub hi: [f64; W],
}

#[inline(always)]
pub(crate) fn pairs(v: &[Vec2; W]) -> &[[f64; 2]; W] {
    // SAFETY: Vec2 is repr(C): two f64, no padding.
    unsafe { &*(v as *const [Vec2; W]).cast::<[[f64; 2]; W]>() }
}

#[inline(always)]
pub(crate) fn pairs_mut(v: &mut [Vec2; W]) -> &mut [[f64; 2]; W] {
    // SAFETY: as above.
    unsafe { &mut *(v as *mut [Vec2; W]).cast::<[[f64; 2]; W]>() }
}

impl DiskKick {
    pub(crate) fn new(dom: &Domain, dt: f64) -> Self {
        let l = dom.size();
        let half = |p: bool, v: f64| if p { 0.5 * v } else { f64::INFINITY };
        Self {
            dt,
            lo: [dom.lo.x, dom.lo.y],
            hi: [dom.hi.x, dom.hi.y],
            len: [l.x, l.y],
            half: [half(dom.periodic[0], l.x), half(dom.periodic[1], l.y)],
            periodic: dom.periodic,
        }
    }

    /// Kick, drift and lines of eight disks; the largest squared displacement since the list
    /// build (NaN if any is NaN), or None (nothing written) if a disk must take the far wrap.
    /// Dispatched on its own (the tests); the stepper calls [`DiskKick::eight_in`] inside its
    /// dispatched pass.
    #[cfg(test)]
    pub(crate) fn eight(&self, e: Eight<'_>) -> Option<f64> {
        simd::dispatch(EightOp { k: self, e })
    }

    /// [`DiskKick::eight`] inside an op dispatched at level `S`: the AVX-512 lanes in the v4
    /// copy, the AVX2 lanes in the v3 copy, the array lanes in the baseline copy.
    #[inline(always)]
    pub(crate) fn eight_in<S: Simd>(&self, e: Eight<'_>) -> Option<f64> {
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx512_in::<S>() {
            return crate::on_avx512::kick::eight(self, e);
        }
        #[cfg(target_arch = "x86_64")]
        if crate::lanes::avx2_in::<S>() {
            return crate::on_avx2::kick::eight(self, e);
        }
        crate::on_arrays::kick::eight(self, e)
    }
}

#[cfg(test)]
struct EightOp<'a, 'b> {
    k: &'a DiskKick,
    e: Eight<'b>,
}

#[cfg(test)]
impl WithSimd for EightOp<'_, '_> {
    type Output = Option<f64>;
    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) -> Option<f64> {
        self.k.eight_in::<S>(self.e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scalar loop of `Stepper::kick_drift_disks`, for one disk.
    #[allow(clippy::too_many_arguments)]
    fn scalar(
        dom: &Domain,
        dt: f64,
        x: &mut Vec2,
        v: &mut Vec2,
        a: &mut f64,
        w: &mut f64,
        f: Vec2,
        t: f64,
        hm: f64,
        hi: f64,
        refp: Vec2,
    ) -> f64 {
        *v += f * hm;
        *w += t * hi;
        *x = dom.wrap(*x + *v * dt);
        *a += *w * dt;
        crate::vector::Vector::norm2(dom.min_image(*x - refp))
    }

    /// Eight disks, some crossing the periodic boundary, against the scalar loop bit for bit.
    #[test]
    fn eight_disks_match_scalar_loop() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for periodic in [[true, true], [false, true], [false, false]] {
            let dom = Domain {
                lo: Vec2::new(-1.0, 2.0),
                hi: Vec2::new(3.0, 5.5),
                periodic,
            };
            for _ in 0..200 {
                let p =
                    |r: &mut dyn FnMut() -> f64| Vec2::new(-1.0 + 4.0 * (r() + 0.5), 2.0 + 3.5 * (r() + 0.5));
                let mut x: [Vec2; W] = std::array::from_fn(|_| p(&mut rnd));
                let mut v: [Vec2; W] = std::array::from_fn(|_| Vec2::new(40.0 * rnd(), 40.0 * rnd()));
                let mut a: [f64; W] = std::array::from_fn(|_| rnd());
                let mut w: [f64; W] = std::array::from_fn(|_| rnd());
                let f: [Vec2; W] = std::array::from_fn(|_| Vec2::new(rnd(), rnd()));
                let t: [f64; W] = std::array::from_fn(|_| rnd());
                let r: [f64; W] = std::array::from_fn(|_| rnd() + 1.0);
                let m: [f64; W] = std::array::from_fn(|_| rnd() + 2.0);
                let refp: [Vec2; W] = std::array::from_fn(|_| p(&mut rnd));
                let hm: [f64; W] = std::array::from_fn(|_| rnd());
                let hi: [f64; W] = std::array::from_fn(|_| rnd());
                let dt = 0.01;
                let (mut xs, mut vs, mut as_, mut ws) = (x, v, a, w);
                let mut worst = 0.0;
                for k in 0..W {
                    let d = scalar(
                        &dom,
                        dt,
                        &mut xs[k],
                        &mut vs[k],
                        &mut as_[k],
                        &mut ws[k],
                        f[k],
                        t[k],
                        hm[k],
                        hi[k],
                        refp[k],
                    );
                    worst = crate::scratch::nan_max(worst, d);
                }
                // The array lane copy on the same inputs: the machine's own path (AVX-512
                // here) is checked below, this one must give the same bits too.
                let (mut x2, mut v2, mut a2, mut w2) = (x, v, a, w);
                let mut st2 = [CircleState::default(); W];
                let got2 = crate::on_arrays::kick::eight(
                    &DiskKick::new(&dom, dt),
                    Eight {
                        x: &mut x2,
                        v: &mut v2,
                        a: &mut a2,
                        w: &mut w2,
                        st: &mut st2,
                        f: &f,
                        t: &t,
                        r: &r,
                        m: &m,
                        refp: &refp,
                        hm,
                        hi,
                    },
                );
                let mut st = [CircleState::default(); W];
                let got = DiskKick::new(&dom, dt).eight(Eight {
                    x: &mut x,
                    v: &mut v,
                    a: &mut a,
                    w: &mut w,
                    st: &mut st,
                    f: &f,
                    t: &t,
                    r: &r,
                    m: &m,
                    refp: &refp,
                    hm,
                    hi,
                });
                let bits = |p: &[Vec2; W]| p.map(|q| (q.x.to_bits(), q.y.to_bits()));
                assert_eq!(got.map(f64::to_bits), Some(worst.to_bits()));
                assert_eq!(bits(&x), bits(&xs));
                assert_eq!(bits(&v), bits(&vs));
                assert_eq!(a.map(f64::to_bits), as_.map(f64::to_bits));
                assert_eq!(w.map(f64::to_bits), ws.map(f64::to_bits));
                assert_eq!(got2.map(f64::to_bits), Some(worst.to_bits()), "array lanes");
                assert_eq!(bits(&x2), bits(&xs), "array lanes");
                assert_eq!(bits(&v2), bits(&vs), "array lanes");
                assert_eq!(a2.map(f64::to_bits), as_.map(f64::to_bits), "array lanes");
                assert_eq!(w2.map(f64::to_bits), ws.map(f64::to_bits), "array lanes");
                for k in 0..W {
                    assert_eq!((st2[k].pos, st2[k].vel, st2[k].omega), (xs[k], vs[k], ws[k]));
                }
                for k in 0..W {
                    assert_eq!((st[k].pos, st[k].vel, st[k].omega), (xs[k], vs[k], ws[k]));
                    assert_eq!((st[k].r, st[k].mass), (r[k], m[k]));
                }
            }
        }
    }

    /// A disk that leaves the box by more than one length is left to the scalar loop.
    #[test]
    fn far_jump_is_refused() {
        let dom = Domain::periodic(Vec2::ZERO, Vec2::new(1.0, 1.0));
        let mut x = [Vec2::new(0.5, 0.5); W];
        let mut v = [Vec2::ZERO; W];
        v[3] = Vec2::new(500.0, 0.0);
        let x0 = x;
        let (mut a, mut w, mut st) = ([0.0; W], [0.0; W], [CircleState::default(); W]);
        let got = DiskKick::new(&dom, 0.01).eight(Eight {
            x: &mut x,
            v: &mut v,
            a: &mut a,
            w: &mut w,
            st: &mut st,
            f: &[Vec2::ZERO; W],
            t: &[0.0; W],
            r: &[0.1; W],
            m: &[1.0; W],
            refp: &[Vec2::new(0.5, 0.5); W],
            hm: [0.0; W],
            hi: [0.0; W],
        });
        assert_eq!(got, None);
        assert_eq!(x, x0);
    }
}
