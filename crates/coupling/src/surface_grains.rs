//! 3D grains in a free-surface liquid by moving bounce-back (Leonardi et al. 2014 Sect. 5.1,
//! Eqs. 19-21): the coupling of issue 20 item 3, on the mass-tracking D3Q19 lattice of
//! `lbdem_lbm::free_surface` and the sphere engine of `lbdem_dem::spheres` (single spheres and
//! rigid clumps of spheres, such as the paper's four-sphere pebbles).
//!
//! Every LBM step ([`SurfaceGrains::exchange`]):
//! 1. **map**: the nodes whose centres lie inside a sphere become that sphere's [`GRAIN`] nodes
//!    (the first sphere in index order when two overlap, so clump members share their clump's
//!    nodes); nodes a grain leaves are refilled and nodes it enters are emptied by
//!    `free_surface::solids` (mass kept to round-off: a grain entering the liquid raises its
//!    surface). Every grain node carries the surface velocity u_w = u_p + ω_p × r_w (Eq. 20);
//! 2. **load**: Eq. 21 over every link from a liquid or interface node into a grain node, with
//!    the atmospheric part 2 w_i ρ_A c_i taken out of each link, so that the load is that of the
//!    gauge pressure: a grain half out of the liquid is not pushed by the liquid's c_s² ρ_A, which
//!    the gas on its dry side does not balance (the gas imposes ρ_A, Eq. 26). Over a closed wet
//!    surface the part sums to zero, so a submerged grain's load is Eq. 21's. The moment is taken
//!    about the sphere's centre at the link's midpoint (the halfway wall). With
//!    `conserve_momentum` the momentum of the liquid a grain covers (and, negative, of the liquid
//!    it leaves behind) is added to its load (Aidun, Lu & Ding 1998); the paper drops it;
//! 3. **stream and collide** the liquid (`FreeSurfaceStepper`), links into grain nodes bounced
//!    back with u_w (Eq. 19).
//!
//! The DEM then takes its sub-steps with that load held ([`SurfaceCoupled`]).
//!
//! **The velocity term.** Eq. 21's −6 w_i ρ (u_w·c_i) c_i makes the load answer the grain's own
//! velocity within the step: held over an LBM step it is an explicit drag K with K Δt/m that
//! grows as the grain shrinks and the liquid thins (K ∝ r², m ∝ r³; for rotation r⁴ against r⁵);
//! a light grain of a couple of nodes then rocks from step to step until the liquid beside it
//! passes the Mach limit (a pebble of 1.6-node spheres at 1.5 times the liquid's density blows up
//! in 64 steps at τ = 0.52, `docs/free_surface.md`). With `implicit` the grain's velocity of the
//! step is solved for instead (after the implicit velocity update of Lowe, Frenkel & Masters 1995
//! and Nguyen & Ladd 2002, as recalled, not checked against the papers): the term is kept as the
//! matrices of its linear dependence on (v, ω) ([`VelocityResponse`]), each body's 6 × 6 system
//! (M + Δt K) u = M u_old + Δt (F_rest + m g) is solved for its velocity and spin u (contacts are
//! not predicted), the liquid bounces back with that u (Eq. 19-20) and the grain is loaded with
//! F_rest − K u: the same exchange on both sides, so momentum stays conserved.
//!
//! With
//! `conserve_momentum`, the liquid's population momentum plus the grains' momentum is conserved to
//! round-off in a periodic, fully liquid box without gravity (`tests/surface_grains.rs`): every
//! term the lattice loses, the grains gain. Grains feel gravity in the DEM and buoyancy through the
//! hydrostatic pressure of the liquid on their nodes.

use crate::error::CouplingError;
use lbdem_dem::spheres::{SphereForceHook, SphereLaw, SphereStepParams, SphereStepper, SphereSystem};
use lbdem_dem::vector::{Vec3, Vector};
use lbdem_lbm::free_surface::{
    Conversions, FreeSurface, FreeSurfaceStepper, GRAIN, INTERFACE, LIQUID, WALL, cover, uncover,
};
use lbdem_lbm::{D3Q19, Lattice};
use nalgebra::{Matrix3, Matrix6, Vector3, Vector6};
use std::ops::AddAssign;

/// No grain covers the node.
pub const NO_GRAIN: u32 = u32::MAX;

