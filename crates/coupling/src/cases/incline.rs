//! Leonardi et al. (2014) Sect. 6: fresh concrete released from a lifted box on a board inclined
//! at 15° (issue 20 item 4). A cube of Bingham paste with four-sphere pebbles, the box around it
//! lifted at constant speed, the paste spreading down the board until it stops. Pure set-up and
//! measures (no I/O): the footprint on the board (Fig. 7c's outline), the viscosity on the
//! longitudinal section (Fig. 8), the share of the liquid at the largest viscosity (the paper's
//! stop: 95 %).
//!
//! Frame: x down the board, y normal to it (up), z across; gravity g (sin θ, −cos θ, 0). The board
//! is the lattice's y = 0 wall (the paper's sandpaper: no slip, which halfway bounce-back gives).
//! **The box** is a lattice of frozen spheres (radius 1.5 dx, 1.25 dx apart, so that no node
//! between them is left open) around the cube, in both solvers as the paper has it ("set as solid
//! boundary both for fluid and granular solvers"), moved up by v Δt every LBM step. The liquid
//! sees its velocity v through Eq. 19; the pebbles touch it at rest (frozen DEM spheres have no
//! velocity), so their friction against the rising wall is missed. It is lifted
//! until its lower edge is 2 dx above the cube's top, then stays.
//! **The pebbles**: radius R uniform in [r_min, r_max] (4-8 mm: the paper's 1000 pebbles then
//! weigh 2.69 kg at 2680 kg/m³ with the volume 4/3 π R³, against the reported 2.629 kg), each a
//! tetrahedron of four equal spheres whose centres are half a member radius from each other (a
//! rounded pebble) scaled so that the union's volume is 4/3 π R³, randomly oriented, placed by
//! random sequential addition of their bounding spheres inside the cube (largest first).
//! **The paste**: ρ = 1800 kg/m³, the density the paper's lattice viscosity implies
//! (μ_pl^LBM = 6.25e-4 = μ_pl Δt / (ρ Δx²) with μ_pl = 0.15 Pa s, Δt = 3e-5 s, Δx = 2 mm); its
//! lattice yield stress 7.75e-6 and gravity 4.41e-6 then match the paper's too.

use crate::error::CouplingError;
use crate::surface_grains::{SurfaceCoupled, SurfaceGrains, SurfaceScale};
use lbdem_dem::spheres::clump::DEFAULT_NODES;
use lbdem_dem::spheres::{
    BodyFrame, ClumpTemplate, Domain3, Elastic, HertzMindlinSpring, SphereStepParams, SphereSystem, Surface,
};
use lbdem_dem::vector::{Vec3, Vector};
use lbdem_lbm::free_surface::{
    ClampCreep, Conversions, FlipFlops, FreeSurface, FreeSurfaceParams, FreeSurfaceStepper, INTERFACE, LIQUID,
};
use lbdem_lbm::{Bingham, Collision, D3Q19, Domain, Face, Limits, Settings};
use nalgebra::UnitQuaternion;
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// The case's parameters (SI). [`InclineSpec::leonardi2014`] is the paper's.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InclineSpec {
    /// Lattice spacing (m) and LBM step (s).
    pub dx: f64,
    pub dt: f64,
    /// Lattice extent down the board, normal to it, across (m).
    pub extent: [f64; 3],
    /// Board inclination (degrees).
    pub tilt_deg: f64,
    /// Edge of the paste cube inside the box (m).
    pub box_edge: f64,
    /// Distance of the box's upslope side from the lattice's upslope end (m).
    pub box_from_top: f64,
    /// Lifting speed of the box (m/s).
    pub lift_speed: f64,
    /// Paste: plastic viscosity (Pa s), yield stress (Pa), density (kg/m³), τ clamp.
    pub mu_pl: f64,
    pub yield_stress: f64,
    pub rho_paste: f64,
    pub tau_min: f64,
    pub tau_max: f64,
    /// Smagorinsky constant of an eddy viscosity on top of the Bingham law (`Bingham::
    /// smagorinsky`; not in the paper, 0 is its model): what lets a coarse lattice carry the front.
    #[serde(default)]
    pub smagorinsky: f64,
    /// Lonely-node threshold of the free surface (`FreeSurfaceParams::lonely`; not in the paper,
    /// 0 is its rules): empties thin films and falling sheets one node thick.
    #[serde(default)]
    pub lonely: f64,
    /// TRT magic parameter Λ of the paste's collision; 0 (default) is the paper's BGK, whose
    /// halfway bounce-back wall moves with τ (far at τ_max = 3.5); TRT with Λ = 3/16 keeps it
    /// halfway for every τ. At 10 mm it changed neither the stability nor the footprint
    /// (docs/free_surface.md, "The incline").
    #[serde(default)]
    pub magic: f64,
    /// Pebbles: count, radius range (m), density (kg/m³), placement seed.
    pub pebbles: usize,
    pub r_min: f64,
    pub r_max: f64,
    pub rho_pebble: f64,
    pub seed: u64,
    /// Pebble material (Hertz-Mindlin with the Mindlin spring): Young's modulus (Pa), Poisson's
    /// ratio, friction, restitution.
    pub young: f64,
    pub poisson: f64,
    pub friction: f64,
    pub restitution: f64,
    /// DEM steps per LBM step.
    pub substeps: u32,
    /// The implicit velocity update of the coupling (`SurfaceGrains::implicit`); the paper's
    /// pebbles of 1-3 nodes rock without it.
    #[serde(default = "yes")]
    pub implicit: bool,
    /// Stop when this share of the paste is at τ_max (the paper: 95 %).
    #[serde(default = "stop_share")]
    pub stop_share: f64,
}

