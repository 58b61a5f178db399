//! `lbdem bench free-surface`: the D3Q19 free-surface step (Leonardi et al. 2014 Sect. 5.2; issue
//! 20 item 5) in MLUPS beside the plain D3Q19 AA kernel on the same box in the same run, with the
//! cost of the free surface and of the Bingham local τ each as a ratio; two box sizes, one and two
//! threads. The free-surface case is a 3D dam break (a column a × 2a against one wall, a a quarter
//! of the box's length or less to stay below the lid; periodic in z) after 100 steps of collapse, so liquid, interface and gas nodes all
//! change while it is timed. MLUPS count every node of the box, as the plain kernel's do. With
//! `--peer`, lbmpy's fastest D3Q19 kernel (AA in place, f64, BGK on a periodic box of the same
//! size: `scripts/peer-lbmpy.sh` installs it) runs after each size and thread count, and the
//! plain and free-surface rates are printed over it.

use super::{BenchArgs, median};
use anyhow::Result;
use lbdem_lbm::free_surface::cases::dam_break_3d;
use lbdem_lbm::{Bingham, Collision, D3Q19, Domain, Fluid, Limits, Settings, StepperAa};
use std::time::Instant;

/// The Bingham paste the costed runs use (lattice units): yielded near the front, clamped in the
/// still column, so both branches of the local τ run.
const BINGHAM: Bingham = Bingham {
    mu_pl: 0.05,
    yield_stress: 1e-6,
    rho: 1.0,
    tau_min: 0.501,
    tau_max: 3.5,
    smagorinsky: 0.0,
};

fn collision() -> Collision {
    Collision::Trt {
        tau: 0.65,
        magic: 0.25,
    }
}

/// MLUPS of `steps` free-surface steps on the box `n` after `warm` steps of collapse.
fn free_surface(n: [usize; 3], bingham: bool, warm: usize, steps: usize) -> Result<(f64, f64)> {
    // A column a quarter of the box long, 2a high, below the lid.
    let a = (n[0] / 4).min(n[1] / 2 - 2);
    let (mut s, mut st) = dam_break_3d(a, n, 1e-4, collision())?;
    if bingham {
        st.set_bingham(Some(BINGHAM))?;
    }
    for _ in 0..warm {
        st.step(&mut s)?;
    }
    let t = Instant::now();
    for _ in 0..steps {
        st.step(&mut s)?;
    }
    let mlups = (s.nodes() * steps) as f64 / t.elapsed().as_secs_f64() / 1e6;
    let wet = s
        .cell
        .iter()
        .filter(|&&c| c == lbdem_lbm::free_surface::LIQUID || c == lbdem_lbm::free_surface::INTERFACE)
        .count();
    Ok((mlups, wet as f64 / s.nodes() as f64))
}

/// MLUPS of the plain D3Q19 AA kernel (same collision, periodic box of the same size).
fn plain(n: [usize; 3], steps: usize) -> Result<f64> {
    let settings = Settings {
        collision: collision(),
        force: [0.0; 3],
        limits: Limits::default(),
    };
    let mut fl = Fluid::<D3Q19, f64>::new(Domain::periodic(n), Vec::new());
    fl.init_equilibrium(|p| {
        (
            1.0 + 1e-4 * ((p[0] * 7 + p[1] * 13 + p[2] * 5) % 17) as f64 / 17.0,
            [0.0; 3],
        )
    });
    let mut st = StepperAa::new(&mut fl, settings)?;
    st.step(&mut fl, None)?;
    let t = Instant::now();
    for _ in 0..steps {
        st.step(&mut fl, None)?;
    }
    Ok((n[0] * n[1] * n[2] * steps) as f64 / t.elapsed().as_secs_f64() / 1e6)
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let sizes: &[[usize; 3]] = if a.quick {
        &[[48, 32, 8]]
    } else {
        &[[96, 64, 32], [192, 64, 32]]
    };
    let steps = if a.quick { 4 } else { 20 };
    println!(
        "D3Q19 free surface (3D dam break, TRT tau 0.65) against the plain D3Q19 AA kernel, f64, median of {} reps",
        a.reps
    );
    println!(
        "{:>14} {:>7} {:>10} {:>10} {:>10} {:>8} {:>8} {:>8}{}",
        "box",
        "threads",
        "plain",
        "free surf",
        "+ Bingham",
        "FS/plain",
        "Bingham",
        "wet",
        if a.peer {
            "      lbmpy plain/lbmpy FS/lbmpy"
        } else {
            ""
        }
    );
    for &n in sizes {
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
            let (mut p, mut f, mut b, mut wet) = (Vec::new(), Vec::new(), Vec::new(), 0.0);
            for _ in 0..a.reps {
                // Back to back in each repetition, so the ratios survive the machine's drift.
                let (pl, (fs, w), (fb, _)) = pool.install(|| -> Result<_> {
                    Ok((
                        plain(n, steps)?,
                        free_surface(n, false, 100, steps)?,
                        free_surface(n, true, 100, steps)?,
                    ))
                })?;
                p.push(pl);
                f.push(fs);
                b.push(fb);
                wet = w;
            }
            let (pm, fm, bm) = (median(&p), median(&f), median(&b));
            // The peer right after, on the same box and threads (its own median of blocks).
            let peer = if a.peer {
                match super::lbm::lbmpy("D3Q19", n, "f64", threads) {
                    Some(l) => format!(" {:>10.1} {:>11.3} {:>8.3}", l, pm / l, fm / l),
                    None => "      lbmpy could not run (see above)".into(),
                }
            } else {
                String::new()
            };
            println!(
                "{:>14} {:>7} {:>10.1} {:>10.1} {:>10.1} {:>8.3} {:>8.3} {:>8.2}{peer}",
                format!("{}x{}x{}", n[0], n[1], n[2]),
                threads,
                pm,
                fm,
                bm,
                fm / pm,
                bm / fm,
                wet
            );
        }
    }
    println!(
        "MLUPS over every node of the box; FS/plain: the free surface's rate over the plain kernel's; Bingham: \
         with the local tau over without; wet: liquid and interface share of the box when timed."
    );
    if a.peer {
        println!(
            "lbmpy: its fastest D3Q19 kernel (AA in place, f64) with BGK (SRT) on a periodic box of the same size, \
             run right after ours; the plain and free-surface kernels here run TRT (more arithmetic than BGK)."
        );
    } else {
        println!("peer (lbmpy D3Q19): add --peer (scripts/peer-lbmpy.sh installs lbmpy)");
    }
    Ok(())
}
