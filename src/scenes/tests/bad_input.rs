//! Every class of bad scene input is refused before anything runs, with the file, the line or
//! key, the value, the limit and the fix, and nothing is left behind (issue 17): sign, range,
//! finiteness, vector length, units, position inside the domain, cross-field consistency, and
//! the particle file's rows (whole grain ids, finite positions, no coincident grains).

use super::*;

/// Run `text` (a scene, with `grains.csv` beside it if given) through the runner; the error
/// message, after checking that the output directory was not created.
fn refused(text: &str, csv: Option<&str>) -> String {
    let t = tempfile::tempdir().unwrap();
    if let Some(c) = csv {
        std::fs::create_dir_all(t.path().join("scene")).unwrap();
        std::fs::write(t.path().join("scene/grains.csv"), c).unwrap();
    }
    let e = simulate(text, t.path(), false).expect_err("bad input must be refused");
    let out = t.path().join("out");
    assert!(
        !out.exists(),
        "a refused scene must leave nothing behind, found {:?}",
        std::fs::read_dir(&out).map(|d| d.flatten().map(|e| e.path()).collect::<Vec<_>>())
    );
    format!("{e:#}")
}

fn contains_all(msg: &str, needles: &[&str]) {
    for n in needles {
        assert!(msg.contains(n), "the message should contain {n:?}: {msg}");
    }
}

/// The dry scene of `dry.rs` with `from` replaced by `to` (which must occur).
fn dry_with(from: &str, to: &str) -> String {
    assert!(super::dry::SCENE.contains(from), "{from}");
    super::dry::SCENE.replacen(from, to, 1)
}

/// "line N" of the first line of the dry scene that holds `needle`.
fn line(needle: &str) -> String {
    let n = super::dry::SCENE
        .lines()
        .position(|l| l.contains(needle))
        .unwrap();
    format!("scene.toml line {}", n + 1)
}

#[test]
fn sign_negative_friction_stiffness_and_damping_are_refused_with_line_and_limit() {
    let m = refused(&dry_with("mu = 0.5", "mu = -0.5"), None);
    contains_all(
        &m,
        &[
            &line("mu = 0.5"),
            "[contact] mu = -0.5",
            "must not be negative",
            "friction",
        ],
    );
    let m = refused(&dry_with("k_n = 1000.0", "k_n = -1000.0"), None);
    contains_all(
        &m,
        &[
            &line("k_n ="),
            "[contact] k_n = -1000.0",
            "must be above 0",
            "N/m",
        ],
    );
    let m = refused(&dry_with("ratio = 0.3", "ratio = -0.3"), None);
    contains_all(
        &m,
        &[&line("ratio"), "damping.ratio = -0.3", "must not be negative"],
    );
    let m = refused(&dry_with("dt = 4.0e-6", "dt = -4.0e-6"), None);
    contains_all(&m, &[&line("dt ="), "[dem] dt = -4e-6", "must be above 0"]);
    assert!(
        !m.contains("critical"),
        "a negative dt is not 'above the critical step': {m}"
    );
}

#[test]
fn range_fractions_and_ratios_outside_their_interval_are_refused() {
    let m = refused(
        &dry_with("density = 2.6", "density = 2.6\narea_factor = 1.5"),
        None,
    );
    contains_all(&m, &["[particles] area_factor = 1.5", "must lie in (0, 1]"]);
    let m = refused(
        &dry_with(
            "gravity = [0.0, -9.81]",
            "gravity = [0.0, -9.81]\nlocal_damping = 1.0",
        ),
        None,
    );
    contains_all(&m, &["[dem] local_damping = 1.0", "must lie in [0, 1)"]);
}

#[test]
fn finiteness_nan_anywhere_is_named_as_itself_not_as_a_time_step_problem() {
    let m = refused(&dry_with("gravity = [0.0, -9.81]", "gravity = [0.0, nan]"), None);
    contains_all(&m, &[&line("gravity"), "[dem] gravity[1] = NaN", "finite"]);
    assert!(!m.contains("lower dt"), "{m}");
    let m = refused(&dry_with("dt = 4.0e-6", "dt = nan"), None);
    contains_all(&m, &["[dem] dt = NaN", "finite"]);
    assert!(!m.contains("critical"), "{m}");
    let m = refused(&dry_with("k_t = 500.0", "k_t = inf"), None);
    contains_all(&m, &["[contact] k_t = inf", "finite"]);
}

#[test]
fn unknown_keys_inside_inline_tables_and_extra_vector_entries_are_refused() {
    let m = refused(&dry_with("mu_r = 0.1", "mu_r = 0.1, extra = 3.0"), None);
    contains_all(&m, &["scene.toml", "extra"]);
    let m = refused(
        &dry_with("gravity = [0.0, -9.81]", "gravity = [0.0, -9.81, 0.0]"),
        None,
    );
    contains_all(
        &m,
        &[
            &line("gravity"),
            "[dem] gravity has 3 numbers",
            "array of 2 numbers",
        ],
    );
}

#[test]
fn overrides_are_checked_like_the_file_and_named_as_overrides() {
    let t = tempfile::tempdir().unwrap();
    let p = t.path().join("s.toml");
    std::fs::write(&p, super::dry::SCENE).unwrap();
    let over: toml::Table = toml::from_str("contact = { mu = -1.0 }").unwrap();
    let m = format!("{:#}", crate::scenes::schema::load(&p, &over).unwrap_err());
    contains_all(&m, &["overridden", "[contact] mu = -1.0", "must not be negative"]);
}

/// The dry scene reading its grains from `grains.csv` instead of generating them.
fn csv_scene() -> String {
    let s = super::dry::SCENE;
    let a = s.find("[particles.generate]").unwrap();
    let b = s.find("[[walls]]").unwrap();
    format!("{}csv = \"grains.csv\"\n{}", &s[..a], &s[b..])
}

