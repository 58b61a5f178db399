//! `lbdem bench coupled`: coupled LBM-DEM steps per second on a shear-cell-sized case (issue 6:
//! about 7,000 two-circle grains, about 250 x 190 lattice nodes, LBM-DEM time-step ratio 100 as
//! in Su et al. 2020 Table 3), partially saturated cells, on 1 and 2 threads, with the share of
//! time in LBM, DEM and coupling. The reference measured in the same run is the same grains
//! stepped by the DEM alone (100 DEM steps per coupled step): the ratio is what the liquid costs.
//! Two sizes, the cell and a quarter of it (half the side each way), so the cost growth with
//! size is on record beside the growth with threads (issue 18 item 6).

use super::{BenchArgs, median};
use anyhow::Result;
use lbdem_core::units::lattice::{LatticeInput, LatticeUnits, TimeSpec};
use lbdem_coupling::units::CouplingUnits;
use lbdem_coupling::{Coupled, Hydro, PsmFluid, PsmSettings};
use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::{Ball, Bodies, ClumpShape, Damping, Law, StepParams, Stepper, System, Vec2, generate};
use lbdem_lbm::{Domain, Face, Limits};
use std::time::Instant;

const DX: f64 = 40e-6;
const RATIO: u32 = 100;

/// 108 x 65 = 7,020 two-circle grains (circles 36 and 30 µm, 40 µm apart: 106 µm long, a 1.6
/// aspect ratio), standing within ±0.1 rad of upright on a 92.6 x 116.9 µm grid (packing
/// fraction about 0.48, no initial overlaps) in a 10 x 7.6 mm walled box (250 x 190
/// nodes at dx = 40 µm); Al-Cu densities of Su et al. Table 3 (per 1 mm depth).
fn shear_cell(cols: usize, rows: usize) -> Result<System> {
    let (w, h) = (cols as f64 * 10e-3 / 108.0, rows as f64 * 7.6e-3 / 65.0);
    let shape = ClumpShape {
        balls: vec![
            Ball {
                centre: Vec2::new(-20e-6, 0.0),
                r: 36e-6,
            },
            Ball {
                centre: Vec2::new(20e-6, 0.0),
                r: 30e-6,
            },
        ],
    };
    let mut b = Bodies::new();
    let mut seed = 12345u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let (sx, sy) = (w / cols as f64, h / rows as f64);
    for j in 0..rows {
        for i in 0..cols {
            let at = Vec2::new((i as f64 + 0.5) * sx, (j as f64 + 0.5) * sy);
            let k = b.add(
                &shape,
                2.55,
                at,
                std::f64::consts::FRAC_PI_2 + 0.2 * (rnd() - 0.5),
            )?;
            b.vel[k] = Vec2::new(2e-3 * (rnd() - 0.5), 2e-3 * (rnd() - 0.5));
        }
    }
    let mut sys = System::new(b, lbdem_dem::Domain::open(Vec2::ZERO, Vec2::new(w, h)));
    sys.walls.extend(generate::box_walls(Vec2::ZERO, Vec2::new(w, h)));
    Ok(sys)
}

fn law() -> Law {
    Law::Linear(LinearSpringDashpot::new(1e4, 5e3, Damping::Ratio(0.3), 0.4))
}

fn build(sys: System) -> Result<Coupled<f64>> {
    let size = sys.domain.size();
    let (nx, ny) = ((size.x / DX).round() as usize, (size.y / DX).round() as usize);
    // Su et al. Table 3, 81 % PK: ρ_L = 2673 kg/m³, μ_L = 1.53e-3 Pa s.
    let nu = 1.53e-3 / 2673.0;
    let lat = LatticeUnits::derive(&LatticeInput::new(DX, nu, 2673.0, 5e-3, TimeSpec::Dt(5e-5)))?;
    let units = CouplingUnits::new(lat, [0.0; 2], 5e-5 / RATIO as f64)?;
    let wall = Face::Wall { velocity: [0.0; 3] };
    let domain = Domain::new(
        [nx, ny, 1],
        [wall, wall, wall, wall, Face::Periodic, Face::Periodic],
    );
    let fluid = PsmFluid::<f64>::new(
        &domain,
        PsmSettings {
            collision: lbdem_lbm::Collision::Bgk {
                tau: units.lattice.tau,
            },
            force: [0.0; 2],
            limits: Limits::default(),
        },
    )?;
    let p = StepParams::new(units.dt_dem, 10e-6);
    let mut c = Coupled::new(Hydro::psm(fluid), sys, law(), law(), p, units, 0.8)?;
    c.depth = 1e-3;
    Ok(c)
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let sizes: [(usize, usize); 2] = if a.quick {
        [(27, 16), (14, 8)]
    } else {
        [(108, 65), (54, 33)]
    };
    let steps = if a.quick { 3 } else { 10 };
    let mut out = Vec::new();
    for (cols, rows) in sizes {
        out.extend(one_size(a, cols, rows, steps)?);
    }
    if let Some(path) = &a.json {
        lbdem_core::atomic::write_atomic(path, &serde_json::to_vec_pretty(&out)?)?;
    }
    Ok(())
}