fn yes() -> bool {
    true
}
fn stop_share() -> f64 {
    0.95
}

/// What an incline run needs besides its spec to continue bit for bit.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct InclineState {
    pub grains: crate::surface_grains::SurfaceGrainsState,
    pub system: SphereSystem,
    pub lifted: f64,
    /// The creep monitor of the paste at τ_max (absent in checkpoints written before it).
    #[serde(default)]
    pub creep: Option<ClampCreep>,
    /// The flip counter of the surface (absent in checkpoints written before it).
    #[serde(default)]
    pub flips: Option<FlipFlops>,
}

/// LBM steps per window of the creep monitor (`lbdem_lbm::free_surface::ClampCreep`): 3 ms at the
/// paper's Δt, long against the surface's ripples, short against the slump.
pub const CREEP_WINDOW: u64 = 100;

impl InclineSpec {
    /// Leonardi et al. (2014) Sect. 6 (the project's reproduction list): lattice 350 × 80 × 250 at
    /// 2 mm (the paper's 350 × 250 × 80 with y normal to the board), Δt 3e-5 s, 15°, 150 mm box
    /// lifted at 0.15 m/s, μ_pl 0.15 Pa s, σ_y 62 Pa, τ in [0.501, 3.5], 1000 pebbles of R 4-8 mm
    /// at 2680 kg/m³. Not in the paper, chosen here: the box 50 mm from the upslope end, ρ_paste
    /// (module doc), the pebbles' material (a soft silica: E 5e7 Pa, ν 0.25, μ 0.5, e 0.5; the
    /// paper gives none) and 20 DEM steps per LBM step.
    pub fn leonardi2014() -> Self {
        Self {
            dx: 2e-3,
            dt: 3e-5,
            extent: [0.7, 0.16, 0.5],
            tilt_deg: 15.0,
            box_edge: 0.15,
            box_from_top: 0.05,
            lift_speed: 0.15,
            mu_pl: 0.15,
            yield_stress: 62.0,
            rho_paste: 1800.0,
            tau_min: 0.501,
            tau_max: 3.5,
            smagorinsky: 0.0,
            lonely: 0.0,
            magic: 0.0,
            pebbles: 1000,
            r_min: 4e-3,
            r_max: 8e-3,
            rho_pebble: 2680.0,
            seed: 1,
            young: 5e7,
            poisson: 0.25,
            friction: 0.5,
            restitution: 0.5,
            substeps: 20,
            implicit: true,
            stop_share: 0.95,
        }
    }

    /// The same case on a lattice `factor` times coarser with Δt scaled by factor² (diffusive
    /// scaling): the lattice viscosity, so τ_pl and the whole Bingham clamp, stay the paper's,
    /// the lattice velocities grow with the factor (the paper's are small: 0.01 at its largest
    /// speed, 0.667 m/s) and the steps to a given time fall with its square.
    pub fn coarsened(&self, factor: f64) -> Self {
        Self {
            dx: self.dx * factor,
            dt: self.dt * factor * factor,
            ..self.clone()
        }
    }

    /// Lattice nodes along each axis.
    pub fn nodes(&self) -> [usize; 3] {
        self.extent.map(|e| (e / self.dx).round() as usize)
    }

