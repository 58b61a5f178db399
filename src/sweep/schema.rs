//! The sweep file: a base scene or pipeline, axes of parameters (crossed with each other; keys
//! zipped within an axis), random replicas, and the scalar results each case reports.
//!
//! ```toml
//! [sweep]
//! name = "su2020-ci"                                   # default: the file's stem
//! scene = "../scenes/su2020/reduced-shear-cell.toml"   # or pipeline = "...": exactly one
//! out = "../runs/su2020-ci"                            # default: out/<name>
//!
//! [set]                                                # every case
//! "dem.mass_scale" = 100.0
//!
//! [[axis]]                                             # axes are crossed
//! name = "rate"
//! key = "walls.plate.velocity.1"                       # arrays: by index or by `name`
//! values = [1.0e-3, 2.5e-3]                            # or range = { from, to, count, log }
//! zip = { "run.until_wall_moved.distance" = [2e-4, 3e-4] }   # in step with the values
//!
//! [replicas]
//! count = 4
//! key = "particles.generate.seed"                      # replica k gets first + k
//!
//! [[result]]
//! name = "eps_vol_1d"
//! column = "eps_vol_dem"                               # of series.csv (or `table`)
//! at = { column = "plate_displacement_d", value = 1.0 }
//! ```
//!
//! Format and every key: docs/sweeps.md.

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use std::collections::HashSet;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct File {
    sweep: Header,
    #[serde(default)]
    set: toml::Table,
    #[serde(default)]
    axis: Vec<Axis>,
    #[serde(default)]
    replicas: Option<Replicas>,
    #[serde(default)]
    result: Vec<ResultSpec>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Header {
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    scene: Option<String>,
    #[serde(default)]
    pipeline: Option<String>,
    #[serde(default)]
    out: Option<PathBuf>,
    #[serde(default)]
    parallel: usize,
    #[serde(default)]
    threads: usize,
    #[serde(default)]
    interleave: bool,
}

/// What every case runs: a scene file (as `lbdem simulate`) or a pipeline file (as `lbdem run`).
/// The path may hold `{axis}` placeholders, replaced by the case's value of that axis.
#[derive(Clone, Debug, PartialEq, Eq, Serialize)]
pub enum Base {
    Scene(String),
    Pipeline(String),
}

impl Base {
    pub fn template(&self) -> &str {
        match self {
            Base::Scene(s) | Base::Pipeline(s) => s,
        }
    }
}

/// `range = { from = 1e-3, to = 3e-3, count = 3 }`: `count` values from `from` to `to`, both
/// included; `log = true` spaces them geometrically.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Range {
    pub from: f64,
    pub to: f64,
    pub count: usize,
    #[serde(default)]
    pub log: bool,
}

/// One axis: a name (its column in the tables, `{name}` in the base's path), the values it
/// takes, the key each value sets, and keys that change in step with it (`zip`).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Axis {
    pub name: String,
    #[serde(default)]
    pub key: Option<String>,
    #[serde(default)]
    pub values: Option<Vec<toml::Value>>,
    #[serde(default)]
    pub range: Option<Range>,
    #[serde(default)]
    pub zip: toml::Table,
}

/// `[replicas]`: `count` random realisations of every point of the axes; replica k sets `key`
/// to `first + k` (an assembly seed, a wall realisation).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Replicas {
    pub count: usize,
    pub key: String,
    #[serde(default = "one")]
    pub first: i64,
}

fn one() -> i64 {
    1
}

/// How a series column becomes one number.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum Reduce {
    #[default]
    Last,
    First,
    Min,
    Max,
    Mean,
}

/// `at = { column = "plate_displacement_d", value = 10.0 }`: where `column` first reaches
/// `value` (linear interpolation between the two rows around it).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct At {
    pub column: String,
    pub value: f64,
}

/// `[[result]]`: one scalar per case, from a stage's summary (`summary = "dotted.path"`) or a
/// column of one of its tables (`column`, with `at` or `reduce`).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ResultSpec {
    pub name: String,
    /// The stage whose directory holds it (pipelines; default: the last stage but reports).
    #[serde(default)]
    pub stage: Option<String>,
    #[serde(default)]
    pub summary: Option<String>,
    #[serde(default)]
    pub column: Option<String>,
    /// The table holding `column` (default `series.csv`).
    #[serde(default)]
    pub table: Option<PathBuf>,
    #[serde(default)]
    pub at: Option<At>,
    #[serde(default)]
    pub reduce: Option<Reduce>,
    /// Unit for the tables and charts, e.g. "N" or "-".
    #[serde(default)]
    pub unit: Option<String>,
}

