//! Checks of a sphere state read from a checkpoint (user input) or built by hand: every array
//! the right length, indices in range, bodies with positive mass, unit quaternions and wall
//! normals, finite numbers. A checkpoint is deserialised through [`RawSphereSystem`] and refused
//! with [`SphereError::Inconsistent`] naming the field, so a bad file never panics a later step;
//! the stepper runs the same check before its first step.

use super::clump::Clumps;
use super::domain::Domain3;
use super::error::SphereError;
use super::system::{FREE, PlaneWall, SphereContacts, SphereSystem, Spheres};
use crate::vector::{Vec3, Vector};
use serde::Deserialize;

/// Tolerance on |q| − 1 of a stored clump orientation and on |n| − 1 of a wall normal (they
/// are renormalised every step, so a valid file is within rounding).
const UNIT_TOL: f64 = 1e-12;

/// The serialised form of [`SphereSystem`], checked on the way in.
#[derive(Deserialize)]
pub struct RawSphereSystem {
    domain: Domain3,
    spheres: Spheres,
    walls: Vec<PlaneWall>,
    contacts: SphereContacts,
    #[serde(default)]
    clumps: Clumps,
    time: f64,
    step: u64,
}

impl TryFrom<RawSphereSystem> for SphereSystem {
    type Error = SphereError;
    fn try_from(r: RawSphereSystem) -> Result<Self, SphereError> {
        let mut sys = SphereSystem {
            domain: r.domain,
            spheres: r.spheres,
            walls: r.walls,
            contacts: r.contacts,
            clumps: r.clumps,
            time: r.time,
            step: r.step,
        };
        // Checkpoints from before clumps carry no owners: every sphere free.
        if sys.spheres.owner.is_empty() {
            sys.spheres.owner = vec![FREE; sys.spheres.len()];
        }
        // Checkpoints from before frozen grains: every sphere mobile.
        if sys.spheres.frozen.is_empty() {
            sys.spheres.frozen = vec![false; sys.spheres.len()];
        }
        sys.validate()?;
        Ok(sys)
    }
}

fn bad(field: &'static str, found: impl ToString, expected: impl ToString) -> SphereError {
    SphereError::Inconsistent {
        field,
        found: found.to_string(),
        expected: expected.to_string(),
    }
}

fn len_is(field: &'static str, len: usize, n: usize) -> Result<(), SphereError> {
    if len == n {
        Ok(())
    } else {
        Err(bad(field, format!("{len} long"), format!("{n} long")))
    }
}

fn all_finite(field: &'static str, v: &[Vec3]) -> Result<(), SphereError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(k) => Err(bad(field, format!("non-finite at entry {k}"), "finite")),
        None => Ok(()),
    }
}

fn all_positive(field: &'static str, v: impl IntoIterator<Item = f64>) -> Result<(), SphereError> {
    match v
        .into_iter()
        .enumerate()
        .find(|(_, x)| !(*x > 0.0 && x.is_finite()))
    {
        Some((k, x)) => Err(bad(field, format!("{x} at entry {k}"), "positive and finite")),
        None => Ok(()),
    }
}

impl SphereSystem {
    /// Check the state's consistency (see the module docs).
    pub fn validate(&self) -> Result<(), SphereError> {
        Domain3::new(self.domain.lo, self.domain.hi, self.domain.periodic)?;
        self.domain.check_shear()?;
        if !self.contacts.list_offset.is_finite() {
            return Err(bad("contacts.list_offset", self.contacts.list_offset, "finite"));
        }
        let s = &self.spheres;
        let n = s.len();
        len_is("spheres.vel", s.vel.len(), n)?;
        len_is("spheres.omega", s.omega.len(), n)?;
        len_is("spheres.force", s.force.len(), n)?;
        len_is("spheres.torque", s.torque.len(), n)?;
        len_is("spheres.radius", s.radius.len(), n)?;
        len_is("spheres.mass", s.mass.len(), n)?;
        len_is("spheres.inertia", s.inertia.len(), n)?;
        len_is("spheres.owner", s.owner.len(), n)?;
        len_is("spheres.frozen", s.frozen.len(), n)?;
        for (field, v) in [
            ("spheres.pos", &s.pos),
            ("spheres.vel", &s.vel),
            ("spheres.omega", &s.omega),
            ("spheres.force", &s.force),
            ("spheres.torque", &s.torque),
        ] {
            all_finite(field, v)?;
        }
        self.inside_periodic("spheres.pos", "sphere", &s.pos)?;
        if let Some(k) = (0..n).find(|&k| {
            s.frozen[k] && (s.owner[k] != FREE || s.vel[k] != Vec3::ZERO || s.omega[k] != Vec3::ZERO)
        }) {
            return Err(bad(
                "spheres.frozen",
                format!(
                    "sphere {k} frozen with owner {}, velocity {:?}, spin {:?}",
                    s.owner[k], s.vel[k], s.omega[k]
                ),
                "frozen spheres free of clumps, at rest",
            ));
        }
        all_positive("spheres.radius", s.radius.iter().copied())?;
        all_positive("spheres.mass", s.mass.iter().copied())?;
        all_positive("spheres.inertia", s.inertia.iter().copied())?;
        if !self.time.is_finite() {
            return Err(bad("time", self.time, "finite"));
        }
        for (k, w) in self.walls.iter().enumerate() {
            let ok = w.point.is_finite() && w.vel.is_finite() && (w.normal.norm() - 1.0).abs() <= UNIT_TOL;
            if !ok {
                return Err(bad(
                    "walls",
                    format!(
                        "wall {k}: point {:?}, normal {:?}, vel {:?}",
                        w.point, w.normal, w.vel
                    ),
                    "finite point and velocity, unit normal",
                ));
            }
        }
        self.validate_contacts()?;
        self.validate_clumps()
    }

