//! `coupled` scenes: grains and interstitial liquid, LBM-DEM by partially saturated cells (Su et
//! al. 2020 Fig. 2, Eqs. 9-14) or by moving bounce-back (Leonardi et al. 2014 Eqs. 19-21). The
//! file is a dry scene (particles, box, walls, contact law, DEM step) plus `[fluid]`,
//! `[lattice]`, `[coupling]` and `[run]`; the run writes the time series (CSV + JSON), the
//! liquid pressure change Δp of Eq. 19 as fields (VTK, PNG) and statistics, particle
//! snapshots, and the share of time spent in LBM, DEM and coupling. Format: docs/coupling.md.

mod config;

use super::SimContext;
use crate::report::plot::{Colormap, FieldPlot, Series, XyPlot, xy_png};
use crate::stages::{Figure, StageOutput, Table, field_figure};
use anyhow::{Context, Result, bail};
use config::CoupledScene;
use lbdem_core::atomic::write_atomic;
use lbdem_core::units::lattice::{LatticeInput, LatticeUnits, TimeSpec};
use lbdem_core::vtk::{Array, Values, write_pvd, write_vti};
use lbdem_coupling::bounce::BounceFluid;
use lbdem_coupling::units::CouplingUnits;
use lbdem_coupling::{Coupled, Hydro, Method, PsmFluid, PsmSettings};
use lbdem_lbm::{Domain, Face, Limits, Real};
use serde::Serialize;
use std::path::{Path, PathBuf};

/// One row of the time series (SI).
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub lbm_step: u64,
    pub time: f64,
    pub grain_kinetic_energy: f64,
    pub max_grain_speed: f64,
    pub contacts: usize,
    /// Mean liquid speed over the active nodes (m/s) and the largest Mach number (Su Eq. 16).
    pub mean_liquid_speed: f64,
    pub max_mach: f64,
    /// Δp statistics (Su Eq. 19): minimum, maximum, and the area where Δp < threshold (m²).
    pub dp_min: f64,
    pub dp_max: f64,
    pub area_below_threshold: f64,
    /// Sum of the hydrodynamic forces on the grains (N).
    pub hydro_force: [f64; 2],
    /// Total momentum of liquid and grains (kg m/s).
    pub momentum: [f64; 2],
}

pub fn run(scene: &toml::Value, ctx: &SimContext) -> Result<StageOutput> {
    let cfg: CoupledScene = scene
        .clone()
        .try_into()
        .context("coupled scene: the file does not match the coupled-scene format (see docs/coupling.md for every key)")?;
    match cfg.lattice.precision.as_str() {
        "f64" => run_with::<f64>(&cfg, ctx),
        "f32" => run_with::<f32>(&cfg, ctx),
        other => bail!("coupled scene [lattice] precision = \"{other}\": use \"f64\" (default) or \"f32\""),
    }
}

fn units(cfg: &CoupledScene) -> Result<CouplingUnits> {
    let f = &cfg.fluid;
    let nu = match (f.viscosity, f.dynamic_viscosity) {
        (Some(nu), None) => nu,
        (None, Some(mu)) => mu / f.density,
        _ => bail!(
            "coupled scene [fluid]: give exactly one of viscosity (kinematic, m²/s) or dynamic_viscosity (Pa s)"
        ),
    };
    let mut inp = LatticeInput::new(
        cfg.lattice.dx,
        nu,
        f.density,
        f.u_max,
        TimeSpec::Dt(cfg.lattice.dt),
    );
    inp.mach_warn = cfg.lattice.mach_warn;
    inp.mach_max = cfg.lattice.mach_max;
    let lat =
        LatticeUnits::derive(&inp).map_err(|e| anyhow::anyhow!("coupled scene [lattice]/[fluid]: {e}"))?;
    for w in &lat.warnings {
        eprintln!("coupled: warning: {w}");
    }
    CouplingUnits::new(lat, cfg.domain.lo, cfg.step.dt)
        .map_err(|e| anyhow::anyhow!("coupled scene [lattice] dt and [step] dt: {e}"))
}

