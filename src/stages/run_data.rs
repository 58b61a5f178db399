//! A finished simulation run as the analysis stages read it (`analyse`, `compare`,
//! `synth-run`): its scene (for the push-plate), its `snapshots.csv` index, its `series.csv`,
//! and its particle snapshots turned into grains (one centroid, area and equivalent diameter per
//! clump). Everything comes from the files a run writes (docs/scenes.md, "What a run writes"):
//! analysis reads snapshots, never engines.

use crate::contract::{MANIFEST, StageContext, StageRecord};
use crate::report::table::{f64_column, read_table, u64_column};
use crate::scenes::schema::{Loaded, WallRef};
use crate::scenes::snapshot::{ParticleTable, read_contacts, read_particles};
use anyhow::{Context, Result, bail};
use lbdem_analysis::P2;
use polars::prelude::{BooleanChunked, DataFrame};
use std::path::{Path, PathBuf};

/// The index of a run's snapshot files (written by the snapshot observer).
pub const SNAPSHOT_INDEX: &str = "snapshots.csv";

/// The output directory of a run: an earlier stage of the pipeline by name (`"sim"` or
/// `"@sim"`), or a path.
pub fn locate(spec: &str, ctx: &StageContext) -> PathBuf {
    match ctx.earlier_stage(spec.trim_start_matches('@')) {
        Some(d) => d.to_path_buf(),
        None => ctx.resolve(Path::new(spec)),
    }
}

/// The manifest of the stage output `spec` names, as an input to hash: always for an earlier
/// stage of the pipeline (it exists by the time this stage runs), else only if it exists (so
/// that a wrong path gets the stage's own error, which says what is missing).
pub fn manifest_input(spec: &str, ctx: &StageContext) -> Option<PathBuf> {
    let m = locate(spec, ctx).join(MANIFEST);
    (ctx.earlier_stage(spec.trim_start_matches('@')).is_some() || m.is_file()).then_some(m)
}

/// The scene file a run recorded. `simulate` records it as given, relative to where it ran; when
/// that path does not lead to it from here, the same relative path under each directory that
/// holds the run (nearest first) is tried, and the first file with the bytes the run recorded
/// (its SHA-256) is the scene. Otherwise the recorded path, whose error says to give `scene`.
fn recorded_scene(dir: &Path, recorded: &crate::contract::InputHash) -> PathBuf {
    let path = &recorded.path;
    if path.is_absolute() || path.is_file() {
        return path.clone();
    }
    let Ok(dir) = dir.canonicalize() else {
        return path.clone();
    };
    dir.ancestors()
        .map(|a| a.join(path))
        .find(|p| crate::contract::hash_file(p).is_ok_and(|h| h.sha256 == recorded.sha256))
        .unwrap_or_else(|| path.clone())
}

/// One row of `snapshots.csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct SnapshotEntry {
    pub step: u64,
    pub time: f64,
    pub kind: String,
    pub file: PathBuf,
}

/// The push-plate of a shear-cell scene: its leading face a → b at t = 0 and its velocity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plate {
    pub a: P2,
    pub b: P2,
    pub velocity: P2,
}

impl Plate {
    /// Unit vector of the plate's motion.
    pub fn dir(&self) -> P2 {
        let n = self.velocity[0].hypot(self.velocity[1]);
        [self.velocity[0] / n, self.velocity[1] / n]
    }
    /// Unit vector along the face, to the right of the motion (x when the plate moves up).
    pub fn across(&self) -> P2 {
        let d = self.dir();
        [d[1], -d[0]]
    }
    /// The face's (left, right) corners after a displacement `u` (m) along the motion; left and
    /// right as seen looking along the motion.
    pub fn corners(&self, u: f64) -> (P2, P2) {
        let d = self.dir();
        let shift = |p: P2| [p[0] + u * d[0], p[1] + u * d[1]];
        let t = self.across();
        let (a, b) = (shift(self.a), shift(self.b));
        if (b[0] - a[0]) * t[0] + (b[1] - a[1]) * t[1] >= 0.0 {
            (a, b)
        } else {
            (b, a)
        }
    }
    /// Midpoint of the face at t = 0: the origin of the coordinates in d̄.
    pub fn origin(&self) -> P2 {
        [0.5 * (self.a[0] + self.b[0]), 0.5 * (self.a[1] + self.b[1])]
    }
    /// Width of the face (m).
    pub fn width(&self) -> f64 {
        (self.b[0] - self.a[0]).hypot(self.b[1] - self.a[1])
    }
}

