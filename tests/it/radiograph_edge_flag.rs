//! The `radiograph` stage flags the REVs that reach a bulk liquid or solid region (issue 17
//! item 6), and the flag marks where the eps_vol accuracy of docs/radiograph.md does not hold.
//!
//! Synthetic frames with a known answer (`synth-radiograph`: truncated spheres squeezed
//! between the windows, 5 % thinner second frame, Poisson noise) with a detector blur of
//! 1.5 px, twice the default: the Jensen bias of a blurred sharp edge (the log of a mean, not
//! the mean of the log) then puts the largest eps_vol errors within one REV of the liquid gap
//! and pad below the assembly. Measured (seed 2): max |eps_vol error| 0.0083 over all REVs,
//! 0.0045 over the unflagged ones, with 29.7 % of the eps_vol REVs flagged (the default window of
//! two grains; at one grain the liquid pockets of this 50 % packing were flagged too: 67 %;
//! the former block rule, which could miss REVs, flagged 26 %).

use lbdem::contract::{Stage, StageContext};
use lbdem::io::tiff::{read_pages, write_u16};
use lbdem::report::table;
use lbdem::stages::radiograph::{Params as RParams, Radiograph};
use lbdem::stages::synth::{Params as SParams, SynthRadiograph};
use lbdem_imaging::Roi;
use lbdem_imaging::beer_lambert::eps_vol_field;
use lbdem_imaging::rev::Sat;
use lbdem_imaging::synth::{self, Beam, Disk, Displacement, GrainShape};
use ndarray::{Array2, Axis, s};
use std::path::Path;

fn read(p: &Path) -> Array2<f64> {
    read_pages(p).unwrap().remove(0).data
}

/// Radiograph parameters for two frames in `dir` with the reference ROIs of the synthetic
/// set, plus `extra` TOML lines.
fn stage_params(dir: &Path, s: &SParams, liquid: Roi, solid: Roi, extra: &str) -> RParams {
    let (mu_s, mu_l) = s.mus();
    let text = format!(
        r#"frames = ["{d}/frame_000.tif", "{d}/frame_001.tif"]
        i_l0_roi = {l:?}
        i_s0_roi = {s_:?}
        mu_s = {mu_s}
        mu_l = {mu_l}
        l_alloy0 = {l0}
        d_bar = {dbar}
        pixel_size = {px}
        thickness = "eq2"
        thickness_roi = {l:?}
        plots = false
        {extra}"#,
        d = dir.display(),
        l = <[usize; 4]>::from(liquid),
        s_ = <[usize; 4]>::from(solid),
        l0 = s.thickness0,
        dbar = s.d_bar,
        px = s.pixel_size,
    );
    toml::from_str(&text).unwrap()
}

/// Largest |eps_vol error| over every REV with both values and over the unflagged ones, and
/// the share of those REVs flagged.
fn errors(eps: &Array2<f64>, truth: &Array2<f64>, near: &Array2<f64>) -> (f64, f64, f64) {
    let (mut all, mut away, mut n, mut flagged) = (0.0f64, 0.0f64, 0usize, 0usize);
    for ((e, t), f) in eps.iter().zip(truth).zip(near) {
        if e.is_finite() && t.is_finite() {
            let err = (e - t).abs();
            all = all.max(err);
            n += 1;
            if *f > 0.0 {
                flagged += 1;
            } else {
                away = away.max(err);
            }
        }
    }
    (all, away, flagged as f64 / n as f64)
}

