//! The time step: velocity Verlet for translation and rotation (Verlet 1967; Allen & Tildesley,
//! "Computer Simulation of Liquids", Sect. 3.2), with optional viscous and local (non-viscous,
//! Cundall) damping. The stepper holds only scratch; all state lives in [`System`].
//!
//! This file is the step skeleton. [`Stepper::step`]: time-step check, wall motion, opening half
//! kick and drift (`kick.rs`), Verlet-list rebuild (`rebuild.rs`), forces, clock. The force
//! phase calls its hook points in a fixed order (as LAMMPS's `post_force` fixes):
//! 1. pair pass (`pairs.rs`: the law over every pair of the list, in parallel; per-body gather),
//! 2. wall forces (`walls.rs`), 3. bonds (`bonds.rs`), 4. membrane (`membrane.rs`),
//! 5. user forces (`hooks.rs`: a [`ForceHook`] passed to [`Stepper::step_with`]),
//! 6. finish pass (`finish.rs`: gravity and the held external load `ext_force`/`ext_torque`,
//!    damping, closing half kick).
//!
//! Systems of disks with none of phases 2-5 take the fused path (`disks.rs`: pair pass and
//! finish per chunk of circles, while the chunk is in cache).
//!
//! Determinism: the pair list is sorted (i < j). One parallel pass over pairs evaluates them and
//! writes one record per pair; a second pass gives each circle its own sum (ascending j) plus its
//! reactions (ascending i). Pairs that do not interact add nothing (or +0.0, an identity for a
//! sum that starts at +0.0), so the order, hence every bit, is independent of the thread count
//! and of the step at which the Verlet list was rebuilt (a resumed run continues bit for bit).

pub mod bond_dashpots;
mod bonds;
mod disks;
mod finish;
mod hooks;
mod kick;
mod membrane;
mod pairs;
mod rebuild;
mod wall_modes;
mod walls;

pub use hooks::ForceHook;

use crate::contact::{ContactLaw, Law, LawVisitor, LinearSpringDashpot};
use crate::error::DemError;
use crate::neighbor::CellList;
use crate::scratch::{CircleState, Kick, PairOut};
use crate::system::System;
use crate::vector::{Vec2, Vector};
use crate::wall::update_wall_velocities;
use finish::Finish;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepParams {
    pub dt: f64,
    #[serde(default)]
    pub gravity: Vec2,
    /// Factor on gravity: 1 for dry grains, 1 − ρ_L/ρ_S for buoyant grains in a liquid.
    #[serde(default = "one")]
    pub gravity_factor: f64,
    /// Viscous damping rate γ (1/s): F −= γ m v, T −= γ I ω.
    #[serde(default)]
    pub viscous_damping: f64,
    /// Local (non-viscous) damping α (Cundall): F_k −= α |F_k| sign(v_k).
    #[serde(default)]
    pub local_damping: f64,
    /// Verlet-list skin (m).
    pub skin: f64,
}

fn one() -> f64 {
    1.0
}

impl StepParams {
    pub fn new(dt: f64, skin: f64) -> Self {
        Self {
            dt,
            gravity: Vec2::ZERO,
            gravity_factor: 1.0,
            viscous_damping: 0.0,
            local_damping: 0.0,
            skin,
        }
    }
}

/// Bodies per parallel task of the per-body passes (any value gives the same bits).
const BODY_CHUNK: usize = 512;

/// Circles per task of the fused pair + per-body pass of disk systems (any value gives the
/// same bits).
const CIRCLE_CHUNK: usize = 1024;

/// Pairs per parallel task of the pair pass (any value gives the same bits).
const PAIR_CHUNK: usize = 1024;

/// A body whose wall contact is unstable at the step asked ([`Stepper::unstable_wall_contact`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallContactStep {
    /// The largest step (s) at which it is stable.
    pub limit: f64,
    pub body: usize,
    /// The wall law's normal stiffness (N/m) and dashpot (N s/m) on that body.
    pub k: f64,
    pub c: f64,
}

