//! Acceptance: the `radiograph` stage recovers the true REV solid fraction (within 0.01)
//! and volumetric strain (within 0.005) from noisy synthetic frames whose thickness changed
//! by 5% (Su et al. 2020 Eqs. 1-5 with the Eq. 2 or Eq. 3 thickness correction), and
//! skipping the thickness correction gives a clearly larger error.

use lbdem::contract::{Stage, StageContext};
use lbdem::io::tiff::read_pages;
use lbdem::stages::radiograph::{Params as RParams, Radiograph, Thickness};
use lbdem::stages::synth::{Params as SParams, SynthRadiograph};
use ndarray::Array2;
use std::path::Path;

fn synth_params() -> SParams {
    let mut p: SParams = toml::from_str("").unwrap();
    p.plots = false;
    p.thickness_change = -0.05;
    p
}

fn read(p: &Path) -> Array2<f64> {
    read_pages(p).unwrap().remove(0).data
}

fn radiograph_params(dir: &Path, s: &SParams, thickness: Thickness) -> RParams {
    let lay = lbdem::stages::synth::layout(s).unwrap();
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
        plots = false"#,
        d = dir.display(),
        l = <[usize; 4]>::from(lay.liquid_ref),
        s_ = <[usize; 4]>::from(lay.solid_ref),
        l0 = s.thickness0,
        dbar = s.d_bar,
        px = s.pixel_size,
    );
    let mut p: RParams = toml::from_str(&text).unwrap();
    p.thickness = thickness;
    p.thickness_roi = match thickness {
        Thickness::Eq2 => Some(lay.liquid_ref),
        Thickness::Eq3 => Some(lay.solid_ref),
        Thickness::None => None,
    };
    p
}

/// Largest |a - b| over pixels where the truth is finite; the measured map must be finite there too.
fn max_err(measured: &Array2<f64>, truth: &Array2<f64>) -> f64 {
    measured
        .iter()
        .zip(truth)
        .filter(|(_, t)| t.is_finite())
        .map(|(m, t)| {
            if m.is_finite() {
                (m - t).abs()
            } else {
                f64::INFINITY
            }
        })
        .fold(0.0, f64::max)
}

/// A true every-pixel map at the centre pixels of the stage's `k` px map cells.
fn on_cells(truth: Array2<f64>, k: usize) -> Array2<f64> {
    let (h, w) = truth.dim();
    Array2::from_shape_fn((h / k, w / k), |(i, j)| truth[[i * k + k / 2, j * k + k / 2]])
}

/// The stage's largest errors against the truth, on its default map grid (5 px cells for this
/// 95 px REV) or with `map_step`.
fn run(thickness: Thickness, synth_dir: &Path, s: &SParams, map_step: Option<usize>) -> (f64, f64, f64) {
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), "radiograph".into(), synth_dir.into());
    let mut p = radiograph_params(synth_dir, s, thickness);
    p.map_step = map_step;
    let summary = Radiograph::run(&p, &ctx).unwrap().summary;
    let k = summary["map_step_px"].as_u64().unwrap() as usize;
    let err = |map: &str, truth: &str| {
        max_err(
            &read(&out.path().join(map)),
            &on_cells(read(&synth_dir.join(truth)), k),
        )
    };
    let e0 = err("gs_rev_000.tif", "true_gs_rev_000.tif");
    let e1 = err("gs_rev_001.tif", "true_gs_rev_001.tif");
    let ee = err("eps_vol_001.tif", "true_eps_vol_001.tif");
    println!(
        "{thickness:?}, {k} px cells: max |g_S error| frame 0 {e0:.5}, frame 1 {e1:.5}; max |eps_vol error| {ee:.5}"
    );
    (e0, e1, ee)
}

#[test]
fn thickness_corrected_solid_fraction_and_strain_match_truth() {
    let dir = tempfile::tempdir().unwrap();
    let s = synth_params();
    let ctx = StageContext::new(dir.path().into(), "synth".into(), dir.path().into());
    SynthRadiograph::run(&s, &ctx).unwrap();

    for (t, step) in [Thickness::Eq2, Thickness::Eq3]
        .into_iter()
        .flat_map(|t| [(t, None), (t, Some(1))])
    {
        let (e0, e1, ee) = run(t, dir.path(), &s, step);
        // Measured on the default 5 px cells: g_S 0.0057 / 0.0056 (Eq. 2), 0.0057 / 0.0054
        // (Eq. 3); eps_vol 0.0027 (Eq. 2), 0.0042 (Eq. 3). Over every pixel (`map_step = 1`):
        // g_S 0.0073 / 0.0072 and 0.0073 / 0.0070, eps_vol 0.0033 and 0.0046. The limits the docs
        // state (0.01, 0.005) are what is asserted.
        assert!(
            e0 < 0.01 && e1 < 0.01,
            "{t:?} {step:?}: g_S errors {e0} {e1} exceed 0.01"
        );
        assert!(ee < 0.005, "{t:?} {step:?}: eps_vol error {ee} exceeds 0.005");
    }
    // Without the thickness correction the 5% thinner frame is misread.
    let (_, e1, ee) = run(Thickness::None, dir.path(), &s, None);
    assert!(e1 > 0.03, "uncorrected g_S error {e1} should be well above 0.01");
    assert!(
        ee > 0.03,
        "uncorrected eps_vol error {ee} should be well above 0.005"
    );
}
