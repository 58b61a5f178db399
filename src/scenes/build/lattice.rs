//! The lattice of a scene from `[fluid]`, `[lattice]`, `[domain]`, `[boundaries]` and
//! `[forcing]`: units (Su Eqs. 15-16, refused where unstable or inaccurate), node counts,
//! faces, collision operator and body force, for fluid and coupled scenes alike.

use crate::scenes::schema::{FaceSection, Scene};
use anyhow::{Context, Result, bail};
use lbdem_core::units::lattice::{LatticeInput, LatticeUnits, TimeSpec};
use lbdem_lbm::{Collision, Face};

/// Everything derived from the liquid's sections.
#[derive(Clone, Debug)]
pub struct LatticeSetup {
    pub units: LatticeUnits,
    pub dim: usize,
    /// Nodes per axis (1 on the z axis in 2D).
    pub n: [usize; 3],
    pub faces: [Face; 6],
    pub collision: Collision,
    /// Body-force density on the liquid, lattice units.
    pub force: [f64; 3],
    /// "aa" or "two-array".
    pub kernel: &'static str,
    /// "f64" or "f32".
    pub precision: String,
    /// Origin of the lattice (m): node i sits at lo + (i + ½) dx.
    pub lo: [f64; 3],
}

/// A vector of the scene's dimension, zero-padded to 3.
pub fn vec3(v: &[f64], dim: usize, what: &str) -> Result<[f64; 3]> {
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

pub fn setup(s: &Scene) -> Result<LatticeSetup> {
    let (Some(l), Some(fl)) = (&s.lattice, &s.fluid) else {
        bail!("the scene has no [fluid] and [lattice]");
    };
    let dim = s.domain.dim();
    let stencil = l
        .stencil
        .clone()
        .unwrap_or_else(|| if dim == 2 { "D2Q9" } else { "D3Q19" }.into());
    let want = match stencil.as_str() {
        "D2Q9" => 2,
        "D3Q19" => 3,
        other => bail!("[lattice] stencil = \"{other}\" is not known; use \"D2Q9\" or \"D3Q19\""),
    };
    if want != dim {
        bail!(
            "[lattice] stencil = \"{stencil}\" is {want}D but [domain] is {dim}D; give lo/hi with {want} numbers \
             or remove stencil"
        );
    }
    let time = match (l.dt, l.tau) {
        (Some(dt), None) => TimeSpec::Dt(dt),
        (None, Some(tau)) => TimeSpec::Tau(tau),
        _ => bail!("[lattice] give exactly one of dt (s) or tau; they fix each other through the viscosity"),
    };
    let nu = fl.kinematic_viscosity().map_err(anyhow::Error::msg)?;
    let mut inp = LatticeInput::new(l.dx, nu, fl.density, fl.u_max, time);
    inp.mach_warn = l.mach_warn;
    inp.mach_max = l.mach_max;
    let units = LatticeUnits::derive(&inp).context("[lattice]/[fluid] parameters refused")?;
    let mut n = [1usize; 3];
    for (a, na) in n.iter_mut().enumerate().take(dim) {
        let side = s.domain.size(a);
        let cells = side / l.dx;
        if !(cells >= 2.0 && cells.is_finite()) {
            bail!(
                "[domain] axis {a}: {side} m gives {cells} nodes at dx = {} m; need at least 2",
                l.dx
            );
        }
        let whole = cells.round();
        if (cells - whole).abs() > 1e-6 * whole {
            bail!(
                "[domain] axis {a}: the side {side} m is not a whole number of lattice spacings dx = {} m \
                 ({cells:.4} nodes), so the lattice faces would not sit on the box; change [lattice] dx or [domain]",
                l.dx
            );
        }
        *na = whole as usize;
    }
    let faces = faces(s, dim, &units)?;
    let collision = match l.collision.as_str() {
        "bgk" => Collision::Bgk { tau: units.tau },
        "trt" => Collision::Trt {
            tau: units.tau,
            magic: l.magic,
        },
        other => bail!("[lattice] collision = \"{other}\" is not known; use \"bgk\" or \"trt\""),
    };
    let accel = s
        .forcing
        .as_ref()
        .map(|f| f.acceleration.clone())
        .unwrap_or_default();
    let force = vec3(&accel, dim, "[forcing] acceleration")?.map(|g| units.acceleration_to_lattice(g));
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
    if !matches!(l.precision.as_str(), "f64" | "f32") {
        bail!(
            "[lattice] precision = \"{}\" is not known; use \"f64\" or \"f32\"",
            l.precision
        );
    }
    let mut lo = [0.0; 3];
    lo[..dim].copy_from_slice(&s.domain.lo);
    Ok(LatticeSetup {
        units,
        dim,
        n,
        faces,
        collision,
        force,
        kernel,
        precision: l.precision.clone(),
        lo,
    })
}

/// Faces: periodic on the axes `[domain] periodic` names, else as `[boundaries]` gives them
/// (a wall at rest when omitted).
fn faces(s: &Scene, dim: usize, units: &LatticeUnits) -> Result<[Face; 6]> {
    let b = s.boundaries.clone().unwrap_or_default();
    let given = [&b.x_min, &b.x_max, &b.y_min, &b.y_max, &b.z_min, &b.z_max];
    let names = ["x_min", "x_max", "y_min", "y_max", "z_min", "z_max"];
    let mut faces = [Face::Periodic; 6];
    for k in 0..6 {
        let axis = k / 2;
        if axis >= dim {
            if given[k].is_some() {
                bail!("[boundaries] {} set on a {dim}D scene; remove it", names[k]);
            }
            continue;
        }
        if s.domain.is_periodic(axis) {
            if given[k].is_some() {
                bail!(
                    "[boundaries] {} is given but [domain] periodic makes axis {axis} periodic; remove one of them",
                    names[k]
                );
            }
            continue;
        }
        let to_lu = |v: [f64; 3]| v.map(|x| units.velocity_to_lattice(x));
        let what = format!("[boundaries] {} velocity", names[k]);
        faces[k] = match given[k] {
            None => Face::Wall { velocity: [0.0; 3] },
            Some(FaceSection::Wall { velocity }) => Face::Wall {
                velocity: to_lu(vec3(velocity, dim, &what)?),
            },
            Some(FaceSection::Velocity { velocity }) => Face::Velocity {
                velocity: to_lu(vec3(velocity, dim, &what)?),
            },
            Some(FaceSection::Pressure { pressure }) => Face::Pressure {
                rho: 1.0 + units.pressure_to_density(*pressure),
            },
        };
    }
    Ok(faces)
}
