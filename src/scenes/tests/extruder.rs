//! The extruder scene (Ness et al. 2017, Fig. 1; `scenes/ness2017/`) through the runner as
//! `lbdem simulate` runs it: the reduced extruder flows through its die with the grains
//! conserved (and its coarse-grained stress balances the wall loads: the `extrusion` stage), an
//! interrupted run resumes to the same bits, the thread count changes nothing, and bad set-ups
//! are refused before anything is written.

use super::*;
use crate::report::table::{f64_column, read_table};

/// The shipped reduced extruder with `over` (TOML sections) appended after its own keys,
/// written beside the case-A base it extends.
fn reduced(dir: &Path, edit: impl Fn(String) -> String) -> String {
    let src = dir.join("scene");
    std::fs::create_dir_all(&src).unwrap();
    std::fs::write(src.join("case-a.toml"), shipped("ness2017/case-a.toml")).unwrap();
    edit(shipped("ness2017/reduced.toml"))
}

fn column(dir: &Path, name: &str) -> Vec<f64> {
    let p = dir.join("out/series.csv");
    f64_column(&read_table(&p).unwrap(), name, &p).unwrap()
}

/// Flow through the die of the reduced extruder (barrel 16 d, die 8 d, case A paste, loose
/// fill): grains leave at the outlet, the die velocity is positive, every row conserves the
/// grains, and the inventory settles.
#[test]
fn reduced_extruder_flows_through_the_die_conserving_grains() {
    let t = tempfile::tempdir().unwrap();
    let text = reduced(t.path(), |s| {
        s.replace("time = 3.0e-5", "time = 2.4e-5")
            .replace("snapshots = { every = 12000 }", "snapshots = { every = 1000 }")
    });
    let rec = simulate(&text, t.path(), false).unwrap();
    let e = &rec.output.summary["engine"];
    let prefilled = e["prefilled"].as_f64().unwrap();
    let (time, ins, out, grains) = (
        column(t.path(), "time"),
        column(t.path(), "inserted"),
        column(t.path(), "removed"),
        column(t.path(), "grains"),
    );
    for k in 0..time.len() {
        assert_eq!(
            prefilled + ins[k],
            grains[k] + out[k],
            "grains lost at t = {:e} s",
            time[k]
        );
    }
    let n = time.len();
    let vd = column(t.path(), "die_velocity");
    let late = &vd[n / 2..];
    let mean = late.iter().sum::<f64>() / late.len() as f64;
    // Measured 2026-11-26: 6.85 m/s (0.68 d/t; d/t = 10 m/s), minimum 6.35; 185 grains out.
    eprintln!(
        "prefilled {prefilled}, inserted {}, removed {}, grains {} -> {}, die velocity (2nd half) {mean:.3} m/s, min {:.3}",
        ins[n - 1],
        out[n - 1],
        grains[n / 2],
        grains[n - 1],
        late.iter().cloned().fold(f64::INFINITY, f64::min)
    );
    assert!(late.iter().all(|v| *v > 0.0), "the die stopped: {late:?}");
    assert!(
        out[n - 1] > 100.0,
        "only {} grains left through the outlet",
        out[n - 1]
    );
    // Approaching steady: the inventory grows much less over the second half than over the
    // first (measured 2026-11-26: +56 against +337 grains from the fill, ratio 0.17).
    let (early, late) = (grains[n / 2] - prefilled, grains[n - 1] - grains[n / 2]);
    assert!(late.abs() < 0.34 * early, "inventory grew {late} after {early}");
    let phi = column(t.path(), "phi_inlet");
    eprintln!(
        "phi_inlet 2nd half mean {:.3}",
        phi[n / 2..].iter().sum::<f64>() / (n - n / 2) as f64
    );
    the_extrusion_analysis_balances_the_wall_loads(t.path());
}

