//! Tests of the sweep: the file's refusals, how cases expand, result extraction, and whole
//! sweeps of a small dry scene (reruns, a changed axis, a failing case, thread counts).

use super::cases::{expand, scene_overrides, set_path};
use super::results::{crossing, reduce, summary_value};
use super::schema::{Reduce, Sweep};
use super::*;
use std::path::Path;

/// 40 two-circle grains settling in a box under a named lid (2000 DEM steps: milliseconds).
const SCENE: &str = r#"
[domain]
lo = [0.0, 0.0]
hi = [0.01, 0.01]
[particles]
density = 2.6
[particles.generate]
count = 40
lo = [0.0, 0.0]
hi = [0.01, 0.006]
seed = 5
templates = [ { circles = [[0.0, 0.0, 3.0e-4], [2.5e-4, 0.0, 2.5e-4]] } ]
[[walls]]
box = [0.0, 0.0, 0.01, 0.01]
[[walls]]
name = "lid"
a = [0.0, 0.009]
b = [0.01, 0.009]
[contact]
law = "linear"
k_n = 1000.0
k_t = 500.0
damping = { ratio = 0.3 }
mu = 0.5
[dem]
dt = 4.0e-6
skin = 5.0e-5
gravity = [0.0, -9.81]
[run]
steps = 2000
[output]
series = { every = 100 }
snapshots = { count = 1 }
checkpoints = { never = true }
"#;

const RESULTS: &str = r#"
[[result]]
name = "ke"
column = "kinetic_energy"
unit = "J"
[[result]]
name = "ke_max"
column = "kinetic_energy"
reduce = "max"
[[result]]
name = "ke_at"
column = "kinetic_energy"
at = { column = "time", value = 0.004 }
[[result]]
name = "pf"
summary = "last.packing_fraction"
"#;

/// A directory holding `scene.toml` and `sweep.toml` (the sweep written as given).
fn setup(sweep: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let t = tempfile::tempdir().unwrap();
    std::fs::write(t.path().join("scene.toml"), SCENE).unwrap();
    let f = t.path().join("sweep.toml");
    std::fs::write(&f, sweep).unwrap();
    (t, f)
}

fn args(file: &Path, out: &Path, parallel: usize, threads: usize) -> Args {
    Args {
        file: file.to_path_buf(),
        out: Some(out.to_path_buf()),
        parallel: Some(parallel),
        threads: Some(threads),
        ..Default::default()
    }
}

fn refusal(text: &str) -> String {
    format!("{:#}", Sweep::parse(text, Path::new("s.toml")).unwrap_err())
}