#[test]
fn flagged_revs_hold_the_edge_errors() {
    let synth = tempfile::tempdir().unwrap();
    let s: SParams =
        toml::from_str("seed = 2\nblur_sigma_px = 1.5\nthickness_change = -0.05\nplots = false").unwrap();
    let ctx = StageContext::new(synth.path().into(), "synth".into(), synth.path().into());
    SynthRadiograph::run(&s, &ctx).unwrap();
    let lay = lbdem::stages::synth::layout(&s).unwrap();
    let p = stage_params(
        synth.path(),
        &s,
        lay.liquid_ref,
        lay.solid_ref,
        // Every pixel's REV (the accuracy figures are per pixel; the default grid's cells are the
        // same values at block centres, `a_map_on_the_default_grid_is_the_full_map_at_block_centres`).
        "map_step = 1\nprofiles = [{ name = \"red\", roi = [100, 0, 200, 512], axis = \"y\" }]",
    );
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), "radiograph".into(), synth.path().into());
    let res = Radiograph::run(&p, &ctx).unwrap();

    let eps = read(&out.path().join("eps_vol_001.tif"));
    let truth = read(&synth.path().join("true_eps_vol_001.tif"));
    let near = read(&out.path().join("near_edge_001.tif"));
    let (all, away, share) = errors(&eps, &truth, &near);
    println!(
        "max |eps error| all {all:.4}, unflagged {away:.4}; flagged {:.1} %",
        100.0 * share
    );
    // The case is hard enough that the documented 0.005 fails somewhere (0.0083 measured) ...
    assert!(all > 0.006, "no REV beyond the documented accuracy: {all}");
    // ... and holds on every unflagged REV (0.0045 measured; the documented limit).
    assert!(away < 0.005, "unflagged REV eps_vol error {away} above 0.005");
    // The flag is local: the pads and gaps, not the assembly (29.7 % measured).
    assert!(share < 0.35, "{:.1} % of the REVs flagged", 100.0 * share);
    // The middle of the assembly (rows 200-300) is never flagged; the solid pad is.
    assert!((200..300).all(|r| near.row(r).iter().all(|&f| f == 0.0)));
    assert!(near.row(5).iter().all(|&f| f == 1.0));

    // The summary, the grid and the profile carry the flag.
    let f = &res.summary["per_frame"][1];
    let (k, kn) = eps
        .iter()
        .zip(&near)
        .filter(|(e, _)| e.is_finite())
        .fold((0, 0), |(k, kn), (_, &f)| (k + 1, kn + usize::from(f > 0.0)));
    let got = f["near_edge_fraction"].as_f64().unwrap();
    assert_eq!(got, kn as f64 / k as f64, "summary vs map");
    assert!(f["eps_vol_mean_away_from_edges"].as_f64().unwrap().is_finite());
    let grid = std::fs::read_to_string(out.path().join("grid.csv")).unwrap();
    assert!(grid.lines().next().unwrap().contains("near_edge_001"));
    let prof = std::fs::read_to_string(out.path().join("profile_red.csv")).unwrap();
    assert!(prof.lines().next().unwrap().contains("near_edge_fraction_001"));
}

/// A threshold pair that cannot classify anything is refused before anything is written.
#[test]
fn inverted_thresholds_are_refused() {
    let out = tempfile::tempdir().unwrap();
    let p: RParams = toml::from_str(
        r#"frames = ["none.tif"]
        i_l0 = 100.0
        i_s0 = 50.0
        mu_s = 1.0
        mu_l = 2.0
        l_alloy0 = 1e-4
        d_bar = 1e-4
        pixel_size = 1e-6
        edge_flag = { liquid_below = 0.9, solid_above = 0.1 }"#,
    )
    .unwrap();
    let ctx = StageContext::new(out.path().join("r"), "radiograph".into(), out.path().into());
    let err = format!("{:#}", Radiograph::run(&p, &ctx).unwrap_err());
    assert!(err.contains("liquid_below") && err.contains("0.9"), "{err}");
    assert!(!out.path().join("r").exists());
}

/// The synthetic set of `toml` (synth-radiograph parameters) written into `dir`.
fn synth_set(dir: &Path, toml_text: &str) -> SParams {
    let s: SParams = toml::from_str(toml_text).unwrap();
    let ctx = StageContext::new(dir.into(), "synth".into(), dir.into());
    SynthRadiograph::run(&s, &ctx).unwrap();
    s
}

