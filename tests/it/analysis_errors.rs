//! The analysis stages refuse bad input with a message that names the problem and the fix, and a
//! refused stage leaves no output directory behind.

use crate::common;
use common::run;
use std::path::{Path, PathBuf};

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn params(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

/// Run `kind` (a subcommand path) on `text`; assert it fails, that stderr holds every `needle`
/// and that the output directory was not left behind.
fn refused(dir: &Path, kind: &[&str], text: &str, needles: &[&str]) {
    let p = params(dir, "p.toml", text);
    let out = dir.join(format!("out-{}", kind.join("-")));
    let mut args: Vec<&str> = kind.to_vec();
    let o = out.display().to_string();
    args.extend([p.as_str(), "--out", o.as_str()]);
    let (ok, err) = run(&args);
    assert!(!ok, "{kind:?} should have failed");
    for n in needles {
        assert!(err.contains(n), "{kind:?}: '{n}' missing from:\n{err}");
    }
    assert!(!out.exists(), "{kind:?} left {} behind", out.display());
}

#[test]
fn analysis_stages_refuse_bad_input_and_leave_nothing() {
    let t = tempfile::tempdir().unwrap();
    let d = t.path();
    // Not a run at all.
    let empty = d.join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    refused(
        d,
        &["analyse"],
        &format!("run = \"{}\"\n", empty.display()),
        &["is not a finished run", "stage.json", "lbdem simulate"],
    );
    // A radiograph stage's output given where a run is expected, and the radiograph for compare.
    let rg = d.join("rg");
    let rp = params(
        d,
        "rg.toml",
        &format!(
            "frames = [\"{0}/data/synth-alcu/frame_000.tif\", \"{0}/data/synth-alcu/frame_001.tif\"]\n\
             i_s0_roi = [16, 8, 480, 32]\ni_l0_roi = [16, 472, 480, 32]\nmu_s = 2147.85\nmu_l = 10120.559\n\
             l_alloy0 = 150e-6\nd_bar = 180e-6\npixel_size = 6e-6\nplots = false\n",
            repo().display()
        ),
    );
    let (ok, err) = run(&["radiograph", &rp, "--out", rg.to_str().unwrap()]);
    assert!(ok, "{err}");
    refused(
        d,
        &["synth", "run"],
        &format!("run = \"{}\"\n", rg.display()),
        &["written by a 'radiograph' stage, not by 'simulate'"],
    );
    // compare: the run is checked first, then the alignment.
    refused(
        d,
        &["compare"],
        &format!(
            "radiograph = \"{}\"\nrun = \"{}\"\n",
            rg.display(),
            empty.display()
        ),
        &["is not a finished run"],
    );
    refused(
        d,
        &["compare"],
        &format!(
            "radiograph = \"{}\"\nrun = \"{}\"\n",
            empty.display(),
            rg.display()
        ),
        &["is not a finished radiograph stage", "lbdem radiograph"],
    );
    // Grids and maps.
    refused(
        d,
        &["matrix"],
        "title = \"t\"\nfield = \"eps_vol\"\nrows = [\"a\", \"b\"]\ncols = [\"c\"]\nanalyses = [\"x\"]\n",
        &["1 analyses for 2 rows x 1 columns", "row by row"],
    );
    refused(
        d,
        &["mechanism-map"],
        "paper = false\n",
        &["nothing to draw", "analyses"],
    );
    refused(
        d,
        &["mechanism-map"],
        "rate_range = [0.0, 100.0]\n",
        &["rate_range", "positive lowest rate"],
    );
    // A misspelt key is named (the strain options are flattened into the stage's keys).
    refused(
        d,
        &["analyse"],
        &format!("run = \"{}\"\nmax_edg_d = 3.0\n", empty.display()),
        &["unknown field `max_edg_d`"],
    );
}
