//! `LBDEM_ISA` (crates/core/src/simd.rs): a value naming no level is refused before anything
//! runs, with the variable, the value and the accepted values; a valid cap is taken and printed
//! (a native build warns that it has no effect); and every level gives the same bits on a DEM
//! scene and a coupled scene.

use std::path::Path;
use std::process::Command;

fn lbdem(isa: &str, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_lbdem"))
        .args(args)
        .env("LBDEM_ISA", isa)
        .output()
        .expect("run lbdem")
}

#[test]
fn a_typo_in_lbdem_isa_is_refused_before_anything_runs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o = lbdem(
        "avx9",
        &[
            "simulate",
            "scenes/dry-settle.toml",
            "--out",
            out.to_str().unwrap(),
        ],
    );
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    for needle in ["LBDEM_ISA", "\"avx9\"", "portable", "v3", "v4"] {
        assert!(err.contains(needle), "missing {needle:?} in: {err}");
    }
    assert!(!out.exists(), "a refused run left {}", out.display());
}

/// A value that is not UTF-8 names no level either: refused, not taken as unset.
#[cfg(unix)]
#[test]
fn a_non_utf8_lbdem_isa_is_refused() {
    use std::os::unix::ffi::OsStrExt;
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("never");
    let o = Command::new(env!("CARGO_BIN_EXE_lbdem"))
        .args([
            "simulate",
            "scenes/dry-settle.toml",
            "--out",
            out.to_str().unwrap(),
        ])
        .env("LBDEM_ISA", std::ffi::OsStr::from_bytes(b"v\xff4"))
        .output()
        .expect("run lbdem");
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("LBDEM_ISA"), "{err}");
    assert!(!out.exists(), "a refused run left {}", out.display());
}

