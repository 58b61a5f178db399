//! The figures of the `extrusion` stage, after Ness et al. (2017) Figs. 3, 4, 6, 7 and 8, on
//! axes in d (x from the ram face, y across the channel), every map on the bins of
//! `fields.csv`, grey where no grain passed.

use super::run::ExtruderRun;
use super::{Layout, Measured};
use crate::contract::Figure;
use crate::report::lines::{Line, LinesPlot, Reference, Style, lines_png};
use crate::report::panels::{Panel, PanelGrid, Shape, panels_png};
use crate::report::plot::Colormap;
use anyhow::Result;
use lbdem_analysis::coarse::{CoarseFields, Gradient};
use ndarray::{Array2, s};
use std::path::Path;

/// Columns [i0, i1) of a field whose bin centres lie in [x0, x1] (d), rows flipped so row 0 is
/// the top (the panels' convention), with the extent in d.
fn window(f: &CoarseFields, a: &Array2<f64>, lay: &Layout, x: [f64; 2]) -> (Array2<f64>, [f64; 4]) {
    let g = f.grid;
    let to_d = |v: f64| v / lay.d;
    let cols: Vec<usize> = (0..g.nx)
        .filter(|&ix| {
            let c = to_d(g.centre(ix, 0).0);
            c >= x[0] && c <= x[1]
        })
        .collect();
    let (i0, i1) = (
        cols.first().copied().unwrap_or(0),
        cols.last().map_or(1, |c| c + 1),
    );
    let sub = a.slice(s![..;-1, i0..i1]).to_owned();
    let extent = [
        to_d(g.x0 + i0 as f64 * g.size),
        to_d(g.x0 + i1 as f64 * g.size),
        to_d(g.y0),
        to_d(g.y0 + g.ny as f64 * g.size),
    ];
    (sub, extent)
}

/// Mean over the occupied bins with centre x in `x` (d), per row: (y in d, value).
fn across(f: &CoarseFields, a: &Array2<f64>, lay: &Layout, x: [f64; 2]) -> (Vec<f64>, Vec<f64>) {
    let g = f.grid;
    let (mut ys, mut vs) = (Vec::new(), Vec::new());
    for iy in 0..g.ny {
        let (mut s, mut n) = (0.0, 0usize);
        for ix in 0..g.nx {
            let cx = g.centre(ix, iy).0 / lay.d;
            let v = a[[iy, ix]];
            if cx >= x[0] && cx <= x[1] && f.count[[iy, ix]] > 0.0 && v.is_finite() {
                s += v;
                n += 1;
            }
        }
        if n > 0 {
            ys.push(g.centre(0, iy).1 / lay.d);
            vs.push(s / n as f64);
        }
    }
    (ys, vs)
}

/// Along x on the centreline: the mean of the rows whose centre is within half a bin of y = 0.
fn centreline(f: &CoarseFields, a: &Array2<f64>, lay: &Layout) -> (Vec<f64>, Vec<f64>) {
    let g = f.grid;
    let (mut xs, mut vs) = (Vec::new(), Vec::new());
    for ix in 0..g.nx {
        let (mut s, mut n) = (0.0, 0usize);
        for iy in 0..g.ny {
            let cy = g.centre(ix, iy).1;
            let v = a[[iy, ix]];
            if cy.abs() <= 0.5 * g.size * (1.0 + 1e-9) && v.is_finite() {
                s += v;
                n += 1;
            }
        }
        if n > 0 {
            xs.push(g.centre(ix, 0).0 / lay.d);
            vs.push(s / n as f64);
        }
    }
    (xs, vs)
}

