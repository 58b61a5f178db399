//! Model no more than a scene needs (issue 16 item 3): the physics a scene can switch off or
//! simplify by name, `[scene] simplify = ["no-rolling", "f32"]`, and `[scene] minimal = true`,
//! which applies every simplification the scene family's table (`minimal.csv`, written by the
//! `minimal-models` stage from measured runs, docs/minimal.md) shows harmless.
//!
//! Each simplification is an edit of the scene's merged TOML table, made before the scene is
//! checked and parsed, so a simplified scene passes the same checks as one written by hand, and
//! one that does not fit the scene (no rolling resistance to remove) is refused with the reason.

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use toml::Value;

/// The plate rate at which `no-rate-sensitivity` holds the yield force (m/s): Su et al. 2020
/// Fig. 11 runs without the strain-rate sensitivity of Eq. 6 but does not say at which rate F_y
/// is held; the scenes under scenes/su2020/fig11-* take the 30 µm/s row of Table 1.
pub const FIXED_YIELD_RATE: f64 = 30.0e-6;

/// The solid-map tolerance `remap` sets (cells): δ = 0.05 is the value the CI test
/// `keeping_the_solid_map_within_a_twentieth_of_a_cell_leaves_the_results_unchanged` checks.
pub const REMAP_CELLS: f64 = 0.05;

/// The lubrication cut `short-lubrication` sets (in d_ij): a fifth of Ness et al.'s 0.05 d_ij
/// (Sect. "Lubrication"), ten times their h_min. Pairs between the two gaps exchange lubrication
/// forces below a tenth of those at the smallest gap (Eq. 3 goes as 1/h).
pub const SHORT_LUBRICATION: f64 = 0.01;

/// One simplification: its name in scene files and tables, what it leaves out, and the edit.
pub struct Simplification {
    pub name: &'static str,
    pub what: &'static str,
    edit: fn(&mut toml::Table) -> Result<(), String>,
}

/// Every simplification, in the order they are applied.
pub const CATALOGUE: &[Simplification] = &[
    Simplification {
        name: "no-liquid",
        what: "the liquid off: the grains alone (Su Fig. 11, right column; [coupling] liquid = false)",
        edit: no_liquid,
    },
    Simplification {
        name: "no-rate-sensitivity",
        what: "F_y held at its 30 µm/s value of Eq. 6 whatever the plate rate, the membrane's F_N = 0.25 F_y with it (Su Fig. 11, centre column)",
        edit: no_rate_sensitivity,
    },
    Simplification {
        name: "no-rolling",
        what: "no rolling resistance between grains ([contact] rolling removed)",
        edit: no_rolling,
    },
    Simplification {
        name: "dry-membrane",
        what: "the membrane grains do not feel the liquid ([coupling] dry_membrane = true)",
        edit: dry_membrane,
    },
    Simplification {
        name: "f32",
        what: "32-bit lattice populations ([lattice] precision = \"f32\")",
        edit: f32_populations,
    },
    Simplification {
        name: "remap",
        what: "a grain's solid fraction recomputed only once it moved 0.05 cells ([coupling] remap_tolerance = 0.05)",
        edit: remap,
    },
    Simplification {
        name: "short-lubrication",
        what: "lubrication only across gaps below 0.01 d_ij instead of Ness et al.'s 0.05 d_ij ([suspension] h_max = 0.01)",
        edit: short_lubrication,
    },
    Simplification {
        name: "monolayer",
        what: "the extruder as one layer of grains (2D disks) instead of the periodic slab, its thickness from the paste (lbdem_dem::spheres::extruder::monolayer_thickness; [extruder] monolayer = true, depth = D)",
        edit: monolayer,
    },
    Simplification {
        name: "coarser-dem-step",
        what: "twice the DEM step, half as many DEM steps per LBM step ([dem] dt x 2)",
        edit: coarser_dem_step,
    },
];

/// The simplification named `name`.
pub fn find(name: &str) -> Option<&'static Simplification> {
    CATALOGUE.iter().find(|s| s.name == name)
}

fn names() -> String {
    CATALOGUE.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
}

fn section<'a>(t: &'a mut toml::Table, name: &str) -> Option<&'a mut toml::Table> {
    t.get_mut(name).and_then(Value::as_table_mut)
}

/// `[coupling]`, made empty if the scene has none.
fn coupling(t: &mut toml::Table) -> Result<&mut toml::Table, String> {
    t.entry("coupling")
        .or_insert_with(|| Value::Table(toml::Table::new()))
        .as_table_mut()
        .ok_or_else(|| "[coupling] is not a table".into())
}

