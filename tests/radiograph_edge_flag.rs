//! The `radiograph` stage flags the REVs that reach a bulk liquid or solid region (issue 17
//! item 6), and the flag marks where the eps_vol accuracy of docs/radiograph.md does not hold.
//!
//! Synthetic frames with a known answer (`synth-radiograph`: truncated spheres squeezed
//! between the windows, 5 % thinner second frame, Poisson noise) with a detector blur of
//! 1.5 px, twice the default: the Jensen bias of a blurred sharp edge (the log of a mean, not
//! the mean of the log) then puts the largest eps_vol errors within one REV of the liquid gap
//! and pad below the assembly. Measured (seed 2): max |eps_vol error| 0.0083 over all REVs,
//! 0.0045 over the unflagged ones, with 26 % of the eps_vol REVs flagged (the default window of
//! two grains; at one grain the liquid pockets of this 50 % packing were flagged too: 67 %).

use lbdem::contract::{Stage, StageContext};
use lbdem::io::tiff::read_pages;
use lbdem::stages::radiograph::{Params as RParams, Radiograph};
use lbdem::stages::synth::{Params as SParams, SynthRadiograph};
use ndarray::Array2;
use std::path::Path;

fn read(p: &Path) -> Array2<f64> {
    read_pages(p).unwrap().remove(0).data
}

#[test]
fn flagged_revs_hold_the_edge_errors() {
    let synth = tempfile::tempdir().unwrap();
    let s: SParams =
        toml::from_str("seed = 2\nblur_sigma_px = 1.5\nthickness_change = -0.05\nplots = false").unwrap();
    let ctx = StageContext::new(synth.path().into(), "synth".into(), synth.path().into());
    SynthRadiograph::run(&s, &ctx).unwrap();
    let lay = lbdem::stages::synth::layout(&s).unwrap();
    let (mu_s, mu_l) = s.mus();
    let text = format!(
        r#"frames = ["{d}/frame_000.tif", "{d}/frame_001.tif"]
        i_l0_roi = {l:?}
        i_s0_roi = {s_:?}
        mu_s = {mu_s}
        mu_l = {mu_l}
        l_alloy0 = {l0}
        d_bar = {dbar}
        pixel_size = {px}
        thickness = "eq2"
        thickness_roi = {l:?}
        plots = false
        profiles = [{{ name = "red", roi = [100, 0, 200, 512], axis = "y" }}]"#,
        d = synth.path().display(),
        l = <[usize; 4]>::from(lay.liquid_ref),
        s_ = <[usize; 4]>::from(lay.solid_ref),
        l0 = s.thickness0,
        dbar = s.d_bar,
        px = s.pixel_size,
    );
    let p: RParams = toml::from_str(&text).unwrap();
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), "radiograph".into(), synth.path().into());
    let res = Radiograph::run(&p, &ctx).unwrap();

    let eps = read(&out.path().join("eps_vol_001.tif"));
    let truth = read(&synth.path().join("true_eps_vol_001.tif"));
    let near = read(&out.path().join("near_edge_001.tif"));
    let (mut all, mut away, mut n, mut flagged) = (0.0f64, 0.0f64, 0usize, 0usize);
    for ((e, t), f) in eps.iter().zip(&truth).zip(&near) {
        if e.is_finite() && t.is_finite() {
            let err = (e - t).abs();
            all = all.max(err);
            n += 1;
            if *f > 0.0 {
                flagged += 1;
            } else {
                away = away.max(err);
            }
        }
    }
    let share = flagged as f64 / n as f64;
    println!(
        "max |eps error| all {all:.4}, unflagged {away:.4}; flagged {:.1} %",
        100.0 * share
    );
    // The case is hard enough that the documented 0.005 fails somewhere (0.0083 measured) ...
    assert!(all > 0.006, "no REV beyond the documented accuracy: {all}");
    // ... and holds on every unflagged REV (0.0045 measured; the documented limit).
    assert!(away < 0.005, "unflagged REV eps_vol error {away} above 0.005");
    // The flag is local: the pads and gaps, not the assembly (26 % measured).
    assert!(share < 0.35, "{:.1} % of the REVs flagged", 100.0 * share);
    // The middle of the assembly (rows 200-300) is never flagged; the solid pad is.
    assert!((200..300).all(|r| near.row(r).iter().all(|&f| f == 0.0)));
    assert!(near.row(5).iter().all(|&f| f == 1.0));

    // The summary, the grid and the profile carry the flag.
    let f = &res.summary["per_frame"][1];
    let (k, kn) = eps
        .iter()
        .zip(&near)
        .filter(|(e, _)| e.is_finite())
        .fold((0, 0), |(k, kn), (_, &f)| (k + 1, kn + usize::from(f > 0.0)));
    let got = f["near_edge_fraction"].as_f64().unwrap();
    assert_eq!(got, kn as f64 / k as f64, "summary vs map");
    assert!(f["eps_vol_mean_away_from_edges"].as_f64().unwrap().is_finite());
    let grid = std::fs::read_to_string(out.path().join("grid.csv")).unwrap();
    assert!(grid.lines().next().unwrap().contains("near_edge_001"));
    let prof = std::fs::read_to_string(out.path().join("profile_red.csv")).unwrap();
    assert!(prof.lines().next().unwrap().contains("near_edge_fraction_001"));
}

/// A threshold pair that cannot classify anything is refused before anything is written.
#[test]
fn inverted_thresholds_are_refused() {
    let out = tempfile::tempdir().unwrap();
    let p: RParams = toml::from_str(
        r#"frames = ["none.tif"]
        i_l0 = 100.0
        i_s0 = 50.0
        mu_s = 1.0
        mu_l = 2.0
        l_alloy0 = 1e-4
        d_bar = 1e-4
        pixel_size = 1e-6
        edge_flag = { liquid_below = 0.9, solid_above = 0.1 }"#,
    )
    .unwrap();
    let ctx = StageContext::new(out.path().join("r"), "radiograph".into(), out.path().into());
    let err = format!("{:#}", Radiograph::run(&p, &ctx).unwrap_err());
    assert!(err.contains("liquid_below") && err.contains("0.9"), "{err}");
    assert!(!out.path().join("r").exists());
}
