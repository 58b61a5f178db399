//! Rigid clumps of spheres (Leonardi et al. 2014, Sect. 3: composite elements; four-sphere
//! tetrahedra there): mass properties of the union of overlapping spheres, the clump state, and
//! the free rotation of an asymmetric rigid body.
//!
//! A clump's member spheres live in [`super::Spheres`] like free spheres (their contacts are
//! found and evaluated the same way, pairs inside one clump left out); their positions and
//! velocities are slaved to the clump: x_s = x_c + Q b_s, v_s = v_c + ω × Q b_s, where b_s is
//! the member's offset in the body frame (principal axes) and Q the orientation.
//!
//! Time integration (in the stepper): the velocity-Verlet half kicks act on v_c and on the
//! world-frame angular momentum L (L += T dt/2); the drift moves x_c and turns Q as a free rigid
//! body with L fixed, by the symplectic splitting of Dullweber, Leimkuhler & McLachlan (1997,
//! J. Chem. Phys. 107:5840): rotations about the body axes x (dt/2), y (dt/2), z (dt), y (dt/2),
//! x (dt/2), each by the angle L_k τ / I_k of the body-frame angular momentum, which rotates
//! the opposite way in the body frame. |L| and |Q| are kept exactly; the energy error stays
//! bounded. ω = Q I⁻¹ Qᵀ L.

use super::error::SphereError;
use crate::vector::Vec3;
use nalgebra::{Matrix3, Quaternion, SymmetricEigen, Unit, UnitQuaternion, Vector3};
use serde::{Deserialize, Serialize};

/// A clump's spheres, (centre, radius), in any frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ClumpTemplate {
    pub spheres: Vec<(Vec3, f64)>,
}

/// Mass properties of the union of the spheres at unit density, in the template's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnionProps {
    /// Volume of the union (overlaps counted once), m³.
    pub volume: f64,
    /// Its centroid.
    pub centroid: Vec3,
    /// Inertia tensor about the centroid per unit density, m⁵ (row-major).
    pub inertia: [[f64; 3]; 3],
}

/// Quadrature nodes per piece of each axis in [`ClumpTemplate::union_props`] by default.
pub const DEFAULT_NODES: usize = 48;

impl ClumpTemplate {
    /// A regular tetrahedron of four spheres of radius `r`, centres `edge` apart, centred on the
    /// origin (Leonardi et al. 2014's composite grain).
    pub fn tetrahedron(r: f64, edge: f64) -> Self {
        let s = edge / (2.0 * 2f64.sqrt());
        let c = [
            (1.0, 1.0, 1.0),
            (1.0, -1.0, -1.0),
            (-1.0, 1.0, -1.0),
            (-1.0, -1.0, 1.0),
        ];
        Self {
            spheres: c
                .iter()
                .map(|&(x, y, z)| (Vec3::new(x * s, y * s, z * s), r))
                .collect(),
        }
    }