    /// The Bingham law in lattice units (ρ = 1).
    pub fn bingham(&self) -> Bingham {
        let nu = self.mu_pl / self.rho_paste * self.dt / (self.dx * self.dx);
        let stress = self.rho_paste * self.dx * self.dx / (self.dt * self.dt);
        Bingham {
            mu_pl: nu,
            yield_stress: self.yield_stress / stress,
            rho: 1.0,
            tau_min: self.tau_min,
            tau_max: self.tau_max,
            smagorinsky: self.smagorinsky,
        }
    }

    /// Gravity (m/s²) in the board's frame.
    pub fn gravity(&self) -> Vec3 {
        let t = self.tilt_deg.to_radians();
        Vec3::new(9.81 * t.sin(), -9.81 * t.cos(), 0.0)
    }

    /// Refuse what cannot be built, naming the parameter.
    pub fn check(&self) -> Result<(), CouplingError> {
        let bad = |name: &str, v: f64, why: &str| {
            Err(CouplingError::Unsupported(format!("incline {name} = {v}: {why}")))
        };
        for (name, v) in [
            ("dx", self.dx),
            ("dt", self.dt),
            ("box_edge", self.box_edge),
            ("lift_speed", self.lift_speed),
            ("rho_paste", self.rho_paste),
            ("r_min", self.r_min),
            ("rho_pebble", self.rho_pebble),
            ("young", self.young),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(name, v, "give a positive, finite value (SI)");
            }
        }
        if !(self.r_max >= self.r_min && self.r_max.is_finite()) {
            return bad("r_max", self.r_max, "give r_max >= r_min");
        }
        if !(0.0..90.0).contains(&self.tilt_deg) {
            return bad("tilt_deg", self.tilt_deg, "give an angle in [0, 90) degrees");
        }
        let n = self.nodes();
        if n.iter().any(|&k| k < 8) {
            return Err(CouplingError::Unsupported(format!(
                "incline lattice of {n:?} nodes at dx = {} m: the extent {:?} m needs at least 8 nodes on each axis",
                self.dx, self.extent
            )));
        }
        let [lx, ly, lz] = self.extent;
        if self.box_from_top < 3.0 * self.dx
            || self.box_from_top + self.box_edge + 3.0 * self.dx > lx
            || self.box_edge + self.dx > ly
            || self.box_edge + 6.0 * self.dx > lz
        {
            return Err(CouplingError::Unsupported(format!(
                "the {} m box {} m from the upslope end does not fit in the {:?} m lattice with its walls (3 dx on each side, a gas node above)",
                self.box_edge, self.box_from_top, self.extent
            )));
        }
        if self.substeps == 0 {
            return bad("substeps", 0.0, "give at least 1 DEM step per LBM step");
        }
        if !(self.stop_share > 0.0 && self.stop_share <= 1.0) {
            return bad(
                "stop_share",
                self.stop_share,
                "give a share in (0, 1] (the paper: 0.95)",
            );
        }
        Ok(())
    }
}

/// A running incline: the coupled run, the box's spheres and how far it has been lifted.
pub struct Incline {
    pub spec: InclineSpec,
    pub run: SurfaceCoupled<HertzMindlinSpring>,
    /// Sphere indices of the box wall (after the pebbles' members).
    pub box_spheres: std::ops::Range<usize>,
    /// How far the box has been lifted (m), and where it stops.
    pub lifted: f64,
    lift_to: f64,
    /// Pebble count placed.
    pub pebbles: usize,
    /// Liquid and interface nodes of the paste at the start.
    pub paste_nodes: usize,
}

