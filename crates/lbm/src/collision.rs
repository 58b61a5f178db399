//! Collision operators: BGK (Su Eq. 9 with B = 0; Leonardi Eq. 11) and two-relaxation-time (TRT),
//! with Guo forcing (Leonardi Eqs. 15-17). BGK is TRT with equal rates, so one kernel serves both.
//!
//! TRT relaxes the symmetric part of each opposite pair with ω⁺ = 1/τ (which sets the viscosity,
//! Su Eq. 15) and the antisymmetric part with ω⁻ = 1/τ⁻ chosen from the "magic" parameter
//! Λ = (τ − ½)(τ⁻ − ½). With Λ fixed, the location of a halfway bounce-back wall no longer depends
//! on the viscosity (Ginzburg & Adler 1994); Λ = 1/4 is the usual choice for stability, Λ = 3/16
//! puts straight walls exactly halfway for Poiseuille flow.

use crate::LbmError;
use crate::lattice::{CS2, Lattice, QMAX};
use crate::real::Real;
use serde::{Deserialize, Serialize};

/// Repeat a block once per listed index (a literal bound to `$k`): loops over the directions
/// whose velocity must be a compile-time constant inside the body.
macro_rules! unroll {
    ($k:ident in [$($n:literal),*] $body:block) => {
        $( { let $k: usize = $n; $body } )*
    };
}
pub(crate) use unroll;

/// The collision operator of a run.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Collision {
    /// Single relaxation time τ (Leonardi Eq. 11).
    Bgk { tau: f64 },
    /// Two relaxation times: τ for the symmetric part (viscosity), `magic` = Λ for the other.
    Trt { tau: f64, magic: f64 },
}

impl Collision {
    pub fn tau(&self) -> f64 {
        match *self {
            Collision::Bgk { tau } | Collision::Trt { tau, .. } => tau,
        }
    }
    /// (ω⁺, ω⁻), refusing τ ≤ ½ or Λ ≤ 0.
    pub fn rates(&self) -> Result<(f64, f64), LbmError> {
        let tau = self.tau();
        if tau.is_nan() || tau <= 0.5 || !tau.is_finite() {
            return Err(LbmError::Tau { tau });
        }
        self.rates_past_tau_check()
    }
    /// (ω⁺, ω⁻) for any finite τ ≠ ½, τ < ½ included (ω > 2, negative viscosity): only for the
    /// stability maps, which must run a refused τ to show the refusal was right
    /// (`cases::taylor_green` with `force_past_refusal`). Λ ≤ 0 is still refused.
    pub fn rates_past_tau_check(&self) -> Result<(f64, f64), LbmError> {
        let tau = self.tau();
        if tau.is_nan() || tau == 0.5 || !tau.is_finite() {
            return Err(LbmError::Tau { tau });
        }
        match *self {
            Collision::Bgk { .. } => Ok((1.0 / tau, 1.0 / tau)),
            Collision::Trt { magic, .. } => {
                if magic.is_nan() || magic <= 0.0 || !magic.is_finite() {
                    return Err(LbmError::Magic { magic });
                }
                let tau_m = 0.5 + magic / (tau - 0.5);
                Ok((1.0 / tau, 1.0 / tau_m))
            }
        }
    }
    /// Kinematic viscosity in lattice units, ν = c_s²(τ − ½) (Su Eq. 15).
    pub fn nu(&self) -> f64 {
        CS2 * (self.tau() - 0.5)
    }
    /// The wall-location parameter Λ: (τ − ½)² for BGK, the magic parameter for TRT.
    pub fn lambda(&self) -> f64 {
        match *self {
            Collision::Bgk { tau } => (tau - 0.5) * (tau - 0.5),
            Collision::Trt { magic, .. } => magic,
        }
    }
}