const GOOD: &str = "grain_id,x,y,r\n0,0.004,0.005,3e-4\n0,0.0043,0.005,2.5e-4\n1,0.006,0.005,3e-4\n";

#[test]
fn the_csv_scene_of_these_tests_runs_when_its_file_is_good() {
    let t = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(t.path().join("scene")).unwrap();
    std::fs::write(t.path().join("scene/grains.csv"), GOOD).unwrap();
    let text = csv_scene().replace("steps = 3000", "steps = 10");
    let r = simulate(&text, t.path(), false).unwrap();
    assert_eq!(r.output.summary["steps"], 10);
}

#[test]
fn position_a_grain_outside_the_domain_is_refused_with_its_line() {
    let csv = GOOD.replace("1,0.006,0.005", "1,5.006,0.005");
    let m = refused(&csv_scene(), Some(&csv));
    contains_all(
        &m,
        &[
            "grains.csv line 4",
            "(5.006, 0.005)",
            "outside the [domain] box",
            "units",
        ],
    );
}

#[test]
fn units_a_radius_larger_than_the_box_names_the_units() {
    // A file in micrometres read as metres: every value 1e6 too large would also be outside;
    // a radius in mm with centres in m is caught by its size.
    let csv = GOOD.replace("1,0.006,0.005,3e-4", "1,0.006,0.005,0.3");
    let m = refused(&csv_scene(), Some(&csv));
    contains_all(&m, &["grains.csv line 4", "r = 0.3 m", "other units"]);
}

#[test]
fn particle_rows_fractional_ids_nan_positions_and_coincident_grains_are_refused() {
    let m = refused(&csv_scene(), Some(&GOOD.replace("1,0.006", "0.5,0.006")));
    contains_all(&m, &["grains.csv line 4", "grain_id = 0.5", "whole number"]);
    let m = refused(&csv_scene(), Some(&GOOD.replace("1,0.006", "1,NaN")));
    contains_all(&m, &["grains.csv line 4", "x = NaN", "finite"]);
    let m = refused(
        &csv_scene(),
        Some(&GOOD.replace("1,0.006,0.005", "1,0.004,0.005")),
    );
    contains_all(&m, &["grains.csv lines 2 and 4", "grains 0 and 1", "same centre"]);
}

#[test]
fn cross_field_a_generation_box_outside_the_domain_or_inverted_is_refused() {
    let m = refused(
        &dry_with("hi = [0.01, 0.01]\nseed", "hi = [0.02, 0.01]\nseed"),
        None,
    );
    contains_all(
        &m,
        &["[particles.generate]", "hi = [0.02, 0.01]", "inside [domain]"],
    );
    let m = refused(
        &dry_with(
            "lo = [0.0, 0.0]\nhi = [0.01, 0.01]\nseed",
            "lo = [0.01, 0.0]\nhi = [0.0, 0.01]\nseed",
        ),
        None,
    );
    contains_all(&m, &["[particles.generate]", "lo", "below hi"]);
}

#[test]
fn a_trigger_of_zero_steps_is_refused_not_a_division_by_zero() {
    let m = refused(
        &dry_with("series = { every = 100 }", "series = { every = 0 }"),
        None,
    );
    contains_all(&m, &["[output] series", "at least 1"]);
}

#[test]
fn every_shipped_scene_passes_the_value_checks() {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(dir).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(&p, out);
            } else if p.extension().is_some_and(|x| x == "toml") {
                out.push(p);
            }
        }
    }
    let mut files = Vec::new();
    walk(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes"), &mut files);
    assert!(files.len() >= 30, "{}", files.len());
    let mut loaded = 0;
    // Bases that other scenes extend are not scenes by themselves.
    let bases: Vec<String> = files
        .iter()
        .filter_map(|p| {
            let t: toml::Table = toml::from_str(&std::fs::read_to_string(p).ok()?).ok()?;
            Some(t.get("scene")?.get("extends")?.as_str()?.to_string())
        })
        .collect();
    for p in files {
        // Bases, and the assembly recipes of scenes/su2020/assemblies/ (parameters of the
        // `assemble` stage, not scenes).
        if bases.iter().any(|b| p.ends_with(b)) || p.components().any(|c| c.as_os_str() == "assemblies") {
            continue;
        }
        match crate::scenes::schema::load(&p, &Default::default()) {
            Ok(_) => loaded += 1,
            Err(e) => panic!("{}: {e:#}", p.display()),
        }
    }
    // 26 on 2026-11-24 (scenes/ and scenes/su2020/ less the files others extend).
    assert!(loaded >= 26, "only {loaded} scenes loaded");
}

/// The windowed stop (`until_slower_than = { speed, over }`): a window that is not positive, a
/// missing key or an unknown one is refused by name before anything runs.
#[test]
fn a_stop_window_of_zero_or_a_malformed_one_is_refused() {
    let with = |v: &str| dry_with("steps = 3000", &format!("steps = 3000\nuntil_slower_than = {v}"));
    let m = refused(&with("{ speed = 1.0e-7, over = 0.0 }"), None);
    contains_all(&m, &["until_slower_than.over = 0.0", "must be above 0"]);
    let m = refused(&with("{ speed = -1.0e-7, over = 10.0 }"), None);
    contains_all(&m, &["until_slower_than.speed = -1e-7", "must be above 0"]);
    for bad in ["{ speed = 1.0e-7 }", "{ speed = 1.0e-7, over = 10.0, extra = 1 }"] {
        let m = refused(&with(bad), None);
        contains_all(&m, &["until_slower_than", "over = 10.0"]);
    }
}