#[test]
fn the_sweep_file_refuses_what_cannot_work_and_says_why() {
    let head = "[sweep]\nscene = \"scene.toml\"\n";
    let cases: &[(&str, &[&str])] = &[
        ("[sweep]\nname = \"x\"\n", &["exactly one of scene", "pipeline"]),
        ("[sweep]\nscene = \"a\"\npipeline = \"b\"\n", &["exactly one"]),
        ("[sweep]\nscene = \"a\"\nscen = 1\n", &["unknown field", "scen"]),
        (
            &format!("{head}[[axis]]\nname = \"a\"\nvalues = [1, 2]\n"),
            &["changes nothing"],
        ),
        (
            &format!("{head}[[axis]]\nname = \"a\"\nkey = \"dem.dt\"\n"),
            &["exactly one of values", "range"],
        ),
        (
            &format!("{head}[[axis]]\nname = \"a\"\nkey = \"dem.dt\"\nvalues = []\n"),
            &["values is empty"],
        ),
        (
            &format!("{head}[[axis]]\nname = \"a\"\nkey = \"x\"\nvalues = [1, 2]\nzip = {{ \"y\" = [1] }}\n"),
            &["zip \"y\" needs a list of 2 values"],
        ),
        (
            &format!(
                "{head}[[axis]]\nname = \"a\"\nkey = \"x\"\nvalues = [1]\n[[axis]]\nname = \"a\"\nkey = \"y\"\nvalues = [1]\n"
            ),
            &["two axes are named 'a'"],
        ),
        (
            &format!("{head}[[axis]]\nname = \"case\"\nkey = \"x\"\nvalues = [1, 2]\n"),
            &[
                "'case': the name is a column every results table has",
                "rename the axis",
            ],
        ),
        (
            "[sweep]\nscene = \"pk{pk}.toml\"\n",
            &["holds {pk}", "no [[axis]] is named 'pk'"],
        ),
        (
            &format!(
                "{head}[[axis]]\nname = \"a\"\nkey = \"x\"\nrange = {{ from = 0.0, to = 1.0, count = 3, log = true }}\n"
            ),
            &["log = true needs from and to above 0"],
        ),
        (
            &format!("{head}[replicas]\ncount = 0\nkey = \"s\"\n"),
            &["count = 0"],
        ),
        (
            &format!("{head}[[result]]\nname = \"r\"\n"),
            &["exactly one of summary", "column"],
        ),
        (
            &format!("{head}[[result]]\nname = \"r\"\nsummary = \"a\"\nreduce = \"max\"\n"),
            &["go with column"],
        ),
        (
            &format!(
                "{head}[[result]]\nname = \"r\"\ncolumn = \"a\"\nreduce = \"max\"\nat = {{ column = \"t\", value = 1.0 }}\n"
            ),
            &["not both"],
        ),
        (
            &format!(
                "{head}[[result]]\nname = \"r\"\ncolumn = \"a\"\n[[result]]\nname = \"r\"\ncolumn = \"b\"\n"
            ),
            &["name 'r' is taken"],
        ),
        (
            &format!(
                "{head}[[axis]]\nname = \"a\"\nkey = \"x\"\nrange = {{ from = 0.0, to = 1.0, count = 1000 }}\n[[axis]]\nname = \"b\"\nkey = \"y\"\nrange = {{ from = 0.0, to = 1.0, count = 1000 }}\n"
            ),
            &["1000000 cases, more than 100000"],
        ),
    ];
    for (text, needles) in cases {
        let msg = refusal(text);
        assert!(msg.contains("s.toml"), "no file name in: {msg}");
        for n in *needles {
            assert!(msg.contains(n), "'{n}' missing from: {msg}\n(for {text})");
        }
    }
}

#[test]
fn cases_side_by_side_never_take_more_threads_than_cores() {
    assert_eq!(slots(12, 2, 0, 0).unwrap(), (2, 1));
    assert_eq!(slots(1, 8, 0, 0).unwrap(), (1, 8));
    assert_eq!(slots(3, 8, 0, 0).unwrap(), (3, 2));
    assert_eq!(slots(12, 8, 0, 4).unwrap(), (2, 4));
    assert_eq!(slots(1, 8, 0, 2).unwrap(), (1, 2));
    assert_eq!(slots(12, 8, 4, 0).unwrap(), (4, 2));
    assert_eq!(slots(12, 8, 2, 3).unwrap(), (2, 3));
    for cases in 1..20 {
        for cores in 1..17 {
            let (p, t) = slots(cases, cores, 0, 0).unwrap();
            assert!(
                p * t <= cores && p >= 1 && t >= 1 && p <= cases,
                "{cases} cases, {cores} cores: {p} x {t}"
            );
        }
    }
    let e = format!("{:#}", slots(12, 2, 2, 2).unwrap_err());
    assert!(
        e.contains("parallel = 2") && e.contains("threads = 2") && e.contains("≤ 2"),
        "{e}"
    );
    assert!(slots(12, 2, 3, 0).is_err() && slots(12, 2, 0, 3).is_err());
}

