//! Stages side by side (`lbdem run --lanes N`): a pipeline's stages form a graph through the
//! names and directories their parameters give (an analysis names its run, a report every stage
//! before it), and a stage starts once every stage it reads has finished, at most N at a time,
//! each in a rayon pool of its share of the cores. A pipeline of long independent runs (the Su
//! 2020 matrix: fourteen simulations, then their analyses) takes the longest lane's time
//! instead of the sum. Each stage's outputs are those of a run one after another: its pool is
//! its own, every kernel gives the same bits on any thread count, and a stage sees only
//! finished stages' files.

use super::schema::StageSpec;
use crate::contract::StageContext;
use std::path::Path;

/// The earlier stages stage `i` reads: those its parameters name (a string equal to the name,
/// `@name` or `@name/...`, or a path inside the stage's output directory), and for a `report`
/// every earlier stage (its default shows them all). A string that only happens to equal a name
/// (a label) adds an edge that is not needed: the stage waits longer, nothing runs early.
pub fn dependencies(specs: &[&StageSpec], ctxs: &[&StageContext], i: usize) -> Vec<usize> {
    if specs[i].kind == "report" {
        return (0..i).collect();
    }
    let mut strings = Vec::new();
    collect_strings(&specs[i].params, &mut strings);
    (0..i)
        .filter(|&j| {
            let name = specs[j].name.as_str();
            let dir = &ctxs[j].out_dir;
            strings.iter().any(|s| {
                s == name
                    || s.strip_prefix('@')
                        .is_some_and(|r| r == name || r.starts_with(&format!("{name}/")))
                    || under(&ctxs[i].resolve(Path::new(s)), dir)
            })
        })
        .collect()
}

/// Whether `p` lies in `dir` (or is it), compared without touching the disk (neither need
/// exist yet).
fn under(p: &Path, dir: &Path) -> bool {
    let norm = |p: &Path| -> std::path::PathBuf {
        let mut out = std::path::PathBuf::new();
        for c in p.components() {
            match c {
                std::path::Component::ParentDir => {
                    out.pop();
                }
                std::path::Component::CurDir => {}
                c => out.push(c),
            }
        }
        out
    };
    norm(p).starts_with(norm(dir))
}

fn collect_strings(v: &toml::Value, out: &mut Vec<String>) {
    match v {
        toml::Value::String(s) => out.push(s.clone()),
        toml::Value::Array(a) => a.iter().for_each(|x| collect_strings(x, out)),
        toml::Value::Table(t) => t.values().for_each(|x| collect_strings(x, out)),
        _ => {}
    }
}