/// How the lattice sits in the DEM's metres and seconds: node (i, j, k) has its centre at
/// `origin + (i + ½, j + ½, k + ½) dx`; one LBM step is `dt`; the liquid's density `rho` (kg/m³)
/// is the lattice density 1.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct SurfaceScale {
    pub dx: f64,
    pub dt: f64,
    pub rho: f64,
    pub origin: [f64; 3],
}

impl SurfaceScale {
    fn check(&self) -> Result<(), CouplingError> {
        for (name, v) in [("dx", self.dx), ("dt", self.dt), ("rho", self.rho)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(CouplingError::Unsupported(format!(
                    "lattice scale {name} = {v}: give a positive, finite value (SI units)"
                )));
            }
        }
        if self.origin.iter().any(|v| !v.is_finite()) {
            return Err(CouplingError::Unsupported(format!(
                "lattice origin {:?} is not finite",
                self.origin
            )));
        }
        Ok(())
    }

    /// A lattice force (ρ = 1, dx = dt = 1) in newtons.
    pub fn force_si(&self) -> f64 {
        self.rho * self.dx.powi(4) / (self.dt * self.dt)
    }
}

/// What a coupled free-surface lattice needs to continue a run bit for bit besides its settings.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct SurfaceGrainsState {
    pub liquid: FreeSurface<D3Q19>,
    /// Sphere that covers each node ([`NO_GRAIN`] if none), from the last mapping.
    pub owner: Vec<u32>,
    /// The grain nodes in the order the last mapping claimed them.
    pub owned: Vec<u32>,
}

/// Fastest a grain surface may move through the lattice, in nodes per LBM step: beyond it the
/// mapping skips nodes (a grain would cross a node between two mappings) and the bounce-back
/// correction of Eq. 19 is far outside the low-Mach range.
pub const MAX_GRAIN_SPEED: f64 = 0.3;

/// The liquid lattice and its grain nodes.
pub struct SurfaceGrains {
    pub liquid: FreeSurface<D3Q19>,
    stepper: FreeSurfaceStepper<D3Q19>,
    scale: SurfaceScale,
    owner: Vec<u32>,
    owned: Vec<u32>,
    next: Vec<u32>,
    claimed: Vec<u32>,
    /// Surface velocity (lattice units) of each claimed node, in `claimed`'s order.
    claimed_u: Vec<[f64; 3]>,
    /// Per sphere: force and moment of the last exchange (N, N m).
    load: Vec<(Vec3, Vec3)>,
    /// Hand the momentum of covered and uncovered liquid to the grains (module doc).
    pub conserve_momentum: bool,
    /// Spheres the caller moves itself (frozen in the DEM, where frozen spheres are at rest)
    /// and the velocity the liquid sees them move at (e.g. a lifted box).
    pub driven: Option<(std::ops::Range<usize>, Vec3)>,
    /// Solve for each grain's velocity of the step with the velocity term of Eq. 21 (module doc,
    /// "The velocity term"). Off by default (the paper's explicit coupling).
    pub implicit: bool,
}

/// How the velocity term of Eq. 21 on one sphere depends on its velocity v and spin ω:
/// F = −(A v + C ω), T = −(Cᵀ v + D ω), summed over its links (SI).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VelocityResponse {
    pub a: Matrix3<f64>,
    pub c: Matrix3<f64>,
    pub d: Matrix3<f64>,
}

impl VelocityResponse {
    fn load(&self, v: Vec3, w: Vec3) -> (Vec3, Vec3) {
        let (v, w): (Vector3<f64>, Vector3<f64>) = (v.into(), w.into());
        let f = -(self.a * v + self.c * w);
        let t = -(self.c.transpose() * v + self.d * w);
        (f.into(), t.into())
    }
}

impl SurfaceGrains {
    /// A lattice with no grain node yet (the first [`Self::exchange`] maps the grains). The box
    /// must be D3Q19 with `nz > 1`; its periodic faces must be the DEM domain's periodic axes
    /// (checked by [`Self::check_domain`]).
    pub fn new(
        liquid: FreeSurface<D3Q19>,
        stepper: FreeSurfaceStepper<D3Q19>,
        scale: SurfaceScale,
    ) -> Result<Self, CouplingError> {
        if liquid.cell.contains(&GRAIN) {
            return Err(CouplingError::Unsupported(
                "the liquid already has grain nodes: start from a lattice without grains; the \
                 first exchange maps them"
                    .into(),
            ));
        }
        Self::build(liquid, stepper, scale)
    }

