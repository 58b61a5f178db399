//! A map over a grid of settings (the stability maps): one cell per run, its colour the run's
//! outcome, a mark on it for what a check said of it. The axes are the grid's indices, labelled
//! with the settings' values, so unevenly spaced values (τ crowding toward ½) get equal cells.

use super::plot::{FONT, de, render_png};
use anyhow::{Result, bail};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// What is drawn on a cell over its colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mark {
    None,
    /// An open circle.
    Ring,
    /// A cross.
    Cross,
}

#[derive(Clone, Copy, Debug)]
pub struct Cell {
    pub ix: usize,
    pub iy: usize,
    pub colour: (u8, u8, u8),
    pub mark: Mark,
}

#[derive(Clone, Debug)]
pub struct GridMap<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    /// Tick label of each column and row.
    pub x_ticks: &'a [String],
    pub y_ticks: &'a [String],
    /// Legend of the colours, then of the marks.
    pub colours: &'a [(&'a str, (u8, u8, u8))],
    pub marks: &'a [(&'a str, Mark)],
}

fn rgb(c: (u8, u8, u8)) -> RGBColor {
    RGBColor(c.0, c.1, c.2)
}

pub fn grid_map_png(path: &Path, cells: &[Cell], g: &GridMap) -> Result<()> {
    let (nx, ny) = (g.x_ticks.len(), g.y_ticks.len());
    if let Some(c) = cells.iter().find(|c| c.ix >= nx || c.iy >= ny) {
        bail!(
            "grid map '{}': cell ({}, {}) outside the {nx} x {ny} grid",
            g.title,
            c.ix,
            c.iy
        );
    }
    render_png(path, (980, 620), None, |root| {
        root.fill(&WHITE).map_err(de)?;
        let (root, side) = root.split_horizontally(760);
        let mut chart = ChartBuilder::on(&root)
            .caption(g.title, (FONT, 18))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(105)
            .build_cartesian_2d(-0.5..nx as f64 - 0.5, -0.5..ny as f64 - 0.5)
            .map_err(de)?;
        let tick = |ticks: &[String], v: f64| {
            let i = v.round();
            if (v - i).abs() < 1e-6 && i >= 0.0 {
                ticks.get(i as usize).cloned().unwrap_or_default()
            } else {
                String::new()
            }
        };
        let (fx, fy) = (|v: &f64| tick(g.x_ticks, *v), |v: &f64| tick(g.y_ticks, *v));
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(nx.max(2) * 2 + 1)
            .y_labels(ny.max(2) * 2 + 1)
            .x_label_formatter(&fx)
            .y_label_formatter(&fy)
            .x_desc(g.x_label)
            .y_desc(g.y_label)
            .label_style((FONT, 12))
            .draw()
            .map_err(de)?;
        for c in cells {
            let (x, y) = (c.ix as f64, c.iy as f64);
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(x - 0.47, y - 0.47), (x + 0.47, y + 0.47)],
                    rgb(c.colour).filled(),
                )))
                .map_err(de)?;
            draw_mark(&root, chart.backend_coord(&(x, y)), c.mark)?;
        }
        let mut at = 40;
        for (text, colour) in g.colours {
            side.draw(&Rectangle::new(
                [(10, at - 8), (26, at + 8)],
                rgb(*colour).filled(),
            ))
            .map_err(de)?;
            side.draw(&Text::new(text.to_string(), (34, at - 7), (FONT, 13)))
                .map_err(de)?;
            at += 26;
        }
        at += 10;
        for (text, mark) in g.marks {
            side.draw(&Rectangle::new(
                [(10, at - 8), (26, at + 8)],
                RGBColor(220, 220, 220).filled(),
            ))
            .map_err(de)?;
            draw_mark(&side, (18, at), *mark)?;
            side.draw(&Text::new(text.to_string(), (34, at - 7), (FONT, 13)))
                .map_err(de)?;
            at += 26;
        }
        Ok(())
    })
}

/// Draw `mark` centred on pixel `at` of `area`.
fn draw_mark(area: &DrawingArea<BitMapBackend, Shift>, at: (i32, i32), mark: Mark) -> Result<()> {
    let ink = BLACK.stroke_width(2);
    let (x, y) = at;
    match mark {
        Mark::None => {}
        Mark::Ring => area.draw(&Circle::new(at, 7, ink)).map_err(de)?,
        Mark::Cross => {
            area.draw(&PathElement::new(vec![(x - 7, y - 7), (x + 7, y + 7)], ink))
                .map_err(de)?;
            area.draw(&PathElement::new(vec![(x - 7, y + 7), (x + 7, y - 7)], ink))
                .map_err(de)?;
        }
    }
    Ok(())
}