/// Precomputed constants of the collision, in the storage precision.
#[derive(Clone, Copy, Debug)]
pub struct CollideParams<T> {
    pub omega_p: T,
    pub omega_m: T,
    /// 1 − ω⁺/2 and 1 − ω⁻/2: the Guo forcing prefactors (Leonardi Eq. 16: 1 − 1/(2τ)).
    pub force_p: T,
    pub force_m: T,
    /// Uniform body force density (lattice units).
    pub force: [T; 3],
    /// ω⁺ = ω⁻ (BGK): `collide_block` takes the single-rate path `bgk_block`.
    pub bgk: bool,
    /// 1 − ω (BGK path).
    pub keep: T,
}

impl<T: Real> CollideParams<T> {
    pub fn new(c: &Collision, force: [f64; 3]) -> Result<Self, LbmError> {
        let (wp, wm) = c.rates()?;
        Ok(Self::from_rates(wp, wm, force))
    }
    /// The constants of the rates (ω⁺, ω⁻), whatever they are.
    pub fn from_rates(wp: f64, wm: f64, force: [f64; 3]) -> Self {
        Self {
            omega_p: T::from_f64(wp),
            omega_m: T::from_f64(wm),
            force_p: T::from_f64(1.0 - 0.5 * wp),
            force_m: T::from_f64(1.0 - 0.5 * wm),
            force: force.map(T::from_f64),
            bgk: wp == wm,
            keep: T::from_f64(1.0 - wp),
        }
    }
}

/// Moments of a block of `W` nodes: density and velocity u = (Σ f c + F/2)/ρ (Leonardi Eqs. 9, 17).
pub struct Moments<T, const W: usize> {
    pub rho: [T; W],
    pub u: [[T; W]; 3],
    /// |u|² as the collision computed it (the kernels' range check uses it).
    pub usq: [T; W],
}

/// Collide `W` nodes held in `f[i][w]` (pre-collision in, post-collision out), uniform force.
///
/// Post-collision f_i = f_i − ω⁺(f_i⁺ − f_i^{eq+}) − ω⁻(f_i⁻ − f_i^{eq−}) + (1 − ω⁺/2)S_i⁺ + (1 − ω⁻/2)S_i⁻
/// with the equilibrium of Su Eq. 7 / Leonardi Eq. 13 and the Guo source
/// S_i = w_i[3(c_i − u) + 9 c_i (c_i·u)]·F (Leonardi Eq. 16) split into its even and odd parts.
/// Written with the node index innermost over fixed-size local arrays so that it vectorises.
/// `FORCED = false` drops the force terms at compile time (the result is the same for F = 0).
/// With equal rates (BGK) the single-rate form `bgk_block` is taken instead: the same operator
/// with about half the arithmetic (no even/odd split).
#[inline(always)]
pub fn collide_block<L: Lattice, T: Real, const W: usize, const FORCED: bool>(
    f: &mut [[T; W]; QMAX],
    p: &CollideParams<T>,
) -> Moments<T, W> {
    if p.bgk {
        return bgk_block::<L, T, W, FORCED>(f, p);
    }
    let zero = T::default();
    let half = T::from_f64(0.5);
    let one = T::from_f64(1.0);
    let three = T::from_f64(3.0);
    let c45 = T::from_f64(4.5);
    let c15 = T::from_f64(1.5);
    let nine = T::from_f64(9.0);
    let mut rho = [zero; W];
    let mut j = [[zero; W]; 3];
    for i in 0..L::Q {
        let c = L::C[i];
        for w in 0..W {
            rho[w] += f[i][w];
        }
        for a in 0..L::D {
            if c[a] != 0 {
                let s = T::from_f64(c[a] as f64);
                for w in 0..W {
                    j[a][w] += s * f[i][w];
                }
            }
        }
    }
    let mut u = [[zero; W]; 3];
    let mut usq = [zero; W];
    let mut uf = [zero; W];
    for w in 0..W {
        let inv = one / rho[w];
        for a in 0..L::D {
            u[a][w] = if FORCED {
                (j[a][w] + half * p.force[a]) * inv
            } else {
                j[a][w] * inv
            };
            usq[w] += u[a][w] * u[a][w];
            if FORCED {
                uf[w] += u[a][w] * p.force[a];
            }
        }
    }
    // rest population: symmetric only
    {
        let w0 = T::from_f64(L::W[0]);
        for w in 0..W {
            let feq = w0 * rho[w] * (one - c15 * usq[w]);
            f[0][w] = f[0][w] - p.omega_p * (f[0][w] - feq);
            if FORCED {
                let s = -w0 * three * uf[w];
                f[0][w] += p.force_p * s;
            }
        }
    }
    for &i in L::HALF {
        let o = L::OPP[i];
        let c = L::C[i];
        let wi = T::from_f64(L::W[i]);
        let mut cf = zero;
        for a in 0..L::D {
            cf += T::from_f64(c[a] as f64) * p.force[a];
        }
        let (cx, cy, cz) = (
            T::from_f64(c[0] as f64),
            T::from_f64(c[1] as f64),
            T::from_f64(c[2] as f64),
        );
        for w in 0..W {
            // L::D is a constant: the z term vanishes at compile time in 2D
            let mut cu = cx * u[0][w] + cy * u[1][w];
            if L::D == 3 {
                cu += cz * u[2][w];
            }
            let wr = wi * rho[w];
            let feq_s = wr * (one + c45 * cu * cu - c15 * usq[w]);
            let feq_a = wr * three * cu;
            let fs = half * (f[i][w] + f[o][w]);
            let fa = half * (f[i][w] - f[o][w]);
            let mut ns = fs - p.omega_p * (fs - feq_s);
            let mut na = fa - p.omega_m * (fa - feq_a);
            if FORCED {
                let s_s = wi * (nine * cu * cf - three * uf[w]);
                let s_a = wi * three * cf;
                ns += p.force_p * s_s;
                na += p.force_m * s_a;
            }
            f[i][w] = ns + na;
            f[o][w] = ns - na;
        }
    }
    Moments { rho, u, usq }
}

