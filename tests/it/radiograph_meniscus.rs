//! Meniscus line scan through the stage (Su et al. 2020 Fig. 12g-h, Eqs. 2, 22, 23): a
//! liquid film whose two faces are pulled in as circular arcs of radius R = 100 um. Eq. (2)
//! per pixel must give the thickness, the parabola fit R, and Young-Laplace
//! dp = -2 gamma / R = -14 kPa for gamma = 0.7 J/m^2 (the paper's figure for R ~ 100 um).

use lbdem::contract::{Stage, StageContext};
use lbdem::io::tiff::write_f32;
use lbdem::stages::radiograph::{Params, Radiograph};
use ndarray::Array2;

#[test]
fn circular_meniscus_gives_radius_and_pressure_drop() {
    let (mu_l, l0, r, lmin, px) = (10120.559f64, 150e-6f64, 100e-6f64, 100e-6f64, 1e-6f64);
    let (h, w) = (400, 64);
    let yc = 200.0 * px;
    let thickness = |row: usize| {
        let y = (row as f64 + 0.5) * px - yc;
        let l = if y.abs() < r {
            lmin + 2.0 * (r - (r * r - y * y).sqrt())
        } else {
            l0
        };
        l.min(l0)
    };
    let d = tempfile::tempdir().unwrap();
    let f0 = Array2::from_elem((h, w), (-mu_l * l0).exp());
    let f1 = Array2::from_shape_fn((h, w), |(row, _)| (-mu_l * thickness(row)).exp());
    write_f32(&d.path().join("f0.tif"), f0.view()).unwrap();
    write_f32(&d.path().join("f1.tif"), f1.view()).unwrap();
    let p: Params = toml::from_str(&format!(
        r#"frames = ["f0.tif", "f1.tif"]
        i_l0 = {il}
        i_s0 = 0.9
        mu_s = 2147.85
        mu_l = {mu_l}
        l_alloy0 = {l0}
        d_bar = 10e-6
        pixel_size = {px}
        plots = false
        [line_scan]
        x = 32
        y0 = 100
        y1 = 300
        fit_half_width = 15e-6
        gamma = 0.7"#,
        il = (-mu_l * l0).exp()
    ))
    .unwrap();
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), "radiograph".into(), d.path().into());
    let o = Radiograph::run(&p, &ctx).unwrap();
    let fit = &o.summary["meniscus"][0]["fit"];
    let (rf, dp, l_min) = (
        fit["radius"].as_f64().unwrap(),
        fit["dp"].as_f64().unwrap(),
        fit["l_min"].as_f64().unwrap(),
    );
    println!(
        "R = {:.1} um, dp = {:.2} kPa, L_min = {:.2} um",
        rf * 1e6,
        dp / 1e3,
        l_min * 1e6
    );
    assert!((rf - r).abs() / r < 0.03, "R = {rf}");
    assert!((dp + 14.0e3).abs() < 0.5e3, "dp = {dp}");
    assert!((l_min - lmin).abs() < 0.3e-6, "L_min = {l_min}");
    assert!(out.path().join("line_scan.csv").is_file());
}