/// A run interrupted by its wall-clock limit and resumed until done ends bit for bit like the
/// uninterrupted run (series and sphere snapshots), with grains inserted and removed across
/// the checkpoints.
#[test]
fn interrupted_and_resumed_extruder_matches_uninterrupted_bitwise() {
    let t = tempfile::tempdir().unwrap();
    let short = |s: String| {
        // 8000 steps of dt = 8.83396e-10 s ([run] time, as the base gives time, not steps): the
        // first grains leave the die near step 5600.
        s.replace("time = 3.0e-5", "time = 7.0672e-6\nwall_clock = 0.3")
            .replace("series = { every = 500 }", "series = { every = 100 }")
            .replace("snapshots = { every = 12000 }", "snapshots = { every = 1000 }")
    };
    let whole_text = reduced(&t.path().join("whole"), |s| {
        short(s).replace("\nwall_clock = 0.3", "")
    });
    let whole = simulate(&whole_text, &t.path().join("whole"), false).unwrap();
    assert_eq!(whole.output.summary["steps"], 8000);
    let cut = t.path().join("cut");
    let text = reduced(&cut, short);
    let interruptions = resume_until_done(&text, &cut, 1000);
    let (a, b) = (t.path().join("whole/out"), cut.join("out"));
    let snaps = [
        "series.csv",
        "snapshots.csv",
        "snapshots/spheres_000001000.csv",
        "snapshots/spheres_000008000.csv",
    ];
    for f in snaps {
        let (x, y) = (
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
        );
        assert!(x == y, "{f} differs after {interruptions} interruptions");
    }
    let removed = column(&t.path().join("whole"), "removed");
    assert!(
        *removed.last().unwrap() > 0.0,
        "nothing left the die in the resumed window"
    );
}

/// The same run on one thread and on two gives the same bits (the sphere engine's pair search
/// and pair laws run on rayon's threads, their sums serially in list order).
#[test]
fn extruder_results_do_not_depend_on_the_thread_count() {
    let t = tempfile::tempdir().unwrap();
    let mut series = Vec::new();
    for threads in [1, 2] {
        let dir = t.path().join(format!("t{threads}"));
        let text = reduced(&dir, |s| {
            // 800 steps of dt = 8.83396e-10 s.
            s.replace("time = 3.0e-5", &format!("time = 7.0672e-7\nthreads = {threads}"))
                .replace("series = { every = 500 }", "series = { every = 50 }")
        });
        simulate(&text, &dir, false).unwrap();
        series.push(std::fs::read(dir.join("out/series.csv")).unwrap());
    }
    assert!(series[0] == series[1], "1 and 2 threads differ");
}

/// Refused before anything runs, naming the parameter, its value and the fix; nothing is
/// left behind.
#[test]
fn bad_extruders_are_refused_naming_the_parameter() {
    let cases: [(&str, &str, &[&str]); 5] = [
        (
            "die_width = 8.0e-5",
            "die_width = 2.0e-4",
            &["die_width", "barrel_width", "smaller"],
        ),
        (
            "die_width = 8.0e-5",
            "die_width = 2.0e-5",
            &["die_width", "largest grains"],
        ),
        (
            "",
            "\n[suspension]\ndt = 1.0e-8\n",
            &["[suspension] dt", "limit", "viscous"],
        ),
        (
            "prefill_phi = 0.35",
            "prefill_phi = 0.35\nphi_inlet = 0.7",
            &["phi_inlet", "0.7"],
        ),
        (
            "",
            "\n[domain]\nlo = [0.0, 0.0]\nhi = [1.0, 1.0]\n",
            &["[domain]", "remove"],
        ),
    ];
    for (from, to, needles) in cases {
        let t = tempfile::tempdir().unwrap();
        let text = reduced(t.path(), |s| {
            if from.is_empty() {
                s + to
            } else {
                s.replace(from, to)
            }
        });
        let e = format!("{:#}", simulate(&text, t.path(), false).expect_err(to));
        for n in needles {
            assert!(e.contains(n), "{to}: the message should contain {n:?}: {e}");
        }
        assert!(!t.path().join("out").exists(), "{to}: a refused run left files");
    }
}

