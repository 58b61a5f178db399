//! Stage `digitise`: the first image of an experiment becomes the grain assembly a
//! simulation starts from, as Su et al. (2020, Sect. 2.4) do: grains are segmented and
//! measured, each fitted by two overlapping circles (Fig. 1c-d), the size and shape
//! distribution defines N grain templates (20 in their work), and the assembly is
//! written as a particle file for the DEM scenes. The kernels are in `lbdem-grains`.
//!
//! Reads a float TIFF solid-fraction map (values 0..1) or any grey/colour image. Writes
//! `particles.csv` + `particles.json` (the assembly), `grains.csv` (per grain),
//! `templates.csv`, `size_distribution.csv`, `shape_distribution.csv`, histograms and an
//! overlay of the fitted circles on the image. User guide: docs/digitise.md.

mod export;
pub mod load;

use crate::contract::{Figure, Stage, StageContext, StageOutput, Table};
use crate::report::{plot, table};
use anyhow::{Context, Result, bail};
use export::{Header, Particle, write_header, write_particles};
use lbdem_grains::segment::Polarity;
use lbdem_grains::watershed::WatershedParams;
use lbdem_grains::{Container, Digitised};
pub use load::Channel;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

fn d_smooth() -> f64 {
    lbdem_grains::Params::default().smooth_px
}
fn d_h_rel() -> f64 {
    WatershedParams::default().h_rel
}
fn d_h_abs() -> f64 {
    WatershedParams::default().h_abs
}
fn d_round() -> f64 {
    lbdem_grains::Params::default().round_aspect
}
fn d_templates() -> usize {
    lbdem_grains::Params::default().n_templates
}
fn d_bins() -> usize {
    20
}

/// What the assembly is made of.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Assembly {
    /// Every grain with its own two-circle fit, where it lies in the image.
    #[default]
    Grains,
    /// Every grain replaced by its template (Su et al.'s N templates), placed at the
    /// grain's centroid and orientation.
    Templates,
}

#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// The image (relative to the pipeline file, or to `from_stage`'s output directory).
    pub image: PathBuf,
    /// Take `image` from the output directory of this earlier pipeline stage.
    #[serde(default)]
    pub from_stage: Option<String>,
    /// Size of one pixel, metres.
    pub pixel_size_m: f64,
    #[serde(default)]
    pub channel: Channel,
    #[serde(default)]
    pub grains_are: Polarity,
    /// Grey level between liquid and grains (in the image's units; 0..1 for a solid
    /// fraction map); omitted: Otsu's.
    #[serde(default)]
    pub threshold: Option<f64>,
    #[serde(default = "d_smooth")]
    pub smooth_px: f64,
    #[serde(default)]
    pub container: Container,
    /// Smaller solid pieces are specks; omitted: 5 % of the median grain area of a first pass
    /// (`lbdem_grains::segment::sizes_from_first_pass`).
    #[serde(default)]
    pub min_grain_area_px: Option<usize>,
    /// Enclosed liquid holes up to this area are filled; omitted: as `min_grain_area_px`.
    #[serde(default)]
    pub max_hole_area_px: Option<usize>,
    #[serde(default = "d_h_rel")]
    pub h_rel: f64,
    #[serde(default = "d_h_abs")]
    pub h_abs: f64,
    #[serde(default = "d_round")]
    pub round_aspect: f64,
    #[serde(default = "d_templates")]
    pub n_templates: usize,
    #[serde(default)]
    pub assembly: Assembly,
    #[serde(default = "d_bins")]
    pub histogram_bins: usize,
}

impl Params {
    /// The kernel's parameters; omitted sizes at the kernel's fixed defaults (the first pass).
    fn kernel(&self) -> lbdem_grains::Params {
        let fixed = lbdem_grains::Params::default();
        lbdem_grains::Params {
            grains_are: self.grains_are,
            threshold: self.threshold,
            smooth_px: self.smooth_px,
            container: self.container.clone(),
            min_grain_area_px: self.min_grain_area_px.unwrap_or(fixed.min_grain_area_px),
            max_hole_area_px: self.max_hole_area_px.unwrap_or(fixed.max_hole_area_px),
            watershed: WatershedParams {
                h_rel: self.h_rel,
                h_abs: self.h_abs,
            },
            round_aspect: self.round_aspect,
            n_templates: self.n_templates,
        }
    }

