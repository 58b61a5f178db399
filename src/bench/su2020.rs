//! `lbdem bench su2020 [--scene FILE]`: a Su et al. 2020 shear-cell case (default Simulation I,
//! `scenes/su2020/sim1.toml`; `--quick`: the reduced cell CI runs) for a few LBM steps: the wall
//! time per LBM step, per mean diameter of push-plate travel and to u_y = 10 d̄, beside the same
//! case's DEM alone (the same DEM steps, no liquid) and LBM alone (the same lattice and solid
//! zone, no grains), measured in the same run: the ratios say what each half costs. Each scene
//! runs on 1 and 2 threads, and the reduced cell runs beside any other scene as its second size
//! (issue 18 item 6).

use super::{BenchArgs, median};
use crate::scenes::models::{coupled, dry::Dry};
use crate::scenes::schema::load;
use crate::scenes::timeloop::Model;
use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// LBM steps per repetition (the DEM alone runs the same number of DEM steps).
const STEPS: usize = 20;

/// The figures of one scene at one thread count.
struct Measured {
    scene: String,
    threads: usize,
    grains: usize,
    lattice: [usize; 2],
    ratio: usize,
    /// Seconds per LBM step: coupled, DEM alone (`ratio` DEM steps), LBM alone.
    coupled: f64,
    dem: f64,
    lbm: f64,
    /// LBM steps per mean diameter of plate travel, and to the scene's stop (settling included).
    per_d: f64,
    to_stop: Option<(f64, f64)>,
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let reduced = root.join("scenes/su2020/reduced-shear-cell.toml");
    // Two sizes (the case and the reduced cell CI runs), so the cost growth with size is on
    // record beside the growth with threads (issue 18 item 6); `--quick`: the reduced cell only.
    let same = |p: &Path| std::fs::canonicalize(p).ok() == std::fs::canonicalize(&reduced).ok();
    let scenes: Vec<PathBuf> = match (&a.scene, a.quick) {
        (Some(p), false) if same(p) => vec![p.clone()],
        (Some(p), false) => vec![p.clone(), reduced],
        (Some(p), true) => vec![p.clone()],
        (None, true) => vec![reduced],
        (None, false) => vec![root.join("scenes/su2020/sim1.toml"), reduced],
    };
    let mut out = Vec::new();
    for scene in &scenes {
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
            let m = pool.install(|| measure(a, scene, threads))?;
            out.push(m);
        }
    }
    if let Some(j) = &a.json {
        let rows: Vec<_> = out
            .iter()
            .map(|m| {
                serde_json::json!({
                    "scene": m.scene, "threads": m.threads, "grains": m.grains, "lattice": m.lattice,
                    "ratio": m.ratio, "coupled_s_per_lbm_step": m.coupled, "dem_s": m.dem,
                    "lbm_s": m.lbm, "s_per_d": m.coupled * m.per_d, "s_to_10d": 10.0 * m.coupled * m.per_d,
                    "stop_m": m.to_stop.map(|t| t.0), "minutes_to_stop": m.to_stop.map(|t| t.1),
                })
            })
            .collect();
        std::fs::write(j, serde_json::to_string_pretty(&rows)?)
            .with_context(|| format!("cannot write {}", j.display()))?;
    }
    // The growth with size and threads, one line per scene.
    for pair in out.chunks(2) {
        if let [one, two] = pair {
            println!(
                "su2020 {}: 2 threads take {:.2} of 1 thread's time per LBM step (coupled), {:.2} (DEM alone), {:.2} (LBM alone)",
                one.scene,
                two.coupled / one.coupled,
                two.dem / one.dem,
                two.lbm / one.lbm
            );
        }
    }
    if let [a1, _, b1, _] = &out[..] {
        // Per grain and DEM step (the coupled step holds `ratio` of them) and per node of the
        // LBM alone: the figures that stay comparable between the sizes.
        let per_grain = |m: &Measured| m.coupled / (m.grains * m.ratio) as f64 * 1e9;
        let per_node = |m: &Measured| m.lbm / (m.lattice[0] * m.lattice[1]) as f64 * 1e9;
        println!(
            "su2020 size, 1 thread: {} ({} grains) {:.0} ns per grain and DEM step coupled, {:.1} ns per node LBM alone; \
             {} ({} grains) {:.0} and {:.1}",
            a1.scene,
            a1.grains,
            per_grain(a1),
            per_node(a1),
            b1.scene,
            b1.grains,
            per_grain(b1),
            per_node(b1)
        );
    }
    Ok(())
}