    fn build(
        liquid: FreeSurface<D3Q19>,
        stepper: FreeSurfaceStepper<D3Q19>,
        scale: SurfaceScale,
    ) -> Result<Self, CouplingError> {
        scale.check()?;
        let n = liquid.nodes();
        Ok(Self {
            liquid,
            stepper,
            scale,
            owner: vec![NO_GRAIN; n],
            owned: Vec::new(),
            next: vec![NO_GRAIN; n],
            claimed: Vec::new(),
            claimed_u: Vec::new(),
            load: Vec::new(),
            conserve_momentum: true,
            driven: None,
            implicit: false,
        })
    }

    /// Continue from a state written by [`Self::state`].
    pub fn restore(
        state: SurfaceGrainsState,
        stepper: FreeSurfaceStepper<D3Q19>,
        scale: SurfaceScale,
    ) -> Result<Self, CouplingError> {
        let n = state.liquid.nodes();
        if state.owner.len() != n || state.owned.iter().any(|&x| x as usize >= n) {
            return Err(CouplingError::Unsupported(format!(
                "grain owners of {} nodes for a lattice of {n}: the state is not of this lattice",
                state.owner.len()
            )));
        }
        let mut s = Self::build(state.liquid, stepper, scale)?;
        s.owner = state.owner;
        s.owned = state.owned;
        Ok(s)
    }

    /// Take `state` (written by [`Self::state`] for a lattice of the same box and settings).
    pub fn set_state(&mut self, state: SurfaceGrainsState) -> Result<(), CouplingError> {
        let n = self.liquid.nodes();
        if state.liquid.nodes() != n
            || state.liquid.domain.n != self.liquid.domain.n
            || state.owner.len() != n
            || state.owned.iter().any(|&x| x as usize >= n)
        {
            return Err(CouplingError::Unsupported(format!(
                "the state's lattice of {:?} nodes is not this one's {:?}",
                state.liquid.domain.n, self.liquid.domain.n
            )));
        }
        self.liquid = state.liquid;
        self.owner = state.owner;
        self.owned = state.owned;
        Ok(())
    }

    pub fn state(&self) -> SurfaceGrainsState {
        SurfaceGrainsState {
            liquid: self.liquid.clone(),
            owner: self.owner.clone(),
            owned: self.owned.clone(),
        }
    }

    pub fn scale(&self) -> &SurfaceScale {
        &self.scale
    }

    pub fn stepper(&self) -> &FreeSurfaceStepper<D3Q19> {
        &self.stepper
    }

    /// Mutable access to the liquid's stepper (e.g. to set the Bingham rheology).
    pub fn stepper_mut(&mut self) -> &mut FreeSurfaceStepper<D3Q19> {
        &mut self.stepper
    }

    /// Force and moment on each sphere from the last exchange (N, N m; zero before the first).
    pub fn loads(&self) -> &[(Vec3, Vec3)] {
        &self.load
    }

    /// Sphere covering each node ([`NO_GRAIN`] if none).
    pub fn owners(&self) -> &[u32] {
        &self.owner
    }

    /// Refuse a DEM domain whose periodic axes or extent differ from the lattice's.
    pub fn check_domain(&self, sys: &SphereSystem) -> Result<(), CouplingError> {
        let dom = &self.liquid.domain;
        let sc = &self.scale;
        for a in 0..3 {
            let periodic = dom.faces[2 * a].is_periodic();
            if periodic != sys.domain.periodic[a] {
                return Err(CouplingError::Unsupported(format!(
                    "axis {a} is {} in the lattice and {} in the DEM domain: make them agree",
                    if periodic { "periodic" } else { "walled" },
                    if sys.domain.periodic[a] {
                        "periodic"
                    } else {
                        "walled"
                    }
                )));
            }
            let lo = sc.origin[a];
            let hi = lo + dom.n[a] as f64 * sc.dx;
            let tol = 1e-9 * sc.dx;
            if periodic
                && ((sys.domain.lo.component(a) - lo).abs() > tol
                    || (sys.domain.hi.component(a) - hi).abs() > tol)
            {
                return Err(CouplingError::Unsupported(format!(
                    "periodic axis {a}: the DEM domain spans [{}, {}] m, the lattice [{lo}, {hi}] m; \
                     a periodic length must be the same on both sides",
                    sys.domain.lo.component(a),
                    sys.domain.hi.component(a)
                )));
            }
        }
        Ok(())
    }