/// One grid of grains on 1 and 2 threads: a JSON row per thread count.
fn one_size(a: &BenchArgs, cols: usize, rows: usize, steps: usize) -> Result<Vec<serde_json::Value>> {
    let sys = shear_cell(cols, rows)?;
    let grains = sys.bodies.len();
    let mut out = Vec::new();
    let [nx, ny] = {
        let c = build(sys.clone())?;
        let [nx, ny] = c.fluid.size();
        println!(
            "coupled shear cell: {grains} two-circle grains, lattice {nx} x {ny}, tau {:.3}, ratio {}, PSM f64; \
             median of {} runs of {steps} coupled steps",
            c.units.lattice.tau, c.units.ratio, a.reps
        );
        [nx, ny]
    };
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
        let (mut rates, mut dem_only, mut shares) = (Vec::new(), Vec::new(), Vec::new());
        for _ in 0..a.reps {
            let (rate, share, dem_rate) = pool.install(|| -> Result<_> {
                let mut c = build(sys.clone())?;
                c.step()?; // warm-up: first solid map, neighbour lists
                c.timing = Default::default();
                let t0 = Instant::now();
                for _ in 0..steps {
                    c.step()?;
                }
                let el = t0.elapsed().as_secs_f64();
                let t = c.timing;
                let tot = (t.lbm + t.dem + t.coupling).as_secs_f64();
                let share = [
                    t.lbm.as_secs_f64() / tot,
                    t.dem.as_secs_f64() / tot,
                    t.coupling.as_secs_f64() / tot,
                ];
                // Reference: the same grains, DEM only, the same number of DEM steps.
                let mut s = sys.clone();
                let mut st = Stepper::new();
                let (l, p) = (law(), c.params);
                st.step_law(&p, &l, &l, &mut s)?;
                let t1 = Instant::now();
                for _ in 0..steps * RATIO as usize {
                    st.step_law(&p, &l, &l, &mut s)?;
                }
                let dem_el = t1.elapsed().as_secs_f64();
                Ok((steps as f64 / el, share, steps as f64 / dem_el))
            })?;
            rates.push(rate);
            dem_only.push(dem_rate);
            shares.push(share);
        }
        let r = median(&rates);
        let d = median(&dem_only);
        let sh: Vec<f64> = (0..3)
            .map(|k| median(&shares.iter().map(|s| s[k]).collect::<Vec<_>>()))
            .collect();
        println!(
            "  {threads} thread(s): {r:.2} coupled steps/s ({:.0} DEM sub-steps/s); time: LBM {:.0} %, DEM {:.0} %, \
             coupling {:.0} %; DEM alone {d:.2} steps-of-100/s, ratio coupled/DEM-alone {:.2}; \
             {:.2} M grain-substeps/s",
            r * RATIO as f64,
            100.0 * sh[0],
            100.0 * sh[1],
            100.0 * sh[2],
            r / d,
            r * RATIO as f64 * grains as f64 * 1e-6
        );
        out.push(serde_json::json!({
            "grains": grains, "nodes": [nx, ny], "threads": threads, "coupled_steps_per_s": r, "dem_alone_steps_per_s": d,
            "share": { "lbm": sh[0], "dem": sh[1], "coupling": sh[2] }, "ratio_to_dem_alone": r / d,
        }));
    }
    Ok(out)
}
