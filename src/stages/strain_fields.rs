//! Strain and pressure fields of a run on a grid of pixels in mean grain diameters, shared by
//! the `analyse`, `compare` and `matrix` stages so every figure is made by one operator: grain
//! centroids → Delaunay triangles of the reference snapshot → each triangle's displacement
//! gradient → pixels → the √10 d̄ REV mean of the radiograph stage (`lbdem_analysis`).
//!
//! All positions are first put in the push-plate's frame in units of d̄ (`run_data::Frame`), so
//! grids, ROIs and fields line up with a radiograph aligned on the same plate.

use super::run_data::{Frame, Grains, Run};
use anyhow::{Context, Result, bail};
use lbdem_analysis::P2;
use lbdem_analysis::mesh::Mesh;
use lbdem_analysis::raster::{self, Grid};
use lbdem_analysis::strain::{self, TriangleStrain};
use ndarray::Array2;
use serde::{Deserialize, Serialize};

/// How the strain is measured: triangulation, pixels and REV (the parameters every stage that
/// measures strain shares).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StrainOptions {
    /// Triangles with an edge longer than this many d̄ are dropped (they span voids along a
    /// concave outline).
    #[serde(default = "d::max_edge")]
    pub max_edge_d: f64,
    /// Pixels per d̄ of the grid the triangle fields are painted on.
    #[serde(default = "d::pixels_per_d")]
    pub pixels_per_d: f64,
    /// REV side = rev_factor × d̄ (Su et al. 2020: √10).
    #[serde(default = "d::sqrt10")]
    pub rev_factor: f64,
    /// A REV window needs this fraction of its pixels inside the mesh.
    #[serde(default = "d::half")]
    pub min_valid: f64,
    /// Where each triangle's strain is drawn: where the grains are in the deformed snapshot
    /// (default; what a radiograph's fixed pixels see, Eq. 5) or where they were at the start.
    #[serde(default)]
    pub paint_on: Configuration,
}

/// The configuration a triangle field is painted in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Configuration {
    #[default]
    Deformed,
    Reference,
}

impl Default for StrainOptions {
    fn default() -> Self {
        Self {
            max_edge_d: d::max_edge(),
            pixels_per_d: d::pixels_per_d(),
            rev_factor: d::sqrt10(),
            min_valid: d::half(),
            paint_on: Configuration::Deformed,
        }
    }
}

pub mod d {
    pub fn max_edge() -> f64 {
        3.0
    }
    pub fn pixels_per_d() -> f64 {
        8.0
    }
    pub fn sqrt10() -> f64 {
        10f64.sqrt()
    }
    pub fn half() -> f64 {
        0.5
    }
}

impl StrainOptions {
    pub fn check(&self) -> Result<()> {
        for (n, v) in [
            ("max_edge_d", self.max_edge_d),
            ("pixels_per_d", self.pixels_per_d),
            ("rev_factor", self.rev_factor),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                bail!("parameter '{n}' = {v} must be positive and finite");
            }
        }
        if !(self.min_valid > 0.0 && self.min_valid <= 1.0) {
            bail!("parameter 'min_valid' = {} must be in (0, 1]", self.min_valid);
        }
        Ok(())
    }
}

/// The reference state of the strain: the grains, the mesh over them and the grid.
pub struct Setup {
    pub frame: Frame,
    pub ref_pts: Vec<P2>,
    pub mesh: Mesh,
    pub grid: Grid,
    owner: Array2<u32>,
    pub rev_side: usize,
    pub min_valid: f64,
    pub paint_on: Configuration,
}

/// The strain between the reference and one deformed snapshot.
pub struct Fields {
    pub strains: Vec<TriangleStrain>,
    /// REV means (sliding window) of ε_xx + ε_yy, ε_xy and the rotation, and the triangles' Eq. 5:
    /// the area ratio of the material in each REV minus one.
    pub eps_vol: Array2<f64>,
    pub eps_xy: Array2<f64>,
    pub rotation: Array2<f64>,
    pub eps_area: Array2<f64>,
    /// Area-weighted mean gradient and area ratio of the whole mesh.
    pub mean: TriangleStrain,
    pub mesh_area_ratio: f64,
}

