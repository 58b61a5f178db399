//! Plots every stage uses. Fields are `ndarray` views indexed `[row, col]` = `[y, x]`
//! with row 0 at the top, as in an image.
//!
//! Text is drawn with DejaVu Sans embedded in the binary (plotters' `ab_glyph`), so a
//! PNG is the same byte for byte on every machine. PNGs are encoded by `image` and
//! written atomically.

use anyhow::{Context, Result, bail};
use ndarray::ArrayView2;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::{BlackWhite, ViridisRGB};
use std::path::Path;
use std::sync::Once;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Colormap {
    /// Sequential (solid fraction, thickness, intensity).
    Viridis,
    /// Blue-white-red, centred on zero (strain, pressure change).
    Diverging,
    Gray,
}

/// Options of a field map. NaN pixels are drawn grey (masked).
#[derive(Clone, Debug)]
pub struct FieldPlot<'a> {
    pub title: &'a str,
    /// Colour-bar label with units, e.g. "g_S (-)".
    pub label: &'a str,
    pub cmap: Colormap,
    /// Colour range; `None` takes the finite min/max (symmetric about 0 for Diverging).
    pub range: Option<(f64, f64)>,
    /// Pixel size in metres: axes in mm when given, in pixels otherwise.
    pub pixel_size: Option<f64>,
}

/// One line (or point set) of an x-y plot.
#[derive(Clone, Debug)]
pub struct Series<'a> {
    pub label: &'a str,
    pub x: &'a [f64],
    pub y: &'a [f64],
    /// Draw markers instead of a line (measured data).
    pub points: bool,
}

#[derive(Clone, Debug, Default)]
pub struct XyPlot<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub log_x: bool,
    pub log_y: bool,
}

/// A circle to draw over an image, in pixel coordinates; `class` picks the colour.
#[derive(Clone, Copy, Debug)]
pub struct Circle {
    pub x: f64,
    pub y: f64,
    pub r: f64,
    pub class: usize,
}

/// Diverging blue-white-red map (Moreland's cool-warm end points), linear between stops.
const COOL_WARM: [(f64, f64, f64); 5] = [
    (59.0, 76.0, 192.0),
    (144.0, 178.0, 254.0),
    (221.0, 221.0, 221.0),
    (245.0, 156.0, 125.0),
    (180.0, 4.0, 38.0),
];

fn cool_warm(t: f64) -> RGBColor {
    let x = t * (COOL_WARM.len() - 1) as f64;
    let i = (x as usize).min(COOL_WARM.len() - 2);
    let f = x - i as f64;
    let (a, b) = (COOL_WARM[i], COOL_WARM[i + 1]);
    let mix = |p: f64, q: f64| (p + f * (q - p)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

pub(crate) const FONT: &str = "sans-serif";
pub(crate) const MASKED: RGBColor = RGBColor(160, 160, 160);
pub(crate) const SERIES_COLOURS: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];

pub(crate) fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        let bytes: &'static [u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");
        for style in [FontStyle::Normal, FontStyle::Bold] {
            // The font is embedded and known valid; a failure here is a build defect.
            plotters::style::register_font(FONT, style, bytes)
                .unwrap_or_else(|_| panic!("embedded DejaVuSans.ttf is not a valid font"));
        }
    });
}

pub(crate) fn colour(cmap: Colormap, t: f64) -> RGBColor {
    let t = t.clamp(0.0, 1.0) as f32;
    match cmap {
        Colormap::Viridis => ViridisRGB::get_color(t),
        Colormap::Diverging => cool_warm(t as f64),
        Colormap::Gray => BlackWhite::get_color(t),
    }
}