/// Grains in a liquid that is on (`no-liquid` applied first leaves nothing for the liquid's
/// simplifications to do).
fn coupled(t: &toml::Table) -> bool {
    let liquid_on = t
        .get("coupling")
        .and_then(|c| c.get("liquid"))
        .and_then(Value::as_bool)
        .unwrap_or(true);
    t.contains_key("particles") && t.contains_key("fluid") && liquid_on
}

/// Ok for grains in a liquid that is on, else why not.
fn need_liquid(t: &toml::Table) -> Result<(), String> {
    match (t.contains_key("particles") && t.contains_key("fluid"), coupled(t)) {
        (_, true) => Ok(()),
        (true, false) => Err("the liquid is off".into()),
        (false, _) => Err("the scene has no liquid and grains together ([fluid] and [particles])".into()),
    }
}

fn no_liquid(t: &mut toml::Table) -> Result<(), String> {
    need_liquid(t)?;
    let c = coupling(t)?;
    c.insert("liquid".into(), Value::Boolean(false));
    Ok(())
}

fn no_rate_sensitivity(t: &mut toml::Table) -> Result<(), String> {
    let contact = section(t, "contact").ok_or("the scene has no [contact]")?;
    let f_y = contact
        .get_mut("f_y")
        .and_then(Value::as_table_mut)
        .ok_or("[contact] f_y is not rate-sensitive (give f_y = { f_0, rate }, Eq. 6)")?;
    let f_0 = f_y
        .get("f_0")
        .and_then(Value::as_float)
        .ok_or("[contact] f_y has no number f_0")?;
    let rate = f_y
        .get("rate")
        .and_then(Value::as_float)
        .ok_or("[contact] f_y has no number rate")?;
    let (before, after) = (
        lbdem_dem::contact::plastic::su_yield_force(f_0, rate),
        lbdem_dem::contact::plastic::su_yield_force(f_0, FIXED_YIELD_RATE),
    );
    f_y.insert("rate".into(), Value::Float(FIXED_YIELD_RATE));
    // Table 1: the membrane's inward force is a quarter of F_y; it follows F_y.
    if let Some(m) = section(t, "membrane")
        && let Some(f) = m.get("force").and_then(Value::as_float)
    {
        m.insert("force".into(), Value::Float(f * after / before));
    }
    Ok(())
}

fn no_rolling(t: &mut toml::Table) -> Result<(), String> {
    let contact = section(t, "contact").ok_or("the scene has no [contact]")?;
    contact
        .remove("rolling")
        .map(|_| ())
        .ok_or_else(|| "[contact] has no rolling resistance to remove".into())
}

fn dry_membrane(t: &mut toml::Table) -> Result<(), String> {
    need_liquid(t)?;
    if !t.contains_key("membrane") {
        return Err("the scene has no [membrane]".into());
    }
    let c = coupling(t)?;
    c.insert("dry_membrane".into(), Value::Boolean(true));
    Ok(())
}

fn f32_populations(t: &mut toml::Table) -> Result<(), String> {
    if t.contains_key("particles") {
        need_liquid(t)?;
    }
    let l = section(t, "lattice").ok_or("the scene has no [lattice]")?;
    if l.get("precision").and_then(Value::as_str) == Some("f32") {
        return Err("[lattice] precision is f32 already".into());
    }
    l.insert("precision".into(), Value::String("f32".into()));
    Ok(())
}

fn remap(t: &mut toml::Table) -> Result<(), String> {
    need_liquid(t)?;
    let c = coupling(t)?;
    if c.get("method").and_then(Value::as_str) == Some("bounce-back") {
        return Err("remap_tolerance is for PSM; [coupling] method is bounce-back".into());
    }
    let now = c.get("remap_tolerance").and_then(Value::as_float).unwrap_or(0.0);
    if now >= REMAP_CELLS {
        return Err(format!("[coupling] remap_tolerance is {now} already"));
    }
    c.insert("remap_tolerance".into(), Value::Float(REMAP_CELLS));
    Ok(())
}

