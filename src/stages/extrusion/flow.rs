//! Stage `extrusion-flow` (`lbdem extrusion-flow PARAMS.toml --out DIR`): Ness et al. (2017)
//! Figs. 5 and 9 and the Benbow-Bridgwater fit of Eq. 1 from the `extrusion` analyses of a
//! sweep's cases (or of named analyses): ΔP (total, barrel, die entry, die) and the wall
//! stresses against the die velocity on log axes, one series per value of an axis (cases A-F),
//! the power of ΔP in V with its standard error (Ness: a gradient of unity), and per series the
//! four-parameter fit (σ_0, α, τ_0, β) and the two-parameter one (α, β).

use super::SUMMARY;
use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::report::lines::{Line, LinesPlot, Style, lines_png};
use crate::report::table::{Col, write_table};
use anyhow::{Context, Result, bail};
use lbdem_analysis::benbow::{self, LineFit};
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// A sweep's output directory: every case's `<stage>/extrusion.json` is a point.
    #[serde(default)]
    pub sweep: Option<String>,
    /// The stage of the sweep's pipeline that ran `extrusion`.
    #[serde(default = "d::stage")]
    pub stage: String,
    /// The sweep axis whose values name the series (e.g. "ness_case"); default: one series.
    #[serde(default)]
    pub series: Option<String>,
    /// More analyses (earlier `extrusion` stages or their directories), each a point of the
    /// series named by its label.
    #[serde(default)]
    pub analyses: Vec<String>,
    #[serde(default = "d::title")]
    pub title: String,
}

mod d {
    pub fn stage() -> String {
        "cg".into()
    }
    pub fn title() -> String {
        "Pressure drops against die velocity (Ness et al. 2017 Fig. 9)".into()
    }
}

pub struct ExtrusionFlow;

impl Stage for ExtrusionFlow {
    const KIND: &'static str = "extrusion-flow";
    const ABOUT: &'static str =
        "Ness et al. 2017 Figs. 5 and 9 and the Benbow-Bridgwater fit from extrusion analyses";
    type Params = Params;
    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        let mut v: Vec<PathBuf> = p
            .analyses
            .iter()
            .map(|a| super::super::run_data::locate(a, ctx).join(SUMMARY))
            .filter(|f| f.is_file())
            .collect();
        if let Some(s) = &p.sweep {
            v.extend(
                sweep_points(&ctx.resolve(Path::new(s)), &p.stage)
                    .into_iter()
                    .map(|c| c.1),
            );
        }
        v
    }
    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        flow(p, ctx)
    }
}

/// (case directory, its analysis file) for every case of the sweep in `dir` whose analysis
/// exists, in directory order.
fn sweep_points(dir: &Path, stage: &str) -> Vec<(PathBuf, PathBuf)> {
    let mut v: Vec<(PathBuf, PathBuf)> = std::fs::read_dir(dir.join("cases"))
        .into_iter()
        .flatten()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .map(|c| {
            let a = c.join(stage).join(SUMMARY);
            (c, a)
        })
        .filter(|(_, a)| a.is_file())
        .collect();
    v.sort();
    v
}

/// One analysed case.
struct Point {
    series: String,
    a: Value,
}

const MEASURES: [(&str, &str, &str); 6] = [
    ("dp_total", "ΔP total, P1 − P4 (Fig. 9a)", "fig9a_total.png"),
    ("dp_barrel", "ΔP barrel, P1 − P2 (Fig. 9b)", "fig9b_barrel.png"),
    ("dp_entry", "ΔP die entry, P2 − P3 (Fig. 9c)", "fig9c_entry.png"),
    ("dp_die", "ΔP die, P3 − P4 (Fig. 9d)", "fig9d_die.png"),
    (
        "wall_stress_barrel",
        "Wall stress, barrel (Fig. 9e)",
        "fig9e_wall_barrel.png",
    ),
    (
        "wall_stress_die",
        "Wall stress, die (Fig. 9f)",
        "fig9f_wall_die.png",
    ),
];

fn read_json(path: &Path) -> Result<Value> {
    serde_json::from_str(
        &std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?,
    )
    .with_context(|| format!("{} is not JSON", path.display()))
}

/// An `extrusion` stage's summary, refused if it lacks what the figures read.
fn read_analysis(path: &Path) -> Result<Value> {
    let v = read_json(path)?;
    if let Some(k) = ["die_velocity", "dp_total", "dp_entry", "dp_die", "geometry"]
        .into_iter()
        .find(|k| v.get(k).is_none())
    {
        bail!(
            "{} is not an extrusion analysis: it has no '{k}' (give the output of an `extrusion` stage)",
            path.display()
        );
    }
    Ok(v)
}

