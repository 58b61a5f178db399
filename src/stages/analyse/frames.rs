//! The geometry an analysis reads from a run's snapshots, shared with `compare` and `synth-run`:
//! the reference grains, each snapshot as a strain frame, ε_vol^DEM of Eq. 18, packing and solid
//! fractions, and the push-plate's outline.

use super::ReferenceState;
use crate::report::panels::Shape;
use crate::stages::run_data::{Frame, Grains, Run};
use crate::stages::strain_fields::Setup;
use anyhow::{Result, bail};
use lbdem_analysis::volume;

/// The reference grains, the step they come from (None: the scene's particle file) and the
/// particle steps after it.
pub fn reference(run: &Run, mode: ReferenceState) -> Result<(Grains, Option<u64>, Vec<u64>)> {
    let steps = run.particle_steps();
    let Some(&first) = steps.first() else {
        bail!(
            "run {} wrote no particle snapshot; give its scene an [output] snapshots trigger",
            run.dir.display()
        );
    };
    let g0 = run.grains(first)?;
    if mode == ReferenceState::Initial
        && let Some(mut init) = run.initial_grains(&g0)
    {
        // The membrane is chosen when the run builds its grains: take its tags from the run.
        init.tag = g0.tag.clone();
        return Ok((init, None, steps));
    }
    if steps.len() < 2 {
        bail!(
            "run {} has one particle snapshot and no initial particle file with the same grains: \
             nothing to measure a strain against; ask for more snapshots ([output] snapshots)",
            run.dir.display()
        );
    }
    Ok((g0, Some(first), steps[1..].to_vec()))
}

/// The frame of the analysis: the plate's when there is one, else the grains' lower-left corner.
pub fn frame_of(run: &Run, reference: &Grains, d_bar: f64) -> Frame {
    match run.plate {
        Some(pl) => Frame::new(pl.origin(), pl.dir(), d_bar),
        None => {
            let lo = reference
                .centroid
                .iter()
                .fold([f64::INFINITY; 2], |a, p| [a[0].min(p[0]), a[1].min(p[1])]);
            Frame::new(lo, [0.0, 1.0], d_bar)
        }
    }
}

/// ε_vol^DEM (Eq. 18) of a snapshot: its membrane polygon (ordered as in the reference) minus the
/// plate's penetration at displacement `u`, against the reference's.
pub fn eq18(run: &Run, reference: &Grains, g: &Grains, u: f64) -> Option<(f64, f64)> {
    let behind = |u: f64| {
        run.plate.map(|pl| {
            let (l, r) = pl.corners(u);
            volume::behind_plate(l, r, pl.dir(), 1.0)
        })
    };
    let ring0 = reference.membrane_ring(reference);
    if ring0.is_empty() {
        return None;
    }
    let a0 = volume::sample_area(&ring0, behind(0.0));
    let a = volume::sample_area(&g.membrane_ring(reference), behind(u));
    Some((a, volume::eps_vol_dem(a, a0)))
}

/// The 2D packing fraction of the sample: grain area inside the membrane polygon (membrane grains
/// count half, the polygon passing through their centroids) over the polygon's area.
pub fn packing_fraction(g: &Grains) -> Option<f64> {
    let ring = g.membrane_ring(g);
    if ring.is_empty() {
        return None;
    }
    let solid: f64 = g
        .area
        .iter()
        .zip(&g.tag)
        .map(|(a, t)| if *t == 1 { 0.5 * a } else { *a })
        .sum();
    Some(solid / volume::polygon_area(&ring))
}

/// The fraction of each pixel of the setup's grid covered by the grains' circles (2D grains
/// span the thickness), 3 × 3 samples per pixel.
pub fn solid_fraction(s: &Setup, g: &Grains) -> ndarray::Array2<f64> {
    let grid = &s.grid;
    let d = s.frame.d_bar;
    let mut disks = Vec::new();
    for cs in &g.circles {
        for c in cs {
            let q = s.frame.from_scene([c[0], c[1]]);
            disks.push(lbdem_imaging::synth::Disk {
                x: (q[0] - grid.x0) / grid.dx,
                y: (grid.y1() - q[1]) / grid.dx,
                r: c[2] / d / grid.dx,
            });
        }
    }
    let beam = lbdem_imaging::synth::Beam {
        i0: 1.0,
        mu_s: 1.0,
        mu_l: 1.0,
    };
    lbdem_imaging::synth::render(
        grid.ny,
        grid.nx,
        &disks,
        3,
        lbdem_imaging::synth::GrainShape::Cylinder,
        1.0,
        1.0,
        &beam,
        &[],
        &[],
    )
    .0
}

pub(super) fn median(v: &[f64]) -> f64 {
    let mut f: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if f.is_empty() {
        return f64::NAN;
    }
    f.sort_by(f64::total_cmp);
    let n = f.len();
    if n % 2 == 1 {
        f[n / 2]
    } else {
        0.5 * (f[n / 2 - 1] + f[n / 2])
    }
}

/// Shapes drawn over every map: the plate's face at displacement `u` (m) as a thick line.
pub fn plate_shapes(run: &Run, frame: &Frame, u: f64) -> Vec<Shape> {
    let Some(pl) = run.plate else {
        return Vec::new();
    };
    let (l, r) = pl.corners(u);
    let (a, b) = (frame.from_scene(l), frame.from_scene(r));
    let back = 0.6;
    vec![Shape {
        points: vec![
            (a[0], a[1]),
            (b[0], b[1]),
            (b[0], b[1] - back),
            (a[0], a[1] - back),
        ],
        colour: (40, 40, 40),
        closed: true,
    }]
}
