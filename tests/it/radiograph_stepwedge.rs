//! Real neutron radiographs of a water step-wedge (WaterInSand, CC0; see
//! data/real/README.md): after dark, open-beam and dose correction and
//! gamma-spot removal, the water attenuation -ln(T_water / T_empty) of the thin wedge must
//! be linear in the known water thickness 0.5-2.5 mm (Beer-Lambert, Su et al. 2020 Eq. 1's
//! premise) with R^2 > 0.99. The thick wedge (3.0-5.0 mm) is fitted and its departure from
//! linearity printed (scattering and beam hardening; see docs/radiograph.md), not asserted.

use lbdem::io::tiff::read_pages;
use lbdem_imaging::correct;
use lbdem_imaging::profile::linear_fit;
use ndarray::{Array2, s};
use std::path::Path;

/// The data, in the repository (data/real/README.md: licence and citation). A missing file is a
/// failure: a test without its data proves nothing.
fn dir() -> &'static Path {
    let d = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/data/real/waterinsand-stepwedge"
    ));
    assert!(
        d.is_dir(),
        "{} is missing: the repository ships it (git checkout data/real)",
        d.display()
    );
    d
}

fn load(name: &str) -> Array2<f64> {
    let f = read_pages(&dir().join(name)).unwrap().remove(0).data;
    correct::remove_gamma_spots(f.view(), 5, 6.0).unwrap().0
}

/// Open-beam region between the two wedge holders (checked on the attenuation map).
const OPEN: [usize; 4] = [700, 300, 120, 400];

/// Water attenuation map -ln(T_h2o / T_empty) with T = (I - D) / (OB - D), each frame
/// dose-normalised on the open region.
pub fn water_attenuation() -> Array2<f64> {
    let (ob, dc) = (load("exp10s_ob.tif"), load("exp10s_dc.tif"));
    let mut t_e = correct::flat_dark(load("exp10s_empty.tif").view(), Some(dc.view()), Some(ob.view()));
    let mut t_w = correct::flat_dark(load("exp10s_h2o.tif").view(), Some(dc.view()), Some(ob.view()));
    let de = correct::dose_normalise(&mut t_e, OPEN.into()).unwrap();
    let dw = correct::dose_normalise(&mut t_w, OPEN.into()).unwrap();
    println!("dose divisors on the open region: empty {de:.4}, water {dw:.4}");
    let mut a = Array2::zeros(t_e.dim());
    ndarray::Zip::from(&mut a)
        .and(&t_e)
        .and(&t_w)
        .for_each(|a, &e, &w| *a = -(w / e).ln());
    a
}

/// Plateaus of the row profile of `a` over columns `x0..x1`: (first row, last row, median).
/// Edges are where the 10-row forward/backward means differ by more than `jump`; a plateau
/// is what lies between two edges (trimmed by 12 rows) if at least 50 rows long and
/// attenuating more than 0.05.
fn plateaus(a: &Array2<f64>, x0: usize, x1: usize, jump: f64) -> Vec<(usize, usize, f64)> {
    let h = a.nrows();
    let prof: Vec<f64> = (0..h)
        .map(|r| correct::median(a.slice(s![r, x0..x1]).iter().copied()))
        .collect();
    let mean = |r0: usize, r1: usize| prof[r0..r1].iter().sum::<f64>() / (r1 - r0) as f64;
    let k = 10;
    let step: Vec<f64> = (0..h)
        .map(|r| {
            if r < k || r + k > h {
                0.0
            } else {
                (mean(r, r + k) - mean(r - k, r)).abs()
            }
        })
        .collect();
    // Edge rows: local maxima of the step signal above `jump`.
    let mut edges = vec![0];
    for r in 1..h - 1 {
        let win = r.saturating_sub(k)..(r + k).min(h);
        if step[r] > jump && win.clone().all(|q| step[q] <= step[r]) {
            edges.push(r);
        }
    }
    edges.push(h);
    let mut out = Vec::new();
    for w in edges.windows(2) {
        let (r0, r1) = (w[0] + 12, w[1].saturating_sub(12));
        if r1 > r0 + 50 {
            let m = correct::median(prof[r0..r1].iter().copied());
            if m > 0.05 {
                out.push((r0, r1, m));
            }
        }
    }
    out
}

#[test]
fn thin_wedge_attenuation_is_linear_in_water_thickness() {
    let a = water_attenuation();
    if let Ok(p) = std::env::var("LBDEM_DEBUG_PNG") {
        let opts = lbdem::report::plot::FieldPlot {
            title: "water attenuation -ln(T_h2o/T_empty)",
            label: "-ln T",
            cmap: lbdem::report::plot::Colormap::Viridis,
            range: Some((-0.1, 1.5)),
            pixel_size: None,
        };
        lbdem::report::plot::field_png(Path::new(&p), a.view(), &opts).unwrap();
    }
    // Thin wedge: x ~ 900-1300 px (README); the central 200 columns avoid its walls.
    let thin = plateaus(&a, 1000, 1200, 0.04);
    println!("thin wedge plateaus (row0, row1, attenuation): {thin:?}");
    assert_eq!(
        thin.len(),
        5,
        "expected the 5 steps of the thin wedge, found {thin:?}"
    );
    // The thickest step is at the top (README): attenuation must fall with the row.
    assert!(
        thin.windows(2).all(|w| w[0].2 > w[1].2),
        "steps not ordered thick-to-thin from the top"
    );
    let t_mm = [2.5, 2.0, 1.5, 1.0, 0.5];
    let att: Vec<f64> = thin.iter().map(|p| p.2).collect();
    let fit = linear_fit(&t_mm, &att).unwrap();
    println!(
        "thin wedge: -ln T = {:.4} /mm x t + {:.4}, R^2 = {:.5}",
        fit.slope, fit.intercept, fit.r2
    );
    assert!(fit.r2 > 0.99, "thin wedge not linear: R^2 = {}", fit.r2);
    assert!(fit.slope > 0.0);

    // Thick wedge (x ~ 190-570 px): reported, not asserted.
    let thick = plateaus(&a, 280, 480, 0.04);
    println!("thick wedge plateaus: {thick:?}");
    // Assign thicknesses from the bottom (thinnest, 3.0 mm) up in 0.5 mm steps; the top
    // step (5.0 mm) carries the curved water meniscus and may not be found as a plateau.
    if thick.len() >= 3 {
        let t_thick: Vec<f64> = (0..thick.len()).rev().map(|i| 3.0 + 0.5 * i as f64).collect();
        for (t, p) in t_thick.iter().zip(&thick) {
            let pred = fit.slope * t + fit.intercept;
            println!(
                "thick wedge t = {t} mm: measured -ln T = {:.4}, thin-wedge line predicts {pred:.4} ({:+.1}%)",
                p.2,
                100.0 * (p.2 / pred - 1.0)
            );
        }
        let all_t: Vec<f64> = t_mm.iter().chain(&t_thick).copied().collect();
        let all_a: Vec<f64> = att.iter().chain(thick.iter().map(|p| &p.2)).copied().collect();
        let f2 = linear_fit(&all_t, &all_a).unwrap();
        println!("both wedges, one line 0.5-5.0 mm: R^2 = {:.5}", f2.r2);
    }
}
