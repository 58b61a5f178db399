//! One extruder step round the sphere engine: grains past the outlet removed, the inlet box
//! topped up (every `insert_every` steps), one velocity-Verlet step with the body force on the
//! grains in the inlet box, the leak check, and the mass balance. The wall grains are the
//! system's first spheres and are never removed, so they keep their indices; paste grains are
//! appended when placed and renumbered in order when others leave (`edit.rs`).

use super::ExtruderSpec;
use super::balance::Balance;
use super::error::ExtruderError;
use super::geometry::Segment;
use super::inlet::{Region, ball, inlet_state, pass_rng, place};
use super::outlet::{check_no_leak, remove_past_outlet};
use crate::spheres::law::SphereLaw;
use crate::spheres::stepper::{SphereStepParams, SphereStepper};
use crate::spheres::system::SphereSystem;
use crate::vector::Vec3;
use serde::{Deserialize, Serialize};

/// The extruder's own state beside the sphere system (plain data; checkpointed with it).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ExtruderState {
    /// Wall grains: spheres 0..walls, frozen.
    pub walls: usize,
    /// The wall segment of each wall grain.
    pub segment: Vec<Segment>,
    /// Grains of the initial fill.
    pub prefilled: u64,
    /// Grains inserted in the inlet box since the start.
    pub inserted: u64,
    /// Grains removed at the outlet since the start.
    pub removed: u64,
    pub balance: Balance,
}

/// What the series records of the current state.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Measures {
    /// Paste grains in the system.
    pub grains: usize,
    /// φ of the inlet box.
    pub phi_inlet: f64,
    /// Mean v_x of the grains in the barrel downstream of the inlet box (m/s; 0 if none).
    pub barrel_velocity: f64,
    /// Mean v_x of the grains in the die (m/s; 0 if none): Ness's die velocity V.
    pub die_velocity: f64,
    /// Force of the paste on each wall segment ([`Segment::ALL`] order), N.
    pub wall_force: [Vec3; 4],
}

impl ExtruderState {
    /// The system of `spec`: its box, the frozen wall grains of its realisation, and the
    /// initial fill (if `prefill_phi` > 0).
    pub fn build(spec: &ExtruderSpec) -> Result<(SphereSystem, Self), ExtruderError> {
        spec.check()?;
        let g = &spec.geometry;
        let d_max = spec.paste.range()[1];
        let mut sys = SphereSystem::new(g.domain(2.0 * d_max)?);
        let walls = g.wall_grains();
        let mut st = Self {
            walls: walls.len(),
            segment: walls.iter().map(|w| w.1).collect(),
            ..Self::default()
        };
        for (p, _) in &walls {
            let k = sys.add_sphere(
                *p,
                Vec3::ZERO,
                Vec3::ZERO,
                0.5 * g.wall_diameter,
                spec.paste.density,
            )?;
            sys.set_frozen(k, true)?;
        }
        let phi = spec.drive.prefill_phi;
        if phi > 0.0 {
            let mut rng = pass_rng(spec.drive.seed, u64::MAX - 1);
            let mut placed = 0;
            st.prefilled = place(
                g,
                &spec.paste,
                &mut sys,
                st.walls,
                Region {
                    x: (0.0, g.die_end()),
                    target: phi * g.channel_volume(),
                    attempts: 2000,
                    vel: Vec3::ZERO,
                },
                &mut rng,
                &mut placed,
            )?;
        }
        Ok((sys, st))
    }

    /// Grains placed so far (fill and insertions): the next one's size follows from it.
    pub fn placed(&self) -> u64 {
        self.prefilled + self.inserted
    }

