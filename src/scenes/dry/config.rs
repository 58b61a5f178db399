//! The dry-scene file format (TOML, SI units). Every key is documented in docs/dem.md.

use super::particles;
use anyhow::{Result, bail};
use lbdem_dem::contact::BondParams;
use lbdem_dem::generate::Compression;
use lbdem_dem::*;
use serde::Deserialize;
use std::path::Path;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DryScene {
    #[allow(dead_code)]
    pub scene: toml::Value,
    pub particles: ParticlesCfg,
    pub domain: DomainCfg,
    #[serde(default)]
    pub walls: Vec<WallCfg>,
    pub contact: Law,
    #[serde(default)]
    pub wall_contact: Option<Law>,
    #[serde(default)]
    pub bonds: Option<BondsCfg>,
    #[serde(default)]
    pub membrane: Option<MembraneCfg>,
    pub step: StepParams,
    pub run: RunCfg,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DomainCfg {
    pub lo: [f64; 2],
    pub hi: [f64; 2],
    #[serde(default)]
    pub periodic: [bool; 2],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParticlesCfg {
    /// Density (kg/m² per unit thickness, i.e. ρ_s × 1 m).
    pub density: f64,
    /// Circles from the digitise stage: CSV with grain_id,x,y,r (+ JSON header beside it).
    #[serde(default)]
    pub csv: Option<std::path::PathBuf>,
    #[serde(default)]
    pub generate: Option<GenerateCfg>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GenerateCfg {
    pub count: usize,
    /// Templates: each a list of circles [x, y, r] (m) and a weight.
    pub templates: Vec<TemplateCfg>,
    pub lo: [f64; 2],
    pub hi: [f64; 2],
    #[serde(default)]
    pub seed: u64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TemplateCfg {
    pub circles: Vec<[f64; 3]>,
    #[serde(default = "one")]
    pub weight: f64,
}

fn one() -> f64 {
    1.0
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WallCfg {
    /// "plane" (p, n) or "segment" (a, b); or `box = [x0, y0, x1, y1]` for four planes.
    #[serde(default, rename = "box")]
    pub box_: Option<[f64; 4]>,
    #[serde(default)]
    pub p: Option<[f64; 2]>,
    #[serde(default)]
    pub n: Option<[f64; 2]>,
    #[serde(default)]
    pub a: Option<[f64; 2]>,
    #[serde(default)]
    pub b: Option<[f64; 2]>,
    /// Prescribed velocity (m/s), e.g. the push-plate.
    #[serde(default)]
    pub velocity: Option<[f64; 2]>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BondsCfg {
    pub params: BondParams,
    /// Bond every pair of membrane circles closer than r_i + r_j + gap.
    pub gap: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MembraneCfg {
    /// Grains whose centre is within this distance of the assembly's outline (box of walls or
    /// the convex extent) become membrane grains.
    pub shell: f64,
    pub threshold: f64,
    pub force: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompressCfg {
    pub target_stress: f64,
    #[serde(default = "alpha")]
    pub alpha: f64,
    pub v_max: f64,
    #[serde(default = "tol")]
    pub tolerance: f64,
    pub v_threshold: f64,
    pub max_steps: u64,
    /// Scale the grains afterwards to this packing fraction (Su Sect. 2.4).
    #[serde(default)]
    pub target_packing: Option<f64>,
}

fn alpha() -> f64 {
    0.1
}
fn tol() -> f64 {
    0.05
}

impl CompressCfg {
    pub fn to_kernel(&self) -> Compression {
        Compression {
            target_stress: self.target_stress,
            alpha: self.alpha,
            v_max: self.v_max,
            tolerance: self.tolerance,
            v_threshold: self.v_threshold,
            max_steps: self.max_steps,
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunCfg {
    pub steps: u64,
    #[serde(default = "hundred")]
    pub output_every: u64,
    #[serde(default)]
    pub snapshot_every: u64,
    #[serde(default)]
    pub checkpoint_every: u64,
    #[serde(default)]
    pub stop_when_slower_than: Option<f64>,
    #[serde(default)]
    pub compress: Option<CompressCfg>,
    /// Testing aid: fail at this step as if the process were killed (after any checkpoint).
    #[serde(default)]
    pub stop_after_steps_for_test: Option<u64>,
}

fn hundred() -> u64 {
    100
}

fn v(a: [f64; 2]) -> Vec2 {
    Vec2::new(a[0], a[1])
}

impl DryScene {
    pub fn build_system(&self, base: &Path) -> Result<System> {
        build_system(
            &self.particles,
            &self.domain,
            &self.walls,
            self.bonds.as_ref(),
            self.membrane.as_ref(),
            base,
        )
    }
}

/// The DEM system of a scene: particles, box, walls, membrane and its bonds (shared by dry and
/// coupled scenes).
pub fn build_system(
    particles: &ParticlesCfg,
    domain: &DomainCfg,
    walls: &[WallCfg],
    bonds: Option<&BondsCfg>,
    membrane: Option<&MembraneCfg>,
    base: &Path,
) -> Result<System> {
    {
        let pc = particles;
        let bodies = match (&pc.csv, &pc.generate) {
            (Some(path), None) => particles::read_csv(&base.join(path), pc.density)?,
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
                generate::random_insert(&shapes, &w, pc.density, v(g.lo), v(g.hi), g.count, g.seed)?
            }
            _ => bail!(
                "scene [particles]: give exactly one of csv = \"FILE.csv\" or a [particles.generate] table"
            ),
        };
        let d = domain;
        let domain = Domain {
            lo: v(d.lo),
            hi: v(d.hi),
            periodic: d.periodic,
        };
        let mut sys = System::new(bodies, domain);
        for (k, w) in walls.iter().enumerate() {
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
                    "scene [[walls]] #{k}: give either box = [x0, y0, x1, y1], or p and n (plane), or a and b (segment)"
                ),
            }
        }
        if let Some(m) = membrane {
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
                    p.x - lo.x < m.shell
                        || hi.x - p.x < m.shell
                        || p.y - lo.y < m.shell
                        || hi.y - p.y < m.shell
                })
                .map(|k| k as u32)
                .collect();
            for &k in &members {
                sys.bodies.tag[k as usize] = 1;
            }
            if let Some(bc) = bonds {
                let b = &sys.bodies;
                for (x, &i) in members.iter().enumerate() {
                    for &j in &members[x + 1..] {
                        for ci in b.circle_start[i as usize]..b.circle_start[i as usize + 1] {
                            for cj in b.circle_start[j as usize]..b.circle_start[j as usize + 1] {
                                let d = (b.circle_pos(cj) - b.circle_pos(ci)).norm();
                                if d < b.circle_r[ci] + b.circle_r[cj] + bc.gap {
                                    sys.bonds
                                        .push(lbdem_dem::contact::Bond::new(ci as u32, cj as u32));
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
}