    /// Positions inside [lo, hi) on every periodic axis (the stepper wraps them there; the
    /// minimum image assumes it, and the cell list would file them in the wrong cell).
    fn inside_periodic(&self, field: &'static str, what: &str, pos: &[Vec3]) -> Result<(), SphereError> {
        const AXES: [&str; 3] = ["x", "y", "z"];
        let d = &self.domain;
        for (k, p) in pos.iter().enumerate() {
            for (a, axis) in AXES.iter().enumerate() {
                let (lo, hi, v) = (d.lo.component(a), d.hi.component(a), p.component(a));
                if d.periodic[a] && !(v >= lo && v < hi) {
                    return Err(bad(
                        field,
                        format!(
                            "{what} {k} at {axis} = {v:e} m, outside [{lo:e}, {hi:e}) on the periodic axis {axis}"
                        ),
                        "positions inside the box on periodic axes: wrap them with Domain3::wrap_moving \
                         (position and velocity, for the Lees-Edwards shift), as add_sphere and add_clump do",
                    ));
                }
            }
        }
        Ok(())
    }

    fn validate_contacts(&self) -> Result<(), SphereError> {
        let n = self.spheres.len() as u32;
        let c = &self.contacts;
        for (k, p) in c.pairs.iter().enumerate() {
            let sorted = k == 0 || c.pairs[k - 1] < *p;
            if !(p[0] < p[1] && p[1] < n && sorted) {
                return Err(bad(
                    "contacts.pairs",
                    format!("pair {k} = {p:?}"),
                    format!("i < j < {n}, in strictly ascending order"),
                ));
            }
        }
        if !c.hist.is_empty() && c.hist.len() != c.pairs.len() {
            return Err(bad(
                "contacts.hist",
                format!("{} records", c.hist.len()),
                format!("one per pair ({})", c.pairs.len()),
            ));
        }
        // A list_ref of another length (spheres added since) only forces a rebuild.
        all_finite("contacts.list_ref", &c.list_ref)
    }

    fn validate_clumps(&self) -> Result<(), SphereError> {
        let cl = &self.clumps;
        let nc = cl.len();
        len_is("clumps.vel", cl.vel.len(), nc)?;
        len_is("clumps.quat", cl.quat.len(), nc)?;
        len_is("clumps.ang_mom", cl.ang_mom.len(), nc)?;
        len_is("clumps.mass", cl.mass.len(), nc)?;
        len_is("clumps.inertia", cl.inertia.len(), nc)?;
        len_is("clumps.force", cl.force.len(), nc)?;
        len_is("clumps.torque", cl.torque.len(), nc)?;
        len_is("clumps.offset", cl.offset.len(), cl.members.len())?;
        if nc == 0 {
            if !(cl.start.len() <= 1 && cl.members.is_empty()) {
                return Err(bad(
                    "clumps.start",
                    format!("{:?}", cl.start),
                    "[] or [0] with no clumps",
                ));
            }
        } else {
            len_is("clumps.start", cl.start.len(), nc + 1)?;
            let ok = cl.start[0] == 0
                && cl.start.windows(2).all(|w| w[0] < w[1])
                && cl.start[nc] as usize == cl.members.len();
            if !ok {
                return Err(bad(
                    "clumps.start",
                    format!("{:?}", cl.start),
                    format!(
                        "from 0, increasing, ending at the member count {}",
                        cl.members.len()
                    ),
                ));
            }
        }
        for (field, v) in [
            ("clumps.pos", &cl.pos),
            ("clumps.vel", &cl.vel),
            ("clumps.ang_mom", &cl.ang_mom),
            ("clumps.force", &cl.force),
            ("clumps.torque", &cl.torque),
            ("clumps.offset", &cl.offset),
        ] {
            all_finite(field, v)?;
        }
        self.inside_periodic("clumps.pos", "clump", &cl.pos)?;
        all_positive("clumps.mass", cl.mass.iter().copied())?;
        all_positive("clumps.inertia", cl.inertia.iter().flat_map(|i| [i.x, i.y, i.z]))?;
        for (k, q) in cl.quat.iter().enumerate() {
            let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            let unit = (norm - 1.0).abs() <= UNIT_TOL;
            if !unit {
                return Err(bad(
                    "clumps.quat",
                    format!("|q| = {norm} for clump {k}"),
                    "a unit quaternion",
                ));
            }
        }
        // Members and owners agree both ways: every member is owned by its clump, and as many
        // spheres are owned as there are members.
        let owner = &self.spheres.owner;
        for c in 0..nc {
            for (m, _) in cl.members_of(c) {
                if owner.get(m) != Some(&(c as u32)) {
                    return Err(bad(
                        "clumps.members",
                        format!("sphere {m} listed in clump {c}"),
                        format!("an existing sphere whose owner is {c}"),
                    ));
                }
            }
        }
        let owned = owner.iter().filter(|&&o| o != FREE).count();
        if let Some(k) = owner.iter().position(|&o| o != FREE && o as usize >= nc) {
            return Err(bad(
                "spheres.owner",
                format!("{} for sphere {k}", owner[k]),
                format!("FREE or below {nc}"),
            ));
        }
        if owned != cl.members.len() {
            return Err(bad(
                "spheres.owner",
                format!("{owned} spheres owned by clumps"),
                format!("the member count {}", cl.members.len()),
            ));
        }
        Ok(())
    }
}
