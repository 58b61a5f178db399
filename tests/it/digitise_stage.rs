//! `lbdem digitise PARAMS.toml --out DIR` end to end on a synthetic image with a known
//! answer: the particle file, its JSON header, the tables and figures, the summary.

use lbdem_grains::synth::{SynthSpec, generate};
use std::path::Path;
use std::process::Command;

/// Column `name` of the CSV table at `path`, every cell a finite number (a malformed table
/// fails the test, naming the file, column and row: `table::finite_f64_column`).
fn finite_column(path: &Path, name: &str) -> Vec<f64> {
    let df = lbdem::report::table::read_table(path).unwrap();
    lbdem::report::table::finite_f64_column(&df, name, path).unwrap()
}

fn save_png(path: &Path, img: &ndarray::Array2<f64>) {
    let (h, w) = img.dim();
    let buf = image::GrayImage::from_fn(w as u32, h as u32, |x, y| {
        image::Luma([(img[[y as usize, x as usize]].clamp(0.0, 1.0) * 255.0).round() as u8])
    });
    buf.save(path).unwrap();
}

#[test]
fn cli_writes_the_assembly_with_its_header() {
    let dir = tempfile::tempdir().unwrap();
    let s = generate(&SynthSpec {
        width: 400,
        height: 300,
        n_grains: 60,
        d_mean_px: 36.0,
        d_spread: 0.25,
        seed: 5,
        ..SynthSpec::default()
    });
    save_png(&dir.path().join("first.png"), &s.image);
    let px = 2.7e-6;
    std::fs::write(
        dir.path().join("digitise.toml"),
        format!("image = \"first.png\"\npixel_size_m = {px}\n"),
    )
    .unwrap();
    let out = dir.path().join("out");
    let st = Command::new(env!("CARGO_BIN_EXE_lbdem"))
        .args([
            "digitise",
            dir.path().join("digitise.toml").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(st.status.success(), "{}", String::from_utf8_lossy(&st.stderr));
    for f in [
        "particles.csv",
        "particles.json",
        "grains.csv",
        "templates.csv",
        "size_distribution.csv",
        "overlay.png",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let header: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("particles.json")).unwrap()).unwrap();
    assert_eq!(header["units"], "m");
    assert_eq!(header["pixel_size_m"].as_f64().unwrap(), px);
    assert!(header["axes"].as_str().unwrap().contains("y up"));
    let csv = std::fs::read_to_string(out.join("particles.csv")).unwrap();
    assert_eq!(csv.lines().next(), Some("grain_id,x,y,r"));
    let path = out.join("particles.csv");
    let col = |n: &str| finite_column(&path, n);
    let (ids, ys) = (col("grain_id"), col("y"));
    let n_grains = ids.iter().map(|&i| i as usize).max().unwrap();
    assert_eq!(n_grains, s.grains.len(), "grain count");
    // y up: a true grain near the top of the image has a large y in metres.
    let top = s.grains.iter().min_by(|a, b| a.y.total_cmp(&b.y)).unwrap();
    let y_top_m = (300.0 - top.y) * px;
    assert!(
        ys.iter().any(|y| (y - y_top_m).abs() < 20.0 * px),
        "no circle near the top grain's y = {y_top_m}"
    );
    // Mean diameter in metres within 3 % of the truth.
    let d_true = s.grains.iter().map(|g| g.d_eq_px).sum::<f64>() / s.grains.len() as f64 * px;
    let d_bar = header["d_bar_m"].as_f64().unwrap();
    assert!(
        (d_bar - d_true).abs() / d_true < 0.03,
        "d_bar {d_bar} vs {d_true}"
    );
    // The manifest records what ran, with what, and what it found and wrote.
    let stage: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("stage.json")).unwrap()).unwrap();
    assert_eq!(stage["kind"], "digitise");
    assert_eq!(stage["params"]["pixel_size_m"].as_f64(), Some(px));
    assert_eq!(
        stage["output"]["summary"]["n_grains"].as_u64(),
        Some(n_grains as u64)
    );
    let files: Vec<&str> = stage["output"]["files"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f.as_str())
        .collect();
    for f in ["particles.csv", "particles.json", "overlay.png"] {
        assert!(files.contains(&f), "stage.json does not list {f}: {files:?}");
    }
    assert_eq!(
        stage["inputs"][0]["sha256"].as_str().map(str::len),
        Some(64),
        "{}",
        stage["inputs"]
    );
}