fn points(p: &Params, ctx: &StageContext) -> Result<Vec<Point>> {
    let mut pts = Vec::new();
    if let Some(s) = &p.sweep {
        let dir = ctx.resolve(Path::new(s));
        let found = sweep_points(&dir, &p.stage);
        if found.is_empty() {
            bail!(
                "sweep {}: no case has {}/{SUMMARY} (is it a sweep over a pipeline whose stage '{}' runs \
                 `extrusion`? give the stage's name as 'stage')",
                dir.display(),
                p.stage,
                p.stage
            );
        }
        for (case, file) in found {
            let series = match &p.series {
                None => String::from("all"),
                Some(axis) => {
                    let c = read_json(&case.join("case.json"))?;
                    let v = c["axes"]
                        .as_array()
                        .and_then(|a| a.iter().find(|e| e[0].as_str() == Some(axis)))
                        .map(|e| e[1].clone())
                        .with_context(|| {
                            format!("{}: no axis '{axis}' (parameter 'series')", case.display())
                        })?;
                    v.as_str().map_or_else(|| v.to_string(), String::from)
                }
            };
            pts.push(Point {
                series,
                a: read_analysis(&file)?,
            });
        }
    }
    for a in &p.analyses {
        let v = read_analysis(&super::super::run_data::locate(a, ctx).join(SUMMARY))?;
        pts.push(Point {
            series: v["label"].as_str().unwrap_or(a).to_string(),
            a: v,
        });
    }
    if pts.is_empty() {
        bail!("nothing to draw: give 'sweep' or 'analyses'");
    }
    Ok(pts)
}

fn num(v: &Value, k: &str) -> f64 {
    v[k].as_f64().unwrap_or(f64::NAN)
}

fn fit_json(f: &LineFit) -> Value {
    json!({"intercept": f.intercept, "intercept_se": f.intercept_se, "slope": f.slope, "slope_se": f.slope_se, "points": f.points})
}