/// ρ, u = (Σ f c + F/2)/ρ (Leonardi Eqs. 9, 17) and |u|² of a block. Velocity components are
/// summed with additions and subtractions only (c_ia ∈ {−1, 0, 1} is a compile-time constant).
#[inline(always)]
pub(crate) fn moments<L: Lattice, T: Real, const W: usize, const FORCED: bool>(
    f: &[[T; W]; QMAX],
    p: &CollideParams<T>,
) -> Moments<T, W> {
    let zero = T::default();
    let half = T::from_f64(0.5);
    let one = T::from_f64(1.0);
    let mut rho = [zero; W];
    let mut j = [[zero; W]; 3];
    // unrolled so that c_i is a compile-time constant and the matches fold away
    unroll!(i in [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18] {
        if i < L::Q {
            let c = L::C[i];
            for w in 0..W {
                rho[w] += f[i][w];
            }
            unroll!(a in [0, 1, 2] {
                if a < L::D {
                    if c[a] == 1 {
                        for w in 0..W {
                            j[a][w] += f[i][w];
                        }
                    } else if c[a] == -1 {
                        for w in 0..W {
                            j[a][w] = j[a][w] - f[i][w];
                        }
                    }
                }
            });
        }
    });
    let mut u = [[zero; W]; 3];
    let mut usq = [zero; W];
    for w in 0..W {
        let inv = one / rho[w];
        for a in 0..L::D {
            u[a][w] = if FORCED {
                (j[a][w] + half * p.force[a]) * inv
            } else {
                j[a][w] * inv
            };
            usq[w] = u[a][w].mul_add(u[a][w], usq[w]);
        }
    }
    Moments { rho, u, usq }
}

/// c_i · u for a compile-time c_i with components in {−1, 0, 1}: additions only.
#[inline(always)]
fn c_dot<T: Real>(c: [i32; 3], u: [T; 3]) -> T {
    let mut s: Option<T> = None;
    unroll!(a in [0, 1, 2] {
        let v = match c[a] {
            1 => Some(u[a]),
            -1 => Some(-u[a]),
            _ => None,
        };
        if let Some(v) = v {
            s = Some(match s {
                None => v,
                Some(acc) => acc + v,
            });
        }
    });
    s.unwrap_or_default()
}

