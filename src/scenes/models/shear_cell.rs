//! What a shear-cell run records (Su et al. 2020 Sect. 2.5), the same with or without liquid:
//! the push-plate's displacement and the force the grains put on it, the sample's area A_def
//! and ε_vol^DEM = ln(A_def/A_0) (Eq. 18: the polygon through the membrane grains' centroids
//! minus the plate's penetration), the mean effective stress p' of the grains (from the DEM
//! stress tensor) and the inertial number of Eq. 20.
//!
//! With `[shear_cell] settle`, the plate is held still for that long first, and A_0 and the
//! plate's origin are taken when it starts to move. The assemblies are relaxed inside the
//! sample's walls and the membrane goes on unstressed (docs/su2020.md), so without it the
//! sample expands against the membrane in the run's first second: ε_vol^DEM +0.015 (84 %PK) to
//! +0.05 (95 %PK) before the plate has moved 0.3 d̄ in the 30 µm/s runs, counted as
//! shear-induced dilation.

use crate::scenes::build::dem::wall_anchor;
use crate::scenes::run::wall_index;
use crate::scenes::schema::Scene;
use anyhow::{Result, bail};
use lbdem_dem::polygon::{contains, plate_region, sample_area};
use lbdem_dem::{Stepper, System, Vec2, Vector, WallMotion};

pub const COLUMNS: [&str; 9] = [
    "settling",
    "plate_displacement",
    "plate_displacement_d",
    "plate_force",
    "sample_area",
    "eps_vol_dem",
    "mean_stress",
    "inertial_number",
    "fastest_grain",
];

/// The push-plate cell of a scene with `[shear_cell]`.
#[derive(Clone, Debug)]
pub struct ShearCell {
    /// The plate's index in `System::walls`.
    pub plate: usize,
    /// Unit vector the plate moves along.
    dir: Vec2,
    /// The plate's speed (m/s), du_y/dt.
    speed: f64,
    /// Membrane members in ring order.
    order: Vec<usize>,
    /// Whether each body is a membrane member.
    member: Vec<bool>,
    /// γ̇ of Eq. 20 (1/s).
    shear_rate: f64,
    /// Mean equivalent-area grain diameter d̄ (m).
    pub d_mean: f64,
}

/// Move the push-plate back along its motion until no grain circle overlaps it, before the
/// first step; the distance moved (m), 0 when nothing overlapped, None without `[shear_cell]`.
///
/// An assembly built inside servo walls leaves its bottom row a few µm into where the plate is
/// drawn (the 84 %PK assembly: 4.5 µm); with the paper's grain-wall stiffness (31.1 N/m) and
/// grains of 6e-9 kg that overlap is released at about 0.2 m/s in the first steps, which blew up
/// the unscaled pk84-2150um scene's lattice at LBM step 217 (docs/minimal.md). A fresh run only:
/// a resumed one takes the plate from its checkpoint.
pub fn clear_plate(s: &Scene, sys: &mut System) -> Result<Option<f64>> {
    let Some(sc) = &s.shear_cell else {
        return Ok(None);
    };
    let k = wall_index(s, &sc.plate).map_err(|e| anyhow::anyhow!("[shear_cell] plate: {e}"))?;
    let dir = match sys.walls[k].motion {
        WallMotion::Velocity { v } if v.norm() > 0.0 => v * (1.0 / v.norm()),
        // ShearCell::new refuses it with the reason.
        _ => return Ok(Some(0.0)),
    };
    let mut moved = 0.0;
    // A segment tilted against its motion needs more than one pass; three settle any plate.
    for _ in 0..3 {
        let b = &sys.bodies;
        let deepest = (0..b.n_circles())
            .filter_map(|c| sys.walls[k].touch_within(b.circle_pos(c), b.circle_r[c], 0.0))
            .map(|(overlap, _)| overlap)
            .fold(0.0f64, f64::max);
        if deepest <= 0.0 {
            break;
        }
        sys.walls[k].translate(dir * -deepest);
        moved += deepest;
    }
    Ok(Some(moved))
}

/// [`clear_plate`], saying how far the plate moved when it did.
pub fn clear_plate_noting(s: &Scene, sys: &mut System) -> Result<()> {
    if let Some(d) = clear_plate(s, sys)?.filter(|d| *d > 0.0)
        && !crate::contract::quiet()
    {
        eprintln!(
            "[shear_cell]: the push-plate overlapped the grains by up to {:.2} um at the start; moved it back \
             as far along its motion, so the first step kicks no grain",
            d * 1e6
        );
    }
    Ok(())
}