    /// Map the grains of `sys`, compute their loads (see [`Self::loads`]) and advance the liquid
    /// one LBM step. The conversions of the step.
    /// `gravity` is the DEM's (m/s²), for the velocity the `implicit` coupling predicts.
    pub fn exchange(&mut self, sys: &SphereSystem, gravity: Vec3) -> Result<Conversions, CouplingError> {
        let impulse = self.map(sys)?;
        self.compute_loads(sys, &impulse, gravity);
        Ok(self.stepper.step(&mut self.liquid)?)
    }

    /// Node index and offset from the centre (lattice units) of every node inside sphere `k`,
    /// passed to `visit`.
    fn for_nodes_of(&self, sys: &SphereSystem, k: usize, mut visit: impl FnMut(usize, [f64; 3])) {
        let dom = &self.liquid.domain;
        let sc = &self.scale;
        let p = sys.spheres.pos[k];
        let c = [
            (p.x - sc.origin[0]) / sc.dx - 0.5,
            (p.y - sc.origin[1]) / sc.dx - 0.5,
            (p.z - sc.origin[2]) / sc.dx - 0.5,
        ];
        let r = sys.spheres.radius[k] / sc.dx;
        let r2 = r * r;
        let range = |a: usize| ((c[a] - r).ceil() as i64, (c[a] + r).floor() as i64);
        let (rx, ry, rz) = (range(0), range(1), range(2));
        let wrap = |a: usize, i: i64| -> Option<usize> {
            let n = dom.n[a] as i64;
            if dom.faces[2 * a].is_periodic() {
                Some(i.rem_euclid(n) as usize)
            } else {
                (0..n).contains(&i).then_some(i as usize)
            }
        };
        for z in rz.0..=rz.1 {
            let dz = z as f64 - c[2];
            let Some(iz) = wrap(2, z) else { continue };
            for y in ry.0..=ry.1 {
                let dy = y as f64 - c[1];
                let Some(iy) = wrap(1, y) else { continue };
                for x in rx.0..=rx.1 {
                    let dx = x as f64 - c[0];
                    if dx * dx + dy * dy + dz * dz > r2 {
                        continue;
                    }
                    let Some(ix) = wrap(0, x) else { continue };
                    visit(dom.index(ix, iy, iz), [dx, dy, dz]);
                }
            }
        }
    }

    /// Surface velocity of sphere `k` at offset `d` (lattice units) from its centre (Eq. 20), in
    /// lattice units.
    fn surface_velocity(&self, sys: &SphereSystem, k: usize, d: [f64; 3]) -> [f64; 3] {
        let sc = &self.scale;
        let arm = Vec3::new(d[0], d[1], d[2]) * sc.dx;
        let u = match &self.driven {
            Some((r, v)) if r.contains(&k) => *v,
            _ => sys.spheres.vel[k] + sys.spheres.omega[k].cross(arm),
        };
        let f = sc.dt / sc.dx;
        [u.x * f, u.y * f, u.z * f]
    }

