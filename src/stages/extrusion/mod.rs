//! Stage `extrusion` (`lbdem extrusion PARAMS.toml --out DIR`): Ness et al. (2017)'s analysis of
//! an extruder at steady state, from the sphere snapshots of one or more runs of the same case
//! (wall realisations: ensemble- and time-averaged, as Ness average). Binned coarse-graining
//! (bins d × d × depth; `lbdem_analysis::coarse`) of velocity, volume fraction and the Eq. 7
//! stress; the velocity gradients as Stokes numbers (Fig. 4), P, σ_xy and N_1 (Fig. 6), the
//! dissipation σ : γ̇ (Fig. 7), the static zones at the die entry (Fig. 5's count), the stress
//! ratio and φ across barrel and die (Fig. 8), and the pressure at four stations with the drops
//! of Fig. 9 and the wall stresses from the series. `extrusion-flow` puts several of these on
//! Fig. 9's axes and fits Benbow-Bridgwater.

mod figures;
pub mod flow;
mod run;

use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::report::table::write_csv;
use anyhow::{Context, Result, bail};
use lbdem_analysis::coarse::{BinGrid, BinSums, CoarseFields};
use run::{ExtruderRun, paste_particles};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::PathBuf;

/// The summary file other stages read (`extrusion-flow`).
pub const SUMMARY: &str = "extrusion.json";

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Runs of one case (earlier simulate stages by name, or output directories); fields are
    /// averaged over all of them.
    pub runs: Vec<String>,
    /// Label of the case in figures and in `extrusion-flow` (default: the first run's name).
    #[serde(default)]
    pub label: Option<String>,
    /// Start of the averaging window (s); default: each run's first steady time (mass balance),
    /// else the second half of the run.
    #[serde(default)]
    pub from: Option<f64>,
    /// Bin side in units of d, the smaller paste diameter (Ness: 1).
    #[serde(default = "d::one")]
    pub bin_d: f64,
    /// The four pressure stations P1-P4 as [x0, x1] windows in d from the ram face; default
    /// from the geometry (Ness's layout: P1 at 2.5-5 inlet lengths, P2 the quarter barrel width
    /// upstream of the entry region, P3 the first 1.25 die widths of the die, P4 its last).
    #[serde(default)]
    pub stations_d: Option<[[f64; 2]; 4]>,
    /// Static zone: bins slower than this fraction of the barrel's centreline speed (Ness: 0.25),
    /// counted within half a barrel width upstream of the die entry.
    #[serde(default = "d::quarter")]
    pub static_fraction: f64,
    /// Fewest snapshots (over all runs) an average may rest on.
    #[serde(default = "d::five")]
    pub min_snapshots: usize,
}

mod d {
    pub fn one() -> f64 {
        1.0
    }
    pub fn quarter() -> f64 {
        0.25
    }
    pub fn five() -> usize {
        5
    }
}

pub struct Extrusion;

impl Stage for Extrusion {
    const KIND: &'static str = "extrusion";
    const ABOUT: &'static str =
        "Ness et al. 2017 Figs. 3-8 and the station pressures of Fig. 9 from extruder runs";
    type Params = Params;
    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        p.runs
            .iter()
            .filter_map(|r| super::run_data::manifest_input(r, ctx))
            .collect()
    }
    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        analyse(p, ctx)
    }
}

/// Geometry in units of d, as the analysis uses it.
#[derive(Clone, Copy, Debug)]
pub struct Layout {
    pub d: f64,
    pub inlet: f64,
    pub barrel_length: f64,
    pub barrel_width: f64,
    pub die_width: f64,
    pub die_length: f64,
    pub depth: f64,
    /// One layer of grains (2D pressure; `Geometry::monolayer`).
    pub monolayer: bool,
}

impl Layout {
    fn of(r: &ExtruderRun) -> Self {
        let g = &r.spec.geometry;
        let d = r.spec.paste.range()[0];
        Self {
            d,
            inlet: g.inlet_length / d,
            barrel_length: g.barrel_length / d,
            barrel_width: g.barrel_width / d,
            die_width: g.die_width / d,
            die_length: g.die_length / d,
            depth: g.depth / d,
            monolayer: g.monolayer,
        }
    }

    fn end(&self) -> f64 {
        self.barrel_length + self.die_length
    }