    /// Volume, centroid and inertia of the union of the spheres (overlaps counted once).
    ///
    /// Integrated in columns along z: in each column the union of the spheres' chords is found
    /// exactly and its moments ∫dz, ∫z dz, ∫z² dz taken in closed form. Across y (at fixed x)
    /// and across x the column moments are smooth between breakpoints — where a sphere's (or a
    /// cross-section disk's) extent ends and where two of them start or stop intersecting —
    /// so each axis is cut at those, and each piece integrated with `n` nodes of a substitution
    /// whose Jacobian vanishes at the piece ends (`for_pieces`), which absorbs the square-root
    /// ends and the kinks. Measured errors at the default `n` in `tests/clumps.rs`.
    pub fn union_props(&self, n: usize) -> Result<UnionProps, SphereError> {
        if self.spheres.is_empty() {
            return Err(SphereError::BadParameter {
                name: "clump sphere count",
                value: 0.0,
                why: "a clump needs at least one sphere",
            });
        }
        for &(c, r) in &self.spheres {
            if !(r > 0.0 && r.is_finite() && c.is_finite()) {
                return Err(SphereError::BadParameter {
                    name: "clump sphere radius",
                    value: r,
                    why: "every sphere of a clump needs a positive, finite radius and a finite centre",
                });
            }
        }
        if n < 4 {
            return Err(SphereError::BadParameter {
                name: "clump quadrature nodes per piece",
                value: n as f64,
                why: "the union quadrature needs at least 4 nodes per piece (default DEFAULT_NODES = 48)",
            });
        }
        let sp = &self.spheres;
        // x breakpoints: sphere extents, and the x-extent of every pairwise intersection circle.
        let mut xb: Vec<f64> = Vec::new();
        for &(c, r) in sp {
            xb.extend([c.x - r, c.x + r]);
        }
        for (a, &(ci, ri)) in sp.iter().enumerate() {
            for &(cj, rj) in &sp[a + 1..] {
                let dv = cj - ci;
                let d = (dv.x * dv.x + dv.y * dv.y + dv.z * dv.z).sqrt();
                if d > 0.0 && d < ri + rj && d > (ri - rj).abs() {
                    let s = (d * d + ri * ri - rj * rj) / (2.0 * d);
                    let rho = (ri * ri - s * s).max(0.0).sqrt();
                    let ux = dv.x / d;
                    let cx = ci.x + s * ux;
                    let e = rho * (1.0 - ux * ux).max(0.0).sqrt();
                    xb.extend([cx - e, cx + e]);
                }
            }
        }
        let mut disks: Vec<(f64, f64, f64)> = Vec::with_capacity(sp.len());
        let mut yb: Vec<f64> = Vec::new();
        let mut iv: Vec<(f64, f64)> = Vec::with_capacity(sp.len());
        // Moments: V, ∫x, ∫y, ∫z, ∫x², ∫y², ∫z², ∫xy, ∫xz, ∫yz.
        let mut m = [0.0f64; 10];
        for_pieces(&mut xb, n, |x, wx| {
            // The cross-section at x: disks (y, z, radius).
            disks.clear();
            for &(c, r) in sp {
                let q = r * r - (x - c.x) * (x - c.x);
                if q > 0.0 {
                    disks.push((c.y, c.z, q.sqrt()));
                }
            }
            yb.clear();
            for (a, &(yi, zi, ri)) in disks.iter().enumerate() {
                yb.extend([yi - ri, yi + ri]);
                for &(yj, zj, rj) in &disks[a + 1..] {
                    let (dy, dz) = (yj - yi, zj - zi);
                    let d = (dy * dy + dz * dz).sqrt();
                    if d > 0.0 && d < ri + rj && d > (ri - rj).abs() {
                        let s = (d * d + ri * ri - rj * rj) / (2.0 * d);
                        let h = (ri * ri - s * s).max(0.0).sqrt();
                        let y0 = yi + s * dy / d;
                        yb.extend([y0 - h * dz / d, y0 + h * dz / d]);
                    }
                }
            }
            for_pieces(&mut yb, n, |y, wy| {
                iv.clear();
                for &(yc, zc, r) in &disks {
                    let q = r * r - (y - yc) * (y - yc);
                    if q > 0.0 {
                        let h = q.sqrt();
                        iv.push((zc - h, zc + h));
                    }
                }
                if iv.is_empty() {
                    return;
                }
                iv.sort_by(|a, b| a.0.total_cmp(&b.0));
                let (mut s0, mut s1, mut s2) = (0.0, 0.0, 0.0);
                let (mut z0, mut z1) = iv[0];
                for &(a, b) in &iv[1..] {
                    if a > z1 {
                        s0 += z1 - z0;
                        s1 += 0.5 * (z1 * z1 - z0 * z0);
                        s2 += (z1 * z1 * z1 - z0 * z0 * z0) / 3.0;
                        (z0, z1) = (a, b);
                    } else {
                        z1 = z1.max(b);
                    }
                }
                s0 += z1 - z0;
                s1 += 0.5 * (z1 * z1 - z0 * z0);
                s2 += (z1 * z1 * z1 - z0 * z0 * z0) / 3.0;
                let w = wx * wy;
                let add = [
                    s0,
                    x * s0,
                    y * s0,
                    s1,
                    x * x * s0,
                    y * y * s0,
                    s2,
                    x * y * s0,
                    x * s1,
                    y * s1,
                ];
                for (mk, a) in m.iter_mut().zip(add) {
                    *mk += w * a;
                }
            });
        });
        let v = m[0];
        let c = Vec3::new(m[1] / v, m[2] / v, m[3] / v);
        // Central second moments.
        let xx = m[4] - v * c.x * c.x;
        let yy = m[5] - v * c.y * c.y;
        let zz = m[6] - v * c.z * c.z;
        let xy = m[7] - v * c.x * c.y;
        let xz = m[8] - v * c.x * c.z;
        let yz = m[9] - v * c.y * c.z;
        Ok(UnionProps {
            volume: v,
            centroid: c,
            inertia: [[yy + zz, -xy, -xz], [-xy, xx + zz, -yz], [-xz, -yz, xx + yy]],
        })
    }
}

