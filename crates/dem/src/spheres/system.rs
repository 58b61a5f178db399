//! The state of a sphere assembly, plain data and serialisable: spheres, plane walls, the
//! Verlet list with its contact histories, the clock. A checkpoint is this struct written with
//! `serde_json` (`float_roundtrip`); a run resumed from it continues bit for bit, because every
//! quantity the step reads — the last forces, the pair list and the positions it was built at —
//! is here, and the stepper holds only scratch. A checkpoint is user input: it is checked on
//! the way in (`validate.rs`).

use super::clump::{BodyFrame, Clumps, quat_array};
use super::domain::Domain3;
use super::error::SphereError;
use super::validate::RawSphereSystem;
use crate::history::Histories;
use crate::vector::{Vec3, Vector};
use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};

/// The spheres, one entry per sphere in every array (structure of arrays).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Spheres {
    pub pos: Vec<Vec3>,
    pub vel: Vec<Vec3>,
    /// Angular velocity ω (rad/s).
    pub omega: Vec<Vec3>,
    /// Total force of the last step (contacts and gravity), N.
    pub force: Vec<Vec3>,
    /// Total torque of the last step about the centre, N m.
    pub torque: Vec<Vec3>,
    pub radius: Vec<f64>,
    pub mass: Vec<f64>,
    /// Moment of inertia about the centre, (2/5) m r² for a solid sphere.
    pub inertia: Vec<f64>,
    /// The clump a sphere belongs to, or [`FREE`] (absent in older checkpoints: all free).
    #[serde(default)]
    pub owner: Vec<u32>,
    /// Frozen grains (Ness et al. 2017's walls of fixed small spheres): not integrated (position
    /// fixed, velocity and spin zero), pairs of two frozen grains left out of the list, the force
    /// on them still summed in `force` (the wall's load). Absent in older checkpoints: all mobile.
    #[serde(default)]
    pub frozen: Vec<bool>,
}

/// `owner` of a sphere that belongs to no clump.
pub const FREE: u32 = u32::MAX;

impl Spheres {
    pub fn len(&self) -> usize {
        self.pos.len()
    }
    pub fn is_empty(&self) -> bool {
        self.pos.is_empty()
    }
}

/// An infinite plane wall: spheres live on the side its normal points to.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlaneWall {
    /// A point of the plane (moves with `vel`).
    pub point: Vec3,
    /// Unit normal, pointing into the region of the spheres.
    pub normal: Vec3,
    /// Translation velocity (m/s).
    #[serde(default)]
    pub vel: Vec3,
}

impl PlaneWall {
    /// A fixed plane through `point` with normal `normal` (normalised here).
    pub fn new(point: Vec3, normal: Vec3) -> Result<Self, SphereError> {
        let l = normal.norm();
        if !(l > 0.0 && l.is_finite() && point.is_finite()) {
            return Err(SphereError::BadParameter {
                name: "wall normal length",
                value: l,
                why: "a plane wall needs a finite point and a non-zero, finite normal",
            });
        }
        Ok(Self {
            point,
            normal: normal * (1.0 / l),
            vel: Vec3::ZERO,
        })
    }
}

/// The Verlet pair list and the contact histories, in the contact law's own record type
/// ([`super::SphereLaw::History`]; e.g. the tangential spring ξ of [`super::HertzMindlinSpring`]).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SphereContacts {
    /// Candidate pairs (i < j), sorted.
    pub pairs: Vec<[u32; 2]>,
    /// History of each pair (fresh when out of the law's range).
    pub hist: Histories,
    /// History of each sphere-wall contact, index `sphere * n_walls + wall` (sphere-major:
    /// appended spheres append records, a removed sphere takes its row out).
    pub wall_hist: Histories,
    /// The wall count `wall_hist` is laid out for (0 in older checkpoints: then the records
    /// are kept only if there are exactly spheres × walls of them). Adding or removing a wall
    /// resets the sphere-wall histories.
    #[serde(default)]
    pub wall_count: usize,
    /// Sphere positions when the list was built (the rebuild test reads them).
    pub list_ref: Vec<Vec3>,
    /// The Lees-Edwards offset when the list was built (0 in older checkpoints and without
    /// shear): pairs across the sheared faces move apart by its change as well.
    #[serde(default)]
    pub list_offset: f64,
}

