//! The assembly file (`lbdem assemble`, Su et al. 2020 Sect. 2.4): `assembly.csv` (grain_id,x,y,r:
//! one row per circle, metres, the digitise export's format) and `assembly.json` beside it, the
//! header that says which grain set it holds and what the protocol measured. A scene starts
//! from it with `[particles] assembly = { file, grains, d }`; the header is checked against what
//! the scene expects, so a case cannot silently run on another case's grains.

use super::particles_csv;
use anyhow::{Context, Result, bail};
use lbdem_dem::Bodies;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The value of `format` in every assembly header.
pub const FORMAT: &str = "lbdem-assembly";

/// What grains an assembly was built from: the recipe's request, before any packing change.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GrainSet {
    /// Grains asked for (Su Table 2, N^DEM).
    pub count: usize,
    /// d_min, d̄, d_max asked for (Su Table 2), m; absent for a digitised microstructure.
    pub d: Option<[f64; 3]>,
    /// Where the shapes came from: "table", a templates file or a microstructure file.
    pub source: String,
}

/// `assembly.json`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct AssemblyHeader {
    pub format: String,
    /// Column units of the CSV (read by the particle reader).
    pub units: String,
    pub grain_set: GrainSet,
    /// Grains in the file (after deleting or adding grains).
    pub grains: usize,
    pub circles: usize,
    /// The sample box, m: [x0, y0, x1, y1].
    pub sample: [f64; 4],
    /// Grain area over the sample box's area (Su's %PK / 100).
    pub packing_fraction: f64,
    /// Equivalent diameters of the grains in the file, m.
    pub d_min: f64,
    pub d_mean: f64,
    pub d_max: f64,
    /// Mean contact force magnitude before deformation under the run's elastic law (Su Table 1,
    /// F_0), N, and the number of contacts it averages.
    pub f_0: f64,
    pub contacts: usize,
    pub membrane_grains: usize,
    /// The recipe (parameters) that made it, for provenance.
    pub recipe: serde_json::Value,
}

/// The header beside an assembly CSV: `NAME.json` for `NAME.csv`.
pub fn header_path(csv: &Path) -> PathBuf {
    csv.with_extension("json")
}

/// What a scene expects of its assembly (`[particles] assembly`).
pub struct Expect<'a> {
    pub grains: usize,
    pub d: Option<[f64; 3]>,
    /// Where the expectation is written, for messages ("scenes/su2020/sim1.toml [particles]").
    pub from: &'a str,
}

/// Read an assembly and check that it holds the grain set the scene expects.
pub fn read_assembly(csv: &Path, density: f64, expect: &Expect) -> Result<(Bodies, AssemblyHeader)> {
    let hp = header_path(csv);
    if !csv.exists() {
        bail!(
            "{}: assembly file {} does not exist; make it with `lbdem assemble RECIPE.toml --out {}` \
             (docs/su2020.md, \"Assemblies\")",
            expect.from,
            csv.display(),
            csv.parent()
                .map_or_else(|| ".".into(), |p| p.display().to_string())
        );
    }
    let text = std::fs::read_to_string(&hp).with_context(|| {
        format!(
            "{}: assembly {} has no header {} (written by `lbdem assemble` beside the CSV); \
             rebuild the assembly, or read a bare particle file with `csv = ...`",
            expect.from,
            csv.display(),
            hp.display()
        )
    })?;
    let h: AssemblyHeader = serde_json::from_str(&text).with_context(|| {
        format!(
            "{}: not an assembly header written by `lbdem assemble`",
            hp.display()
        )
    })?;
    if h.format != FORMAT {
        bail!("{}: format {:?}, expected {FORMAT:?}", hp.display(), h.format);
    }
    if h.grain_set.count != expect.grains {
        bail!(
            "{}: the scene expects the grain set of {} grains, but {} was built from {} grains ({}): \
             it is another case's assembly; point `assembly.file` at the right one or fix `assembly.grains`",
            expect.from,
            expect.grains,
            csv.display(),
            h.grain_set.count,
            h.grain_set.source
        );
    }
    if let Some(d) = expect.d {
        let same = h
            .grain_set
            .d
            .is_some_and(|hd| hd.iter().zip(d).all(|(a, b)| (a - b).abs() <= 1e-9 * b.abs()));
        if !same {
            bail!(
                "{}: the scene expects grain sizes d_min:d:d_max = {:?} m, but {} was built for {:?}: \
                 it is another case's assembly; point `assembly.file` at the right one or fix `assembly.d`",
                expect.from,
                d,
                csv.display(),
                h.grain_set.d
            );
        }
    }
    let bodies = particles_csv::read_csv(csv, density)?;
    if bodies.len() != h.grains {
        bail!(
            "{}: holds {} grains but its header {} says {}; the pair is damaged, rebuild it with `lbdem assemble`",
            csv.display(),
            bodies.len(),
            hp.display(),
            h.grains
        );
    }
    Ok((bodies, h))
}
