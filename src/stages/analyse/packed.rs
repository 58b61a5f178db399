//! The packed zone of a Float run (Su et al. 2020 Sect. 3.2, Fig. 5h) as Su measured it on the
//! radiographs: grains that moved less than 2 µm in 10 s are still, and the zone is the run of
//! still bands from the side the grains pack against. The run's own series uses the grains'
//! instantaneous speed, which a settling layer's vibration keeps above Su's 2e-7 m/s long after
//! its grains stopped moving on the scale of a radiograph; this reads pairs of particle
//! snapshots `window` apart instead.

use super::Params;
use crate::contract::{Figure, Table};
use crate::report::lines::{Line, LinesPlot, Reference, Style, lines_png};
use crate::report::table::{Col, write_table};
use crate::scenes::models::packed_zone::{Band, PackedZone, interior_fraction};
use crate::stages::run_data::Run;
use anyhow::{Result, bail};
use std::path::{Path, PathBuf};

/// The zone by displacement at every particle snapshot that has one `window` earlier:
/// (time of the later snapshot, packing fraction, height, interior packing fraction
/// ([`interior_fraction`])), and the bands of the last pair.
pub fn by_displacement(
    run: &Run,
    zone: &PackedZone,
    window: f64,
    moved: f64,
) -> Result<(Vec<[f64; 4]>, Vec<Band>)> {
    let steps = run.particle_steps();
    let times: Vec<f64> = steps.iter().map(|&s| run.time_of(s)).collect();
    let (mut rows, mut bands) = (Vec::new(), Vec::new());
    for (k1, &t1) in times.iter().enumerate() {
        // The earlier snapshot closest to t1 − window, within 1 % of the window.
        let Some(k0) = (0..k1)
            .filter(|&k| ((t1 - times[k]) - window).abs() <= 0.01 * window)
            .min_by(|&a, &b| {
                let da = ((t1 - times[a]) - window).abs();
                let db = ((t1 - times[b]) - window).abs();
                da.total_cmp(&db)
            })
        else {
            continue;
        };
        let (g0, g1) = (run.grains(steps[k0])?, run.grains(steps[k1])?);
        if !g1.same_grains(&g0) {
            bail!(
                "run {}: the particle snapshots at steps {} and {} hold other grains ({} vs {} clumps); the \
                 packed zone by displacement needs the same grains in both",
                run.dir.display(),
                steps[k0],
                steps[k1],
                g0.len(),
                g1.len()
            );
        }
        let grains = (0..g1.len()).map(|k| {
            let (a, b) = (g0.centroid[k], g1.centroid[k]);
            let still = (b[0] - a[0]).hypot(b[1] - a[1]) < moved;
            (g1.area[k], still, g1.circles[k].iter().map(|c| (c[1], c[2])))
        });
        let (b, _) = zone.bands(grains);
        let [fraction, height] = zone.zone(&b);
        rows.push([t1, fraction, height, interior_fraction(&b)]);
        bands = b;
    }
    Ok((rows, bands))
}