/// A sphere assembly: state only (see the module docs).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "RawSphereSystem")]
pub struct SphereSystem {
    pub domain: Domain3,
    pub spheres: Spheres,
    pub walls: Vec<PlaneWall>,
    pub contacts: SphereContacts,
    /// Rigid clumps of spheres (their members are in `spheres`).
    #[serde(default)]
    pub clumps: Clumps,
    /// Simulated time (s).
    pub time: f64,
    /// Steps taken.
    pub step: u64,
}

impl SphereSystem {
    pub fn new(domain: Domain3) -> Self {
        Self {
            domain,
            spheres: Spheres::default(),
            walls: Vec::new(),
            contacts: SphereContacts::default(),
            clumps: Clumps::default(),
            time: 0.0,
            step: 0,
        }
    }

    /// Add a solid sphere of radius `r` and density `rho` at `pos` (wrapped into the box on
    /// periodic axes, its velocity shifted with it across Lees-Edwards faces) moving at `vel`,
    /// spinning at `omega`; returns its index.
    pub fn add_sphere(
        &mut self,
        pos: Vec3,
        vel: Vec3,
        omega: Vec3,
        r: f64,
        rho: f64,
    ) -> Result<usize, SphereError> {
        if !(r > 0.0 && r.is_finite()) {
            return Err(SphereError::BadParameter {
                name: "sphere radius",
                value: r,
                why: "it must be positive and finite (m)",
            });
        }
        if !(rho > 0.0 && rho.is_finite()) {
            return Err(SphereError::BadParameter {
                name: "sphere density",
                value: rho,
                why: "it must be positive and finite (kg/m^3)",
            });
        }
        let s = &mut self.spheres;
        if ![pos, vel, omega].iter().all(|v| v.is_finite()) {
            return Err(SphereError::NonFinite {
                sphere: s.len(),
                step: self.step,
            });
        }
        let m = rho * 4.0 / 3.0 * std::f64::consts::PI * r * r * r;
        let (pos, vel) = self.domain.wrap_moving(pos, vel);
        s.pos.push(pos);
        s.vel.push(vel);
        s.omega.push(omega);
        s.force.push(Vec3::ZERO);
        s.torque.push(Vec3::ZERO);
        s.radius.push(r);
        s.mass.push(m);
        s.inertia.push(0.4 * m * r * r);
        s.owner.push(FREE);
        s.frozen.push(false);
        Ok(s.len() - 1)
    }

    /// Add a rigid clump of the template whose body frame is `frame` ([`BodyFrame::of`], built
    /// once per template and density), its centre of mass at `pos`, turned by `orientation`
    /// from the template's frame, moving at `vel`, spinning at `omega`; returns the clump's
    /// index.
    pub fn add_clump(
        &mut self,
        frame: &BodyFrame,
        pos: Vec3,
        orientation: UnitQuaternion<f64>,
        vel: Vec3,
        omega: Vec3,
    ) -> Result<usize, SphereError> {
        let c = self.clumps.len();
        if ![pos, vel, omega].iter().all(|v| v.is_finite()) {
            return Err(SphereError::NonFiniteClump { clump: c });
        }
        let q = orientation * frame.to_template;
        let first = self.spheres.len();
        for (k, (&b, &r)) in frame.offsets.iter().zip(&frame.radii).enumerate() {
            let arm = b.rotated_by(&q);
            self.add_sphere(pos + arm, vel + omega.cross(arm), omega, r, frame.density)?;
            self.spheres.owner[first + k] = c as u32;
        }
        let cl = &mut self.clumps;
        if cl.start.is_empty() {
            cl.start.push(0);
        }
        cl.members.extend((first..self.spheres.len()).map(|k| k as u32));
        cl.offset.extend_from_slice(&frame.offsets);
        cl.start.push(cl.members.len() as u32);
        let i = frame.inertia;
        // L = Q I Qᵀ ω.
        let wb = omega.rotated_back_by(&q);
        let l = Vec3::new(i.x * wb.x, i.y * wb.y, i.z * wb.z).rotated_by(&q);
        let (pos, vel) = self.domain.wrap_moving(pos, vel);
        cl.pos.push(pos);
        cl.vel.push(vel);
        cl.quat.push(quat_array(&q));
        cl.ang_mom.push(l);
        cl.mass.push(frame.mass);
        cl.inertia.push(i);
        cl.force.push(Vec3::ZERO);
        cl.torque.push(Vec3::ZERO);
        Ok(c)
    }

