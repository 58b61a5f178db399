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

const PHOTO: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/data/real/pegs-photoelastic-disks/Step09-0001.jpg"
);

#[test]
fn finds_the_disks_in_the_box_and_their_two_sizes() {
    assert!(
        Path::new(PHOTO).is_file(),
        "{PHOTO} is missing: the repository ships it"
    );
    let dir = tempfile::tempdir().unwrap();
    let params = format!(
        "image = \"{PHOTO}\"\npixel_size_m = 1e-4\ncontainer = {{ kind = \"auto-box\" }}\nsmooth_px = 2.0\n\
         min_grain_area_px = 400\nmax_hole_area_px = 400\n"
    );
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
    let csv = std::fs::read_to_string(dir.path().join("grains.csv")).unwrap();
    let mut lines = csv.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = head.iter().position(|&h| h == "d_eq_m").unwrap();
    let mut d: Vec<f64> = lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect();
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
}
