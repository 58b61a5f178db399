//! Stage `mechanism-map` (`lbdem mechanism-map PARAMS.toml --out DIR`): Su et al. (2020) Fig. 3j.
//! The experimental datasets the paper names with their class (Sects. 2-3.5,
//! `lbdem_analysis::mechanism::PAPER_DATASETS`) and this project's analysed runs, on initial
//! solid fraction against push-plate rate (log), with the void ratio on the top axis, the shear
//! rate on the right, and the transition lines: the suspension line at g_S⁰ = 38 % (the heating
//! experiment) and the two inclined lines, each the widest-gap straight line between the classes
//! on either side (`mechanism::transition_lines`), fitted to the experiments.

use super::analyse::ANALYSIS;
use super::run_data;
use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::report::mechanism_map::{MapAxes, MapLine, MapPoint, Marker, mechanism_map_png};
use crate::report::table::{self, Col};
use anyhow::{Context, Result, bail};
use lbdem_analysis::mechanism::{Class, Frame, Line, PAPER_DATASETS, PERCOLATION_G_S, transition_lines};
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::PathBuf;

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    #[serde(default = "d::title")]
    pub title: String,
    /// Analysed runs: earlier `analyse` stages by name, or their output directories.
    #[serde(default)]
    pub analyses: Vec<String>,
    /// Draw the paper's experimental datasets (and fit the transition lines to them).
    #[serde(default = "d::yes")]
    pub paper: bool,
    /// Sample width for the shear-rate axis (m): Su Fig. 1a, 7.5 mm.
    #[serde(default = "d::width")]
    pub sample_width: f64,
    /// Axis ranges: g_S⁰ and rate (µm/s).
    #[serde(default = "d::g_range")]
    pub g_range: [f64; 2],
    #[serde(default = "d::rate_range")]
    pub rate_range: [f64; 2],
}

mod d {
    pub fn title() -> String {
        "Deformation mechanism map (Su et al. 2020 Fig. 3j)".into()
    }
    pub fn yes() -> bool {
        true
    }
    pub fn width() -> f64 {
        7.5e-3
    }
    pub fn g_range() -> [f64; 2] {
        [0.3, 0.95]
    }
    pub fn rate_range() -> [f64; 2] {
        [0.3, 1e4]
    }
}

pub struct MechanismMap;

impl Stage for MechanismMap {
    const KIND: &'static str = "mechanism-map";
    const ABOUT: &'static str =
        "Fig. 3j: the paper's datasets and the analysed runs on g_S⁰ against rate, with transition lines";
    type Params = Params;
    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        p.analyses
            .iter()
            .map(|a| run_data::locate(a, ctx).join(ANALYSIS))
            .filter(|f| f.is_file() || ctx.earlier.iter().any(|(_, d)| f.starts_with(d)))
            .collect()
    }
    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        map(p, ctx)
    }
}

fn parse_class(s: &str) -> Option<Class> {
    Class::ALL.into_iter().find(|c| {
        serde_json::to_value(c)
            .ok()
            .and_then(|v| v.as_str().map(|x| x == s))
            == Some(true)
    })
}

/// Points along a transition line across the rate axis, in (g_S⁰, rate).
fn line_points(l: &Line, f: &Frame, rate: [f64; 2]) -> Vec<(f64, f64)> {
    (0..=40)
        .filter_map(|k| {
            let r = rate[0] * (rate[1] / rate[0]).powf(k as f64 / 40.0);
            let v = f.to_plot(0.5, r)[1];
            let u = l.u_at(v)?;
            Some((f.from_plot([u, v]).0, r))
        })
        .collect()
}

