//! Stage `matrix` (`lbdem matrix PARAMS.toml --out DIR`): a grid of analysed runs on one colour
//! scale, as Su et al. (2020) Figs. 8-11 lay out their simulations: rows and columns named (e.g.
//! %PK × rate for Figs. 8-10; rate sensitivity and liquid on/off × rate for Fig. 11), each panel
//! the last snapshot's ε_xx + ε_yy, ε_xy or Δp from an `analyse` stage, framed black for net
//! contraction (ε_vol^DEM < 0) and green for net dilation, titled with ε_vol^DEM (and u_y,min when
//! the run reached Δp_c). Panels are resampled onto the first run's grid (same field of view in
//! d̄ from the plate).

use super::analyse::ANALYSIS;
use super::run_data;
use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::io::tiff as tio;
use crate::report::panels::{Panel, PanelGrid, Shape, panels_png};
use crate::report::plot::Colormap;
use crate::report::table::{self, Col};
use anyhow::{Context, Result, bail};
use lbdem_analysis::mechanism::Class;
use lbdem_analysis::raster::Grid;
use ndarray::Array2;
use serde::{Deserialize, Serialize};
use serde_json::json;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Field {
    EpsVol,
    EpsXy,
    Dp,
    /// The grains' solid fraction per pixel (Su Fig. 7: the deformed microstructures).
    Microstructure,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    pub title: String,
    pub field: Field,
    /// Row and column labels.
    pub rows: Vec<String>,
    pub cols: Vec<String>,
    /// Analysed runs row by row (earlier `analyse` stages or their directories); "" leaves a
    /// cell empty.
    pub analyses: Vec<String>,
    /// Shared colour range (default: symmetric over every panel).
    #[serde(default)]
    pub range: Option<[f64; 2]>,
    /// What the figure stands for, added to its caption (e.g. "Su Fig. 11, reduced cell").
    #[serde(default)]
    pub note: Option<String>,
}

pub struct Matrix;

impl Stage for Matrix {
    const KIND: &'static str = "matrix";
    const ABOUT: &'static str =
        "Figs. 8-11: a grid of analysed runs (ε_vol, ε_xy or Δp) on one colour scale, framed by net class";
    type Params = Params;
    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        p.analyses
            .iter()
            .filter(|a| !a.is_empty())
            .map(|a| run_data::locate(a, ctx).join(ANALYSIS))
            .filter(|f| f.is_file() || ctx.earlier.iter().any(|(_, d)| f.starts_with(d)))
            .collect()
    }
    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        matrix(p, ctx)
    }
}

struct Cell {
    label: String,
    grid: Grid,
    field: Array2<f64>,
    eps_dem: f64,
    class: Option<Class>,
    u_min: Option<f64>,
    plate: Option<[[f64; 2]; 2]>,
}

fn load(spec: &str, field: Field, ctx: &StageContext) -> Result<Cell> {
    let dir = run_data::locate(spec, ctx);
    let path = dir.join(ANALYSIS);
    let v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(&path).with_context(|| format!("matrix: cannot read {}", path.display()))?,
    )
    .with_context(|| format!("{} is not an analysis", path.display()))?;
    let grid: Grid = serde_json::from_value(v["grid"].clone())
        .with_context(|| format!("{}: no grid (made by an older analyse stage?)", path.display()))?;
    let key = match field {
        Field::EpsVol => "eps_vol",
        Field::EpsXy => "eps_xy",
        Field::Dp => "dp",
        Field::Microstructure => "gs",
    };
    let file = dir.join(v["last_maps"][key].as_str().unwrap_or_default());
    if !file.is_file() {
        bail!(
            "{}: the run has no {key} map ({}); Δp needs a run with liquid",
            path.display(),
            file.display()
        );
    }
    let f = tio::read_pages(&file)?.remove(0).data;
    if f.dim() != (grid.ny, grid.nx) {
        bail!(
            "{}: map {:?} does not match its grid {} x {}",
            file.display(),
            f.dim(),
            grid.ny,
            grid.nx
        );
    }
    let plate = v["last_maps"]["plate"].as_array().and_then(|a| {
        let p = |i: usize| -> Option<[f64; 2]> {
            let q = a.get(i)?.as_array()?;
            Some([q.first()?.as_f64()?, q.get(1)?.as_f64()?])
        };
        Some([p(0)?, p(1)?])
    });
    Ok(Cell {
        label: v["label"].as_str().unwrap_or(spec).to_string(),
        grid,
        field: f,
        eps_dem: v["eps_vol_dem_final"].as_f64().unwrap_or(f64::NAN),
        class: v["class"].as_str().and_then(|s| {
            Class::ALL.into_iter().find(|c| {
                serde_json::to_value(c)
                    .ok()
                    .and_then(|x| x.as_str().map(|y| y == s))
                    == Some(true)
            })
        }),
        u_min: v["cracking"]["u_y_min_d"].as_f64(),
        plate,
    })
}

