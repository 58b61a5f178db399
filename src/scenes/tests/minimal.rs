//! Model no more than the scene needs (issue 16 item 3): `[scene] simplify` switches off what it
//! names, and `minimal = true` applies what the committed table (scenes/su2020/minimal.csv,
//! written by `lbdem run pipelines/minimal.toml`) shows harmless for the scene's family.

use super::*;
use crate::scenes::schema::simplify::{harmless_for, read_verdicts};
use crate::scenes::schema::{Physics, load};

fn su2020() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/su2020")
}

fn set(key: &str, value: &str) -> toml::Table {
    let mut t = toml::Table::new();
    let mut inner = toml::Table::new();
    inner.insert(key.into(), toml::Value::String(value.into()));
    t.insert("scene".into(), toml::Value::Table(inner));
    t
}

#[test]
fn a_minimal_scene_applies_what_the_committed_table_shows_harmless() {
    let table = su2020().join("minimal.csv");
    let verdicts = read_verdicts(&table).unwrap();
    let want = harmless_for(&verdicts, "shear-cell");
    let l = load(
        &su2020().join("reduced-shear-cell-minimal.toml"),
        &Default::default(),
    )
    .unwrap();
    assert_eq!(l.minimal_table.as_deref(), Some(table.as_path()));
    assert_eq!(
        l.simplified.len(),
        want.len(),
        "{:?} against {:?}",
        l.simplified,
        want.iter().map(|s| s.name).collect::<Vec<_>>()
    );
    for (s, got) in want.iter().zip(&l.simplified) {
        assert!(
            got.starts_with(&format!("{} (harmless for a shear-cell", s.name))
                || got.starts_with(&format!("not {}: ", s.name)),
            "{got}"
        );
    }
    // What the table found harmful for the shear cell is not applied.
    for v in verdicts
        .iter()
        .filter(|v| v.family == "shear-cell" && !v.harmless)
    {
        assert!(
            !l.simplified
                .iter()
                .any(|g| g.starts_with(&format!("{} (", v.simplification))),
            "{:?}",
            l.simplified
        );
    }
}

#[test]
fn a_simplified_scene_is_the_scene_without_what_it_names() {
    let base = su2020().join("reduced-shear-cell.toml");
    let full = load(&base, &Default::default()).unwrap();
    assert_eq!(full.physics, Physics::Coupled);
    assert!(full.simplified.is_empty());
    let dry = load(&base, &set("simplify", "no-liquid")).unwrap();
    assert_eq!(dry.physics, Physics::Dry);
    let light = load(&base, &set("simplify", "no-rolling+f32")).unwrap();
    assert_eq!(light.scene.lattice.as_ref().unwrap().precision, "f32");
    let law = serde_json::to_value(light.scene.contact.as_ref().unwrap()).unwrap();
    let full_law = serde_json::to_value(full.scene.contact.as_ref().unwrap()).unwrap();
    assert!(
        full_law.to_string().contains("rolling") && !full_law["rolling"].is_null(),
        "{full_law}"
    );
    assert!(law["rolling"].is_null(), "{law}");
    assert_eq!(light.simplified, ["no-rolling (asked)", "f32 (asked)"]);
    let e = format!(
        "{:#}",
        load(&base, &set("simplify", "no-rate-sensitivity")).unwrap_err()
    );
    assert!(
        e.contains("reduced-shear-cell.toml") && e.contains("not rate-sensitive"),
        "{e}"
    );
}

/// The extruder's family: `short-lubrication` cuts the lubrication at 0.01 d_ij, and
/// `minimal = true` applies what scenes/ness2017/minimal.csv shows harmless for an extruder
/// (measured: nothing, docs/minimal.md).
#[test]
fn an_extruder_scene_takes_its_own_table_and_the_lubrication_cut() {
    let ness = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/ness2017");
    let base = ness.join("reduced.toml");
    let full = load(&base, &Default::default()).unwrap();
    assert_eq!(full.scene.suspension.as_ref().unwrap().h_max, 0.05);
    let short = load(&base, &set("simplify", "short-lubrication")).unwrap();
    assert_eq!(short.scene.suspension.as_ref().unwrap().h_max, 0.01);
    assert_eq!(short.simplified, ["short-lubrication (asked)"]);
    let mut minimal = toml::Table::new();
    let mut inner = toml::Table::new();
    inner.insert("minimal".into(), toml::Value::Boolean(true));
    minimal.insert("scene".into(), toml::Value::Table(inner));
    let l = load(&base, &minimal).unwrap();
    let table = ness.join("minimal.csv");
    assert_eq!(l.minimal_table.as_deref(), Some(table.as_path()));
    let want: Vec<&str> = harmless_for(&read_verdicts(&table).unwrap(), "extruder")
        .iter()
        .map(|s| s.name)
        .collect();
    let got: Vec<&str> = l
        .simplified
        .iter()
        .map(|g| g.split(' ').next().unwrap_or(""))
        .collect();
    assert_eq!(got, want, "{:?}", l.simplified);
    assert_eq!(l.scene.suspension.as_ref().unwrap().h_max, 0.05);
}
