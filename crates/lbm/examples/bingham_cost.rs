//! Development speed probe: the Bingham collision (Leonardi et al. 2014 Sect. 5.3) against the
//! Newtonian one on the same case, AA kernel, D2Q9 BGK f64, periodic, best of 5 × 50 steps each,
//! the two timed back to back so the ratio survives other load. Indicative only: the benchmark
//! proper is issue 20 item 5 (`lbdem bench`), with its peer in the same run.
//! `cargo run --release -p lbdem-lbm --example bingham_cost --features probes -- [NX NY]` (default 256 192)

use lbdem_lbm::bingham::Bingham;
use lbdem_lbm::{Collision, D2Q9, Domain, Face, Fluid, Limits, Settings, StepperAa};
use std::time::Instant;

fn mlups(n: [usize; 3], bingham: bool) -> Result<f64, Box<dyn std::error::Error>> {
    let dom = Domain::new(n, [Face::Periodic; 6]);
    let settings = Settings {
        collision: Collision::Bgk { tau: 0.65 },
        force: [1e-6, 0.0, 0.0],
        limits: Limits::default(),
    };
    let mut fl = Fluid::<D2Q9, f64>::new(dom, Vec::new());
    fl.init_equilibrium(|p| (1.0, [0.01 * (p[1] as f64 / 30.0).sin(), 0.0, 0.0]));
    let mut st = StepperAa::new(&mut fl, settings)?;
    if bingham {
        // A yield stress that leaves yielded and clamped nodes in this flow.
        st.set_bingham(Some(Bingham {
            mu_pl: 0.05,
            yield_stress: 2e-5,
            rho: 1.0,
            tau_min: 0.501,
            tau_max: 3.5,
            smagorinsky: 0.0,
        }))?;
    }
    let mut best = f64::INFINITY;
    for _ in 0..5 {
        let t0 = Instant::now();
        for _ in 0..50 {
            st.step(&mut fl, None)?;
        }
        best = best.min(t0.elapsed().as_secs_f64());
    }
    Ok((n[0] * n[1] * 50) as f64 / best / 1e6)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<usize> = std::env::args()
        .skip(1)
        .map(|s| s.parse())
        .collect::<Result<_, _>>()?;
    let n = match a.as_slice() {
        [] => [256, 192, 1],
        [nx, ny] => [*nx, *ny, 1],
        _ => return Err("usage: bingham_cost [NX NY]".into()),
    };
    let (newt, bing) = (mlups(n, false)?, mlups(n, true)?);
    println!(
        "{} x {}: Newtonian {newt:.0} MLUPS, Bingham {bing:.0} MLUPS, cost ratio {:.2} (indicative)",
        n[0],
        n[1],
        newt / bing
    );
    Ok(())
}