/// Render into an RGB buffer with `draw`, then PNG-encode and write atomically.
pub(crate) fn render_png<F>(path: &Path, size: (u32, u32), background: Option<&[u8]>, draw: F) -> Result<()>
where
    F: FnOnce(&DrawingArea<BitMapBackend, Shift>) -> Result<()>,
{
    register_font();
    let mut buf = match background {
        Some(bg) => bg.to_vec(),
        None => vec![255u8; (size.0 * size.1 * 3) as usize],
    };
    {
        let root = BitMapBackend::with_buffer(&mut buf, size).into_drawing_area();
        draw(&root)?;
        root.present()
            .map_err(|e| anyhow::anyhow!("plot drawing failed: {e}"))?;
    }
    let img = image::RgbImage::from_raw(size.0, size.1, buf).context("plot buffer has the wrong size")?;
    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)?;
    lbdem_core::atomic::write_atomic(path, &png).with_context(|| format!("cannot write {}", path.display()))
}

pub(crate) fn de<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow::anyhow!("plot drawing failed: {e}")
}

/// Finite min and max, or `None` when every value is NaN/inf.
pub fn finite_range(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    let (lo, hi) = values
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(v), hi.max(v))
        });
    (lo <= hi).then_some((lo, hi))
}

/// The colour range a field map uses: given, or finite min/max (symmetric for Diverging),
/// widened when flat so that the colour bar has a span.
fn colour_range(field: &ArrayView2<f64>, opts: &FieldPlot) -> (f64, f64) {
    let (mut lo, mut hi) = opts
        .range
        .or_else(|| finite_range(field.iter().copied()))
        .unwrap_or((0.0, 1.0));
    if opts.cmap == Colormap::Diverging && opts.range.is_none() {
        let m = lo.abs().max(hi.abs());
        (lo, hi) = (-m, m);
    }
    if hi <= lo {
        let pad = if lo == 0.0 { 1e-12 } else { lo.abs() * 1e-6 };
        (lo, hi) = (lo - pad, hi + pad);
    }
    (lo, hi)
}

/// PNG map of a field with a colour bar.
pub fn field_png(path: &Path, field: ArrayView2<f64>, opts: &FieldPlot) -> Result<()> {
    let (ny, nx) = field.dim();
    if nx == 0 || ny == 0 {
        bail!("cannot plot '{}': the field is empty ({nx} x {ny})", opts.title);
    }
    let (lo, hi) = colour_range(&field, opts);
    let (scale, unit) = match opts.pixel_size {
        Some(p) => (p * 1e3, "mm"),
        None => (1.0, "px"),
    };
    let (w_data, h_data) = (nx as f64 * scale, ny as f64 * scale);
    // Plot area about 640 px on its long side; the figure adds margins and the colour bar.
    let long = 640.0;
    let (pw, ph) = if nx >= ny {
        (long, (long * ny as f64 / nx as f64).max(120.0))
    } else {
        ((long * nx as f64 / ny as f64).max(120.0), long)
    };
    let size = ((pw + 230.0) as u32, (ph + 110.0) as u32);
    render_png(path, size, None, |root| {
        root.fill(&WHITE).map_err(de)?;
        let (left, right) = root.split_horizontally(size.0 - 140);
        let mut chart = ChartBuilder::on(&left)
            .caption(opts.title, (FONT, 20))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(55)
            .build_cartesian_2d(0.0..w_data, 0.0..h_data)
            .map_err(de)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(format!("x ({unit})"))
            .y_desc(format!("y ({unit})"))
            .label_style((FONT, 13))
            .draw()
            .map_err(de)?;
        let area = chart.plotting_area().strip_coord_spec();
        let (aw, ah) = area.dim_in_pixel();
        for py in 0..ah {
            let row = ((py as f64 + 0.5) / ah as f64 * ny as f64) as usize;
            for px in 0..aw {
                let col = ((px as f64 + 0.5) / aw as f64 * nx as f64) as usize;
                let v = field[[row.min(ny - 1), col.min(nx - 1)]];
                let c = if v.is_finite() {
                    colour(opts.cmap, (v - lo) / (hi - lo))
                } else {
                    MASKED
                };
                area.draw_pixel((px as i32, py as i32), &c).map_err(de)?;
            }
        }
        colour_bar(&right, opts, lo, hi)
    })
}