    /// True if sphere `k` moves by itself (belongs to no clump).
    #[inline]
    pub fn is_free(&self, k: usize) -> bool {
        self.spheres.owner.get(k).is_none_or(|&o| o == FREE)
    }

    /// True if sphere `k` is frozen (see [`Spheres::frozen`]).
    #[inline]
    pub fn is_frozen(&self, k: usize) -> bool {
        self.spheres.frozen.get(k).is_some_and(|&f| f)
    }

    /// True if sphere `k` is integrated by itself: free and not frozen.
    #[inline]
    pub fn is_mobile(&self, k: usize) -> bool {
        self.is_free(k) && !self.is_frozen(k)
    }

    /// Freeze sphere `k` in place (its velocity and spin set to zero) or release it. A clump
    /// member cannot be frozen (the clump integrates it).
    pub fn set_frozen(&mut self, k: usize, frozen: bool) -> Result<(), SphereError> {
        let n = self.spheres.len();
        if k >= n {
            return Err(SphereError::NoSuchSphere { sphere: k, count: n });
        }
        if !self.is_free(k) {
            return Err(SphereError::ClumpMember {
                sphere: k,
                clump: self.spheres.owner[k] as usize,
                action: "frozen",
            });
        }
        let s = &mut self.spheres;
        s.frozen[k] = frozen;
        if frozen {
            s.vel[k] = Vec3::ZERO;
            s.omega[k] = Vec3::ZERO;
        }
        Ok(())
    }

    /// Translational plus rotational kinetic energy of free spheres and clumps (J).
    pub fn kinetic_energy(&self) -> f64 {
        let s = &self.spheres;
        let free: f64 = (0..s.len())
            .filter(|&k| self.is_free(k))
            .map(|k| 0.5 * s.mass[k] * s.vel[k].norm2() + 0.5 * s.inertia[k] * s.omega[k].norm2())
            .sum();
        let c = &self.clumps;
        let clumps: f64 = (0..c.len())
            .map(|k| 0.5 * c.mass[k] * c.vel[k].norm2() + c.rotational_energy(k))
            .sum();
        free + clumps
    }

    /// Total linear momentum of free spheres and clumps (kg m/s).
    pub fn momentum(&self) -> Vec3 {
        let s = &self.spheres;
        let c = &self.clumps;
        let free = (0..s.len())
            .filter(|&k| self.is_free(k))
            .fold(Vec3::ZERO, |acc, k| acc + s.vel[k] * s.mass[k]);
        (0..c.len()).fold(free, |acc, k| acc + c.vel[k] * c.mass[k])
    }

    /// Total angular momentum about the origin (kg m²/s): x × m v + I ω of free spheres,
    /// x_c × m v_c + L of clumps (positions as stored, so only meaningful without periodic wrap).
    pub fn angular_momentum(&self) -> Vec3 {
        let s = &self.spheres;
        let c = &self.clumps;
        let free = (0..s.len())
            .filter(|&k| self.is_free(k))
            .fold(Vec3::ZERO, |acc, k| {
                acc + s.pos[k].cross(s.vel[k] * s.mass[k]) + s.omega[k] * s.inertia[k]
            });
        (0..c.len()).fold(free, |acc, k| {
            acc + c.pos[k].cross(c.vel[k] * c.mass[k]) + c.ang_mom[k]
        })
    }
}