/// Scratch for stepping a [`System`].
#[derive(Default)]
pub struct Stepper {
    cells: CellList,
    cpos: Vec<Vec2>,
    carm: Vec<Vec2>,
    /// Per body: sine and cosine of its angle, one `sin_cos` for all its circles.
    turn: Vec<(f64, f64)>,
    cstate: Vec<CircleState>,
    ref_pos: Vec<Vec2>,
    /// Pairs of circle i (as the lower index) are `pair_start[i]..pair_start[i + 1]`.
    pair_start: Vec<u32>,
    /// Result of every pair (force on i, torques on i and j; zero when not interacting) and
    /// whether the law acted on it (1) or not (0).
    out: Vec<PairOut>,
    touch: Vec<u8>,
    /// Per circle: the pairs in which it is j, ascending i (indices into `out_j`).
    j_start: Vec<u32>,
    j_list: Vec<u32>,
    /// Circles (ascending) with a reaction from a lower chunk of `CIRCLE_CHUNK` circles, and
    /// where each chunk's start in that list (the fused disk pass finishes them last).
    deferred: Vec<u32>,
    deferred_start: Vec<u32>,
    /// Every body is a single circle at its centre (circle c = body c): fused fast paths.
    all_disks: bool,
    /// Circles (ascending) that may reach a wall before the next search, and the walls as they
    /// were at that search (`walls.rs`).
    wall_near: Vec<u32>,
    wall_ref: Vec<crate::wall::Wall>,
    kick: Vec<Kick>,
    /// Per bond: what it hands its bodies at this force evaluation (`bonds.rs`).
    bond_load: Vec<bonds::BondLoad>,
    n_circles: usize,
    n_bodies: usize,
    checked_dt: f64,
    pub rebuilds: u64,
    /// Run a dt above the critical step instead of refusing it ([`Stepper::past_critical_check`]).
    past_critical: bool,
}

impl Stepper {
    pub fn new() -> Self {
        Self::default()
    }

    /// A stepper that runs a dt above the critical step instead of refusing it: only for the
    /// stability maps, which must run a refused step to show the refusal was right.
    pub fn past_critical_check() -> Self {
        Self {
            past_critical: true,
            ..Self::default()
        }
    }

    /// Critical time step of `sys` under `law` (and `wall_law`): sqrt(m_min / k_max).
    pub fn critical_time_step<L: ContactLaw, W: ContactLaw>(
        sys: &System,
        law: &L,
        wall_law: &W,
    ) -> (f64, f64, f64) {
        let b = &sys.bodies;
        let m_min = b.mass.iter().copied().fold(f64::INFINITY, f64::min);
        let r_max = b.circle_r.iter().copied().fold(0.0, f64::max);
        let mut k = law.max_stiffness(0.5 * r_max).max(wall_law.max_stiffness(r_max));
        if let Some(p) = &sys.bond_params {
            k = k.max(p.k_n.max(p.k_s) * 2.0 * p.lambda * r_max);
        }
        (lbdem_core::units::dem::critical_time_step(m_min, k), m_min, k)
    }

    /// The largest step the stepper accepts (s) for the grains' springs,
    /// [`lbdem_core::units::dem::largest_accepted_step`]: the lightest body held by six grain
    /// springs and, if the system has walls, pressed by two walls. [`Stepper::check_step`] also
    /// refuses a step at which a clump's wall contact is unstable ([`Stepper::unstable_wall_contact`]).
    pub fn largest_accepted_step<L: ContactLaw, W: ContactLaw>(sys: &System, law: &L, wall_law: &W) -> f64 {
        let b = &sys.bodies;
        let m_min = b.mass.iter().copied().fold(f64::INFINITY, f64::min);
        let r_max = b.circle_r.iter().copied().fold(0.0, f64::max);
        let mut k = law.max_stiffness(0.5 * r_max);
        if let Some(p) = &sys.bond_params {
            k = k.max(p.k_n.max(p.k_s) * 2.0 * p.lambda * r_max);
        }
        lbdem_core::units::dem::largest_accepted_step(
            m_min,
            k,
            wall_law.max_stiffness(r_max),
            !sys.walls.is_empty(),
        )
    }

    /// The body whose wall contact is unstable at step `dt` with the lowest stable step, if any
    /// is (`stepper/wall_modes.rs`: each body resting on a wall by two circles or by one, its contacts
    /// linearised, the step's spectral radius). `None` without walls or when every body is
    /// stable. Unstable bodies are searched for their largest stable step, so the answer names
    /// the step that holds them all.
    pub fn unstable_wall_contact<W: ContactLaw>(
        sys: &System,
        wall_law: &W,
        dt: f64,
    ) -> Option<WallContactStep> {
        if sys.walls.is_empty() {
            return None;
        }
        let b = &sys.bodies;
        (0..b.len())
            .into_par_iter()
            .filter_map(|k| {
                let (m, i) = (b.mass[k], b.inertia[k]);
                if !(m.is_finite() && m > 0.0 && i.is_finite() && i > 0.0) {
                    return None;
                }
                let circles = b.circle_start[k]..b.circle_start[k + 1];
                let r_max = b.circle_r[circles.clone()].iter().copied().fold(0.0, f64::max);
                let sd = wall_law.spring_dashpots(r_max, m);
                let ways = wall_modes::resting_ways(&b.circle_offset[circles.clone()], &b.circle_r[circles]);
                if wall_modes::stable(&ways, m, i, &sd, dt) {
                    return None;
                }
                Some(WallContactStep {
                    limit: wall_modes::largest_stable_step(&ways, m, i, &sd),
                    body: k,
                    k: sd.normal.0,
                    c: sd.normal.1,
                })
            })
            .min_by(|x, y| x.limit.total_cmp(&y.limit).then(x.body.cmp(&y.body)))
    }