/// Call `f(s, weight)` at `n` nodes of each piece between consecutive sorted, distinct
/// `breaks`: s = mid + half φ(t), φ(t) = (15 sin t − 10 sin³ t + 3 sin⁵ t)/8, t at the
/// midpoints of `n` equal cells of (−π/2, π/2), weight = half φ'(t) Δt = (15/8) half cos⁵ t Δt.
/// The Jacobian vanishes to fifth order at the piece ends, so the midpoint rule keeps a high order both where the
/// integrand has a square-root end and where it only has a kink.
fn for_pieces(breaks: &mut Vec<f64>, n: usize, mut f: impl FnMut(f64, f64)) {
    breaks.sort_by(f64::total_cmp);
    breaks.dedup();
    let dt = std::f64::consts::PI / n as f64;
    for k in 1..breaks.len() {
        let (a, b) = (breaks[k - 1], breaks[k]);
        let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
        if half <= 0.0 {
            continue;
        }
        for i in 0..n {
            let t = -std::f64::consts::FRAC_PI_2 + (i as f64 + 0.5) * dt;
            let (s, c) = t.sin_cos();
            let (s2, c2) = (s * s, c * c);
            let phi = s * (15.0 - 10.0 * s2 + 3.0 * s2 * s2) / 8.0;
            f(mid + half * phi, half * 1.875 * c * c2 * c2 * dt);
        }
    }
}

/// The body frame of a clump template at a density: principal moments, the rotation from the
/// body frame to the template frame, and the members' body-frame offsets and radii. Built once
/// per template ([`BodyFrame::of`], the union quadrature) and passed to every
/// [`super::SphereSystem::add_clump`] of that template.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyFrame {
    /// Density of the clump (kg/m³).
    pub density: f64,
    pub mass: f64,
    pub inertia: Vec3,
    /// Body frame → template frame.
    pub to_template: UnitQuaternion<f64>,
    pub offsets: Vec<Vec3>,
    /// The members' radii (m), in the template's order.
    pub radii: Vec<f64>,
}

impl BodyFrame {
    /// The body frame of `t` at density `rho` (kg/m³), the union's mass properties integrated
    /// with `nodes` per piece ([`ClumpTemplate::union_props`], e.g. [`DEFAULT_NODES`]).
    pub fn of(t: &ClumpTemplate, rho: f64, nodes: usize) -> Result<Self, SphereError> {
        if !(rho > 0.0 && rho.is_finite()) {
            return Err(SphereError::BadParameter {
                name: "clump density",
                value: rho,
                why: "it must be positive and finite (kg/m^3)",
            });
        }
        let p = t.union_props(nodes)?;
        let i = Matrix3::from_fn(|r, c| rho * p.inertia[r][c]);
        let eig = SymmetricEigen::new(i);
        let mut axes = eig.eigenvectors;
        if axes.determinant() < 0.0 {
            axes.set_column(2, &(-axes.column(2)));
        }
        let rot = nalgebra::Rotation3::from_matrix_unchecked(axes);
        let to_template = UnitQuaternion::from_rotation_matrix(&rot);
        let offsets = t
            .spheres
            .iter()
            .map(|&(c, _)| (c - p.centroid).rotated_back_by(&to_template))
            .collect();
        Ok(Self {
            density: rho,
            mass: rho * p.volume,
            inertia: Vec3::new(eig.eigenvalues[0], eig.eigenvalues[1], eig.eigenvalues[2]),
            to_template,
            offsets,
            radii: t.spheres.iter().map(|&(_, r)| r).collect(),
        })
    }
}

