//! Bad input gets a clear error that names the file or parameter, and nothing is written.

use crate::common;

use lbdem::contract::{Stage, StageContext};
use lbdem::io::tiff::{write_u8, write_u16};
use lbdem::stages::radiograph::{Params, Radiograph};
use ndarray::Array2;
use std::path::Path;
use tiff::encoder::{TiffEncoder, colortype};

fn frame(h: usize, w: usize, v: u16) -> Array2<u16> {
    Array2::from_shape_fn(
        (h, w),
        |(r, c)| if c < w / 2 { v } else { v / 4 + (r % 3) as u16 },
    )
}

/// Base parameters over two good 64x64 frames in `dir`, modified by `extra` (TOML lines).
fn params(dir: &Path, extra: &str) -> Params {
    let mut t: toml::Table = toml::from_str(&format!(
        r#"frames = ["{d}/a.tif", "{d}/b.tif"]
        i_s0_roi = [0, 0, 16, 16]
        i_l0_roi = [40, 0, 16, 16]
        mu_s = 2000.0
        mu_l = 9000.0
        l_alloy0 = 150e-6
        d_bar = 10e-6
        pixel_size = 1e-6
        plots = false"#,
        d = dir.display()
    ))
    .unwrap();
    let e: toml::Table = toml::from_str(extra).unwrap();
    t.extend(e);
    toml::Value::Table(t).try_into().unwrap()
}

fn expect_error(dir: &Path, extra: &str, needles: &[&str]) {
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), "radiograph".into(), dir.into());
    let err = Radiograph::run(&params(dir, extra), &ctx).expect_err("bad input must fail");
    let msg = format!("{err:#}");
    for n in needles {
        assert!(msg.contains(n), "error for `{extra}` should mention '{n}': {msg}");
    }
    let written: Vec<_> = std::fs::read_dir(out.path()).unwrap().collect();
    assert!(
        written.is_empty(),
        "nothing may be written on bad input `{extra}`, found {written:?}"
    );
}

fn setup() -> tempfile::TempDir {
    let d = tempfile::tempdir().unwrap();
    write_u16(&d.path().join("a.tif"), frame(64, 64, 20000).view()).unwrap();
    write_u16(&d.path().join("b.tif"), frame(64, 64, 19000).view()).unwrap();
    write_u16(&d.path().join("small.tif"), frame(32, 64, 19000).view()).unwrap();
    write_u16(
        &d.path().join("hot_dark.tif"),
        Array2::from_elem((64, 64), 30000u16).view(),
    )
    .unwrap();
    write_u8(
        &d.path().join("eight.tif"),
        Array2::from_elem((64, 64), 200u8).view(),
    )
    .unwrap();
    // A 32-bit unsigned integer TIFF: a bit depth lbdem does not read.
    let mut buf = std::io::Cursor::new(Vec::new());
    TiffEncoder::new(&mut buf)
        .unwrap()
        .write_image::<colortype::Gray32>(64, 64, &vec![7u32; 64 * 64])
        .unwrap();
    std::fs::write(d.path().join("u32.tif"), buf.into_inner()).unwrap();
    d
}

#[test]
fn good_input_runs() {
    let d = setup();
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), "radiograph".into(), d.path().into());
    let o = Radiograph::run(&params(d.path(), ""), &ctx).unwrap();
    assert!(o.files.iter().any(|f| f.ends_with("eps_vol_001.tif")));
}

