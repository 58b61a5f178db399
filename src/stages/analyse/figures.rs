//! The analysis's figures: per-snapshot field panels (Figs. 8-10) and the series charts.

use super::{Params, SnapshotRows, plate_shapes};
use crate::contract::Figure;
use crate::report::lines::{Line, LinesPlot, Reference, Style, lines_png};
use crate::report::panels::{Panel, PanelGrid, panels_png};
use crate::report::plot::Colormap;
use crate::stages::run_data::Run;
use crate::stages::strain_fields::Setup;
use anyhow::Result;
use lbdem_analysis::cracking;
use std::path::{Path, PathBuf};

#[allow(clippy::too_many_arguments)]
pub(super) fn draw_maps(
    p: &Params,
    run: &Run,
    s: &Setup,
    f: &crate::stages::strain_fields::Fields,
    dp: Option<&ndarray::Array2<f64>>,
    step: u64,
    u: f64,
    label: &str,
    out: &Path,
    figures: &mut Vec<Figure>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    let d_bar = s.frame.d_bar;
    let shapes = plate_shapes(run, &s.frame, u);
    let grid = |title: &'static str, label: &'static str, cmap| PanelGrid {
        title,
        cols: 1,
        label,
        cmap,
        range: None,
        extent: s.extent(),
        x_label: "x (d_bar)",
        y_label: "y (d_bar)",
        mark_label: None,
    };
    let ud = u / d_bar;
    let mut one = |file: String,
                   field: &ndarray::Array2<f64>,
                   marked: Option<&ndarray::Array2<bool>>,
                   g: PanelGrid,
                   caption: String|
     -> Result<()> {
        let panel = Panel {
            title: format!("{label}, u_y = {ud:.2} d_bar"),
            field: field.view(),
            marked: marked.map(|m| m.view()),
            shapes: shapes.clone(),
            frame: None,
        };
        let (lo, hi) = panels_png(&out.join(&file), &[panel], &g)?;
        figures.push(Figure {
            path: file.clone().into(),
            caption: format!("{caption} Colour scale {lo:.3e} to {hi:.3e}."),
        });
        files.push(file.into());
        Ok(())
    };
    one(
        format!("eps_vol_tri_{step:09}.png"),
        &f.eps_vol,
        None,
        grid(
            "ε_xx + ε_yy by triangulation (Su Fig. 8)",
            "ε_xx + ε_yy (-)",
            Colormap::Diverging,
        ),
        format!(
            "Volumetric strain ε_xx + ε_yy by triangulation of the grain centroids (Su et al. 2020 Sect. 2.5), \
             √10 d̄ REV, run '{label}' at step {step} (u_y = {ud:.2} d̄) against the reference; positive = dilation; \
             x, y in d̄ = {d_bar:.3e} m from the middle of the push-plate's face (dark outline). From {}.",
            run.dir.display()
        ),
    )?;
    one(
        format!("eps_xy_tri_{step:09}.png"),
        &f.eps_xy,
        None,
        grid(
            "ε_xy by triangulation (Su Fig. 9)",
            "ε_xy (-)",
            Colormap::Diverging,
        ),
        format!(
            "Shear strain ε_xy = γ_xy/2 by triangulation, √10 d̄ REV, run '{label}' at step {step} (u_y = {ud:.2} d̄). \
             From {}.",
            run.dir.display()
        ),
    )?;
    if let Some(dp) = dp {
        let marked = dp.mapv(|v| v < p.pressure_threshold);
        let mut g = grid(
            "liquid pressure change Δp (Su Fig. 10)",
            "Δp (Pa)",
            Colormap::Diverging,
        );
        let mark = format!("Δp < {} Pa", p.pressure_threshold);
        g.mark_label = Some(&mark);
        one(
            format!("dp_{step:09}.png"),
            dp,
            Some(&marked),
            g,
            format!(
                "Liquid pressure change Δp = (ρ − ρ₀)c_s² (Eq. 19) on the liquid nodes of run '{label}' at step {step} \
                 (u_y = {ud:.2} d̄); yellow: Δp below Δp_c = {} Pa (Sect. 3.5); grey: no liquid. From {}.",
                p.pressure_threshold,
                run.dir.display()
            ),
        )?;
    }
    Ok(())
}

