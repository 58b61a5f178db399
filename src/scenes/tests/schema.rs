//! The scene format: every shipped scene parses and names its physics; typos, sections the
//! physics does not use and files of the earlier format are refused with a way out.

use super::*;
use crate::scenes::schema::{Physics, load};

fn load_text(text: &str) -> anyhow::Result<crate::scenes::schema::Loaded> {
    let t = tempfile::tempdir()?;
    let p = t.path().join("s.toml");
    std::fs::write(&p, text)?;
    load(&p, &Default::default())
}

#[test]
fn every_shipped_scene_parses_with_its_physics() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut seen = 0;
    for e in std::fs::read_dir(&dir).unwrap().flatten() {
        let p = e.path();
        if p.extension().is_none_or(|x| x != "toml") {
            continue;
        }
        let l = load(&p, &Default::default()).unwrap_or_else(|e| panic!("{}: {e:#}", p.display()));
        let name = p.file_name().unwrap().to_string_lossy();
        let want = match &name[..3] {
            "dry" => Physics::Dry,
            "flu" => Physics::Fluid,
            _ => Physics::Coupled,
        };
        assert_eq!(l.physics, want, "{name}");
        seen += 1;
    }
    assert_eq!(seen, 7);
}

#[test]
fn a_typo_names_the_file_the_line_and_the_nearest_key() {
    let text = super::dry::SCENE.replace("skin = 5.0e-5", "skni = 5.0e-5");
    let e = format!("{:#}", load_text(&text).unwrap_err());
    assert!(
        e.contains("s.toml") && e.contains("skni") && e.contains("did you mean `skin`"),
        "{e}"
    );
    assert!(e.contains("line"), "{e}");
    let text = super::dry::SCENE.replace("[output]", "[outptu]");
    let e = format!("{:#}", load_text(&text).unwrap_err());
    assert!(e.contains("did you mean `output`"), "{e}");
}

#[test]
fn sections_the_physics_does_not_use_are_refused() {
    let text = format!("{}\n[lattice]\ndx = 1e-4\ntau = 0.8\n", super::dry::SCENE);
    let e = format!("{:#}", load_text(&text).unwrap_err());
    assert!(
        e.contains("[lattice] is given but the scene has no [fluid]"),
        "{e}"
    );
    let text = format!(
        "{}\n[[walls]]\nbox = [0.0, 0.0, 1e-3, 1e-3]\n",
        super::fluid::POISEUILLE
    );
    let e = format!("{:#}", load_text(&text).unwrap_err());
    assert!(
        e.contains("[[walls]] is given but the scene has no [particles]"),
        "{e}"
    );
    let text = super::fluid::POISEUILLE.replace(
        "periodic = [true, false]",
        "periodic = [true, false]\n[boundaries]\nx_min = { type = \"wall\" }",
    );
    let t = tempfile::tempdir().unwrap();
    let e = format!("{:#}", simulate(&text, t.path(), false).unwrap_err());
    assert!(e.contains("x_min") && e.contains("periodic"), "{e}");
    assert!(!t.path().join("out").exists());
}

#[test]
fn an_old_style_file_is_refused_with_how_to_convert_it() {
    let old = "[scene]\nkind = \"dry\"\n[domain]\nlo = [0.0, 0.0]\nhi = [1.0, 1.0]\n[step]\ndt = 1e-6\nskin = 1e-5\n\
               [run]\nsteps = 10\noutput_every = 5\n";
    let e = format!("{:#}", load_text(old).unwrap_err());
    assert!(e.contains("earlier format"), "{e}");
    assert!(
        e.contains("remove [scene] kind") && e.contains("rename [step] to [dem]"),
        "{e}"
    );
    assert!(e.contains("series = { every = N }"), "{e}");
}

#[test]
fn overrides_reach_into_sections() {
    let t = tempfile::tempdir().unwrap();
    let p = t.path().join("s.toml");
    std::fs::write(&p, super::dry::SCENE).unwrap();
    let over: toml::Table = toml::from_str("run = { steps = 7 }\ndem = { dt = 2e-6 }").unwrap();
    let l = load(&p, &over).unwrap();
    assert_eq!(l.scene.run.steps, Some(7));
    assert_eq!(l.scene.dem.unwrap().dt, 2e-6);
    let bad: toml::Table = toml::from_str("run = { stpes = 7 }").unwrap();
    let e = format!("{:#}", load(&p, &bad).unwrap_err());
    assert!(e.contains("did you mean `steps`"), "{e}");
}