/// BGK collision of a block, f_i ← (1 − ω) f_i + ω f_i^eq + (1 − ω/2) S_i (Leonardi Eqs. 11, 15-16),
/// written per opposite pair (i, ī) as f_i^eq = A + B, f_ī^eq = A − B with the even part
/// A = w_i ρ (1 + 4.5 (c_i·u)² − 1.5 u²) and the odd part B = 3 w_i ρ c_i·u (Su Eq. 7), with ω
/// folded into the weights and fused multiply-adds: about 65 operations per node in D2Q9 instead
/// of the 130 of the TRT form. The Guo source splits the same way (even part w_i(9 (c_i·u)(c_i·F)
/// − 3 u·F), odd part 3 w_i c_i·F).
#[inline(always)]
pub fn bgk_block<L: Lattice, T: Real, const W: usize, const FORCED: bool>(
    f: &mut [[T; W]; QMAX],
    p: &CollideParams<T>,
) -> Moments<T, W> {
    let m = moments::<L, T, W, FORCED>(f, p);
    let one = T::from_f64(1.0);
    let three = T::from_f64(3.0);
    let c45 = T::from_f64(4.5);
    let m15 = T::from_f64(-1.5);
    let nine = T::from_f64(9.0);
    let omega = p.omega_p;
    let keep = p.keep;
    // 1 − 1.5 u² and (forced) u·F, shared by every direction
    let mut base = [T::default(); W];
    let mut uf = [T::default(); W];
    for w in 0..W {
        base[w] = m15.mul_add(m.usq[w], one);
        if FORCED {
            for a in 0..L::D {
                uf[w] = m.u[a][w].mul_add(p.force[a], uf[w]);
            }
        }
    }
    {
        let w0 = T::from_f64(L::W[0]);
        let ow0 = omega * w0;
        let src0 = p.force_p * (-(w0 * three));
        for w in 0..W {
            let mut a = (ow0 * m.rho[w]) * base[w];
            if FORCED {
                a = src0.mul_add(uf[w], a);
            }
            f[0][w] = keep.mul_add(f[0][w], a);
        }
    }
    // unrolled (see `moments`)
    unroll!(h in [0, 1, 2, 3, 4, 5, 6, 7, 8] {
        if h < L::HALF.len() {
        let i = L::HALF[h];
        let o = L::OPP[i];
        let c = L::C[i];
        let wi = T::from_f64(L::W[i]);
        let owi = omega * wi;
        let owi3 = owi * three;
        let cf = c_dot(c, p.force);
        // forcing: even part force_p w_i (9 cu cf − 3 uf), odd part force_p 3 w_i cf
        let s9 = p.force_p * wi * nine * cf;
        let s3 = p.force_p * wi * three;
        let s_odd = s3 * cf;
        for w in 0..W {
            let cu = c_dot(c, [m.u[0][w], m.u[1][w], m.u[2][w]]);
            let rho = m.rho[w];
            let mut a = (owi * rho) * (c45 * cu).mul_add(cu, base[w]);
            let mut b = (owi3 * rho) * cu;
            if FORCED {
                a = s9.mul_add(cu, a);
                a = (-s3).mul_add(uf[w], a);
                b += s_odd;
            }
            f[i][w] = keep.mul_add(f[i][w], a + b);
            f[o][w] = keep.mul_add(f[o][w], a - b);
        }
        }
    });
    m
}

