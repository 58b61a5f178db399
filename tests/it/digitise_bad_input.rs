//! Bad input to the digitise stage gets an error (or a warning) that names the problem:
//! an empty image, an image with no grains, a container that covers nothing, a grain
//! smaller than a few pixels, a missing pixel size.

use lbdem::contract::{Stage, StageContext, StageOutput};
use lbdem::stages::digitise::Digitise;
use std::path::Path;

fn save_png(path: &Path, img: &ndarray::Array2<f64>) {
    let (h, w) = img.dim();
    let buf = image::GrayImage::from_fn(w as u32, h as u32, |x, y| {
        image::Luma([(img[[y as usize, x as usize]].clamp(0.0, 1.0) * 255.0).round() as u8])
    });
    buf.save(path).unwrap();
}

fn run(dir: &Path, params: &str) -> anyhow::Result<StageOutput> {
    let p: <Digitise as Stage>::Params = toml::from_str(params).unwrap();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let ctx = StageContext::new(out, "digitise".into(), dir.to_path_buf());
    Digitise::run(&p, &ctx)
}

fn err(dir: &Path, params: &str) -> String {
    format!("{:#}", run(dir, params).expect_err("should fail"))
}

/// Two disks on a dark background, plus whatever `extra` draws.
fn disks(extra: impl Fn(usize, usize) -> bool) -> ndarray::Array2<f64> {
    ndarray::Array2::from_shape_fn((80, 120), |(r, c)| {
        let (x, y) = (c as f64 + 0.5, r as f64 + 0.5);
        let d = ((x - 35.0).powi(2) + (y - 40.0).powi(2)).sqrt() < 15.0
            || ((x - 80.0).powi(2) + (y - 40.0).powi(2)).sqrt() < 18.0;
        if d || extra(r, c) { 0.9 } else { 0.1 }
    })
}

#[test]
fn empty_file_is_named() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("empty.png"), b"").unwrap();
    let e = err(dir.path(), "image = \"empty.png\"\npixel_size_m = 1e-5");
    assert!(e.contains("empty.png") && e.contains("empty"), "{e}");
}

#[test]
fn tiny_image_is_empty() {
    let dir = tempfile::tempdir().unwrap();
    save_png(
        &dir.path().join("one.png"),
        &ndarray::Array2::from_elem((1, 1), 0.5),
    );
    let e = err(dir.path(), "image = \"one.png\"\npixel_size_m = 1e-5");
    assert!(e.contains("image is empty (1 x 1 pixels)"), "{e}");
}

#[test]
fn uniform_image_has_no_grains() {
    let dir = tempfile::tempdir().unwrap();
    save_png(
        &dir.path().join("flat.png"),
        &ndarray::Array2::from_elem((50, 50), 0.5),
    );
    let e = err(dir.path(), "image = \"flat.png\"\npixel_size_m = 1e-5");
    assert!(e.contains("uniform") && e.contains("flat.png"), "{e}");
}

#[test]
fn threshold_above_everything_finds_no_grains() {
    let dir = tempfile::tempdir().unwrap();
    save_png(&dir.path().join("d.png"), &disks(|_, _| false));
    let e = err(
        dir.path(),
        "image = \"d.png\"\npixel_size_m = 1e-5\nthreshold = 250.0",
    );
    assert!(e.contains("no grains found") && e.contains("threshold"), "{e}");
}

#[test]
fn container_outside_the_image_covers_nothing() {
    let dir = tempfile::tempdir().unwrap();
    save_png(&dir.path().join("d.png"), &disks(|_, _| false));
    let e = err(
        dir.path(),
        "image = \"d.png\"\npixel_size_m = 1e-5\ncontainer = { kind = \"rect\", x0 = 500.0, y0 = 0.0, x1 = 600.0, y1 = 50.0 }",
    );
    assert!(
        e.contains("mask covers nothing") && e.contains("rectangle"),
        "{e}"
    );
}

#[test]
fn a_grain_of_a_few_pixels_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    // A 2 x 2 pixel grain at x = 110, y = 10.
    save_png(
        &dir.path().join("d.png"),
        &disks(|r, c| (10..12).contains(&r) && (110..112).contains(&c)),
    );
    let o = run(
        dir.path(),
        "image = \"d.png\"\npixel_size_m = 1e-5\nsmooth_px = 0.0",
    )
    .unwrap();
    let warnings = o.summary["warnings"].to_string();
    assert!(warnings.contains("4 px at x = 111.0, y = 11.0"), "{warnings}");
    assert_eq!(o.summary["n_grains"], 2);
}

#[test]
fn missing_pixel_size_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let e = toml::from_str::<<Digitise as Stage>::Params>("image = \"d.png\"")
        .unwrap_err()
        .to_string();
    assert!(e.contains("pixel_size_m"), "{e}");
    save_png(&dir.path().join("d.png"), &disks(|_, _| false));
    let e = err(dir.path(), "image = \"d.png\"\npixel_size_m = 0.0");
    assert!(e.contains("pixel_size_m = 0"), "{e}");
}