    /// Refuses `dt` if it is not a positive finite step, if a body resting on a wall is unstable
    /// at it ([`Stepper::unstable_wall_contact`]) or if it is above
    /// [`Stepper::largest_accepted_step`], naming the bound that refused it.
    pub fn check_step<L: ContactLaw, W: ContactLaw>(
        sys: &System,
        law: &L,
        wall_law: &W,
        dt: f64,
    ) -> Result<(), DemError> {
        if !(dt > 0.0 && dt.is_finite()) {
            return Err(DemError::BadTimeStep { dt });
        }
        if let Some(wall) = Self::unstable_wall_contact(sys, wall_law, dt) {
            return Err(DemError::WallContactStepTooLarge {
                dt,
                limit: wall.limit,
                body: wall.body,
                k_wall: wall.k,
                c_wall: wall.c,
            });
        }
        if let Some(b) = Self::bond_dashpot_number(sys, dt)
            && b.number > bond_dashpots::BOND_DASHPOT_LIMIT
        {
            return Err(DemError::BondDashpotsTooStiff {
                dt,
                number: b.number,
                limit: bond_dashpots::BOND_DASHPOT_LIMIT,
                body: b.body,
                largest_ratio: b.largest_ratio,
                largest_step: dt * bond_dashpots::BOND_DASHPOT_LIMIT / b.number,
            });
        }
        let limit = Self::largest_accepted_step(sys, law, wall_law);
        if dt > limit {
            let (critical, m_min, k_max) = Self::critical_time_step(sys, law, wall_law);
            return Err(DemError::TimeStepTooLarge {
                dt,
                limit,
                critical,
                m_min,
                k_max,
            });
        }
        Ok(())
    }

    /// [`Stepper::step`] compiled in this crate for the scene-selectable [`Law`]: the pair law
    /// is dispatched once per step to the pass monomorphised for it (batched kernel for the
    /// linear and elastic-plastic laws), the wall law through the enum.
    #[inline(never)]
    pub fn step_law(
        &mut self,
        p: &StepParams,
        law: &Law,
        wall_law: &Law,
        sys: &mut System,
    ) -> Result<(), DemError> {
        law.visit(StepLaw {
            st: self,
            p,
            wall_law,
            sys,
            hook: None,
        })
    }

    /// [`Stepper::step_law`] with a user force hook (see [`Stepper::step_with`]).
    #[inline(never)]
    pub fn step_law_with(
        &mut self,
        p: &StepParams,
        law: &Law,
        wall_law: &Law,
        sys: &mut System,
        hook: &mut dyn ForceHook,
    ) -> Result<(), DemError> {
        law.visit(StepLaw {
            st: self,
            p,
            wall_law,
            sys,
            hook: Some(hook),
        })
    }

    /// [`Stepper::step`] for the linear law (benchmark case), compiled in this crate.
    #[inline(never)]
    pub fn step_linear(
        &mut self,
        p: &StepParams,
        law: &LinearSpringDashpot,
        sys: &mut System,
    ) -> Result<(), DemError> {
        self.step(p, law, law, sys)
    }

    /// Number of pairs the law acted on (in contact, or within its range) at the last force
    /// evaluation.
    pub fn n_contacts(&self) -> usize {
        self.touch.iter().map(|&t| t as usize).sum()
    }

    /// The pairs the law acted on at the last force evaluation of `sys` (the system last
    /// stepped): circles (i, j), i < j, and the force on i (j receives its negative), in list
    /// order.
    pub fn contact_forces<'a>(&'a self, sys: &'a System) -> impl Iterator<Item = (u32, u32, Vec2)> + 'a {
        sys.contacts
            .pairs
            .iter()
            .zip(&self.out)
            .zip(&self.touch)
            .filter(|(_, t)| **t != 0)
            .map(|((pr, o), _)| (pr[0], pr[1], Vec2::new(o.fx, o.fy)))
    }

    /// Advance `sys` by one step, `law` between circles and `wall_law` between circles and
    /// walls.
    pub fn step<L: ContactLaw, W: ContactLaw>(
        &mut self,
        p: &StepParams,
        law: &L,
        wall_law: &W,
        sys: &mut System,
    ) -> Result<(), DemError> {
        self.step_hooked(p, law, wall_law, sys, None)
    }

    /// [`Stepper::step`] with user forces: `hook` adds forces and torques to the bodies after
    /// the contact, wall, bond and membrane forces and before the finish pass (gravity,
    /// `ext_force`, damping, closing half kick), at every force evaluation.
    pub fn step_with<L: ContactLaw, W: ContactLaw>(
        &mut self,
        p: &StepParams,
        law: &L,
        wall_law: &W,
        sys: &mut System,
        hook: &mut dyn ForceHook,
    ) -> Result<(), DemError> {
        self.step_hooked(p, law, wall_law, sys, Some(hook))
    }