/// The collision seam: collide a block of `W` nodes (populations `f[i][w]`, pre-collision in,
/// post-collision out) whose first node, in node order, is `node`. The kernels (`kernel`,
/// `kernel_aa`) and the PSM lattice of `lbdem-coupling` are generic over it and monomorphised, so
/// the operator is inlined into their loops. Implemented by the uniform operator
/// [`CollideParams`] (BGK or TRT, one rate everywhere) and by [`LocalRates`] (the same operator
/// with ω⁺ read per node: the seam of local-τ rheology such as Bingham, Leonardi et al. 2014
/// Eqs. 5-8). A new operator is a new type implementing this trait.
pub trait Collider<L: Lattice, T: Real>: Copy + Send + Sync {
    /// The steppers compile this collider with the force terms only (no unforced copy): true for
    /// the per-node operators, whose own work dwarfs the force terms, so that each is built half
    /// as many times (the crate's build is CI's longest, README "CI's cost"). A zero force gives
    /// the same result either way (`collide_block`'s `FORCED` note).
    const FORCE_TERMS_ALWAYS: bool = false;

    /// Collide `W` nodes starting at node `node`; the moments the collision used.
    fn collide<const W: usize, const FORCED: bool>(
        &self,
        f: &mut [[T; W]; QMAX],
        node: usize,
    ) -> Moments<T, W>;
}

impl<L: Lattice, T: Real> Collider<L, T> for CollideParams<T> {
    /// The uniform operator: `collide_block` (the node index is not read).
    #[inline(always)]
    fn collide<const W: usize, const FORCED: bool>(
        &self,
        f: &mut [[T; W]; QMAX],
        _node: usize,
    ) -> Moments<T, W> {
        collide_block::<L, T, W, FORCED>(f, self)
    }
}

/// The rate constants of one node in the storage precision (what `CollideParams` holds for the
/// whole lattice), rounded from f64 exactly as `CollideParams::new` rounds them.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NodeRates<T> {
    pub omega_p: T,
    pub omega_m: T,
    pub force_p: T,
    pub force_m: T,
    /// 1 − ω⁺ (BGK path).
    pub keep: T,
}

/// Per-node rates from per-node relaxation times τ⁺ (node order), with the kind (BGK or TRT with
/// its magic Λ) of `collision`: node x gets exactly the constants `CollideParams::new` would give
/// for `collision` with τ = `tau[x]`, so equal τ everywhere reproduces the uniform run bit for bit.
/// Also returns whether every node has ω⁺ = ω⁻ (the BGK path).
pub fn local_rates<T: Real>(
    collision: &Collision,
    tau: &[f64],
) -> Result<(Vec<NodeRates<T>>, bool), LbmError> {
    let mut out = Vec::with_capacity(tau.len());
    let mut bgk = true;
    for (node, &t) in tau.iter().enumerate() {
        let c = match *collision {
            Collision::Bgk { .. } => Collision::Bgk { tau: t },
            Collision::Trt { magic, .. } => Collision::Trt { tau: t, magic },
        };
        let (wp, wm) = c.rates().map_err(|e| match e {
            LbmError::Tau { tau } => LbmError::LocalTau { node, tau },
            other => other,
        })?;
        bgk &= wp == wm;
        out.push(NodeRates {
            omega_p: T::from_f64(wp),
            omega_m: T::from_f64(wm),
            force_p: T::from_f64(1.0 - 0.5 * wp),
            force_m: T::from_f64(1.0 - 0.5 * wm),
            keep: T::from_f64(1.0 - wp),
        });
    }
    Ok((out, bgk))
}

/// The uniform operator with per-node rates (Leonardi et al. 2014 Eq. 8: τ from the local
/// apparent viscosity): `base` gives the force and whether every node takes the BGK path,
/// `rates[node]` the relaxation constants. The arithmetic is that of `collide_block` lane by lane.
#[derive(Clone, Copy, Debug)]
pub struct LocalRates<'a, T> {
    pub base: CollideParams<T>,
    /// One entry per node of the lattice (node order).
    pub rates: &'a [NodeRates<T>],
}

impl<L: Lattice, T: Real> Collider<L, T> for LocalRates<'_, T> {
    const FORCE_TERMS_ALWAYS: bool = true;

    #[inline(always)]
    fn collide<const W: usize, const FORCED: bool>(
        &self,
        f: &mut [[T; W]; QMAX],
        node: usize,
    ) -> Moments<T, W> {
        let mut r = [NodeRates::default(); W];
        r.copy_from_slice(&self.rates[node..node + W]);
        if self.base.bgk {
            bgk_block_local::<L, T, W, FORCED>(f, &self.base, &r)
        } else {
            trt_block_local::<L, T, W, FORCED>(f, &self.base, &r)
        }
    }
}