/// The clumps' state (plain data, serialisable). Clump c's members are the spheres
/// `members[start[c]..start[c + 1]]`, with body-frame offsets `offset[start[c]..start[c + 1]]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Clumps {
    /// Centre of mass.
    pub pos: Vec<Vec3>,
    pub vel: Vec<Vec3>,
    /// Orientation, body frame → world, as a unit quaternion (w, x, y, z).
    pub quat: Vec<[f64; 4]>,
    /// Angular momentum in the world frame (kg m²/s).
    pub ang_mom: Vec<Vec3>,
    pub mass: Vec<f64>,
    /// Principal moments of inertia (body frame).
    pub inertia: Vec<Vec3>,
    /// Total force and torque of the last step.
    pub force: Vec<Vec3>,
    pub torque: Vec<Vec3>,
    pub start: Vec<u32>,
    pub members: Vec<u32>,
    pub offset: Vec<Vec3>,
}

impl Clumps {
    pub fn len(&self) -> usize {
        self.pos.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }
    /// Members of clump `c` as (sphere, body-frame offset).
    pub fn members_of(&self, c: usize) -> impl Iterator<Item = (usize, Vec3)> + '_ {
        let r = self.start[c] as usize..self.start[c + 1] as usize;
        self.members[r.clone()]
            .iter()
            .map(|&m| m as usize)
            .zip(self.offset[r].iter().copied())
    }
    /// Orientation of clump `c`.
    pub fn orientation(&self, c: usize) -> UnitQuaternion<f64> {
        let [w, x, y, z] = self.quat[c];
        Unit::new_unchecked(Quaternion::new(w, x, y, z))
    }
    /// Angular velocity of clump `c` in the world frame: Q I⁻¹ Qᵀ L.
    pub fn omega(&self, c: usize) -> Vec3 {
        let q = self.orientation(c);
        let lb = self.ang_mom[c].rotated_back_by(&q);
        let i = self.inertia[c];
        Vec3::new(lb.x / i.x, lb.y / i.y, lb.z / i.z).rotated_by(&q)
    }
    /// Rotational kinetic energy of clump `c`, (1/2) L·ω.
    pub fn rotational_energy(&self, c: usize) -> f64 {
        let w = self.omega(c);
        let l = self.ang_mom[c];
        0.5 * (l.x * w.x + l.y * w.y + l.z * w.z)
    }
}

/// Turn `q` over `dt` as a free rigid body of principal moments `inertia` with world-frame
/// angular momentum `l` (the splitting in the module docs); returns the new unit quaternion.
pub fn free_rotation(q: UnitQuaternion<f64>, l: Vec3, inertia: Vec3, dt: f64) -> UnitQuaternion<f64> {
    let mut q = q;
    let mut lb: Vector3<f64> = l.rotated_back_by(&q).into();
    let axes = [Vector3::x_axis(), Vector3::y_axis(), Vector3::z_axis()];
    let moments = [inertia.x, inertia.y, inertia.z];
    for (k, tau) in [(0, 0.5), (1, 0.5), (2, 1.0), (1, 0.5), (0, 0.5)] {
        let angle = lb[k] / moments[k] * tau * dt;
        let r = UnitQuaternion::from_axis_angle(&axes[k], angle);
        q *= r;
        lb = r.inverse_transform_vector(&lb);
    }
    q.renormalize();
    q
}

/// A quaternion as the state stores it, (w, x, y, z).
#[inline]
pub(crate) fn quat_array(q: &UnitQuaternion<f64>) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}