/// Profiles average the flag over the REVs that have an eps_vol only (review finding 2): the
/// synthetic frames turned upside down put the bulk liquid (pad and gap, 64 rows) at the top,
/// where the REVs of the first rows hold less than eps_min_gs of solid and have no eps_vol.
/// There the profile's near_edge_fraction is NaN (it was 1: the flags of REVs without eps_vol
/// were averaged); just below, where eps_vol exists, 1; in the middle rows 200-300, 0; and the
/// top row of grid tiles, which holds the bulk liquid, is flagged.
#[test]
fn profile_fraction_counts_only_revs_with_eps_vol() {
    let synth = tempfile::tempdir().unwrap();
    let s = synth_set(synth.path(), "seed = 2\nthickness_change = -0.05\nplots = false");
    let lay = lbdem::stages::synth::layout(&s).unwrap();
    let flipped = tempfile::tempdir().unwrap();
    for k in 0..2 {
        let name = format!("frame_{k:03}.tif");
        let f = read(&synth.path().join(&name));
        let up = f.slice(s![..;-1, ..]).mapv(|v| v as u16);
        write_u16(&flipped.path().join(&name), up.view()).unwrap();
    }
    let h = s.height;
    let flip = |r: Roi| Roi::new(r.x, h - r.y - r.h, r.w, r.h);
    let p = stage_params(
        flipped.path(),
        &s,
        flip(lay.liquid_ref),
        flip(lay.solid_ref),
        "map_step = 1\nprofiles = [{ name = \"all\", roi = [0, 0, 512, 512], axis = \"y\" }]",
    );
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), "radiograph".into(), flipped.path().into());
    Radiograph::run(&p, &ctx).unwrap();

    let eps = read(&out.path().join("eps_vol_001.tif"));
    let near = read(&out.path().join("near_edge_001.tif"));
    let path = out.path().join("profile_all.csv");
    let df = table::read_table(&path).unwrap();
    let frac = table::f64_column(&df, "near_edge_fraction_001", &path).unwrap();
    assert_eq!(frac.len(), h);
    // Every row: the mean flag over the pixels with an eps_vol, NaN where none has one.
    for (r, (got, (erow, nrow))) in frac
        .iter()
        .zip(eps.axis_iter(Axis(0)).zip(near.axis_iter(Axis(0))))
        .enumerate()
    {
        let (k, kn) = erow
            .iter()
            .zip(nrow)
            .filter(|(e, _)| e.is_finite())
            .fold((0usize, 0usize), |(k, kn), (_, &f)| {
                (k + 1, kn + usize::from(f > 0.0))
            });
        if k == 0 {
            assert!(got.is_nan(), "row {r}: no eps_vol, fraction {got}");
        } else {
            assert!(
                (got - kn as f64 / k as f64).abs() < 1e-12,
                "row {r}: {got} vs {kn}/{k}"
            );
        }
    }
    // The liquid rows: flagged everywhere, but only some have an eps_vol.
    let no_eps = (0..h)
        .filter(|&r| eps.row(r).iter().all(|e| !e.is_finite()))
        .count();
    println!(
        "rows without eps_vol: {no_eps}; first row with: {:?}",
        frac.iter().position(|f| f.is_finite())
    );
    assert!(frac[0].is_nan() && near.row(0).iter().all(|&f| f == 1.0));
    let first = frac.iter().position(|f| f.is_finite()).unwrap();
    assert!(
        frac[first..first + 10].iter().all(|&f| f == 1.0),
        "{:?}",
        &frac[first..first + 10]
    );
    assert!(frac[200..300].iter().all(|&f| f == 0.0));
    let gpath = out.path().join("grid.csv");
    let grid = table::read_table(&gpath).unwrap();
    let y = table::f64_column(&grid, "y_mm", &gpath).unwrap();
    let flag = table::f64_column(&grid, "near_edge_001", &gpath).unwrap();
    let y0 = y[0];
    let top: Vec<f64> = y
        .iter()
        .zip(&flag)
        .filter(|(y, _)| **y == y0)
        .map(|(_, f)| *f)
        .collect();
    assert!(!top.is_empty() && top.iter().all(|&f| f == 1.0), "{top:?}");
}