    /// Claim the nodes inside the spheres, cover and uncover, set the surface velocities; the
    /// momentum (lattice units) each sphere took from the liquid by covering and uncovering.
    fn map(&mut self, sys: &SphereSystem) -> Result<Vec<[f64; 3]>, CouplingError> {
        let ns = sys.spheres.len();
        let f = self.scale.dt / self.scale.dx;
        for k in 0..ns {
            let v = sys.spheres.vel[k].norm() + sys.spheres.omega[k].norm() * sys.spheres.radius[k];
            if v * f > MAX_GRAIN_SPEED || !v.is_finite() {
                return Err(CouplingError::Unsupported(format!(
                    "sphere {k} moves its surface at up to {:.3} nodes per LBM step (|v| + |ω| r = \
                     {v:.4e} m/s), above {MAX_GRAIN_SPEED}: the grid cannot follow it; refine dt \
                     or coarsen dx",
                    v * f
                )));
            }
        }
        let mut claimed = std::mem::take(&mut self.claimed);
        let mut next = std::mem::take(&mut self.next);
        let mut claimed_u = std::mem::take(&mut self.claimed_u);
        claimed.clear();
        claimed_u.clear();
        for k in 0..ns {
            self.for_nodes_of(sys, k, |x, d| {
                if next[x] == NO_GRAIN && self.liquid.cell[x] != WALL {
                    next[x] = k as u32;
                    claimed.push(x as u32);
                    claimed_u.push(self.surface_velocity(sys, k, d));
                }
            });
        }
        let mut impulse = vec![[0.0; 3]; ns];
        for &x in &claimed {
            let x = x as usize;
            if self.owner[x] == NO_GRAIN {
                let got = cover(&mut self.liquid, x, [0.0; 3]);
                let k = next[x] as usize;
                for a in 0..3 {
                    impulse[k][a] += got.momentum[a];
                }
            }
        }
        for &x in &self.owned {
            let x = x as usize;
            if next[x] == NO_GRAIN {
                let gave = uncover(&mut self.liquid, x);
                let k = self.owner[x] as usize;
                if k < ns {
                    for a in 0..3 {
                        impulse[k][a] -= gave.momentum[a];
                    }
                }
            }
            self.owner[x] = NO_GRAIN;
        }
        std::mem::swap(&mut self.owner, &mut next);
        std::mem::swap(&mut self.owned, &mut claimed);
        self.next = next;
        self.claimed = claimed;
        // surface velocities (Eq. 20) of every grain node, found when it was claimed
        for (&x, &u) in self.owned.iter().zip(&claimed_u) {
            self.liquid.solid_u[x as usize] = u;
        }
        self.claimed_u = claimed_u;
        Ok(impulse)
    }

    /// Eq. 21 (gauge) over the links into grain nodes, plus the mapping's impulses.
    fn compute_loads(&mut self, sys: &SphereSystem, impulse: &[[f64; 3]], gravity: Vec3) {
        let ns = sys.spheres.len();
        let s = &self.liquid;
        let n = s.nodes();
        let links = self.stepper.links();
        let rho_a = self.stepper.params().rho_atm;
        let mut force = vec![[0.0f64; 3]; ns];
        let mut torque = vec![[0.0f64; 3]; ns];
        let implicit = self.implicit;
        let mut resp = vec![VelocityResponse::default(); if implicit { ns } else { 0 }];
        let sc = self.scale;
        for &y in &self.owned {
            let y = y as usize;
            let k = self.owner[y] as usize;
            let u_w = s.solid_u[y];
            let d = self.offset(sys, k, y);
            for i in 1..D3Q19::Q {
                // fluid node x = y − c_i, whose population f_i streams into y
                let x = links[D3Q19::OPP[i] * n + y];
                if x == lbdem_lbm::free_surface::stepper::NONE {
                    continue;
                }
                let x = x as usize;
                if !matches!(s.cell[x], LIQUID | INTERFACE) {
                    continue;
                }
                let c = D3Q19::C[i].map(|v| v as f64);
                let w = D3Q19::W[i];
                let cu = u_w[0] * c[0] + u_w[1] * c[1] + u_w[2] * c[2];
                let mag = if implicit {
                    let k6 = 6.0 * w * s.rho[x];
                    let cv = Vector3::new(c[0], c[1], c[2]);
                    let dc = Vector3::new(d[0], d[1], d[2]).cross(&cv);
                    let r = &mut resp[k];
                    r.a += cv * cv.transpose() * k6;
                    r.c += cv * dc.transpose() * k6;
                    r.d += dc * dc.transpose() * k6;
                    2.0 * s.f[i * n + x] - 2.0 * w * rho_a
                } else {
                    2.0 * s.f[i * n + x] - 2.0 * w * rho_a - 6.0 * w * s.rho[x] * cu
                };
                let fl = c.map(|v| mag * v);
                let arm = [d[0] - 0.5 * c[0], d[1] - 0.5 * c[1], d[2] - 0.5 * c[2]];
                for a in 0..3 {
                    force[k][a] += fl[a];
                }
                let t = cross(arm, fl);
                for a in 0..3 {
                    torque[k][a] += t[a];
                }
            }
        }
        let fs = sc.force_si();
        self.load.clear();
        for k in 0..ns {
            let mut f = force[k];
            if self.conserve_momentum {
                for a in 0..3 {
                    f[a] += impulse[k][a];
                }
            }
            self.load.push((
                Vec3::new(f[0] * fs, f[1] * fs, f[2] * fs),
                Vec3::new(torque[k][0], torque[k][1], torque[k][2]) * (fs * sc.dx),
            ));
        }
        if implicit {
            for r in &mut resp {
                r.a *= fs * sc.dt / sc.dx;
                r.c *= fs * sc.dt;
                r.d *= fs * sc.dx * sc.dt;
            }
            self.implicit_update(sys, &resp, gravity);
        }
    }