/// The shipped sweep expands to Table 1's six cases × five wall realisations, each case's
/// scene loading with its row's values and its own wall seed (nothing is run).
#[test]
fn the_wall_realisation_sweep_expands_to_thirty_checked_cases() {
    use crate::sweep::{cases::expand, schema::Sweep};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let s = Sweep::load(&root.join("sweeps/ness2017-walls.toml")).unwrap();
    let t = tempfile::tempdir().unwrap();
    let cases = expand(&s, t.path()).unwrap();
    assert_eq!(cases.len(), 30);
    // Table 1: (mu_p, mu_w, eta_f in Pa s at d = 10 µm, t = 1 µs, k_n in N/m).
    let rows = [
        ("a", 1.0, 0.0, 5e-3, 1e4),
        ("b", 1.0, 0.1, 5e-3, 1e4),
        ("c", 0.1, 0.0, 5e-3, 1e4),
        ("d", 0.1, 0.1, 5e-3, 1e4),
        ("e", 1.0, 0.0, 5e-5, 1e4),
        ("f", 1.0, 0.0, 5e-3, 2e4),
    ];
    for (k, c) in cases.iter().enumerate() {
        let (name, mu_p, mu_w, eta, k_n) = rows[k / 5];
        assert_eq!(c.base, format!("../scenes/ness2017/case-{name}.toml"));
        let over = c.pipeline.stages[0].params["overrides"].as_table().unwrap();
        let l = crate::scenes::schema::load(
            &root.join("scenes/ness2017").join(format!("case-{name}.toml")),
            over,
        )
        .unwrap();
        let (e, su) = (l.scene.extruder.unwrap(), l.scene.suspension.unwrap());
        assert_eq!(e.wall_seed, (k % 5) as u64 + 1, "case {name}");
        assert_eq!(
            (su.mu_p, su.mu_w, su.viscosity, su.k_n),
            (mu_p, mu_w, eta, k_n),
            "case {name}"
        );
        assert_eq!(e.barrel_width / su.diameters[0], 100.0);
    }
}

/// sweeps/ness2017-fig9.toml (the full Fig. 9 sweep over pipelines/ness2017-case.toml) expands to
/// 6 cases x 3 forces x 5 wall seeds, each case's simulate stage on its own Table 1 file with its
/// force and seed, its analysis reading that run; the reduced flow sweep to its 4 forces, and
/// the slab-against-monolayer sweep to its 40 cases (5 wall realisations).
/// Nothing is run.
#[test]
fn the_fig9_sweeps_expand_to_checked_cases() {
    use crate::sweep::{cases::expand, schema::Sweep};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let s = Sweep::load(&root.join("sweeps/ness2017-fig9.toml")).unwrap();
    let t = tempfile::tempdir().unwrap();
    let cases = expand(&s, t.path()).unwrap();
    assert_eq!(cases.len(), 90);
    let forces = [1.0e-6, 1.0e-5, 1.0e-4];
    let mu_w = [0.0, 0.1, 0.0, 0.1, 0.0, 0.0];
    for (k, c) in cases.iter().enumerate() {
        let (case, force, seed) = (k / 15, forces[(k / 5) % 3], (k % 5) as u64 + 1);
        let sim = &c.pipeline.stages[0].params;
        let scene = sim["scene"].as_str().unwrap();
        assert_eq!(
            scene,
            format!(
                "scenes/ness2017/case-{}.toml",
                ["a", "b", "c", "d", "e", "f"][case]
            )
        );
        let l = crate::scenes::schema::load(&root.join(scene), sim["overrides"].as_table().unwrap()).unwrap();
        let (e, su) = (l.scene.extruder.unwrap(), l.scene.suspension.unwrap());
        assert_eq!(
            (e.body_force, e.wall_seed, su.mu_w),
            (force, seed, mu_w[case]),
            "{scene}"
        );
        assert_eq!(c.pipeline.stages[1].params["runs"][0].as_str(), Some("sim"));
    }
    let s = Sweep::load(&root.join("sweeps/ness2017-reduced-flow.toml")).unwrap();
    assert_eq!(expand(&s, t.path()).unwrap().len(), 4);
    // The slab against the monolayer: 2 layers x 4 forces x 5 walls, the layer's switch and thickness
    // reaching the scene.
    let s = Sweep::load(&root.join("sweeps/ness2017-reduced-layers.toml")).unwrap();
    let cases = expand(&s, t.path()).unwrap();
    assert_eq!(cases.len(), 40);
    for (k, c) in cases.iter().enumerate() {
        let e = simulated_scene(root, c).scene.extruder.unwrap();
        let want = [
            (false, 5.0e-5),
            (
                true,
                lbdem_dem::spheres::extruder::monolayer_thickness([1.0e-5, 1.5e-5]),
            ),
        ];
        assert_eq!((e.monolayer, e.depth), want[k / 20], "case {k}");
    }
    // The reduced Table 1 cases: each case's friction and stiffness reach its simulate stage.
    let s = Sweep::load(&root.join("sweeps/ness2017-reduced-cases.toml")).unwrap();
    let cases = expand(&s, t.path()).unwrap();
    assert_eq!(cases.len(), 10);
    let want = [
        (1.0, 0.0, 1e4),
        (1.0, 0.1, 1e4),
        (0.1, 0.0, 1e4),
        (0.1, 0.1, 1e4),
        (1.0, 0.0, 2e4),
    ];
    for (k, c) in cases.iter().enumerate() {
        let su = simulated_scene(root, c).scene.suspension.unwrap();
        assert_eq!((su.mu_p, su.mu_w, su.k_n), want[k / 2], "case {k}");
    }
}

