//! Liquid only: a lattice-Boltzmann run (D2Q9 or D3Q19, f64 or f32) with fixed or moving
//! obstacles and mask images; the in-place AA kernel unless a face is Zou-He. The series holds
//! the mean velocity, the pressure drop between the x faces and the force and torque on each
//! obstacle (momentum exchange, Leonardi Eq. 21), all in SI.

use crate::scenes::build::lattice::{LatticeSetup, setup, vec3};
use crate::scenes::schema::Scene;
use crate::scenes::snapshot::{FluidFields, write_fluid};
use crate::scenes::timeloop::{Model, Probe};
use anyhow::{Context, Result, bail};
use lbdem_lbm::domain::FLUID;
use lbdem_lbm::{
    D2Q9, D3Q19, Domain, Fluid, ForceTorque, Lattice, Limits, Macro, Motion, Real, Settings, Stepper,
    StepperAa,
};
use std::path::{Path, PathBuf};

/// Build the model of a liquid-only scene.
pub fn build(s: &Scene, base: &Path) -> Result<Box<dyn Model>> {
    let su = setup(s)?;
    for w in &su.units.warnings {
        eprintln!("warning: {w}");
    }
    let geo = geometry(s, &su, base)?;
    Ok(match (su.dim, su.precision.as_str()) {
        (2, "f32") => Box::new(FluidModel::<D2Q9, f32>::new(su, geo)?),
        (2, _) => Box::new(FluidModel::<D2Q9, f64>::new(su, geo)?),
        (_, "f32") => Box::new(FluidModel::<D3Q19, f32>::new(su, geo)?),
        _ => Box::new(FluidModel::<D3Q19, f64>::new(su, geo)?),
    })
}

/// Obstacles (name, motion, centre and radius in nodes) and the mask.
struct Geometry {
    spheres: Vec<(String, Motion, [f64; 3], f64)>,
    mask: Option<(String, Vec<bool>)>,
    /// `[fluid] initial` (resolved) and `[fluid] u_max`.
    initial: Option<(PathBuf, f64)>,
}

fn geometry(s: &Scene, su: &LatticeSetup, base: &Path) -> Result<Geometry> {
    let (dim, dx, units) = (su.dim, su.units.dx, &su.units);
    let mut spheres = Vec::new();
    for (k, o) in s.obstacles.iter().enumerate() {
        let want = if dim == 2 { "circle" } else { "sphere" };
        if o.shape != want {
            bail!(
                "[[obstacles]] #{k}: shape = \"{}\" in a {dim}D scene; use \"{want}\"",
                o.shape
            );
        }
        if o.centre.len() != dim {
            bail!("[[obstacles]] #{k}: centre needs {dim} coordinates (m)");
        }
        let c = vec3(&o.centre, dim, "centre")?;
        // node i sits at lo + (i + 1/2) dx
        let centre = [0, 1, 2].map(|a| {
            if a < dim {
                (c[a] - su.lo[a]) / dx - 0.5
            } else {
                0.0
            }
        });
        let omega = match &o.omega {
            None => [0.0; 3],
            Some(toml::Value::Float(w)) if dim == 2 => [0.0, 0.0, *w],
            Some(toml::Value::Integer(w)) if dim == 2 => [0.0, 0.0, *w as f64],
            Some(v) => {
                let w: Vec<f64> = v
                    .clone()
                    .try_into()
                    .context("[[obstacles]] omega: a number (2D) or 3 numbers")?;
                vec3(&w, 3, "[[obstacles]] omega")?
            }
        };
        let motion = Motion {
            centre,
            velocity: vec3(&o.velocity, dim, "[[obstacles]] velocity")?.map(|v| units.velocity_to_lattice(v)),
            omega: omega.map(|w| w * units.dt),
        };
        let name = o.name.clone().unwrap_or_else(|| format!("obstacle{k}"));
        spheres.push((name, motion, centre, o.radius / dx));
    }
    let n = su.n;
    let mask = match &s.mask {
        None => None,
        Some(m) => {
            if dim != 2 {
                bail!("[mask] images are 2D; use [[obstacles]] spheres in 3D");
            }
            let path = base.join(&m.image);
            let img = crate::io::image::open(&path)
                .with_context(|| format!("[mask] image = {:?}", m.image))?
                .to_luma8();
            if img.width() as usize != n[0] || img.height() as usize != n[1] {
                bail!(
                    "[mask] image {} is {}x{} pixels but the lattice is {}x{} nodes; resample the image or \
                     change [domain] / [lattice] dx",
                    path.display(),
                    img.width(),
                    img.height(),
                    n[0],
                    n[1]
                );
            }
            let mut solid = vec![false; n[0] * n[1]];
            for (x, row, p) in img.enumerate_pixels() {
                let y = n[1] - 1 - row as usize;
                solid[x as usize + n[0] * y] = p.0[0] < 128;
            }
            Some((m.name.clone(), solid))
        }
    };
    let initial = s
        .fluid
        .as_ref()
        .and_then(|f| f.initial.as_ref().map(|p| (base.join(p), f.u_max)));
    Ok(Geometry {
        spheres,
        mask,
        initial,
    })
}

