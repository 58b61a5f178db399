//! The DEM system of a scene: particles, box, walls, membrane and its bonds.

use super::{assembly_file, particles_csv};
use crate::scenes::schema::{DomainSection, Scene};
use anyhow::{Context, Result, bail};
use lbdem_dem::*;
use std::path::Path;

fn v(a: [f64; 2]) -> Vec2 {
    Vec2::new(a[0], a[1])
}

/// Build the grains' system from `[particles]`, `[domain]`, `[[walls]]`, `[membrane]` and
/// `[bonds]`; relative paths resolve from `base`.
pub fn build_system(s: &Scene, base: &Path) -> Result<System> {
    let bodies = bodies(s, base)?;
    let mut sys = System::new(bodies, domain(&s.domain));
    sys.walls = walls(s)?;
    if let Some(m) = membrane_spec(s) {
        assembly::install_membrane(&mut sys, &m);
    }
    if let (Some(m), Some(mem)) = (&s.membrane, &sys.membrane) {
        let f = m.mass_scale;
        if !(f > 0.0 && f.is_finite()) {
            bail!("[membrane] mass_scale = {f}: give a positive factor (1 = the grains' own masses)");
        }
        let b = &mut sys.bodies;
        for &k in &mem.bodies {
            let k = k as usize;
            b.density[k] *= f;
            b.mass[k] *= f;
            b.inertia[k] *= f;
        }
    }
    Ok(sys)
}

/// The grains of `[particles]`: a particle file, an assembly file or generated.
pub fn bodies(s: &Scene, base: &Path) -> Result<Bodies> {
    let pc = s.particles.as_ref().context("the scene has no [particles]")?;
    if let Some(dir) = &pc.continue_from {
        return particles_csv::read_csv(&base.join(dir), pc.density)
            .with_context(|| format!("[particles] continue_from = {:?}", dir.display().to_string()));
    }
    Ok(match (&pc.csv, &pc.generate, &pc.assembly) {
        (Some(path), None, None) => particles_csv::read_csv_in(
            &base.join(path),
            pc.density,
            Some((s.domain.lo2(), s.domain.hi2())),
        )?,
        (None, None, Some(a)) => {
            let from = format!(
                "[particles] assembly = {{ file = {:?} }}",
                a.file.display().to_string()
            );
            let expect = assembly_file::Expect {
                grains: a.grains,
                d: a.d,
                from: &from,
            };
            assembly_file::read_assembly(&base.join(&a.file), pc.density, &expect)?.0
        }
        (None, Some(g), None) => {
            let shapes: Vec<ClumpShape<Vec2>> = g
                .templates
                .iter()
                .map(|t| ClumpShape {
                    balls: t
                        .circles
                        .iter()
                        .map(|c| Ball {
                            centre: Vec2::new(c[0], c[1]),
                            r: c[2],
                        })
                        .collect(),
                })
                .collect();
            let w: Vec<f64> = g.templates.iter().map(|t| t.weight).collect();
            generate::random_insert(&shapes, &w, pc.density, v(g.lo), v(g.hi), g.count, g.seed)
                .context("[particles.generate]")?
        }
        _ => bail!(
            "[particles]: give exactly one of csv = \"FILE.csv\", assembly = {{ file, grains, d }} or a \
             [particles.generate] table"
        ),
    })
}

/// The walls of `[[walls]]`, in order (a box counts four: left, right, bottom, top).
pub fn walls(s: &Scene) -> Result<Vec<Wall>> {
    let mut out = Vec::new();
    for (k, w) in s.walls.iter().enumerate() {
        let motion = match w.velocity {
            Some(u) => WallMotion::Velocity { v: v(u) },
            None => WallMotion::Fixed,
        };
        match (w.box_, w.p, w.n, w.a, w.b) {
            (Some(bx), None, None, None, None) => out.extend(generate::box_walls(
                Vec2::new(bx[0], bx[1]),
                Vec2::new(bx[2], bx[3]),
            )),
            (None, Some(p), Some(n), None, None) => {
                let mut wall = Wall::plane(v(p), v(n));
                wall.motion = motion;
                wall.vel = match motion {
                    WallMotion::Velocity { v } => v,
                    _ => Vec2::ZERO,
                };
                out.push(wall)
            }
            (None, None, None, Some(a), Some(b)) => {
                out.push(Wall::new(WallShape::Segment { a: v(a), b: v(b) }, motion))
            }
            _ => bail!(
                "[[walls]] #{k}: give either box = [x0, y0, x1, y1], or p and n (plane), or a and b (segment)"
            ),
        }
    }
    Ok(out)
}

/// The membrane of `[membrane]` and `[bonds]` (Su et al. 2020 Sect. 2.4), if the scene has one.
pub fn membrane_spec(s: &Scene) -> Option<assembly::MembraneSpec> {
    s.membrane.as_ref().map(|m| assembly::MembraneSpec {
        shell: m.shell,
        threshold: m.threshold,
        force: m.force,
        ramp: m.ramp,
        bonds: s.bonds.as_ref().map(|b| (b.params, b.gap)),
    })
}

/// The DEM box of `[domain]` (2D).
pub fn domain(d: &DomainSection) -> Domain {
    Domain {
        lo: v(d.lo2()),
        hi: v(d.hi2()),
        periodic: d.periodic2(),
    }
}

/// A point of wall `w` that moves with it (for the displacement stop condition).
pub fn wall_anchor(w: &Wall) -> Vec2 {
    match w.shape {
        WallShape::Plane { p, .. } => p,
        WallShape::Segment { a, .. } => a,
    }
}