/// A profile across the barrel beside the same across the die, against y (d).
fn barrel_and_die(
    path: &Path,
    labels: [&str; 2],
    barrel: &(Vec<f64>, Vec<f64>),
    die: &(Vec<f64>, Vec<f64>),
    title: &str,
    y_label: &str,
) -> Result<()> {
    let [(lb, b), (ld, d)] = [(labels[0], barrel), (labels[1], die)];
    let lines = [
        Line {
            label: lb,
            x: &b.0,
            y: &b.1,
            style: Style::LinePoints,
            colour: None,
        },
        Line {
            label: ld,
            x: &d.0,
            y: &d.1,
            style: Style::LinePoints,
            colour: None,
        },
    ];
    lines_png(
        path,
        &lines,
        &LinesPlot {
            title,
            x_label: "y (d)",
            y_label,
            ..Default::default()
        },
    )
}

fn outline(lay: &Layout) -> Shape {
    let (b, w, e) = (0.5 * lay.barrel_width, 0.5 * lay.die_width, lay.end());
    Shape {
        points: vec![
            (0.0, -b),
            (lay.barrel_length, -b),
            (lay.barrel_length, -w),
            (e, -w),
            (e, w),
            (lay.barrel_length, w),
            (lay.barrel_length, b),
            (0.0, b),
        ],
        colour: (40, 40, 40),
        closed: true,
    }
}

struct Map<'a> {
    file: &'a str,
    title: String,
    label: &'a str,
    cmap: Colormap,
    field: Array2<f64>,
    marked: Option<Array2<bool>>,
    x: [f64; 2],
    caption: String,
}

fn draw_map(out: &Path, f: &CoarseFields, lay: &Layout, m: Map, shapes: Vec<Shape>) -> Result<Figure> {
    let (field, extent) = window(f, &m.field, lay, m.x);
    let marked = m.marked.map(|mk| {
        let as_f = mk.mapv(|b| if b { 1.0 } else { 0.0 });
        window(f, &as_f, lay, m.x).0.mapv(|v| v > 0.5)
    });
    let panel = Panel {
        title: String::new(),
        field: field.view(),
        marked: marked.as_ref().map(|a| a.view()),
        shapes,
        frame: None,
    };
    panels_png(
        &out.join(m.file),
        &[panel],
        &PanelGrid {
            title: &m.title,
            cols: 1,
            label: m.label,
            cmap: m.cmap,
            range: None,
            extent,
            x_label: "x (d)",
            y_label: "y (d)",
            mark_label: marked.as_ref().map(|_| "static zone"),
        },
    )?;
    Ok(Figure {
        path: m.file.into(),
        caption: m.caption,
    })
}