fn colour_bar(area: &DrawingArea<BitMapBackend, Shift>, opts: &FieldPlot, lo: f64, hi: f64) -> Result<()> {
    let mut bar = ChartBuilder::on(area)
        .margin_top(40)
        .margin_bottom(50)
        .margin_right(10)
        .y_label_area_size(75)
        .build_cartesian_2d(0.0..1.0, lo..hi)
        .map_err(de)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc(opts.label)
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
            colour(opts.cmap, (i as f64 + 0.5) / n as f64).filled(),
        )
    }))
    .map_err(de)?;
    Ok(())
}

fn padded(lo: f64, hi: f64, log: bool) -> (f64, f64) {
    if log {
        return (lo / 1.3, hi * 1.3);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        lo.abs().max(1.0) * 0.05
    };
    (lo - pad, hi + pad)
}

/// A tick label with at most three significant digits: plain between 1e-3 and 1e4, else
/// "2.5e-5" (plotters' default prints the float's full expansion, e.g. 0.00999999998).
pub fn tick_label(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() {
        return format!("{v}");
    }
    let s = if (1e-3..1e4).contains(&a) {
        let digits = (2 - a.log10().floor() as i32).max(0) as usize;
        format!("{v:.digits$}")
    } else {
        format!("{v:.2e}")
    };
    // Trailing zeros of the mantissa only ("2.50e-5" -> "2.5e-5", "1.00" -> "1").
    let (mant, exp) = s
        .split_once('e')
        .map_or((s.as_str(), None), |(m, e)| (m, Some(e)));
    let mant = if mant.contains('.') {
        mant.trim_end_matches('0').trim_end_matches('.')
    } else {
        mant
    };
    exp.map_or_else(|| mant.to_string(), |e| format!("{mant}e{e}"))
}

/// A tick label on a log axis: only 1, 2 and 5 times a power of ten are labelled (plotters
/// puts a key point at every mantissa, whose labels overprint each other near a decade), each
/// as [`tick_label`].
pub fn log_tick_label(v: f64) -> String {
    if !(v > 0.0 && v.is_finite()) {
        return String::new();
    }
    let m = v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0, 10.0].iter().any(|k| (m / k - 1.0).abs() < 1e-6) {
        tick_label(v)
    } else {
        String::new()
    }
}

