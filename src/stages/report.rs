//! Stage `report`: one HTML page from the manifests of the pipeline's earlier stages
//! (their figures, tables and summaries) with the provenance block. In a pipeline it
//! writes `index.html` at the top of the pipeline's output directory, so figure links
//! point into the sibling stage directories.

use crate::contract::{
    InputHash, MANIFEST, Provenance, Stage, StageContext, StageOutput, StageProvenance, StageRecord,
    code_version,
};
use anyhow::{Context, Result, bail};
use polars::prelude::{CsvReadOptions, DataType, SerReader};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// Page title.
    pub title: String,
    /// Stages to show, by name, in order (default: every earlier stage).
    #[serde(default)]
    pub stages: Option<Vec<String>>,
    /// Rows of each table shown inline (the full CSV is linked).
    #[serde(default = "default_rows")]
    pub table_rows: usize,
}

fn default_rows() -> usize {
    12
}

pub struct Report;

pub const PAGE: &str = "index.html";

impl Stage for Report {
    const KIND: &'static str = "report";
    const ABOUT: &'static str = "Assemble an HTML report from the outputs of earlier stages";
    type Params = Params;

    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        selected(p, ctx)
            .map(|v| v.into_iter().map(|(_, d)| d.join(MANIFEST)).collect())
            .unwrap_or_default()
    }

    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        let stages = selected(p, ctx)?;
        let page_dir = &ctx.out_dir;
        let mut views = Vec::new();
        for (name, dir) in &stages {
            let path = dir.join(MANIFEST);
            let text = std::fs::read_to_string(&path)
                .with_context(|| format!("report: stage '{name}' has no manifest at {}", path.display()))?;
            let rec: StageRecord = serde_json::from_str(&text)
                .with_context(|| format!("report: {} is not a stage manifest", path.display()))?;
            views.push(stage_view(&rec, dir, page_dir, p.table_rows)?);
        }
        let prov = Provenance::load(ctx.pipeline_dir().unwrap_or(page_dir))
            .unwrap_or_else(|| standalone_provenance(&stages));
        let html = render(&p.title, &views, &prov)?;
        lbdem_core::atomic::write_atomic(&page_dir.join(PAGE), html.as_bytes())?;
        Ok(StageOutput {
            summary: serde_json::json!({ "stages": views.len(), "page": PAGE }),
            files: vec![PathBuf::from(PAGE)],
            ..Default::default()
        })
    }
}