/// The coupled case, its DEM alone and its LBM alone on `threads` threads (the caller's pool).
fn measure(a: &BenchArgs, scene: &Path, threads: usize) -> Result<Measured> {
    let mut l = load(scene, &Default::default())?;
    l.scene.run.threads = threads;
    // The steps timed are the shear's: the plate moves from the first one. The settling is
    // counted in the time to the scene's stop, at the same cost per step (a settling to rest
    // at its longest: how long it takes only a run says).
    let settle = l.scene.shear_cell.as_mut().map_or(0.0, |c| {
        let t = std::mem::take(&mut c.settle);
        c.settle_until_rest.take().map_or(t, |r| r.max_time)
    });
    if l.scene.shear_cell.is_none() || l.scene.fluid.is_none() {
        bail!(
            "{}: bench su2020 needs a coupled shear-cell scene ([fluid] and [shear_cell])",
            scene.display()
        );
    }
    // A mass scale that follows the run is timed at its top rung, the scene's own ratio: where
    // the run spends its steps on the ladder only the whole run says.
    if let Some(d) = l.scene.dem.as_mut()
        && d.mass_scale_control.take().is_some()
        && threads == 1
    {
        println!(
            "su2020 {}: [dem.mass_scale_control] is off here: the figures are for the top of its ladder ([dem] \
             mass_scale = {}); the whole run (lbdem simulate) moves down it while the inertial number is high",
            l.name, d.mass_scale
        );
    }
    let steps = if a.quick { 5 } else { STEPS };
    let mut dry_scene = l.scene.clone();
    dry_scene.fluid = None;
    dry_scene.lattice = None;
    dry_scene.coupling = None;

    let (mut t_coupled, mut t_dem, mut t_lbm) = (Vec::new(), Vec::new(), Vec::new());
    // Inside the coupled step: solid map, solid zone, the rest of the coupling, PSM lattice
    // step, DEM sub-steps (per LBM step).
    let mut parts: Vec<[f64; 5]> = Vec::new();
    let mut info = None;
    for _ in 0..a.reps.max(1) {
        let mut m = coupled::build_f64(&l.scene, &l.base_dir).context("building the coupled case")?;
        let ratio = m.run.units.ratio as usize;
        // One step untimed: the first maps every grain afresh and checks the DEM step (the wall
        // contacts' stability, tenths of a second on 7000 grains), once per run.
        m.step(false)?;
        let before = m.run.timing;
        let t0 = Instant::now();
        for _ in 0..steps {
            m.step(false)?;
        }
        t_coupled.push(t0.elapsed().as_secs_f64() / steps as f64);
        let tm = m.run.timing;
        let per = |d: std::time::Duration, d0: std::time::Duration| (d - d0).as_secs_f64() / steps as f64;
        parts.push([
            per(tm.map, before.map),
            per(tm.zone, before.zone),
            per(
                tm.coupling - tm.map - tm.zone,
                before.coupling - before.map - before.zone,
            ),
            per(tm.lbm, before.lbm),
            per(tm.dem, before.dem),
        ]);
        let cell = m.shear_cell().context("the scene has no [shear_cell]")?;
        info = Some((
            m.run.sys.bodies.len(),
            m.lattice_size(),
            ratio,
            m.run.units.dt(),
            cell.cell.speed(),
            cell.cell.d_mean,
        ));

        // LBM alone: the same lattice and solid zone, no grains.
        let r_hd = m.run.r_hd;
        m.run.fluid.map(&[], &[], r_hd, [false; 2])?;
        let mut loads = Vec::new();
        m.run.fluid.step(&[], &mut loads)?;
        let t0 = Instant::now();
        for _ in 0..steps {
            m.run.fluid.step(&[], &mut loads)?;
        }
        t_lbm.push(t0.elapsed().as_secs_f64() / steps as f64);

        // DEM alone: the same grains and laws, `ratio` DEM steps per LBM step.
        let mut d = Dry::build(&dry_scene, &l.base_dir, false)?;
        d.step(false)?;
        let t0 = Instant::now();
        for _ in 0..steps * ratio {
            d.step(false)?;
        }
        t_dem.push(t0.elapsed().as_secs_f64() / steps as f64);
    }
    let Some((grains, n, ratio, dt, speed, d_mean)) = info else {
        bail!("no repetition ran")
    };
    let (c, dm, lb) = (median(&t_coupled), median(&t_dem), median(&t_lbm));
    // LBM steps per mean diameter of plate travel.
    let per_d = d_mean / (speed * dt);
    println!(
        "su2020 {}: {grains} grains, lattice {} x {}, {ratio} DEM steps per LBM step, d = {:.0} um, \
         plate {:.3e} m/s, {threads} threads",
        l.name,
        n[0],
        n[1],
        d_mean * 1e6,
        speed,
    );
    println!(
        "  coupled  {:9.3} ms per LBM step  {:9.1} s per d  {:9.1} min to 10 d",
        c * 1e3,
        c * per_d,
        10.0 * c * per_d / 60.0
    );
    // The scene's own stop may use another d̄ (the paper's Table 2, not the assembly's measured
    // one): the time to it, at the same rate per LBM step.
    let to_stop = l.scene.run.until_wall_moved.as_ref().map(|w| {
        let minutes = c * (w.distance / speed + settle) / dt / 60.0;
        println!(
            "  to the scene's stop, u_y = {:.3} mm, after {settle} s of settling: {minutes:.1} min",
            w.distance * 1e3,
        );
        (w.distance, minutes)
    });
    println!(
        "  DEM only {:9.3} ms per {ratio} DEM steps ({:.2} of coupled)",
        dm * 1e3,
        dm / c
    );
    println!(
        "  LBM only {:9.3} ms per LBM step ({:.2} of coupled)",
        lb * 1e3,
        lb / c
    );
    println!(
        "  coupling overhead (coupled − DEM − LBM): {:.3} ms per LBM step ({:.2} of coupled); median of {} reps",
        (c - dm - lb) * 1e3,
        (c - dm - lb) / c,
        a.reps.max(1)
    );
    let part = |k: usize| median(&parts.iter().map(|p| p[k]).collect::<Vec<_>>());
    println!(
        "  inside the coupled step (ms): solid map {:.3}, solid zone {:.3}, loads {:.3}, PSM lattice {:.3}, \
         DEM {:.3}",
        part(0) * 1e3,
        part(1) * 1e3,
        part(2) * 1e3,
        part(3) * 1e3,
        part(4) * 1e3
    );
    Ok(Measured {
        scene: l.name.clone(),
        threads,
        grains,
        lattice: n,
        ratio,
        coupled: c,
        dem: dm,
        lbm: lb,
        per_d,
        to_stop,
    })
}