/// Coordinates in mean grain diameters relative to the push-plate (Su Figs. 6-10 measure x and y
/// in d̄): origin at the middle of the plate's face before it moves, x along the face to the
/// right, y along the plate's motion. Without a plate: the lower-left corner of the grains'
/// bounding box and the axes of the scene.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub origin: P2,
    /// Unit vectors of the x and y axes (in the scene's coordinates).
    pub ex: P2,
    pub ey: P2,
    pub d_bar: f64,
}

impl Frame {
    pub fn new(origin: P2, ey: P2, d_bar: f64) -> Self {
        Self {
            origin,
            ex: [ey[1], -ey[0]],
            ey,
            d_bar,
        }
    }
    /// Scene coordinates (m) of a point at (x, y) d̄.
    pub fn to_scene(&self, x: f64, y: f64) -> P2 {
        let s = self.d_bar;
        [
            self.origin[0] + s * (x * self.ex[0] + y * self.ey[0]),
            self.origin[1] + s * (x * self.ex[1] + y * self.ey[1]),
        ]
    }
    /// (x, y) in d̄ of a scene point.
    pub fn from_scene(&self, p: P2) -> P2 {
        let (dx, dy) = (p[0] - self.origin[0], p[1] - self.origin[1]);
        [
            (dx * self.ex[0] + dy * self.ex[1]) / self.d_bar,
            (dx * self.ey[0] + dy * self.ey[1]) / self.d_bar,
        ]
    }
    /// Whether the axes are the scene's own (plate moving up): grids can then be laid out in
    /// scene coordinates directly.
    pub fn axis_aligned(&self) -> bool {
        (self.ey[0]).abs() < 1e-12 && self.ey[1] > 0.0
    }
}

/// A finished run: its directory, scene, snapshots and series.
pub struct Run {
    pub dir: PathBuf,
    pub scene: Loaded,
    pub snapshots: Vec<SnapshotEntry>,
    pub plate: Option<Plate>,
    series: Option<(PathBuf, polars::prelude::DataFrame)>,
    /// Whether the series holds rows of a settling before the shear (`[shear_cell] settle`).
    settled: bool,
}

/// One clump of a particle snapshot.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Grains {
    pub body: Vec<u64>,
    pub centroid: Vec<P2>,
    /// Area of the union of the clump's circles (m²).
    pub area: Vec<f64>,
    /// Lowest and highest extent of the clump's circles along y (m).
    pub y_lo: Vec<f64>,
    pub y_hi: Vec<f64>,
    /// 1 for membrane grains (Su Sect. 2.4).
    pub tag: Vec<u64>,
    /// The circles (x, y, r) of every clump, for rendering.
    pub circles: Vec<Vec<[f64; 3]>>,
}

/// Area of the union of two circles (exact).
fn union2(a: [f64; 3], b: [f64; 3]) -> f64 {
    let (r1, r2) = (a[2], b[2]);
    let d = (a[0] - b[0]).hypot(a[1] - b[1]);
    let pi = std::f64::consts::PI;
    let (a1, a2) = (pi * r1 * r1, pi * r2 * r2);
    if d >= r1 + r2 {
        return a1 + a2;
    }
    if d <= (r1 - r2).abs() {
        return a1.max(a2);
    }
    // Lens of the two circles.
    let c1 = ((d * d + r1 * r1 - r2 * r2) / (2.0 * d * r1))
        .clamp(-1.0, 1.0)
        .acos();
    let c2 = ((d * d + r2 * r2 - r1 * r1) / (2.0 * d * r2))
        .clamp(-1.0, 1.0)
        .acos();
    let lens = r1 * r1 * (c1 - c1.sin() * c1.cos()) + r2 * r2 * (c2 - c2.sin() * c2.cos());
    a1 + a2 - lens
}