/// `collide_block`'s TRT form with the rates of each lane from `r` (force from `p`).
#[inline(always)]
fn trt_block_local<L: Lattice, T: Real, const W: usize, const FORCED: bool>(
    f: &mut [[T; W]; QMAX],
    p: &CollideParams<T>,
    r: &[NodeRates<T>; W],
) -> Moments<T, W> {
    let zero = T::default();
    let half = T::from_f64(0.5);
    let one = T::from_f64(1.0);
    let mut rho = [zero; W];
    let mut j = [[zero; W]; 3];
    for i in 0..L::Q {
        let c = L::C[i];
        for w in 0..W {
            rho[w] += f[i][w];
        }
        for a in 0..L::D {
            if c[a] != 0 {
                let s = T::from_f64(c[a] as f64);
                for w in 0..W {
                    j[a][w] += s * f[i][w];
                }
            }
        }
    }
    let mut u = [[zero; W]; 3];
    let mut usq = [zero; W];
    let mut uf = [zero; W];
    for w in 0..W {
        let inv = one / rho[w];
        for a in 0..L::D {
            u[a][w] = if FORCED {
                (j[a][w] + half * p.force[a]) * inv
            } else {
                j[a][w] * inv
            };
            usq[w] += u[a][w] * u[a][w];
            if FORCED {
                uf[w] += u[a][w] * p.force[a];
            }
        }
    }
    trt_relax_local::<L, T, W, FORCED>(f, p, r, Moments { rho, u, usq }, &uf)
}

/// The relaxation of `trt_block_local` from given moments and u·F (shared with the Bingham
/// collider, which computes the moments first to get the shear rate).
#[inline(always)]
pub(crate) fn trt_relax_local<L: Lattice, T: Real, const W: usize, const FORCED: bool>(
    f: &mut [[T; W]; QMAX],
    p: &CollideParams<T>,
    r: &[NodeRates<T>; W],
    m: Moments<T, W>,
    uf: &[T; W],
) -> Moments<T, W> {
    let zero = T::default();
    let half = T::from_f64(0.5);
    let one = T::from_f64(1.0);
    let three = T::from_f64(3.0);
    let c45 = T::from_f64(4.5);
    let c15 = T::from_f64(1.5);
    let nine = T::from_f64(9.0);
    let Moments { rho, u, usq } = m;
    {
        let w0 = T::from_f64(L::W[0]);
        for w in 0..W {
            let feq = w0 * rho[w] * (one - c15 * usq[w]);
            f[0][w] = f[0][w] - r[w].omega_p * (f[0][w] - feq);
            if FORCED {
                let s = -w0 * three * uf[w];
                f[0][w] += r[w].force_p * s;
            }
        }
    }
    for &i in L::HALF {
        let o = L::OPP[i];
        let c = L::C[i];
        let wi = T::from_f64(L::W[i]);
        let mut cf = zero;
        for a in 0..L::D {
            cf += T::from_f64(c[a] as f64) * p.force[a];
        }
        let (cx, cy, cz) = (
            T::from_f64(c[0] as f64),
            T::from_f64(c[1] as f64),
            T::from_f64(c[2] as f64),
        );
        for w in 0..W {
            let mut cu = cx * u[0][w] + cy * u[1][w];
            if L::D == 3 {
                cu += cz * u[2][w];
            }
            let wr = wi * rho[w];
            let feq_s = wr * (one + c45 * cu * cu - c15 * usq[w]);
            let feq_a = wr * three * cu;
            let fs = half * (f[i][w] + f[o][w]);
            let fa = half * (f[i][w] - f[o][w]);
            let mut ns = fs - r[w].omega_p * (fs - feq_s);
            let mut na = fa - r[w].omega_m * (fa - feq_a);
            if FORCED {
                let s_s = wi * (nine * cu * cf - three * uf[w]);
                let s_a = wi * three * cf;
                ns += r[w].force_p * s_s;
                na += r[w].force_m * s_a;
            }
            f[i][w] = ns + na;
            f[o][w] = ns - na;
        }
    }
    Moments { rho, u, usq }
}