impl Setup {
    /// A setup on `reference` in `frame`, with the grid over `fov` = [x0, x1, y0, y1] (d̄), or
    /// over the reference grains when `None`.
    pub fn new(reference: &Grains, frame: Frame, fov: Option<[f64; 4]>, o: &StrainOptions) -> Result<Self> {
        o.check()?;
        let ref_pts: Vec<P2> = reference.centroid.iter().map(|&p| frame.from_scene(p)).collect();
        let mesh = Mesh::delaunay(&ref_pts, o.max_edge_d).context("triangulating the reference grains")?;
        let [x0, x1, y0, y1] = match fov {
            Some(f) => f,
            None => {
                let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
                for p in &ref_pts {
                    for k in 0..2 {
                        lo[k] = lo[k].min(p[k]);
                        hi[k] = hi[k].max(p[k]);
                    }
                }
                [lo[0], hi[0], lo[1], hi[1]]
            }
        };
        let grid = Grid::cover(x0, y0, x1, y1, 1.0 / o.pixels_per_d)
            .with_context(|| format!("field of view [x0, x1, y0, y1] = {:?} (d̄)", [x0, x1, y0, y1]))?;
        Self::with_grid(ref_pts, mesh, frame, grid, o)
    }

    /// A setup on `reference` whose fields fill `grid` (d̄, in `frame`): the grid of a
    /// radiograph aligned on the same plate, so both sides share every pixel and the REV.
    pub fn on_grid(reference: &Grains, frame: Frame, grid: Grid, o: &StrainOptions) -> Result<Self> {
        o.check()?;
        let ref_pts: Vec<P2> = reference.centroid.iter().map(|&p| frame.from_scene(p)).collect();
        let mesh = Mesh::delaunay(&ref_pts, o.max_edge_d).context("triangulating the reference grains")?;
        Self::with_grid(ref_pts, mesh, frame, grid, o)
    }

    fn with_grid(ref_pts: Vec<P2>, mesh: Mesh, frame: Frame, grid: Grid, o: &StrainOptions) -> Result<Self> {
        let rev_side = raster::rev_side(o.rev_factor, 1.0, grid.dx)?;
        if rev_side > grid.nx.min(grid.ny) {
            bail!(
                "the REV ({} d̄ = {rev_side} cells of {:.3} d̄) is larger than the field of view ({} x {} cells = \
                 {:.1} x {:.1} d̄); widen 'fov' or lower 'rev_factor'",
                o.rev_factor,
                grid.dx,
                grid.nx,
                grid.ny,
                grid.nx as f64 * grid.dx,
                grid.ny as f64 * grid.dx
            );
        }
        let owner = raster::locate(&grid, &mesh, &ref_pts);
        Ok(Self {
            frame,
            ref_pts,
            mesh,
            grid,
            owner,
            rev_side,
            min_valid: o.min_valid,
            paint_on: o.paint_on,
        })
    }

    /// [x0, x1, y0, y1] of the grid (d̄), for figure axes.
    pub fn extent(&self) -> [f64; 4] {
        let g = &self.grid;
        [g.x0, g.x0 + g.nx as f64 * g.dx, g.y0, g.y1()]
    }