/// The scene a sweep case's first stage (`simulate`) loads, with its overrides.
fn simulated_scene(root: &Path, c: &crate::sweep::cases::Case) -> crate::scenes::schema::Loaded {
    let sim = &c.pipeline.stages[0].params;
    crate::scenes::schema::load(
        &root.join(sim["scene"].as_str().unwrap()),
        sim["overrides"].as_table().unwrap(),
    )
    .unwrap()
}

/// The reduced extruder run until its mass balance holds (stop_when_steady): insertion and
/// removal rates over a 30 t window within 15 % with at least 100 grains out in the window.
/// About 60-150 s in release on the shared 2-core machine; scripts/validate-all.sh.
#[test]
#[ignore = "slow: the reduced extruder to its steady state"]
fn reduced_extruder_reaches_the_mass_balance() {
    let t = tempfile::tempdir().unwrap();
    let text = reduced(t.path(), |s| {
        s.replace("time = 3.0e-5", "time = 1.5e-4")
            .replace(
                "steady_window = 2.0e-5",
                "steady_window = 3.0e-5\nsteady_tolerance = 0.15",
            )
            .replace("stop_when_steady = false", "stop_when_steady = true")
    });
    let rec = simulate(&text, t.path(), false).unwrap();
    let s = &rec.output.summary;
    eprintln!(
        "stopped: {}; steps {}, first steady at {} s, removed {}",
        s["stopped"], s["steps"], s["engine"]["first_steady"], s["engine"]["removed"]
    );
    assert!(
        s["stopped"].as_str().is_some_and(|w| w.contains("steady")),
        "{}",
        s["stopped"]
    );
    let vd = column(t.path(), "die_velocity");
    assert!(*vd.last().unwrap() > 0.0);
    let imb = column(t.path(), "imbalance");
    assert!(*imb.last().unwrap() <= 0.15);
}

