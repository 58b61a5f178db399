//! Reader of the digitise stage's circle file: CSV with a header naming the columns
//! `grain_id,x,y,r` (any order, extra columns ignored; one row per circle; rows of one grain
//! form a rigid clump), plus an optional JSON header beside it (`NAME.json` for `NAME.csv`):
//! `{"units": "m" | "px", "pixel_size": metres per pixel}`. Without the header, metres.

use anyhow::{Context, Result, bail};
use lbdem_dem::{Ball, Bodies, ClumpShape, Vec2};
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
    let scale = if header_path.exists() {
        let h: Header = serde_json::from_str(
            &std::fs::read_to_string(&header_path)
                .with_context(|| format!("cannot read {}", header_path.display()))?,
        )
        .with_context(|| {
            format!(
                "{}: expected {{\"units\": \"m\"|\"px\", \"pixel_size\": ...}}",
                header_path.display()
            )
        })?;
        match (h.units.as_str(), h.pixel_size) {
            ("m", _) => 1.0,
            ("px", Some(s)) if s > 0.0 => s,
            (u, s) => bail!(
                "{}: units = {u:?}, pixel_size = {s:?}; use units \"m\", or \"px\" with a positive pixel_size in metres",
                header_path.display()
            ),
        }
    } else {
        1.0
    };
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
    let (_, head) = lines
        .next()
        .with_context(|| format!("{}: empty file; expected a header grain_id,x,y,r", path.display()))?;
    let cols: Vec<&str> = head.split(',').map(str::trim).collect();
    let idx = |name: &str| {
        cols.iter().position(|c| *c == name).with_context(|| {
            format!(
                "{}: header {head:?} has no column {name:?}; need grain_id,x,y,r",
                path.display()
            )
        })
    };
    // A particle snapshot of a run (`body,circle,...,x,y,r,...`) reads back too: its `body`
    // column is the grain id.
    let ig = match cols.iter().position(|c| *c == "body") {
        Some(k) if !cols.contains(&"grain_id") => k,
        _ => idx("grain_id")?,
    };
    let (ix, iy, ir) = (idx("x")?, idx("y")?, idx("r")?);
    let mut grains: BTreeMap<i64, Vec<Ball<Vec2>>> = BTreeMap::new();
    for (ln, line) in lines {
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        let num = |k: usize, name: &str| -> Result<f64> {
            f.get(k).and_then(|s| s.parse::<f64>().ok()).with_context(|| {
                format!(
                    "{} line {}: column {name} is missing or not a number in {line:?}",
                    path.display(),
                    ln + 1
                )
            })
        };
        let g = num(ig, "grain_id")? as i64;
        let ball = Ball {
            centre: Vec2::new(num(ix, "x")? * scale, num(iy, "y")? * scale),
            r: num(ir, "r")? * scale,
        };
        if ball.r.is_nan() || ball.r <= 0.0 {
            bail!(
                "{} line {}: r = {} must be positive",
                path.display(),
                ln + 1,
                ball.r
            );
        }
        grains.entry(g).or_default().push(ball);
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
