//! `fluid` scenes: a lattice-Boltzmann run set up in SI units from a TOML file (domain, fluid,
//! obstacles as circles/spheres or a mask image, boundaries, forcing, stop condition). Writes the
//! time series (mean velocity, pressure drop, force and torque on each obstacle) as CSV and JSON,
//! fields as VTK image data with a `.pvd` collection, and a summary. A run that goes unstable
//! stops with the diagnosis and leaves nothing built on it (its snapshots are removed).

mod config;
mod output;
#[cfg(test)]
mod tests;

use super::SimContext;
use crate::stages::StageOutput;
use anyhow::{Context, Result, bail};
use config::{FaceCfg, FluidScene};
use lbdem_core::units::lattice::{LatticeInput, LatticeUnits, TimeSpec};
use lbdem_lbm::{
    Collision, D2Q9, D3Q19, Domain, Face, Fluid, ForceTorque, Lattice, LbmError, Limits, Macro, Motion, Real,
    Settings, Stepper, StepperAa,
};

/// The kernel a scene runs on: in-place AA (half the memory traffic) unless a face is Zou-He.
enum Engine<L: Lattice, T: Real> {
    Aa(StepperAa<L, T>),
    TwoArray(Stepper<L, T>),
}

impl<L: Lattice, T: Real> Engine<L, T> {
    fn step(&mut self, fluid: &mut Fluid<L, T>, out: Option<&mut Macro>) -> Result<(), LbmError> {
        match self {
            Engine::Aa(s) => s.step(fluid, out),
            Engine::TwoArray(s) => s.step(fluid, out),
        }
    }
    fn forces(&self) -> &[ForceTorque] {
        match self {
            Engine::Aa(s) => &s.forces,
            Engine::TwoArray(s) => &s.forces,
        }
    }
}
use output::{Sample, Writer};

/// Everything derived from the scene file before the run.
struct Setup {
    units: LatticeUnits,
    dim: usize,
    n: [usize; 3],
    faces: [Face; 6],
    collision: Collision,
    force: [f64; 3],
    obstacles: Vec<(String, Motion, ObstacleShape)>,
    mask: Option<(String, Vec<bool>)>,
    steps: u64,
    steady_tol: Option<f64>,
    sample_every: u64,
    snapshot_every: u64,
    threads: usize,
    /// "aa" or "two-array".
    kernel: &'static str,
}

enum ObstacleShape {
    Sphere { centre: [f64; 3], radius: f64 },
}

fn vec3(v: &[f64], dim: usize, what: &str) -> Result<[f64; 3]> {
    if !v.is_empty() && v.len() != dim {
        bail!(
            "{what} has {} components but the scene is {dim}D; give {dim} numbers",
            v.len()
        );
    }
    let mut out = [0.0; 3];
    for (o, x) in out.iter_mut().zip(v) {
        *o = *x;
    }
    Ok(out)
}