    /// Where static zones are counted (m): the barrel's last half width before the die entry,
    /// across the barrel (Ness: "near the die entrance").
    pub fn static_window(&self) -> ([f64; 2], [f64; 2]) {
        let (d, x) = (self.d, self.barrel_length * self.d);
        let h = 0.5 * self.barrel_width * d;
        ([x - h, x], [-h, h])
    }

    /// Half the channel's width at x (d).
    pub fn half_width(&self, x: f64) -> f64 {
        0.5 * if x < self.barrel_length {
            self.barrel_width
        } else {
            self.die_width
        }
    }

    fn default_stations(&self) -> [[f64; 2]; 4] {
        let entry_region = self.barrel_length - 0.5 * self.barrel_width;
        [
            [2.5 * self.inlet, 5.0 * self.inlet],
            [entry_region - 0.25 * self.barrel_width, entry_region],
            [self.barrel_length, self.barrel_length + 1.25 * self.die_width],
            [self.end() - 1.25 * self.die_width, self.end()],
        ]
    }

    /// The stations, checked: inside the channel, in order, not overlapping, P1-P2 in the barrel
    /// and P3-P4 in the die.
    fn stations(&self, given: Option<[[f64; 2]; 4]>) -> Result<[[f64; 2]; 4]> {
        let s = given.unwrap_or_else(|| self.default_stations());
        let ok = s.iter().all(|w| w[1] > w[0] && w[0] >= 0.0)
            && s.windows(2).all(|p| p[0][1] <= p[1][0])
            && s[1][1] <= self.barrel_length
            && s[2][0] >= self.barrel_length
            && s[3][1] <= self.end() + 1e-9;
        if !ok {
            bail!(
                "parameter 'stations_d' = {s:?}{}: four increasing, non-overlapping [x0, x1] windows (in d) are \
                 needed, P1 and P2 in the barrel (x < {}), P3 and P4 in the die ({} to {}); give them as \
                 stations_d = [[a, b], [c, d], [e, f], [g, h]]",
                if given.is_none() {
                    " (the default for this geometry)"
                } else {
                    ""
                },
                self.barrel_length,
                self.barrel_length,
                self.end()
            );
        }
        Ok(s)
    }
}

/// What the stage measures from the fields and the series, all SI.
#[derive(Clone, Debug, Serialize)]
pub struct Measured {
    pub label: String,
    pub runs: usize,
    pub snapshots: usize,
    pub window_from: Vec<f64>,
    pub die_velocity: f64,
    pub barrel_velocity: f64,
    /// Mean speed of the barrel's centreline bins between P1 and P2 (Ness's V^barrel).
    pub centreline_velocity: f64,
    pub stations_d: [[f64; 2]; 4],
    /// P at P1-P4 (Pa), and its hydrodynamic part.
    pub station_pressure: [f64; 4],
    pub station_pressure_hydro: [f64; 4],
    /// P1 − P4, P1 − P2, P2 − P3, P3 − P4 (Pa): Fig. 9a-d.
    pub dp_total: f64,
    pub dp_barrel: f64,
    pub dp_entry: f64,
    pub dp_die: f64,
    /// Wall shear stress (Pa): the paste's x-load on the barrel's and the die's side walls over
    /// their area (Fig. 9e-f).
    pub wall_stress_barrel: f64,
    pub wall_stress_die: f64,
    /// Grains in the static zones (Fig. 5), bins below `static_fraction` of the centreline speed.
    pub static_grains: f64,
    /// The static zones' area (d²: static bins × bin area), comparable between the slab and a
    /// monolayer where grain counts are not.
    pub static_area: f64,
    pub static_fraction: f64,
    /// Largest |St| of the four gradients over the channel (Fig. 4: ≪ 1).
    pub max_stokes: f64,
    /// Contact share of the pressure over the channel: Σ P_contact / Σ P.
    pub contact_pressure_share: f64,
    /// The kinetic pressure over the Eq. 7 pressure, summed over the channel: how far from
    /// Ness's inertia-free regime the run is.
    pub kinetic_pressure_ratio: f64,
    /// Momentum balance downstream of P1: the axial force through the barrel there, mean σ_xx
    /// at P1 × W_b × depth (N), against the paste's x-load on every wall downstream (barrel,
    /// entry faces, die; from the series, N). Equal at steady state up to the barrel walls' load
    /// upstream of P1; an independent check of the Eq. 7 stress.
    pub axial_force_p1: f64,
    pub wall_load_x: f64,
    /// Volume flux per depth ∫ φ v_x dy (m²/s) at each station: the same at steady state.
    pub station_flux: [f64; 4],
    pub geometry: serde_json::Value,
}

