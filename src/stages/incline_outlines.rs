//! Stage `incline-outlines`: Leonardi et al. (2014) Sect. 6 from finished incline runs (issue 20
//! item 4): the final outline of the paste on the board (Fig. 7c), the viscosity on the middle
//! longitudinal section (Fig. 8) of the reference run, and the speed-against-accuracy chart of the
//! outline over lattices: each run's footprint against the reference's (the area where exactly one
//! of the two has paste, over the reference's area) against its wall time.
//!
//! A footprint is the board cells whose paste is at least `threshold` thick (one common height in
//! metres for every lattice; the engine's own `footprint` takes half a node of its lattice). A run
//! on another lattice is read at the reference's cell centres (the cell of its own grid that
//! holds each centre), so the difference is an area on the reference's grid.

use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::report::plot::{Colormap, FieldPlot, Series, XyPlot, field_png, xy_png};
use crate::report::table::{Col, f64_column, read_table, str_column, write_table};
use anyhow::{Context, Result, bail};
use ndarray::Array2;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One finished run of an `[incline]` scene (the `--out` directory of `lbdem simulate`).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunRef {
    /// Label in the tables and figures, e.g. "5 mm".
    pub name: String,
    pub dir: PathBuf,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    pub runs: Vec<RunRef>,
    /// The `name` of the run the others are compared with (the finest lattice).
    pub reference: String,
    /// Smallest paste thickness (m) counted as footprint.
    #[serde(default = "threshold")]
    pub threshold: f64,
}

fn threshold() -> f64 {
    5e-3
}

/// A thickness map on a regular board grid: `t[[i, k]]` at x = (i + ½) dx, z = (k + ½) dx.
#[derive(Clone, Debug)]
pub struct Board {
    pub dx: f64,
    pub t: Array2<f64>,
}

impl Board {
    /// From the columns of a `thickness_*.csv` (cell centres x, z and the thickness).
    pub fn from_columns(x: &[f64], z: &[f64], t: &[f64], dx: f64) -> Result<Self> {
        let cell = |v: f64| (v / dx - 0.5).round();
        let nx = x.iter().map(|&v| cell(v)).fold(0.0, f64::max) as usize + 1;
        let nz = z.iter().map(|&v| cell(v)).fold(0.0, f64::max) as usize + 1;
        let mut a = Array2::from_elem((nx, nz), f64::NAN);
        for ((&xv, &zv), &tv) in x.iter().zip(z).zip(t) {
            let (i, k) = (cell(xv), cell(zv));
            if i < 0.0 || k < 0.0 {
                bail!("thickness cell at x = {xv}, z = {zv} lies before the board's origin");
            }
            a[[i as usize, k as usize]] = tv;
        }
        if a.iter().any(|v| v.is_nan()) {
            bail!("the thickness table does not cover its {nx} x {nz} grid of {dx} m cells");
        }
        Ok(Self { dx, t: a })
    }

    /// Whether the cell holding the point (x, z) has paste at least `h` thick (false off the grid).
    pub fn wet_at(&self, x: f64, z: f64, h: f64) -> bool {
        let (i, k) = ((x / self.dx).floor(), (z / self.dx).floor());
        if i < 0.0 || k < 0.0 {
            return false;
        }
        self.t.get([i as usize, k as usize]).is_some_and(|&v| v >= h)
    }

    /// Footprint area (m²), down-board extent (largest wet x, m) and width across (m).
    pub fn footprint(&self, h: f64) -> (f64, f64, f64) {
        let (mut n, mut x_max, mut z_lo, mut z_hi) = (0usize, 0.0f64, f64::INFINITY, 0.0f64);
        for ((i, k), &v) in self.t.indexed_iter() {
            if v >= h {
                n += 1;
                x_max = x_max.max((i + 1) as f64 * self.dx);
                z_lo = z_lo.min(k as f64 * self.dx);
                z_hi = z_hi.max((k + 1) as f64 * self.dx);
            }
        }
        let width = if n == 0 { 0.0 } else { z_hi - z_lo };
        (n as f64 * self.dx * self.dx, x_max, width)
    }

