//! Figures of several field maps side by side on one colour scale (Su et al. 2020 Figs. 7-11:
//! the same field of view for every case, each framed in the colour of its net class): one
//! shared colour bar, cells of a mask drawn in a highlight colour (Fig. 10's yellow Δp < Δp_c),
//! rectangles (ROIs) and polygons (the push-plate) over the maps. Axes are in the data units of
//! `extent` (mean grain diameters in the comparison figures).

use super::plot::{Colormap, FONT, MASKED, colour, de, finite_range, render_png};
use anyhow::{Result, bail};
use ndarray::ArrayView2;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// The highlight colour of marked cells (Fig. 10: yellow).
pub const MARK: (u8, u8, u8) = (255, 220, 0);

/// A polyline or polygon in data coordinates, drawn over a map.
#[derive(Clone, Debug)]
pub struct Shape {
    pub points: Vec<(f64, f64)>,
    pub colour: (u8, u8, u8),
    pub closed: bool,
}

impl Shape {
    /// The rectangle [x0, x1] × [y0, y1].
    pub fn rect(x0: f64, y0: f64, x1: f64, y1: f64, colour: (u8, u8, u8)) -> Self {
        Self {
            points: vec![(x0, y0), (x1, y0), (x1, y1), (x0, y1)],
            colour,
            closed: true,
        }
    }
}

/// One map. `field` rows run from the top of the extent down.
#[derive(Clone, Debug)]
pub struct Panel<'a> {
    pub title: String,
    pub field: ArrayView2<'a, f64>,
    /// Cells drawn in [`MARK`] instead of their value.
    pub marked: Option<ArrayView2<'a, bool>>,
    pub shapes: Vec<Shape>,
    /// Frame colour around the panel (a class colour), if any.
    pub frame: Option<(u8, u8, u8)>,
}

/// The layout and colour scale shared by every panel.
#[derive(Clone, Debug)]
pub struct PanelGrid<'a> {
    pub title: &'a str,
    pub cols: usize,
    /// Colour-bar label with units.
    pub label: &'a str,
    pub cmap: Colormap,
    /// Shared colour range; `None`: every panel's finite values (symmetric for Diverging).
    pub range: Option<(f64, f64)>,
    /// [x0, x1, y0, y1] of every panel, data units.
    pub extent: [f64; 4],
    pub x_label: &'a str,
    pub y_label: &'a str,
    /// Legend text for the marked cells (drawn under the colour bar).
    pub mark_label: Option<&'a str>,
}

/// The colour range `g` gives, or the panels' shared finite range.
pub fn shared_range(panels: &[Panel], g: &PanelGrid) -> (f64, f64) {
    let (mut lo, mut hi) = g
        .range
        .or_else(|| finite_range(panels.iter().flat_map(|p| p.field.iter().copied())))
        .unwrap_or((-1.0, 1.0));
    if g.cmap == Colormap::Diverging && g.range.is_none() {
        let m = lo.abs().max(hi.abs());
        (lo, hi) = (-m, m);
    }
    if hi <= lo {
        let pad = if lo == 0.0 { 1e-12 } else { lo.abs() * 1e-6 };
        (lo, hi) = (lo - pad, hi + pad);
    }
    (lo, hi)
}

/// Draw the panels in a grid of `g.cols` columns with one colour bar; returns the range used.
pub fn panels_png(path: &Path, panels: &[Panel], g: &PanelGrid) -> Result<(f64, f64)> {
    if panels.is_empty() {
        bail!("cannot draw '{}': no panels", g.title);
    }
    let [x0, x1, y0, y1] = g.extent;
    if !(x1 > x0 && y1 > y0) {
        bail!("cannot draw '{}': empty extent {:?}", g.title, g.extent);
    }
    let (lo, hi) = shared_range(panels, g);
    let cols = g.cols.clamp(1, panels.len());
    let rows = panels.len().div_ceil(cols);
    // Plot areas about 300 px on their long side.
    let aspect = (y1 - y0) / (x1 - x0);
    let long = if cols <= 2 { 420.0 } else { 300.0 };
    let (pw, ph) = if aspect <= 1.0 {
        (long, (long * aspect).max(90.0))
    } else {
        ((long / aspect).max(120.0), long)
    };
    let (cell_w, cell_h) = (pw as u32 + 80, ph as u32 + 85);
    let bar_w = 150;
    let size = (cols as u32 * cell_w + bar_w, rows as u32 * cell_h + 45);
    // Titles shrink to fit the figure's width (about 0.55 em per character).
    let fit =
        |text: &str, max: f64, width: f64| (width / (0.55 * text.chars().count().max(1) as f64)).min(max);
    let title_font = fit(g.title, 20.0, size.0 as f64 - 20.0);
    let panel_font = panels
        .iter()
        .map(|p| fit(&p.title, 14.0, cell_w as f64 - 20.0))
        .fold(14.0, f64::min);
    render_png(path, size, None, |root| {
        root.fill(&WHITE).map_err(de)?;
        let root = root.titled(g.title, (FONT, title_font)).map_err(de)?;
        let (grid, bar) = root.split_horizontally(size.0 - bar_w);
        let cells = grid.split_evenly((rows, cols));
        for (p, cell) in panels.iter().zip(cells.iter()) {
            draw_panel(cell, p, g, lo, hi, panel_font)?;
        }
        colour_bar(&bar, g, lo, hi)
    })?;
    Ok((lo, hi))
}

