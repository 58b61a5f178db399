//! The DEM system of a scene: particles, box, walls, membrane and its bonds.

use super::particles_csv;
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
    let pc = s.particles.as_ref().context("the scene has no [particles]")?;
    let bodies = match (&pc.csv, &pc.generate) {
        (Some(path), None) => particles_csv::read_csv_in(
            &base.join(path),
            pc.density,
            Some((s.domain.lo2(), s.domain.hi2())),
        )?,
        (None, Some(g)) => {
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
        _ => bail!("[particles]: give exactly one of csv = \"FILE.csv\" or a [particles.generate] table"),
    };
    let mut sys = System::new(bodies, domain(&s.domain));
    for (k, w) in s.walls.iter().enumerate() {
        let motion = match w.velocity {
            Some(u) => WallMotion::Velocity { v: v(u) },
            None => WallMotion::Fixed,
        };
        match (w.box_, w.p, w.n, w.a, w.b) {
            (Some(bx), None, None, None, None) => sys.walls.extend(generate::box_walls(
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
                sys.walls.push(wall)
            }
            (None, None, None, Some(a), Some(b)) => sys
                .walls
                .push(Wall::new(WallShape::Segment { a: v(a), b: v(b) }, motion)),
            _ => bail!(
                "[[walls]] #{k}: give either box = [x0, y0, x1, y1], or p and n (plane), or a and b (segment)"
            ),
        }
    }
    if let Some(m) = &s.membrane {
        let b = &sys.bodies;
        let (lo, hi) = (
            b.pos.iter().fold(Vec2::new(f64::MAX, f64::MAX), |a, p| {
                Vec2::new(a.x.min(p.x), a.y.min(p.y))
            }),
            b.pos.iter().fold(Vec2::new(f64::MIN, f64::MIN), |a, p| {
                Vec2::new(a.x.max(p.x), a.y.max(p.y))
            }),
        );
        let members: Vec<u32> = (0..b.len())
            .filter(|&k| {
                let p = b.pos[k];
                p.x - lo.x < m.shell || hi.x - p.x < m.shell || p.y - lo.y < m.shell || hi.y - p.y < m.shell
            })
            .map(|k| k as u32)
            .collect();
        for &k in &members {
            sys.bodies.tag[k as usize] = 1;
        }
        if let Some(bc) = &s.bonds {
            let b = &sys.bodies;
            for (x, &i) in members.iter().enumerate() {
                for &j in &members[x + 1..] {
                    for ci in b.circle_start[i as usize]..b.circle_start[i as usize + 1] {
                        for cj in b.circle_start[j as usize]..b.circle_start[j as usize + 1] {
                            let d = (b.circle_pos(cj) - b.circle_pos(ci)).norm();
                            if d < b.circle_r[ci] + b.circle_r[cj] + bc.gap {
                                sys.bonds.push(contact::Bond::new(ci as u32, cj as u32));
                            }
                        }
                    }
                }
            }
            sys.bond_params = Some(bc.params);
        }
        sys.membrane = Some(Membrane::new(members, &sys.bodies, m.threshold, m.force));
    }
    Ok(sys)
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
