//! The comparison's outputs: Fig. 6-style profiles, Figs. 8-10-style panels on one colour
//! scale, and the agreement table and chart.

use super::{Agreement, Params, rms_diff, roi_profile};
use crate::contract::{Figure, Table};
use crate::report::lines::{Line, LinesPlot, Reference, Style, lines_png};
use crate::report::panels::{Panel, PanelGrid, Shape, panels_png};
use crate::report::plot::Colormap;
use crate::report::table::{self, Col};
use crate::stages::analyse::plate_shapes;
use crate::stages::run_data::Run;
use crate::stages::strain_fields::{Fields, Setup, pressure_on_grid};
use anyhow::{Result, bail};
use lbdem_analysis::cracking::DP_C;
use ndarray::Array2;
use std::path::{Path, PathBuf};

#[allow(clippy::too_many_arguments)]
pub(super) fn profiles(
    p: &Params,
    s: &Setup,
    xip: &Array2<f64>,
    f: &Fields,
    out: &Path,
    src: &str,
    figures: &mut Vec<Figure>,
    tables: &mut Vec<Table>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    for (name, roi, along_x, colour) in [
        ("red", p.red_roi, true, (200, 30, 30)),
        ("blue", p.blue_roi, false, (30, 60, 200)),
    ] {
        let (pos, a) = roi_profile(xip, &s.grid, roi, along_x);
        let (_, b) = roi_profile(&f.eps_vol, &s.grid, roi, along_x);
        let (_, c) = roi_profile(&f.eps_area, &s.grid, roi, along_x);
        if pos.is_empty() || !a.iter().chain(&b).any(|v| v.is_finite()) {
            bail!(
                "the {name} ROI {roi:?} (d̄) holds no pixel where both sides have a strain; the common field of \
                 view is x {:.1}..{:.1}, y {:.1}..{:.1} d̄: move '{name}_roi'",
                s.grid.x0,
                s.grid.x0 + s.grid.nx as f64 * s.grid.dx,
                s.grid.y0,
                s.grid.y1()
            );
        }
        let diff: Vec<f64> = a.iter().zip(&b).map(|(x, y)| x - y).collect();
        let axis = if along_x { "x" } else { "y" };
        let csv = format!("profile_{name}.csv");
        table::write_table(
            &out.join(&csv),
            &[
                (if along_x { "x_d" } else { "y_d" }, Col::F64(&pos)),
                ("eps_vol_xip", Col::F64(&a)),
                ("eps_vol_tri", Col::F64(&b)),
                ("area_strain_tri", Col::F64(&c)),
                ("xip_minus_tri", Col::F64(&diff)),
            ],
        )?;
        files.push(csv.clone().into());
        tables.push(Table {
            path: csv.into(),
            caption: format!(
                "Profile along {axis} (d̄) of the {name} ROI {roi:?}: ε_vol by intensity (Eq. 5, XIP), ε_xx + ε_yy by \
                 triangulation (TRI), the triangles' area strain J − 1, and XIP − TRI. {src}."
            ),
        });
        let png = format!("profile_{name}.png");
        let title = format!("{name} ROI: ε_vol along {axis} (Su Fig. 6)");
        lines_png(
            &out.join(&png),
            &[
                Line {
                    label: "XIP (Eq. 5)",
                    x: &pos,
                    y: &a,
                    style: Style::Solid,
                    colour: Some(colour),
                },
                Line {
                    label: "TRI ε_xx + ε_yy",
                    x: &pos,
                    y: &b,
                    style: Style::Dashed,
                    colour: Some((20, 20, 20)),
                },
            ],
            &LinesPlot {
                title: &title,
                x_label: &format!("{axis} (d_bar from the plate)"),
                y_label: "volumetric strain (-)",
                h_refs: vec![Reference {
                    value: 0.0,
                    label: "",
                }],
                ..Default::default()
            },
        )?;
        figures.push(Figure {
            path: png.clone().into(),
            caption: format!(
                "Volumetric strain in the {name} ROI [x0, x1, y0, y1] = {roi:?} d̄, averaged along {}: from \
                 intensity (XIP, solid) and from triangulation (TRI, dashed), both on the √10 d̄ REV (RMS difference \
                 {:.3e}). {src}.",
                if along_x { "y" } else { "x" },
                rms_diff(&a, &b)
            ),
        });
        files.push(png.into());
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
pub(super) fn maps(
    p: &Params,
    run: &Run,
    s: &Setup,
    xip: &Array2<f64>,
    f: &Fields,
    step: u64,
    u: f64,
    out: &Path,
    src: &str,
    figures: &mut Vec<Figure>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    let mut shapes = plate_shapes(run, &s.frame, u);
    let [rx0, rx1, ry0, ry1] = p.red_roi;
    let [bx0, bx1, by0, by1] = p.blue_roi;
    shapes.push(Shape::rect(rx0, ry0, rx1, ry1, (210, 30, 30)));
    shapes.push(Shape::rect(bx0, by0, bx1, by1, (30, 60, 210)));
    let grid = |title: &'static str, label: &'static str| PanelGrid {
        title,
        cols: 2,
        label,
        cmap: Colormap::Diverging,
        range: None,
        extent: s.extent(),
        x_label: "x (d_bar)",
        y_label: "y (d_bar)",
        mark_label: None,
    };
    // XIP beside TRI on one colour scale, over the cells (pixels at map_step 1) where both are defined.
    let both = |a: &Array2<f64>, b: &Array2<f64>| {
        let mut a = a.clone();
        a.zip_mut_with(b, |x, y| {
            if !y.is_finite() {
                *x = f64::NAN;
            }
        });
        a
    };
    let (xb, tb) = (both(xip, &f.eps_vol), both(&f.eps_vol, xip));
    let panels = vec![
        Panel {
            title: "radiographs: ε_vol (Eq. 5, XIP)".into(),
            field: xb.view(),
            marked: None,
            shapes: shapes.clone(),
            frame: None,
        },
        Panel {
            title: "run: ε_xx + ε_yy (TRI)".into(),
            field: tb.view(),
            marked: None,
            shapes: shapes.clone(),
            frame: None,
        },
    ];
    let file = "eps_vol_side_by_side.png";
    let (lo, hi) = panels_png(
        &out.join(file),
        &panels,
        &grid(
            "volumetric strain, radiographs | simulation",
            "volumetric strain (-)",
        ),
    )?;
    figures.push(Figure {
        path: file.into(),
        caption: format!(
            "Volumetric strain from intensity (left, Eq. 5 on the √10 d̄ REV) and by triangulation of the run's grains \
             (right, ε_xx + ε_yy on the same pixels and REV), one colour scale ({lo:.3e} to {hi:.3e}); grey where either \
             side has none. Red and blue boxes: the ROIs of the profiles; dark outline: the push-plate. {src}."
        ),
    });
    files.push(file.into());
    let mut single = |file: String,
                      title: &'static str,
                      label: &'static str,
                      field: &Array2<f64>,
                      marked: Option<&Array2<bool>>,
                      caption: String|
     -> Result<()> {
        let mut g = grid(title, label);
        g.cols = 1;
        let mark = format!("Δp < {} Pa", p.pressure_threshold);
        if marked.is_some() {
            g.mark_label = Some(&mark);
        }
        let (lo, hi) = panels_png(
            &out.join(&file),
            &[Panel {
                title: format!("run, u_y = {:.2} d_bar", u / s.frame.d_bar),
                field: field.view(),
                marked: marked.map(|m| m.view()),
                shapes: shapes.clone(),
                frame: None,
            }],
            &g,
        )?;
        figures.push(Figure {
            path: file.clone().into(),
            caption: format!("{caption} Colour scale {lo:.3e} to {hi:.3e}. {src}."),
        });
        files.push(file.into());
        Ok(())
    };
    single(
        "eps_xy_tri.png".into(),
        "shear strain ε_xy by triangulation (Su Fig. 9)",
        "ε_xy (-)",
        &f.eps_xy,
        None,
        "Shear strain ε_xy = γ_xy/2 of the run by triangulation on the radiograph's grid (no radiograph \
         counterpart: intensity gives only the volumetric strain)."
            .into(),
    )?;
    if let Some(dp) = pressure_on_grid(run, step, s)? {
        let marked = dp.mapv(|v| v < p.pressure_threshold);
        single(
            "dp.png".into(),
            "liquid pressure change Δp (Su Fig. 10)",
            "Δp (Pa)",
            &dp,
            Some(&marked),
            format!(
                "Liquid pressure change Δp (Eq. 19) of the run on the same field of view; yellow: Δp below Δp_c = {} Pa \
                 (the cracking criterion, Sect. 3.5; Su take {DP_C} Pa).",
                p.pressure_threshold
            ),
        )?;
    }
    Ok(())
}

pub(super) fn agreement_outputs(
    a: &Agreement,
    out: &Path,
    src: &str,
    figures: &mut Vec<Figure>,
    tables: &mut Vec<Table>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    table::write_table(
        &out.join("agreement.csv"),
        &[
            ("frame", Col::U64(&a.frame)),
            ("step", Col::U64(&a.step)),
            ("u_y_d", Col::F64(&a.u_d)),
            ("mean_eps_vol_xip", Col::F64(&a.mean_xip)),
            ("mean_eps_vol_tri", Col::F64(&a.mean_tri)),
            ("mean_area_strain_tri", Col::F64(&a.mean_area)),
            ("rms_xip_minus_tri", Col::F64(&a.rms)),
            ("rms_xip_minus_area_strain", Col::F64(&a.rms_area)),
            ("correlation", Col::F64(&a.corr)),
            ("rms_profile_red", Col::F64(&a.rms_red)),
            ("rms_profile_blue", Col::F64(&a.rms_blue)),
            ("eps_vol_dem", Col::F64(&a.eps_dem)),
            ("net_signs_agree", Col::U64(&a.same_sign)),
            ("overlap_cells", Col::U64(&a.overlap)),
            ("mean_eps_vol_true", Col::F64(&a.mean_true)),
            ("rms_xip_minus_true", Col::F64(&a.rms_xip_true)),
            ("rms_true_minus_area_strain", Col::F64(&a.rms_true_area)),
        ],
    )?;
    files.push("agreement.csv".into());
    tables.push(Table {
        path: "agreement.csv".into(),
        caption: format!(
            "Agreement of every frame-snapshot pair over the map cells both sides cover (overlap_cells; the radiograph \
             stage's pixels at map_step 1): means of XIP ε_vol, TRI ε_xx + ε_yy \
             and TRI J − 1, RMS of XIP − TRI and XIP − (J − 1), their correlation, RMS of the red and blue profile \
             differences, ε_vol^DEM (Eq. 18) and whether the mean XIP and ε_vol^DEM have the same sign; with frames from \
             synth-run, also Eq. 5 on the true solid fraction (no blur, no noise) and its RMS differences from XIP and \
             from J − 1, which split XIP − TRI into what the imaging adds and what the two definitions differ by. {src}."
        ),
    });
    let f = "difference.png";
    lines_png(
        &out.join(f),
        &[
            Line {
                label: "mean XIP ε_vol",
                x: &a.u_d,
                y: &a.mean_xip,
                style: Style::LinePoints,
                colour: Some((200, 30, 30)),
            },
            Line {
                label: "mean TRI ε_xx + ε_yy",
                x: &a.u_d,
                y: &a.mean_tri,
                style: Style::Dashed,
                colour: Some((20, 20, 20)),
            },
            Line {
                label: "RMS(XIP − TRI)",
                x: &a.u_d,
                y: &a.rms,
                style: Style::LinePoints,
                colour: Some((30, 60, 200)),
            },
            Line {
                label: "ε_vol^DEM (Eq. 18)",
                x: &a.u_d,
                y: &a.eps_dem,
                style: Style::Points,
                colour: Some((30, 150, 50)),
            },
        ],
        &LinesPlot {
            title: "intensity (XIP) vs triangulation (TRI) over the run",
            x_label: "push-plate displacement u_y (d_bar)",
            y_label: "strain (-)",
            h_refs: vec![Reference {
                value: 0.0,
                label: "",
            }],
            ..Default::default()
        },
    )?;
    figures.push(Figure {
        path: f.into(),
        caption: format!(
            "The two strain operators on the same snapshots, frame by frame: field-of-view means of ε_vol from \
             intensity (Eq. 5) and of ε_xx + ε_yy from triangulation, the RMS of their difference per pixel, and the \
             sample's ε_vol^DEM (Eq. 18). {src}."
        ),
    });
    files.push(f.into());
    Ok(())
}