fn analyse(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
    if p.runs.is_empty() {
        bail!("parameter 'runs' is empty: name at least one extruder run");
    }
    if !(p.bin_d > 0.0 && p.bin_d.is_finite() && p.static_fraction > 0.0 && p.static_fraction < 1.0) {
        bail!(
            "parameters bin_d = {} and static_fraction = {}: bin_d must be a positive number of diameters (Ness: \
             1) and static_fraction in (0, 1) (Ness: 0.25)",
            p.bin_d,
            p.static_fraction
        );
    }
    let runs: Vec<ExtruderRun> = p
        .runs
        .iter()
        .map(|r| {
            let dir = super::run_data::locate(r, ctx);
            ExtruderRun::open(&dir).with_context(|| format!("extrusion: run '{r}'"))
        })
        .collect::<Result<_>>()?;
    let lay = Layout::of(&runs[0]);
    for r in &runs[1..] {
        let (a, b) = (&runs[0].spec, &r.spec);
        let mut g = b.geometry;
        g.wall_seed = a.geometry.wall_seed;
        let mut drive = b.drive;
        drive.seed = a.drive.seed;
        let differs = [
            ("geometry (beyond the wall seed)", g != a.geometry),
            ("paste", b.paste != a.paste),
            ("drive (body force, inlet)", drive != a.drive),
            ("contact and lubrication law", r.law != runs[0].law),
        ];
        if let Some((what, _)) = differs.iter().find(|d| d.1) {
            bail!(
                "runs {} and {} are not one case: their {what} differ; analyse each case on its own (only the wall \
                 and insertion seeds may differ between the runs averaged)",
                runs[0].dir.display(),
                r.dir.display()
            );
        }
    }
    let stations = lay.stations(p.stations_d)?;
    let d = lay.d;
    let grid = BinGrid::covering(
        [0.0, lay.end() * d],
        [-0.5 * lay.barrel_width * d, 0.5 * lay.barrel_width * d],
        p.bin_d * d,
        lay.depth * d,
    )?
    .in_plane(lay.monolayer);
    let mut sums = BinSums::new(grid);
    let mut from = Vec::new();
    let chosen: Vec<(usize, PathBuf)> = runs
        .iter()
        .enumerate()
        .flat_map(|(i, r)| {
            let t0 = r.window_start(p.from);
            from.push(t0);
            r.snapshots
                .iter()
                .filter(move |(t, _)| *t >= t0)
                .map(move |(_, f)| (i, f.clone()))
        })
        .collect();
    for (i, r) in runs.iter().enumerate() {
        if !chosen.iter().any(|(k, _)| *k == i) {
            bail!(
                "run {} has no sphere snapshot at or after t = {:e} s (its snapshots: {}): give an earlier 'from' or \
                 write more snapshots ([output] snapshots)",
                r.dir.display(),
                from[i],
                r.snapshots.len()
            );
        }
    }
    if chosen.len() < p.min_snapshots {
        bail!(
            "only {} sphere snapshot(s) at or after the window's start (from = {:?} s): an average needs \
             min_snapshots = {}; give an earlier 'from', write snapshots more often ([output] snapshots), or run \
             longer past the steady state (stop_when_steady = false)",
            chosen.len(),
            from,
            p.min_snapshots
        );
    }
    let bar = ctx.progress_bar(chosen.len() as u64, "snapshots");
    for (_, f) in &chosen {
        sums.add_snapshot(&paste_particles(f)?)
            .with_context(|| format!("binning {}", f.display()))?;
        bar.inc(1);
    }
    bar.finish_and_clear();
    let fields = sums
        .fields(runs[0].spec.paste.density)
        .context("no snapshot was binned")?;
    let measured = measure(p, &runs, &from, &lay, stations, &fields)?;
    let out = &ctx.out_dir;
    let mut tables = Vec::new();
    let mut files = Vec::new();
    let grad = fields.gradient();
    write_fields(&out.join("fields.csv"), &fields, &grad, &lay, &runs[0])?;
    tables.push(Table {
        path: "fields.csv".into(),
        caption:
            "Time- and ensemble-averaged bins (x, y in d): count, φ, velocity, gradients, stress, dissipation"
                .into(),
    });
    let names = ["P1", "P2", "P3", "P4"];
    let st_x0: Vec<f64> = stations.iter().map(|s| s[0]).collect();
    let st_x1: Vec<f64> = stations.iter().map(|s| s[1]).collect();
    write_csv(
        &out.join("stations.csv"),
        &[
            ("station", &[1.0, 2.0, 3.0, 4.0]),
            ("x0_d", &st_x0),
            ("x1_d", &st_x1),
            ("pressure", &measured.station_pressure),
            ("pressure_hydro", &measured.station_pressure_hydro),
        ],
    )?;
    tables.push(Table {
        path: "stations.csv".into(),
        caption: format!(
            "Pressure (Pa) at the stations {} (windows in d, mean over the channel's bins)",
            names.join(", ")
        ),
    });
    let figs = figures::draw(out, &fields, &grad, &lay, &measured, &runs[0])?;
    let figures: Vec<Figure> = figs;
    files.extend(figures.iter().map(|f| f.path.clone()));
    files.extend(tables.iter().map(|t| t.path.clone()));
    let summary = serde_json::to_value(&measured)?;
    std::fs::write(out.join(SUMMARY), serde_json::to_string_pretty(&summary)?)
        .with_context(|| format!("cannot write {}", out.join(SUMMARY).display()))?;
    files.push(SUMMARY.into());
    Ok(StageOutput {
        summary,
        figures,
        tables,
        files,
    })
}