/// Fig. 5h: the packed zone's packing fraction over time, by speed (the series) and by
/// displacement (the snapshots), with Su's ≈ 77 %. Nothing when the run has no packed zone.
pub(super) fn analyse(
    p: &Params,
    run: &Run,
    out: &Path,
    figures: &mut Vec<Figure>,
    files: &mut Vec<PathBuf>,
    tables: &mut Vec<Table>,
) -> Result<Option<serde_json::Value>> {
    let Some(zone) = PackedZone::new(&run.scene.scene)? else {
        return Ok(None);
    };
    if !(p.packed_window > 0.0 && p.packed_window.is_finite() && p.packed_moved_less_than > 0.0) {
        bail!(
            "parameters 'packed_window' = {} s and 'packed_moved_less_than' = {} m must be positive (Su et al. \
             2020 Sect. 3.2: 10 s and 2e-6 m)",
            p.packed_window,
            p.packed_moved_less_than
        );
    }
    let (rows, bands) = by_displacement(run, &zone, p.packed_window, p.packed_moved_less_than)?;
    let col = |i: usize| rows.iter().map(|r| r[i]).collect::<Vec<f64>>();
    let (t_d, frac_d, height_d, inner_d) = (col(0), col(1), col(2), col(3));
    let name = "packed_zone_displacement.csv";
    write_table(
        &out.join(name),
        &[
            ("time", Col::F64(&t_d)),
            ("packed_zone_fraction", Col::F64(&frac_d)),
            ("packed_zone_height", Col::F64(&height_d)),
            ("packed_zone_interior_fraction", Col::F64(&inner_d)),
        ],
    )?;
    files.push(name.into());
    tables.push(Table {
        path: name.into(),
        caption: format!(
            "The packed zone by Su's criterion (Sect. 3.2): at each particle snapshot with one {} s earlier, \
             the run of bands from the packing side whose grains all moved less than {:e} m since; its \
             packing fraction (NaN: no band packed) and height (m), and its interior packing fraction \
             (without the band against the wall and the ragged lowest band; NaN under three bands).",
            p.packed_window, p.packed_moved_less_than
        ),
    });
    if !bands.is_empty() {
        let name = "packed_zone_bands.csv";
        let depth: Vec<f64> = bands.iter().map(|b| b.depth).collect();
        let fraction: Vec<f64> = bands.iter().map(|b| b.fraction).collect();
        let still: Vec<f64> = bands.iter().map(|b| f64::from(u8::from(b.still))).collect();
        write_table(
            &out.join(name),
            &[
                ("depth", Col::F64(&depth)),
                ("fraction", Col::F64(&fraction)),
                ("still", Col::F64(&still)),
            ],
        )?;
        files.push(name.into());
        tables.push(Table {
            path: name.into(),
            caption: format!(
                "The bands of the last snapshot pair (t = {:.4} s) from the packing side: depth of the band's middle \
                 (m), the grains' area in it over its area, and whether all its grains moved less than {:e} m in \
                 {} s (1) or not (0). The zone is the run of still bands from the packing side; inside it the \
                 profile shows the wall layer, the bulk and the ragged lower edge.",
                rows.last().map_or(f64::NAN, |r| r[0]),
                p.packed_moved_less_than,
                p.packed_window
            ),
        });
    }
    let t = run.series("time").unwrap_or_default();
    let pz = run.series("packed_zone_fraction").unwrap_or_default();
    let fov = run.series("packing_box").unwrap_or_default();
    let f = "packed_zone.png";
    lines_png(
        &out.join(f),
        &[
            Line {
                label: "f_S,pk,PK, speed below the scene's threshold (series)",
                x: &t,
                y: &pz,
                style: Style::Solid,
                colour: Some((30, 90, 200)),
            },
            Line {
                label: "f_S,pk,PK, moved under the window's distance (snapshots)",
                x: &t_d,
                y: &frac_d,
                style: Style::LinePoints,
                colour: Some((20, 150, 60)),
            },
            Line {
                label: "f_S,pk,PK inside the zone, edge bands left out (snapshots)",
                x: &t_d,
                y: &inner_d,
                style: Style::Points,
                colour: Some((120, 40, 160)),
            },
            Line {
                label: "f_S,pk,FOV (box)",
                x: &t,
                y: &fov,
                style: Style::Dashed,
                colour: Some((200, 60, 30)),
            },
        ],
        &LinesPlot {
            title: "packing fraction of the floated layer (Su Fig. 5h)",
            x_label: "t_DEM (s)",
            y_label: "packing fraction (-)",
            h_refs: vec![Reference {
                value: 0.77,
                label: "Su: ≈ 77 %",
            }],
            ..Default::default()
        },
    )?;
    figures.push(Figure {
        path: f.into(),
        caption: format!(
            "Packing fraction of the packed zone from the side the grains pack against, by the grains' speed \
             (the run's series) and by their displacement over {} s between snapshots (Su's radiograph \
             criterion), and of the whole box, over time, as Su et al. 2020 Fig. 5h; their full Float case \
             reached ≈ 77 %. From {}.",
            p.packed_window,
            run.dir.display()
        ),
    });
    files.push(f.into());
    let last = rows.iter().rev().find(|r| r[1].is_finite());
    Ok(Some(serde_json::json!({
        "window_s": p.packed_window,
        "moved_less_than_m": p.packed_moved_less_than,
        "pairs": rows.len(),
        "last_packed": last.map(|r| serde_json::json!({"time_s": r[0], "fraction": r[1], "height_m": r[2],
                                                        "interior_fraction": r[3]})),
    })))
}