/// A sweep file, parsed and checked.
#[derive(Debug)]
pub struct Sweep {
    pub name: String,
    pub file: PathBuf,
    /// The sweep file's directory: the base and `out` resolve from here.
    pub dir: PathBuf,
    pub base: Base,
    pub out: PathBuf,
    pub parallel: usize,
    pub threads: usize,
    /// Run replica by replica (every point of the first replica, then of the second ...) so that
    /// paired cases run close in time and their wall-time ratio is fair on a shared machine.
    pub interleave: bool,
    pub set: Vec<(String, toml::Value)>,
    pub axes: Vec<Axis>,
    pub replicas: Option<Replicas>,
    pub results: Vec<ResultSpec>,
}

/// Most cases one sweep may expand to: a typo in a range should not fill a disk.
pub const MAX_CASES: usize = 100_000;

impl Sweep {
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("cannot read sweep file {}", path.display()))?;
        Self::parse(&text, path)
    }

    pub fn parse(text: &str, path: &Path) -> Result<Self> {
        let f: File = toml::from_str(text).with_context(|| {
            format!(
                "sweep file {} is not valid (every key: docs/sweeps.md)",
                path.display()
            )
        })?;
        let at = |m: String| anyhow::anyhow!("sweep file {}: {m}", path.display());
        let base = match (f.sweep.scene, f.sweep.pipeline) {
            (Some(s), None) => Base::Scene(s),
            (None, Some(p)) => Base::Pipeline(p),
            _ => {
                return Err(at(
                    "[sweep] needs exactly one of scene = \"SCENE.toml\" or pipeline = \"PIPELINE.toml\""
                        .into(),
                ));
            }
        };
        let name = f.sweep.name.unwrap_or_else(|| {
            path.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "sweep".into())
        });
        if name.is_empty() || name.contains(['/', '\\']) {
            return Err(at(format!(
                "[sweep] name = {name:?}: give a non-empty name without slashes"
            )));
        }
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let out = match f.sweep.out {
            Some(o) if o.is_absolute() => o,
            Some(o) => dir.join(o),
            None => PathBuf::from("out").join(&name),
        };
        let mut set = Vec::new();
        flatten("", &f.set, &mut set);
        let mut names = HashSet::new();
        for a in &f.axis {
            check_axis(a, &base).map_err(|e| at(format!("[[axis]] '{}': {e}", a.name)))?;
            if !names.insert(a.name.as_str()) {
                return Err(at(format!(
                    "two axes are named '{}'; axis names must be unique",
                    a.name
                )));
            }
            // The tables' own columns: an axis of the same name would make two columns of one
            // name, refused only after every case had run.
            if ["case", "point", "seed"].contains(&a.name.as_str()) {
                return Err(at(format!(
                    "[[axis]] '{}': the name is a column every results table has (case, point, replica, seed); \
                     rename the axis, e.g. '{}_'",
                    a.name, a.name
                )));
            }
        }
        for p in placeholders(base.template()) {
            if !names.contains(p.as_str()) {
                return Err(at(format!(
                    "the base path {:?} holds {{{p}}}, but no [[axis]] is named '{p}'; axes: {:?}",
                    base.template(),
                    names
                )));
            }
        }
        if let Some(r) = &f.replicas {
            if r.count == 0 || r.count > MAX_CASES {
                return Err(at(format!(
                    "[replicas] count = {}: give 1 to {MAX_CASES}",
                    r.count
                )));
            }
            if r.key.trim().is_empty() {
                return Err(at(
                    "[replicas] key is empty; e.g. key = \"particles.generate.seed\"".into(),
                ));
            }
            if names.contains("replica") {
                return Err(at(
                    "an axis is named 'replica', the column of [replicas]; rename the axis".into(),
                ));
            }
        }
        let mut rnames: HashSet<&str> = HashSet::new();
        for r in &f.result {
            check_result(r).map_err(|e| at(format!("[[result]] '{}': {e}", r.name)))?;
            if names.contains(r.name.as_str())
                || r.name == "case"
                || r.name == "replica"
                || !rnames.insert(&r.name)
            {
                return Err(at(format!(
                    "[[result]] name '{}' is taken (by another result, an axis, `case` or `replica`)",
                    r.name
                )));
            }
        }
        let s = Self {
            name,
            file: path.to_path_buf(),
            dir,
            base,
            out,
            parallel: f.sweep.parallel,
            threads: f.sweep.threads,
            interleave: f.sweep.interleave,
            set,
            axes: f.axis,
            replicas: f.replicas,
            results: f.result,
        };
        let n = s.case_count();
        if n > MAX_CASES {
            return Err(at(format!(
                "the axes and replicas make {n} cases, more than {MAX_CASES}; shorten an axis or split the sweep"
            )));
        }
        Ok(s)
    }

    /// How many cases the axes and replicas make (saturating).
    pub fn case_count(&self) -> usize {
        let points = self
            .axes
            .iter()
            .map(|a| a.values().map_or(0, |v| v.len()))
            .fold(1usize, usize::saturating_mul);
        points.saturating_mul(self.replicas.as_ref().map_or(1, |r| r.count))
    }
}

