//! Scene files of the earlier format (one scene kind per file) are refused with the steps that
//! convert them, instead of a list of unknown keys.

use anyhow::{Result, bail};
use std::path::Path;

/// Each mark of the old format and how to convert it.
const MARKS: &[(&str, Option<&str>, &str)] = &[
    (
        "scene",
        Some("kind"),
        "remove [scene] kind: what a scene simulates follows from its sections",
    ),
    (
        "step",
        None,
        "rename [step] to [dem] and write gravity = [x, y] instead of { x = .., y = .. }",
    ),
    (
        "stop",
        None,
        "move [stop] steps / time into [run], and steady_tol into [run] until_steady",
    ),
    (
        "domain",
        Some("size"),
        "replace [domain] size = [X, Y] by lo = [0.0, 0.0] and hi = [X, Y]; faces that were periodic by default need periodic = [true, ...]",
    ),
    (
        "run",
        Some("output_every"),
        "replace [run] output_every = N by [output] series = { every = N }",
    ),
    (
        "run",
        Some("snapshot_every"),
        "replace [run] snapshot_every = N by [output] snapshots = { every = N }",
    ),
    (
        "run",
        Some("checkpoint_every"),
        "replace [run] checkpoint_every = N by [output] checkpoints = { every = N }",
    ),
    (
        "run",
        Some("stop_when_slower_than"),
        "rename [run] stop_when_slower_than to until_slower_than",
    ),
    (
        "run",
        Some("compress"),
        "move [run] compress = { ... } into its own [compress] section",
    ),
    (
        "run",
        Some("pressure_threshold"),
        "move [run] pressure_threshold into [output]",
    ),
    (
        "output",
        Some("samples"),
        "replace [output] samples = N by series = { count = N }",
    ),
    ("lattice", Some("threads"), "move [lattice] threads into [run]"),
    (
        "coupling",
        Some("trt_magic"),
        "replace [coupling] trt_magic = M by [lattice] collision = \"trt\", magic = M",
    ),
];

pub fn refuse_old_format(v: &toml::Table, path: &Path) -> Result<()> {
    let mut found = Vec::new();
    for (section, key, how) in MARKS {
        let Some(s) = v.get(*section) else { continue };
        let hit = match key {
            None => true,
            Some(k) => s.get(k).is_some(),
        };
        if hit {
            found.push(format!("  - {how}"));
        }
    }
    if let Some(snap) = v.get("output").and_then(|o| o.get("snapshots"))
        && snap.is_integer()
    {
        found.push("  - replace [output] snapshots = N by snapshots = { count = N }".into());
    }
    if !found.is_empty() {
        bail!(
            "scene file {} is in the earlier format (one scene kind per file); convert it:\n{}\n(see docs/scenes.md)",
            path.display(),
            found.join("\n")
        );
    }
    Ok(())
}