impl Grains {
    /// Clumps of a particle table, in body order. The area of a clump is the union of its
    /// circles: exact for one and two circles (Su's grains), pairwise inclusion-exclusion beyond.
    pub fn of(t: &ParticleTable) -> Self {
        let mut g = Grains::default();
        for c in 0..t.body.len() {
            let circle = [t.x[c], t.y[c], t.r[c]];
            if g.body.last() != Some(&t.body[c]) {
                g.body.push(t.body[c]);
                g.centroid.push([t.body_x[c], t.body_y[c]]);
                g.tag.push(t.tag[c]);
                g.circles.push(Vec::new());
            }
            if let Some(v) = g.circles.last_mut() {
                v.push(circle);
            }
        }
        for cs in &g.circles {
            let pi = std::f64::consts::PI;
            let area = match cs.len() {
                1 => pi * cs[0][2] * cs[0][2],
                _ => {
                    let single: f64 = cs.iter().map(|c| pi * c[2] * c[2]).sum();
                    let mut overlap = 0.0;
                    for i in 0..cs.len() {
                        for j in i + 1..cs.len() {
                            let (ai, aj) = (pi * cs[i][2] * cs[i][2], pi * cs[j][2] * cs[j][2]);
                            overlap += ai + aj - union2(cs[i], cs[j]);
                        }
                    }
                    single - overlap
                }
            };
            g.area.push(area);
            g.y_lo
                .push(cs.iter().map(|c| c[1] - c[2]).fold(f64::INFINITY, f64::min));
            g.y_hi
                .push(cs.iter().map(|c| c[1] + c[2]).fold(f64::NEG_INFINITY, f64::max));
        }
        g
    }

    pub fn len(&self) -> usize {
        self.body.len()
    }

    pub fn is_empty(&self) -> bool {
        self.body.is_empty()
    }

    /// Mean equivalent-area diameter √(4A/π) of the grains that are not membrane grains (all of
    /// them if every grain is a membrane grain).
    pub fn d_bar(&self) -> f64 {
        let pick: Vec<f64> = self
            .area
            .iter()
            .zip(&self.tag)
            .filter(|(_, t)| **t == 0)
            .map(|(a, _)| *a)
            .collect();
        let v = if pick.is_empty() { self.area.clone() } else { pick };
        v.iter()
            .map(|a| (4.0 * a / std::f64::consts::PI).sqrt())
            .sum::<f64>()
            / v.len().max(1) as f64
    }

    /// Whether `other` holds the same clumps (same bodies and circle radii, in order).
    pub fn same_grains(&self, other: &Grains) -> bool {
        self.body == other.body
            && self.circles.len() == other.circles.len()
            && self
                .circles
                .iter()
                .zip(&other.circles)
                .all(|(a, b)| a.len() == b.len() && a.iter().zip(b).all(|(p, q)| p[2] == q[2]))
    }

    /// The polygon through the membrane grains' centroids (Su Sect. 2.5), ordered by angle about
    /// their mean in `order_from` (the reference snapshot: the ring is star-shaped there).
    pub fn membrane_ring(&self, order_from: &Grains) -> Vec<P2> {
        let idx: Vec<usize> = (0..order_from.len())
            .filter(|&k| order_from.tag[k] == 1)
            .collect();
        if idx.len() < 3 {
            return Vec::new();
        }
        let n = idx.len() as f64;
        let c = idx.iter().fold([0.0, 0.0], |s, &k| {
            [
                s[0] + order_from.centroid[k][0] / n,
                s[1] + order_from.centroid[k][1] / n,
            ]
        });
        let mut order = idx.clone();
        let angle = |k: usize| {
            let p = order_from.centroid[k];
            (p[1] - c[1]).atan2(p[0] - c[0])
        };
        order.sort_by(|&a, &b| angle(a).total_cmp(&angle(b)).then(a.cmp(&b)));
        order.iter().map(|&k| self.centroid[k]).collect()
    }
}