    /// The share of `reference`'s footprint area where exactly one of the two has paste, on the
    /// reference's grid.
    pub fn outline_difference(&self, reference: &Board, h: f64) -> f64 {
        let (mut differ, mut wet) = (0usize, 0usize);
        for ((i, k), &v) in reference.t.indexed_iter() {
            let (x, z) = ((i as f64 + 0.5) * reference.dx, (k as f64 + 0.5) * reference.dx);
            let r = v >= h;
            wet += usize::from(r);
            differ += usize::from(r != self.wet_at(x, z, h));
        }
        if wet == 0 {
            f64::NAN
        } else {
            differ as f64 / wet as f64
        }
    }

    /// The cell centres on the footprint's edge (a wet cell with a dry or missing 4-neighbour).
    pub fn outline(&self, h: f64) -> (Vec<f64>, Vec<f64>) {
        let (nx, nz) = self.t.dim();
        let wet = |i: isize, k: isize| {
            i >= 0
                && k >= 0
                && (i as usize) < nx
                && (k as usize) < nz
                && self.t[[i as usize, k as usize]] >= h
        };
        let (mut xs, mut zs) = (Vec::new(), Vec::new());
        for i in 0..nx as isize {
            for k in 0..nz as isize {
                if wet(i, k) && !(wet(i - 1, k) && wet(i + 1, k) && wet(i, k - 1) && wet(i, k + 1)) {
                    xs.push((i as f64 + 0.5) * self.dx);
                    zs.push((k as f64 + 0.5) * self.dx);
                }
            }
        }
        (xs, zs)
    }
}

/// What one run's directory gives: its lattice, wall time, end time, last rigid share, the last
/// thickness map and the last section file.
struct RunData {
    dx: f64,
    dt: f64,
    smagorinsky: f64,
    lonely: f64,
    wall_seconds: f64,
    time: f64,
    rigid_share: f64,
    board: Board,
    section: PathBuf,
}

fn load(dir: &Path) -> Result<RunData> {
    let stage = dir.join("stage.json");
    let text = std::fs::read_to_string(&stage).with_context(|| {
        format!(
            "incline-outlines: cannot read {} (a run's --out directory of `lbdem simulate` on an [incline] scene)",
            stage.display()
        )
    })?;
    let json: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{} is not JSON", stage.display()))?;
    let spec = &json["output"]["summary"]["engine"]["spec"];
    let num = |v: &serde_json::Value, what: &str| {
        v.as_f64()
            .with_context(|| format!("{}: no number at {what}; is it an incline run?", stage.display()))
    };
    let dx = num(&spec["dx"], "output.summary.engine.spec.dx")?;
    let dt = num(&spec["dt"], "output.summary.engine.spec.dt")?;
    let wall_seconds = num(&json["wall_s"], "wall_s")?;
    let index = dir.join("snapshots.csv");
    let df = read_table(&index)?;
    let kinds = str_column(&df, "kind", &index)?;
    let files = str_column(&df, "file", &index)?;
    let times = f64_column(&df, "time", &index)?;
    let last = |kind: &str| {
        (0..kinds.len())
            .rev()
            .find(|&r| kinds[r] == kind)
            .with_context(|| format!("{} lists no {kind} snapshot", index.display()))
    };
    let (rt, rs) = (last("thickness")?, last("section")?);
    let tpath = dir.join(&files[rt]);
    let tdf = read_table(&tpath)?;
    let board = Board::from_columns(
        &f64_column(&tdf, "x", &tpath)?,
        &f64_column(&tdf, "z", &tpath)?,
        &f64_column(&tdf, "thickness", &tpath)?,
        dx,
    )
    .with_context(|| tpath.display().to_string())?;
    let series = dir.join("series.csv");
    let sdf = read_table(&series)?;
    let rigid = f64_column(&sdf, "rigid_share", &series)?;
    Ok(RunData {
        dx,
        dt,
        smagorinsky: spec["smagorinsky"].as_f64().unwrap_or(0.0),
        lonely: spec["lonely"].as_f64().unwrap_or(0.0),
        wall_seconds,
        time: times[rt],
        rigid_share: rigid.last().copied().unwrap_or(f64::NAN),
        board,
        section: dir.join(&files[rs]),
    })
}

