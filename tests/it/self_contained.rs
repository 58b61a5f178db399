//! Nothing in the repository points outside it (issue 17): a fresh clone's docs, comments,
//! tests and scripts must work without the development machine's `shared/` directory.

use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, out);
        } else if p.extension().is_some_and(|x| {
            ["rs", "md", "toml", "sh", "py", "in", "csv", "json", "txt", "html"]
                .contains(&x.to_str().unwrap_or(""))
        }) {
            out.push(p);
        }
    }
}

#[test]
fn no_file_names_a_path_outside_the_repository() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut all = vec![
        root.join("README.md"),
        root.join("Cargo.toml"),
        root.join(".ci/run"),
    ];
    for d in [
        "src",
        "crates",
        "tests",
        "docs",
        "scripts",
        "scenes",
        "pipelines",
        "sweeps",
        "data",
        "reports",
    ] {
        files(&root.join(d), &mut all);
    }
    assert!(all.len() > 100, "{}", all.len());
    // Split so that this file does not match itself.
    // A machine's scratch directory is not the repository either: examples use runs/ or
    // target/, code uses std::env::temp_dir().
    let needles = [
        concat!("/wo", "rk/"),
        concat!("../sha", "red"),
        concat!("sha", "red/data"),
        concat!("/tm", "p/"),
    ];
    let mut bad = Vec::new();
    for f in &all {
        let text = std::fs::read_to_string(f).unwrap_or_default();
        for (n, line) in text.lines().enumerate() {
            if needles.iter().any(|k| line.contains(k)) {
                bad.push(format!("{}:{}: {line}", f.display(), n + 1));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "paths outside the repository:\n{}",
        bad.join("\n")
    );
}

/// Every ignored test is a slow validation that `scripts/validate-all.sh` runs (or an
/// exploration it names as such), so the docs' slow figures are reproducible from one command.
#[test]
fn every_ignored_test_is_listed_in_the_validation_script() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let script = std::fs::read_to_string(root.join("scripts/validate-all.sh")).unwrap();
    let mut all = Vec::new();
    for d in ["src", "crates", "tests"] {
        files(&root.join(d), &mut all);
    }
    let mut ignored = Vec::new();
    for f in all.iter().filter(|f| f.extension().is_some_and(|x| x == "rs")) {
        let text = std::fs::read_to_string(f).unwrap_or_default();
        let lines: Vec<&str> = text.lines().collect();
        for (n, line) in lines.iter().enumerate() {
            if !line.trim_start().starts_with(concat!("#[ig", "nore")) {
                continue;
            }
            // The function the attribute belongs to: the next `fn` line.
            let name = lines[n + 1..]
                .iter()
                .find_map(|l| l.trim_start().strip_prefix("fn "))
                .and_then(|l| l.split('(').next())
                .unwrap_or_else(|| panic!("{}:{}: no fn after the attribute", f.display(), n + 1));
            ignored.push((f.display().to_string(), name.to_string()));
        }
    }
    assert!(ignored.len() >= 10, "found only {ignored:?}");
    let missing: Vec<_> = ignored
        .iter()
        .filter(|(_, name)| !script.contains(&format!("|{name}|")) && !script.contains(&format!("|{name}'")))
        .collect();
    assert!(
        missing.is_empty(),
        "ignored tests not in scripts/validate-all.sh (add a line: crate|file|name|figure|reference|tolerance): {missing:?}"
    );
}

/// The scripts the docs quote must at least parse: an unescaped apostrophe in the validation
/// table (`liquid's` inside a single-quoted string) once broke `validate-all.sh` for every use,
/// `--help` included, and no test noticed. `--list` reads the whole table without running it.
#[test]
fn the_scripts_parse_and_the_validation_table_lists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut scripts: Vec<PathBuf> = std::fs::read_dir(root.join("scripts"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "sh"))
        .collect();
    scripts.push(root.join(".ci/run"));
    assert!(scripts.len() >= 5, "found only {scripts:?}");
    for s in &scripts {
        let o = std::process::Command::new("bash")
            .arg("-n")
            .arg(s)
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "{}: {}",
            s.display(),
            String::from_utf8_lossy(&o.stderr)
        );
    }
    let o = std::process::Command::new("bash")
        .arg(root.join("scripts/validate-all.sh"))
        .arg("--list")
        .output()
        .unwrap();
    assert!(
        o.status.success(),
        "validate-all.sh --list: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    let table = String::from_utf8_lossy(&o.stdout);
    for id in [
        "lbdem-lbm/cavity/re1000_matches_ghia",
        "lbdem/sweep_cli/mass_scaling_by_a_hundred",
    ] {
        assert!(
            table.contains(id),
            "validate-all.sh --list does not list {id}:\n{table}"
        );
    }
}