impl Run {
    /// Open the run in `dir` (the output directory of `lbdem simulate` or a `simulate` stage).
    /// `scene` overrides the scene file recorded in the run's manifest.
    pub fn open(dir: &Path, scene: Option<&Path>) -> Result<Self> {
        let manifest = dir.join(MANIFEST);
        let text = std::fs::read_to_string(&manifest).with_context(|| {
            format!(
                "{} is not a finished run: it has no {MANIFEST} (give the output directory of \
                 `lbdem simulate`, or the name of an earlier simulate stage)",
                dir.display()
            )
        })?;
        let rec: StageRecord = serde_json::from_str(&text)
            .with_context(|| format!("{} is not a stage manifest", manifest.display()))?;
        if rec.kind != "simulate" {
            bail!(
                "{} was written by a '{}' stage, not by 'simulate': give a simulation run",
                dir.display(),
                rec.kind
            );
        }
        let scene_path = match scene {
            Some(p) => p.to_path_buf(),
            None => recorded_scene(
                dir,
                rec.inputs.first().with_context(|| {
                    format!("{} lists no scene file among its inputs", manifest.display())
                })?,
            ),
        };
        let overrides: toml::Table = match rec.params.get("overrides") {
            Some(v) if !v.is_null() => serde_json::from_value(v.clone())
                .with_context(|| format!("{}: params.overrides is not a table", manifest.display()))?,
            _ => toml::Table::new(),
        };
        let scene = crate::scenes::schema::load(&scene_path, &overrides).with_context(|| {
            format!(
                "the scene of run {} ({}); if it moved, give its path as 'scene'",
                dir.display(),
                scene_path.display()
            )
        })?;
        let index = dir.join(SNAPSHOT_INDEX);
        let df = read_table(&index).with_context(|| format!("run {}: no snapshot index", dir.display()))?;
        let steps = u64_column(&df, "step", &index)?;
        let times = f64_column(&df, "time", &index)?;
        let col = |name: &str| -> Result<Vec<String>> {
            let c = df
                .column(name)
                .map_err(|_| anyhow::anyhow!("table {} has no column '{name}'", index.display()))?;
            Ok(c.str()?
                .iter()
                .map(|v| v.unwrap_or_default().to_string())
                .collect())
        };
        let (kinds, files) = (col("kind")?, col("file")?);
        let snapshots = (0..steps.len())
            .map(|k| SnapshotEntry {
                step: steps[k],
                time: times[k],
                kind: kinds[k].clone(),
                file: PathBuf::from(&files[k]),
            })
            .collect();
        let plate = plate_of(&scene)?;
        let sp = dir.join(crate::scenes::observers::SERIES_FILE);
        let (series, settled) = match read_table(&sp) {
            Ok(df) => {
                let (df, settled) = sheared_rows(df, &sp)?;
                (Some((sp.clone(), df)), settled)
            }
            Err(_) => (None, false),
        };
        Ok(Self {
            dir: dir.to_path_buf(),
            scene,
            snapshots,
            plate,
            series,
            settled,
        })
    }

    /// Steps with a particle snapshot, ascending.
    pub fn particle_steps(&self) -> Vec<u64> {
        let mut v: Vec<u64> = self
            .snapshots
            .iter()
            .filter(|s| s.kind == "particles")
            .map(|s| s.step)
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }

    /// The file of `kind` at `step`.
    pub fn file(&self, kind: &str, step: u64) -> Option<PathBuf> {
        self.snapshots
            .iter()
            .find(|s| s.kind == kind && s.step == step)
            .map(|s| self.dir.join(&s.file))
    }

    /// Time of the snapshot at `step`.
    pub fn time_of(&self, step: u64) -> f64 {
        self.snapshots
            .iter()
            .find(|s| s.step == step)
            .map_or(f64::NAN, |s| s.time)
    }