fn measure(
    p: &Params,
    runs: &[ExtruderRun],
    from: &[f64],
    lay: &Layout,
    stations: [[f64; 2]; 4],
    f: &CoarseFields,
) -> Result<Measured> {
    let d = lay.d;
    let series = |name: &str| -> Result<f64> {
        let v: Vec<f64> = runs
            .iter()
            .zip(from)
            .map(|(r, &t)| r.series_mean(name, t))
            .collect::<Result<_>>()?;
        Ok(v.iter().sum::<f64>() / v.len() as f64)
    };
    let pressure = f.pressure(false);
    let hydro = f.pressure(true);
    let mut sp = [0.0; 4];
    let mut sh = [0.0; 4];
    for (k, w) in stations.iter().enumerate() {
        let hw = lay.half_width(0.5 * (w[0] + w[1])) * d;
        let x = [w[0] * d, w[1] * d];
        let (m, n) = f.mean_over(&pressure, x, [-hw, hw]);
        if n == 0 {
            bail!(
                "station P{} ({:?} d) holds no occupied bin: no grain passed there in the window; move it \
                 ('stations_d') or average over a later window",
                k + 1,
                w
            );
        }
        sp[k] = m;
        sh[k] = f.mean_over(&hydro, x, [-hw, hw]).0;
    }
    let speed = f.speed();
    let half_bin = 0.5 * f.grid.size;
    let (v_centre, n_centre) = f.mean_over(
        &speed,
        [stations[0][0] * d, stations[1][1] * d],
        [-half_bin - 1e-12 * d, half_bin + 1e-12 * d],
    );
    if n_centre == 0 {
        bail!(
            "no occupied bin on the barrel's centreline between P1 ({:?} d) and P2 ({:?} d): the barrel is empty in \
             the averaging window; give a later 'from', or move the stations ('stations_d')",
            stations[0],
            stations[1]
        );
    }
    let (zx, zy) = lay.static_window();
    let (zone, static_grains) = f.static_zone(v_centre, p.static_fraction, zx, zy);
    let static_area = zone.iter().filter(|&&z| z).count() as f64 * p.bin_d * p.bin_d;
    let scale = runs[0].stokes_scale();
    let grad = f.gradient();
    let max_stokes = grad
        .iter()
        .flatten()
        .flat_map(|g| g.iter())
        .filter(|v| v.is_finite())
        .fold(0.0, |m: f64, v| m.max(v.abs() * scale));
    let (ptot, pcontact) = pressure
        .iter()
        .zip(hydro.iter())
        .filter(|(a, b)| a.is_finite() && b.is_finite())
        .fold((0.0, 0.0), |(t, c), (a, b)| (t + a, c + a - b));
    let area = |len: f64| 2.0 * len * d * lay.depth * d;
    let p1 = [stations[0][0] * d, stations[0][1] * d];
    let hb = 0.5 * lay.barrel_width * d;
    let axial_force_p1 = f.mean_over(&f.sigma[0], p1, [-hb, hb]).0 * lay.barrel_width * d * lay.depth * d;
    let wall_load_x = series("wall_fx_barrel")? + series("wall_fx_entry")? + series("wall_fx_die")?;
    let station_flux = stations.map(|w| f.flux_x([w[0] * d, w[1] * d]));
    Ok(Measured {
        label: p.label.clone().unwrap_or_else(|| p.runs[0].clone()),
        runs: runs.len(),
        snapshots: f.snapshots,
        window_from: from.to_vec(),
        die_velocity: series("die_velocity")?,
        barrel_velocity: series("barrel_velocity")?,
        centreline_velocity: v_centre,
        stations_d: stations,
        station_pressure: sp,
        station_pressure_hydro: sh,
        dp_total: sp[0] - sp[3],
        dp_barrel: sp[0] - sp[1],
        dp_entry: sp[1] - sp[2],
        dp_die: sp[2] - sp[3],
        wall_stress_barrel: series("wall_fx_barrel")? / area(lay.barrel_length),
        wall_stress_die: series("wall_fx_die")? / area(lay.die_length),
        static_grains,
        static_area,
        static_fraction: p.static_fraction,
        max_stokes,
        contact_pressure_share: pcontact / ptot,
        kinetic_pressure_ratio: f
            .kinetic_pressure()
            .iter()
            .zip(pressure.iter())
            .filter(|(k, p)| k.is_finite() && p.is_finite())
            .map(|(k, _)| k)
            .sum::<f64>()
            / ptot,
        axial_force_p1,
        wall_load_x,
        station_flux,
        geometry: json!({
            "d": d, "inlet_d": lay.inlet, "barrel_length_d": lay.barrel_length, "barrel_width_d": lay.barrel_width,
            "die_width_d": lay.die_width, "die_length_d": lay.die_length, "depth_d": lay.depth, "monolayer": lay.monolayer,
            "density": runs[0].spec.paste.density, "viscosity": runs[0].viscosity,
        }),
    })
}

