//! The alternative to partially saturated cells: moving-boundary halfway bounce-back with
//! momentum exchange (Leonardi et al. 2014 Eqs. 19-21), on the `lbdem-lbm` two-array stepper.
//!
//! Every LBM step the nodes whose centres lie inside a grain (radius scaled by r_hd) become
//! solid nodes of that grain; links from fluid nodes into them bounce back with the grain's
//! local velocity (Eq. 19-20) and carry the momentum-exchange force and moment (Eq. 21). A node
//! that a grain uncovers is refilled with the equilibrium at the mean density of its fluid
//! neighbours and the grain's local velocity (the usual refilling; its fluid momentum is not
//! conserved exactly, unlike the PSM's, which the comparison chart shows).

use crate::error::CouplingError;
use crate::psm::{GrainMotion, Load};
use crate::solid_fraction::{GrainCircle, wrap};
use lbdem_lbm::collision::equilibrium;
use lbdem_lbm::domain::{FLUID, NO_OBSTACLE, SOLID};
use lbdem_lbm::{Collision, D2Q9, Domain, Fluid, Lattice, Limits, Macro, Motion, Real, Settings, Stepper};

/// What a bounce-back lattice needs besides its settings to continue a run bit for bit
/// (`BounceFluid::state`, `BounceFluid::restore`): the `Fluid` (post-collision populations, the
/// domain with the grains' solid nodes and obstacle ids, the obstacle motions, the step) and the
/// macroscopic fields of the last step.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(bound = "")]
pub struct BounceState<T: Real> {
    pub fluid: Fluid<D2Q9, T>,
    pub macro_fields: Macro,
}

/// A bounce-back lattice whose solid nodes follow the grains.
pub struct BounceFluid<T: Real> {
    pub fluid: Fluid<D2Q9, T>,
    stepper: Stepper<D2Q9, T>,
    pub macro_fields: Macro,
    was_solid: Vec<bool>,
    /// Grain that covered each node before this step's mapping.
    owner: Vec<u16>,
}

impl<T: Real> BounceFluid<T> {
    pub fn new(domain: Domain, tau: f64, force: [f64; 2], limits: Limits) -> Result<Self, CouplingError> {
        if domain.n[2] != 1 {
            return Err(CouplingError::Unsupported(
                "the bounce-back coupling here is 2D".into(),
            ));
        }
        let n = domain.len();
        let fluid = Fluid::<D2Q9, T>::new(domain, Vec::new());
        let settings = Settings {
            collision: Collision::Bgk { tau },
            force: [force[0], force[1], 0.0],
            limits,
        };
        let stepper = Stepper::new(&fluid, settings)?;
        Ok(Self {
            fluid,
            stepper,
            macro_fields: Macro::default(),
            was_solid: vec![false; n],
            owner: vec![NO_OBSTACLE; n],
        })
    }

    /// The state to checkpoint (see [`BounceState`]). Populations of non-fluid nodes are
    /// never read (a node a grain uncovers is refilled) and hold whatever the two-array swap
    /// left there, so they are written as 0: equal runs give equal states.
    pub fn state(&self) -> BounceState<T> {
        let mut fluid = self.fluid.clone();
        let n = fluid.nodes();
        for (idx, &k) in fluid.domain.kind.iter().enumerate() {
            if k != FLUID {
                for i in 0..D2Q9::Q {
                    fluid.f[i * n + idx] = T::default();
                }
            }
        }
        BounceState {
            fluid,
            macro_fields: self.macro_fields.clone(),
        }
    }

    /// Continue from `state` on a lattice built with the same box and settings.
    pub fn restore(&mut self, state: BounceState<T>) -> Result<(), CouplingError> {
        if state.fluid.domain.n != self.fluid.domain.n || state.fluid.f.len() != self.fluid.f.len() {
            return Err(CouplingError::Unsupported(format!(
                "bounce-back state of a {:?} box restored into a {:?} box: build the lattice with the \
                 checkpoint's domain",
                state.fluid.domain.n, self.fluid.domain.n
            )));
        }
        self.fluid = state.fluid;
        self.macro_fields = state.macro_fields;
        self.stepper.rebuild(&self.fluid);
        Ok(())
    }