/// SplitMix64: a small deterministic jitter for the lattice below.
fn jitter(i: u64) -> f64 {
    let mut z = i.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

/// Disks of diameter `d` px on a hexagonal lattice whose spacing gives them `phi` of the plane,
/// jittered by up to half the gap, kept inside `region`.
fn hex_disks(region: Roi, d: f64, phi: f64) -> Vec<Disk> {
    let a = d * (std::f64::consts::PI / (2.0 * 3f64.sqrt() * phi)).sqrt();
    let gap = 0.5 * (a - d);
    let r = 0.5 * d;
    let mut disks = Vec::new();
    let (mut row, mut k) = (0usize, 0u64);
    loop {
        let y = region.y as f64 + r + row as f64 * a * 3f64.sqrt() / 2.0;
        if y + r > (region.y + region.h) as f64 {
            break;
        }
        let mut x = region.x as f64 + r + if row % 2 == 1 { 0.5 * a } else { 0.0 };
        while x + r <= (region.x + region.w) as f64 {
            disks.push(Disk {
                x: x + gap * jitter(2 * k),
                y: y + gap * jitter(2 * k + 1),
                r,
            });
            x += a;
            k += 1;
        }
        row += 1;
    }
    disks
}

/// The flag at a dense packing (~84 % of the assembly's area in grains, as a jammed random
/// packing of disks; the synthetic stage's random addition stops near 55 %): truncated spheres
/// on a jittered hexagonal lattice, the synthetic stage's pads, displacement, 5 % thinning,
/// blur 1.5 px and Poisson noise. Such a packing must not read as bulk solid: the window mean
/// of L_S/L there is about 0.65, far from 0.95.
#[test]
fn dense_packing_is_flagged_at_its_edges_only() {
    let s: SParams =
        toml::from_str("seed = 3\nblur_sigma_px = 1.5\nthickness_change = -0.05\nplots = false").unwrap();
    let lay = lbdem::stages::synth::layout(&s).unwrap();
    let (h, w) = (s.height, s.width);
    let d = s.d_bar / s.pixel_size;
    let region = lay.assembly;
    // 84 % inside the lattice; the assembly region as a whole holds less (whole rows and
    // columns of disks only).
    let disks0 = hex_disks(region, d, 0.84);
    let phi = disks0
        .iter()
        .map(|k| std::f64::consts::PI * k.r * k.r)
        .sum::<f64>()
        / (region.w * region.h) as f64;
    let (mu_s, mu_l) = s.mus();
    let beam = Beam { i0: s.i0, mu_s, mu_l };
    let disp = Displacement {
        strain_xx: 0.0,
        strain_yy: 0.01,
        bump_amplitude: 0.05,
        bump_sigma_px: 60.0,
    };
    let centre = (
        region.x as f64 + 0.5 * region.w as f64,
        region.y as f64 + 0.5 * region.h as f64,
    );
    let rev_side = lbdem_imaging::rev::rev_side_px(s.rev_factor, s.d_bar, s.pixel_size).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let mut truth = Vec::new();
    let mut sat = Sat::new();
    for k in 0..2 {
        let disks = if k == 0 {
            disks0.clone()
        } else {
            disp.apply(&disks0, centre)
        };
        let l = s.thickness0 * (1.0 + k as f64 * s.thickness_change);
        let (cov, counts) = synth::render(
            h,
            w,
            &disks,
            s.supersample,
            GrainShape::TruncatedSphere,
            l / s.pixel_size,
            l,
            &beam,
            &[lay.solid_pad],
            &[lay.liquid_pad],
        );
        let blurred = synth::gaussian_blur(counts.view(), s.blur_sigma_px);
        let raw = synth::noisy_u16(blurred.view(), 40 + k as u64).unwrap();
        write_u16(&dir.path().join(format!("frame_{k:03}.tif")), raw.view()).unwrap();
        sat.build(cov.view());
        truth.push(sat.rev_mean(rev_side, 0.5).unwrap());
    }
    let true_eps = eps_vol_field(truth[0].view(), truth[1].view(), 0.1);
    let p = stage_params(dir.path(), &s, lay.liquid_ref, lay.solid_ref, "map_step = 1");
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), "radiograph".into(), dir.path().into());
    let res = Radiograph::run(&p, &ctx).unwrap();
    let eps = read(&out.path().join("eps_vol_001.tif"));
    let near = read(&out.path().join("near_edge_001.tif"));
    let (all, away, share) = errors(&eps, &true_eps, &near);
    let g_mid = truth[0].slice(s![200..300, ..]).mean().unwrap();
    println!(
        "disk area fraction {phi:.3}, REV g_S rows 200-300 {g_mid:.3}; max |eps error| all {all:.4}, \
         unflagged {away:.4}; flagged {:.1} %; summary near_edge_fraction {}",
        100.0 * share,
        res.summary["per_frame"][1]["near_edge_fraction"]
    );
    // Measured (seed 3): disk area fraction 0.780 of the assembly region (0.84 inside the
    // lattice), REV g_S 0.616 in rows 200-300; max |eps_vol error| 0.0076 over all REVs,
    // 0.0049 over the unflagged ones, 29.7 % flagged. Denser lattices (0.86 and 0.897 of the
    // plane, seed 3) gave 0.0053 and 0.0067 unflagged: the documented 0.005 is marginal there.
    assert!(phi > 0.77, "disk area fraction {phi}");
    assert!(
        away < 0.0055,
        "unflagged REV eps_vol error {away} (0.0049 measured)"
    );
    assert!(
        all > 0.006,
        "no REV beyond the documented accuracy: {all} (0.0076 measured)"
    );
    assert!(
        share < 0.35,
        "{:.1} % of the REVs flagged (29.7 % measured)",
        100.0 * share
    );
    assert!((200..300).all(|r| near.row(r).iter().all(|&f| f == 0.0)));
    assert!(near.row(5).iter().all(|&f| f == 1.0));
}

