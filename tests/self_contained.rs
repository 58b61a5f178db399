//! Nothing in the repository points outside it (issue 17): a fresh clone's docs, comments,
//! tests and scripts must work without the development machine's `shared/` directory.

use std::path::{Path, PathBuf};

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, out);
        } else if p
            .extension()
            .is_some_and(|x| ["rs", "md", "toml", "sh", "py", "in"].contains(&x.to_str().unwrap_or("")))
        {
            out.push(p);
        }
    }
}

#[test]
fn no_file_names_a_path_outside_the_repository() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut all = vec![root.join("README.md"), root.join("Cargo.toml")];
    for d in [
        "src",
        "crates",
        "tests",
        "docs",
        "scripts",
        "scenes",
        "pipelines",
        "data/synth-alcu",
    ] {
        files(&root.join(d), &mut all);
    }
    assert!(all.len() > 100, "{}", all.len());
    // Split so that this file does not match itself.
    let needles = [
        concat!("/wo", "rk/"),
        concat!("../sha", "red"),
        concat!("sha", "red/data"),
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