/// Checks of the scene's own keys that no engine makes.
fn check(cfg: &CoupledScene) -> Result<()> {
    let r = &cfg.run;
    if r.steps == 0 || r.output_every == 0 {
        bail!(
            "coupled scene [run]: steps = {} and output_every = {} must both be at least 1",
            r.steps,
            r.output_every
        );
    }
    let depth = cfg.coupling.depth;
    if !(depth > 0.0 && depth.is_finite()) {
        bail!(
            "coupled scene [coupling] depth = {depth}: must be a positive length in m (the sample depth, default 1)"
        );
    }
    if let Some((k, _)) = cfg.walls.iter().enumerate().find(|(_, w)| w.velocity.is_some()) {
        bail!(
            "coupled scene [[walls]] #{k}: moving walls are not seen by the liquid yet (its walls are the \
             [domain] box faces, at rest); remove the velocity or use a dry scene"
        );
    }
    let ratio = 1.0 - cfg.fluid.density * depth / cfg.particles.density;
    if (cfg.step.gravity_factor - ratio).abs() > 1e-3 * ratio.abs().max(1e-3)
        && cfg.step.gravity != Default::default()
    {
        eprintln!(
            "coupled: note: [step] gravity_factor = {} but 1 - rho_L depth / density = {ratio:.4}; \
             the buoyancy of Su et al. Sect. 2.4 uses the latter",
            cfg.step.gravity_factor
        );
    }
    Ok(())
}