impl ShearCell {
    /// The cell of `s` (None without `[shear_cell]`), checked against the built system.
    pub fn new(s: &Scene, sys: &System) -> Result<Option<Self>> {
        let Some(sc) = &s.shear_cell else {
            return Ok(None);
        };
        let plate = wall_index(s, &sc.plate).map_err(|e| anyhow::anyhow!("[shear_cell] plate: {e}"))?;
        let w = &sys.walls[plate];
        let v = match w.motion {
            WallMotion::Velocity { v } if v.norm() > 0.0 => v,
            _ => bail!(
                "[shear_cell] plate = {:?}: that wall does not move; give it a velocity",
                sc.plate
            ),
        };
        if plate_region(w).is_none() {
            bail!(
                "[shear_cell] plate = {:?}: the push-plate must be a segment wall (a, b), not a plane",
                sc.plate
            );
        }
        let Some(mem) = &sys.membrane else {
            bail!("[shear_cell] needs the membrane of [membrane]");
        };
        if mem.bodies.len() < 3 {
            bail!(
                "[membrane] shell selects {} grains: a sample outline needs at least 3; widen shell",
                mem.bodies.len()
            );
        }
        let b = &sys.bodies;
        let mut member = vec![false; b.len()];
        for &k in &mem.bodies {
            member[k as usize] = true;
        }
        let n = b.len().max(1) as f64;
        let d_mean = (0..b.len())
            .map(|k| (4.0 * b.mass[k] / b.density[k] / std::f64::consts::PI).sqrt())
            .sum::<f64>()
            / n;
        Ok(Some(Self {
            plate,
            dir: v * (1.0 / v.norm()),
            speed: v.norm(),
            order: mem.ring_order(),
            member,
            shear_rate: v.norm() / sc.shear_length,
            d_mean,
        }))
    }

    /// The largest speed of the sample's grains (m/s): [`fastest_inside`] the membrane.
    pub fn fastest_in_sample(&self, sys: &System) -> f64 {
        match &sys.membrane {
            Some(mem) => fastest_inside(&sys.bodies, &mem.polygon(&self.order, &sys.bodies), &self.member),
            None => sys.bodies.max_speed(),
        }
    }

    /// Grains outside the polygon through the membrane's centroids: they left the sample.
    pub fn escaped(&self, sys: &System) -> usize {
        let Some(mem) = &sys.membrane else { return 0 };
        outside_ring(&sys.bodies, &mem.polygon(&self.order, &sys.bodies), &self.member)
    }

    /// Membrane grains whose centroid lies outside the box `lo`-`hi` (a coupled run's lattice).
    pub fn membrane_outside(sys: &System, lo: [f64; 2], hi: [f64; 2]) -> usize {
        let Some(mem) = &sys.membrane else { return 0 };
        mem.bodies
            .iter()
            .map(|&k| sys.bodies.pos[k as usize])
            .filter(|p| p.x < lo[0] || p.y < lo[1] || p.x > hi[0] || p.y > hi[1])
            .count()
    }

    /// A_def of Eq. 18 (m²).
    pub fn area(&self, sys: &System) -> f64 {
        let Some(mem) = &sys.membrane else { return 0.0 };
        let ring = mem.polygon(&self.order, &sys.bodies);
        let plates: Vec<_> = plate_region(&sys.walls[self.plate]).into_iter().collect();
        sample_area(&ring, &plates)
    }

    /// Mean effective stress of the grains, p' = −tr σ / 2 with σ = (1/A) Σ_c f_c ⊗ ℓ_c over the
    /// grain-grain contacts (f_c the force on the first grain, ℓ_c the branch vector from its
    /// centroid to the other's): the Love-Weber mean stress, compressive positive, in N/m over
    /// the sample's depth.
    pub fn mean_stress(sys: &System, st: &Stepper, area: f64) -> f64 {
        let b = &sys.bodies;
        let mut trace = 0.0;
        for (i, j, f) in st.contact_forces(sys) {
            let (bi, bj) = (
                b.circle_body[i as usize] as usize,
                b.circle_body[j as usize] as usize,
            );
            trace += f.dot(b.pos[bj] - b.pos[bi]);
        }
        -0.5 * trace / area.max(f64::MIN_POSITIVE)
    }

    /// Inertial number I = γ̇ d̄ √(ρ/p') (Eq. 20 in the form of da Cruz et al. 2005, Su's ref.
    /// [120]; Su's γ̇ √(m_grain/P) with m_grain = ¼ρπd̄² is the same up to √(π/4) and the 2D
    /// units), ρ the grains' mean density (kg/m², per depth) as the DEM steps them (mass
    /// scaling included, which `[dem.mass_scale_control]` changes during the run). NaN while
    /// the grains carry no stress.
    pub fn inertial_number(&self, p: f64, rho: f64) -> f64 {
        if p > 0.0 {
            self.shear_rate * self.d_mean * (rho / p).sqrt()
        } else {
            f64::NAN
        }
    }

