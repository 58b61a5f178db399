//! The layers of `src/` import only downwards (docs/architecture.md): contract ← report/io ←
//! scenes ← stages ← registry ← pipeline ← cli. A file that imports a layer above its own
//! would start an import loop; this test reads every source file and names any such import.

use std::path::{Path, PathBuf};

/// Layers from the bottom; a module may import its own layer and those below it.
const LAYERS: &[&[&str]] = &[
    &["contract"],
    &["io", "report"],
    &["scenes"],
    &["stages"],
    &["registry"],
    &["pipeline"],
    &["sweep"],
    &["bench", "cli"],
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|l| l.contains(&module))
}

fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.extend(rust_files(&p));
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
    out
}

/// `crate::<module>` references in `text` outside comments.
fn crate_refs(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or("");
        let mut rest = code;
        while let Some(i) = rest.find("crate::") {
            let tail = &rest[i + 7..];
            let name: String = tail
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            out.push(name);
            rest = &tail[1.min(tail.len())..];
        }
    }
    out
}

#[test]
fn src_layers_import_only_downwards() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut bad = Vec::new();
    let mut checked = 0;
    for f in rust_files(&src) {
        let rel = f.strip_prefix(&src).unwrap();
        let top = rel.components().next().unwrap().as_os_str().to_string_lossy();
        let module = top.trim_end_matches(".rs");
        let Some(own) = layer_of(module) else { continue };
        let text = std::fs::read_to_string(&f).unwrap();
        // Tests of a module may drive it through the runner; only the module's code counts.
        let code = text.split("#[cfg(test)]").next().unwrap_or("");
        let is_test_file = rel.components().any(|c| c.as_os_str() == "tests")
            || rel.file_stem().is_some_and(|s| s == "tests");
        if is_test_file {
            continue;
        }
        checked += 1;
        for r in crate_refs(code) {
            if let Some(l) = layer_of(&r)
                && l > own
            {
                bad.push(format!(
                    "{} imports crate::{r} (a layer above {module})",
                    rel.display()
                ));
            }
        }
    }
    assert!(checked > 40, "only {checked} files checked");
    assert!(bad.is_empty(), "imports against the layers:\n{}", bad.join("\n"));
}

#[test]
fn the_contract_imports_nothing_from_the_crate() {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/contract.rs")).unwrap();
    assert!(crate_refs(&text).is_empty(), "{:?}", crate_refs(&text));
}

#[test]
fn layer_check_sees_a_bad_import() {
    // The detector itself: a stage calling the runner is caught.
    let refs = crate_refs("use crate::pipeline::execute; // crate::cli in a comment");
    assert_eq!(refs, vec!["pipeline".to_string()]);
    assert!(layer_of("pipeline") > layer_of("stages"));
}

#[test]
fn engine_kernels_import_nothing_from_their_steppers() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates");
    let kernels = [
        "dem/src/pair_batched.rs",
        "dem/src/kick_disks.rs",
        "dem/src/scratch.rs",
        "lbm/src/kernel.rs",
        "lbm/src/kernel_aa.rs",
        "lbm/src/collision.rs",
    ];
    for k in kernels {
        let text = std::fs::read_to_string(root.join(k)).unwrap();
        let refs = crate_refs(&text);
        assert!(
            !refs.iter().any(|r| r == "stepper" || r == "stepper_aa"),
            "{k} imports its stepper: {refs:?}"
        );
    }
}

#[test]
fn engine_crates_do_no_file_io() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("crates");
    for krate in ["dem", "lbm", "coupling", "imaging", "grains", "analysis"] {
        for f in rust_files(&root.join(krate).join("src")) {
            let text = std::fs::read_to_string(&f).unwrap();
            for bad in ["std::fs::", "File::open", "File::create"] {
                assert!(!text.contains(bad), "{} uses {bad}", f.display());
            }
        }
    }
}