/// The reduced extruder as one layer of grains (`scenes/ness2017/reduced-monolayer.toml`,
/// issue 19 item 6) through the runner and the analysis: every sphere of every snapshot has
/// its centre in the plane z = D/2, grains flow through the die, and the Eq. 7 stress, with the
/// layer's thickness D as the bins' depth, carries the load the walls take downstream as in the
/// slab (about 1 s in release).
#[test]
fn a_monolayer_extruder_flows_in_its_plane_and_balances_its_wall_loads() {
    let t = tempfile::tempdir().unwrap();
    let src = t.path().join("scene");
    std::fs::create_dir_all(&src).unwrap();
    std::fs::write(src.join("case-a.toml"), shipped("ness2017/case-a.toml")).unwrap();
    std::fs::write(src.join("reduced.toml"), shipped("ness2017/reduced.toml")).unwrap();
    let text = shipped("ness2017/reduced-monolayer.toml")
        + "\n[run]\ntime = 2.4e-5\n\n[output]\nsnapshots = { every = 1000 }\n";
    let rec = simulate(&text, t.path(), false).unwrap();
    assert!(rec.output.summary["engine"]["removed"].as_f64().unwrap() > 20.0);
    let z0 = 0.5 * lbdem_dem::spheres::extruder::monolayer_thickness([1.0e-5, 1.5e-5]);
    let mut snaps = 0;
    for p in walk(&t.path().join("out/snapshots")) {
        if p.extension().is_some_and(|e| e == "csv") {
            let z = f64_column(&read_table(&p).unwrap(), "z", &p).unwrap();
            assert!(z.iter().all(|&z| z == z0), "{} left the plane", p.display());
            snaps += 1;
        }
    }
    assert!(snaps > 20, "{snaps} snapshots");
    let stations = "stations_d = [[5.0, 8.0], [9.0, 12.0], [20.0, 23.0], [27.0, 30.0]]";
    let rec = extrusion(
        t.path(),
        "cg",
        &t.path().join("out"),
        &format!("from = 1.2e-5\n{stations}"),
    )
    .unwrap();
    let s = &rec.output.summary;
    let f = |k: &str| s[k].as_f64().unwrap();
    let balance = f("axial_force_p1") / f("wall_load_x");
    let p: Vec<f64> = (0..4)
        .map(|k| s["station_pressure"][k].as_f64().unwrap())
        .collect();
    eprintln!(
        "monolayer: balance {balance:.4}, P {p:?} Pa, static area {} d²",
        f("static_area")
    );
    assert_eq!(s["geometry"]["monolayer"], true);
    // Measured 2026-11-30: 0.985 (P 767, 677, 5.7, 1.9 kPa); tolerance twice the 1.5 %.
    assert!((balance - 1.0).abs() < 0.03, "momentum balance {balance}");
    assert!(p[0] > p[1] && p[1] > p[2] && p[2] > p[3], "{p:?}");
}

/// Run the `extrusion` stage on `run` with `params` (TOML, `runs` added), into `dir/name`.
fn extrusion(dir: &Path, name: &str, run: &Path, params: &str) -> anyhow::Result<StageRecord> {
    let kind = crate::registry::find("extrusion")?;
    let ctx = StageContext::new(dir.join(name), name.into(), dir.to_path_buf());
    let text = format!("runs = [\"{}\"]\n{params}", run.display());
    let prepared = kind.prepare(toml::from_str(&text)?, &ctx)?;
    crate::pipeline::execute(prepared, &ctx)
}