    /// The strain fields of `deformed` (the same grains as the reference).
    pub fn fields(&self, deformed: &Grains) -> Result<Fields> {
        let pts: Vec<P2> = deformed
            .centroid
            .iter()
            .map(|&p| self.frame.from_scene(p))
            .collect();
        let strains = strain::triangle_strains(&self.mesh, &self.ref_pts, &pts)?;
        let deformed_owner;
        let owner = match self.paint_on {
            Configuration::Reference => &self.owner,
            Configuration::Deformed => {
                deformed_owner = raster::locate(&self.grid, &self.mesh, &pts);
                &deformed_owner
            }
        };
        let rev = |f: &dyn Fn(&TriangleStrain) -> f64| -> Result<Array2<f64>> {
            let v: Vec<f64> = strains.iter().map(f).collect();
            Ok(raster::rev_mean(
                &raster::paint(owner, &v),
                self.rev_side,
                self.min_valid,
            )?)
        };
        Ok(Fields {
            eps_vol: rev(&|s| s.eps_vol())?,
            eps_xy: rev(&|s| s.eps_xy())?,
            rotation: rev(&|s| s.rotation())?,
            // Eq. 5 is a ratio of REV sums: the window's present area over the reference area of
            // the material in it. Painted where the grains are now, that is 1 / REV(1/J); painted
            // where they were, REV(J). (A REV mean of J − 1 on the deformed configuration would
            // weight dilated triangles by their larger area and read high.)
            eps_area: match self.paint_on {
                Configuration::Deformed => rev(&|s| 1.0 / s.area_ratio())?.mapv(|m| 1.0 / m - 1.0),
                Configuration::Reference => rev(&|s| s.area_ratio())?.mapv(|m| m - 1.0),
            },
            mean: strain::mean_gradient(&self.mesh, &strains),
            mesh_area_ratio: strain::mesh_area_ratio(&self.mesh, &strains),
            strains,
        })
    }

    /// Centres of the grid's pixels in scene coordinates (m), row by row.
    pub fn scene_point(&self, row: usize, col: usize) -> P2 {
        let c = self.grid.centre(row, col);
        self.frame.to_scene(c[0], c[1])
    }
}

/// The liquid pressure change Δp (Pa, Su Eq. 19) of the run's fluid snapshot at `step` on the
/// setup's grid (the node under each pixel; NaN where no liquid or off the lattice), or `None`
/// when the run wrote no fluid snapshot then.
pub fn pressure_on_grid(run: &Run, step: u64, s: &Setup) -> Result<Option<Array2<f64>>> {
    let Some(path) = run.file("fluid", step) else {
        return Ok(None);
    };
    let df = crate::report::table::read_table(&path)?;
    let col = |n: &str| crate::report::table::f64_column(&df, n, &path);
    let (x, y, p) = (col("x")?, col("y")?, col("pressure")?);
    let (i, j) = (
        crate::report::table::u64_column(&df, "i", &path)?,
        crate::report::table::u64_column(&df, "j", &path)?,
    );
    if x.len() < 2 {
        bail!("fluid snapshot {} holds fewer than two nodes", path.display());
    }
    let nx = i.iter().max().map_or(0, |m| *m as usize + 1);
    let ny = j.iter().max().map_or(0, |m| *m as usize + 1);
    // Node (i, j) sits at lo + (i + ½, j + ½) dx.
    let dx = if nx > 1 { x[1] - x[0] } else { y[nx] - y[0] };
    if dx.is_nan() || dx <= 0.0 || nx * ny != x.len() {
        bail!(
            "fluid snapshot {}: nodes are not a regular {nx} x {ny} lattice in i-fastest order",
            path.display()
        );
    }
    let lo = [x[0] - 0.5 * dx, y[0] - 0.5 * dx];
    let mut out = Array2::from_elem((s.grid.ny, s.grid.nx), f64::NAN);
    for ((r, c), v) in out.indexed_iter_mut() {
        let q = s.scene_point(r, c);
        let (fi, fj) = ((q[0] - lo[0]) / dx, (q[1] - lo[1]) / dx);
        if fi >= 0.0 && fj >= 0.0 && (fi as usize) < nx && (fj as usize) < ny {
            *v = p[fi as usize + nx * fj as usize];
        }
    }
    Ok(Some(out))
}