fn run_with<T: Real>(cfg: &CoupledScene, ctx: &SimContext) -> Result<StageOutput> {
    check(cfg)?;
    let units = units(cfg)?;
    let sys = crate::scenes::dry::config::build_system(
        &cfg.particles,
        &cfg.domain,
        &cfg.walls,
        cfg.bonds.as_ref(),
        cfg.membrane.as_ref(),
        &ctx.base_dir,
    )?;
    let dx = units.dx();
    let size = [
        cfg.domain.hi[0] - cfg.domain.lo[0],
        cfg.domain.hi[1] - cfg.domain.lo[1],
    ];
    let (nx, ny) = ((size[0] / dx).round() as usize, (size[1] / dx).round() as usize);
    for side in size {
        let n = (side / dx).round();
        if ((side / dx) - n).abs() > 1e-6 * n.max(1.0) {
            bail!(
                "coupled scene: the box side {side} m ([domain] lo..hi) is not a whole number of lattice spacings \
                 dx = {dx} m, so the lattice faces would not sit on the box; change [lattice] dx or [domain]"
            );
        }
    }
    if nx < 4 || ny < 4 {
        bail!("coupled scene: the lattice has {nx} x {ny} nodes; refine [lattice] dx");
    }
    let face = |p: bool| {
        if p {
            Face::Periodic
        } else {
            Face::Wall { velocity: [0.0; 3] }
        }
    };
    let per = cfg.domain.periodic;
    let domain = Domain::new(
        [nx, ny, 1],
        [
            face(per[0]),
            face(per[0]),
            face(per[1]),
            face(per[1]),
            Face::Periodic,
            Face::Periodic,
        ],
    );
    let tau = units.lattice.tau;
    let limits = Limits::default();
    let psm_only = |what: &str| {
        anyhow::anyhow!("[coupling] {what} is for method = \"psm\" only; remove it or set method = \"psm\"")
    };
    let hydro = match cfg.coupling.method {
        Method::Psm => {
            let mut fluid = PsmFluid::<T>::new(
                &domain,
                PsmSettings {
                    collision: lbdem_lbm::Collision::Bgk { tau },
                    force: [0.0; 2],
                    limits,
                },
            )?;
            if let Some(m) = cfg.coupling.trt_magic {
                fluid = fluid
                    .with_trt(m)
                    .map_err(|e| anyhow::anyhow!("[coupling] trt_magic: {e}"))?;
            }
            Hydro::psm(fluid)
        }
        Method::BounceBack => {
            if cfg.coupling.trt_magic.is_some() {
                return Err(psm_only("trt_magic"));
            }
            if cfg.coupling.interior_liquid_correction {
                return Err(psm_only("interior_liquid_correction"));
            }
            Hydro::BounceBack(Box::new(BounceFluid::<T>::new(domain, tau, [0.0; 2], limits)?))
        }
    };
    let law = cfg.contact.clone();
    let wall_law = cfg.wall_contact.clone().unwrap_or_else(|| law.clone());
    let mut run = Coupled::new(hydro, sys, law, wall_law, cfg.step, units, cfg.coupling.r_hd)
        .map_err(|e| anyhow::anyhow!("coupled scene: {e}"))?;
    run.depth = cfg.coupling.depth;
    if cfg.coupling.dry_membrane {
        for k in 0..run.sys.bodies.len() {
            run.dry[k] = run.sys.bodies.tag[k] == 1;
        }
    }
    if cfg.coupling.interior_liquid_correction {
        run = run
            .with_interior_liquid_correction()
            .map_err(|e| anyhow::anyhow!("[coupling] interior_liquid_correction = true: {e}"))?;
    }
    eprintln!(
        "coupled: {} grains, lattice {nx} x {ny} (dx = {dx:e} m, tau = {tau:.4}), LBM dt = {:e} s, \
         DEM dt = {:e} s, ratio {}, {:?}, {}",
        run.sys.bodies.len(),
        run.units.dt(),
        run.units.dt_dem,
        run.units.ratio,
        cfg.coupling.method,
        T::NAME
    );

    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(cfg.lattice.threads)
        .build()
        .context("cannot start the thread pool")?;
    std::fs::create_dir_all(ctx.out_dir.join("fields"))
        .with_context(|| format!("cannot create {}", ctx.out_dir.display()))?;
    let r = &cfg.run;
    let bar = indicatif::ProgressBar::new(r.steps);
    bar.set_style(
        indicatif::ProgressStyle::with_template("coupled {bar:40} {pos}/{len} LBM steps, {eta} left")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let mut rows = Vec::new();
    let mut fluid_snaps: Vec<(f64, String)> = Vec::new();
    let mut particle_snaps: Vec<(f64, String)> = Vec::new();
    let mut files: Vec<PathBuf> = Vec::new();
    let t0 = std::time::Instant::now();
    for s in 1..=r.steps {
        if let Err(e) = pool.install(|| run.step()) {
            // Nothing built on an unstable run stays behind.
            for f in &files {
                let _ = std::fs::remove_file(ctx.out_dir.join(f));
            }
            bail!("coupled scene: {e}; the run's snapshots were removed and no series or summary written");
        }
        if s % r.output_every == 0 || s == r.steps {
            rows.push(record(&run, s, r.pressure_threshold));
        }
        if (r.snapshot_every > 0 && s % r.snapshot_every == 0) || s == r.steps {
            let time = s as f64 * run.units.dt();
            let f = format!("fields/fluid_{s:08}.vti");
            write_fields(&ctx.out_dir.join(&f), &run)?;
            fluid_snaps.push((time, f.clone()));
            files.push(f.into());
            let p = format!("fields/particles_{s:08}.vtp");
            crate::scenes::dry::write_snapshot(&ctx.out_dir.join(&p), &run.sys)?;
            particle_snaps.push((time, p.clone()));
            files.push(p.into());
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let wall = t0.elapsed().as_secs_f64();
    write_pvd(&ctx.out_dir.join("fluid.pvd"), &fluid_snaps)?;
    write_pvd(&ctx.out_dir.join("particles.pvd"), &particle_snaps)?;
    files.extend(["fluid.pvd".into(), "particles.pvd".into()]);
    files.extend(write_series(&ctx.out_dir, &rows)?);

    let mut figures = Vec::new();
    let dp = pressure_si(&run);
    let field = ndarray::Array2::from_shape_fn((ny, nx), |(row, col)| dp[col + nx * (ny - 1 - row)]);
    field_figure(
        &ctx.out_dir,
        "pressure_change.png".into(),
        field.view(),
        &FieldPlot {
            title: "liquid pressure change (Su Eq. 19)",
            label: "Δp (Pa)",
            cmap: Colormap::Diverging,
            range: None,
            pixel_size: Some(dx),
        },
        format!(
            "Liquid pressure change Δp = (ρ − ρ₀)c_s² at the end of the run (t = {:.4e} s).",
            rows.last().map_or(0.0, |r: &Row| r.time)
        ),
        &mut figures,
        &mut files,
    )?;
    let t: Vec<f64> = rows.iter().map(|r| r.time).collect();
    let dpmin: Vec<f64> = rows.iter().map(|r| r.dp_min).collect();
    xy_png(
        &ctx.out_dir.join("pressure_min.png"),
        &[Series {
            label: "min Δp",
            x: &t,
            y: &dpmin,
            points: false,
        }],
        &XyPlot {
            title: "minimum liquid pressure change",
            x_label: "t (s)",
            y_label: "Δp (Pa)",
            log_x: false,
            log_y: false,
        },
    )?;
    figures.push(Figure {
        path: "pressure_min.png".into(),
        caption: "Minimum of the liquid pressure change over the run.".into(),
    });
    files.push("pressure_min.png".into());

    let tm = run.timing;
    let total = (tm.lbm + tm.dem + tm.coupling).as_secs_f64().max(1e-12);
    let summary = serde_json::json!({
        "lbm_steps": r.steps, "dem_steps_per_lbm_step": run.units.ratio, "grains": run.sys.bodies.len(),
        "lattice": [nx, ny], "tau": tau, "method": cfg.coupling.method, "precision": T::NAME,
        "wall_seconds": wall, "coupled_steps_per_second": r.steps as f64 / wall,
        "time_share": { "lbm": tm.lbm.as_secs_f64() / total, "dem": tm.dem.as_secs_f64() / total,
                        "coupling": tm.coupling.as_secs_f64() / total },
        "last": rows.last(),
    });
    write_atomic(
        &ctx.out_dir.join("summary.json"),
        &serde_json::to_vec_pretty(&summary)?,
    )?;
    files.push("summary.json".into());
    Ok(StageOutput {
        summary,
        figures,
        tables: vec![Table {
            path: "series.csv".into(),
            caption: "Coupled LBM-DEM time series".into(),
        }],
        files,
    })
}

fn pressure_si<T: Real>(run: &Coupled<T>) -> Vec<f64> {
    run.fluid
        .pressure_change()
        .into_iter()
        .map(|p| run.units.pressure_to_si(p))
        .collect()
}

fn record<T: Real>(run: &Coupled<T>, step: u64, threshold: f64) -> Row {
    let [nx, ny] = run.fluid.size();
    let u = &run.units;
    let vscale = u.dx() / u.dt();
    let (mut speed_sum, mut n_active, mut max_u) = (0.0, 0usize, 0.0f64);
    for i in 0..nx * ny {
        let (rho, v) = run.fluid.node(i);
        if rho.is_finite() {
            let s = (v[0] * v[0] + v[1] * v[1]).sqrt();
            speed_sum += s;
            max_u = max_u.max(s);
            n_active += 1;
        }
    }
    let dp = pressure_si(run);
    let (lo, hi) = crate::report::plot::finite_range(dp.iter().copied()).unwrap_or((0.0, 0.0));
    let below = dp.iter().filter(|&&p| p < threshold).count() as f64 * u.dx() * u.dx();
    let b = &run.sys.bodies;
    let hydro = run
        .hydro
        .iter()
        .fold([0.0; 2], |a, l| [a[0] + l.force[0], a[1] + l.force[1]]);
    Row {
        lbm_step: step,
        time: step as f64 * u.dt(),
        grain_kinetic_energy: b.kinetic_energy(),
        max_grain_speed: b.max_speed(),
        contacts: run.n_contacts(),
        mean_liquid_speed: speed_sum / n_active.max(1) as f64 * vscale,
        max_mach: max_u * 3f64.sqrt(),
        dp_min: lo,
        dp_max: hi,
        area_below_threshold: below,
        hydro_force: hydro,
        momentum: run.momentum(),
    }
}

fn write_series(dir: &Path, rows: &[Row]) -> Result<Vec<PathBuf>> {
    let mut csv = String::from(
        "lbm_step,time,grain_kinetic_energy,max_grain_speed,contacts,mean_liquid_speed,max_mach,dp_min,dp_max,\
         area_below_threshold,hydro_fx,hydro_fy,momentum_x,momentum_y\n",
    );
    for r in rows {
        csv.push_str(&format!(
            "{},{:e},{:e},{:e},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}\n",
            r.lbm_step,
            r.time,
            r.grain_kinetic_energy,
            r.max_grain_speed,
            r.contacts,
            r.mean_liquid_speed,
            r.max_mach,
            r.dp_min,
            r.dp_max,
            r.area_below_threshold,
            r.hydro_force[0],
            r.hydro_force[1],
            r.momentum[0],
            r.momentum[1]
        ));
    }
    write_atomic(&dir.join("series.csv"), csv.as_bytes())?;
    write_atomic(&dir.join("series.json"), &serde_json::to_vec_pretty(rows)?)?;
    Ok(vec!["series.csv".into(), "series.json".into()])
}

/// Liquid velocity (m/s), pressure change (Pa) and, for PSM, the solid fraction of each node.
fn write_fields<T: Real>(path: &Path, run: &Coupled<T>) -> Result<()> {
    let [nx, ny] = run.fluid.size();
    let u = &run.units;
    let vscale = u.dx() / u.dt();
    let mut vel = Vec::with_capacity(3 * nx * ny);
    for i in 0..nx * ny {
        let (_, v) = run.fluid.node(i);
        vel.extend([v[0] * vscale, v[1] * vscale, 0.0]);
    }
    let dp = pressure_si(run);
    let solid: Vec<f64> = match &run.fluid {
        Hydro::Psm { map, .. } => map.total.clone(),
        Hydro::BounceBack(b) => b.fluid.domain.kind.iter().map(|&k| f64::from(k != 0)).collect(),
    };
    let o = u.origin;
    write_vti(
        path,
        [nx, ny, 1],
        [o[0] + 0.5 * u.dx(), o[1] + 0.5 * u.dx(), 0.0],
        [u.dx(); 3],
        &[
            Array::vector("velocity", Values::F64(&vel)),
            Array::scalar("pressure_change", Values::F64(&dp)),
            Array::scalar("solid_fraction", Values::F64(&solid)),
        ],
    )
    .with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests;
