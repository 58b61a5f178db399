//! Time one PSM lattice step on a Su-sized case (238 x 300 walled nodes, 6972 two-circle grains
//! of 0.9 and 0.75 cells a cell apart, about 1.4 covers per covered node, as Simulation I):
//! `cargo run --release -p lbdem-coupling --example psm_step --features probes -- [STEPS]`.
//! Prints the median milliseconds per step of five rounds, with grains and without.

use lbdem_coupling::solid_fraction::{GrainCircle, solid_map};
use lbdem_coupling::{GrainMotion, PsmFluid, PsmSettings};
use lbdem_lbm::{Collision, Domain, Face, Limits};
use rand::RngExt;
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let steps: usize = std::env::args()
        .nth(1)
        .map(|a| a.parse())
        .transpose()?
        .unwrap_or(50);
    let (nx, ny) = (238, 300);
    let wall = Face::Wall { velocity: [0.0; 3] };
    let domain = Domain::new(
        [nx, ny, 1],
        [wall, wall, wall, wall, Face::Periodic, Face::Periodic],
    );
    let settings = PsmSettings {
        collision: Collision::Trt {
            tau: 1.343,
            magic: 3.0 / 16.0,
        },
        force: [0.0; 2],
        limits: Limits::default(),
    };
    let mut rng = lbdem_dem::generate::rng(7);
    let mut rnd = || rng.random::<f64>();
    let (cols, rows) = (83, 84);
    let (sx, sy) = ((nx - 8) as f64 / cols as f64, (ny - 8) as f64 / rows as f64);
    let (mut circles, mut grains) = (Vec::new(), Vec::new());
    for j in 0..rows {
        for i in 0..cols {
            let c = [4.0 + (i as f64 + 0.5) * sx, 4.0 + (j as f64 + 0.5) * sy];
            let a = std::f64::consts::FRAC_PI_2 + 0.4 * (rnd() - 0.5);
            let (s, co) = a.sin_cos();
            let body = grains.len() as u32;
            circles.push(GrainCircle {
                body,
                centre: [c[0] - 0.5 * co, c[1] - 0.5 * s],
                radius: 0.9,
            });
            circles.push(GrainCircle {
                body,
                centre: [c[0] + 0.5 * co, c[1] + 0.5 * s],
                radius: 0.75,
            });
            grains.push(GrainMotion {
                centre: c,
                velocity: [1e-3 * (rnd() - 0.5), 1e-3 * (rnd() - 0.5)],
                omega: 1e-4 * (rnd() - 0.5),
            });
        }
    }
    let map = solid_map(&circles, 1.0, nx, ny, [false; 2]);
    let empty = solid_map(&[], 1.0, nx, ny, [false; 2]);
    let cells = map.total.iter().filter(|&&t| t > 0.0).count();
    let mut loads = Vec::new();
    for (name, m, g) in [("grains", &map, &grains[..]), ("no grains", &empty, &[][..])] {
        let mut times = Vec::new();
        for _ in 0..5 {
            let mut fluid = PsmFluid::<f64>::new(&domain, settings)?;
            fluid.step(m, g, &mut loads)?;
            let t0 = Instant::now();
            for _ in 0..steps {
                fluid.step(m, g, &mut loads)?;
            }
            times.push(t0.elapsed().as_secs_f64() * 1e3 / steps as f64);
        }
        times.sort_by(f64::total_cmp);
        let nodes = (nx * ny) as f64;
        println!(
            "{name:>9}: {:.3} ms per step ({:.1} MLUPS), {} covers on {cells} cells, {} threads",
            times[2],
            nodes / times[2] / 1e3,
            m.covers.len(),
            rayon::current_num_threads()
        );
    }
    Ok(())
}