fn coarser_dem_step(t: &mut toml::Table) -> Result<(), String> {
    let dt = section(t, "dem")
        .and_then(|d| d.get("dt"))
        .and_then(Value::as_float)
        .ok_or("the scene has no [dem] dt")?;
    let lattice_dt = section(t, "lattice")
        .and_then(|l| l.get("dt"))
        .and_then(Value::as_float);
    if let Some(ldt) = lattice_dt
        && coupled(t)
    {
        let ratio = (ldt / (2.0 * dt)).round();
        if ratio < 1.0 || (ratio * 2.0 * dt - ldt).abs() > 1e-9 * ldt {
            return Err(format!(
                "[lattice] dt = {ldt} is not a whole multiple of twice [dem] dt = {dt}"
            ));
        }
    }
    let d = section(t, "dem").ok_or("the scene has no [dem]")?;
    d.insert("dt".into(), Value::Float(2.0 * dt));
    Ok(())
}

fn short_lubrication(t: &mut toml::Table) -> Result<(), String> {
    let s = section(t, "suspension").ok_or("the scene has no lubricated suspension ([suspension])")?;
    let h_max = s.get("h_max").and_then(Value::as_float).unwrap_or(0.05);
    if h_max <= SHORT_LUBRICATION {
        return Err(format!("[suspension] h_max is {h_max} already"));
    }
    let h_min = s.get("h_min").and_then(Value::as_float).unwrap_or(0.001);
    if h_min >= SHORT_LUBRICATION {
        return Err(format!(
            "[suspension] h_min = {h_min} is not below the short cut {SHORT_LUBRICATION}"
        ));
    }
    s.insert("h_max".into(), Value::Float(SHORT_LUBRICATION));
    Ok(())
}

fn monolayer(t: &mut toml::Table) -> Result<(), String> {
    let d = section(t, "suspension")
        .and_then(|s| s.get("diameters"))
        .and_then(Value::as_array)
        .and_then(|a| Some([a.first()?.as_float()?, a.get(1)?.as_float()?]))
        .ok_or("the scene has no [suspension] diameters = [d, 1.5 d]")?;
    let e = section(t, "extruder").ok_or("the scene has no [extruder]")?;
    if e.get("monolayer").and_then(Value::as_bool) == Some(true) {
        return Err("[extruder] monolayer is true already".into());
    }
    e.insert("monolayer".into(), Value::Boolean(true));
    let depth = lbdem_dem::spheres::extruder::monolayer_thickness(d);
    e.insert("depth".into(), Value::Float(depth));
    Ok(())
}

/// `simplify = "none"`, `"no-rolling+f32"` or `["no-rolling", "f32"]`: the names, checked.
pub fn parse_list(v: &Value) -> Result<Vec<&'static Simplification>, String> {
    let raw: Vec<String> = match v {
        Value::String(s) => s.split('+').map(|p| p.trim().to_string()).collect(),
        Value::Array(a) => a
            .iter()
            .map(|x| x.as_str().map(str::to_string))
            .collect::<Option<_>>()
            .ok_or("give names in quotes")?,
        _ => return Err("give a name, names joined by '+', or a list of names".into()),
    };
    let mut out = Vec::new();
    for n in raw.iter().filter(|n| n.as_str() != "none" && !n.is_empty()) {
        let s = find(n).ok_or_else(|| format!("'{n}' is not a simplification; known: {}", names()))?;
        if !out.iter().any(|o: &&Simplification| o.name == s.name) {
            out.push(s);
        }
    }
    Ok(out)
}

/// The family a scene belongs to in a minimal-model table: what it measures decides which
/// study applies to it.
pub fn family(t: &toml::Table) -> Option<&'static str> {
    if t.contains_key("shear_cell") {
        Some("shear-cell")
    } else if t.contains_key("packed_zone") {
        Some("float")
    } else if t.contains_key("extruder") {
        Some("extruder")
    } else {
        None
    }
}

/// A table row: a simplification measured for a family, and whether it was harmless there.
#[derive(Clone, Debug, PartialEq)]
pub struct Verdict {
    pub family: String,
    pub simplification: String,
    pub harmless: bool,
}

/// The rows of a minimal-model table (columns family, simplification, harmless).
pub fn read_verdicts(path: &Path) -> Result<Vec<Verdict>> {
    use crate::report::table::{read_table, str_column};
    let df = read_table(path)?;
    let family = str_column(&df, "family", path)?;
    let simp = str_column(&df, "simplification", path)?;
    let harmless = str_column(&df, "harmless", path)?;
    family
        .into_iter()
        .zip(simp)
        .zip(harmless)
        .map(|((family, simplification), h)| {
            let harmless = match h.as_str() {
                "true" => true,
                "false" => false,
                other => bail!(
                    "{}: harmless = {other:?} in the row of {simplification}; give true or false",
                    path.display()
                ),
            };
            Ok(Verdict {
                family,
                simplification,
                harmless,
            })
        })
        .collect()
}