/// PNG x-y plot of one or more series (lines, or markers where `points`).
pub fn xy_png(path: &Path, series: &[Series], opts: &XyPlot) -> Result<()> {
    for s in series {
        if s.x.len() != s.y.len() {
            bail!(
                "series '{}' has {} x values and {} y values",
                s.label,
                s.x.len(),
                s.y.len()
            );
        }
    }
    let keep = |v: f64, log: bool| v.is_finite() && (!log || v > 0.0);
    let xs = series
        .iter()
        .flat_map(|s| s.x.iter().copied())
        .filter(|&v| keep(v, opts.log_x));
    let ys = series
        .iter()
        .flat_map(|s| s.y.iter().copied())
        .filter(|&v| keep(v, opts.log_y));
    let (Some((x0, x1)), Some((y0, y1))) = (finite_range(xs), finite_range(ys)) else {
        bail!("cannot plot '{}': no finite data points", opts.title);
    };
    let (x0, x1) = padded(x0, x1, opts.log_x);
    let (y0, y1) = padded(y0, y1, opts.log_y);
    let labels = series.iter().map(|s| s.label);
    let corner = super::legend::quietest_corner(
        &super::legend::Frame::new((x0, x1), (y0, y1), (opts.log_x, opts.log_y), labels),
        series
            .iter()
            .flat_map(|s| s.x.iter().copied().zip(s.y.iter().copied())),
        &[],
    );
    render_png(path, (800, 560), None, |root| {
        root.fill(&WHITE).map_err(de)?;
        let mut b = ChartBuilder::on(root);
        b.caption(opts.title, (FONT, 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70);
        macro_rules! draw {
            ($chart:expr) => {{
                let mut chart = $chart.map_err(de)?;
                chart
                    .configure_mesh()
                    .x_desc(opts.x_label)
                    .y_desc(opts.y_label)
                    .x_label_formatter(&|v| tick_label(*v))
                    .y_label_formatter(&|v| tick_label(*v))
                    .label_style((FONT, 13))
                    .light_line_style(RGBColor(235, 235, 235))
                    .draw()
                    .map_err(de)?;
                for (i, s) in series.iter().enumerate() {
                    let c = SERIES_COLOURS[i % SERIES_COLOURS.len()];
                    let pts: Vec<(f64, f64)> =
                        s.x.iter()
                            .zip(s.y)
                            .map(|(&x, &y)| (x, y))
                            .filter(|&(x, y)| keep(x, opts.log_x) && keep(y, opts.log_y))
                            .collect();
                    let anno = if s.points {
                        chart.draw_series(
                            pts.iter()
                                .map(|&p| plotters::element::Circle::new(p, 3, c.filled())),
                        )
                    } else {
                        chart.draw_series(LineSeries::new(pts, c.stroke_width(2)))
                    }
                    .map_err(de)?;
                    if !s.label.is_empty() {
                        anno.label(s.label).legend(move |(x, y)| {
                            PathElement::new(vec![(x, y), (x + 18, y)], c.stroke_width(2))
                        });
                    }
                }
                if series.iter().any(|s| !s.label.is_empty()) {
                    chart
                        .configure_series_labels()
                        .position(corner.clone())
                        .background_style(WHITE.mix(0.85))
                        .border_style(BLACK)
                        .label_font((FONT, 13))
                        .draw()
                        .map_err(de)?;
                }
            }};
        }
        match (opts.log_x, opts.log_y) {
            (false, false) => draw!(b.build_cartesian_2d(x0..x1, y0..y1)),
            (true, false) => draw!(b.build_cartesian_2d((x0..x1).log_scale(), y0..y1)),
            (false, true) => draw!(b.build_cartesian_2d(x0..x1, (y0..y1).log_scale())),
            (true, true) => draw!(b.build_cartesian_2d((x0..x1).log_scale(), (y0..y1).log_scale())),
        }
        Ok(())
    })
}

/// Counts of `values` in `bins` equal bins over their finite range: (edges, counts).
pub fn histogram(values: &[f64], bins: usize) -> Option<(Vec<f64>, Vec<usize>)> {
    let (lo, hi) = finite_range(values.iter().copied())?;
    let bins = bins.max(1);
    let width = if hi > lo { (hi - lo) / bins as f64 } else { 1.0 };
    let mut counts = vec![0usize; bins];
    for &v in values.iter().filter(|v| v.is_finite()) {
        counts[(((v - lo) / width) as usize).min(bins - 1)] += 1;
    }
    Some(((0..=bins).map(|i| lo + width * i as f64).collect(), counts))
}

/// PNG histogram.
pub fn histogram_png(path: &Path, values: &[f64], bins: usize, title: &str, x_label: &str) -> Result<()> {
    let Some((edges, counts)) = histogram(values, bins) else {
        bail!("cannot plot histogram '{title}': no finite values");
    };
    let top = *counts.iter().max().unwrap_or(&1) as f64 * 1.08;
    render_png(path, (800, 520), None, |root| {
        root.fill(&WHITE).map_err(de)?;
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FONT, 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(60)
            .build_cartesian_2d(edges[0]..edges[edges.len() - 1], 0.0..top.max(1.0))
            .map_err(de)?;
        chart
            .configure_mesh()
            .x_desc(x_label)
            .y_desc("count")
            .label_style((FONT, 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(de)?;
        chart
            .draw_series(counts.iter().enumerate().map(|(i, &c)| {
                Rectangle::new(
                    [(edges[i], 0.0), (edges[i + 1], c as f64)],
                    SERIES_COLOURS[0].mix(0.8).filled(),
                )
            }))
            .map_err(de)?;
        Ok(())
    })
}

/// PNG of a grey image (scaled to its finite min/max) with circles drawn over it, at the
/// image's own pixel size so a person can check a fit by eye.
pub fn circles_overlay_png(path: &Path, image: ArrayView2<f64>, circles: &[Circle]) -> Result<()> {
    let (ny, nx) = image.dim();
    if nx == 0 || ny == 0 {
        bail!("cannot draw an overlay on an empty image");
    }
    let (lo, hi) = finite_range(image.iter().copied()).unwrap_or((0.0, 1.0));
    let span = if hi > lo { hi - lo } else { 1.0 };
    let mut bg = Vec::with_capacity(nx * ny * 3);
    for v in image.iter() {
        let g = if v.is_finite() {
            (255.0 * (v - lo) / span).round() as u8
        } else {
            0
        };
        bg.extend([g, g, g]);
    }
    render_png(path, (nx as u32, ny as u32), Some(&bg), |root| {
        for c in circles {
            let colour = SERIES_COLOURS[(c.class + 1) % SERIES_COLOURS.len()];
            root.draw(&plotters::element::Circle::new(
                (c.x.round() as i32, c.y.round() as i32),
                c.r.round().max(1.0) as i32,
                colour.stroke_width(2),
            ))
            .map_err(de)?;
        }
        Ok(())
    })
}

/// Plot `field` as `dir/file`, and record it as a figure (with `caption`) and an output
/// file: the bookkeeping every map a stage makes needs.
pub fn field_figure(
    dir: &Path,
    file: String,
    field: ArrayView2<f64>,
    opts: &FieldPlot,
    caption: String,
    figures: &mut Vec<crate::contract::Figure>,
    files: &mut Vec<std::path::PathBuf>,
) -> Result<()> {
    field_png(&dir.join(&file), field, opts)?;
    figures.push(crate::contract::Figure {
        path: std::path::PathBuf::from(&file),
        caption,
    });
    files.push(file.into());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use ndarray::Array2;

    fn png_size(p: &Path) -> (u32, u32) {
        let img = image::open(p).unwrap();
        (img.width(), img.height())
    }

    #[test]
    fn tick_labels_have_at_most_three_significant_digits() {
        assert_eq!(tick_label(0.00999999998), "0.01");
        assert_eq!(tick_label(0.002), "0.002");
        assert_eq!(tick_label(1.0), "1");
        assert_eq!(tick_label(250.0), "250");
        assert_eq!(tick_label(-0.125), "-0.125");
        assert_eq!(tick_label(2.5e-5), "2.5e-5");
        assert_eq!(tick_label(1e-14), "1e-14");
        assert_eq!(tick_label(0.0), "0");
        // Log axes: 1, 2, 5 per decade, the rest blank.
        assert_eq!(log_tick_label(2e5), "2e5");
        assert_eq!(log_tick_label(1000000.0), "1e6");
        assert_eq!(log_tick_label(5.0), "5");
        assert_eq!(log_tick_label(0.999999999 * 1e3), "1000");
        assert_eq!(log_tick_label(3e5), "");
        assert_eq!(log_tick_label(900000.0), "");
        assert_eq!(log_tick_label(0.0), "");
    }

    #[test]
    fn field_map_is_written_and_masks_nan() {
        let dir = tempfile::tempdir().unwrap();
        let mut f = Array2::from_shape_fn((50, 80), |(r, c)| (r as f64 - c as f64) / 50.0);
        f[[0, 0]] = f64::NAN;
        let p = dir.path().join("f.png");
        let opts = FieldPlot {
            title: "test",
            label: "eps (-)",
            cmap: Colormap::Diverging,
            range: None,
            pixel_size: Some(1e-5),
        };
        field_png(&p, f.view(), &opts).unwrap();
        let (w, h) = png_size(&p);
        assert!(w > 640 && h > 300, "unexpected figure size {w}x{h}");
        // An all-NaN field still draws (all masked) instead of failing.
        field_png(&p, Array2::from_elem((4, 4), f64::NAN).view(), &opts).unwrap();
    }

    #[test]
    fn diverging_range_is_symmetric() {
        let f = Array2::from_shape_vec((1, 2), vec![-0.01, 0.03]).unwrap();
        let opts = FieldPlot {
            title: "",
            label: "",
            cmap: Colormap::Diverging,
            range: None,
            pixel_size: None,
        };
        assert_eq!(colour_range(&f.view(), &opts), (-0.03, 0.03));
        let opts = FieldPlot {
            cmap: Colormap::Viridis,
            ..opts
        };
        assert_eq!(colour_range(&f.view(), &opts), (-0.01, 0.03));
    }

    #[test]
    fn xy_rejects_mismatched_series_and_draws_log_axes() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("xy.png");
        let bad = [Series {
            label: "a",
            x: &[1.0, 2.0],
            y: &[1.0],
            points: false,
        }];
        assert!(xy_png(&p, &bad, &XyPlot::default()).is_err());
        let x = [1.0, 10.0, 100.0];
        let y = [1.0, 0.1, 0.01];
        let s = [Series {
            label: "decay",
            x: &x,
            y: &y,
            points: true,
        }];
        xy_png(
            &p,
            &s,
            &XyPlot {
                title: "t",
                x_label: "x",
                y_label: "y",
                log_x: true,
                log_y: true,
            },
        )
        .unwrap();
        assert_eq!(png_size(&p), (800, 560));
    }

    #[test]
    fn histogram_counts_every_finite_value() {
        let v = [0.0, 0.1, 0.5, 0.9, 1.0, f64::NAN];
        let (edges, counts) = histogram(&v, 2).unwrap();
        assert_eq!(edges, vec![0.0, 0.5, 1.0]);
        assert_eq!(counts, vec![2, 3]);
        assert!(histogram(&[f64::NAN], 3).is_none());
    }

    #[test]
    fn overlay_keeps_image_size() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("o.png");
        let img = Array2::from_shape_fn((60, 90), |(r, c)| ((r * c) % 7) as f64);
        circles_overlay_png(
            &p,
            img.view(),
            &[Circle {
                x: 30.0,
                y: 20.0,
                r: 8.0,
                class: 0,
            }],
        )
        .unwrap();
        assert_eq!(png_size(&p), (90, 60));
    }
}

/// A grain circle in metres, for [`grains_png`]; `class` 0 draws grey, 1 red (membrane).
#[derive(Clone, Copy, Debug)]
pub struct Disc {
    pub x: f64,
    pub y: f64,
    pub r: f64,
    pub class: usize,
}

/// PNG of a grain assembly: filled circles on axes in mm (Su et al. 2020 Fig. 1b: grains grey,
/// the membrane red), the box [lo, hi] drawn, aspect kept.
pub fn grains_png(path: &Path, discs: &[Disc], lo: (f64, f64), hi: (f64, f64), title: &str) -> Result<()> {
    let (w, h) = ((hi.0 - lo.0) * 1e3, (hi.1 - lo.1) * 1e3);
    if !(w > 0.0 && h > 0.0 && w.is_finite() && h.is_finite()) {
        bail!("cannot draw grains in an empty box {lo:?}..{hi:?}");
    }
    let px_h = 900u32;
    let px_w = ((px_h as f64 - 80.0) * w / h + 100.0)
        .round()
        .clamp(300.0, 2400.0) as u32;
    render_png(path, (px_w, px_h), None, |root| {
        root.fill(&WHITE).map_err(de)?;
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FONT, 18))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(50)
            .build_cartesian_2d(lo.0 * 1e3..hi.0 * 1e3, lo.1 * 1e3..hi.1 * 1e3)
            .map_err(de)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("x (mm)")
            .y_desc("y (mm)")
            .label_style((FONT, 13))
            .draw()
            .map_err(de)?;
        let plot_w = chart.plotting_area().dim_in_pixel().0 as f64;
        let px_per_mm = plot_w / w;
        let grey = RGBColor(150, 150, 150);
        let red = RGBColor(214, 39, 40);
        chart
            .draw_series(discs.iter().map(|d| {
                let c = if d.class == 1 { red } else { grey };
                plotters::element::Circle::new(
                    (d.x * 1e3, d.y * 1e3),
                    (d.r * 1e3 * px_per_mm).round().max(1.0) as i32,
                    c.filled(),
                )
            }))
            .map_err(de)?;
        Ok(())
    })
}

