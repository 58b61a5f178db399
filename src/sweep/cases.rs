//! A sweep's cases: the axes crossed (first axis outermost), the replicas innermost, each case a
//! pipeline ready for the runner in a directory named by a hash of what defines it (the base's
//! path and every key the case sets). A rerun finds the same directory, where the runner's own
//! cache skips a finished case, resumes an interrupted one and reruns one whose inputs changed.

use super::schema::{Base, Sweep, flatten};
use crate::pipeline::schema::{Pipeline, StageSpec};
use anyhow::{Context, Result, bail};
use serde::Serialize;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The string in a setting's value that becomes the case's directory (absolute), so a pipeline
/// case can point a later stage at an earlier one's output: `"{case}/assembly/snapshots"`.
pub const CASE_DIR: &str = "{case}";

/// One case of a sweep.
#[derive(Debug)]
pub struct Case {
    /// Position in the sweep's order (the row order of its tables).
    pub index: usize,
    /// Directory name under `<out>/cases/`: the axis values, then a hash of the definition.
    pub id: String,
    pub dir: PathBuf,
    /// The value of every axis, in the sweep's axis order.
    pub axes: Vec<(String, toml::Value)>,
    /// Replica number and the value its key got.
    pub replica: Option<(usize, i64)>,
    /// Every key the case sets (the sweep's `[set]`, its axes and zips, its replica), in order.
    pub settings: Vec<(String, toml::Value)>,
    /// The base file with the axis values in its path, relative to the sweep file.
    pub base: String,
    pub pipeline: Pipeline,
}

/// What `case.json` records of a case.
#[derive(Serialize)]
pub struct CaseRecord<'a> {
    pub id: &'a str,
    pub base: &'a str,
    pub axes: Vec<(&'a str, serde_json::Value)>,
    pub replica: Option<(usize, i64)>,
    pub settings: Vec<(&'a str, serde_json::Value)>,
}

impl Case {
    pub fn record(&self) -> CaseRecord<'_> {
        let j = |v: &toml::Value| serde_json::to_value(v).unwrap_or(serde_json::Value::Null);
        CaseRecord {
            id: &self.id,
            base: &self.base,
            axes: self.axes.iter().map(|(k, v)| (k.as_str(), j(v))).collect(),
            replica: self.replica,
            settings: self.settings.iter().map(|(k, v)| (k.as_str(), j(v))).collect(),
        }
    }

    /// `pk=84; rate=30; replica 2`: the case for people.
    pub fn label(&self) -> String {
        let mut parts: Vec<String> = self
            .axes
            .iter()
            .map(|(k, v)| format!("{k}={}", plain(v)))
            .collect();
        if let Some((k, _)) = self.replica {
            parts.push(format!("replica {k}"));
        }
        if parts.is_empty() {
            "the base case".into()
        } else {
            parts.join("; ") // no comma: the label is a cell of cases.csv
        }
    }
}

/// A TOML value as written in a path or a label: strings without quotes.
pub fn plain(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => s.clone(),
        v => v.to_string(),
    }
}