fn map(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
    if !(p.sample_width > 0.0
        && p.g_range[1] > p.g_range[0]
        && p.rate_range[0] > 0.0
        && p.rate_range[1] > p.rate_range[0])
    {
        bail!(
            "sample_width = {} m, g_range = {:?}, rate_range = {:?} µm/s: need a positive width and increasing \
             ranges with a positive lowest rate",
            p.sample_width,
            p.g_range,
            p.rate_range
        );
    }
    if !p.paper && p.analyses.is_empty() {
        bail!("nothing to draw: give 'analyses' or set paper = true");
    }
    let mut points = Vec::new();
    let (mut name, mut g, mut rate, mut class, mut source) = (vec![], vec![], vec![], vec![], vec![]);
    if p.paper {
        for d in &PAPER_DATASETS {
            points.push(MapPoint {
                label: d.name.into(),
                g_s0: d.g_s0,
                rate_um_s: d.rate_um_s,
                colour: d.class.colour(),
                marker: Marker::Experiment,
            });
            name.push(d.name.to_string());
            g.push(d.g_s0);
            rate.push(d.rate_um_s);
            class.push(d.class.name().to_string());
            source.push(format!("Su et al. 2020, {}", d.source));
        }
    }
    for a in &p.analyses {
        let path = run_data::locate(a, ctx).join(ANALYSIS);
        let v: serde_json::Value = serde_json::from_str(
            &std::fs::read_to_string(&path)
                .with_context(|| format!("mechanism-map: cannot read {}", path.display()))?,
        )
        .with_context(|| format!("{} is not an analysis", path.display()))?;
        let label = v["label"].as_str().unwrap_or(a).to_string();
        let (Some(gs), Some(r), Some(c)) = (
            v["g_s0"].as_f64(),
            v["plate_rate_um_s"].as_f64(),
            v["class"].as_str().and_then(parse_class),
        ) else {
            bail!(
                "{}: the run needs a g_s0 (or a membrane to measure its packing), a moving plate and a class to go \
                 on the map",
                path.display()
            );
        };
        points.push(MapPoint {
            label: label.clone(),
            g_s0: gs,
            rate_um_s: r,
            colour: c.colour(),
            marker: Marker::Simulation,
        });
        name.push(label);
        g.push(gs);
        rate.push(r);
        class.push(c.name().to_string());
        source.push(path.display().to_string());
    }
    let frame = Frame {
        g_lo: p.g_range[0],
        g_hi: p.g_range[1],
        l_lo: p.rate_range[0].log10(),
        l_hi: p.rate_range[1].log10(),
    };
    let exp: Vec<(f64, f64, Class)> = PAPER_DATASETS
        .iter()
        .map(|d| (d.g_s0, d.rate_um_s, d.class))
        .collect();
    let (cd, crack) = if p.paper {
        transition_lines(&exp, &frame)
    } else {
        (None, None)
    };
    let mut lines = vec![MapLine {
        label: "suspension | network (38 %, Sect. 3.2)".into(),
        points: vec![
            (PERCOLATION_G_S, p.rate_range[0]),
            (PERCOLATION_G_S, p.rate_range[1]),
        ],
        colour: Class::Suspension.colour(),
    }];
    if let Some(l) = cd {
        lines.push(MapLine {
            label: "contraction | dilation".into(),
            points: line_points(&l, &frame, p.rate_range),
            colour: Class::Dilation.colour(),
        });
    }
    if let Some(l) = crack {
        lines.push(MapLine {
            label: "no cracking | cracking".into(),
            points: line_points(&l, &frame, p.rate_range),
            colour: Class::Cracking.colour(),
        });
    }
    let mut legend: Vec<(String, (u8, u8, u8), Marker)> = Class::ALL
        .iter()
        .map(|c| {
            (
                format!("{} (experiment)", c.name()),
                c.colour(),
                Marker::Experiment,
            )
        })
        .collect();
    if !p.analyses.is_empty() {
        legend.push((
            "simulation (this project)".into(),
            (80, 80, 80),
            Marker::Simulation,
        ));
    }
    let out = &ctx.out_dir;
    let png = "mechanism_map.png";
    mechanism_map_png(
        &out.join(png),
        &points,
        &lines,
        &MapAxes {
            title: p.title.clone(),
            g_range: (p.g_range[0], p.g_range[1]),
            rate_range: (p.rate_range[0], p.rate_range[1]),
            width_m: p.sample_width,
            legend,
        },
    )?;
    table::write_table(
        &out.join("map_points.csv"),
        &[
            ("name", Col::Str(&name)),
            ("g_s0", Col::F64(&g)),
            ("rate_um_s", Col::F64(&rate)),
            ("class", Col::Str(&class)),
            ("source", Col::Str(&source)),
        ],
    )?;
    let line_json = |l: Option<Line>| {
        l.map(|l| {
            let at = |r: f64| {
                let v = frame.to_plot(0.5, r)[1];
                l.u_at(v).map(|u| frame.from_plot([u, v]).0)
            };
            json!({"g_s0_at_1_um_s": at(1.0), "g_s0_at_30_um_s": at(30.0), "g_s0_at_1000_um_s": at(1000.0),
                   "margin_plot_units": l.margin})
        })
    };
    let summary = json!({
        "experiments": if p.paper { PAPER_DATASETS.len() } else { 0 },
        "simulations": p.analyses.len(),
        "sample_width_m": p.sample_width,
        "contraction_dilation_line": line_json(cd),
        "cracking_line": line_json(crack),
    });
    Ok(StageOutput {
        summary,
        figures: vec![Figure {
            path: png.into(),
            caption: format!(
                "Deformation mechanism map as Su et al. 2020 Fig. 3j: filled circles, the {} experimental datasets the \
                 paper names with their class (grey suspension, black shear-induced contraction, green shear-induced \
                 dilation, red shear cracking); open squares, this project's analysed runs (class by the rule in \
                 docs/analysis.md; their g_S⁰ is the value given to the analysis or their 2D packing fraction). \
                 Dashed: the 38 % suspension line (the heating experiment) and the widest-gap lines between the \
                 experiments' classes. Top axis: e⁰ = (1 − g_S⁰)/g_S⁰ at the g_S⁰ ticks; right axis: rate / {} mm. \
                 A rate of 0 sits on the bottom edge.",
                if p.paper { PAPER_DATASETS.len() } else { 0 },
                p.sample_width * 1e3
            ),
        }],
        tables: vec![Table {
            path: "map_points.csv".into(),
            caption:
                "Every point of the map: name, g_S⁰, push-plate rate (µm/s), class and where it comes from."
                    .into(),
        }],
        files: vec![png.into(), "map_points.csv".into()],
    })
}
