//! `LBDEM_ISA` (crates/core/src/simd.rs): a value naming no level is refused before anything
//! runs, with the variable, the value and the accepted values; a valid cap is taken and printed (a native build warns that it has no effect).

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
