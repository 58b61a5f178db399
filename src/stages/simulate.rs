//! Stage `simulate`: run a scene file (`lbdem simulate SCENE.toml`, or `kind = "simulate"` in a
//! pipeline with `scene = "scenes/x.toml"`). The scene writes its series, snapshots and
//! checkpoints; this stage draws the figures from those files. Resumable: an interrupted run
//! continues from its last checkpoint with `--resume` (and automatically in a pipeline).

use crate::contract::{Figure, Stage, StageContext, StageOutput};
use crate::report::plot::{Colormap, FieldPlot, Series, XyPlot, field_figure, xy_png};
use crate::report::table::{f64_column, read_table};
use crate::scenes::schema::Physics;
use crate::scenes::snapshot::read_fluid;
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `scene = "scenes/x.toml"`, with optional overrides of its keys
/// (`overrides = { run = { steps = 100 } }`, or `--set run.steps=100` on the command line).
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    pub scene: PathBuf,
    #[serde(default)]
    pub overrides: toml::Table,
}

pub struct Simulate;

impl Stage for Simulate {
    const KIND: &'static str = "simulate";
    const ABOUT: &'static str = "Run a scene (grains, liquid or both) from its TOML file of sections";
    const RESUMABLE: bool = true;
    type Params = Params;

    fn inputs(p: &Params, ctx: &StageContext) -> Vec<PathBuf> {
        let scene = ctx.resolve(&p.scene);
        let mut v = vec![scene.clone()];
        // The files the scene reads (particle CSV, mask image) are inputs too.
        if let Ok(l) = crate::scenes::schema::load(&scene, &p.overrides) {
            // ...and the files it extends.
            v.extend(l.sources.iter().skip(1).cloned());
            v.extend(l.minimal_table.clone());
            let pc = l.scene.particles.as_ref();
            if let Some(csv) = pc.and_then(|pc| pc.continue_from.as_ref().or(pc.csv.as_ref())) {
                let p = l.base_dir.join(csv);
                // A snapshot directory stands for its newest particle file.
                match p.is_dir() {
                    true => v.extend(crate::scenes::build::particles_csv::newest_snapshot(&p).ok()),
                    false => v.push(p),
                }
            }
            if let Some(a) = pc
                .and_then(|pc| pc.assembly.as_ref())
                .filter(|_| pc.is_some_and(|p| p.continue_from.is_none()))
            {
                // A missing assembly is refused when the scene is built, with how to make it.
                let p = l.base_dir.join(&a.file);
                let h = crate::scenes::build::assembly_file::header_path(&p);
                v.extend([p, h].into_iter().filter(|f| f.exists()));
            }
            if let Some(m) = &l.scene.mask {
                v.push(l.base_dir.join(&m.image));
            }
        }
        v
    }

    fn run(p: &Params, ctx: &StageContext) -> Result<StageOutput> {
        let l = crate::scenes::schema::load(&ctx.resolve(&p.scene), &p.overrides)?;
        let r = crate::scenes::run::run(&l, &ctx.out_dir, &ctx.key, ctx.resume)?;
        let mut files = r.files;
        let mut figures = Vec::new();
        if r.physics == Physics::Coupled {
            coupled_figures(&ctx.out_dir, &r.summary, &mut figures, &mut files)?;
        }
        Ok(StageOutput {
            summary: r.summary,
            figures,
            tables: r.tables,
            files,
        })
    }
}

/// The liquid pressure change Δp (Su Eq. 19) at the end of the run, and its minimum over time.
fn coupled_figures(
    dir: &Path,
    summary: &serde_json::Value,
    figures: &mut Vec<Figure>,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    let step = summary["steps"].as_u64().unwrap_or(0);
    let table = dir.join(format!("snapshots/fluid_{step:09}.csv"));
    let fl = read_fluid(&table).context("the last fluid snapshot")?;
    let nx = fl.i.iter().max().map_or(0, |m| *m as usize + 1);
    let ny = fl.j.iter().max().map_or(0, |m| *m as usize + 1);
    let dx = summary["engine"]["dx"].as_f64();
    let field = ndarray::Array2::from_shape_fn((ny, nx), |(row, col)| fl.pressure[col + nx * (ny - 1 - row)]);
    field_figure(
        dir,
        "pressure_change.png".into(),
        field.view(),
        &FieldPlot {
            title: "liquid pressure change (Su Eq. 19)",
            label: "Δp (Pa)",
            cmap: Colormap::Diverging,
            range: None,
            pixel_size: dx,
        },
        format!(
            "Liquid pressure change Δp = (ρ − ρ₀)c_s² at the end of the run (t = {:.4e} s).",
            summary["time"].as_f64().unwrap_or(0.0)
        ),
        figures,
        files,
    )?;
    let series = dir.join(crate::scenes::observers::SERIES_FILE);
    let df = read_table(&series)?;
    let t = f64_column(&df, "time", &series)?;
    let dpmin = f64_column(&df, "dp_min", &series)?;
    xy_png(
        &dir.join("pressure_min.png"),
        &[Series {
            label: "min Δp",
            x: &t,
            y: &dpmin,
            points: false,
        }],
        &XyPlot {
            title: "minimum liquid pressure change",
            x_label: "t (s)",
            y_label: "Δp (Pa)",
            log_x: false,
            log_y: false,
        },
    )?;
    figures.push(Figure {
        path: "pressure_min.png".into(),
        caption: "Minimum of the liquid pressure change over the run.".into(),
    });
    files.push("pressure_min.png".into());
    Ok(())
}