/// One series of [`xy_err_png`]: markers joined by a line, with a vertical error bar of
/// half-width `err[i]` at each point (none where it is not finite).
#[derive(Clone, Debug)]
pub struct ErrSeries<'a> {
    pub label: &'a str,
    pub x: &'a [f64],
    pub y: &'a [f64],
    pub err: &'a [f64],
}

/// PNG x-y plot (linear axes) of series with error bars: a sweep's result against an axis, one
/// series per value of the other axes, bars the replicas' confidence interval.
pub fn xy_err_png(path: &Path, series: &[ErrSeries], opts: &XyPlot) -> Result<()> {
    for s in series {
        if s.x.len() != s.y.len() || s.err.len() != s.y.len() {
            bail!(
                "series '{}' has {} x, {} y and {} error values",
                s.label,
                s.x.len(),
                s.y.len(),
                s.err.len()
            );
        }
    }
    let bar = |e: f64| if e.is_finite() { e.abs() } else { 0.0 };
    let pts = |s: &ErrSeries| -> Vec<(f64, f64, f64)> {
        s.x.iter()
            .zip(s.y)
            .zip(s.err)
            .filter(|((x, y), _)| x.is_finite() && y.is_finite())
            .map(|((&x, &y), &e)| (x, y, bar(e)))
            .collect()
    };
    let all: Vec<(f64, f64, f64)> = series.iter().flat_map(pts).collect();
    let xs = all.iter().map(|p| p.0);
    let ys = all.iter().flat_map(|p| [p.1 - p.2, p.1 + p.2]);
    let (Some((x0, x1)), Some((y0, y1))) = (finite_range(xs), finite_range(ys)) else {
        bail!("cannot plot '{}': no finite data points", opts.title);
    };
    let (x0, x1) = padded(x0, x1, false);
    let (y0, y1) = padded(y0, y1, false);
    render_png(path, (800, 560), None, |root| {
        root.fill(&WHITE).map_err(de)?;
        let mut chart = ChartBuilder::on(root)
            .caption(opts.title, (FONT, 20))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(de)?;
        chart
            .configure_mesh()
            .x_desc(opts.x_label)
            .y_desc(opts.y_label)
            .label_style((FONT, 13))
            .light_line_style(RGBColor(235, 235, 235))
            .draw()
            .map_err(de)?;
        for (i, s) in series.iter().enumerate() {
            let c = SERIES_COLOURS[i % SERIES_COLOURS.len()];
            let p = pts(s);
            chart
                .draw_series(LineSeries::new(p.iter().map(|q| (q.0, q.1)), c.stroke_width(1)))
                .map_err(de)?;
            chart
                .draw_series(
                    p.iter().filter(|q| q.2 > 0.0).map(|q| {
                        ErrorBar::new_vertical(q.0, q.1 - q.2, q.1, q.1 + q.2, c.stroke_width(2), 8)
                    }),
                )
                .map_err(de)?;
            let anno = chart
                .draw_series(
                    p.iter()
                        .map(|q| plotters::element::Circle::new((q.0, q.1), 4, c.filled())),
                )
                .map_err(de)?;
            if !s.label.is_empty() {
                anno.label(s.label)
                    .legend(move |(x, y)| plotters::element::Circle::new((x + 9, y), 4, c.filled()));
            }
        }
        if series.iter().any(|s| !s.label.is_empty()) {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font((FONT, 13))
                .draw()
                .map_err(de)?;
        }
        Ok(())
    })
}