    fn image_path(&self, ctx: &StageContext) -> Result<PathBuf> {
        match &self.from_stage {
            None => Ok(ctx.resolve(&self.image)),
            Some(name) => {
                let dir = ctx.earlier_stage(name).with_context(|| {
                    format!("digitise: from_stage = '{name}' is not an earlier stage of this pipeline; name one that runs before it")
                })?;
                Ok(dir.join(&self.image))
            }
        }
    }
}

pub struct Digitise;

impl Stage for Digitise {
    const KIND: &'static str = "digitise";
    const ABOUT: &'static str = "Segment grains in an image and fit two-circle clumps and templates";
    type Params = Params;
    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        p.image_path(ctx).map(|x| vec![x]).unwrap_or_default()
    }
    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        if !(p.pixel_size_m > 0.0 && p.pixel_size_m.is_finite()) {
            bail!(
                "digitise: pixel_size_m = {} must be a positive length in metres (e.g. 2.7e-6 for a 5.5 mm field on 2048 px)",
                p.pixel_size_m
            );
        }
        if p.histogram_bins == 0 {
            bail!("digitise: histogram_bins = 0; give at least 1 (default 20)");
        }
        let path = p.image_path(ctx)?;
        let loaded = load::load(&path, p.channel)?;
        let mut kernel = p.kernel();
        // Speck and hole sizes follow from the image unless given.
        let first_pass = match (p.min_grain_area_px, p.max_hole_area_px) {
            (Some(_), Some(_)) => None,
            (min, hole) => {
                let s = lbdem_grains::segment::sizes_from_first_pass(loaded.grey.view(), &kernel)
                    .with_context(|| {
                        format!(
                            "digitise of {} (first pass, to size specks and holes)",
                            path.display()
                        )
                    })?;
                kernel.min_grain_area_px = min.unwrap_or(s.min_grain_area_px);
                kernel.max_hole_area_px = hole.unwrap_or(s.max_hole_area_px);
                Some(s)
            }
        };
        let d = lbdem_grains::digitise(loaded.grey.view(), &kernel)
            .with_context(|| format!("digitise of {}", path.display()))?;
        for w in &d.warnings {
            eprintln!("digitise: warning: {} ({})", w, path.display());
        }
        write_outputs(p, ctx, &path, &loaded, &d, &kernel, first_pass)
    }
}