fn setup(s: &FluidScene, ctx: &SimContext) -> Result<Setup> {
    let l = &s.lattice;
    let dim = match l.stencil.as_str() {
        "D2Q9" => 2,
        "D3Q19" => 3,
        other => bail!("[lattice] stencil = \"{other}\" is not known; use \"D2Q9\" or \"D3Q19\""),
    };
    if s.domain.size.len() != dim {
        bail!(
            "[domain] size has {} entries but stencil {} needs {dim}; give the box size in m per axis",
            s.domain.size.len(),
            l.stencil
        );
    }
    let time = match (l.dt, l.tau) {
        (Some(dt), None) => TimeSpec::Dt(dt),
        (None, Some(tau)) => TimeSpec::Tau(tau),
        _ => bail!("[lattice] give exactly one of dt (s) or tau; they fix each other through the viscosity"),
    };
    let mut inp = LatticeInput::new(l.dx, s.fluid.viscosity, s.fluid.density, s.fluid.u_max, time);
    inp.mach_warn = l.mach_warn;
    inp.mach_max = l.mach_max;
    let units = LatticeUnits::derive(&inp).context("[lattice]/[fluid] parameters refused")?;
    let mut n = [1usize; 3];
    for (a, na) in n.iter_mut().enumerate().take(dim) {
        let cells = s.domain.size[a] / l.dx;
        if cells.is_nan() || cells < 2.0 || !cells.is_finite() {
            bail!(
                "[domain] size[{a}] = {} m gives {cells} nodes at dx = {} m; need at least 2",
                s.domain.size[a],
                l.dx
            );
        }
        *na = cells.round() as usize;
    }
    let b = &s.boundaries;
    let face_cfgs = [&b.x_min, &b.x_max, &b.y_min, &b.y_max, &b.z_min, &b.z_max];
    let names = ["x_min", "x_max", "y_min", "y_max", "z_min", "z_max"];
    let mut faces = [Face::Periodic; 6];
    for k in 0..6 {
        let Some(fc) = face_cfgs[k] else { continue };
        if k / 2 >= dim {
            bail!("[boundaries] {} set on a {dim}D scene; remove it", names[k]);
        }
        let to_lu = |v: [f64; 3]| v.map(|x| units.velocity_to_lattice(x));
        faces[k] = match fc {
            FaceCfg::Periodic => Face::Periodic,
            FaceCfg::Wall { velocity } => Face::Wall {
                velocity: to_lu(vec3(
                    velocity,
                    dim,
                    &format!("[boundaries] {} velocity", names[k]),
                )?),
            },
            FaceCfg::Velocity { velocity } => Face::Velocity {
                velocity: to_lu(vec3(
                    velocity,
                    dim,
                    &format!("[boundaries] {} velocity", names[k]),
                )?),
            },
            FaceCfg::Pressure { pressure } => Face::Pressure {
                rho: 1.0 + units.pressure_to_density(*pressure),
            },
        };
    }
    let collision = match l.collision.as_str() {
        "bgk" => Collision::Bgk { tau: units.tau },
        "trt" => Collision::Trt {
            tau: units.tau,
            magic: l.magic,
        },
        other => bail!("[lattice] collision = \"{other}\" is not known; use \"bgk\" or \"trt\""),
    };
    let force = vec3(&s.forcing.acceleration, dim, "[forcing] acceleration")?
        .map(|g| units.acceleration_to_lattice(g));
    let mut obstacles = Vec::new();
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
        // node i sits at (i + 1/2) dx: walls of the box are at 0 and size
        let centre = [0, 1, 2].map(|a| if a < dim { c[a] / l.dx - 0.5 } else { 0.0 });
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
        obstacles.push((
            name,
            motion,
            ObstacleShape::Sphere {
                centre,
                radius: o.radius / l.dx,
            },
        ));
    }
    let mask = match &s.mask {
        None => None,
        Some(m) => {
            if dim != 2 {
                bail!("[mask] images are 2D; use [[obstacles]] spheres in 3D");
            }
            let path = ctx.base_dir.join(&m.image);
            let img = image::open(&path)
                .with_context(|| format!("[mask] cannot read image {}", path.display()))?
                .to_luma8();
            if img.width() as usize != n[0] || img.height() as usize != n[1] {
                bail!(
                    "[mask] image {} is {}x{} pixels but the lattice is {}x{} nodes; resample the image or \
                     change [domain] size / [lattice] dx",
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
    let steps = match (s.stop.time, s.stop.steps) {
        (Some(t), None) => (t / units.dt).round().max(1.0) as u64,
        (None, Some(k)) => k.max(1),
        _ => bail!("[stop] give exactly one of time (s) or steps"),
    };
    let sample_every = (steps / s.output.samples.max(1)).max(1);
    let snapshot_every = steps
        .checked_div(s.output.snapshots)
        .map_or(u64::MAX, |k| k.max(1));
    let any_zou_he = faces.iter().any(|f| f.is_zou_he());
    let kernel = match (l.kernel.as_str(), any_zou_he) {
        ("auto", false) | ("aa", false) => "aa",
        ("auto", true) | ("two-array", _) => "two-array",
        ("aa", true) => bail!(
            "[lattice] kernel = \"aa\" with a Zou-He (velocity/pressure) face: use kernel = \"two-array\" or \"auto\""
        ),
        (other, _) => {
            bail!("[lattice] kernel = \"{other}\" is not known; use \"auto\", \"aa\" or \"two-array\"")
        }
    };
    Ok(Setup {
        kernel,
        units,
        dim,
        n,
        faces,
        collision,
        force,
        obstacles,
        mask,
        steps,
        steady_tol: s.stop.steady_tol,
        sample_every,
        snapshot_every,
        threads: l.threads,
    })
}

pub fn run(scene: &toml::Value, ctx: &SimContext) -> Result<StageOutput> {
    let s: FluidScene = scene
        .clone()
        .try_into()
        .context("fluid scene: a key is missing, misspelt or has the wrong type (see docs/lbm.md)")?;
    let setup = setup(&s, ctx)?;
    for w in &setup.units.warnings {
        eprintln!("warning: {w}");
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(setup.threads)
        .build()?;
    pool.install(|| match (setup.dim, s.lattice.precision.as_str()) {
        (2, "f64") => run_typed::<D2Q9, f64>(&setup, ctx),
        (2, "f32") => run_typed::<D2Q9, f32>(&setup, ctx),
        (3, "f64") => run_typed::<D3Q19, f64>(&setup, ctx),
        (3, "f32") => run_typed::<D3Q19, f32>(&setup, ctx),
        (_, p) => bail!("[lattice] precision = \"{p}\" is not known; use \"f64\" or \"f32\""),
    })
}

fn run_typed<L: Lattice, T: Real>(su: &Setup, ctx: &SimContext) -> Result<StageOutput> {
    let mut dom = Domain::new(su.n, su.faces);
    let mut motions = Vec::new();
    let mut names = Vec::new();
    for (k, (name, motion, shape)) in su.obstacles.iter().enumerate() {
        let ObstacleShape::Sphere { centre, radius } = shape;
        dom.fill_sphere(k as u16, *centre, *radius);
        motions.push(*motion);
        names.push(name.clone());
    }
    if let Some((name, solid)) = &su.mask {
        let id = motions.len() as u16;
        dom.fill_mask(id, solid);
        let c = [su.n[0] as f64 / 2.0 - 0.5, su.n[1] as f64 / 2.0 - 0.5, 0.0];
        motions.push(Motion {
            centre: c,
            ..Default::default()
        });
        names.push(name.clone());
    }
    if dom.fluid_count() == 0 {
        bail!("the obstacles and mask cover every node; nothing to simulate");
    }
    let mut fluid = Fluid::<L, T>::new(dom, motions);
    let settings = Settings {
        collision: su.collision,
        force: su.force,
        limits: Limits::default(),
    };
    let mut stepper = if su.kernel == "aa" {
        Engine::Aa(StepperAa::new(&mut fluid, settings).context("lattice set-up refused")?)
    } else {
        Engine::TwoArray(Stepper::new(&fluid, settings).context("lattice set-up refused")?)
    };
    let mut writer = Writer::new(ctx, su, names)?;
    let mut m = Macro::default();
    let mut last_mean: Option<f64> = None;
    let t0 = std::time::Instant::now();
    let mut stopped_steady = false;
    for step in 1..=su.steps {
        let sample = step % su.sample_every == 0 || step == su.steps;
        let snapshot = step % su.snapshot_every == 0 || step == su.steps;
        let out = if sample || snapshot { Some(&mut m) } else { None };
        if let Err(e) = stepper.step(&mut fluid, out) {
            writer.discard();
            return Err(anyhow::Error::new(e).context(format!(
                "fluid scene stopped at step {step} of {}; no time series or summary written",
                su.steps
            )));
        }
        if sample {
            let smp = Sample::take(&fluid, stepper.forces(), &m, &su.units, su.dim, su.n);
            let mean = smp.mean_u[0].hypot(smp.mean_u[1]).hypot(smp.mean_u[2]);
            writer.push(smp);
            if let (Some(tol), Some(prev)) = (su.steady_tol, last_mean)
                && (mean - prev).abs() <= tol * mean.abs().max(f64::MIN_POSITIVE)
            {
                stopped_steady = true;
            }
            last_mean = Some(mean);
        }
        if snapshot || stopped_steady {
            writer.snapshot(&fluid, &m, &su.units, step)?;
        }
        if stopped_steady {
            break;
        }
    }
    writer.finish(su, &fluid, stopped_steady, t0.elapsed().as_secs_f64())
}