/// The stage as a whole gives the same bytes on 1 and 2 threads: maps, grid, profiles and the
/// summary's means (summed per row in parallel, rows added in order). Four frames, so the map
/// writer's returned buffers (stale contents, overwritten by the REV pass) are reused. The same
/// frames as one four-page stack, read page by page as the stage goes, give the same maps.
#[test]
fn the_stage_gives_the_same_bytes_on_one_and_two_threads() {
    let synth = tempfile::tempdir().unwrap();
    let s: SParams = toml::from_str("seed = 3\nframes = 4\nthickness_change = -0.05\nplots = false").unwrap();
    let ctx = StageContext::new(synth.path().into(), "synth".into(), synth.path().into());
    SynthRadiograph::run(&s, &ctx).unwrap();
    let lay = lbdem::stages::synth::layout(&s).unwrap();
    let mut p = stage_params(
        synth.path(),
        &s,
        lay.liquid_ref,
        lay.solid_ref,
        r#"profiles = [{ name = "red", roi = [100, 0, 200, 512], axis = "y" }]"#,
    );
    p.frames = (0..4)
        .map(|n| synth.path().join(format!("frame_{n:03}.tif")))
        .collect();
    let run = |p: &lbdem::stages::radiograph::Params, threads: usize| {
        let out = tempfile::tempdir().unwrap();
        let ctx = StageContext::new(out.path().into(), "radiograph".into(), synth.path().into());
        let summary = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| Radiograph::run(p, &ctx).unwrap().summary);
        let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(out.path())
            .unwrap()
            .map(|e| e.unwrap().path())
            .map(|f| {
                (
                    f.file_name().unwrap().to_string_lossy().into_owned(),
                    std::fs::read(&f).unwrap(),
                )
            })
            .collect();
        files.sort();
        (summary.to_string(), files)
    };
    let (one, two) = (run(&p, 1), run(&p, 2));
    assert_eq!(one.0, two.0, "summary differs between 1 and 2 threads");
    let names: Vec<&String> = one.1.iter().map(|f| &f.0).collect();
    assert!(names.iter().any(|n| *n == "eps_vol_003.tif"), "{names:?}");
    assert_eq!(one.1.len(), two.1.len());
    for ((name, a), (_, b)) in one.1.iter().zip(&two.1) {
        assert!(a == b, "{name} differs between 1 and 2 threads");
    }
    let pages: Vec<ndarray::Array2<u16>> = p
        .frames
        .iter()
        .map(|f| {
            lbdem::io::tiff::read_pages(f)
                .unwrap()
                .remove(0)
                .data
                .mapv(|v| v as u16)
        })
        .collect();
    let views: Vec<_> = pages.iter().map(|a| a.view()).collect();
    let stack = synth.path().join("stack.tif");
    lbdem::io::tiff::write_u16_stack(&stack, &views).unwrap();
    p.frames = vec![stack];
    let stacked = run(&p, 2);
    assert_eq!(stacked.1.len(), two.1.len());
    for ((name, a), (_, b)) in stacked.1.iter().zip(&two.1) {
        assert!(
            name == "summary.json" || a == b,
            "{name} differs between a stack and numbered files"
        );
    }
}