/// `bgk_block` with the rates of each lane from `r` (the products that `bgk_block` hoists out of
/// the lane loop are formed per lane in the same order, so equal rates give the same bits).
#[inline(always)]
fn bgk_block_local<L: Lattice, T: Real, const W: usize, const FORCED: bool>(
    f: &mut [[T; W]; QMAX],
    p: &CollideParams<T>,
    r: &[NodeRates<T>; W],
) -> Moments<T, W> {
    let m = moments::<L, T, W, FORCED>(f, p);
    bgk_relax_local::<L, T, W, FORCED>(f, p, r, m)
}

/// The relaxation of `bgk_block_local` from given moments (shared with the Bingham collider).
#[inline(always)]
pub(crate) fn bgk_relax_local<L: Lattice, T: Real, const W: usize, const FORCED: bool>(
    f: &mut [[T; W]; QMAX],
    p: &CollideParams<T>,
    r: &[NodeRates<T>; W],
    m: Moments<T, W>,
) -> Moments<T, W> {
    let one = T::from_f64(1.0);
    let three = T::from_f64(3.0);
    let c45 = T::from_f64(4.5);
    let m15 = T::from_f64(-1.5);
    let nine = T::from_f64(9.0);
    let mut base = [T::default(); W];
    let mut uf = [T::default(); W];
    for w in 0..W {
        base[w] = m15.mul_add(m.usq[w], one);
        if FORCED {
            for a in 0..L::D {
                uf[w] = m.u[a][w].mul_add(p.force[a], uf[w]);
            }
        }
    }
    {
        let w0 = T::from_f64(L::W[0]);
        for w in 0..W {
            let ow0 = r[w].omega_p * w0;
            let src0 = r[w].force_p * (-(w0 * three));
            let mut a = (ow0 * m.rho[w]) * base[w];
            if FORCED {
                a = src0.mul_add(uf[w], a);
            }
            f[0][w] = r[w].keep.mul_add(f[0][w], a);
        }
    }
    unroll!(h in [0, 1, 2, 3, 4, 5, 6, 7, 8] {
        if h < L::HALF.len() {
        let i = L::HALF[h];
        let o = L::OPP[i];
        let c = L::C[i];
        let wi = T::from_f64(L::W[i]);
        let cf = c_dot(c, p.force);
        for w in 0..W {
            let owi = r[w].omega_p * wi;
            let owi3 = owi * three;
            let s9 = r[w].force_p * wi * nine * cf;
            let s3 = r[w].force_p * wi * three;
            let s_odd = s3 * cf;
            let cu = c_dot(c, [m.u[0][w], m.u[1][w], m.u[2][w]]);
            let rho = m.rho[w];
            let mut a = (owi * rho) * (c45 * cu).mul_add(cu, base[w]);
            let mut b = (owi3 * rho) * cu;
            if FORCED {
                a = s9.mul_add(cu, a);
                a = (-s3).mul_add(uf[w], a);
                b += s_odd;
            }
            f[i][w] = r[w].keep.mul_add(f[i][w], a + b);
            f[o][w] = r[w].keep.mul_add(f[o][w], a - b);
        }
        }
    });
    m
}

/// Equilibrium populations (Su Eq. 7) for one node.
pub fn equilibrium<L: Lattice>(rho: f64, u: [f64; 3]) -> [f64; QMAX] {
    let mut out = [0.0; QMAX];
    let usq = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
    for i in 0..L::Q {
        let c = L::C[i];
        let cu = c[0] as f64 * u[0] + c[1] as f64 * u[1] + c[2] as f64 * u[2];
        out[i] = L::W[i] * rho * (1.0 + 3.0 * cu + 4.5 * cu * cu - 1.5 * usq);
    }
    out
}