/// Ness et al. (2017)'s coarse-grained analysis of the reduced extruder (`extrusion` stage):
/// the Eq. 7 stress in the barrel carries the load the walls take downstream (an independent
/// measurement: the series sums the paste's force on the wall grains), the pressure falls from
/// station to station to about zero at the open end, contacts carry the pressure (Ness: "the
/// pressure contribution due to the contact forces exceeds that due to hydrodynamics"), the
/// barrel passes the same volume flux at its two stations, and every figure is drawn. A
/// snapshot taken before snapshots carried dipoles, and stations outside the channel, are refused.
/// Called on the run of `reduced_extruder_flows_through_the_die_conserving_grains` (one
/// simulation for both: CI time).
fn the_extrusion_analysis_balances_the_wall_loads(t: &Path) {
    let run = t.join("out");
    let stations = "stations_d = [[5.0, 8.0], [9.0, 12.0], [20.0, 23.0], [27.0, 30.0]]";
    let rec = extrusion(t, "cg", &run, &format!("from = 1.2e-5\n{stations}")).unwrap();
    let s = &rec.output.summary;
    let f = |k: &str| s[k].as_f64().unwrap();
    let p: Vec<f64> = (0..4)
        .map(|k| s["station_pressure"][k].as_f64().unwrap())
        .collect();
    let q: Vec<f64> = (0..4).map(|k| s["station_flux"][k].as_f64().unwrap()).collect();
    let balance = f("axial_force_p1") / f("wall_load_x");
    eprintln!(
        "{} snapshots; σ_xx at P1 × area / wall loads downstream = {balance:.4}; P = {p:?} Pa; flux {q:?} m²/s; \
         contact share {:.4}; kinetic / Eq. 7 pressure {:.2e}; static grains {}; largest |St| {:.2}",
        f("snapshots"),
        f("contact_pressure_share"),
        f("kinetic_pressure_ratio"),
        f("static_grains"),
        f("max_stokes")
    );
    // Measured 2026-11-29 on this 2.4e-5 s run, window from 1.2e-5 s: 0.966 (on 3e-5 s runs
    // 0.975 from 1.5e-5 s, 0.962 from 1e-5; 0.940 over 2.6-6e-5 s). The barrel walls' load
    // upstream of P1 (about a third of their 6e-4 N, against 5.2e-3 N in all) is in the wall
    // sum and not in the section: most of the 3.3 %. Tolerance twice that.
    assert!((balance - 1.0).abs() < 0.07, "momentum balance {balance}");
    // Measured: 595 352, 536 270, 2 691, 80 Pa. A physical criterion (the open end is at zero
    // pressure, Ness), not a tolerance on a measurement.
    assert!(p[0] > p[1] && p[1] > p[2] && p[2] > p[3], "{p:?}");
    assert!(p[3].abs() < 0.01 * p[0], "{p:?}");
    // Measured 0.9965. Ness's statement is the criterion: contacts carry more than the liquid.
    assert!(f("contact_pressure_share") > 0.5);
    // Inertia: the kinetic pressure is a small fraction of Eq. 7's (measured 9.1e-4).
    assert!(f("kinetic_pressure_ratio") > 0.0 && f("kinetic_pressure_ratio") < 0.01);
    // Measured: P2 passes 0.958 of P1's flux (the inventory still grows); tolerance twice 4.2 %.
    assert!((q[1] / q[0] - 1.0).abs() < 0.085, "{q:?}");
    for fig in rec.output.figures.iter() {
        assert!(t.join("cg").join(&fig.path).is_file(), "{}", fig.path.display());
    }
    assert_eq!(rec.output.figures.len(), 14);
    let fields = t.join("cg/fields.csv");
    assert!(read_table(&fields).unwrap().height() == 30 * 16);
    // Stations outside the die, and a run whose snapshots have no dipoles, are refused.
    let bad = extrusion(
        t,
        "bad",
        &run,
        "stations_d = [[5.0, 8.0], [9.0, 12.0], [20.0, 23.0], [27.0, 40.0]]",
    );
    assert!(format!("{:#}", bad.unwrap_err()).contains("stations_d"));
    assert!(!t.join("bad").exists(), "a refused analysis left its directory");
    let snap = std::fs::read_dir(run.join("snapshots"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "csv"))
        .max()
        .unwrap();
    let df = read_table(&snap).unwrap();
    let keep: Vec<String> = df
        .get_column_names()
        .iter()
        .map(|c| c.to_string())
        .filter(|c| !c.starts_with("w_") && !c.starts_with("wh_"))
        .collect();
    let mut old = df.select(keep).unwrap();
    crate::report::table::write_frame(&snap, &mut old).unwrap();
    let err = extrusion(t, "old", &run, &format!("from = 1.2e-5\n{stations}")).unwrap_err();
    assert!(format!("{err:#}").contains("no dipole columns"), "{err:#}");
    assert!(!t.join("old").exists());
}
