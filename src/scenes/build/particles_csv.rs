//! Reader of the digitise stage's circle file: CSV with a header naming the columns
//! `grain_id,x,y,r` (any order, extra columns ignored; one row per circle; rows of one grain
//! form a rigid clump), plus an optional JSON header beside it (`NAME.json` for `NAME.csv`):
//! `{"units": "m" | "px", "pixel_size": metres per pixel}`. Without the header, metres.

use anyhow::{Context, Result, bail};
use lbdem_dem::{Ball, Bodies, ClumpShape, Vec2, Vector};
use polars::prelude::{CsvReadOptions, DataType, SerReader};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Deserialize)]
struct Header {
    #[serde(default = "metres")]
    units: String,
    #[serde(default)]
    pixel_size: Option<f64>,
}

fn metres() -> String {
    "m".into()
}

pub fn read_csv(path: &Path, density: f64) -> Result<Bodies> {
    read_csv_in(path, density, None)
}

/// [`read_csv`], refusing a circle whose centre lies outside `domain` ([lo, hi] in m) with its
/// line: a file in the wrong units or of another scene, caught before anything runs.
pub fn read_csv_in(path: &Path, density: f64, domain: Option<([f64; 2], [f64; 2])>) -> Result<Bodies> {
    let newest;
    let path = if path.is_dir() {
        newest = newest_snapshot(path)?;
        newest.as_path()
    } else {
        path
    };
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read particle file {}", path.display()))?;
    let header_path = path.with_extension("json");
    let header = if header_path.exists() {
        Some(
            std::fs::read_to_string(&header_path)
                .with_context(|| format!("cannot read {}", header_path.display()))?,
        )
    } else {
        None
    };
    let rows = parse(&text, header.as_deref(), path)?;
    if let Some((lo, hi)) = domain {
        inside(&rows, lo, hi, path)?;
    }
    coincident(&rows, path)?;
    let mut grains: BTreeMap<i64, Vec<Ball<Vec2>>> = BTreeMap::new();
    for r in rows {
        grains.entry(r.grain).or_default().push(r.ball);
    }
    let mut bodies = Bodies::new();
    for balls in grains.into_values() {
        let shape = ClumpShape { balls };
        let c = shape.mass_props().context("particle file")?.centroid;
        bodies
            .add(&shape, density, c, 0.0)
            .with_context(|| format!("{}", path.display()))?;
    }
    Ok(bodies)
}

/// One circle of the file and the line (from 1) it came from.
#[derive(Clone, Debug)]
pub struct Row {
    pub line: usize,
    pub grain: i64,
    pub ball: Ball<Vec2>,
}

/// The circles of a particle file's `text` (`header`: the JSON beside it, if any), scaled to
/// metres; every value checked (whole grain ids, finite positions, positive finite radii).
pub fn parse(text: &str, header: Option<&str>, path: &Path) -> Result<Vec<Row>> {
    let header_path = path.with_extension("json");
    let scale = match header {
        Some(json) => {
            let h: Header = serde_json::from_str(json).with_context(|| {
                format!(
                    "{}: expected {{\"units\": \"m\"|\"px\", \"pixel_size\": ...}}",
                    header_path.display()
                )
            })?;
            match (h.units.as_str(), h.pixel_size) {
                ("m", _) => 1.0,
                ("px", Some(s)) if s > 0.0 && s.is_finite() => s,
                (u, s) => bail!(
                    "{}: units = {u:?}, pixel_size = {s:?}; use units \"m\", or \"px\" with a positive pixel_size in metres",
                    header_path.display()
                ),
            }
        }
        None => 1.0,
    };
    // Comment and blank lines out, so that data row k of the table is `lines[k + 1]` (the line
    // numbers of the messages); polars reads the table, every cell as text, and each value is
    // checked here with its line.
    let lines: Vec<(usize, &str)> = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'))
        .collect();
    let Some(&(_, head)) = lines.first() else {
        bail!("{}: empty file; expected a header grain_id,x,y,r", path.display());
    };
    let clean: String = lines.iter().flat_map(|(_, l)| [*l, "\n"]).collect();
    let df = CsvReadOptions::default()
        .with_has_header(true)
        .with_infer_schema_length(Some(0))
        .map_parse_options(|o| o.with_truncate_ragged_lines(true).with_missing_is_null(true))
        .into_reader_with_file_handle(std::io::Cursor::new(clean.as_bytes()))
        .finish()
        .map_err(|e| {
            anyhow::anyhow!(
                "{}: not a CSV table with a header grain_id,x,y,r: {e}",
                path.display()
            )
        })?;
    let cols: Vec<String> = df
        .get_column_names()
        .iter()
        .map(|c| c.trim().to_string())
        .collect();
    let idx = |name: &str| {
        cols.iter().position(|c| c == name).with_context(|| {
            format!(
                "{}: header {head:?} has no column {name:?}; need grain_id,x,y,r",
                path.display()
            )
        })
    };
    // A particle snapshot of a run (`body,circle,...,x,y,r,...`) reads back too: its `body`
    // column is the grain id.
    let ig = match cols.iter().position(|c| c == "body") {
        Some(k) if !cols.iter().any(|c| c == "grain_id") => k,
        _ => idx("grain_id")?,
    };
    let (ix, iy, ir) = (idx("x")?, idx("y")?, idx("r")?);
    let text_col = |k: usize| -> Result<Vec<Option<String>>> {
        let c = df.columns()[k].cast(&DataType::String)?;
        Ok(c.str()?.iter().map(|v| v.map(|s| s.trim().to_string())).collect())
    };
    let [g_col, x_col, y_col, r_col] = [ig, ix, iy, ir].map(text_col);
    let (g_col, x_col, y_col, r_col) = (g_col?, x_col?, y_col?, r_col?);
    let mut rows = Vec::new();
    for row in 0..df.height() {
        let (ln, line) = lines[row + 1];
        let at = || format!("{} line {}", path.display(), ln + 1);
        let num = |col: &[Option<String>], name: &str| -> Result<f64> {
            let v = col[row]
                .as_deref()
                .and_then(|s| s.parse::<f64>().ok())
                .with_context(|| format!("{}: column {name} is missing or not a number in {line:?}", at()))?;
            if !v.is_finite() {
                bail!(
                    "{}: {name} = {v}: every value must be a finite number; fix the row",
                    at()
                );
            }
            Ok(v)
        };
        let g = num(&g_col, "grain_id")?;
        if g.fract() != 0.0 || g.abs() > 9.0e15 {
            bail!(
                "{}: grain_id = {g} is not a whole number; grain ids are integers (rows of one grain share one)",
                at()
            );
        }
        let ball = Ball {
            centre: Vec2::new(num(&x_col, "x")? * scale, num(&y_col, "y")? * scale),
            r: num(&r_col, "r")? * scale,
        };
        if !(ball.r > 0.0 && ball.r.is_finite()) {
            bail!("{}: r = {} must be positive", at(), ball.r);
        }
        rows.push(Row {
            line: ln + 1,
            grain: g as i64,
            ball,
        });
    }
    Ok(rows)
}

