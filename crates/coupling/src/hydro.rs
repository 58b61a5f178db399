//! The two ways the fluid sees the grains, behind one type so that a scene or a study can
//! switch between them on the same case: partially saturated cells (Su et al. 2020 Eqs. 9-14,
//! the default) or moving-boundary bounce-back (Leonardi et al. 2014 Eqs. 19-21).

use crate::bounce::{BounceFluid, BounceState};
use crate::error::CouplingError;
use crate::psm::{GrainMotion, Load, PsmFluid, PsmState, ZoneMass};
use crate::remap::SolidMapper;
use crate::solid_fraction::{GrainCircle, SolidMap};
use lbdem_lbm::Real;
use serde::{Deserialize, Serialize};

/// Which fluid-solid coupling a run uses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Partially saturated cells (Noble & Torczynski 1998; Su et al. Eqs. 9-11, 14).
    #[default]
    Psm,
    /// Halfway bounce-back on moving solid nodes with refilling (Leonardi et al. Eqs. 19-21).
    BounceBack,
}

/// Moments of the liquid a grain carries (lattice units, ρ = 1): mass A = Σ w, first moment
/// S = Σ w r and polar moment J = Σ w |r|² about the grain centre.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct InteriorLiquid {
    pub area: f64,
    pub first: [f64; 2],
    pub polar: f64,
}

/// The checkpointed state of a [`Hydro`] (the PSM solid map is not part of it: the coupled loop
/// recomputes it from the grains before every LBM step).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(bound = "", rename_all = "kebab-case")]
#[allow(clippy::large_enum_variant)]
pub enum HydroState<T: Real> {
    Psm(PsmState<T>),
    BounceBack(BounceState<T>),
}

/// One per run: the size difference between the variants does not matter.
#[allow(clippy::large_enum_variant)]
pub enum Hydro<T: Real> {
    Psm {
        fluid: PsmFluid<T>,
        map: SolidMap,
        mapper: SolidMapper,
    },
    BounceBack(Box<BounceFluid<T>>),
}

impl<T: Real> Hydro<T> {
    pub fn psm(fluid: PsmFluid<T>) -> Self {
        let (nx, ny) = (fluid.nx, fluid.ny);
        Hydro::Psm {
            fluid,
            map: SolidMap {
                nx,
                ny,
                covers: Vec::new(),
                total: vec![0.0; nx * ny],
            },
            mapper: SolidMapper::new(0.0),
        }
    }

    /// Map a grain again only once it moved more than `cells` lattice cells ([`SolidMapper`];
    /// 0, the default, maps every grain that moved). PSM only.
    pub fn set_remap_tolerance(&mut self, cells: f64) -> Result<(), CouplingError> {
        if !(cells.is_finite() && cells >= 0.0) {
            return Err(CouplingError::Unsupported(format!(
                "remap tolerance {cells} cells must be finite and at least 0"
            )));
        }
        match self {
            Hydro::Psm { mapper, .. } => {
                *mapper = SolidMapper::new(cells);
                Ok(())
            }
            Hydro::BounceBack(_) if cells == 0.0 => Ok(()),
            Hydro::BounceBack(_) => Err(CouplingError::Unsupported(format!(
                "[coupling] remap_tolerance = {cells}: bounce-back grains are mapped every step;                  use it with method = \"psm\" or set it to 0"
            ))),
        }
    }

    /// The circles each grain was last mapped at, where a resumed run needs them to map the same
    /// grains at the same steps (a tolerance above 0); empty otherwise.
    pub fn mapped_circles(&self) -> Vec<GrainCircle> {
        match self {
            Hydro::Psm { mapper, .. } if mapper.tolerance() > 0.0 => mapper.mapped().to_vec(),
            _ => Vec::new(),
        }
    }

    /// Continue the map from circles of [`Hydro::mapped_circles`] (nothing if empty).
    pub fn restore_mapped(&mut self, circles: Vec<GrainCircle>, periodic: [bool; 2]) {
        if let Hydro::Psm { fluid, mapper, .. } = self
            && !circles.is_empty()
        {
            mapper.restore(circles, fluid.nx, fluid.ny, periodic);
        }
    }

    /// The state to checkpoint.
    pub fn state(&self) -> HydroState<T> {
        match self {
            Hydro::Psm { fluid, .. } => HydroState::Psm(fluid.state()),
            Hydro::BounceBack(b) => HydroState::BounceBack(b.state()),
        }
    }

    /// Continue from `state` (same method, same box, same settings).
    pub fn restore(&mut self, state: HydroState<T>) -> Result<(), CouplingError> {
        match (self, state) {
            (Hydro::Psm { fluid, .. }, HydroState::Psm(s)) => fluid.restore(s),
            (Hydro::BounceBack(b), HydroState::BounceBack(s)) => b.restore(s),
            (h, _) => Err(CouplingError::Unsupported(format!(
                "checkpoint of the other coupling method restored into a {:?} run: use the \
                 checkpoint's [coupling] method",
                h.method()
            ))),
        }
    }