    /// The grains of the particle snapshot at `step`.
    pub fn grains(&self, step: u64) -> Result<Grains> {
        let f = self.file("particles", step).with_context(|| {
            format!(
                "run {} has no particle snapshot at step {step}",
                self.dir.display()
            )
        })?;
        Ok(Grains::of(&read_particles(&f)?))
    }

    /// Touching grain pairs (body indices into [`Grains`]) of the contact snapshot at `step`.
    pub fn contact_pairs(&self, step: u64, g: &Grains) -> Result<Vec<(usize, usize)>> {
        let Some(f) = self.file("contacts", step) else {
            return Ok(Vec::new());
        };
        let cs = read_contacts(&f)?;
        // Circle index -> grain index.
        let mut of_circle = Vec::new();
        for (k, c) in g.circles.iter().enumerate() {
            of_circle.extend(std::iter::repeat_n(k, c.len()));
        }
        Ok(cs
            .iter()
            .filter_map(|c| Some((*of_circle.get(c.i as usize)?, *of_circle.get(c.j as usize)?)))
            .collect())
    }

    /// The grains the run started from: the scene's particle file when it holds the same clumps
    /// (the run wrote no snapshot at step 0), else `None`.
    pub fn initial_grains(&self, like: &Grains) -> Option<Grains> {
        // After a settling the shear starts from the settled grains, not from the file. The
        // series says whether the run settled (its scene file may have changed since).
        if self.settled {
            return None;
        }
        let p = self.scene.scene.particles.as_ref()?.csv.as_ref()?;
        let path = self.scene.base_dir.join(p);
        if !path.is_file() {
            return None;
        }
        let g = Grains::of(&read_particles(&path).ok()?);
        g.same_grains(like).then_some(g)
    }

    /// A series column (None when the run did not record it).
    pub fn series(&self, name: &str) -> Option<Vec<f64>> {
        let (p, df) = self.series.as_ref()?;
        df.column(name).ok()?;
        f64_column(df, name, p).ok()
    }

    /// `name` of the series at `time` (linear interpolation between rows; the first or last
    /// value outside).
    pub fn series_at(&self, name: &str, time: f64) -> Option<f64> {
        let (t, v) = (self.series("time")?, self.series(name)?);
        interp(&t, &v, time)
    }

    /// Push-plate displacement (m) at `time` (0 without a plate).
    pub fn plate_displacement(&self, time: f64) -> f64 {
        if time <= 0.0 {
            return 0.0;
        }
        self.series_at("plate_displacement", time)
            .or_else(|| {
                let p = self.plate?;
                Some(time * p.velocity[0].hypot(p.velocity[1]))
            })
            .unwrap_or(0.0)
    }
}

/// A run's series as everything after the run reads it: the rows after the shear cell's
/// settling ([`sheared_rows`]).
pub fn read_series(path: &Path) -> Result<DataFrame> {
    Ok(sheared_rows(read_table(path)?, path)?.0)
}

/// The rows of a run's series after the shear cell's settling (`settling` = 0): the analysis
/// measures the shear, from the settled state on (`[shear_cell] settle`); and whether there
/// were settling rows.
fn sheared_rows(df: DataFrame, path: &Path) -> Result<(DataFrame, bool)> {
    if df.column("settling").is_err() {
        return Ok((df, false));
    }
    let settling = f64_column(&df, "settling", path)?;
    let keep: BooleanChunked = settling.iter().map(|&v| v == 0.0).collect();
    let settled = settling.iter().any(|&v| v != 0.0);
    let df = df
        .filter(&keep)
        .with_context(|| format!("cannot select the rows after the settling in {}", path.display()))?;
    Ok((df, settled))
}

/// Linear interpolation of (x, y) at `x0` (x ascending); clamped at the ends.
pub fn interp(x: &[f64], y: &[f64], x0: f64) -> Option<f64> {
    let n = x.len().min(y.len());
    if n == 0 {
        return None;
    }
    if x0 <= x[0] {
        return Some(y[0]);
    }
    for i in 1..n {
        if x0 <= x[i] {
            let f = (x0 - x[i - 1]) / (x[i] - x[i - 1]);
            return Some(y[i - 1] + f * (y[i] - y[i - 1]));
        }
    }
    Some(y[n - 1])
}