    /// The grains' mean density as the DEM steps them (kg/m², per depth).
    fn density(sys: &System) -> f64 {
        let b = &sys.bodies;
        b.density.iter().sum::<f64>() / b.len().max(1) as f64
    }

    /// The inertial number of the grains as they stand (the sample's area, p' and I of
    /// [`ShearCell::sample`]).
    pub fn inertial_now(&self, sys: &System, st: &Stepper) -> f64 {
        let p = Self::mean_stress(sys, st, self.area(sys));
        self.inertial_number(p, Self::density(sys))
    }

    /// The plate's displacement along its motion (m) since `start`.
    pub fn displacement(&self, sys: &System, start: Vec2) -> f64 {
        (wall_anchor(&sys.walls[self.plate]) - start).dot(self.dir)
    }

    /// Where the plate starts now.
    pub fn plate_anchor(&self, sys: &System) -> Vec2 {
        wall_anchor(&sys.walls[self.plate])
    }

    /// The plate's speed du_y/dt (m/s).
    pub fn speed(&self) -> f64 {
        self.speed
    }

    /// One series row ([`COLUMNS`]); `a0` is the sample area at the start, `settling` whether
    /// the plate is still held.
    pub fn sample(&self, sys: &System, st: &Stepper, start: Vec2, a0: f64, settling: bool) -> Vec<f64> {
        let u = self.displacement(sys, start);
        let a = self.area(sys);
        let p = Self::mean_stress(sys, st, a);
        vec![
            if settling { 1.0 } else { 0.0 },
            u,
            u / self.d_mean,
            // The grains push back against the plate's motion.
            -sys.walls[self.plate].force.dot(self.dir),
            a,
            (a / a0).ln(),
            p,
            self.inertial_number(p, Self::density(sys)),
            self.fastest_in_sample(sys),
        ]
    }
}

/// A [`ShearCell`] and where it started: the plate's position and the sample's area A_0 at the
/// start of the shear (kept in checkpoints, so that a resumed run measures from the same
/// origin), and the settling before it.
#[derive(Clone, Debug)]
pub struct Tracked {
    pub cell: ShearCell,
    pub start: Vec2,
    pub a0: f64,
    hold: Option<Hold>,
}

/// The plate held still for at least `until` steps of the model and at most `last`, then
/// moving at `velocity`. Without `rest_speed` the two are the same step, and whether the run
/// is settling follows from the step count; with it, the step the plate was let go (and the
/// fastest grain's speed then) is part of the checkpoint ([`Origin::released`]).
#[derive(Clone, Copy, Debug)]
struct Hold {
    until: u64,
    last: u64,
    rest_speed: Option<f64>,
    velocity: Vec2,
    released: Option<Release>,
}

/// When the plate was let go: the model's step and the fastest grain's speed (m/s) then.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Release {
    pub step: u64,
    pub fastest_grain: f64,
}

/// The part of [`Tracked`] a checkpoint keeps.
#[derive(Clone, Copy, Debug, serde::Serialize, serde::Deserialize)]
pub struct Origin {
    pub start: Vec2,
    pub a0: f64,
    /// None in checkpoints written before `settle_until_rest` (their hold has a fixed length).
    #[serde(default)]
    pub released: Option<Release>,
}

impl Tracked {
    /// The scene's cell as the system stands now (None without `[shear_cell]`); with `settle`,
    /// the plate is held for that long in steps of `dt` (s, the model's step), and with
    /// `settle_until_rest` on until the grains are at rest.
    pub fn start(s: &Scene, sys: &mut System, dt: f64) -> Result<Option<Self>> {
        let Some(cell) = ShearCell::new(s, sys)? else {
            return Ok(None);
        };
        let hold = settle_steps(s, dt).map(|(until, last)| {
            // Held by its velocity alone: its motion still says which side is behind it.
            let w = &mut sys.walls[cell.plate];
            let velocity = w.vel;
            w.vel = Vec2::ZERO;
            let rest_speed = s
                .shear_cell
                .as_ref()
                .and_then(|sc| sc.settle_until_rest)
                .map(|r| r.speed);
            Hold {
                until,
                last,
                rest_speed,
                velocity,
                released: None,
            }
        });
        let a0 = cell.area(sys);
        Ok(Some(Self {
            start: cell.plate_anchor(sys),
            a0,
            cell,
            hold,
        }))
    }