/// `c`'s field sampled at the pixel centres of `to` (nearest pixel; NaN off its grid).
fn resample(c: &Cell, to: &Grid) -> Array2<f64> {
    Array2::from_shape_fn((to.ny, to.nx), |(r, col)| {
        c.grid
            .pixel_of(to.centre(r, col))
            .map_or(f64::NAN, |(rr, cc)| c.field[[rr, cc]])
    })
}

fn matrix(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
    let (nr, nc) = (p.rows.len(), p.cols.len());
    if nr == 0 || nc == 0 || p.analyses.len() != nr * nc {
        bail!(
            "matrix: {} analyses for {nr} rows x {nc} columns; list one per cell, row by row (\"\" for an empty cell)",
            p.analyses.len()
        );
    }
    let cells: Vec<Option<Cell>> = p
        .analyses
        .iter()
        .map(|a| {
            if a.is_empty() {
                Ok(None)
            } else {
                load(a, p.field, ctx).map(Some)
            }
        })
        .collect::<Result<_>>()?;
    let Some(base) = cells.iter().flatten().next().map(|c| c.grid) else {
        bail!("matrix: every cell is empty");
    };
    let fields: Vec<Array2<f64>> = cells
        .iter()
        .map(|c| match c {
            Some(c) => resample(c, &base),
            None => Array2::from_elem((base.ny, base.nx), f64::NAN),
        })
        .collect();
    let marked: Vec<Option<Array2<bool>>> = fields
        .iter()
        .map(|f| (p.field == Field::Dp).then(|| f.mapv(|v| v < lbdem_analysis::cracking::DP_C)))
        .collect();
    let panels: Vec<Panel> = cells
        .iter()
        .enumerate()
        .map(|(k, c)| {
            let (row, col) = (&p.rows[k / nc], &p.cols[k % nc]);
            let (title, frame, shapes) = match c {
                None => (format!("{row}, {col}: (none)"), None, Vec::new()),
                Some(c) => {
                    let mut t = format!("{row}, {col}: eps_vol_DEM = {:.3}", c.eps_dem);
                    if let Some(u) = c.u_min {
                        t.push_str(&format!(", u_y,min = {u:.1} d_bar"));
                    }
                    let frame = match c.class {
                        Some(Class::Suspension) => Some(Class::Suspension.colour()),
                        _ if c.eps_dem > 0.0 => Some(Class::Dilation.colour()),
                        _ => Some(Class::Contraction.colour()),
                    };
                    let shapes = c
                        .plate
                        .map(|[a, b]| {
                            vec![Shape {
                                points: vec![
                                    (a[0], a[1]),
                                    (b[0], b[1]),
                                    (b[0], b[1] - 0.6),
                                    (a[0], a[1] - 0.6),
                                ],
                                colour: (40, 40, 40),
                                closed: true,
                            }]
                        })
                        .unwrap_or_default();
                    (t, frame, shapes)
                }
            };
            Panel {
                title,
                field: fields[k].view(),
                marked: marked[k].as_ref().map(|m| m.view()),
                shapes,
                frame,
            }
        })
        .collect();
    let cmap = if p.field == Field::Microstructure {
        Colormap::Gray
    } else {
        Colormap::Diverging
    };
    let (label, name) = match p.field {
        Field::EpsVol => ("ε_xx + ε_yy (-)", "ε_xx + ε_yy by triangulation (√10 d̄ REV)"),
        Field::EpsXy => ("ε_xy (-)", "ε_xy = γ_xy/2 by triangulation (√10 d̄ REV)"),
        Field::Dp => (
            "Δp (Pa)",
            "the liquid pressure change Δp (Eq. 19), yellow below Δp_c = −0.03 Pa",
        ),
        Field::Microstructure => (
            "solid fraction (-)",
            "the deformed microstructure (grains light, liquid black)",
        ),
    };
    let mark = format!("Δp < {} Pa", lbdem_analysis::cracking::DP_C);
    let out = &ctx.out_dir;
    let png = "matrix.png";
    let (lo, hi) = panels_png(
        &out.join(png),
        &panels,
        &PanelGrid {
            title: &p.title,
            cols: nc,
            label,
            cmap,
            range: p
                .range
                .map(|r| (r[0], r[1]))
                .or((p.field == Field::Microstructure).then_some((0.0, 1.0))),
            extent: [base.x0, base.x0 + base.nx as f64 * base.dx, base.y0, base.y1()],
            x_label: "x (d_bar)",
            y_label: "y (d_bar)",
            mark_label: (p.field == Field::Dp).then_some(mark.as_str()),
        },
    )?;
    let mut labels = Vec::new();
    let (mut eps, mut umin, mut classes) = (Vec::new(), Vec::new(), Vec::new());
    let (mut rl, mut cl) = (Vec::new(), Vec::new());
    for (k, c) in cells.iter().enumerate() {
        rl.push(p.rows[k / nc].clone());
        cl.push(p.cols[k % nc].clone());
        labels.push(c.as_ref().map_or(String::new(), |c| c.label.clone()));
        eps.push(c.as_ref().map_or(f64::NAN, |c| c.eps_dem));
        umin.push(c.as_ref().and_then(|c| c.u_min).unwrap_or(f64::NAN));
        classes.push(
            c.as_ref()
                .and_then(|c| c.class)
                .map_or(String::new(), |c| c.name().to_string()),
        );
    }
    table::write_table(
        &out.join("matrix.csv"),
        &[
            ("row", Col::Str(&rl)),
            ("column", Col::Str(&cl)),
            ("run", Col::Str(&labels)),
            ("eps_vol_dem", Col::F64(&eps)),
            ("u_y_min_d", Col::F64(&umin)),
            ("class", Col::Str(&classes)),
        ],
    )?;
    let caption = format!(
        "{name} at the end of each run, rows {:?} × columns {:?}, one colour scale ({lo:.3e} to {hi:.3e}); frames: \
         black net contraction (ε_vol^DEM < 0), green net dilation; titles give ε_vol^DEM (Eq. 18) and, where Δp fell \
         below Δp_c, u_y,min. x, y in d̄ from the middle of the plate's face; the dark outline is the plate.{}",
        p.rows,
        p.cols,
        p.note.as_ref().map_or(String::new(), |n| format!(" {n}."))
    );
    Ok(StageOutput {
        summary: json!({ "rows": nr, "cols": nc, "field": p.field, "range": [lo, hi] }),
        figures: vec![Figure {
            path: png.into(),
            caption,
        }],
        tables: vec![Table {
            path: "matrix.csv".into(),
            caption: "Each cell of the grid: its run, ε_vol^DEM, u_y,min (d̄; empty when Δp never fell below Δp_c) and \
                      net class."
                .into(),
        }],
        files: vec![png.into(), "matrix.csv".into()],
    })
}