/// The default map grid (issue 18 item 5): each map the stage writes holds, in every cell, the
/// value of the every-pixel map (`map_step = 1`) at the cell's centre pixel, bit for bit; the
/// summary's means and the profiles, formed over the cells, stay close to the every-pixel ones.
#[test]
fn a_map_on_the_default_grid_is_the_full_map_at_block_centres() {
    let synth = tempfile::tempdir().unwrap();
    let s = synth_set(synth.path(), "seed = 2\nthickness_change = -0.05\nplots = false");
    let lay = lbdem::stages::synth::layout(&s).unwrap();
    let prof = r#"profiles = [{ name = "red", roi = [100, 0, 200, 512], axis = "y" }]"#;
    let run = |extra: &str| {
        let p = stage_params(synth.path(), &s, lay.liquid_ref, lay.solid_ref, extra);
        let out = tempfile::tempdir().unwrap();
        let ctx = StageContext::new(out.path().into(), "radiograph".into(), synth.path().into());
        let summary = Radiograph::run(&p, &ctx).unwrap().summary;
        (out, summary)
    };
    let (full_dir, full) = run(&format!("map_step = 1\n{prof}"));
    let (grid_dir, grid) = run(prof);
    let k = grid["map_step_px"].as_u64().unwrap() as usize;
    let side = full["rev_side_px"].as_u64().unwrap() as usize;
    // A 95 px REV: cells of 5 px.
    assert_eq!((side, k), (95, lbdem_imaging::rev::map_step_auto(side)));
    assert_eq!(k, 5);
    for name in [
        "gs_rev_000.tif",
        "gs_rev_001.tif",
        "eps_vol_001.tif",
        "near_edge_001.tif",
    ] {
        let (a, b) = (
            read(&full_dir.path().join(name)),
            read(&grid_dir.path().join(name)),
        );
        assert_eq!(b.dim(), (a.nrows() / k, a.ncols() / k), "{name}");
        for ((i, j), &v) in b.indexed_iter() {
            let w = a[[i * k + k / 2, j * k + k / 2]];
            assert!(
                (v.is_nan() && w.is_nan()) || v.to_bits() == w.to_bits(),
                "{name} ({i}, {j}): {v} vs {w}"
            );
        }
    }
    // The means over the cells against those over every pixel. Measured (seed 2): g_S 1.36e-3
    // (the cells leave out the last 2 rows and columns, and sample the pads' steep edges),
    // eps_vol 4.7e-5 (of -0.0288), near-edge share 1.17e-3; tolerances twice those.
    let (fa, ga) = (&full["per_frame"][1], &grid["per_frame"][1]);
    for (key, tol) in [
        ("g_s_rev_mean", 2.8e-3),
        ("eps_vol_mean", 1e-4),
        ("near_edge_fraction", 2.4e-3),
    ] {
        let (a, b) = (fa[key].as_f64().unwrap(), ga[key].as_f64().unwrap());
        println!(
            "{key}: every pixel {a:.6}, cells {b:.6}, difference {:.2e}",
            (a - b).abs()
        );
        assert!((a - b).abs() < tol, "{key}: {a} vs {b}");
    }
    // The grid's profile points are every-pixel profile points (the cells' centre rows) averaged
    // over the ROI's centre columns only. Measured: largest eps_vol difference 1.03e-3 (at the
    // pads' edges, where eps_vol changes fastest across a row).
    let col = |dir: &Path, c: &str| {
        let path = dir.join("profile_red.csv");
        table::f64_column(&table::read_table(&path).unwrap(), c, &path).unwrap()
    };
    let (ya, yb) = (col(full_dir.path(), "y_mm"), col(grid_dir.path(), "y_mm"));
    let (ea, eb) = (
        col(full_dir.path(), "eps_vol_001"),
        col(grid_dir.path(), "eps_vol_001"),
    );
    assert_eq!(yb.len(), 512 / k);
    let mut worst = 0.0f64;
    for (y, e) in yb.iter().zip(&eb) {
        let r = ya
            .iter()
            .position(|v| (v - y).abs() < 1e-9)
            .expect("a cell's row is a pixel row");
        assert_eq!(
            e.is_finite(),
            ea[r].is_finite(),
            "row at {y} mm: {e} vs {}",
            ea[r]
        );
        if e.is_finite() {
            worst = worst.max((e - ea[r]).abs());
        }
    }
    println!("profile eps_vol: largest difference {worst:.2e}");
    assert!(worst < 2.1e-3, "profile eps_vol differs by {worst}");
}