#[test]
fn axes_cross_zip_and_replicas_expand_in_order_with_stable_distinct_directories() {
    let (t, f) = setup(
        r#"
[sweep]
scene = "scene.toml"
[set]
"run.steps" = 100
[[axis]]
name = "mu"
key = "contact.mu"
values = [0.1, 0.5]
zip = { "contact.k_t" = [400.0, 450.0] }
[[axis]]
name = "lid_speed"
key = "walls.lid.velocity"
range = { from = 0.0, to = 0.002, count = 3 }
[replicas]
count = 2
key = "particles.generate.seed"
first = 10
"#,
    );
    // The velocity is a list: give the axis whole lists instead.
    let text = std::fs::read_to_string(&f).unwrap().replace(
        "range = { from = 0.0, to = 0.002, count = 3 }",
        "values = [[0.0, 0.0], [0.0, 0.001], [0.0, 0.002]]",
    );
    std::fs::write(&f, text).unwrap();
    let s = Sweep::load(&f).unwrap();
    let out = t.path().join("out");
    let cases = expand(&s, &out).unwrap();
    assert_eq!(cases.len(), 2 * 3 * 2);
    // First axis outermost, replicas innermost.
    let mu: Vec<f64> = cases.iter().map(|c| c.axes[0].1.as_float().unwrap()).collect();
    assert_eq!(&mu[..6], &[0.1; 6]);
    assert_eq!(cases[1].replica, Some((1, 11)));
    assert_eq!(cases[2].axes[1].1.to_string(), "[0.0, 0.001]");
    let mut ids: Vec<&str> = cases.iter().map(|c| c.id.as_str()).collect();
    assert!(ids[0].starts_with("mu0.1_lid_speed-0.0--0.0-_r0-"), "{}", ids[0]);
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), cases.len(), "two cases share a directory");
    // The same file expands to the same directories.
    let again = expand(&s, &out).unwrap();
    assert!(cases.iter().zip(&again).all(|(a, b)| a.dir == b.dir));
    // What a case runs: the zip in step with its axis, the lid's speed inside the wall list
    // (the box kept), the replica's seed, [set].
    let c = &cases[11]; // mu 0.5, lid 0.002, replica 1
    let params = &c.pipeline.stages[0].params;
    let over = params["overrides"].as_table().unwrap();
    let l = crate::scenes::schema::load(&t.path().join("scene.toml"), over).unwrap();
    assert_eq!(l.scene.contact.as_ref().map(|_| ()), Some(()));
    let contact = serde_json::to_value(l.scene.contact.as_ref().unwrap()).unwrap();
    assert_eq!(contact["mu"], 0.5);
    assert_eq!(contact["k_t"], 450.0);
    assert_eq!(l.scene.walls.len(), 2);
    assert_eq!(l.scene.walls[0].box_, Some([0.0, 0.0, 0.01, 0.01]));
    assert_eq!(l.scene.walls[1].velocity, Some([0.0, 0.002]));
    assert_eq!(
        l.scene
            .particles
            .as_ref()
            .unwrap()
            .generate
            .as_ref()
            .unwrap()
            .seed,
        11
    );
    assert_eq!(l.scene.run.steps, Some(100));
    // Run order: as expanded, or replica by replica with [sweep] interleave.
    let order = |q: local::Queue| std::iter::from_fn(|| q.take()).collect::<Vec<_>>();
    assert_eq!(
        order(local::Queue::new(&cases, false)),
        (0..12).collect::<Vec<_>>()
    );
    assert_eq!(
        order(local::Queue::new(&cases, true)),
        [0, 2, 4, 6, 8, 10, 1, 3, 5, 7, 9, 11]
    );
}

#[test]
fn keys_reach_into_lists_by_index_or_name_and_refuse_what_is_not_there() {
    let t = tempfile::tempdir().unwrap();
    let scene = t.path().join("scene.toml");
    std::fs::write(&scene, SCENE).unwrap();
    let set = |k: &str, v: toml::Value| scene_overrides(&scene, &toml::Table::new(), &[(k.into(), v)]);
    let o = set("walls.1.b", toml::Value::Array(vec![0.01.into(), 0.0095.into()])).unwrap();
    let walls = o["walls"].as_array().unwrap();
    assert_eq!(walls.len(), 2, "the whole list is carried over");
    assert_eq!(walls[1]["b"].as_array().unwrap()[1].as_float(), Some(0.0095));
    let e = format!("{:#}", set("walls.plate.a", toml::Value::Float(1.0)).unwrap_err());
    assert!(e.contains("named 'plate'") && e.contains("lid"), "{e}");
    let e = format!("{:#}", set("walls.5.a", toml::Value::Float(1.0)).unwrap_err());
    assert!(e.contains("index 5") && e.contains("list of 2"), "{e}");
    let mut v = toml::Value::Table(toml::from_str("a = 1").unwrap());
    let e = format!(
        "{:#}",
        set_path(&mut v, &["a", "b"], toml::Value::Integer(2)).unwrap_err()
    );
    assert!(e.contains("'b' is inside 1"), "{e}");
    // A table key below a list: the depth of the first list is reported.
    let mut v = toml::Value::Table(toml::from_str("w = [{ name = \"p\", v = [0.0, 0.0] }]").unwrap());
    assert_eq!(
        set_path(&mut v, &["w", "p", "v", "1"], 2.0.into()).unwrap(),
        Some(1)
    );
    assert_eq!(v["w"][0]["v"][1].as_float(), Some(2.0));
}