/// The kernel a scene runs on: in-place AA (half the memory traffic) unless a face is Zou-He.
enum Engine<L: Lattice, T: Real> {
    Aa(StepperAa<L, T>),
    TwoArray(Stepper<L, T>),
}

pub struct FluidModel<L: Lattice, T: Real> {
    su: LatticeSetup,
    fluid: Fluid<L, T>,
    engine: Engine<L, T>,
    settings: Settings,
    names: Vec<String>,
    m: Macro,
    fields_step: u64,
}

impl<L: Lattice, T: Real> FluidModel<L, T> {
    fn new(su: LatticeSetup, geo: Geometry) -> Result<Self> {
        let mut dom = Domain::new(su.n, su.faces);
        let mut motions = Vec::new();
        let mut names = Vec::new();
        for (k, (name, motion, centre, radius)) in geo.spheres.into_iter().enumerate() {
            dom.fill_sphere(k as u16, centre, radius);
            motions.push(motion);
            names.push(name);
        }
        if let Some((name, solid)) = geo.mask {
            let id = motions.len() as u16;
            dom.fill_mask(id, &solid);
            let c = [su.n[0] as f64 / 2.0 - 0.5, su.n[1] as f64 / 2.0 - 0.5, 0.0];
            motions.push(Motion {
                centre: c,
                ..Default::default()
            });
            names.push(name);
        }
        if dom.fluid_count() == 0 {
            bail!("the obstacles and mask cover every node; nothing to simulate");
        }
        let mut fluid = Fluid::<L, T>::new(dom, motions);
        if let Some((path, u_max)) = &geo.initial {
            let d = &fluid.domain;
            let states =
                crate::scenes::build::initial_fluid::read(path, su.n, su.dim, &d.kind, &su.units, *u_max)?;
            let n = d.n;
            fluid.init_equilibrium(|c| states[c[0] + n[0] * (c[1] + n[1] * c[2])]);
        }
        let settings = Settings {
            collision: su.collision,
            force: su.force,
            limits: Limits::default(),
        };
        let engine = make_engine(&su, &mut fluid, settings)?;
        if !crate::contract::quiet() {
            eprintln!(
                "fluid: {} {} lattice {:?}, tau = {:.4}, dt = {:e} s, kernel {}, SIMD {}",
                L::NAME,
                T::NAME,
                &su.n[..su.dim],
                su.units.tau,
                su.units.dt,
                su.kernel,
                lbdem_core::simd::level().name()
            );
        }
        Ok(Self {
            su,
            fluid,
            engine,
            settings,
            names,
            m: Macro::default(),
            fields_step: u64::MAX,
        })
    }

    fn forces(&self) -> &[ForceTorque] {
        match &self.engine {
            Engine::Aa(s) => &s.forces,
            Engine::TwoArray(s) => &s.forces,
        }
    }

    fn fields(&self) -> Result<&Macro> {
        if self.fields_step != self.fluid.step {
            bail!(
                "internal: the liquid's fields were not computed at step {}",
                self.fluid.step
            );
        }
        Ok(&self.m)
    }
}

fn make_engine<L: Lattice, T: Real>(
    su: &LatticeSetup,
    fluid: &mut Fluid<L, T>,
    settings: Settings,
) -> Result<Engine<L, T>> {
    Ok(if su.kernel == "aa" {
        Engine::Aa(StepperAa::new(fluid, settings).context("lattice set-up refused")?)
    } else {
        Engine::TwoArray(Stepper::new(fluid, settings).context("lattice set-up refused")?)
    })
}