fn draw_panel(
    cell: &DrawingArea<BitMapBackend, Shift>,
    p: &Panel,
    g: &PanelGrid,
    lo: f64,
    hi: f64,
    font: f64,
) -> Result<()> {
    let [x0, x1, y0, y1] = g.extent;
    let mut chart = ChartBuilder::on(cell)
        .caption(&p.title, (FONT, font))
        .margin(6)
        .x_label_area_size(34)
        .y_label_area_size(44)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(de)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc(g.x_label)
        .y_desc(g.y_label)
        .x_labels(5)
        .y_labels(5)
        .label_style((FONT, 11))
        .draw()
        .map_err(de)?;
    let (ny, nx) = p.field.dim();
    if nx > 0 && ny > 0 {
        let area = chart.plotting_area().strip_coord_spec();
        let (aw, ah) = area.dim_in_pixel();
        let mark = RGBColor(MARK.0, MARK.1, MARK.2);
        for py in 0..ah {
            let row = (((py as f64 + 0.5) / ah as f64 * ny as f64) as usize).min(ny - 1);
            for px in 0..aw {
                let col = (((px as f64 + 0.5) / aw as f64 * nx as f64) as usize).min(nx - 1);
                let c = if p
                    .marked
                    .is_some_and(|m| m.get((row, col)).copied().unwrap_or(false))
                {
                    mark
                } else {
                    let v = p.field[[row, col]];
                    if v.is_finite() {
                        colour(g.cmap, (v - lo) / (hi - lo))
                    } else {
                        MASKED
                    }
                };
                area.draw_pixel((px as i32, py as i32), &c).map_err(de)?;
            }
        }
    }
    for s in &p.shapes {
        let c = RGBColor(s.colour.0, s.colour.1, s.colour.2);
        let mut pts: Vec<(f64, f64)> = s
            .points
            .iter()
            .map(|&(x, y)| (x.clamp(x0, x1), y.clamp(y0, y1)))
            .collect();
        if s.closed && !pts.is_empty() {
            pts.push(pts[0]);
        }
        chart
            .draw_series(std::iter::once(PathElement::new(pts, c.stroke_width(2))))
            .map_err(de)?;
    }
    if let Some(f) = p.frame {
        let c = RGBColor(f.0, f.1, f.2);
        let (w, h) = cell.dim_in_pixel();
        cell.draw(&Rectangle::new(
            [(1, 1), (w as i32 - 2, h as i32 - 2)],
            c.stroke_width(3),
        ))
        .map_err(de)?;
    }
    Ok(())
}

fn colour_bar(area: &DrawingArea<BitMapBackend, Shift>, g: &PanelGrid, lo: f64, hi: f64) -> Result<()> {
    let (upper, lower) = area.split_vertically(area.dim_in_pixel().1.saturating_sub(70));
    let mut bar = ChartBuilder::on(&upper)
        .margin_top(30)
        .margin_bottom(20)
        .margin_right(10)
        // A gap on the left keeps the label off the neighbouring panel's frame.
        .margin_left(15)
        .y_label_area_size(75)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(de)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(g.label)
        .label_style((FONT, 12))
        .draw()
        .map_err(de)?;
    let n = 256;
    bar.draw_series((0..n).map(|i| {
        let (a, b) = (
            lo + (hi - lo) * i as f64 / n as f64,
            lo + (hi - lo) * (i + 1) as f64 / n as f64,
        );
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            colour(g.cmap, (i as f64 + 0.5) / n as f64).filled(),
        )
    }))
    .map_err(de)?;
    if let Some(text) = g.mark_label {
        lower
            .draw(&Rectangle::new(
                [(10, 10), (28, 28)],
                RGBColor(MARK.0, MARK.1, MARK.2).filled(),
            ))
            .map_err(de)?;
        lower
            .draw(&Text::new(text.to_string(), (34, 12), (FONT, 12)))
            .map_err(de)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    #[test]
    fn a_grid_of_panels_shares_one_symmetric_range() {
        let dir = tempfile::tempdir().unwrap();
        let a = Array2::from_shape_fn((20, 30), |(r, c)| (c as f64 - r as f64) * 0.01);
        let b = Array2::from_shape_fn((20, 30), |(r, _)| -0.5 + r as f64 * 0.001);
        let m = Array2::from_shape_fn((20, 30), |(r, c)| r < 3 && c < 3);
        let panels = vec![
            Panel {
                title: "a".into(),
                field: a.view(),
                marked: Some(m.view()),
                shapes: vec![Shape::rect(-1.0, 0.0, 1.0, 5.0, (200, 0, 0))],
                frame: Some((0, 150, 0)),
            },
            Panel {
                title: "b".into(),
                field: b.view(),
                marked: None,
                shapes: vec![],
                frame: None,
            },
        ];
        let g = PanelGrid {
            title: "two",
            cols: 2,
            label: "eps (-)",
            cmap: Colormap::Diverging,
            range: None,
            extent: [-5.0, 5.0, 0.0, 7.0],
            x_label: "x (d)",
            y_label: "y (d)",
            mark_label: Some("dp < dp_c"),
        };
        let p = dir.path().join("p.png");
        let (lo, hi) = panels_png(&p, &panels, &g).unwrap();
        assert_eq!((lo, hi), (-0.5, 0.5));
        let img = image::open(&p).unwrap();
        assert!(img.width() > 2 * 420 && img.height() > 200);
        assert!(panels_png(&p, &[], &g).is_err());
    }
}