/// The section table (x, y, dynamic viscosity) as log10 μ on an (x, y) grid, NaN outside the paste;
/// the field is drawn with y up.
fn section_field(path: &Path, dx: f64) -> Result<Array2<f64>> {
    let df = read_table(path)?;
    let (x, y, mu) = (
        f64_column(&df, "x", path)?,
        f64_column(&df, "y", path)?,
        f64_column(&df, "viscosity", path)?,
    );
    let cell = |v: f64| (v / dx - 0.5).round().max(0.0) as usize;
    let nx = x.iter().map(|&v| cell(v)).max().unwrap_or(0) + 1;
    let ny = y.iter().map(|&v| cell(v)).max().unwrap_or(0) + 1;
    let mut a = Array2::from_elem((ny, nx), f64::NAN);
    for ((&xv, &yv), &m) in x.iter().zip(&y).zip(&mu) {
        a[[ny - 1 - cell(yv), cell(xv)]] = if m > 0.0 { m.log10() } else { f64::NAN };
    }
    Ok(a)
}

pub struct InclineOutlines;

impl Stage for InclineOutlines {
    const KIND: &'static str = "incline-outlines";
    const ABOUT: &'static str = "Leonardi et al. 2014 Fig. 7c and 8 from incline runs, and the outline's error against wall time over lattices";
    type Params = Params;

    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        p.runs
            .iter()
            .flat_map(|r| {
                let d = ctx.resolve(&r.dir);
                [d.join("stage.json"), d.join("snapshots.csv")]
            })
            .collect()
    }

    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        if p.runs.is_empty() {
            bail!(
                "incline-outlines: runs is empty; list the runs as [{{ name = \"5 mm\", dir = \"runs/incline-5mm\" }}, ...]"
            );
        }
        if !(p.threshold.is_finite() && p.threshold > 0.0) {
            bail!(
                "incline-outlines: threshold = {} must be a positive thickness in metres (default 0.005)",
                p.threshold
            );
        }
        let Some(ri) = p.runs.iter().position(|r| r.name == p.reference) else {
            bail!(
                "incline-outlines: reference = \"{}\" names none of the runs ({}); give one of their names",
                p.reference,
                p.runs
                    .iter()
                    .map(|r| r.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        };
        let data: Vec<RunData> = p
            .runs
            .iter()
            .map(|r| {
                load(&ctx.resolve(&r.dir)).with_context(|| format!("incline-outlines: run \"{}\"", r.name))
            })
            .collect::<Result<_>>()?;
        let h = p.threshold;
        let reference = &data[ri].board;
        let rows: Vec<(f64, f64, f64, f64)> = data
            .iter()
            .map(|d| {
                let (area, x_max, width) = d.board.footprint(h);
                (area, x_max, width, d.board.outline_difference(reference, h))
            })
            .collect();
        let names: Vec<String> = p.runs.iter().map(|r| r.name.clone()).collect();
        let col = |f: &dyn Fn(usize) -> f64| (0..data.len()).map(f).collect::<Vec<f64>>();
        write_table(
            &ctx.out_dir.join("incline_outlines.csv"),
            &[
                ("run", Col::Str(&names)),
                ("dx", Col::F64(&col(&|k| data[k].dx))),
                ("dt", Col::F64(&col(&|k| data[k].dt))),
                ("smagorinsky", Col::F64(&col(&|k| data[k].smagorinsky))),
                ("lonely", Col::F64(&col(&|k| data[k].lonely))),
                ("time", Col::F64(&col(&|k| data[k].time))),
                ("rigid_share", Col::F64(&col(&|k| data[k].rigid_share))),
                ("wall_seconds", Col::F64(&col(&|k| data[k].wall_seconds))),
                ("area", Col::F64(&col(&|k| rows[k].0))),
                ("x_max", Col::F64(&col(&|k| rows[k].1))),
                ("width", Col::F64(&col(&|k| rows[k].2))),
                ("outline_difference", Col::F64(&col(&|k| rows[k].3))),
            ],
        )?;
        // Fig. 7c: the outlines, x down the board and z across, in mm
        let outlines: Vec<(Vec<f64>, Vec<f64>)> = data
            .iter()
            .map(|d| {
                let (x, z) = d.board.outline(h);
                (
                    z.iter().map(|v| v * 1e3).collect(),
                    x.iter().map(|v| v * 1e3).collect(),
                )
            })
            .collect();
        let series: Vec<Series> = outlines
            .iter()
            .zip(&names)
            .map(|((z, x), n)| Series {
                label: n,
                x: z,
                y: x,
                points: true,
            })
            .collect();
        xy_png(
            &ctx.out_dir.join("outlines.png"),
            &series,
            &XyPlot {
                title: "Paste outline on the board at the end of each run (Leonardi Fig. 7c)",
                x_label: "across the board z (mm)",
                y_label: "down the board x (mm)",
                log_x: false,
                log_y: false,
            },
        )?;
        // the chart: outline difference against wall time, every run but the reference
        let (wx, wy): (Vec<f64>, Vec<f64>) = (0..data.len())
            .filter(|&k| k != ri)
            .map(|k| (data[k].wall_seconds.max(1e-3), rows[k].3))
            .unzip();
        let cost_label = format!("against the {} run", p.reference);
        let (lo, hi) = wx
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &v| (a.min(v), b.max(v)));
        let wide = hi > 10.0 * lo;
        xy_png(
            &ctx.out_dir.join("outline_vs_wall_time.png"),
            &[Series {
                label: &cost_label,
                x: &wx,
                y: &wy,
                points: true,
            }],
            &XyPlot {
                title: "Outline difference against wall time (incline, coarser lattices)",
                x_label: "wall time (s)",
                y_label: "area with paste in one run only / reference area",
                // a log axis only labels 1, 2 and 5 per decade: linear within a decade
                log_x: wide,
                log_y: false,
            },
        )?;
        let field = section_field(&data[ri].section, data[ri].dx)?;
        let section_title = format!(
            "log10 dynamic viscosity (Pa s) on the middle section, {} run (Leonardi Fig. 8)",
            p.reference
        );
        field_png(
            &ctx.out_dir.join("section.png"),
            field.view(),
            &FieldPlot {
                title: &section_title,
                label: "log10 mu (Pa s)",
                cmap: Colormap::Viridis,
                range: None,
                pixel_size: Some(data[ri].dx),
            },
        )?;
        let lattices = data
            .iter()
            .zip(&names)
            .map(|(d, n)| {
                format!(
                    "{n}: dx {} mm, C = {}, lonely {}, ended at {:.2} s with {:.1} % of the paste at tau_max after {:.0} s of wall time",
                    d.dx * 1e3,
                    d.smagorinsky,
                    d.lonely,
                    d.time,
                    100.0 * d.rigid_share,
                    d.wall_seconds
                )
            })
            .collect::<Vec<_>>()
            .join("; ");
        Ok(StageOutput {
            summary: serde_json::json!({
                "reference": p.reference,
                "threshold": h,
                "runs": names.iter().enumerate().map(|(k, n)| serde_json::json!({
                    "name": n, "dx": data[k].dx, "wall_seconds": data[k].wall_seconds,
                    "time": data[k].time, "rigid_share": data[k].rigid_share,
                    "area": rows[k].0, "x_max": rows[k].1, "width": rows[k].2,
                    "outline_difference": rows[k].3,
                })).collect::<Vec<_>>(),
            }),
            figures: vec![
                Figure {
                    path: "outlines.png".into(),
                    caption: format!(
                        "Edge cells of the paste's footprint (at least {} mm thick) at the end of each run. {lattices}.",
                        h * 1e3
                    ),
                },
                Figure {
                    path: "outline_vs_wall_time.png".into(),
                    caption: format!(
                        "Share of the {} run's footprint where exactly one run has paste, against each run's wall time.",
                        p.reference
                    ),
                },
                Figure {
                    path: "section.png".into(),
                    caption: format!(
                        "Dynamic viscosity on the longitudinal section through the middle of the board at the end of the {} \
                         run (x down the board, y normal to it; grey: no paste).",
                        p.reference
                    ),
                },
            ],
            tables: vec![Table {
                path: "incline_outlines.csv".into(),
                caption: "Every run: lattice, options, end, wall time, footprint and its difference from the reference"
                    .into(),
            }],
            files: vec![
                "incline_outlines.csv".into(),
                "outlines.png".into(),
                "outline_vs_wall_time.png".into(),
                "section.png".into(),
            ],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn board(dx: f64, nx: usize, nz: usize, wet: impl Fn(f64, f64) -> bool) -> Board {
        let mut t = Array2::zeros((nx, nz));
        for ((i, k), v) in t.indexed_iter_mut() {
            if wet((i as f64 + 0.5) * dx, (k as f64 + 0.5) * dx) {
                *v = 0.02;
            }
        }
        Board { dx, t }
    }

    /// A rectangle of paste and the same rectangle on a lattice twice as coarse, shifted by one
    /// coarse cell down the board: the cells where exactly one has paste are the two strips of
    /// one coarse cell each, 2 x 0.01 x 0.2 m² over the 0.1 x 0.2 m² footprint, 0.2; the same
    /// rectangle on the coarse grid is 0.
    #[test]
    fn the_outline_difference_of_a_shifted_rectangle_is_its_two_strips() {
        let fine = board(0.005, 60, 60, |x, z| {
            (0.05..0.15).contains(&x) && (0.05..0.25).contains(&z)
        });
        let same = board(0.01, 30, 30, |x, z| {
            (0.05..0.15).contains(&x) && (0.05..0.25).contains(&z)
        });
        let moved = board(0.01, 30, 30, |x, z| {
            (0.06..0.16).contains(&x) && (0.05..0.25).contains(&z)
        });
        let (area, x_max, width) = fine.footprint(0.005);
        assert!((area - 0.02).abs() < 1e-12 && (x_max - 0.15).abs() < 1e-12 && (width - 0.2).abs() < 1e-12);
        assert_eq!(same.outline_difference(&fine, 0.005), 0.0);
        let d = moved.outline_difference(&fine, 0.005);
        assert!((d - 0.2).abs() < 1e-12, "{d}");
        // below the threshold nothing counts
        assert!(fine.outline_difference(&fine, 0.05).is_nan());
        let (x, _) = fine.outline(0.005);
        // the edge of a 20 x 40 cell rectangle: 2 (20 + 40) - 4 cells
        assert_eq!(x.len(), 116);
    }

    #[test]
    fn a_missing_run_and_a_wrong_reference_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let ctx = StageContext::new(
            dir.path().to_path_buf(),
            "outlines".into(),
            dir.path().to_path_buf(),
        );
        let p = Params {
            runs: vec![RunRef {
                name: "5 mm".into(),
                dir: "nowhere".into(),
            }],
            reference: "2 mm".into(),
            threshold: threshold(),
        };
        let e = InclineOutlines::run(&p, &ctx).unwrap_err().to_string();
        assert!(e.contains("reference = \"2 mm\"") && e.contains("5 mm"), "{e}");
        let p = Params {
            reference: "5 mm".into(),
            ..p
        };
        let e = format!("{:#}", InclineOutlines::run(&p, &ctx).unwrap_err());
        assert!(e.contains("stage.json") && e.contains("nowhere"), "{e}");
    }
}