impl<L: Lattice, T: Real> Model for FluidModel<L, T> {
    fn step(&mut self, fields: bool) -> Result<()> {
        let out = if fields { Some(&mut self.m) } else { None };
        let r = match &mut self.engine {
            Engine::Aa(s) => s.step(&mut self.fluid, out),
            Engine::TwoArray(s) => s.step(&mut self.fluid, out),
        };
        r.map_err(anyhow::Error::new)
            .with_context(|| format!("the liquid went unstable at step {}", self.fluid.step))?;
        if fields {
            self.fields_step = self.fluid.step;
        }
        Ok(())
    }
    fn steps_done(&self) -> u64 {
        self.fluid.step
    }
    fn time(&self) -> f64 {
        self.fluid.step as f64 * self.su.units.dt
    }
    fn dt(&self) -> f64 {
        self.su.units.dt
    }
    fn series_columns(&self) -> Vec<String> {
        let mut h: Vec<String> = ["mean_ux", "mean_uy", "mean_uz", "pressure_drop", "max_mach"]
            .map(String::from)
            .to_vec();
        for n in &self.names {
            for c in ["fx", "fy", "fz", "tx", "ty", "tz"] {
                h.push(format!("{n}_{c}"));
            }
        }
        h
    }
    fn sample(&self) -> Vec<f64> {
        let Ok(m) = self.fields() else {
            return vec![f64::NAN; self.series_columns().len()];
        };
        let u = &self.su.units;
        let (dim, n) = (self.su.dim, self.su.n);
        let dom = &self.fluid.domain;
        let (mut sum, mut cnt, mut umax2) = ([0.0; 3], 0usize, 0.0f64);
        let (mut p_in, mut n_in, mut p_out, mut n_out) = (0.0, 0usize, 0.0, 0usize);
        for idx in 0..dom.len() {
            if dom.kind[idx] != FLUID {
                continue;
            }
            let v = [m.u[3 * idx], m.u[3 * idx + 1], m.u[3 * idx + 2]];
            for a in 0..3 {
                sum[a] += v[a];
            }
            umax2 = umax2.max(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            cnt += 1;
            let x = idx % n[0];
            if x == 0 {
                p_in += m.rho[idx];
                n_in += 1;
            } else if x + 1 == n[0] {
                p_out += m.rho[idx];
                n_out += 1;
            }
        }
        let drop = if n_in > 0 && n_out > 0 {
            u.density_to_pressure(1.0 + p_in / n_in as f64 - p_out / n_out as f64)
        } else {
            0.0
        };
        let mut row: Vec<f64> = sum.map(|s| u.velocity_to_si(s / cnt.max(1) as f64)).to_vec();
        row.push(drop);
        row.push(umax2.sqrt() / (1.0f64 / 3.0).sqrt());
        for f in &self.forces()[..self.fluid.obstacles.len()] {
            row.extend(f.force.map(|x| u.force_to_si(x, dim)));
            row.extend(f.torque.map(|x| u.torque_to_si(x, dim)));
        }
        row
    }
    fn probe(&self, q: Probe) -> Option<f64> {
        match q {
            Probe::MeanLiquidSpeed => {
                let s = self.sample();
                Some(s[0].hypot(s[1]).hypot(s[2]))
            }
            _ => None,
        }
    }
    fn probe_needs_fields(&self, q: Probe) -> bool {
        q == Probe::MeanLiquidSpeed
    }
    fn snapshot(&self, dir: &Path) -> Result<Vec<(&'static str, PathBuf)>> {
        let m = self.fields()?;
        let u = &self.su.units;
        let dom = &self.fluid.domain;
        let liquid = |i: usize| dom.kind[i] == FLUID;
        let velocity = (0..3 * dom.len())
            .map(|k| {
                if liquid(k / 3) {
                    u.velocity_to_si(m.u[k])
                } else {
                    f64::NAN
                }
            })
            .collect();
        let pressure = (0..dom.len())
            .map(|i| {
                if liquid(i) {
                    u.density_to_pressure(m.rho[i])
                } else {
                    f64::NAN
                }
            })
            .collect();
        let f = FluidFields {
            n: self.su.n,
            lo: self.su.lo,
            dx: u.dx,
            velocity,
            pressure,
            solid_fraction: None,
            node_kind: Some(dom.kind.iter().map(|&k| k as i32).collect()),
        };
        write_fluid(dir, self.fluid.step, &f)
    }
    fn describe(&self) -> serde_json::Value {
        let faces: Vec<String> = self.su.faces.iter().map(|f| format!("{f:?}")).collect();
        serde_json::json!({
            "lattice": L::NAME, "precision": T::NAME, "nodes": self.su.n,
            "fluid_nodes": self.fluid.domain.fluid_count(), "units": self.su.units,
            "collision": self.su.collision, "kernel": self.su.kernel, "faces": faces,
            "obstacles": self.names,
        })
    }
    fn can_checkpoint(&self) -> bool {
        // The AA kernel's array is in its natural layout only after an even number of steps.
        !matches!(self.engine, Engine::Aa(_)) || self.fluid.step.is_multiple_of(2)
    }
    fn save(&self) -> Result<serde_json::Value> {
        let f: Vec<f64> = match &self.engine {
            Engine::Aa(s) => s.canonical(&self.fluid)?.iter().map(|v| v.to_f64()).collect(),
            Engine::TwoArray(_) => self.fluid.f.iter().map(|v| v.to_f64()).collect(),
        };
        Ok(serde_json::json!({ "step": self.fluid.step, "f": f }))
    }
    fn restore(&mut self, state: serde_json::Value) -> Result<()> {
        #[derive(serde::Deserialize)]
        struct S {
            step: u64,
            f: Vec<f64>,
        }
        let s: S = serde_json::from_value(state)?;
        let dom = self.fluid.domain.clone();
        let mut fluid = Fluid::<L, T>::new(dom, self.fluid.obstacles.clone());
        if s.f.len() != fluid.f.len() {
            bail!(
                "the checkpoint holds {} populations, the lattice {}",
                s.f.len(),
                fluid.f.len()
            );
        }
        fluid.f = s.f.into_iter().map(T::from_f64).collect();
        fluid.step = s.step;
        self.engine = make_engine(&self.su, &mut fluid, self.settings)?;
        self.fluid = fluid;
        Ok(())
    }
}