/// Every case of `sweep`, writing under `out` (the sweep's output directory), each checked
/// against its scene or pipeline before anything runs.
pub fn expand(sweep: &Sweep, out: &Path) -> Result<Vec<Case>> {
    let axes: Vec<(&super::schema::Axis, Vec<toml::Value>)> = sweep
        .axes
        .iter()
        .map(|a| Ok((a, a.values()?)))
        .collect::<Result<_>>()?;
    let points = axes.iter().map(|(_, v)| v.len()).product::<usize>();
    let replicas = sweep.replicas.as_ref().map_or(1, |r| r.count);
    let out_abs = std::path::absolute(out).with_context(|| format!("output directory {}", out.display()))?;
    let mut cases = Vec::with_capacity(points * replicas);
    for point in 0..points {
        // Mixed radix, the last axis fastest.
        let mut rest = point;
        let mut picks = vec![0; axes.len()];
        for (k, (_, v)) in axes.iter().enumerate().rev() {
            picks[k] = rest % v.len();
            rest /= v.len();
        }
        for r in 0..replicas {
            let mut settings = sweep.set.clone();
            let mut axis_values = Vec::new();
            for ((a, values), &i) in axes.iter().zip(&picks) {
                let v = values[i].clone();
                if let Some(key) = &a.key {
                    settings.push((key.clone(), v.clone()));
                }
                let mut zipped = Vec::new();
                flatten("", &a.zip, &mut zipped);
                for (k, list) in zipped {
                    if let Some(x) = list.as_array().and_then(|l| l.get(i)) {
                        settings.push((k, x.clone()));
                    }
                }
                axis_values.push((a.name.clone(), v));
            }
            let replica = sweep.replicas.as_ref().map(|rp| {
                let seed = rp.first + r as i64;
                settings.push((rp.key.clone(), toml::Value::Integer(seed)));
                (r, seed)
            });
            let mut base = sweep.base.template().to_string();
            for (name, v) in &axis_values {
                base = base.replace(&format!("{{{name}}}"), &plain(v));
            }
            let id = case_id(&sweep.base, &base, &axis_values, replica, &settings);
            let dir = out_abs.join("cases").join(&id);
            let dir_text = dir.to_string_lossy().into_owned();
            let resolved: Vec<(String, toml::Value)> = settings
                .iter()
                .map(|(k, v)| (k.clone(), substitute(v, &dir_text)))
                .collect();
            let index = cases.len();
            let pipeline = build(sweep, &base, &id, &dir, &resolved).with_context(|| {
                format!(
                    "sweep file {}: case {} ({})",
                    sweep.file.display(),
                    index,
                    describe(&axis_values, replica)
                )
            })?;
            cases.push(Case {
                index,
                id,
                dir,
                axes: axis_values,
                replica,
                settings,
                base,
                pipeline,
            });
        }
    }
    Ok(cases)
}

fn describe(axes: &[(String, toml::Value)], replica: Option<(usize, i64)>) -> String {
    let mut s: Vec<String> = axes.iter().map(|(k, v)| format!("{k} = {v}")).collect();
    if let Some((r, seed)) = replica {
        s.push(format!("replica {r} (seed {seed})"));
    }
    s.join(", ")
}

/// `pk84_rate30_r2-<10 hex>`: readable, and unique by the hash of the case's definition.
fn case_id(
    base: &Base,
    path: &str,
    axes: &[(String, toml::Value)],
    replica: Option<(usize, i64)>,
    settings: &[(String, toml::Value)],
) -> String {
    let mut h = Sha256::new();
    let kind = match base {
        Base::Scene(_) => "scene",
        Base::Pipeline(_) => "pipeline",
    };
    for part in [kind, path] {
        h.update(part.as_bytes());
        h.update([0]);
    }
    for (k, v) in settings {
        h.update(k.as_bytes());
        h.update([0]);
        h.update(serde_json::to_string(v).unwrap_or_default().as_bytes());
        h.update([0]);
    }
    let hash = hex::encode(h.finalize());
    let mut label: String = axes
        .iter()
        .map(|(k, v)| format!("{k}{}", plain(v)))
        .chain(replica.map(|(r, _)| format!("r{r}")))
        .collect::<Vec<_>>()
        .join("_")
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' || c == '_' {
                c
            } else {
                '-'
            }
        })
        .take(48)
        .collect();
    if !label.is_empty() {
        label.push('-');
    }
    format!("{label}{}", &hash[..10])
}