#[allow(clippy::too_many_arguments)]
pub(super) fn series_figures(
    p: &Params,
    run: &Run,
    rows: &SnapshotRows,
    crossing: Option<cracking::Crossing>,
    d_bar: f64,
    out: &Path,
    figures: &mut Vec<Figure>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    let u = run
        .series("plate_displacement")
        .map(|v| v.iter().map(|x| x / d_bar).collect::<Vec<_>>());
    let src = run.dir.display();
    if let (Some(u), Some(e)) = (&u, run.series("eps_vol_dem")) {
        let lines = [
            Line {
                label: "series (Eq. 18)",
                x: u,
                y: &e,
                style: Style::Solid,
                colour: None,
            },
            Line {
                label: "snapshots: membrane polygon (Eq. 18)",
                x: &rows.u_d,
                y: &rows.eq18_snapshot,
                style: Style::Points,
                colour: None,
            },
            Line {
                label: "snapshots: ln J of the triangulation",
                x: &rows.u_d,
                y: &rows.mesh_ln_j,
                style: Style::Points,
                colour: Some((40, 160, 40)),
            },
        ];
        let f = "eps_vol_dem.png";
        lines_png(
            &out.join(f),
            &lines,
            &LinesPlot {
                title: "total volumetric strain ε_vol^DEM (Su Eq. 18)",
                x_label: "push-plate displacement u_y (d_bar)",
                y_label: "ε_vol^DEM = ln(A_def/A_0) (-)",
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
                "ε_vol^DEM = ln(A_def/A₀) (Eq. 18) against the push-plate displacement: the run's series (line), \
                 the same from each particle snapshot's membrane polygon minus the plate's penetration (points), \
                 and ln J of the triangulated region (green). Negative: net contraction. From {src}."
            ),
        });
        files.push(f.into());
    }
    if let (Some(u), Some(d)) = (&u, run.series("dp_min")) {
        let mut opts = LinesPlot {
            title: "minimum liquid pressure change (Su Sect. 3.5)",
            x_label: "push-plate displacement u_y (d_bar)",
            y_label: "Δp_min (Pa)",
            h_refs: vec![Reference {
                value: p.pressure_threshold,
                label: "Δp_c",
            }],
            ..Default::default()
        };
        if let Some(c) = crossing {
            opts.v_refs.push(Reference {
                value: c.u_d,
                label: "u_y,min",
            });
        }
        let f = "dp_min.png";
        lines_png(
            &out.join(f),
            &[Line {
                label: "Δp_min over liquid nodes",
                x: u,
                y: &d,
                style: Style::Solid,
                colour: Some((40, 80, 200)),
            }],
            &opts,
        )?;
        figures.push(Figure {
            path: f.into(),
            caption: format!(
                "Lowest liquid pressure change over the liquid nodes (Eq. 19) against u_y, with the cracking \
                 threshold Δp_c = {} Pa; {}. From {src}.",
                p.pressure_threshold,
                match crossing {
                    Some(c) => format!("first crossed at u_y,min = {:.2} d̄ (t = {:.4e} s)", c.u_d, c.time),
                    None => "never crossed".into(),
                }
            ),
        });
        files.push(f.into());
    }
    if let (Some(u), Some(i)) = (&u, run.series("inertial_number")) {
        let f = "inertial_number.png";
        lines_png(
            &out.join(f),
            &[Line {
                label: "I (Eq. 20)",
                x: u,
                y: &i,
                style: Style::Solid,
                colour: None,
            }],
            &LinesPlot {
                title: "inertial number (Su Eq. 20)",
                x_label: "push-plate displacement u_y (d_bar)",
                y_label: "I (-)",
                log_y: true,
                h_refs: vec![
                    Reference {
                        value: 1e-3,
                        label: "quasi-static limit 1e-3",
                    },
                    Reference {
                        value: 1e-1,
                        label: "collisional 1e-1",
                    },
                ],
                ..Default::default()
            },
        )?;
        figures.push(Figure {
            path: f.into(),
            caption: format!(
                "Inertial number I = γ̇ d̄ √(ρ/p') (Eq. 20) against u_y, with the quasi-static (1e-3) and \
                 collisional (1e-1) limits of Sect. 3.4. From {src}."
            ),
        });
        files.push(f.into());
    }
    Ok(())
}