    /// Whether the plate is still held after `steps` steps of the model.
    pub fn settling(&self, steps: u64) -> bool {
        self.hold.is_some_and(|h| match h.released {
            Some(r) => steps < r.step,
            None => steps < h.last,
        })
    }

    /// After each step of the model: at the end of the settling (the step `settle` names, or
    /// with `settle_until_rest` the first step after it with every grain slower than its
    /// speed, or its `max_time`), set the plate moving and take A_0 and the plate's origin from
    /// the settled sample. True at that step.
    pub fn after_step(&mut self, sys: &mut System, steps: u64) -> bool {
        let Some(h) = &mut self.hold else {
            return false;
        };
        if h.released.is_some() {
            return false;
        }
        // `==` at the last step: a checkpoint of a fixed hold written before `released` was
        // kept restores with none, and must not be let go a second time. The speeds are read
        // only where they decide (a dry model's step is one DEM step).
        let resting = match h.rest_speed {
            Some(v) if steps >= h.until => {
                let fastest = self.cell.fastest_in_sample(sys);
                (fastest < v).then_some(fastest)
            }
            _ => None,
        };
        let fastest_grain = match resting {
            Some(f) => f,
            None if steps == h.last => self.cell.fastest_in_sample(sys),
            None => return false,
        };
        h.released = Some(Release {
            step: steps,
            fastest_grain,
        });
        sys.walls[self.cell.plate].vel = h.velocity;
        self.start = self.cell.plate_anchor(sys);
        self.a0 = self.cell.area(sys);
        true
    }
    pub fn origin(&self) -> Origin {
        Origin {
            start: self.start,
            a0: self.a0,
            released: self.hold.and_then(|h| h.released),
        }
    }
    pub fn set_origin(&mut self, o: Origin) {
        self.start = o.start;
        self.a0 = o.a0;
        if let Some(h) = &mut self.hold {
            h.released = o.released;
        }
    }

    /// Grains that left the sample through the membrane, and a settling to rest that ran out of
    /// time: the plate was let go with grains still moving faster than the criterion, so what
    /// is sheared is a sample still relaxing.
    pub fn warnings(&self, sys: &System, dt: f64) -> Vec<String> {
        let mut w = Vec::new();
        let escaped = self.cell.escaped(sys);
        if escaped > 0 {
            w.push(format!(
                "[shear_cell]: {escaped} grain(s) lie outside the membrane at the end (they left the sample \
                 through it, and ε_vol^DEM and the liquid no longer see them); a membrane pushed out this far \
                 needs a larger [membrane] force or a looser assembly"
            ));
        }
        let Some(h) = self.hold else {
            return w;
        };
        match (h.rest_speed, h.released) {
            (Some(v), Some(r)) if r.fastest_grain >= v => w.push(format!(
                "[shear_cell] settle_until_rest: the plate was let go at max_time = {:.3} s with the fastest grain \
                 at {:.2e} m/s, above speed = {v:e} m/s: the sample was still relaxing when the shear began; \
                 raise max_time",
                h.last as f64 * dt,
                r.fastest_grain
            )),
            _ => {}
        }
        w
    }
    pub fn sample(&self, sys: &System, st: &Stepper, steps: u64) -> Vec<f64> {
        self.cell
            .sample(sys, st, self.start, self.a0, self.settling(steps))
    }

    /// The plate's displacement for the stop and snapshot conditions: none while it is held, so
    /// that a snapshot `when` the displacement crosses 0 is written as the shear starts.
    fn probe_displacement(&self, wall: usize, steps: u64, measured: f64) -> Option<f64> {
        (wall != self.cell.plate || !self.settling(steps)).then_some(measured)
    }

    /// "u_y = 2.41 d̄" for the progress bar ("settling" while the plate is held).
    pub fn note(&self, sys: &System, steps: u64) -> String {
        if self.settling(steps) {
            return match self.hold.and_then(|h| h.rest_speed) {
                Some(_) => format!(
                    "settling, plate held, fastest grain {:.1e} m/s",
                    sys.bodies.max_speed()
                ),
                None => "settling, plate held".into(),
            };
        }
        let u = self.cell.displacement(sys, self.start);
        format!("u_y = {:.2} d̄", u / self.cell.d_mean)
    }
}