/// `v` with every `{case}` in its strings replaced by the case's directory.
fn substitute(v: &toml::Value, dir: &str) -> toml::Value {
    match v {
        toml::Value::String(s) => toml::Value::String(s.replace(CASE_DIR, dir)),
        toml::Value::Array(a) => toml::Value::Array(a.iter().map(|x| substitute(x, dir)).collect()),
        toml::Value::Table(t) => {
            toml::Value::Table(t.iter().map(|(k, x)| (k.clone(), substitute(x, dir))).collect())
        }
        v => v.clone(),
    }
}

/// The case's pipeline: the scene as one `simulate` stage, or the pipeline file with the
/// settings applied to its stages (`STAGE.key...`).
fn build(
    sweep: &Sweep,
    base: &str,
    id: &str,
    dir: &Path,
    settings: &[(String, toml::Value)],
) -> Result<Pipeline> {
    match &sweep.base {
        Base::Scene(_) => {
            let scene = sweep.dir.join(base);
            let overrides = scene_overrides(&scene, &toml::Table::new(), settings)?;
            crate::scenes::schema::load(&scene, &overrides)?;
            let mut params = toml::Table::new();
            params.insert("scene".into(), toml::Value::String(base.to_string()));
            params.insert("overrides".into(), toml::Value::Table(overrides));
            Ok(Pipeline {
                name: id.to_string(),
                root: sweep.dir.clone(),
                out: dir.to_path_buf(),
                stages: vec![StageSpec {
                    name: "simulate".into(),
                    kind: "simulate".into(),
                    params: toml::Value::Table(params),
                }],
            })
        }
        Base::Pipeline(_) => {
            let file = sweep.dir.join(base);
            let mut p = Pipeline::load(&file)?;
            p.out = dir.to_path_buf();
            for (key, value) in settings {
                let (stage, rest) = key.split_once('.').with_context(|| {
                    format!("key \"{key}\": a pipeline's keys start with a stage name, e.g. \"simulate.overrides.run.steps\"")
                })?;
                let names: Vec<String> = p.stages.iter().map(|s| s.name.clone()).collect();
                let spec = p.stages.iter_mut().find(|s| s.name == stage).with_context(|| {
                    format!(
                        "key \"{key}\": the pipeline {} has no stage '{stage}'; stages: {names:?}",
                        file.display()
                    )
                })?;
                let scene_key = rest
                    .strip_prefix("overrides.")
                    .filter(|_| spec.kind == "simulate");
                match scene_key {
                    Some(inner) => {
                        let params = spec
                            .params
                            .as_table_mut()
                            .context("stage params are not a table")?;
                        let scene = params
                            .get("scene")
                            .and_then(|s| s.as_str())
                            .with_context(|| format!("stage '{stage}' has no scene = \"...\""))?;
                        let scene = p.root.join(scene);
                        let old = match params.get("overrides") {
                            Some(toml::Value::Table(t)) => t.clone(),
                            _ => toml::Table::new(),
                        };
                        let new = scene_overrides(&scene, &old, &[(inner.to_string(), value.clone())])
                            .with_context(|| format!("key \"{key}\""))?;
                        params.insert("overrides".into(), toml::Value::Table(new));
                    }
                    None => {
                        let parts: Vec<&str> = rest.split('.').collect();
                        set_path(&mut spec.params, &parts, value.clone())
                            .with_context(|| format!("key \"{key}\""))?;
                    }
                }
            }
            for spec in &p.stages {
                let ctx = crate::contract::StageContext::new(
                    dir.join(&spec.name),
                    spec.name.clone(),
                    p.root.clone(),
                );
                crate::registry::find(&spec.kind)?.prepare(spec.params.clone(), &ctx)?;
                if spec.kind == "simulate"
                    && let Some(scene) = spec.params.get("scene").and_then(|s| s.as_str())
                {
                    let over = match spec.params.get("overrides") {
                        Some(toml::Value::Table(t)) => t.clone(),
                        _ => toml::Table::new(),
                    };
                    crate::scenes::schema::load(&p.root.join(scene), &over)
                        .with_context(|| format!("stage '{}'", spec.name))?;
                }
            }
            Ok(p)
        }
    }
}