pub fn draw(
    out: &Path,
    f: &CoarseFields,
    g: &Gradient,
    lay: &Layout,
    m: &Measured,
    run: &ExtruderRun,
) -> Result<Vec<Figure>> {
    let mut figs = Vec::new();
    let all = [0.0, lay.end()];
    let entry = [
        lay.barrel_length - 0.5 * lay.barrel_width,
        (lay.barrel_length + lay.barrel_width.min(lay.die_length)).min(lay.end()),
    ];
    let src = format!(
        "{} run(s), {} snapshots from t = {:.3e} s; bins {:.2} d",
        m.runs,
        m.snapshots,
        m.window_from.iter().copied().fold(f64::INFINITY, f64::min),
        f.grid.size / lay.d
    );
    let stations: Vec<Shape> = m
        .stations_d
        .iter()
        .map(|w| {
            let h = lay.half_width(0.5 * (w[0] + w[1]));
            Shape::rect(w[0], -h, w[1], h, (230, 120, 0))
        })
        .collect();
    // Fig. 3a with the static zones of Fig. 5 marked.
    let v_ref = m.centreline_velocity;
    let (zx, zy) = lay.static_window();
    let (zone, _) = f.static_zone(v_ref, m.static_fraction, zx, zy);
    let mut shapes = vec![outline(lay)];
    shapes.extend(stations.iter().cloned());
    figs.push(draw_map(
        out,
        f,
        lay,
        Map {
            file: "velocity.png",
            title: format!("{}: |V| / V_barrel (Ness Fig. 3a)", m.label),
            label: "|V| / V_barrel (-)",
            cmap: Colormap::Viridis,
            field: f.speed() / v_ref,
            marked: Some(zone),
            x: all,
            caption: format!(
                "Speed over the barrel's centreline speed V_barrel = {:.3e} m/s (mean between P1 and P2); yellow: \
                 the static zones (below {} V_barrel within half a barrel width of the die entry, {:.1} grains); \
                 orange boxes: the pressure stations P1-P4. {src}.",
                v_ref, m.static_fraction, m.static_grains
            ),
        },
        shapes,
    )?);
    // Fig. 3c-e: the centreline, and across the barrel and the die.
    let speed = f.speed() / v_ref;
    let (cx, cv) = centreline(f, &speed, lay);
    let mid_barrel = [m.stations_d[0][0], m.stations_d[1][1]];
    let mid_die = [
        m.stations_d[2][1],
        m.stations_d[3][0].max(m.stations_d[2][1] + 1.0),
    ];
    lines_png(
        &out.join("centreline.png"),
        &[Line {
            label: "y = 0",
            x: &cx,
            y: &cv,
            style: Style::LinePoints,
            colour: None,
        }],
        &LinesPlot {
            title: "Centreline speed (Ness Fig. 3c)",
            x_label: "x (d)",
            y_label: "|V| / V_barrel (-)",
            v_refs: vec![Reference {
                value: lay.barrel_length,
                label: "die entry",
            }],
            ..Default::default()
        },
    )?;
    figs.push(Figure {
        path: "centreline.png".into(),
        caption: format!("Speed along y = 0 over V_barrel; the die carries about W_b/W_d = {:.1} times the barrel's. {src}.", lay.barrel_width / lay.die_width),
    });
    let bl = format!("barrel, x {:.0}-{:.0} d", mid_barrel[0], mid_barrel[1]);
    let dl = format!("die, x {:.0}-{:.0} d", mid_die[0], mid_die[1]);
    barrel_and_die(
        &out.join("plug.png"),
        [&bl, &dl],
        &across(f, &speed, lay, mid_barrel),
        &across(f, &speed, lay, mid_die),
        "Speed across the channel (Ness Fig. 3d-e)",
        "|V| / V_barrel (-)",
    )?;
    figs.push(Figure {
        path: "plug.png".into(),
        caption: format!("Speed across the barrel and the die, averaged over the x windows named (plug flow is flat). {src}."),
    });
    // Fig. 4: the four gradients as Stokes numbers at the die entry.
    let st = run.stokes_scale();
    for (file, name, a, b) in [
        ("stokes_xy.png", "St_xy = ρd²/η_f ∂V_x/∂y (Fig. 4a)", 0, 1),
        ("stokes_yx.png", "St_yx = ρd²/η_f ∂V_y/∂x (Fig. 4b)", 1, 0),
        ("stokes_xx.png", "St_xx = ρd²/η_f ∂V_x/∂x (Fig. 4c)", 0, 0),
        ("stokes_yy.png", "St_yy = ρd²/η_f ∂V_y/∂y (Fig. 4d)", 1, 1),
    ] {
        figs.push(draw_map(
            out,
            f,
            lay,
            Map {
                file,
                title: format!("{}: {name}", m.label),
                label: "Stokes number (-)",
                cmap: Colormap::Diverging,
                field: &g[a][b] * st,
                marked: None,
                x: entry,
                caption: format!(
                    "Velocity gradient at the die entry scaled by ρd²/η_f = {st:.3e} s (a Stokes number; Ness: ≪ 1 \
                     everywhere; largest |St| over the channel {:.2e}). Central differences between bins. {src}.",
                    m.max_stokes
                ),
            },
            vec![outline(lay)],
        )?);
    }
    // Fig. 6: P, σ_xy and N_1 over P_barrel (P1), N_1 in the die over P_die (P3).
    let (p_b, p_d) = (m.station_pressure[0], m.station_pressure[2]);
    let n1 = f.n1();
    for (file, title, label, cmap, field, x, scale) in [
        (
            "pressure.png",
            "P / P_barrel (Fig. 6a)",
            "P / P_barrel (-)",
            Colormap::Viridis,
            f.pressure(false),
            all,
            p_b,
        ),
        (
            "shear_stress.png",
            "σ_xy / P_barrel (Fig. 6b)",
            "σ_xy / P_barrel (-)",
            Colormap::Diverging,
            f.sigma[1].clone(),
            all,
            p_b,
        ),
        (
            "n1.png",
            "N_1 / P_barrel (Fig. 6c)",
            "N_1 / P_barrel (-)",
            Colormap::Diverging,
            n1.clone(),
            all,
            p_b,
        ),
        (
            "n1_die.png",
            "N_1 / P_die in the die (Fig. 6d)",
            "N_1 / P_die (-)",
            Colormap::Diverging,
            n1.clone(),
            [lay.barrel_length, lay.end()],
            p_d,
        ),
    ] {
        figs.push(draw_map(
            out,
            f,
            lay,
            Map {
                file,
                title: format!("{}: {title}", m.label),
                label,
                cmap,
                field: field / scale,
                marked: None,
                x,
                caption: format!(
                    "Coarse-grained stress of Eq. 7 (contact and lubrication dipoles, compression positive) over \
                     P_barrel = {p_b:.3e} Pa (station P1) or P_die = {p_d:.3e} Pa (P3); the contact forces carry \
                     {:.0} % of the pressure. {src}.",
                    100.0 * m.contact_pressure_share
                ),
            },
            vec![outline(lay)],
        )?);
    }
    // Fig. 7: dissipation.
    figs.push(draw_map(
        out,
        f,
        lay,
        Map {
            file: "dissipation.png",
            title: format!("{}: S = σ : γ̇ (Fig. 7)", m.label),
            label: "S (W/m³)",
            cmap: Colormap::Diverging,
            field: f.dissipation(g),
            marked: None,
            x: entry,
            caption: format!(
                "Rate of working per volume at the die entry, S = −Σ σ_ba ∂V_a/∂x_b (compression-positive σ; \
                 positive where the paste dissipates). {src}."
            ),
        },
        vec![outline(lay)],
    )?);
    // Fig. 8: σ_xy/P and φ across the barrel and the die; the ratio of the row means (a bin's
    // own ratio is noise where P is small).
    let pressure = f.pressure(false);
    let ratio_across = |x: [f64; 2]| {
        let (y, s) = across(f, &f.sigma[1], lay, x);
        let (_, p) = across(f, &pressure, lay, x);
        let r: Vec<f64> = s.iter().zip(&p).map(|(s, p)| s / p).collect();
        (y, r)
    };
    for (file, title, ylab, ratio) in [
        (
            "stress_ratio.png",
            "Stress ratio across the channel (Ness Fig. 8a-b)",
            "σ_xy / P (-)",
            true,
        ),
        (
            "phi_across.png",
            "Volume fraction across the channel (Ness Fig. 8c-d)",
            "φ (-)",
            false,
        ),
    ] {
        let (barrel, die) = if ratio {
            (ratio_across(mid_barrel), ratio_across(mid_die))
        } else {
            (
                across(f, &f.phi, lay, mid_barrel),
                across(f, &f.phi, lay, mid_die),
            )
        };
        barrel_and_die(&out.join(file), [&bl, &dl], &barrel, &die, title, ylab)?;
        figs.push(Figure {
            path: file.into(),
            caption: format!(
                "{title}: bin rows averaged over the barrel between P1 and P2 and over the die between P3 and P4 \
                 (σ_xy / P: the ratio of the row means; φ: volume of the grains whose centre is in the bin over the \
                 bin's, Ness's definition). {src}."
            ),
        });
    }
    Ok(figs)
}