    /// Mark the grains' nodes (lattice coordinates: node i at i + ½), refill uncovered nodes.
    pub fn map(
        &mut self,
        circles: &[GrainCircle],
        motions: &[GrainMotion],
        r_hd: f64,
    ) -> Result<(), CouplingError> {
        if motions.len() >= NO_OBSTACLE as usize {
            return Err(CouplingError::Unsupported(format!(
                "{} grains: the bounce-back coupling takes at most {} (use PSM)",
                motions.len(),
                NO_OBSTACLE - 1
            )));
        }
        let dom = &mut self.fluid.domain;
        let [nx, ny, _] = dom.n;
        let per = [dom.faces[0].is_periodic(), dom.faces[2].is_periodic()];
        // Only the grains' own nodes are released (static obstacles of the domain stay); the
        // grain that covered each node is kept for the refill.
        let n_grains = motions.len();
        for (i, k) in dom.kind.iter_mut().enumerate() {
            let grain = dom.obstacle[i];
            let mine = *k == SOLID && (grain as usize) < n_grains;
            self.was_solid[i] = mine;
            self.owner[i] = if mine { grain } else { NO_OBSTACLE };
            if mine {
                *k = FLUID;
                dom.obstacle[i] = NO_OBSTACLE;
            }
        }
        for c in circles {
            let r = c.radius * r_hd;
            let (x0, x1) = (
                (c.centre[0] - r - 0.5).floor() as i64,
                (c.centre[0] + r - 0.5).ceil() as i64,
            );
            let (y0, y1) = (
                (c.centre[1] - r - 0.5).floor() as i64,
                (c.centre[1] + r - 0.5).ceil() as i64,
            );
            for y in y0..=y1 {
                let Some(yy) = wrap(y, ny, per[1]) else { continue };
                for x in x0..=x1 {
                    let Some(xx) = wrap(x, nx, per[0]) else { continue };
                    let (dx, dy) = (x as f64 + 0.5 - c.centre[0], y as f64 + 0.5 - c.centre[1]);
                    let i = xx + nx * yy;
                    if dx * dx + dy * dy <= r * r && dom.kind[i] == FLUID {
                        dom.kind[i] = SOLID;
                        dom.obstacle[i] = c.body as u16;
                    }
                }
            }
        }
        self.fluid.obstacles = motions
            .iter()
            .map(|m| Motion {
                centre: [m.centre[0] - 0.5, m.centre[1] - 0.5, 0.0],
                velocity: [m.velocity[0], m.velocity[1], 0.0],
                omega: [0.0, 0.0, m.omega],
            })
            .collect();
        self.refill(motions, nx, ny, per);
        self.stepper.rebuild(&self.fluid);
        Ok(())
    }

    /// Uncovered nodes take the equilibrium of their fluid neighbours' mean density and the
    /// local velocity of the grain that left them.
    fn refill(&mut self, motions: &[GrainMotion], nx: usize, ny: usize, per: [bool; 2]) {
        let n = nx * ny;
        let mut fresh = Vec::new();
        for i in 0..n {
            if self.was_solid[i] && self.fluid.domain.kind[i] == FLUID {
                fresh.push(i);
            }
        }
        for &i in &fresh {
            let (x, y) = ((i % nx) as i64, (i / nx) as i64);
            let (mut rho, mut cnt) = (0.0, 0);
            for c in &D2Q9::C[1..] {
                let (Some(xx), Some(yy)) = (
                    wrap(x + c[0] as i64, nx, per[0]),
                    wrap(y + c[1] as i64, ny, per[1]),
                ) else {
                    continue;
                };
                let j = xx + nx * yy;
                if !self.was_solid[j] && self.fluid.domain.kind[j] == FLUID {
                    rho += self.fluid.moments(j).0;
                    cnt += 1;
                }
            }
            let rho = if cnt > 0 { rho / cnt as f64 } else { 1.0 };
            // The grain that uncovered the node gives its local velocity (minimum image).
            let m = &motions[self.owner[i] as usize];
            let r = self.fluid.domain.offset(
                [m.centre[0] - 0.5, m.centre[1] - 0.5, 0.0],
                [x as f64, y as f64, 0.0],
            );
            let u = m.velocity_at([r[0], r[1]]);
            let feq = equilibrium::<D2Q9>(rho, [u[0], u[1], 0.0]);
            for (q, v) in feq.iter().enumerate().take(D2Q9::Q) {
                self.fluid.f[q * n + i] = T::from_f64(*v);
            }
        }
    }

    /// One LBM step; the load on each grain (lattice units).
    pub fn step(&mut self, loads: &mut Vec<Load>, n_grains: usize) -> Result<(), CouplingError> {
        self.stepper.step(&mut self.fluid, Some(&mut self.macro_fields))?;
        loads.clear();
        loads.extend(self.stepper.forces.iter().take(n_grains).map(|ft| Load {
            force: [ft.force[0], ft.force[1]],
            torque: ft.torque[2],
        }));
        Ok(())
    }
}