/// The overrides of a scene that set `settings` (dotted keys; arrays by index or by the `name`
/// of their tables) over `old`. A key inside an array replaces the whole array with the
/// scene's own, changed in that one place, because overrides replace arrays whole.
pub fn scene_overrides(
    scene: &Path,
    old: &toml::Table,
    settings: &[(String, toml::Value)],
) -> Result<toml::Table> {
    let mut tree = toml::Value::Table(crate::scenes::schema::merged_table(scene)?);
    merge_into(&mut tree, old);
    let mut prefixes = Vec::new();
    for (key, value) in settings {
        let parts: Vec<&str> = key.split('.').collect();
        if parts.iter().any(|p| p.trim().is_empty()) {
            bail!("key \"{key}\" has an empty part; write e.g. \"run.steps\"");
        }
        let first_array =
            set_path(&mut tree, &parts, value.clone()).with_context(|| format!("key \"{key}\""))?;
        let n = first_array.unwrap_or(parts.len());
        prefixes.push(parts[..n].iter().map(|s| s.to_string()).collect::<Vec<_>>());
    }
    let mut over = old.clone();
    for prefix in prefixes {
        let mut src = &tree;
        for p in &prefix {
            src = src.get(p.as_str()).context("internal: a set key vanished")?;
        }
        let mut dst = &mut over;
        for p in &prefix[..prefix.len() - 1] {
            let slot = dst
                .entry(p.clone())
                .or_insert_with(|| toml::Value::Table(Default::default()));
            if !slot.is_table() {
                *slot = toml::Value::Table(Default::default());
            }
            dst = slot.as_table_mut().context("internal: not a table")?;
        }
        dst.insert(prefix[prefix.len() - 1].clone(), src.clone());
    }
    Ok(over)
}

fn merge_into(base: &mut toml::Value, over: &toml::Table) {
    let Some(b) = base.as_table_mut() else { return };
    for (k, v) in over {
        match (b.get_mut(k), v) {
            (Some(inner @ toml::Value::Table(_)), toml::Value::Table(o)) => merge_into(inner, o),
            _ => {
                b.insert(k.clone(), v.clone());
            }
        }
    }
}

/// Set `value` at `parts` in `tree`: tables by key (created when missing), arrays by index or
/// by the `name` of their tables. Returns the depth of the first array on the path.
pub fn set_path(tree: &mut toml::Value, parts: &[&str], value: toml::Value) -> Result<Option<usize>> {
    let mut cur = tree;
    let mut first_array = None;
    for (depth, part) in parts.iter().enumerate() {
        let last = depth + 1 == parts.len();
        cur = match cur {
            toml::Value::Table(t) => {
                if last {
                    t.insert((*part).to_string(), value);
                    return Ok(first_array);
                }
                t.entry(*part)
                    .or_insert_with(|| toml::Value::Table(Default::default()))
            }
            toml::Value::Array(a) => {
                first_array.get_or_insert(depth);
                let len = a.len();
                let slot = match part.parse::<usize>() {
                    Ok(i) if i < len => &mut a[i],
                    Ok(i) => bail!("index {i} is past the end of a list of {len}"),
                    Err(_) => {
                        let names: Vec<String> = a
                            .iter()
                            .filter_map(|x| x.get("name").and_then(|n| n.as_str()).map(str::to_string))
                            .collect();
                        let pos = a
                            .iter()
                            .position(|x| x.get("name").and_then(|n| n.as_str()) == Some(*part))
                            .with_context(|| {
                                format!("no entry of the list is named '{part}'; named entries: {names:?}")
                            })?;
                        &mut a[pos]
                    }
                };
                if last {
                    *slot = value;
                    return Ok(first_array);
                }
                slot
            }
            other => bail!("'{part}' is inside {other}, which is neither a table nor a list"),
        };
    }
    Ok(first_array)
}