    pub fn method(&self) -> Method {
        match self {
            Hydro::Psm { .. } => Method::Psm,
            Hydro::BounceBack(_) => Method::BounceBack,
        }
    }
    pub fn size(&self) -> [usize; 2] {
        match self {
            Hydro::Psm { fluid, .. } => [fluid.nx, fluid.ny],
            Hydro::BounceBack(b) => [b.fluid.domain.n[0], b.fluid.domain.n[1]],
        }
    }

    /// Put the grains (circles grouped by body, lattice units) on the lattice.
    pub fn map(
        &mut self,
        circles: &[GrainCircle],
        motions: &[GrainMotion],
        r_hd: f64,
        periodic: [bool; 2],
    ) -> Result<(), CouplingError> {
        match self {
            Hydro::Psm { map, mapper, .. } => {
                mapper.map(circles, r_hd, periodic, map);
                Ok(())
            }
            Hydro::BounceBack(b) => b.map(circles, motions, r_hd),
        }
    }

    /// Per grain, the liquid the PSM collision drags along with it: the sum over its cells of
    /// the weight w, of w r and of w |r|² (r from the grain centre, lattice units). `None` for
    /// bounce-back, whose covered nodes hold no liquid.
    ///
    /// The weight is the covered fraction ε_s. In one step the collision replaces only the share
    /// B_s of Eq. 10 of a cell's liquid momentum, and near τ = ½ B_s is far below ε_s in partly
    /// covered cells; but it does so every step, so over the many steps in which a grain changes
    /// speed the liquid of a partly covered cell follows the grain as well. On the DKT case
    /// (`tests/dkt_uhlmann.rs`, 16 cells per diameter, τ = 0.51) the ε_s weight gives a drafting
    /// error of 0.04 d RMS, the B_s weight 0.14 d.
    pub fn interior_liquid(&self, motions: &[GrainMotion]) -> Option<Vec<InteriorLiquid>> {
        let Hydro::Psm { fluid, map, .. } = self else {
            return None;
        };
        let (nx, ny) = (fluid.nx, fluid.ny);
        let mut out = vec![InteriorLiquid::default(); motions.len()];
        for cv in &map.covers {
            let idx = cv.cell as usize;
            let w = cv.fraction;
            let x = [(idx % nx) as f64 + 0.5, (idx / nx) as f64 + 0.5];
            let r = crate::psm::min_image(x, motions[cv.body as usize].centre, nx, ny);
            let o = &mut out[cv.body as usize];
            o.area += w;
            o.first[0] += w * r[0];
            o.first[1] += w * r[1];
            o.polar += w * (r[0] * r[0] + r[1] * r[1]);
        }
        Some(out)
    }

    /// Lay the solid zone over the lattice (PSM only, see [`PsmFluid::set_zone`]).
    pub fn set_zone(&mut self, zone: &[u32], velocities: &[[f64; 3]]) -> Result<(), CouplingError> {
        match self {
            Hydro::Psm { fluid, .. } => fluid.set_zone(zone, velocities),
            Hydro::BounceBack(_) => Err(CouplingError::Unsupported(
                "a liquid confined to a deforming sample (membrane, push-plate) is built for \
                 method = \"psm\" only; use it"
                    .into(),
            )),
        }
    }

    /// The liquid mass the solid zone removed and added so far (zero without one).
    pub fn zone_mass(&self) -> ZoneMass {
        match self {
            Hydro::Psm { fluid, .. } => fluid.zone_mass(),
            Hydro::BounceBack(_) => ZoneMass::default(),
        }
    }

    /// One LBM step; the load on each grain in lattice units.
    pub fn step(&mut self, motions: &[GrainMotion], loads: &mut Vec<Load>) -> Result<(), CouplingError> {
        match self {
            Hydro::Psm { fluid, map, .. } => fluid.step(map, motions, loads),
            Hydro::BounceBack(b) => b.step(loads, motions.len()),
        }
    }

    /// Total mass and momentum of the fluid (lattice units).
    pub fn mass_momentum(&self) -> (f64, [f64; 2]) {
        match self {
            Hydro::Psm { fluid, .. } => fluid.mass_momentum(),
            Hydro::BounceBack(b) => {
                let n = b.fluid.nodes();
                let (mut m, mut j) = (0.0, [0.0; 2]);
                for i in 0..n {
                    if b.fluid.domain.kind[i] == lbdem_lbm::domain::FLUID {
                        let (r, ji) = b.fluid.moments(i);
                        m += r;
                        j[0] += ji[0];
                        j[1] += ji[1];
                    }
                }
                (m, j)
            }
        }
    }

    /// Density and velocity of node `idx` after the last step (NaN off the fluid).
    pub fn node(&self, idx: usize) -> (f64, [f64; 2]) {
        match self {
            Hydro::Psm { fluid, .. } => {
                if fluid.is_active(idx) {
                    let u = fluid.u[idx];
                    (fluid.rho[idx], [u[0], u[1]])
                } else {
                    (f64::NAN, [f64::NAN; 2])
                }
            }
            Hydro::BounceBack(b) => {
                let m = &b.macro_fields;
                if b.fluid.domain.kind[idx] == lbdem_lbm::domain::FLUID && m.rho.len() > idx {
                    (m.rho[idx], [m.u[3 * idx], m.u[3 * idx + 1]])
                } else {
                    (f64::NAN, [f64::NAN; 2])
                }
            }
        }
    }
}