impl Axis {
    /// The values this axis takes, from `values` or `range`.
    pub fn values(&self) -> Result<Vec<toml::Value>> {
        match (&self.values, &self.range) {
            (Some(v), None) => Ok(v.clone()),
            (None, Some(r)) => {
                let ok = r.from.is_finite() && r.to.is_finite() && (1..=MAX_CASES).contains(&r.count);
                if !ok {
                    bail!(
                        "range = {{ from = {}, to = {}, count = {} }}: give finite ends and a count of 1 to {MAX_CASES}",
                        r.from,
                        r.to,
                        r.count
                    );
                }
                if r.log && !(r.from > 0.0 && r.to > 0.0) {
                    bail!(
                        "range with log = true needs from and to above 0 (got {} and {})",
                        r.from,
                        r.to
                    );
                }
                let n = r.count;
                Ok((0..n)
                    .map(|k| {
                        let t = if n == 1 { 0.0 } else { k as f64 / (n - 1) as f64 };
                        let v = match (r.log, k) {
                            (_, 0) => r.from,
                            (_, k) if k + 1 == n => r.to,
                            (true, _) => (r.from.ln() + t * (r.to.ln() - r.from.ln())).exp(),
                            (false, _) => r.from + t * (r.to - r.from),
                        };
                        toml::Value::Float(v)
                    })
                    .collect())
            }
            _ => bail!("give exactly one of values = [...] or range = {{ from, to, count }}"),
        }
    }
}

fn check_axis(a: &Axis, base: &Base) -> Result<()> {
    if a.name.is_empty()
        || !a
            .name
            .chars()
            .all(|c| c.is_alphanumeric() || c == '_' || c == '-')
    {
        bail!("name must be letters, digits, '_' or '-' (it names a table column)");
    }
    let values = a.values()?;
    if values.is_empty() {
        bail!("values is empty; give at least one value");
    }
    if values
        .iter()
        .any(|v| matches!(v, toml::Value::Float(f) if !f.is_finite()))
    {
        bail!("values hold a NaN or infinity");
    }
    let mut zip = Vec::new();
    flatten("", &a.zip, &mut zip);
    for (k, v) in &zip {
        match v.as_array() {
            Some(list) if list.len() == values.len() => {}
            _ => bail!(
                "zip \"{k}\" needs a list of {} values, one per value of the axis",
                values.len()
            ),
        }
    }
    let in_path = placeholders(base.template()).iter().any(|p| p == &a.name);
    if a.key.is_none() && zip.is_empty() && !in_path {
        bail!(
            "the axis changes nothing: give key = \"section.key\", a zip table, or use {{{}}} in the base's path",
            a.name
        );
    }
    Ok(())
}

fn check_result(r: &ResultSpec) -> Result<()> {
    if r.name.is_empty()
        || !r
            .name
            .chars()
            .all(|c| c.is_alphanumeric() || c == '_' || c == '-')
    {
        bail!("name must be letters, digits, '_' or '-' (it names a table column)");
    }
    match (&r.summary, &r.column) {
        (Some(_), None) => {
            if r.at.is_some() || r.reduce.is_some() || r.table.is_some() {
                bail!("at, reduce and table go with column = \"...\", not with summary");
            }
        }
        (None, Some(_)) => {
            if r.at.is_some() && r.reduce.is_some() {
                bail!("give at = {{ column, value }} or reduce, not both");
            }
            if r.at.as_ref().is_some_and(|a| !a.value.is_finite()) {
                bail!("at value must be a finite number");
            }
        }
        _ => bail!(
            "give exactly one of summary = \"dotted.key\" (a stage.json summary value) or column = \"name\" (a table column)"
        ),
    }
    Ok(())
}

/// `{name}` placeholders in a path template.
pub fn placeholders(t: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = t;
    while let Some(i) = rest.find('{') {
        let Some(j) = rest[i..].find('}') else { break };
        out.push(rest[i + 1..i + j].to_string());
        rest = &rest[i + j + 1..];
    }
    out
}

/// A table of keys as (dotted key, value): `"a.b" = 1` and `a = { b = 1 }` alike.
pub fn flatten(prefix: &str, t: &toml::Table, out: &mut Vec<(String, toml::Value)>) {
    for (k, v) in t {
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            toml::Value::Table(inner) if !inner.is_empty() => flatten(&key, inner, out),
            _ => out.push((key, v.clone())),
        }
    }
}