    fn step_hooked<L: ContactLaw, W: ContactLaw>(
        &mut self,
        p: &StepParams,
        law: &L,
        wall_law: &W,
        sys: &mut System,
        mut hook: Option<&mut dyn ForceHook>,
    ) -> Result<(), DemError> {
        let dt = p.dt;
        let shape = (sys.bodies.n_circles(), sys.bodies.len());
        self.kick.resize(sys.bodies.len(), Kick::default());
        if self.checked_dt != dt || (self.n_circles, self.n_bodies) != shape {
            match Self::check_step(sys, law, wall_law, dt) {
                Err(e @ DemError::BadTimeStep { .. }) => return Err(e),
                Err(e) if !self.past_critical => return Err(e),
                _ => {}
            }
            self.checked_dt = dt;
            let fresh = (self.n_circles, self.n_bodies) != shape || self.ref_pos.is_empty();
            (self.n_circles, self.n_bodies) = shape;
            if fresh {
                let b = &sys.bodies;
                self.all_disks =
                    b.n_circles() == b.len() && b.circle_offset.iter().all(|o| o.x == 0.0 && o.y == 0.0);
                self.update_circles(sys);
                self.rebuild(sys, p.skin, law, wall_law)?;
                if sys.step == 0 {
                    // Prime F(0) for the first half-kick; dt = 0 leaves the history untouched.
                    let p0 = StepParams { dt: 0.0, ..*p };
                    self.forces(&p0, law, wall_law, sys, 0.0, hook.as_deref_mut());
                }
            }
        }
        update_wall_velocities(&mut sys.walls, wall_law.max_stiffness(1.0), dt);
        for w in sys.walls.iter_mut() {
            let v = w.vel;
            w.translate(v * dt);
        }
        let worst = if self.all_disks {
            self.kick_drift_disks(sys, 0.5 * dt, dt)
        } else {
            self.kick_drift_clumps(sys, 0.5 * dt, dt)
        };
        let half_skin2 = 0.25 * p.skin * p.skin;
        if !worst.is_finite() {
            let body = (0..sys.bodies.len())
                .find(|&k| !(sys.bodies.pos[k].norm2().is_finite() && sys.bodies.vel[k].norm2().is_finite()))
                .unwrap_or(0);
            return Err(DemError::NonFinite { body, step: sys.step });
        }
        if worst > half_skin2 {
            self.rebuild(sys, p.skin, law, wall_law)?;
        }
        self.forces(p, law, wall_law, sys, 0.5 * dt, hook);
        sys.time += dt;
        sys.step += 1;
        Ok(())
    }

    /// Forces and torques on every body, phase by phase (module docs); then, if `h > 0`, the
    /// closing half kick v += F/m h.
    #[allow(clippy::too_many_arguments)]
    fn forces<'h, L: ContactLaw, W: ContactLaw>(
        &mut self,
        p: &StepParams,
        law: &L,
        wall_law: &W,
        sys: &mut System,
        h: f64,
        hook: Option<&mut (dyn ForceHook + 'h)>,
    ) {
        let fin = Finish::new(p, h);
        let simple =
            sys.walls.is_empty() && sys.bond_params.is_none() && sys.membrane.is_none() && hook.is_none();
        if self.all_disks && simple {
            self.forces_disks(p.dt, law, sys, &fin);
            return;
        }
        // 1. Pairs; per body, each circle's own sum plus its reactions. With nothing else to
        //    add, the finish pass follows in the same per-body pass.
        self.pair_pass(p.dt, law, sys);
        self.gather(sys, simple.then_some(&fin));
        if simple {
            return;
        }
        self.wall_forces(p.dt, p.skin, wall_law, sys);
        self.bond_forces(p.dt, sys);
        membrane::membrane_forces(sys);
        if let Some(hook) = hook {
            hooks::user_forces(hook, sys.time + p.dt, sys);
        }
        self.finish(sys, &fin);
    }
}

/// [`Stepper::step_law`]: the step for the concrete pair law inside a [`Law`].
struct StepLaw<'a, 'h> {
    st: &'a mut Stepper,
    p: &'a StepParams,
    wall_law: &'a Law,
    sys: &'a mut System,
    hook: Option<&'h mut dyn ForceHook>,
}

impl LawVisitor for StepLaw<'_, '_> {
    type Output = Result<(), DemError>;
    fn visit<L: ContactLaw>(self, law: &L) -> Self::Output {
        self.st
            .step_hooked(self.p, law, self.wall_law, self.sys, self.hook)
    }
}