/// The (name, output dir) of the stages to show, in order.
fn selected(p: &Params, ctx: &StageContext) -> Result<Vec<(String, PathBuf)>> {
    match &p.stages {
        None => Ok(ctx.earlier.clone()),
        Some(names) => names
            .iter()
            .map(|n| match ctx.earlier_stage(n) {
                Some(d) => Ok((n.clone(), d.to_path_buf())),
                None if ctx.earlier.is_empty() => Ok((n.clone(), ctx.resolve(Path::new(n)))),
                None => bail!(
                    "report: stages = [... \"{n}\" ...] names no earlier stage; earlier stages: {}",
                    ctx.earlier
                        .iter()
                        .map(|e| e.0.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })
            .collect(),
    }
}

/// Run alone, there is no pipeline provenance: record what can be known.
fn standalone_provenance(stages: &[(String, PathBuf)]) -> Provenance {
    Provenance {
        pipeline_name: "(standalone report)".into(),
        code_version: code_version(),
        pipeline_file: InputHash {
            path: PathBuf::from("-"),
            sha256: String::new(),
            bytes: 0,
        },
        started_unix_s: 0,
        threads: rayon::current_num_threads(),
        simd: lbdem_core::simd::level().name().to_string(),
        stages: stages
            .iter()
            .filter_map(|(_, d)| {
                let rec: StageRecord =
                    serde_json::from_str(&std::fs::read_to_string(d.join(MANIFEST)).ok()?).ok()?;
                Some(StageProvenance {
                    name: rec.name,
                    kind: rec.kind,
                    wall_s: rec.wall_s,
                    cached: rec.cached,
                    out_dir: d.clone(),
                    inputs: rec.inputs,
                })
            })
            .collect(),
        total_wall_s: 0.0,
    }
}

#[derive(Serialize)]
struct FigureView {
    href: String,
    caption: String,
}

#[derive(Serialize)]
struct TableView {
    href: String,
    caption: String,
    rows: usize,
    header: Vec<String>,
    shown: Vec<Vec<String>>,
}

#[derive(Serialize)]
struct StageView {
    name: String,
    kind: String,
    wall_s: f64,
    cached: bool,
    warnings: Vec<String>,
    summary: Vec<(String, String)>,
    figures: Vec<FigureView>,
    tables: Vec<TableView>,
}

/// Link from the page's directory to a file in a stage's directory.
fn href(stage_dir: &Path, page_dir: &Path, file: &Path) -> String {
    let rel = stage_dir
        .strip_prefix(page_dir)
        .map(|r| r.join(file))
        .unwrap_or_else(|_| stage_dir.join(file));
    rel.to_string_lossy().replace('\\', "/")
}

fn stage_view(rec: &StageRecord, dir: &Path, page_dir: &Path, rows: usize) -> Result<StageView> {
    let mut summary = Vec::new();
    flatten("", &rec.output.summary, &mut summary);
    let warnings = rec.output.summary["warnings"]
        .as_array()
        .map(|w| {
            w.iter()
                .map(|v| v.as_str().map_or_else(|| v.to_string(), str::to_string))
                .collect()
        })
        .unwrap_or_default();
    summary.retain(|(k, _)| !k.starts_with("warnings"));
    let figures = rec
        .output
        .figures
        .iter()
        .map(|f| FigureView {
            href: href(dir, page_dir, &f.path),
            caption: f.caption.clone(),
        })
        .collect();
    let tables = rec
        .output
        .tables
        .iter()
        .map(|t| table_view(dir, page_dir, &t.path, &t.caption, rows))
        .collect::<Result<_>>()?;
    Ok(StageView {
        name: rec.name.clone(),
        kind: rec.kind.clone(),
        wall_s: rec.wall_s,
        cached: rec.cached,
        warnings,
        summary,
        figures,
        tables,
    })
}

fn table_view(dir: &Path, page_dir: &Path, file: &Path, caption: &str, rows: usize) -> Result<TableView> {
    let path = dir.join(file);
    // Every cell as its text (polars, no type inference), so the page shows what the file holds.
    let df = CsvReadOptions::default()
        .with_has_header(true)
        .with_infer_schema_length(Some(0))
        .try_into_reader_with_file_path(Some(path.clone()))
        .and_then(|r| r.finish())
        .map_err(|e| anyhow::anyhow!("report: cannot read table {}: {e}", path.display()))?;
    let header = df.get_column_names().iter().map(|c| c.to_string()).collect();
    let cols = df
        .columns()
        .iter()
        .map(|c| c.cast(&DataType::String))
        .collect::<Result<Vec<_>, _>>()?;
    let cols = cols
        .iter()
        .map(|c| {
            c.str()
                .map(|s| s.iter().map(|v| v.map(str::to_string)).collect::<Vec<_>>())
        })
        .collect::<Result<Vec<_>, _>>()?;
    let shown = (0..df.height().min(rows))
        .map(|r| {
            cols.iter()
                .map(|c| c[r].as_deref().map(format_cell).unwrap_or_default())
                .collect()
        })
        .collect();
    let all = df.height();
    Ok(TableView {
        href: href(dir, page_dir, file),
        caption: caption.into(),
        rows: all,
        header,
        shown,
    })
}

fn format_cell(c: &str) -> String {
    c.parse::<f64>()
        .map(format_number)
        .unwrap_or_else(|_| c.to_string())
}

/// Six significant digits, plain where readable, scientific otherwise.
pub fn format_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return v.to_string();
    }
    let a = v.abs();
    if (1e-3..1e6).contains(&a) {
        let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        format!("{v:.5e}")
    }
}

/// Summary JSON as (dotted key, readable value) rows.
fn flatten(prefix: &str, v: &serde_json::Value, out: &mut Vec<(String, String)>) {
    use serde_json::Value;
    let key = |k: &str| {
        if prefix.is_empty() {
            k.to_string()
        } else {
            format!("{prefix}.{k}")
        }
    };
    match v {
        Value::Object(m) => m.iter().for_each(|(k, v)| flatten(&key(k), v, out)),
        Value::Number(n) => out.push((
            prefix.into(),
            n.as_f64().map_or_else(|| n.to_string(), format_number),
        )),
        Value::Array(a) if a.len() > 8 => out.push((prefix.into(), format!("[{} values]", a.len()))),
        Value::Array(a) if a.iter().all(|x| !x.is_object()) => out.push((
            prefix.into(),
            a.iter()
                .map(|x| {
                    x.as_f64()
                        .map_or_else(|| x.to_string().trim_matches('"').to_string(), format_number)
                })
                .collect::<Vec<_>>()
                .join(", "),
        )),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, x)| flatten(&key(&i.to_string()), x, out)),
        Value::String(s) => out.push((prefix.into(), s.clone())),
        Value::Bool(b) => out.push((prefix.into(), b.to_string())),
        Value::Null => {}
    }
}