/// The push-plate of `[shear_cell]` (None without one).
fn plate_of(l: &Loaded) -> Result<Option<Plate>> {
    let s = &l.scene;
    let Some(sc) = &s.shear_cell else {
        return Ok(None);
    };
    let mut k = 0;
    for w in &s.walls {
        let n = if w.box_.is_some() { 4 } else { 1 };
        let hit = match &sc.plate {
            WallRef::Name(name) => w.name.as_deref() == Some(name.as_str()),
            WallRef::Index(i) => (k..k + n).contains(i),
        };
        if hit {
            let (Some(a), Some(b), Some(v)) = (w.a, w.b, w.velocity) else {
                bail!(
                    "scene {}: the [shear_cell] plate must be a segment wall with a and b and a velocity",
                    l.path.display()
                );
            };
            if v[0].hypot(v[1]) == 0.0 {
                bail!("scene {}: the [shear_cell] plate does not move", l.path.display());
            }
            return Ok(Some(Plate { a, b, velocity: v }));
        }
        k += n;
    }
    bail!(
        "scene {}: [shear_cell] plate names no wall of [[walls]]",
        l.path.display()
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_circle_union_area() {
        let pi = std::f64::consts::PI;
        assert!((union2([0.0, 0.0, 1.0], [3.0, 0.0, 1.0]) - 2.0 * pi).abs() < 1e-12);
        assert!((union2([0.0, 0.0, 1.0], [0.1, 0.0, 2.0]) - 4.0 * pi).abs() < 1e-12);
        // Two unit circles one radius apart: 2π - lens, lens = 2π/3 - √3/2.
        let lens = 2.0 * pi / 3.0 - 3f64.sqrt() / 2.0;
        assert!((union2([0.0, 0.0, 1.0], [1.0, 0.0, 1.0]) - (2.0 * pi - lens)).abs() < 1e-12);
    }

    /// A run simulated in another directory records its scene relative to that directory; the
    /// scene is found under the directories holding the run, and only with the recorded bytes.
    #[test]
    fn a_run_finds_its_scene_from_another_directory_by_its_bytes() {
        let t = tempfile::tempdir().unwrap();
        let rel = Path::new("scenes-not-in-the-repo/cell.toml");
        let scene = t.path().join(rel);
        std::fs::create_dir_all(scene.parent().unwrap()).unwrap();
        std::fs::write(&scene, "[scene]\nname = \"cell\"\n").unwrap();
        let run = t.path().join("runs/cell");
        std::fs::create_dir_all(&run).unwrap();
        let mut recorded = crate::contract::hash_file(&scene).unwrap();
        recorded.path = rel.to_path_buf();
        assert!(
            !rel.is_file(),
            "the test needs a path that does not exist from the working directory"
        );
        assert_eq!(recorded_scene(&run, &recorded), scene.canonicalize().unwrap());
        // The same path with other bytes is another scene: the recorded path comes back, and
        // opening it fails with the message that says to give `scene`.
        std::fs::write(&scene, "[scene]\nname = \"changed\"\n").unwrap();
        assert_eq!(recorded_scene(&run, &recorded), rel);
    }

    #[test]
    fn plate_frame_round_trip() {
        let p = Plate {
            a: [3.0, 1.0],
            b: [5.0, 1.0],
            velocity: [0.0, 2.0],
        };
        assert_eq!(p.corners(0.5), ([3.0, 1.5], [5.0, 1.5]));
        let f = Frame::new(p.origin(), p.dir(), 0.5);
        assert!(f.axis_aligned());
        assert_eq!(f.from_scene([5.0, 2.0]), [2.0, 2.0]);
        assert_eq!(f.to_scene(2.0, 2.0), [5.0, 2.0]);
        assert_eq!(interp(&[0.0, 1.0, 2.0], &[0.0, 10.0, 30.0], 1.5), Some(20.0));
        assert_eq!(interp(&[0.0, 1.0], &[1.0, 2.0], 5.0), Some(2.0));
    }
}