fn flow(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
    let pts = points(p, ctx)?;
    let mut by: BTreeMap<&str, Vec<&Point>> = BTreeMap::new();
    for q in &pts {
        by.entry(q.series.as_str()).or_default().push(q);
    }
    let out = &ctx.out_dir;
    // The table of points.
    let series: Vec<String> = pts.iter().map(|q| q.series.clone()).collect();
    let mut cols: Vec<(&str, Vec<f64>)> = vec![(
        "die_velocity",
        pts.iter().map(|q| num(&q.a, "die_velocity")).collect(),
    )];
    for (k, _, _) in MEASURES {
        cols.push((k, pts.iter().map(|q| num(&q.a, k)).collect()));
    }
    for k in [
        "static_grains",
        "static_area",
        "max_stokes",
        "contact_pressure_share",
        "kinetic_pressure_ratio",
    ] {
        cols.push((k, pts.iter().map(|q| num(&q.a, k)).collect()));
    }
    let mut table: Vec<(&str, Col)> = vec![("series", Col::Str(&series))];
    table.extend(cols.iter().map(|(n, v)| (*n, Col::F64(v))));
    write_table(&out.join("flow.csv"), &table)?;
    // Fits per series.
    let mut fits = serde_json::Map::new();
    let (mut f_series, mut f_cols): (Vec<String>, Vec<[f64; 10]>) = (Vec::new(), Vec::new());
    for (name, qs) in &by {
        let v: Vec<f64> = qs.iter().map(|q| num(&q.a, "die_velocity")).collect();
        let get = |k: &str| qs.iter().map(|q| num(&q.a, k)).collect::<Vec<f64>>();
        let g = &qs[0].a["geometry"];
        let (l, w) = benbow::geometry_factors(
            num(g, "barrel_width_d"),
            num(g, "die_width_d"),
            num(g, "die_length_d"),
        );
        if v.len() < 2 {
            fits.insert(
                name.to_string(),
                json!({"points": v.len(), "note": "one point: nothing to fit"}),
            );
            continue;
        }
        let slope = benbow::log_slope(&v, &get("dp_total"));
        let bb = benbow::fit(&v, &get("dp_entry"), &get("dp_die"), l, w);
        let errors: Vec<String> = [slope.as_ref().err(), bb.as_ref().err()]
            .into_iter()
            .flatten()
            .map(|e| e.to_string())
            .collect();
        let (slope, bb) = (slope.ok(), bb.ok());
        fits.insert(
            name.to_string(),
            json!({
                "points": v.len(),
                "log_slope_dp_total": slope.as_ref().map(fit_json),
                "ln_area_ratio": l, "wall_factor": w,
                "sigma0_alpha": bb.as_ref().map(|b| fit_json(&b.entry)),
                "tau0_beta": bb.as_ref().map(|b| fit_json(&b.die)),
                "alpha_no_yield": bb.as_ref().map(|b| fit_json(&b.entry_no_yield)),
                "beta_no_yield": bb.as_ref().map(|b| fit_json(&b.die_no_yield)),
                "errors": errors,
            }),
        );
        let nan = f64::NAN;
        let s = slope.map_or([nan, nan], |s| [s.slope, s.slope_se]);
        let b = bb.map_or([nan; 8], |b| {
            [
                b.entry.intercept,
                b.entry.intercept_se,
                b.entry.slope,
                b.entry.slope_se,
                b.die.intercept,
                b.die.intercept_se,
                b.die.slope,
                b.die.slope_se,
            ]
        });
        f_series.push(name.to_string());
        f_cols.push([s[0], s[1], b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]);
    }
    let names = [
        "log_slope",
        "log_slope_se",
        "sigma0",
        "sigma0_se",
        "alpha",
        "alpha_se",
        "tau0",
        "tau0_se",
        "beta",
        "beta_se",
    ];
    let f_vals: Vec<Vec<f64>> = (0..names.len())
        .map(|j| f_cols.iter().map(|r| r[j]).collect())
        .collect();
    let mut ft: Vec<(&str, Col)> = vec![("series", Col::Str(&f_series))];
    ft.extend(names.iter().zip(&f_vals).map(|(n, v)| (*n, Col::F64(v))));
    write_table(&out.join("fits.csv"), &ft)?;
    // Figures: each measure against V on log axes, one series per value, and the unit slope.
    let mut figures = Vec::new();
    let all_v: Vec<f64> = pts
        .iter()
        .map(|q| num(&q.a, "die_velocity"))
        .filter(|v| *v > 0.0)
        .collect();
    let (v0, v1) = all_v
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
    for (k, title, file) in MEASURES.iter().copied().chain([
        ("static_grains", "Static-zone grains (Fig. 5)", "fig5_static.png"),
        ("static_area", "Static-zone area (Fig. 5)", "fig5_static_area.png"),
    ]) {
        let data: Vec<(String, Vec<f64>, Vec<f64>)> = by
            .iter()
            .map(|(n, qs)| {
                let (mut x, mut y) = (Vec::new(), Vec::new());
                for q in qs {
                    let (a, b) = (num(&q.a, "die_velocity"), num(&q.a, k));
                    if a > 0.0 && b > 0.0 {
                        x.push(a);
                        y.push(b);
                    }
                }
                (n.to_string(), x, y)
            })
            .collect();
        let mut lines: Vec<Line> = data
            .iter()
            .map(|(n, x, y)| Line {
                label: n,
                x,
                y,
                style: Style::Points,
                colour: None,
            })
            .collect();
        // The unit slope through the geometric mean of the points (Ness's dashed line).
        let ys: Vec<f64> = data.iter().flat_map(|d| d.2.iter().copied()).collect();
        let xs: Vec<f64> = data.iter().flat_map(|d| d.1.iter().copied()).collect();
        let unit = if !k.starts_with("static_") && !ys.is_empty() && v1 > v0 {
            let c = (ys.iter().zip(&xs).map(|(y, x)| (y / x).ln()).sum::<f64>() / ys.len() as f64).exp();
            Some(([v0, v1], [c * v0, c * v1]))
        } else {
            None
        };
        if let Some((x, y)) = &unit {
            lines.push(Line {
                label: "gradient 1",
                x,
                y,
                style: Style::Dashed,
                colour: Some((0, 0, 0)),
            });
        }
        if ys.is_empty() {
            continue;
        }
        let y_label = match k {
            "static_grains" => "grains in static zones (-)",
            "static_area" => "static-zone area (d²)",
            _ if k.starts_with("wall") => "τ_w (Pa)",
            _ => "ΔP (Pa)",
        };
        lines_png(
            &out.join(file),
            &lines,
            &LinesPlot {
                title,
                x_label: "V_die (m/s)",
                y_label,
                log_x: true,
                log_y: true,
                ..Default::default()
            },
        )?;
        figures.push(Figure {
            path: file.into(),
            caption: format!(
                "{title} against the die velocity, one marker per analysed case (time- and wall-realisation averaged \
                 as each analysis was); dashed: a gradient of unity. Series by {}. {} points; fits in fits.csv.",
                p.series.as_deref().unwrap_or("label"),
                xs.len()
            ),
        });
    }
    let tables = vec![
        Table {
            path: "flow.csv".into(),
            caption: "One row per analysed case: die velocity (m/s), pressure drops and wall stresses (Pa)".into(),
        },
        Table {
            path: "fits.csv".into(),
            caption: "Per series: power of ΔP_total in V (± standard error) and Eq. 1's four parameters (Pa, Pa s/m)"
                .into(),
        },
    ];
    let mut files: Vec<PathBuf> = figures.iter().map(|f| f.path.clone()).collect();
    files.extend(tables.iter().map(|t| t.path.clone()));
    Ok(StageOutput {
        summary: json!({"points": pts.len(), "series": by.keys().collect::<Vec<_>>(), "fits": fits}),
        figures,
        tables,
        files,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sweep's worth of analyses made up from Eq. 1 (m = n = 1) for two series: the stage
    /// finds the cases, groups them by the axis, returns the four parameters and a log slope
    /// of one where the yield terms are zero, and draws Figs. 5 and 9.
    #[test]
    fn fits_eq1_per_series_from_a_sweeps_cases() {
        let t = tempfile::tempdir().unwrap();
        let sweep = t.path().join("sweep");
        let (wb, wd, ld) = (100.0, 20.0, 200.0);
        let (l, w) = benbow::geometry_factors(wb, wd, ld);
        let law = |case: &str| {
            if case == "a" {
                (0.0, 3.0e6, 0.0, 4.0e4)
            } else {
                (2.0e4, 6.0e6, 150.0, 4.0e4)
            }
        };
        for case in ["a", "b"] {
            let (s0, a, t0, b) = law(case);
            for (k, v) in [0.01, 0.02, 0.05, 0.1].into_iter().enumerate() {
                let dir = sweep.join("cases").join(format!("case{case}-{k}"));
                std::fs::create_dir_all(dir.join("cg")).unwrap();
                std::fs::write(
                    dir.join("case.json"),
                    json!({"axes": [["case", case], ["force", k]]}).to_string(),
                )
                .unwrap();
                let (entry, die) = ((s0 + a * v) * l, (t0 + b * v) * w);
                let a_json = json!({
                    "label": "x", "die_velocity": v, "dp_entry": entry, "dp_die": die, "dp_barrel": 10.0 * v,
                    "dp_total": entry + die + 10.0 * v, "wall_stress_barrel": v, "wall_stress_die": 2.0 * v,
                    "static_grains": 5.0 / v, "static_area": 3.0 / v, "max_stokes": 0.01, "contact_pressure_share": 0.9,
                    "geometry": {"barrel_width_d": wb, "die_width_d": wd, "die_length_d": ld},
                });
                std::fs::write(dir.join("cg").join(SUMMARY), a_json.to_string()).unwrap();
            }
        }
        let ctx = StageContext::new(t.path().join("out"), "fig9".into(), t.path().to_path_buf());
        std::fs::create_dir_all(&ctx.out_dir).unwrap();
        let p: Params = toml::from_str("sweep = \"sweep\"\nseries = \"case\"").unwrap();
        let out = flow(&p, &ctx).unwrap();
        let fits = &out.summary["fits"];
        for case in ["a", "b"] {
            let (s0, a, t0, b) = law(case);
            let f = &fits[case];
            let got = |k: &str, m: &str| f[k][m].as_f64().unwrap();
            for (g, want) in [
                (got("sigma0_alpha", "intercept"), s0),
                (got("sigma0_alpha", "slope"), a),
                (got("tau0_beta", "intercept"), t0),
                (got("tau0_beta", "slope"), b),
            ] {
                // Measured: below 1e-10 relative (round-off of the sums); τ_0 = 0 to 1e-8 Pa.
                assert!(
                    (g - want).abs() < 1e-8 * want.abs().max(1.0),
                    "{case}: {g} vs {want}"
                );
            }
        }
        // No yield terms: ΔP ∝ V, gradient 1 on log axes.
        let slope = fits["a"]["log_slope_dp_total"]["slope"].as_f64().unwrap();
        assert!((slope - 1.0).abs() < 1e-12, "{slope}");
        assert!(fits["b"]["log_slope_dp_total"]["slope"].as_f64().unwrap() < 0.99);
        assert_eq!(out.figures.len(), 8);
        for f in &out.figures {
            assert!(ctx.out_dir.join(&f.path).is_file());
        }
        // An axis the cases lack is refused, naming the parameter.
        let bad: Params = toml::from_str("sweep = \"sweep\"\nseries = \"mu\"").unwrap();
        assert!(format!("{:#}", flow(&bad, &ctx).unwrap_err()).contains("'series'"));
    }
}
