//! Scene-level tests, through the runner as `lbdem simulate` runs them: the physics of each
//! kind of scene points the right way or matches its analytic answer, bad set-ups are refused
//! before anything is written, a failed run publishes nothing (its series kept to look at), and
//! an interrupted run resumes to the same bits.

use crate::contract::{StageContext, StageRecord};
use std::path::{Path, PathBuf};

/// Run `text` as a scene file in `dir/scene` with output in `dir/out`.
fn simulate(text: &str, dir: &Path, resume: bool) -> anyhow::Result<StageRecord> {
    simulate_to(text, dir, &dir.join("out"), resume)
}

fn simulate_to(text: &str, dir: &Path, out: &Path, resume: bool) -> anyhow::Result<StageRecord> {
    let src = dir.join("scene");
    std::fs::create_dir_all(&src)?;
    std::fs::write(src.join("scene.toml"), text)?;
    let kind = crate::registry::find("simulate")?;
    let mut ctx = StageContext::new(out.to_path_buf(), "simulate".into(), src);
    ctx.resume = resume;
    let params: toml::Value = toml::from_str("scene = \"scene.toml\"")?;
    let prepared = kind.prepare(params, &ctx)?;
    crate::pipeline::execute(prepared, &ctx)
}

/// Run `text` (which sets a `[run] wall_clock` limit) again and again, resuming, until it
/// finishes; every stop must be an interruption that kept its checkpoint. Returns how many
/// interruptions there were (at least one, or the test proves nothing).
fn resume_until_done(text: &str, dir: &Path, max: usize) -> usize {
    let mut resume = false;
    let mut interruptions = 0;
    while let Err(e) = simulate(text, dir, resume) {
        let msg = format!("{e:#}");
        assert!(msg.contains("--resume"), "{msg}");
        assert!(
            dir.join("out/.partial/checkpoint.json").is_file(),
            "no checkpoint kept: {msg}"
        );
        interruptions += 1;
        resume = true;
        assert!(interruptions < max, "never finished");
    }
    assert!(
        interruptions >= 1,
        "the wall-clock limit never interrupted the run"
    );
    interruptions
}

/// Every file under `dir`.
fn walk(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    if let Ok(rd) = std::fs::read_dir(dir) {
        for e in rd.flatten() {
            if e.path().is_dir() {
                out.extend(walk(&e.path()));
            } else {
                out.push(e.path());
            }
        }
    }
    out
}

fn shipped(name: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(name)).unwrap()
}

mod bad_input;
mod coupled;
mod dry;
mod extruder;
mod float;
mod fluid;
mod incline;
mod initial;
mod initial_fluid;
mod minimal;
mod schema;
mod shear_cell;