/// One row per bin: centre (d), count, φ, velocity (m/s), gradients (1/s), stress (Pa) and
/// dissipation (W/m³), NaN where no grain was.
fn write_fields(
    path: &std::path::Path,
    f: &CoarseFields,
    g: &lbdem_analysis::coarse::Gradient,
    lay: &Layout,
    run: &ExtruderRun,
) -> Result<()> {
    let (ny, nx) = (f.grid.ny, f.grid.nx);
    let mut cols: Vec<(&str, Vec<f64>)> = Vec::new();
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for iy in 0..ny {
        for ix in 0..nx {
            let (cx, cy) = f.grid.centre(ix, iy);
            x.push(cx / lay.d);
            y.push(cy / lay.d);
        }
    }
    let flat = |a: &ndarray::Array2<f64>| a.iter().copied().collect::<Vec<f64>>();
    let st = run.stokes_scale();
    let stokes = |a: &ndarray::Array2<f64>| a.iter().map(|v| v * st).collect::<Vec<f64>>();
    cols.push(("x_d", x));
    cols.push(("y_d", y));
    cols.push(("count", flat(&f.count)));
    cols.push(("phi", flat(&f.phi)));
    cols.push(("vx", flat(&f.vel[0])));
    cols.push(("vy", flat(&f.vel[1])));
    cols.push(("vz", flat(&f.vel[2])));
    cols.push(("speed", flat(&f.speed())));
    cols.push(("dvx_dx", flat(&g[0][0])));
    cols.push(("dvx_dy", flat(&g[0][1])));
    cols.push(("dvy_dx", flat(&g[1][0])));
    cols.push(("dvy_dy", flat(&g[1][1])));
    cols.push(("st_xx", stokes(&g[0][0])));
    cols.push(("st_xy", stokes(&g[0][1])));
    cols.push(("st_yx", stokes(&g[1][0])));
    cols.push(("st_yy", stokes(&g[1][1])));
    for (name, c) in [("sxx", 0), ("sxy", 1), ("syx", 3), ("syy", 4), ("szz", 8)] {
        cols.push((name, flat(&f.sigma[c])));
    }
    cols.push(("pressure", flat(&f.pressure(false))));
    cols.push(("pressure_hydro", flat(&f.pressure(true))));
    cols.push(("pressure_kinetic", flat(&f.kinetic_pressure())));
    cols.push(("n1", flat(&f.n1())));
    cols.push(("dissipation", flat(&f.dissipation(g))));
    let refs: Vec<(&str, &[f64])> = cols.iter().map(|(n, v)| (*n, v.as_slice())).collect();
    write_csv(path, &refs)
}