    /// The `implicit` coupling (module doc): each mobile body's velocity and spin of the step,
    /// then every grain node's surface velocity from them (Eq. 20) and each sphere's load
    /// F_rest − K u.
    fn implicit_update(&mut self, sys: &SphereSystem, resp: &[VelocityResponse], gravity: Vec3) {
        let s = &sys.spheres;
        let cl = &sys.clumps;
        let dt = self.scale.dt;
        let ns = s.len();
        // (v, ω) of every sphere's body as predicted; frozen and driven spheres keep theirs
        let mut pred: Vec<(Vec3, Vec3)> = (0..ns).map(|k| (s.vel[k], s.omega[k])).collect();
        let solve = |members: &[(usize, Vec3)], mass: f64, inertia: Matrix3<f64>, v: Vec3, l: Vec3| {
            let mut k6 = Matrix6::<f64>::zeros();
            let mut rhs = Vector6::<f64>::zeros();
            for &(m, b) in members {
                let r = &resp[m];
                let bx = skew(b);
                let c_eff = r.c - r.a * bx;
                let mut blk = Matrix6::zeros();
                blk.fixed_view_mut::<3, 3>(0, 0).copy_from(&r.a);
                blk.fixed_view_mut::<3, 3>(0, 3).copy_from(&c_eff);
                blk.fixed_view_mut::<3, 3>(3, 0)
                    .copy_from(&(bx * r.a + r.c.transpose()));
                blk.fixed_view_mut::<3, 3>(3, 3)
                    .copy_from(&(bx * c_eff + r.d - r.c.transpose() * bx));
                k6 += blk;
                let (f, t) = self.load[m];
                let (f, t): (Vector3<f64>, Vector3<f64>) = (f.into(), t.into());
                let t = t + bx * f;
                rhs.fixed_rows_mut::<3>(0).add_assign(&(f * dt));
                rhs.fixed_rows_mut::<3>(3).add_assign(&(t * dt));
            }
            let mut mm = Matrix6::<f64>::zeros();
            mm.fixed_view_mut::<3, 3>(0, 0)
                .copy_from(&(Matrix3::identity() * mass));
            mm.fixed_view_mut::<3, 3>(3, 3).copy_from(&inertia);
            let g: Vector3<f64> = gravity.into();
            let (v, l): (Vector3<f64>, Vector3<f64>) = (v.into(), l.into());
            rhs.fixed_rows_mut::<3>(0)
                .add_assign(&(v * mass + g * (mass * dt)));
            rhs.fixed_rows_mut::<3>(3).add_assign(&l);
            let u = (mm + k6 * dt).lu().solve(&rhs)?;
            Some((Vec3::new(u[0], u[1], u[2]), Vec3::new(u[3], u[4], u[5])))
        };
        for k in 0..ns {
            if sys.is_mobile(k) && !self.is_driven(k) {
                let i = Matrix3::identity() * s.inertia[k];
                let l = s.omega[k] * s.inertia[k];
                if let Some(u) = solve(&[(k, Vec3::ZERO)], s.mass[k], i, s.vel[k], l) {
                    pred[k] = u;
                }
            }
        }
        for c in 0..cl.len() {
            let members: Vec<(usize, Vec3)> = cl
                .members_of(c)
                .map(|(m, _)| (m, sys.domain.min_image(s.pos[m] - cl.pos[c])))
                .collect();
            let rot = cl.orientation(c).to_rotation_matrix();
            let i = rot.matrix() * Matrix3::from_diagonal(&cl.inertia[c].into()) * rot.matrix().transpose();
            if let Some((v, w)) = solve(&members, cl.mass[c], i, cl.vel[c], cl.ang_mom[c]) {
                for (m, b) in members {
                    pred[m] = (v + w.cross(b), w);
                }
            }
        }
        // the surface velocities the liquid bounces back with, and the loads F_rest − K u
        let f = self.scale.dt / self.scale.dx;
        for &y in &self.owned {
            let y = y as usize;
            let k = self.owner[y] as usize;
            if self.is_driven(k) || sys.is_frozen(k) {
                continue;
            }
            let d = self.offset(sys, k, y);
            let (v, w) = pred[k];
            let u = v + w.cross(Vec3::new(d[0], d[1], d[2]) * self.scale.dx);
            self.liquid.solid_u[y] = [u.x * f, u.y * f, u.z * f];
        }
        for k in 0..ns {
            if sys.is_frozen(k) || self.is_driven(k) {
                continue;
            }
            let (df, dt_) = resp[k].load(pred[k].0, pred[k].1);
            self.load[k].0 += df;
            self.load[k].1 += dt_;
        }
    }