fn render(title: &str, stages: &[StageView], prov: &Provenance) -> Result<String> {
    let mut env = minijinja::Environment::new();
    env.add_template("report.html", include_str!("../report/templates/report.html"))?;
    let started = if prov.started_unix_s == 0 {
        "-".to_string()
    } else {
        humantime::format_rfc3339_seconds(
            std::time::UNIX_EPOCH + std::time::Duration::from_secs(prov.started_unix_s),
        )
        .to_string()
    };
    let generated = humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string();
    let stage_wall_total: f64 = prov.stages.iter().map(|s| s.wall_s).sum();
    Ok(env.get_template("report.html")?.render(minijinja::context! {
        title, stages, prov, started, generated, stage_wall_total
    })?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn page_shows_figures_tables_summary_and_escapes_text() {
        use crate::contract::{Figure, Table};
        use crate::registry::Prepared;
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("reports/x");
        let input = dir.path().join("in.txt");
        std::fs::write(&input, b"abc").unwrap();
        let stage = Prepared::from_parts(
            "test",
            serde_json::json!({}),
            vec![input],
            |ctx: &StageContext| {
                crate::report::table::write_csv(
                    &ctx.out_dir.join("p.csv"),
                    &[("x", &[1.0, 2.0]), ("g", &[0.25, 0.5])],
                )?;
                Ok(StageOutput {
                    summary: serde_json::json!({"g_s_mean": 0.375, "warnings": ["thick <wedge> departs"]}),
                    figures: vec![Figure {
                        path: "m.png".into(),
                        caption: "map <script>".into(),
                    }],
                    tables: vec![Table {
                        path: "p.csv".into(),
                        caption: "profile".into(),
                    }],
                    files: vec!["p.csv".into()],
                })
            },
        );
        let sctx = StageContext::new(out.join("first"), "first".into(), dir.path().into());
        let rec = crate::pipeline::execute(stage, &sctx).unwrap();
        let mut ctx = StageContext::new(out.clone(), "report".into(), dir.path().into());
        ctx.earlier = vec![("first".into(), out.join("first"))];
        ctx.pipeline_out = Some(out.clone());
        let params = Params {
            title: "T & co".into(),
            stages: None,
            table_rows: 12,
        };
        assert_eq!(
            Report::inputs(&params, &ctx),
            vec![out.join("first").join(MANIFEST)]
        );
        Report::run(&params, &ctx).unwrap();
        let html = std::fs::read_to_string(out.join(PAGE)).unwrap();
        assert!(html.contains("T &amp; co"));
        // minijinja escapes "/" as &#x2f; in attributes (OWASP rule); browsers decode it.
        assert!(html.contains(r#"src="first&#x2f;m.png""#), "{html}");
        assert!(html.contains("map &lt;script&gt;") && !html.contains("map <script>"));
        assert!(html.contains("thick &lt;wedge&gt; departs"));
        assert!(html.contains("0.375"));
        assert!(html.contains(r#"href="first&#x2f;p.csv""#) && html.contains("<td>0.25</td>"));
        assert!(
            html.contains(&rec.inputs[0].sha256),
            "input hash missing from provenance"
        );
        let bad = Params {
            title: "t".into(),
            stages: Some(vec!["nope".into()]),
            table_rows: 3,
        };
        let e = Report::run(&bad, &ctx).unwrap_err();
        let msg = format!("{e:#}");
        assert!(
            msg.contains("\"nope\"") && msg.contains("names no earlier stage"),
            "{msg}"
        );
    }

    #[test]
    fn numbers_read_well() {
        assert_eq!(format_number(0.123456789), "0.123457");
        assert_eq!(format_number(25.0), "25");
        assert_eq!(format_number(1.5e-7), "1.50000e-7");
        assert_eq!(format_number(-0.004), "-0.004");
    }

    #[test]
    fn summary_flattens_with_dotted_keys() {
        let v =
            serde_json::json!({"g_s": {"mean": 0.5, "rev_px": 32}, "tags": ["a", "b"], "big": vec![0; 20]});
        let mut rows = Vec::new();
        flatten("", &v, &mut rows);
        assert!(rows.contains(&("g_s.mean".into(), "0.5".into())));
        assert!(rows.contains(&("g_s.rev_px".into(), "32".into())));
        assert!(rows.contains(&("tags".into(), "a, b".into())));
        assert!(rows.contains(&("big".into(), "[20 values]".into())));
    }
}