#[test]
fn a_scene_extends_another_key_by_key_and_loops_are_refused() {
    let t = tempfile::tempdir().unwrap();
    let base = super::dry::SCENE.replace("name = ", "description = ");
    std::fs::write(t.path().join("base.toml"), &base).unwrap();
    std::fs::write(
        t.path().join("child.toml"),
        "[scene]\nextends = \"base.toml\"\n[dem]\nskin = 7.0e-5\n",
    )
    .unwrap();
    let l = load(&t.path().join("child.toml"), &Default::default()).unwrap();
    let parent = load(&t.path().join("base.toml"), &Default::default()).unwrap();
    let (c, p) = (l.scene.dem.as_ref().unwrap(), parent.scene.dem.as_ref().unwrap());
    assert_eq!(c.skin, 7.0e-5);
    assert_ne!(p.skin, 7.0e-5);
    assert_eq!(c.dt, p.dt, "keys the child does not give come from the base");
    assert_eq!(l.name, "child");
    assert_eq!(l.sources.len(), 2);
    // a loop
    std::fs::write(t.path().join("a.toml"), "[scene]\nextends = \"b.toml\"\n").unwrap();
    std::fs::write(t.path().join("b.toml"), "[scene]\nextends = \"a.toml\"\n").unwrap();
    let e = format!(
        "{:#}",
        load(&t.path().join("a.toml"), &Default::default()).unwrap_err()
    );
    assert!(e.contains("loop"), "{e}");
    // a missing base names the file
    std::fs::write(t.path().join("c.toml"), "[scene]\nextends = \"gone.toml\"\n").unwrap();
    let e = format!(
        "{:#}",
        load(&t.path().join("c.toml"), &Default::default()).unwrap_err()
    );
    assert!(e.contains("gone.toml"), "{e}");
}

/// Every Su 2020 case scene parses, and where its assembly is in the repository
/// (`scenes/su2020/assemblies/NAME/`, built by `lbdem assemble`) its grains load: the file's
/// grain set is the one the scene names (Table 2's count and sizes), the scene's walls and
/// membrane go on them, and the coupled case builds (lattice, τ, step ratio). The assemblies listed here must exist: a missing one fails.
#[test]
fn the_su2020_cases_load_their_committed_assemblies() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/su2020");
    let committed = [
        "pk81",
        "pk84",
        "pk93",
        "pk95",
        "sim1",
        "sim2",
        "sim3",
        "float",
        "pk93-membrane",
    ];
    let (mut built, mut refused) = (0, Vec::new());
    for e in std::fs::read_dir(&dir).unwrap().flatten() {
        let p = e.path();
        // `shear-base.toml` is what the cases extend, not a case.
        if p.extension().is_none_or(|x| x != "toml") || p.to_string_lossy().ends_with("-base.toml") {
            continue;
        }
        let l = load(&p, &Default::default()).unwrap_or_else(|e| panic!("{}: {e:#}", p.display()));
        let Some(a) = l.scene.particles.as_ref().and_then(|pc| pc.assembly.as_ref()) else {
            continue;
        };
        let case = a
            .file
            .parent()
            .unwrap()
            .file_name()
            .unwrap()
            .to_string_lossy()
            .to_string();
        if !committed.contains(&case.as_str()) {
            continue;
        }
        // The whole coupled case as `lbdem simulate` builds it: grains, walls, membrane, the
        // lattice on the box (its faces on whole spacings), τ and the LBM-DEM ratio.
        // Fig. 11's dry cases are the grains alone.
        let built_case = if l.physics == Physics::Coupled {
            crate::scenes::models::coupled::build_f64(&l.scene, &l.base_dir).map(|m| m.run.sys)
        } else {
            crate::scenes::build::dem::build_system(&l.scene, &l.base_dir)
        };
        let sys = match built_case {
            Ok(sys) => sys,
            Err(e) => {
                refused.push(format!("{}: {e:#}", p.display()));
                continue;
            }
        };
        // A deleting %PK recipe may drop grains (81 %PK: 5083 -> 5000), never add them.
        assert!(
            sys.bodies.len() <= a.grains && sys.bodies.len() > a.grains * 9 / 10,
            "{}: {} grains from an assembly of {}",
            p.display(),
            sys.bodies.len(),
            a.grains
        );
        assert_eq!(
            sys.membrane.as_ref().is_some_and(|m| !m.bodies.is_empty()),
            l.scene.membrane.is_some(),
            "{}: a [membrane] section and membrane grains go together",
            p.display()
        );
        built += 1;
    }
    assert!(refused.is_empty(), "{}", refused.join("\n"));
    // sim1, sim1-quick, sim1-quasistatic, sim2, sim3, 12 matrix cases and the 30 µm/s
    // column's four quick variants, 6 Fig. 11 cases (84 %PK), float.
    assert!(built >= 28, "only {built} Su cases built their grains");
}

/// Issue 16 item 4: a TRT lattice without `magic` gets Λ = 3/16, the value the atlas's
/// collision chart (docs/atlas.md) shows exact at the walls for the cost of 1/4.
#[test]
fn the_trt_magic_parameter_defaults_to_three_sixteenths() {
    let l: crate::scenes::schema::LatticeSection = toml::from_str("dx = 1.0e-4\ntau = 0.8").unwrap();
    assert_eq!((l.collision.as_str(), l.magic), ("trt", 0.1875));
}