#[test]
fn the_portable_cap_is_taken_or_its_lack_of_effect_named() {
    let dir = tempfile::tempdir().unwrap();
    let o = lbdem(
        "portable",
        &[
            "simulate",
            "scenes/dry-settle.toml",
            "--out",
            dir.path().join("run").to_str().unwrap(),
            "--set",
            "run.steps=2",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{err}");
    // A native build for an AVX-512 CPU compiles every level alike and says so (v4).
    let expect = if lbdem_core::simd::NATIVE_V4 {
        "x86-64-v4"
    } else {
        "SIMD portable"
    };
    assert!(err.contains(expect), "expected {expect:?} in: {err}");
}

/// Run `scene` (a scene file's text) once per `LBDEM_ISA` cap, `portable`, `v3` and none (the
/// best level this CPU has), and compare `files` of the runs byte for byte. Snapshot and series
/// files print every f64 in its shortest round-trip form, so equal bytes are equal bits.
/// Returns the level each run printed.
fn same_bits_at_every_level(scene: &str, extra: &[(&str, &str)], files: &[&str]) -> Vec<String> {
    let t = tempfile::tempdir().unwrap();
    let path = t.path().join("scene.toml");
    std::fs::write(&path, scene).unwrap();
    for (name, text) in extra {
        std::fs::write(t.path().join(name), text).unwrap();
    }
    let mut runs = Vec::new();
    for isa in ["portable", "v3", ""] {
        let out = t.path().join(if isa.is_empty() { "best" } else { isa });
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_lbdem"));
        cmd.args(["simulate", path.to_str().unwrap(), "--out", out.to_str().unwrap()]);
        if isa.is_empty() {
            cmd.env_remove("LBDEM_ISA");
        } else {
            cmd.env("LBDEM_ISA", isa);
        }
        let o = cmd.output().expect("run lbdem");
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(o.status.success(), "LBDEM_ISA={isa}: {err}");
        let level = err
            .lines()
            .find_map(|l| l.split_once("SIMD ").map(|(_, r)| r.to_string()))
            .unwrap_or_else(|| panic!("LBDEM_ISA={isa}: no SIMD level printed in: {err}"));
        runs.push((isa, out, level));
    }
    let (_, base, _) = &runs[0];
    for (isa, out, level) in &runs[1..] {
        for f in files {
            let a = std::fs::read(base.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
            let b = std::fs::read(out.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
            assert!(
                a == b,
                "{f} differs between LBDEM_ISA=portable and LBDEM_ISA={isa:?} ({level})"
            );
        }
    }
    runs.into_iter().map(|(_, _, level)| level).collect()
}

/// In a portable build (the default) the three runs take three code paths where the CPU has
/// AVX-512: baseline, AVX2 + FMA, and AVX-512 with the hand-written lane kernels.
fn levels_differ_unless_native(levels: &[String]) {
    #[cfg(target_arch = "x86_64")]
    let v3 = std::is_x86_feature_detected!("avx2") && std::is_x86_feature_detected!("fma");
    #[cfg(not(target_arch = "x86_64"))]
    let v3 = false;
    if !lbdem_core::simd::NATIVE_V4 {
        assert!(levels[0].starts_with("portable"), "{levels:?}");
        if v3 {
            assert!(levels[1].starts_with("x86-64-v3"), "{levels:?}");
        }
    }
}

/// Bidisperse disks (radii 0.3 and 0.42 mm) on a lattice closer than their diameters in a
/// periodic box without walls: they push apart and stay jammed (φ ≈ 0.86), so every step has
/// contacts, and the list is rebuilt as they move. The linear law without rolling: the fused
/// all-disk pass, the batched pair and kick kernels (AVX-512 lanes at v4), the list rebuild.
/// 19 x 21 = 399 disks: full batches of eight and a tail.
#[test]
fn dem_disks_give_the_same_bits_at_every_level() {
    let (nx, ny, a) = (19usize, 21usize, 6.6e-4);
    let mut csv = String::from("grain_id,x,y,r\n");
    for j in 0..ny {
        for i in 0..nx {
            let k = j * nx + i;
            let r = if (i + 2 * j) % 3 == 0 { 4.2e-4 } else { 3.0e-4 };
            // A small deterministic jitter so the disks do not sit on a perfect lattice.
            let jx = 2.0e-5 * ((k * 7919 % 13) as f64 / 13.0 - 0.5);
            let jy = 2.0e-5 * ((k * 104_729 % 17) as f64 / 17.0 - 0.5);
            let x = (i as f64 + 0.5) * a + jx;
            let y = (j as f64 + 0.5) * a + jy;
            csv.push_str(&format!("{k},{x},{y},{r}\n"));
        }
    }
    let scene = format!(
        r#"
[domain]
lo = [0.0, 0.0]
hi = [{lx}, {ly}]
periodic = [true, true]
[particles]
density = 2.6
csv = "disks.csv"
[contact]
law = "linear"
k_n = 1000.0
k_t = 500.0
damping = {{ ratio = 0.3 }}
mu = 0.5
[dem]
dt = 4.0e-6
skin = 5.0e-5
[run]
steps = 3000
[output]
series = {{ every = 100 }}
snapshots = {{ every = 3000 }}
"#,
        lx = nx as f64 * a,
        ly = ny as f64 * a
    );
    let levels = same_bits_at_every_level(
        &scene,
        &[("disks.csv", csv.as_str())],
        &[
            "series.csv",
            "snapshots/particles_000003000.csv",
            "snapshots/contacts_000003000.csv",
        ],
    );
    levels_differ_unless_native(&levels);
}

/// `scenes/dry-settle.toml`, 2000 steps, series every 100.
fn dry_settle_short() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dry-settle.toml"))
        .unwrap()
        .replace("steps = 20000", "steps = 2000")
        .replace("series = { every = 200 }", "series = { every = 100 }")
        .replace("snapshots = { every = 5000 }", "snapshots = { every = 2000 }")
        .replace("checkpoints = { every = 5000 }", "")
}

/// Two-circle grains settling onto the walls of a box with rolling resistance: the batched pair
/// kernel with its rolling spring, the per-body gather, the wall forces
/// (`scenes/dry-settle.toml`, shorter).
#[test]
fn dem_clumps_on_walls_give_the_same_bits_at_every_level() {
    let levels = same_bits_at_every_level(
        &dry_settle_short(),
        &[],
        &[
            "series.csv",
            "snapshots/particles_000002000.csv",
            "snapshots/contacts_000002000.csv",
        ],
    );
    levels_differ_unless_native(&levels);
}

/// The same grains with Su et al. 2020's elastic-plastic law (Eq. 6) and its rolling spring, the
/// law of every shear-cell scene: its batched kernel in the AVX-512 lanes and in the array lanes.
/// Gravity ×10 and 6000 steps so the grains land and pile: 606 contacts at the end, 367 of them
/// above the yield force (measured with the release binary).
#[test]
fn dem_plastic_clumps_give_the_same_bits_at_every_level() {
    let scene = std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/dry-settle.toml"))
        .unwrap()
        .replace("steps = 20000", "steps = 6000")
        .replace("snapshots = { every = 5000 }", "snapshots = { every = 6000 }")
        .replace("checkpoints = { every = 5000 }", "")
        .replace("gravity = [0.0, -9.81]", "gravity = [0.0, -100.0]")
        .replace(
            "law = \"linear\"\nk_n = 1000.0\n",
            "law = \"plastic\"\nk_e = 1000.0\nk_p = 100.0\nf_y = 1.0e-4\n",
        );
    assert!(
        scene.contains("law = \"plastic\"") && scene.contains("-100.0"),
        "dry-settle.toml's [contact] or gravity changed"
    );
    let levels = same_bits_at_every_level(
        &scene,
        &[],
        &[
            "series.csv",
            "snapshots/particles_000006000.csv",
            "snapshots/contacts_000006000.csv",
        ],
    );
    levels_differ_unless_native(&levels);
}

/// Grains in a liquid (`scenes/coupled-float.toml`, shorter): the LBM kernels, the PSM
/// coupling and the DEM sub-steps.
#[test]
fn coupled_grains_in_liquid_give_the_same_bits_at_every_level() {
    let scene =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/coupled-float.toml"))
            .unwrap()
            .replace("steps = 1000", "steps = 200")
            .replace("series = { every = 50 }", "series = { every = 20 }")
            .replace("snapshots = { every = 500 }", "snapshots = { every = 200 }");
    let levels = same_bits_at_every_level(
        &scene,
        &[],
        &[
            "series.csv",
            "snapshots/fluid_000000200.csv",
            "snapshots/particles_000000200.csv",
            "snapshots/contacts_000000200.csv",
        ],
    );
    levels_differ_unless_native(&levels);
}

/// The liquid alone (the `lbdem-lbm` steppers): a periodic channel under a body force, past a
/// cylinder, below a sliding lid, for each stepper and precision and both lattices. 67 nodes a
/// row: full blocks at every copy's width (32 or 16 nodes where the copy has 256-bit vectors, 8
/// or 4 in the portable one, `lbm::kernel::block_width`) and every narrower tail; the cylinder
/// and the walls take the general nodes. The portable copy runs narrower blocks than the others,
/// so this is what shows the width changes no bit.
#[test]
fn the_liquid_gives_the_same_bits_at_every_level() {
    for (stencil, precision, kernel, collision, hi, centre) in [
        ("D2Q9", "f32", "aa", "bgk", "[3.35e-3, 1.0e-3]", "[1e-3, 5e-4]"),
        (
            "D2Q9",
            "f64",
            "two-array",
            "trt",
            "[3.35e-3, 1.0e-3]",
            "[1e-3, 5e-4]",
        ),
        (
            "D3Q19",
            "f64",
            "aa",
            "trt",
            "[3.35e-3, 3.5e-4, 3.5e-4]",
            "[1e-3, 1.75e-4, 1.75e-4]",
        ),
    ] {
        let periodic = if stencil == "D2Q9" {
            "[true, false]"
        } else {
            "[true, false, true]"
        };
        let lid = if stencil == "D2Q9" {
            "[0.01, 0.0]"
        } else {
            "[0.01, 0.0, 0.0]"
        };
        let force = if stencil == "D2Q9" {
            "[0.02, 0.0]"
        } else {
            "[0.02, 0.0, 0.0]"
        };
        let scene = format!(
            r#"
[lattice]
stencil = "{stencil}"
precision = "{precision}"
kernel = "{kernel}"
collision = "{collision}"
dx = 5e-5
tau = 0.9
[domain]
lo = [0.0, 0.0{z}]
hi = {hi}
periodic = {periodic}
[fluid]
density = 1000.0
viscosity = 1e-6
u_max = 0.015
[forcing]
acceleration = {force}
[boundaries]
y_max = {{ type = "wall", velocity = {lid} }}
[[obstacles]]
shape = "{shape}"
centre = {centre}
radius = 1.2e-4
[run]
steps = 40
[output]
series = {{ every = 10 }}
snapshots = {{ every = 40 }}
"#,
            z = if stencil == "D2Q9" { "" } else { ", 0.0" },
            shape = if stencil == "D2Q9" { "circle" } else { "sphere" },
        );
        let levels = same_bits_at_every_level(&scene, &[], &["series.csv", "snapshots/fluid_000000040.csv"]);
        levels_differ_unless_native(&levels);
    }
}
