//! The radiograph stage of pipelines/quickstart.toml on the bundled data/synth-alcu frames:
//! it runs, lists its figures and tables for the report, and its mean eps_vol matches the
//! true one written by the synthetic stage (truth.json) within 0.005.

use lbdem::contract::StageContext;
use lbdem::pipeline::schema::Pipeline;
use lbdem::registry;
use std::path::Path;

#[test]
fn quickstart_radiograph_stage_runs_on_bundled_frames() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let pl = Pipeline::load(&root.join("pipelines/quickstart.toml")).unwrap();
    let spec = pl.stages.iter().find(|s| s.kind == "radiograph").unwrap();
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), spec.name.clone(), pl.root.clone());
    let o = registry::find(&spec.kind)
        .unwrap()
        .prepare(spec.params.clone(), &ctx)
        .unwrap()
        .run(&ctx)
        .unwrap();
    assert!(o.figures.iter().any(|f| f.path.ends_with("eps_vol_001.png")));
    assert!(o.tables.iter().any(|t| t.path.ends_with("grid.csv")));
    for f in o.files.iter().chain(o.figures.iter().map(|f| &f.path)) {
        assert!(out.path().join(f).is_file(), "{} listed but missing", f.display());
    }
    let truth: serde_json::Value =
        serde_json::from_slice(&std::fs::read(root.join("data/synth-alcu/truth.json")).unwrap()).unwrap();
    let true_eps = truth["per_frame"][1]["true_eps_vol_mean"].as_f64().unwrap();
    let eps = o.summary["per_frame"][1]["eps_vol_mean"].as_f64().unwrap();
    println!("mean eps_vol: measured {eps:.5}, true {true_eps:.5}");
    assert!((eps - true_eps).abs() < 0.005);
}