impl Incline {
    pub fn build(spec: &InclineSpec) -> Result<Self, CouplingError> {
        spec.check()?;
        let n = spec.nodes();
        let (dx, dt) = (spec.dx, spec.dt);
        let g = spec.gravity();
        let g_lu = g * (dt * dt / dx);
        let wall = Face::Wall { velocity: [0.0; 3] };
        let dom = Domain::new(n, [wall; 6]);
        // the cube on whole nodes: `ne` of them along each edge, from node `i0` down the board
        // and `k0` across (centred), so its volume is ne³ dx³ whatever the rounding
        let ne = (spec.box_edge / dx).round() as usize;
        let (i0, k0) = ((spec.box_from_top / dx).round() as usize, (n[2] - ne) / 2);
        let (e, x0, z0) = (ne as f64 * dx, i0 as f64 * dx, k0 as f64 * dx);
        let inside =
            |p: [usize; 3]| (i0..i0 + ne).contains(&p[0]) && p[1] < ne && (k0..k0 + ne).contains(&p[2]);
        let liquid = FreeSurface::<D3Q19>::new(dom, |p| {
            let fill = if inside(p) { 1.0 } else { 0.0 };
            let depth = (e / dx - 0.5 - p[1] as f64).max(0.0);
            (fill, 1.0 - 3.0 * g_lu.y * depth, [0.0; 3])
        })?;
        let paste_nodes = liquid
            .cell
            .iter()
            .filter(|&&c| c == LIQUID || c == INTERFACE)
            .count();
        let bingham = spec.bingham();
        let settings = Settings {
            collision: if spec.magic > 0.0 {
                Collision::Trt {
                    tau: bingham.tau_pl().max(spec.tau_min),
                    magic: spec.magic,
                }
            } else {
                Collision::Bgk {
                    tau: bingham.tau_pl().max(spec.tau_min),
                }
            },
            force: [g_lu.x, g_lu.y, g_lu.z],
            limits: Limits::default(),
        };
        let mut stepper = FreeSurfaceStepper::new(
            &liquid,
            settings,
            FreeSurfaceParams {
                lonely: spec.lonely,
                ..FreeSurfaceParams::default()
            },
        )?;
        stepper.set_bingham(Some(bingham))?;
        stepper.record_tau(true, liquid.nodes());
        stepper.monitor_creep(Some(CREEP_WINDOW));
        let scale = SurfaceScale {
            dx,
            dt,
            rho: spec.rho_paste,
            origin: [0.0; 3],
        };
        let mut grains = SurfaceGrains::new(liquid, stepper, scale)?;
        grains.implicit = spec.implicit;
        // the DEM box is taller than the lattice: the lifted box leaves the lattice's top
        let lift_to = e + 2.0 * dx;
        let size = Vec3::new(
            spec.extent[0],
            spec.extent[1] + lift_to + 4.0 * dx,
            spec.extent[2],
        );
        let mut sys = SphereSystem::new(Domain3::new(Vec3::ZERO, size, [false; 3])?);
        let pebbles = place_pebbles(spec, &mut sys, [x0, 0.0, z0], e)?;
        let first_box = sys.spheres.len();
        let rb = 1.5 * dx;
        let step = 1.25 * dx;
        let along = |len: f64| (len / step).ceil() as usize + 1;
        let height = spec.extent[1];
        let (nh, ne) = (along(height - rb), along(e + 2.0 * rb));
        for k in 0..nh {
            let y = rb + k as f64 * step;
            for j in 0..ne {
                let t = -rb + j as f64 * (e + 2.0 * rb) / (ne - 1) as f64;
                for p in [
                    Vec3::new(x0 - rb, y, z0 + t),
                    Vec3::new(x0 + e + rb, y, z0 + t),
                    Vec3::new(x0 + t, y, z0 - rb),
                    Vec3::new(x0 + t, y, z0 + e + rb),
                ] {
                    let id = sys.add_sphere(p, Vec3::ZERO, Vec3::ZERO, rb, spec.rho_pebble)?;
                    sys.set_frozen(id, true)?;
                }
            }
        }
        let box_spheres = first_box..sys.spheres.len();
        let law = HertzMindlinSpring::uniform(
            Elastic {
                young: spec.young,
                poisson: spec.poisson,
            },
            Surface {
                mu: spec.friction,
                restitution: spec.restitution,
            },
        );
        let mut params = SphereStepParams::new(dt / spec.substeps as f64, 0.25 * spec.r_min);
        params.gravity = g;
        // the board for the pebbles, and the lattice's four side walls: the paste reaches them on
        // lattices of 10 and 5 mm (it spreads upslope too) and a pebble carried there would leave
        // the DEM box
        let (lx, lz) = (spec.extent[0], spec.extent[2]);
        for (point, normal) in [
            (Vec3::ZERO, Vec3::new(0.0, 1.0, 0.0)),
            (Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0)),
            (Vec3::new(lx, 0.0, 0.0), Vec3::new(-1.0, 0.0, 0.0)),
            (Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0)),
            (Vec3::new(0.0, 0.0, lz), Vec3::new(0.0, 0.0, -1.0)),
        ] {
            sys.walls.push(lbdem_dem::spheres::PlaneWall::new(point, normal)?);
        }
        let run = SurfaceCoupled::new(grains, sys, law, params, spec.substeps)?;
        Ok(Self {
            spec: spec.clone(),
            run,
            box_spheres,
            lifted: 0.0,
            lift_to,
            pebbles,
            paste_nodes,
        })
    }

    /// Lift the box by v Δt (until it is clear), then one coupled LBM step.
    pub fn step(&mut self) -> Result<Conversions, CouplingError> {
        let v = if self.lifted < self.lift_to {
            self.spec.lift_speed
        } else {
            0.0
        };
        let dy = v * self.spec.dt;
        self.lifted += dy;
        let s = &mut self.run.sys.spheres;
        for k in self.box_spheres.clone() {
            s.pos[k].y += dy;
        }
        self.run.grains.driven = Some((self.box_spheres.clone(), Vec3::new(0.0, v, 0.0)));
        self.run.step()
    }

    /// The state to checkpoint.
    pub fn state(&self) -> InclineState {
        InclineState {
            grains: self.run.grains.state(),
            system: self.run.sys.clone(),
            lifted: self.lifted,
            creep: self.run.grains.stepper().creep().cloned(),
            flips: Some(self.run.grains.stepper().flips().clone()),
        }
    }

    /// Continue from `state` (written by [`Self::state`] for the same spec).
    pub fn restore(&mut self, state: InclineState) -> Result<(), CouplingError> {
        if state.system.spheres.len() != self.run.sys.spheres.len() {
            return Err(CouplingError::Unsupported(format!(
                "the checkpoint has {} spheres where this incline has {}: it is not of this scene",
                state.system.spheres.len(),
                self.run.sys.spheres.len()
            )));
        }
        self.run.grains.set_state(state.grains)?;
        if let Some(c) = state.creep {
            self.run.grains.stepper_mut().restore_creep(c);
        }
        if let Some(f) = state.flips {
            self.run.grains.stepper_mut().restore_flips(f);
        }
        self.run.sys = state.system;
        self.run.dem = lbdem_dem::spheres::SphereStepper::new();
        self.lifted = state.lifted;
        Ok(())
    }

    /// The largest pebble speed (m/s).
    pub fn max_pebble_speed(&self) -> f64 {
        let s = &self.run.sys.spheres;
        (0..self.box_spheres.start)
            .map(|k| s.vel[k].norm())
            .fold(0.0, f64::max)
    }

    /// Runout (m, down the board from the box's downslope side) and width (m, across) of the
    /// footprint: the columns at least half a node thick.
    pub fn footprint(&self) -> (f64, f64) {
        let spec = &self.spec;
        let [nx, _, nz] = spec.nodes();
        let th = self.thickness();
        let (mut x_max, mut z_lo, mut z_hi) = (0usize, usize::MAX, 0usize);
        for z in 0..nz {
            for x in 0..nx {
                if th[x + nx * z] > 0.5 * spec.dx {
                    x_max = x_max.max(x + 1);
                    z_lo = z_lo.min(z);
                    z_hi = z_hi.max(z + 1);
                }
            }
        }
        if z_lo == usize::MAX {
            return (0.0, 0.0);
        }
        (
            x_max as f64 * spec.dx - (spec.box_from_top + spec.box_edge),
            (z_hi - z_lo) as f64 * spec.dx,
        )
    }

    /// Physical time (s).
    pub fn time(&self) -> f64 {
        self.run.grains.liquid.step as f64 * self.spec.dt
    }

    /// The accuracy failures of the free surface measured so far, named with their fixes: the
    /// creep at the Bingham clamp and cells converting back and forth.
    pub fn warnings(&self) -> Vec<String> {
        let st = self.run.grains.stepper();
        st.creep_warning().into_iter().chain(st.flip_warning()).collect()
    }

    /// The share of the paste's volume that moved while at least 95 % of it sat at τ_max (the
    /// creep at the Bingham clamp, `ClampCreep::moved`; [`Self::warnings`] names it).
    pub fn creep(&self) -> f64 {
        self.run.grains.stepper().creep().map_or(0.0, |c| c.moved)
    }

    /// Share of the paste's nodes (liquid and interface) whose relaxation time is at τ_max: the
    /// paper stops at 95 %.
    pub fn rigid_share(&self) -> f64 {
        let s = &self.run.grains.liquid;
        let Some(tau) = self.run.grains.stepper().tau() else {
            return 0.0;
        };
        let top = self.spec.tau_max * (1.0 - 1e-12);
        let (mut wet, mut rigid) = (0usize, 0usize);
        for (x, &c) in s.cell.iter().enumerate() {
            if c == LIQUID || c == INTERFACE {
                wet += 1;
                if tau[x] >= top {
                    rigid += 1;
                }
            }
        }
        if wet == 0 { 0.0 } else { rigid as f64 / wet as f64 }
    }

    /// Paste thickness normal to the board (m) per column (x, z), `[x + nx * z]`: Σ fill over y
    /// times dx. The footprint is where it is at least half a node.
    pub fn thickness(&self) -> Vec<f64> {
        let s = &self.run.grains.liquid;
        let [nx, ny, nz] = s.domain.n;
        let mut t = vec![0.0; nx * nz];
        for z in 0..nz {
            for x in 0..nx {
                t[x + nx * z] = (0..ny).map(|y| s.fill(s.domain.index(x, y, z))).sum::<f64>() * self.spec.dx;
            }
        }
        t
    }

    /// Dynamic viscosity (Pa s) on the longitudinal section through the middle of the board
    /// (Fig. 8), `[x + nx * y]`, NaN outside the paste.
    pub fn viscosity_section(&self) -> Vec<f64> {
        let s = &self.run.grains.liquid;
        let [nx, ny, nz] = s.domain.n;
        let z = nz / 2;
        let tau = self.run.grains.stepper().tau();
        let unit = self.spec.rho_paste * self.spec.dx * self.spec.dx / self.spec.dt;
        let mut out = vec![f64::NAN; nx * ny];
        for y in 0..ny {
            for x in 0..nx {
                let i = s.domain.index(x, y, z);
                if matches!(s.cell[i], LIQUID | INTERFACE)
                    && let Some(t) = tau.map(|t| t[i])
                {
                    out[x + nx * y] = (t - 0.5) / 3.0 * unit;
                }
            }
        }
        out
    }
}