/// The largest speed (m/s) of the bodies that are `member`s of the ring or lie inside it. A
/// grain that has left through the membrane (one did in the 95 %PK settling, drifting on at
/// 5.7e-5 m/s outside the lattice, where nothing slows it) is not the sample's and would keep a
/// settling to rest from ending. The fastest bodies are tried first, so the ring is searched
/// once per escaped grain faster than the answer.
pub fn fastest_inside(b: &lbdem_dem::Bodies, ring: &[Vec2], member: &[bool]) -> f64 {
    let mut outside: Vec<usize> = Vec::new();
    loop {
        let fastest = (0..b.len())
            .filter(|k| !outside.contains(k))
            .map(|k| (k, b.vel[k].norm2()))
            .fold(None, |m: Option<(usize, f64)>, (k, v)| match m {
                Some((_, w)) if w >= v => m,
                _ => Some((k, v)),
            });
        let Some((k, v2)) = fastest else {
            return 0.0;
        };
        if member[k] || contains(ring, b.pos[k]) {
            return v2.sqrt();
        }
        outside.push(k);
    }
}

/// The bodies neither `member`s of the ring nor inside it.
pub fn outside_ring(b: &lbdem_dem::Bodies, ring: &[Vec2], member: &[bool]) -> usize {
    (0..b.len())
        .filter(|&k| !member[k] && !contains(ring, b.pos[k]))
        .count()
}

/// `[shear_cell] settle` in steps of `dt`, and the longest hold (`settle_until_rest.max_time`,
/// else the same); None without a settling or without `[shear_cell]`.
pub fn settle_steps(s: &Scene, dt: f64) -> Option<(u64, u64)> {
    let sc = s.shear_cell.as_ref()?;
    let steps = |t: f64| (t / dt).round().max(1.0) as u64;
    match sc.settle_until_rest {
        Some(r) => Some((
            if sc.settle > 0.0 { steps(sc.settle) } else { 0 },
            steps(r.max_time),
        )),
        None => (sc.settle > 0.0).then(|| (steps(sc.settle), steps(sc.settle))),
    }
}

/// How far wall `k` moved from `start` (its anchor at the start of the run), for the stop and
/// snapshot conditions of either model; none for the push-plate while it is held.
pub fn wall_displacement(
    sys: &System,
    start: &[Vec2],
    cell: Option<&Tracked>,
    k: usize,
    steps: u64,
) -> Option<f64> {
    let d = (wall_anchor(sys.walls.get(k)?) - start[k]).norm();
    match cell {
        Some(c) => c.probe_displacement(k, steps, d),
        None => Some(d),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use lbdem_dem::{Bodies, ClumpShape, Domain, Membrane};

    /// A square ring of four members, a slow grain inside and a fast one outside: the sample's
    /// fastest is the inside grain's speed, or a member's when that is faster; with the outside
    /// grain inside, its own.
    #[test]
    fn the_sample_s_fastest_grain_leaves_out_those_outside_the_membrane() {
        let mut b = Bodies::new();
        let disk = ClumpShape::disk(1e-4);
        for (x, y) in [
            (0.0, 0.0),
            (1e-3, 0.0),
            (1e-3, 1e-3),
            (0.0, 1e-3),
            (5e-4, 5e-4),
            (3e-3, 5e-4),
        ] {
            b.add(&disk, 1.0, Vec2::new(x, y), 0.0).unwrap();
        }
        b.vel[4] = Vec2::new(2e-7, 0.0);
        b.vel[5] = Vec2::new(0.0, 5e-5);
        let ring: Vec<Vec2> = (0..4).map(|k| b.pos[k]).collect();
        let member = [true, true, true, true, false, false];
        assert_eq!(fastest_inside(&b, &ring, &member), 2e-7);
        assert_eq!(outside_ring(&b, &ring, &member), 1);
        b.vel[2] = Vec2::new(-3e-7, 0.0);
        assert_eq!(fastest_inside(&b, &ring, &member), 3e-7);
        b.pos[5] = Vec2::new(6e-4, 4e-4);
        assert_eq!(fastest_inside(&b, &ring, &member), 5e-5);
        assert_eq!(outside_ring(&b, &ring, &member), 0);
        assert_eq!(b.max_speed(), 5e-5);
        // The ring's members against a lattice box: the two at x = 1 mm lie past a face at 0.9.
        let members = Membrane::new(vec![0, 1, 2, 3], &b, 5e-5, 1e-9);
        let mut sys = System::new(b, Domain::open(Vec2::new(-1e-2, -1e-2), Vec2::new(1e-2, 1e-2)));
        sys.membrane = Some(members);
        assert_eq!(
            ShearCell::membrane_outside(&sys, [-1e-4, -1e-4], [1.1e-3, 1.1e-3]),
            0
        );
        assert_eq!(
            ShearCell::membrane_outside(&sys, [-1e-4, -1e-4], [0.9e-3, 1.1e-3]),
            2
        );
    }
}
