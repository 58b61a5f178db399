//! The real photograph of issue 5: touching bidisperse photoelastic disks in a box
//! (PeGS test data set, J. Kollmer, `data/real/pegs-photoelastic-disks/`, licence and citation in
//! data/real/README.md). The box
//! is detected from the image, the disks inside it are found and split, the two size
//! classes come apart, and no fitted circle lies outside the container.
//!
//! Reference count: 29 disks (14 large, 15 small), counted by eye on the photograph.

use lbdem::contract::{Stage, StageContext};
use lbdem::stages::digitise::Digitise;
use std::path::Path;

/// Column `name` of the CSV table at `path`, every cell a finite number (a malformed table
/// fails the test, naming the file, column and row: `table::finite_f64_column`).
fn finite_column(path: &Path, name: &str) -> Vec<f64> {
    let df = lbdem::report::table::read_table(path).unwrap();
    lbdem::report::table::finite_f64_column(&df, name, path).unwrap()
}

const PHOTO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/data/real/pegs-photoelastic-disks/Step09-0001.jpg"
);

/// With the defaults (only the container named): speck and hole sizes from a first pass.
/// Before they followed from the image, the fixed defaults (12 px specks, no hole filling) found
/// 33 grains here: the photoelastic fringes left dark holes that split four disks.
#[test]
fn finds_the_disks_in_the_box_and_their_two_sizes_with_the_defaults() {
    let s = check_photo("");
    // The first pass's median grain (a small disk, ~8300 px) gives 5 % of it.
    let min = s["min_grain_area_px"].as_u64().unwrap();
    assert!(
        (300..=500).contains(&min),
        "min_grain_area_px from the first pass: {min}"
    );
    assert_eq!(s["max_hole_area_px"], s["min_grain_area_px"]);
}

/// With hand-set sizes and smoothing (what the defaults now find by themselves).
#[test]
fn finds_the_disks_in_the_box_and_their_two_sizes_hand_set() {
    let s = check_photo("smooth_px = 2.0\nmin_grain_area_px = 400\nmax_hole_area_px = 400\n");
    assert!(s["sizes_first_pass"].is_null());
}

/// Digitise the photo with `extra` parameters, check the count, the box and the two size
/// classes; returns the summary.
fn check_photo(extra: &str) -> serde_json::Value {
    assert!(
        Path::new(PHOTO).is_file(),
        "{PHOTO} is missing: the repository ships it"
    );
    let dir = tempfile::tempdir().unwrap();
    let params =
        format!("image = \"{PHOTO}\"\npixel_size_m = 1e-4\ncontainer = {{ kind = \"auto-box\" }}\n{extra}");
    let p: <Digitise as Stage>::Params = toml::from_str(&params).unwrap();
    let ctx = StageContext::new(
        dir.path().to_path_buf(),
        "digitise".into(),
        dir.path().to_path_buf(),
    );
    let o = Digitise::run(&p, &ctx).unwrap();
    let s = &o.summary;
    eprintln!("{}", serde_json::to_string_pretty(s).unwrap());
    assert!(
        s["container"].as_str().unwrap().contains("detected box"),
        "{}",
        s["container"]
    );
    assert_eq!(s["circles_outside_container"], 0);
    // Grains: all disks, counted by eye.
    let n = s["n_grains"].as_u64().unwrap();
    assert_eq!(n, 29, "disks found");
    // Two size classes: split the equivalent diameters at their largest gap.
    let path = dir.path().join("grains.csv");
    let mut d = finite_column(&path, "d_eq_m");
    d.sort_by(f64::total_cmp);
    let (gap_at, gap) = (1..d.len())
        .map(|i| (i, d[i] - d[i - 1]))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    let (small, large) = d.split_at(gap_at);
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let cv =
        |v: &[f64]| (v.iter().map(|x| (x - mean(v)).powi(2)).sum::<f64>() / v.len() as f64).sqrt() / mean(v);
    eprintln!(
        "small {} (mean {:.4e}, cv {:.3}), large {} (mean {:.4e}, cv {:.3}), gap {gap:.3e}",
        small.len(),
        mean(small),
        cv(small),
        large.len(),
        mean(large),
        cv(large)
    );
    assert_eq!((small.len(), large.len()), (15, 14));
    assert!(mean(large) / mean(small) > 1.2);
    assert!(cv(small) < 0.06 && cv(large) < 0.06);
    s.clone()
}