/// Place the pebbles in the cube of edge `e` with its low corner at `corner` (module doc); how
/// many.
pub fn place_pebbles(
    spec: &InclineSpec,
    sys: &mut SphereSystem,
    corner: [f64; 3],
    e: f64,
) -> Result<usize, CouplingError> {
    if spec.pebbles == 0 {
        return Ok(0);
    }
    // the unit pebble: four unit spheres, centres half a radius apart, scaled to the volume of
    // the unit sphere
    let unit = ClumpTemplate::tetrahedron(1.0, 0.5);
    let v1 = unit.union_props(DEFAULT_NODES)?.volume;
    let member = (4.0 / 3.0 * std::f64::consts::PI / v1).cbrt();
    let bound = member * (1.0 + 0.5 * 6f64.sqrt() / 4.0);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(spec.seed);
    let mut radii: Vec<f64> = (0..spec.pebbles)
        .map(|_| spec.r_min + (spec.r_max - spec.r_min) * rng.random_range(0.0..1.0))
        .collect();
    radii.sort_by(|a, b| b.total_cmp(a));
    let mut placed: Vec<(Vec3, f64)> = Vec::with_capacity(radii.len());
    for (k, &r) in radii.iter().enumerate() {
        let rb = bound * r;
        if 2.0 * rb >= e {
            return Err(CouplingError::Unsupported(format!(
                "a pebble of radius {r} m (bounding {rb} m) does not fit in the {e} m box"
            )));
        }
        let mut found = None;
        for _ in 0..20_000 {
            let p = Vec3::new(
                corner[0] + rb + (e - 2.0 * rb) * rng.random_range(0.0..1.0),
                corner[1] + rb + (e - 2.0 * rb) * rng.random_range(0.0..1.0),
                corner[2] + rb + (e - 2.0 * rb) * rng.random_range(0.0..1.0),
            );
            if placed.iter().all(|&(q, s)| (p - q).norm() >= rb + s) {
                found = Some(p);
                break;
            }
        }
        let Some(p) = found else {
            return Err(CouplingError::Unsupported(format!(
                "placed {k} of {} pebbles in the {e} m box: no room for the next (radius {r} m) after \
                 20000 tries; use fewer or smaller pebbles",
                radii.len()
            )));
        };
        placed.push((p, rb));
        let frame = BodyFrame::of(
            &ClumpTemplate::tetrahedron(member * r, 0.5 * member * r),
            spec.rho_pebble,
            DEFAULT_NODES,
        )?;
        let q = UnitQuaternion::from_euler_angles(
            std::f64::consts::TAU * rng.random_range(0.0..1.0),
            std::f64::consts::PI * rng.random_range(0.0..1.0),
            std::f64::consts::TAU * rng.random_range(0.0..1.0),
        );
        sys.add_clump(&frame, p, q, Vec3::ZERO, Vec3::ZERO)?;
    }
    Ok(radii.len())
}