#[test]
fn results_interpolate_at_the_first_crossing_reduce_and_read_summaries() {
    let x = [0.0, 1.0, 2.0, 3.0, 2.0];
    let y = [10.0, 20.0, 40.0, 50.0, 0.0];
    assert_eq!(crossing(&x, &y, 1.5), Some(30.0));
    assert_eq!(crossing(&x, &y, 2.0), Some(40.0)); // on a row: that row
    assert_eq!(crossing(&x, &y, 0.0), Some(10.0));
    assert_eq!(crossing(&x, &y, 3.5), None); // never reached
    // From above: the level is reached going down.
    assert_eq!(crossing(&[5.0, 3.0, 1.0], &[0.0, 1.0, 2.0], 2.0), Some(1.5));
    // NaN rows are skipped.
    assert_eq!(crossing(&[0.0, f64::NAN, 2.0], &[0.0, 5.0, 2.0], 1.0), Some(1.0));
    assert_eq!(reduce(&y, Reduce::Last), Some(0.0));
    assert_eq!(reduce(&y, Reduce::First), Some(10.0));
    assert_eq!(reduce(&y, Reduce::Max), Some(50.0));
    assert_eq!(reduce(&y, Reduce::Min), Some(0.0));
    assert_eq!(reduce(&[1.0, f64::NAN, 3.0], Reduce::Mean), Some(2.0));
    assert_eq!(reduce(&[f64::NAN], Reduce::Mean), None);
    let s = serde_json::json!({"a": {"b": [1.5, {"c": "dilatant"}]}, "n": null});
    assert_eq!(summary_value(&s, "a.b.0").unwrap(), 1.5);
    assert_eq!(summary_value(&s, "a.b.1.c").unwrap(), "dilatant");
    let e = format!("{:#}", summary_value(&s, "a.x").unwrap_err());
    assert!(e.contains("no 'x'") && e.contains("\"b\""), "{e}");
    assert!(summary_value(&s, "a.b.7").is_err() && summary_value(&s, "n").is_err());
    assert!(summary_value(&s, "a").is_err(), "an object is not one value");
}

const SWEEP: &str = r#"
[sweep]
name = "t"
scene = "scene.toml"
[[axis]]
name = "mu"
key = "contact.mu"
values = [0.1, 0.5]
[replicas]
count = 2
key = "particles.generate.seed"
"#;