    fn is_driven(&self, k: usize) -> bool {
        self.driven.as_ref().is_some_and(|(r, _)| r.contains(&k))
    }

    /// Offset (lattice units) of node `y` from the centre of sphere `k`, the minimum image on
    /// periodic axes.
    fn offset(&self, sys: &SphereSystem, k: usize, y: usize) -> [f64; 3] {
        let dom = &self.liquid.domain;
        let sc = &self.scale;
        let p = dom.coords(y);
        let c = sys.spheres.pos[k];
        let c = [c.x, c.y, c.z];
        let mut d = [0.0; 3];
        for a in 0..3 {
            let mut v = p[a] as f64 - ((c[a] - sc.origin[a]) / sc.dx - 0.5);
            if dom.faces[2 * a].is_periodic() {
                let l = dom.n[a] as f64;
                v -= l * (v / l).round();
            }
            d[a] = v;
        }
        d
    }
}

/// [b]×, the matrix of b × ·.
fn skew(b: Vec3) -> Matrix3<f64> {
    Matrix3::new(0.0, -b.z, b.y, b.z, 0.0, -b.x, -b.y, b.x, 0.0)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// A free-surface liquid and its grains, stepped together: one LBM step, then `substeps` DEM
/// steps with the load of that LBM step held (the load is constant over an LBM step, so the
/// impulse a grain receives is exactly the one the liquid gave).
pub struct SurfaceCoupled<L: SphereLaw> {
    pub grains: SurfaceGrains,
    pub sys: SphereSystem,
    pub dem: SphereStepper<L>,
    pub law: L,
    pub params: SphereStepParams,
    pub substeps: u32,
}

/// Adds the held hydrodynamic loads.
struct HeldLoads<'a>(&'a [(Vec3, Vec3)]);

impl SphereForceHook for HeldLoads<'_> {
    fn post_force(&mut self, _: f64, _: &SphereSystem, force: &mut [Vec3], torque: &mut [Vec3]) {
        for (k, (f, t)) in self.0.iter().enumerate() {
            force[k] += *f;
            torque[k] += *t;
        }
    }
}

impl<L: SphereLaw> SurfaceCoupled<L> {
    /// Check that the DEM step is the LBM step over `substeps` and the domains agree.
    pub fn new(
        grains: SurfaceGrains,
        sys: SphereSystem,
        law: L,
        params: SphereStepParams,
        substeps: u32,
    ) -> Result<Self, CouplingError> {
        grains.check_domain(&sys)?;
        let dt = grains.scale().dt;
        let want = dt / substeps.max(1) as f64;
        if substeps == 0 || ((params.dt - want) / want).abs() > 1e-12 {
            return Err(CouplingError::Unsupported(format!(
                "DEM step {} s with {substeps} sub-steps per LBM step of {dt} s: the DEM step must \
                 be dt_LBM / substeps = {want} s",
                params.dt
            )));
        }
        Ok(Self {
            grains,
            sys,
            dem: SphereStepper::new(),
            law,
            params,
            substeps,
        })
    }

    /// One LBM step and its DEM sub-steps.
    pub fn step(&mut self) -> Result<Conversions, CouplingError> {
        let conv = self.grains.exchange(&self.sys, self.params.gravity)?;
        let mut hook = HeldLoads(&self.grains.load);
        for _ in 0..self.substeps {
            self.dem
                .step_with(&self.params, &self.law, &mut self.sys, &mut hook)
                .map_err(CouplingError::Spheres)?;
        }
        Ok(conv)
    }
}
