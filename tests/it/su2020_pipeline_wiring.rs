//! The Su 2020 pipelines are wired right before anything runs: `pipelines/su2020.toml` takes
//! tens of hours (docs/analysis.md), so a misspelt scene or stage name must not surface only
//! when its last stage starts. For it, the CI version and the quickstart: every stage kind is
//! known (`Pipeline::load`), every scene file exists, and every reference to another stage
//! (`run`, `radiograph`, `from_stage`, the `analyses` lists, `@NAME/...` paths) names an
//! earlier stage.

use lbdem::pipeline::schema::Pipeline;
use std::collections::HashSet;
use std::path::Path;

/// The stage names a parameter value refers to.
fn references(key: &str, v: &toml::Value, out: &mut Vec<String>) {
    match v {
        toml::Value::String(s) => {
            if let Some(rest) = s.strip_prefix('@') {
                out.push(rest.split('/').next().unwrap_or_default().to_string());
            } else if matches!(key, "run" | "radiograph" | "from_stage" | "analyses") && !s.is_empty() {
                out.push(s.clone());
            }
        }
        toml::Value::Array(a) => a.iter().for_each(|x| references(key, x, out)),
        toml::Value::Table(t) => t.iter().for_each(|(k, x)| references(k, x, out)),
        _ => {}
    }
}

/// Every problem with one pipeline file's wiring, as sentences.
fn wiring_problems(file: &str) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let pl = Pipeline::load(&root.join(file)).unwrap_or_else(|e| panic!("{file}: {e:#}"));
    let mut earlier = HashSet::new();
    let mut problems = Vec::new();
    for s in &pl.stages {
        if let Some(scene) = s.params.get("scene").and_then(|v| v.as_str())
            && !pl.root.join(scene).is_file()
        {
            problems.push(format!(
                "{file}: stage '{}': scene {scene} does not exist",
                s.name
            ));
        }
        let mut refs = Vec::new();
        references("", &s.params, &mut refs);
        for r in refs {
            // A directory given instead of a stage name is allowed when it exists.
            if !earlier.contains(r.as_str()) && !pl.root.join(&r).is_dir() {
                problems.push(format!(
                    "{file}: stage '{}' refers to '{r}', which is no earlier stage",
                    s.name
                ));
            }
        }
        earlier.insert(s.name.as_str());
    }
    problems
}

#[test]
fn su2020_pipelines_name_existing_scenes_and_earlier_stages() {
    let mut all = Vec::new();
    for f in [
        "pipelines/su2020.toml",
        "pipelines/su2020-ci.toml",
        "pipelines/su2020-quick.toml",
        "pipelines/su2020-fig11-2150um.toml",
        "pipelines/quickstart.toml",
    ] {
        all.extend(wiring_problems(f));
    }
    assert!(all.is_empty(), "{}", all.join("\n"));
}

#[test]
fn a_misspelt_reference_is_caught() {
    let mut refs = Vec::new();
    let params: toml::Value = toml::from_str(
        "run = \"sim1\"\nframes = [\"@radiographs-sim1/frames\"]\nanalyses = [\"a\", \"\"]\nlabel = \"x\"",
    )
    .unwrap();
    references("", &params, &mut refs);
    refs.sort();
    assert_eq!(refs, ["a", "radiographs-sim1", "sim1"]);
}