    /// Check that the state fits `sys` (a checkpoint is user input).
    pub fn check(&self, sys: &SphereSystem) -> Result<(), String> {
        let n = sys.spheres.len();
        if self.segment.len() != self.walls || self.walls > n {
            return Err(format!(
                "{} wall segments for {} wall grains in a system of {n} spheres",
                self.segment.len(),
                self.walls
            ));
        }
        if let Some(k) = (0..n).find(|&k| sys.is_frozen(k) != (k < self.walls)) {
            return Err(format!(
                "sphere {k} is frozen where it should not be, or the reverse"
            ));
        }
        let inside = (n - self.walls) as u64;
        if self.placed() != inside + self.removed {
            return Err(format!(
                "{} placed but {inside} inside and {} removed",
                self.placed(),
                self.removed
            ));
        }
        Ok(())
    }

    /// One step: outlet, inlet, engine step with the body force, leak check, mass balance.
    pub fn step<L: SphereLaw>(
        &mut self,
        spec: &ExtruderSpec,
        law: &L,
        params: &SphereStepParams,
        stepper: &mut SphereStepper<L>,
        sys: &mut SphereSystem,
    ) -> Result<(), ExtruderError> {
        let g = &spec.geometry;
        let d = &spec.drive;
        self.removed += remove_past_outlet(g, law, sys, self.walls)?;
        if sys.step.is_multiple_of(d.insert_every) {
            let (phi, vel) = inlet_state(g, sys, self.walls);
            let box_volume = g.inlet_length * g.barrel_width * g.depth;
            let target = (d.phi_inlet - phi) * box_volume;
            if target > 0.0 {
                let mut rng = pass_rng(d.seed, sys.step);
                let mut placed = self.placed();
                self.inserted += place(
                    g,
                    &spec.paste,
                    sys,
                    self.walls,
                    Region {
                        x: (0.0, g.inlet_length),
                        target,
                        attempts: d.insert_attempts,
                        vel,
                    },
                    &mut rng,
                    &mut placed,
                )?;
            }
        }
        let (first, x_in, f) = (self.walls, g.inlet_length, d.body_force);
        let mut drive = |_t: f64, s: &SphereSystem, force: &mut [Vec3], _torque: &mut [Vec3]| {
            for (k, fk) in force.iter_mut().enumerate().skip(first) {
                if s.spheres.pos[k].x < x_in {
                    fk.x += f;
                }
            }
        };
        stepper.step_with(params, law, sys, &mut drive)?;
        check_no_leak(g, sys, self.walls)?;
        self.balance
            .record(&spec.steady, sys.time, self.inserted, self.removed);
        Ok(())
    }

    /// The series quantities of the current state.
    pub fn measure(&self, spec: &ExtruderSpec, sys: &SphereSystem) -> Measures {
        let g = &spec.geometry;
        let s = &sys.spheres;
        let (lb, le) = (g.barrel_length, g.die_end());
        let (mut vb, mut nb, mut vd, mut nd) = (0.0, 0usize, 0.0, 0usize);
        for k in self.walls..s.len() {
            let x = s.pos[k].x;
            if x >= g.inlet_length && x < lb {
                vb += s.vel[k].x;
                nb += 1;
            } else if (lb..=le).contains(&x) {
                vd += s.vel[k].x;
                nd += 1;
            }
        }
        let mut wall_force = [Vec3::ZERO; 4];
        for (k, seg) in self.segment.iter().enumerate() {
            wall_force[seg.index()] += s.force[k];
        }
        let mean = |v: f64, n: usize| if n > 0 { v / n as f64 } else { 0.0 };
        Measures {
            grains: s.len() - self.walls,
            phi_inlet: inlet_state(g, sys, self.walls).0,
            barrel_velocity: mean(vb, nb),
            die_velocity: mean(vd, nd),
            wall_force,
        }
    }

    /// The paste's volume fraction over the channel (grain volume inside / channel volume).
    pub fn channel_phi(&self, spec: &ExtruderSpec, sys: &SphereSystem) -> f64 {
        let s = &sys.spheres;
        let v: f64 = (self.walls..s.len()).map(|k| ball(2.0 * s.radius[k])).sum();
        v / spec.geometry.channel_volume()
    }
}