/// The simplifications the table proves harmless for `family`: every row measured for it says
/// harmless (a simplification harmless on the reduced cell but not at the paper's scale is not).
pub fn harmless_for(verdicts: &[Verdict], family: &str) -> Vec<&'static Simplification> {
    CATALOGUE
        .iter()
        .filter(|s| {
            let rows: Vec<&Verdict> = verdicts
                .iter()
                .filter(|v| v.family == family && v.simplification == s.name)
                .collect();
            !rows.is_empty() && rows.iter().all(|v| v.harmless)
        })
        .collect()
}

/// What [`apply`] did: the names applied, each with why ("asked" or the table that proved it
/// harmless), or "not NAME: why" for one the table allows that does not fit the scene; and the
/// table read (an input of the run: a new table changes its key).
#[derive(Debug, Default)]
pub struct Applied {
    pub names: Vec<String>,
    pub table: Option<PathBuf>,
}

/// Apply `[scene] simplify` and `minimal` to the merged table of the scene at `path`.
pub fn apply(t: &mut toml::Table, path: &Path) -> Result<Applied> {
    let at = |m: String| anyhow::anyhow!("scene file {}: [scene] {m}", path.display());
    let header = t
        .get("scene")
        .and_then(Value::as_table)
        .cloned()
        .unwrap_or_default();
    let mut chosen: Vec<(&Simplification, String)> = Vec::new();
    let mut read = None;
    if let Some(v) = header.get("simplify") {
        for s in parse_list(v).map_err(|e| at(format!("simplify = {v}: {e}")))? {
            chosen.push((s, "asked".into()));
        }
    }
    match header.get("minimal") {
        None | Some(Value::Boolean(false)) => {}
        Some(Value::Boolean(true)) => {
            let rel = match header.get("minimal_table") {
                Some(Value::String(s)) => PathBuf::from(s),
                Some(v) => return Err(at(format!("minimal_table = {v}: give a file name in quotes"))),
                None => PathBuf::from("minimal.csv"),
            };
            let table = path.parent().unwrap_or(Path::new(".")).join(&rel);
            let fam = family(t).ok_or_else(|| {
                at(
                    "minimal = true: the minimal-model tables are per family of scenes (a shear cell, \
                    [shear_cell]; a float, [packed_zone]; an extruder, [extruder]) and this scene is none \
                    of them; list what to switch off in simplify = [...] instead"
                        .into(),
                )
            })?;
            if !table.is_file() {
                return Err(at(format!(
                    "minimal = true: the table {} is missing; write it with `lbdem run \
                     pipelines/minimal.toml` (docs/minimal.md) or name one with minimal_table = \"...\"",
                    table.display()
                )));
            }
            let verdicts = read_verdicts(&table).with_context(|| format!("scene file {}", path.display()))?;
            for s in harmless_for(&verdicts, fam) {
                if !chosen.iter().any(|(c, _)| c.name == s.name) {
                    chosen.push((s, format!("harmless for a {fam} in {}", table.display())));
                }
            }
            read = Some(table);
        }
        Some(v) => return Err(at(format!("minimal = {v}: give true or false"))),
    }
    chosen.sort_by_key(|(s, _)| CATALOGUE.iter().position(|c| c.name == s.name));
    let mut names = Vec::new();
    for (s, why) in chosen {
        // What the scene asked for must fit it; what a table proved harmless for its family
        // may not (no rate sensitivity to hold in a linear law) and is then left out, saying so.
        let mut trial = t.clone();
        match (s.edit)(&mut trial) {
            Ok(()) => {
                *t = trial;
                names.push(format!("{} ({why})", s.name));
            }
            Err(e) if why != "asked" => names.push(format!("not {}: {e}", s.name)),
            Err(e) => {
                return Err(at(format!(
                    "simplification '{}' does not fit this scene: {e}",
                    s.name
                )));
            }
        }
    }
    Ok(Applied { names, table: read })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table(s: &str) -> toml::Table {
        toml::from_str(s).unwrap()
    }

    const COUPLED: &str = r#"
        [particles]
        density = 1.0
        [contact]
        law = "plastic"
        f_y = { f_0 = 7.2e-9, rate = 0.00215 }
        rolling = { k_r = 1.0, mu_r = 0.5 }
        [membrane]
        force = 3.0e-9
        [dem]
        dt = 1.0e-7
        [fluid]
        density = 1.0
        [lattice]
        dt = 1.0e-4
        [shear_cell]
        plate = "plate"
    "#;

    #[test]
    fn each_simplification_edits_what_it_names() {
        let p = Path::new("s.toml");
        let mut t = table(COUPLED);
        t.insert(
            "scene".into(),
            Value::Table(table(
                r#"simplify = "no-rate-sensitivity+no-rolling+f32+remap+coarser-dem-step+dry-membrane""#,
            )),
        );
        let applied = apply(&mut t, p).unwrap().names;
        assert_eq!(applied.len(), 6, "{applied:?}");
        assert_eq!(t["coupling"]["dry_membrane"].as_bool(), Some(true));
        assert_eq!(t["coupling"]["remap_tolerance"].as_float(), Some(REMAP_CELLS));
        assert_eq!(t["contact"]["f_y"]["rate"].as_float(), Some(FIXED_YIELD_RATE));
        assert!(t["contact"].get("rolling").is_none());
        assert_eq!(t["lattice"]["precision"].as_str(), Some("f32"));
        assert_eq!(t["dem"]["dt"].as_float(), Some(2.0e-7));
        // Table 1: F_N = 0.25 F_y at both rates, so the membrane force follows F_y (Fig. 11
        // files: 3.02e-9 N at 2150 µm/s, 2.2e-9 N held at 30 µm/s).
        let f = t["membrane"]["force"].as_float().unwrap();
        let want =
            3.0e-9 * (7.2e-9 + 2.4e-8 * 30e-6f64.powf(0.26)) / (7.2e-9 + 2.4e-8 * 0.00215f64.powf(0.26));
        assert!((f - want).abs() < 1e-20 && (f - 2.19e-9).abs() < 0.01e-9, "{f}");
        // The liquid off: the grains alone, and nothing left for the liquid's simplifications.
        let mut t = table(COUPLED);
        t.insert("scene".into(), Value::Table(table(r#"simplify = ["no-liquid"]"#)));
        apply(&mut t, p).unwrap();
        assert_eq!(t["coupling"]["liquid"].as_bool(), Some(false));
        t.insert("scene".into(), Value::Table(table(r#"simplify = ["f32"]"#)));
        let e = apply(&mut t, p).unwrap_err().to_string();
        assert!(e.contains("the liquid is off"), "{e}");
    }

    #[test]
    fn short_lubrication_cuts_the_extruders_lubrication_and_refuses_where_it_cannot() {
        let p = Path::new("s.toml");
        let ext = "[extruder]\nbarrel_width = 1.0\n[suspension]\nh_min = 0.001\nh_max = 0.05\n";
        let mut t = table(ext);
        assert_eq!(family(&t), Some("extruder"));
        t.insert(
            "scene".into(),
            Value::Table(table(r#"simplify = ["short-lubrication"]"#)),
        );
        apply(&mut t, p).unwrap();
        assert_eq!(t["suspension"]["h_max"].as_float(), Some(SHORT_LUBRICATION));
        for (scene, want) in [
            (COUPLED, "no lubricated suspension"),
            ("[suspension]\nh_max = 0.01\n", "h_max is 0.01 already"),
            ("[suspension]\nh_min = 0.02\n", "h_min = 0.02 is not below"),
        ] {
            let mut t = table(scene);
            t.insert(
                "scene".into(),
                Value::Table(table(r#"simplify = ["short-lubrication"]"#)),
            );
            let e = apply(&mut t, p).unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
    }

    /// `monolayer` turns the slab into one layer of the paste's thickness (1.1779 d for d and
    /// 1.5 d: (2/3)(4.375/3.25) × 0.84/0.64), once, and only on an extruder.
    #[test]
    fn monolayer_makes_the_extruder_one_layer_of_the_pastes_thickness() {
        let p = Path::new("s.toml");
        let ext = "[scene]\nsimplify = \"monolayer\"\n[extruder]\ndepth = 5.0e-5\n[suspension]\ndiameters = [1.0e-5, 1.5e-5]\n";
        let mut t = table(ext);
        apply(&mut t, p).unwrap();
        assert_eq!(t["extruder"]["monolayer"].as_bool(), Some(true));
        let depth = t["extruder"]["depth"].as_float().unwrap();
        let want = 2.0 / 3.0 * (1.0 + 3.375) / (1.0 + 2.25) * 0.84 / 0.64 * 1e-5;
        assert!(
            (depth - want).abs() < 1e-18 && (depth - 1.17788e-5).abs() < 1e-10,
            "{depth}"
        );
        let e = apply(&mut t, p).unwrap_err().to_string();
        assert!(e.contains("monolayer is true already"), "{e}");
        let mut t = table(COUPLED);
        t.insert("scene".into(), Value::Table(table(r#"simplify = "monolayer""#)));
        let e = apply(&mut t, p).unwrap_err().to_string();
        assert!(e.contains("[suspension] diameters"), "{e}");
    }

    #[test]
    fn a_simplification_that_does_not_fit_is_refused_with_the_reason() {
        let p = Path::new("s.toml");
        for (simplify, edit, want) in [
            ("no-rolling", "", "no rolling resistance"),
            ("no-rate-sensitivity", "f_y = 1e-9", "not rate-sensitive"),
            ("coarser-dem-step", "dt = 3.0e-7", "whole multiple"),
            ("no-friction", "", "not a simplification; known: no-liquid"),
        ] {
            let mut t = table(COUPLED);
            let c = t["contact"].as_table_mut().unwrap();
            c.remove("rolling");
            if edit == "f_y = 1e-9" {
                c.insert("f_y".into(), Value::Float(1e-9));
            }
            if edit == "dt = 3.0e-7" {
                t["dem"]
                    .as_table_mut()
                    .unwrap()
                    .insert("dt".into(), Value::Float(3.0e-7));
            }
            t.insert(
                "scene".into(),
                Value::Table(table(&format!("simplify = [\"{simplify}\"]"))),
            );
            let e = apply(&mut t, p).unwrap_err().to_string();
            assert!(e.contains(want) && e.contains("s.toml"), "{simplify}: {e}");
        }
    }

    #[test]
    fn minimal_applies_what_every_row_of_the_family_shows_harmless() {
        let d = tempfile::tempdir().unwrap();
        std::fs::write(
            d.path().join("minimal.csv"),
            "family,study,simplification,harmless\n\
             shear-cell,reduced,no-rolling,true\n\
             shear-cell,paper,no-rolling,true\n\
             shear-cell,reduced,f32,true\n\
             shear-cell,paper,f32,false\n\
             shear-cell,reduced,no-liquid,false\n\
             shear-cell,paper,coarser-dem-step,true\n\
             float,reduced,remap,true\n",
        )
        .unwrap();
        let p = d.path().join("s.toml");
        let mut t = table(COUPLED);
        t.insert(
            "scene".into(),
            Value::Table(table("minimal = true\nsimplify = \"remap\"")),
        );
        // A DEM step the lattice step is not a multiple of twice: the table's harmless
        // coarser-dem-step does not fit, and is left out with the reason.
        t["dem"]
            .as_table_mut()
            .unwrap()
            .insert("dt".into(), Value::Float(3.0e-7));
        let a = apply(&mut t, &p).unwrap();
        assert_eq!(a.table, Some(d.path().join("minimal.csv")));
        let applied = a.names;
        assert_eq!(applied.len(), 3, "{applied:?}");
        assert!(
            applied[0].starts_with("no-rolling (harmless for a shear-cell in "),
            "{applied:?}"
        );
        assert_eq!(applied[1], "remap (asked)");
        assert!(
            applied[2].starts_with("not coarser-dem-step: ") && applied[2].contains("whole multiple"),
            "{applied:?}"
        );
        assert_eq!(t["dem"]["dt"].as_float(), Some(3.0e-7));
        assert_eq!(
            t["lattice"].get("precision"),
            None,
            "f32 failed at the paper's scale"
        );
        // A scene of no family, and a missing table, are refused with the fix.
        let mut t = table(COUPLED);
        t.remove("shear_cell");
        t.insert("scene".into(), Value::Table(table("minimal = true")));
        let e = apply(&mut t, &p).unwrap_err().to_string();
        assert!(
            e.contains("none of them") && e.contains("simplify = [...]"),
            "{e}"
        );
        let mut t = table(COUPLED);
        t.insert(
            "scene".into(),
            Value::Table(table("minimal = true\nminimal_table = \"gone.csv\"")),
        );
        let e = apply(&mut t, &p).unwrap_err().to_string();
        assert!(
            e.contains("gone.csv") && e.contains("pipelines/minimal.toml"),
            "{e}"
        );
    }
}