#[test]
fn a_sweep_reruns_only_what_changed_and_its_table_does_not_depend_on_threads() {
    let (t, f) = setup(&format!("{SWEEP}{RESULTS}"));
    let out = t.path().join("a");
    let s = run(&args(&f, &out, 2, 1)).unwrap();
    assert_eq!((s.cases, s.finished, s.failed, s.reused), (4, 4, 0, 0));
    let results = std::fs::read(out.join("results.csv")).unwrap();
    let df = crate::report::table::read_table(&out.join("results.csv")).unwrap();
    assert_eq!(df.height(), 4);
    let col = |n: &str| crate::report::table::f64_column(&df, n, &out).unwrap();
    let (ke, ke_max, ke_at, pf, seed) = (col("ke"), col("ke_max"), col("ke_at"), col("pf"), col("seed"));
    assert_eq!(seed, [1.0, 2.0, 1.0, 2.0]);
    // Replicas are different assemblies (the same grains, so the same packing fraction of the
    // box, placed elsewhere): their kinetic energies differ.
    assert!(ke[0] != ke[1] && ke[2] != ke[3], "{ke:?}");
    assert!(pf[0] == pf[1], "{pf:?}");
    for k in 0..4 {
        assert!(
            ke[k] > 0.0 && ke[k] <= ke_max[k] && ke_at[k] <= ke_max[k],
            "row {k}"
        );
    }
    // ke_at: time 0.004 s is the series row of step 1000 (every 100 steps of 4e-6 s).
    let case0 = std::fs::read_dir(out.join("cases"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .min()
        .unwrap();
    let series = crate::report::table::read_table(&case0.join("simulate/series.csv")).unwrap();
    let p = case0.join("simulate/series.csv");
    let (tc, kc) = (
        crate::report::table::f64_column(&series, "time", &p).unwrap(),
        crate::report::table::f64_column(&series, "kinetic_energy", &p).unwrap(),
    );
    let row = tc.iter().position(|&x| (x - 0.004).abs() < 1e-12).unwrap();
    assert!(
        (ke_at[0] - kc[row]).abs() <= 1e-9 * kc[row].abs(),
        "{} vs {}",
        ke_at[0],
        kc[row]
    );
    // The ensemble: one row per value of mu, two replicas each, mean and interval.
    let e = crate::report::table::read_table(&out.join("ensemble.csv")).unwrap();
    let ec = |n: &str| crate::report::table::f64_column(&e, n, &out).unwrap();
    assert_eq!(ec("mu"), [0.1, 0.5]);
    assert_eq!(ec("pf_n"), [2.0, 2.0]);
    let (m, sd, ci) = (ec("ke_mean"), ec("ke_std"), ec("ke_ci95"));
    assert!((m[0] - (ke[0] + ke[1]) / 2.0).abs() <= 1e-15 * m[0]);
    assert!((sd[0] - (ke[0] - ke[1]).abs() / 2f64.sqrt()).abs() <= 1e-12 * sd[0]);
    // Two samples: t(0.975, 1) = 12.7062; half-width t sd / sqrt 2.
    assert!(
        (ci[0] / (sd[0] / 2f64.sqrt()) - 12.7062).abs() < 1e-3,
        "{}",
        ci[0]
    );
    for file in [
        "results.parquet",
        "ensemble.parquet",
        "cases.csv",
        "index.html",
        "figures/ke_vs_mu.png",
    ] {
        assert!(out.join(file).is_file(), "{file} missing");
    }
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        page.contains("ke_vs_mu.png") && page.contains("results.csv"),
        "the page lacks the chart or table"
    );
    // Parquet holds the same table.
    let pq = polars::prelude::ParquetReader::new(std::fs::File::open(out.join("results.parquet")).unwrap());
    use polars::prelude::SerReader;
    assert!(pq.finish().unwrap().equals_missing(&df));

    // The same sweep again: every case is reused, the table is the same bytes.
    let s = run(&args(&f, &out, 2, 1)).unwrap();
    assert_eq!((s.finished, s.reused), (4, 4));
    assert_eq!(std::fs::read(out.join("results.csv")).unwrap(), results);

    // One case at a time with two threads each, elsewhere: the same table.
    let other = t.path().join("b");
    run(&args(&f, &other, 1, 2)).unwrap();
    assert!(
        std::fs::read(other.join("results.csv")).unwrap() == results,
        "threads changed the results"
    );

    // One value of the axis changed: only its two cases run.
    std::fs::write(
        &f,
        format!("{SWEEP}{RESULTS}").replace("[0.1, 0.5]", "[0.1, 0.3]"),
    )
    .unwrap();
    let s = run(&args(&f, &out, 2, 1)).unwrap();
    assert_eq!((s.finished, s.reused), (4, 2));
}

#[test]
fn a_failed_case_is_reported_and_the_others_still_make_the_table() {
    let (t, f) = setup(
        r#"
[sweep]
scene = "scene.toml"
[set]
"run.until_wall_moved.distance" = 1.0
[[axis]]
name = "stop_wall"
key = "run.until_wall_moved.wall"
values = ["nope", "lid"]
[[result]]
name = "pf"
summary = "last.packing_fraction"
[[result]]
name = "never"
column = "kinetic_energy"
at = { column = "time", value = 99.0 }
"#,
    );
    let out = t.path().join("out");
    let e = format!("{:#}", run(&args(&f, &out, 2, 1)).unwrap_err());
    assert!(
        e.contains("1 of 2 cases failed") && e.contains("cases.csv"),
        "{e}"
    );
    let df = crate::report::table::read_table(&out.join("results.csv")).unwrap();
    assert_eq!(df.height(), 1, "a failed case gives no row");
    let cases = std::fs::read_to_string(out.join("cases.csv")).unwrap();
    assert!(cases.contains("failed") && cases.contains("nope"), "{cases}");
    // A result the finished case never reached is missing, with the reason.
    assert!(cases.contains("never reaches 99"), "{cases}");
    let rec: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("stage.json")).unwrap()).unwrap();
    assert_eq!(rec["output"]["summary"]["missing_cases"], 1);
    assert_eq!(rec["output"]["summary"]["missing_values"]["never"], 1);
    let page = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(
        page.contains("failed") && page.contains("nope"),
        "the page does not report the failure"
    );
}
