//! The main job end to end through the real binary: `lbdem run pipelines/quickstart.toml`
//! writes the HTML report with provenance, skips unchanged stages on a second run and
//! reruns them with `--force`. The pipeline is copied with its output redirected to a
//! temporary directory so the test never writes into the repository.

use crate::common;
use common::run;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The quickstart pipeline with `root` pointing at the repository and `out` at `out`.
fn redirected_pipeline(dir: &Path, out: &Path) -> PathBuf {
    let text = std::fs::read_to_string(repo().join("pipelines/quickstart.toml")).unwrap();
    let mut doc: toml::Table = toml::from_str(&text).unwrap();
    let header = doc.get_mut("pipeline").and_then(|p| p.as_table_mut()).unwrap();
    header.insert("root".into(), toml::Value::String(repo().display().to_string()));
    header.insert("out".into(), toml::Value::String(out.display().to_string()));
    let path = dir.join("quickstart.toml");
    std::fs::write(&path, toml::to_string(&doc).unwrap()).unwrap();
    path
}

#[test]
fn quickstart_report_cache_and_force() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("reports");
    let pipeline = redirected_pipeline(dir.path(), &out);
    let p = pipeline.to_str().unwrap();

    let (ok, err) = run(&["run", p]);
    assert!(ok, "first run failed:\n{err}");
    assert!(err.contains("running"), "{err}");
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("Provenance"));
    let prov: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("provenance.json")).unwrap()).unwrap();
    let stages = prov["stages"].as_array().unwrap();
    assert!(stages.len() >= 2);
    // Every input of every stage before the report is hashed and its hash is on the page
    // (the page cannot describe its own making; provenance.json does).
    for s in stages.iter().filter(|s| s["kind"] != "report") {
        for i in s["inputs"].as_array().unwrap() {
            let h = i["sha256"].as_str().unwrap();
            assert_eq!(h.len(), 64);
            assert!(html.contains(h), "input {} not in the report", i["path"]);
        }
        assert!(s["wall_s"].as_f64().unwrap() >= 0.0);
    }
    assert!(html.contains(prov["pipeline_file"]["sha256"].as_str().unwrap()));

    // Second run: nothing changed, so every stage, the report included, is skipped.
    let (ok, err) = run(&["run", p]);
    assert!(ok, "second run failed:\n{err}");
    assert_eq!(err.matches("unchanged, skipped").count(), stages.len(), "{err}");

    // A changed parameter reruns that stage and the report built on it.
    let mut doc: toml::Table = toml::from_str(&std::fs::read_to_string(&pipeline).unwrap()).unwrap();
    let params = doc["stage"].as_array_mut().unwrap()[0]["params"]
        .as_table_mut()
        .unwrap();
    let d_bar = params["d_bar"].as_float().unwrap();
    params.insert("d_bar".into(), toml::Value::Float(d_bar * 1.01));
    std::fs::write(&pipeline, toml::to_string(&doc).unwrap()).unwrap();
    let (ok, err) = run(&["run", p]);
    assert!(ok, "run with a changed parameter failed:\n{err}");
    assert_eq!(
        err.matches("unchanged, skipped").count(),
        stages.len() - 2,
        "{err}"
    );

    // --force reruns everything.
    let (ok, err) = run(&["run", p, "--force"]);
    assert!(ok, "forced run failed:\n{err}");
    assert_eq!(err.matches("unchanged, skipped").count(), 0, "{err}");
}

/// Every file under `dir` but the records of how and when it was made (stage manifests,
/// provenance, the report page that prints them), by path relative to `dir`.
fn outputs(dir: &Path) -> std::collections::BTreeMap<PathBuf, Vec<u8>> {
    let mut files = std::collections::BTreeMap::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            if p.is_dir() {
                todo.push(p);
            } else if !["stage.json", "provenance.json", "index.html", "summary.json"]
                .contains(&name.as_str())
            {
                files.insert(
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                );
            }
        }
    }
    files
}

/// `lbdem run --lanes 2`: the shear run goes beside the radiograph and digitise stages (it reads
/// neither), the analyses wait for it, and every file written is the one a run in one lane
/// writes, byte for byte.
#[test]
fn quickstart_in_two_lanes_writes_what_one_lane_writes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("reports");
    let pipeline = redirected_pipeline(dir.path(), &out);
    let mut files = Vec::new();
    for lanes in ["1", "2"] {
        // The same output directory for both (the analysis records the run's path), emptied.
        let _ = std::fs::remove_dir_all(&out);
        let (ok, err) = run(&["run", pipeline.to_str().unwrap(), "--lanes", lanes]);
        assert!(ok, "--lanes {lanes} failed:\n{err}");
        if lanes == "2" {
            assert!(err.contains("2 stages side by side"), "{err}");
        }
        files.push(outputs(&out));
    }
    assert!(files[0].len() > 20, "{} files", files[0].len());
    assert_eq!(
        files[0].keys().collect::<Vec<_>>(),
        files[1].keys().collect::<Vec<_>>(),
        "the two runs wrote different files"
    );
    for (path, bytes) in &files[0] {
        assert!(&files[1][path] == bytes, "{} differs", path.display());
    }
    let (ok, err) = run(&["run", "pipelines/quickstart.toml", "--lanes", "0"]);
    assert!(!ok && err.contains("--lanes"), "{err}");
}