/// Refuse a circle whose centre lies outside [lo, hi] (a radius larger than the box is a file
/// in other units).
fn inside(rows: &[Row], lo: [f64; 2], hi: [f64; 2], path: &Path) -> Result<()> {
    let side = (hi[0] - lo[0]).min(hi[1] - lo[1]);
    for r in rows {
        let c = r.ball.centre;
        if c.x < lo[0] || c.x > hi[0] || c.y < lo[1] || c.y > hi[1] {
            bail!(
                "{} line {}: the circle at ({}, {}) m lies outside the [domain] box [{}, {}] x [{}, {}] m; \
                 is the file in other units (give NAME.json with \"units\": \"px\" and the pixel_size) or of \
                 another scene? Move the circle inside or enlarge [domain]",
                path.display(),
                r.line,
                c.x,
                c.y,
                lo[0],
                hi[0],
                lo[1],
                hi[1]
            );
        }
        if r.ball.r > 0.5 * side {
            bail!(
                "{} line {}: r = {} m is more than half the [domain] box ({side} m across); is the file in \
                 other units (mm or pixels: give NAME.json with \"units\": \"px\" and the pixel_size)?",
                path.display(),
                r.line,
                r.ball.r
            );
        }
    }
    Ok(())
}

/// Refuse two circles of different grains with the same centre (their contact has no normal:
/// the first step would be NaN).
fn coincident(rows: &[Row], path: &Path) -> Result<()> {
    let mut order: Vec<usize> = (0..rows.len()).collect();
    order.sort_by(|&a, &b| rows[a].ball.centre.x.total_cmp(&rows[b].ball.centre.x));
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            let (p, q) = (&rows[a], &rows[b]);
            let tol = 1e-9 * (p.ball.r + q.ball.r);
            if q.ball.centre.x - p.ball.centre.x > tol {
                break;
            }
            if p.grain != q.grain && (q.ball.centre - p.ball.centre).norm() <= tol {
                let (first, second) = (p.line.min(q.line), p.line.max(q.line));
                bail!(
                    "{} lines {first} and {second}: circles of grains {} and {} have the same centre ({}, {}) m; \
                     two grains cannot sit on one point (their contact has no direction): remove or move one",
                    path.display(),
                    p.grain.min(q.grain),
                    p.grain.max(q.grain),
                    p.ball.centre.x,
                    p.ball.centre.y
                );
            }
        }
    }
    Ok(())
}

/// The newest particle snapshot (`particles_<step>.csv`, highest step) in a run's snapshot
/// directory: a scene continues from where another run ended (Su Float: the second 10 % cut).
pub fn newest_snapshot(dir: &Path) -> Result<std::path::PathBuf> {
    let mut v: Vec<std::path::PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot list {}", dir.display()))?
        .flatten()
        .map(|e| e.path())
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with("particles_") && n.ends_with(".csv"))
        })
        .collect();
    v.sort();
    v.pop().with_context(|| {
        format!(
            "{} holds no particles_<step>.csv snapshot: give a particle file, or the snapshots \
             directory of a finished run",
            dir.display()
        )
    })
}