fn write_outputs(
    p: &Params,
    ctx: &StageContext,
    src: &Path,
    loaded: &load::Loaded,
    d: &Digitised,
    kernel: &lbdem_grains::Params,
    first_pass: Option<lbdem_grains::segment::FirstPassSizes>,
) -> Result<StageOutput> {
    let out = &ctx.out_dir;
    let px = p.pixel_size_m;
    let (h, w) = loaded.grey.dim();
    let to_si = |x: f64, y: f64| [x * px, (h as f64 - y) * px];
    let mut o = StageOutput::default();

    // The assembly.
    let mut particles = Vec::new();
    for (i, (g, f)) in d.grains.iter().zip(&d.fits).enumerate() {
        let circles: Vec<lbdem_grains::FitCircle> = match (p.assembly, d.template_of[i]) {
            (Assembly::Templates, Some(k)) => {
                let (c, s) = (g.orientation.cos(), -g.orientation.sin());
                d.templates[k]
                    .circles
                    .iter()
                    .map(|t| lbdem_grains::FitCircle {
                        x: g.x + t.x * c,
                        y: g.y + t.x * s,
                        r: t.r,
                    })
                    .collect()
            }
            _ => f.circles.clone(),
        };
        for c in circles {
            let [x, y] = to_si(c.x, c.y);
            particles.push(Particle {
                grain_id: i + 1,
                x,
                y,
                r: c.r * px,
            });
        }
    }
    write_particles(&out.join("particles.csv"), &particles)?;
    let d_bar_m = d.size.d_mean_px * px;
    let assembly = match p.assembly {
        Assembly::Grains => "grains",
        Assembly::Templates => "templates",
    };
    write_header(
        &out.join("particles.json"),
        &Header {
            format: "lbdem-particles",
            version: 1,
            file: "particles.csv",
            columns: ["grain_id", "x", "y", "r"],
            units: "m",
            axes: "x to the right, y up, origin at the bottom-left corner of the image",
            pixel_size_m: px,
            image_width_px: w,
            image_height_px: h,
            width_m: w as f64 * px,
            height_m: h as f64 * px,
            source: src.display().to_string(),
            container_m: d.mask.outline.iter().map(|v| to_si(v[0], v[1])).collect(),
            assembly,
            n_grains: d.grains.len(),
            n_circles: particles.len(),
            d_bar_m,
            solid_fraction_fitted: d.solid_fraction_fitted,
        },
    )?;
    o.files
        .extend(["particles.csv", "particles.json"].map(PathBuf::from));

    // Per grain.
    let col = |f: &dyn Fn(usize) -> f64| (0..d.grains.len()).map(f).collect::<Vec<f64>>();
    let gid = col(&|i| (i + 1) as f64);
    let xs = col(&|i| to_si(d.grains[i].x, d.grains[i].y)[0]);
    let ys = col(&|i| to_si(d.grains[i].x, d.grains[i].y)[1]);
    let area = col(&|i| d.grains[i].area_px * px * px);
    let deq = col(&|i| d.grains[i].d_eq_px * px);
    let ori = col(&|i| d.grains[i].orientation);
    let asp = col(&|i| d.grains[i].aspect);
    let edge = col(&|i| f64::from(u8::from(d.grains[i].at_edge)));
    let ncirc = col(&|i| d.fits[i].circles.len() as f64);
    let fit_t = col(&|i| d.fits[i].t);
    let fit_err = col(&|i| d.fits[i].error);
    let tmpl = col(&|i| d.template_of[i].map_or(0.0, |k| (k + 1) as f64));
    table::write_csv(
        &out.join("grains.csv"),
        &[
            ("grain_id", &gid),
            ("x_m", &xs),
            ("y_m", &ys),
            ("area_m2", &area),
            ("d_eq_m", &deq),
            ("orientation_rad", &ori),
            ("aspect_ratio", &asp),
            ("at_edge", &edge),
            ("n_circles", &ncirc),
            ("fit_t", &fit_t),
            ("fit_error", &fit_err),
            ("template_id", &tmpl),
        ],
    )?;
    o.tables.push(Table {
        path: "grains.csv".into(),
        caption: "Per grain: centroid (m, y up), area, equivalent diameter, orientation of the major axis \
                  (rad, counter-clockwise from +x), aspect ratio, cut by the container edge (1), circles \
                  fitted, t = s/r of the pair, fit error (mismatched area over grain area), template."
            .into(),
    });

    // Templates.
    let tc = |f: &dyn Fn(&lbdem_grains::templates::Template) -> f64| {
        d.templates.iter().map(f).collect::<Vec<f64>>()
    };
    table::write_csv(
        &out.join("templates.csv"),
        &[
            ("template_id", &tc(&|t| t.id as f64)),
            ("weight", &tc(&|t| t.weight)),
            ("count", &tc(&|t| t.count as f64)),
            ("d_eq_m", &tc(&|t| t.d_eq_px * px)),
            ("aspect_ratio", &tc(&|t| t.aspect)),
            ("r_m", &tc(&|t| t.circles[0].r * px)),
            ("offset_m", &tc(&|t| t.circles.last().map_or(0.0, |c| c.x) * px)),
            ("n_circles", &tc(&|t| t.circles.len() as f64)),
        ],
    )?;
    o.tables.push(Table {
        path: "templates.csv".into(),
        caption: format!(
            "{} grain templates from the measured size and shape distribution (Su et al. 2020, Sect. 2.4): \
             equal-count groups by size; each is two circles of radius r_m at +-offset_m along its major \
             axis (one circle when n_circles = 1); weight = share of grains.",
            d.templates.len()
        ),
    });

    // Distributions (grains not cut by the container edge).
    let interior: Vec<usize> = (0..d.grains.len()).filter(|&i| !d.grains[i].at_edge).collect();
    let sel: Vec<usize> = if interior.is_empty() {
        (0..d.grains.len()).collect()
    } else {
        interior
    };
    let dvals: Vec<f64> = sel.iter().map(|&i| d.grains[i].d_eq_px * px * 1e6).collect();
    let avals: Vec<f64> = sel.iter().map(|&i| d.grains[i].aspect).collect();
    for (name, vals, label, what) in [
        ("size_distribution", &dvals, "d_eq_um", "equivalent diameter (um)"),
        ("shape_distribution", &avals, "aspect_ratio", "aspect ratio (-)"),
    ] {
        let (lo, hi, counts) = histogram(vals, p.histogram_bins);
        let bw = (hi - lo) / counts.len() as f64;
        let centres: Vec<f64> = (0..counts.len()).map(|k| lo + (k as f64 + 0.5) * bw).collect();
        let cnt: Vec<f64> = counts.iter().map(|&c| c as f64).collect();
        let total: f64 = cnt.iter().sum::<f64>().max(1.0);
        let mut acc = 0.0;
        let cum: Vec<f64> = cnt
            .iter()
            .map(|c| {
                acc += c;
                acc / total
            })
            .collect();
        table::write_csv(
            &out.join(format!("{name}.csv")),
            &[
                (format!("{label}_bin_centre").as_str(), &centres),
                ("count", &cnt),
                ("cumulative_fraction", &cum),
            ],
        )?;
        o.tables.push(Table {
            path: format!("{name}.csv").into(),
            caption: format!(
                "Distribution of the grain {what}, {} grains not cut by the container edge.",
                vals.len()
            ),
        });
        plot::histogram_png(
            &out.join(format!("{name}.png")),
            vals,
            p.histogram_bins,
            &format!("Grain {what}"),
            what,
        )?;
        o.figures.push(Figure {
            path: format!("{name}.png").into(),
            caption: format!("Histogram of the grain {what} ({} grains).", vals.len()),
        });
    }

    // Overlay for checking by eye: class 0 one circle, 1 a pair, 2 a grain cut by the container.
    let circles: Vec<plot::Circle> = d
        .grains
        .iter()
        .zip(&d.fits)
        .flat_map(|(g, f)| {
            let class = if g.at_edge { 2 } else { f.circles.len() - 1 };
            f.circles.iter().map(move |c| plot::Circle {
                x: c.x,
                y: c.y,
                r: c.r,
                class,
            })
        })
        .collect();
    plot::circles_overlay_png(&out.join("overlay.png"), loaded.grey.view(), &circles)?;
    o.figures.push(Figure {
        path: "overlay.png".into(),
        caption: format!(
            "Fitted circles over {}: {} grains, {} circles (one colour per class: single circle, pair, \
             grain cut by the container). Container: {}.",
            src.file_name()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            d.grains.len(),
            circles.len(),
            d.mask.description
        ),
    });
    o.files.extend(
        [
            "grains.csv",
            "templates.csv",
            "size_distribution.csv",
            "shape_distribution.csv",
            "size_distribution.png",
            "shape_distribution.png",
            "overlay.png",
        ]
        .map(PathBuf::from),
    );

    let errs: Vec<f64> = d.fits.iter().map(|f| f.error).collect();
    o.summary = serde_json::json!({
        "source": src.display().to_string(),
        "image_kind": loaded.kind,
        "image_width_px": w,
        "image_height_px": h,
        "pixel_size_m": px,
        "axes": "particles.csv: x right, y up from the bottom-left corner of the image; grains.csv likewise",
        "container": d.mask.description,
        "threshold": d.threshold,
        "min_grain_area_px": kernel.min_grain_area_px,
        "max_hole_area_px": kernel.max_hole_area_px,
        "sizes_first_pass": first_pass,
        "n_grains": d.grains.len(),
        "n_grains_cut_by_container": d.grains.iter().filter(|g| g.at_edge).count(),
        "n_circles": particles.len(),
        "n_pairs": d.fits.iter().filter(|f| f.circles.len() == 2).count(),
        "d_bar_m": d_bar_m,
        "d_min_m": d.size.d_min_px * px,
        "d_max_m": d.size.d_max_px * px,
        "d_std_m": d.size.d_std_px * px,
        "aspect_mean": d.size.aspect_mean,
        "push_plate_displacement_10dbar_m": 10.0 * d_bar_m,
        "solid_fraction_image": d.solid_fraction_image,
        "solid_fraction_fitted": d.solid_fraction_fitted,
        "fit_error_mean": errs.iter().sum::<f64>() / errs.len().max(1) as f64,
        "fit_error_max": errs.iter().copied().fold(0.0, f64::max),
        "circles_outside_container": d.circles_outside,
        "max_protrusion_m": d.max_protrusion_px * px,
        "n_templates": d.templates.len(),
        "assembly": assembly,
        "warnings": d.warnings,
    });
    Ok(o)
}

/// Equal-width histogram over [min, max] of the values.
fn histogram(v: &[f64], bins: usize) -> (f64, f64, Vec<usize>) {
    let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
    let mut hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !lo.is_finite() {
        return (0.0, 1.0, vec![0; bins]);
    }
    if hi <= lo {
        hi = lo + 1.0;
    }
    let mut c = vec![0usize; bins];
    for &x in v {
        let k = (((x - lo) / (hi - lo)) * bins as f64) as usize;
        c[k.min(bins - 1)] += 1;
    }
    (lo, hi, c)
}