#[test]
fn bad_inputs_are_named_and_nothing_is_written() {
    let d = setup();
    let p = d.path().display().to_string();
    expect_error(
        d.path(),
        &format!(r#"frames = ["{p}/a.tif", "{p}/missing.tif"]"#),
        &["missing.tif"],
    );
    expect_error(
        d.path(),
        &format!(r#"frames = ["{p}/a.tif", "{p}/u32.tif"]"#),
        &["u32.tif", "32-bit"],
    );
    expect_error(
        d.path(),
        &format!(r#"frames = ["{p}/a.tif", "{p}/small.tif"]"#),
        &["small.tif", "32x64"],
    );
    expect_error(
        d.path(),
        &format!(r#"frames = ["{p}/a.tif", "{p}/eight.tif", "{p}/small.tif"]"#),
        &["small.tif"],
    );
    expect_error(d.path(), "i_l0_roi = [60, 0, 16, 16]", &["i_l0_roi", "outside"]);
    expect_error(
        d.path(),
        "thickness = \"eq2\"\nthickness_roi = [0, 60, 8, 8]",
        &["thickness_roi"],
    );
    expect_error(d.path(), "i_l0 = 0.5", &["exactly one of 'i_l0'"]);
    expect_error(
        d.path(),
        &format!(r#"dark = "{p}/hot_dark.tif""#),
        &["a.tif", "not positive", "row 0, col 0"],
    );
    expect_error(d.path(), "d_bar = 100e-6", &["REV side 316 px", "d_bar"]);
    expect_error(d.path(), "pixel_size = -1.0", &["pixel_size"]);
    expect_error(d.path(), "map_step = 2", &["map_step", "odd"]);
    expect_error(d.path(), "map_step = 0", &["map_step"]);
    // A profile too thin to hold the centre of a 3 px map cell.
    expect_error(
        d.path(),
        "map_step = 3\n[[profiles]]\nname = \"thin\"\nroi = [0, 0, 1, 32]\naxis = \"y\"",
        &["profile 'thin'", "map cell", "map_step"],
    );
}

#[test]
fn equal_reference_intensities_are_refused() {
    let d = setup();
    let out = tempfile::tempdir().unwrap();
    let ctx = StageContext::new(out.path().into(), "radiograph".into(), d.path().into());
    let mut p = params(d.path(), "");
    (p.i_l0_roi, p.i_s0_roi, p.i_l0, p.i_s0) = (None, None, Some(0.5), Some(0.5));
    let msg = format!("{:#}", Radiograph::run(&p, &ctx).unwrap_err());
    assert!(
        msg.contains("I_S^0") && msg.contains("I_L^0") && msg.contains("equal"),
        "{msg}"
    );
    assert_eq!(std::fs::read_dir(out.path()).unwrap().count(), 0);
}

/// A 300-byte little-endian TIFF whose header claims `w` x `h` 16-bit grey pixels in one
/// uncompressed strip (the pixel data is absent).
fn hostile_tiff(w: u32, h: u32) -> Vec<u8> {
    // (tag, type: 3 = SHORT, 4 = LONG, value)
    let entries: [(u16, u16, u32); 9] = [
        (256, 4, w),   // ImageWidth
        (257, 4, h),   // ImageLength
        (258, 3, 16),  // BitsPerSample
        (259, 3, 1),   // Compression: none
        (262, 3, 1),   // PhotometricInterpretation: black is zero
        (273, 4, 8),   // StripOffsets
        (277, 3, 1),   // SamplesPerPixel
        (278, 4, h),   // RowsPerStrip
        (279, 4, 200), // StripByteCounts
    ];
    let mut b = b"II*\0".to_vec();
    b.extend(8u32.to_le_bytes());
    b.extend((entries.len() as u16).to_le_bytes());
    for (tag, ty, v) in entries {
        b.extend(tag.to_le_bytes());
        b.extend(ty.to_le_bytes());
        b.extend(1u32.to_le_bytes());
        match ty {
            3 => b.extend((v as u16).to_le_bytes().into_iter().chain([0, 0])),
            _ => b.extend(v.to_le_bytes()),
        }
    }
    b.extend(0u32.to_le_bytes());
    b.resize(300, 0);
    b
}

/// Regression (issue 17): a 300-byte TIFF claiming 200000 x 200000 pixels made `lbdem
/// radiograph` allocate 80 GB and abort (exit 134), leaving a staging directory behind. Now the
/// header is checked against the per-frame limit before anything is allocated: exit 1, the
/// file and the limit named, and the output directory not created.
#[test]
fn a_header_claiming_80_gb_is_refused_without_allocating() {
    let d = tempfile::tempdir().unwrap();
    std::fs::write(d.path().join("huge.tif"), hostile_tiff(200_000, 200_000)).unwrap();
    std::fs::write(
        d.path().join("p.toml"),
        "frames = [\"huge.tif\"]\ni_s0_roi = [0, 0, 4, 4]\ni_l0_roi = [4, 0, 4, 4]\nmu_s = 2000.0\n\
         mu_l = 9000.0\nl_alloy0 = 150e-6\nd_bar = 10e-6\npixel_size = 1e-6\n",
    )
    .unwrap();
    let out = d.path().join("out");
    let (code, err) = common::run_code(Some(d.path()), &["radiograph", "p.toml", "--out", "out"]);
    assert_eq!(code, Some(1), "a refused file exits 1, not abort: {err}");
    for needle in ["huge.tif", "200000 x 200000", "limit", "128 MiB"] {
        assert!(err.contains(needle), "the error should name '{needle}': {err}");
    }
    assert!(
        !out.exists(),
        "nothing may be left behind: {:?}",
        std::fs::read_dir(&out).map(|r| r.count())
    );
    // The reader alone, from bytes: the same refusal, and the limit is what a real frame needs.
    let e = lbdem::io::tiff::read_pages_from(std::io::Cursor::new(hostile_tiff(200_000, 200_000)), "x")
        .unwrap_err();
    assert!(format!("{e:#}").contains("above lbdem's limit"), "{e:#}");
    // Su's detector frame (2048 x 2048, 16 bits) reads under the limit.
    let su = d.path().join("su.tif");
    write_u16(&su, Array2::from_elem((2048, 2048), 1234u16).view()).unwrap();
    let f = lbdem::io::tiff::read_pages(&su).unwrap();
    assert_eq!((f[0].data.dim(), f[0].data[[2047, 2047]]), ((2048, 2048), 1234.0));
    // 4096 x 4096 at 16 bits is under the limit: the header passes and the missing data is named.
    let e =
        lbdem::io::tiff::read_pages_from(std::io::Cursor::new(hostile_tiff(4096, 4096)), "x").unwrap_err();
    assert!(format!("{e:#}").contains("cannot decode the pixel data"), "{e:#}");
}

/// Frames are read one at a time while earlier ones are processed (issue 18 item 5), so a pixel
/// that is not positive in a later frame is found after the first maps were made: the stage
/// still fails naming that frame and pixel, and through `lbdem radiograph` (the pipeline's
/// staging directory) nothing is left behind. With `mask_nonpositive` the same frames run and
/// the pixel is counted as masked.
#[test]
fn a_bad_pixel_in_a_later_frame_fails_the_run_and_leaves_nothing() {
    let d = setup();
    let mut bad = frame(64, 64, 19000);
    bad[[5, 7]] = 0;
    write_u16(&d.path().join("c.tif"), bad.view()).unwrap();
    let base = "frames = [\"a.tif\", \"b.tif\", \"c.tif\"]\ni_s0_roi = [0, 0, 16, 16]\n\
                i_l0_roi = [40, 0, 16, 16]\nmu_s = 2000.0\nmu_l = 9000.0\nl_alloy0 = 150e-6\n\
                d_bar = 10e-6\npixel_size = 1e-6\nplots = false\n";
    std::fs::write(d.path().join("p.toml"), base).unwrap();
    let (code, err) = common::run_code(Some(d.path()), &["radiograph", "p.toml", "--out", "out"]);
    assert_eq!(code, Some(1), "{err}");
    for needle in ["c.tif", "not positive", "row 5, col 7"] {
        assert!(err.contains(needle), "the error should name '{needle}': {err}");
    }
    assert!(!d.path().join("out").exists(), "nothing may be left behind");
    std::fs::write(
        d.path().join("m.toml"),
        format!("{base}mask_nonpositive = true\n"),
    )
    .unwrap();
    let (code, err) = common::run_code(Some(d.path()), &["radiograph", "m.toml", "--out", "out"]);
    assert_eq!(code, Some(0), "{err}");
    let s: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("out/summary.json")).unwrap()).unwrap();
    let masked: Vec<u64> = (0..3)
        .map(|n| s["per_frame"][n]["masked_pixels"].as_u64().unwrap())
        .collect();
    assert_eq!(masked, [0, 0, 1]);
}
