//! Accuracy of the partially-saturated-cells coupling (Su et al. 2020 Eqs. 9-14) at the coarse
//! resolution of the paper: dx = 40 µm for grains of mean diameter d̄ = 120 µm, whose
//! hydrodynamic diameter (r_hd = 0.8, Su Sect. 2.3) is 0.8 · 120 / 40 = 2.4 cells. Two cases with
//! a reference, shared by `tests/low_resolution.rs` and `lbdem bench resolution` (no I/O):
//!
//! - **Disk array:** Stokes drag F/(μU) on a periodic square array of fixed disks against
//!   Sangani & Acrivos, Int. J. Multiphase Flow 8 (1982) 193, Table 1 (REFERENCES.md), and
//!   against the same case on a fine lattice. At a few cells per diameter the answer depends on
//!   where the disk sits relative to the nodes, so each resolution is run at several sub-cell
//!   offsets of the centre ([`offsets`]) and the mean and the spread are reported.
//! - **Packed two-circle grains:** the permeability k = μ⟨u⟩/g of a periodic box of 32
//!   two-circle grains at packing fraction π/4 ≈ 0.785 by area (close to Su's percolation limit,
//!   about 0.77, Sect. 3.3), mapped onto the lattice with r_hd = 0.8 so that the liquid
//!   percolates, driven by a uniform body force g; the reference is the same assembly on a fine
//!   lattice (there is no published value for it).
//!
//! In both cases the force balance is checked too: in steady state the Eq. 14 drag on the grains
//! must equal the body force put into the liquid, g Σ(1 − B) (B of Eq. 10).

use crate::error::CouplingError;
use crate::psm::{GrainMotion, Load, PsmFluid, PsmSettings};
use crate::solid_fraction::{GrainCircle, SolidMap, solid_map};
use crate::weighting::psm_weight;
use lbdem_dem::contact::LinearSpringDashpot;
use lbdem_dem::{Ball, ClumpShape, Damping, StepParams, Stepper, System, Vec2, generate};
use lbdem_lbm::{Collision, Domain, Limits};
use std::time::Instant;

/// Sangani & Acrivos 1982 Table 1 (square array, REFERENCES.md): (solid area fraction Φ,
/// F/(μU)), F the drag per unit length, U the superficial velocity.
pub const SANGANI_ACRIVOS_SQUARE: [(f64, f64); 6] = [
    (0.05, 15.56),
    (0.10, 24.83),
    (0.20, 51.53),
    (0.30, 102.90),
    (0.40, 217.89),
    (0.50, 532.55),
];

/// Sangani & Acrivos's F/(μU) at a tabulated Φ, or `None`.
pub fn sangani_acrivos(phi: f64) -> Option<f64> {
    SANGANI_ACRIVOS_SQUARE
        .iter()
        .find(|(p, _)| (p - phi).abs() < 1e-12)
        .map(|&(_, k)| k)
}

/// Gebart's F/(μU) for a square array at solid fraction Φ (J. Composite Mater. 26 (1992) 1100,
/// REFERENCES.md): the lubrication asymptote k = C₁R²(√(Φ_max/Φ) − 1)^{5/2}, C₁ = 16/(9π√2),
/// Φ_max = π/4, with F/(μU) = L²/k and L² = πR²/Φ. Exact toward close packing; at Φ = 0.4 and
/// 0.5 it lies 11.7 % and 8.7 % under Sangani & Acrivos's exact values, and the gap closes as Φ
/// grows. `None` outside (0, π/4).
pub fn gebart_square(phi: f64) -> Option<f64> {
    let max = std::f64::consts::FRAC_PI_4;
    if !(phi > 0.0 && phi < max) {
        return None;
    }
    let c1 = 16.0 / (9.0 * std::f64::consts::PI * std::f64::consts::SQRT_2);
    let k_over_r2 = c1 * ((max / phi).sqrt() - 1.0).powf(2.5);
    Some(std::f64::consts::PI / phi / k_over_r2)
}

/// Hydrodynamic radius factor of Su Sect. 2.3 (2D grains, so that the liquid percolates).
pub const R_HD: f64 = 0.8;
/// Cells per hydrodynamic diameter at Su's resolution: 0.8 · 120 µm / 40 µm.
pub const PAPER_CELLS: f64 = 2.4;

/// When a run counts as steady: the superficial velocity changes by less than `tol` (relative)
/// over `every` steps; `max_steps` bounds the run.
#[derive(Clone, Copy, Debug)]
pub struct Steady {
    pub every: usize,
    pub tol: f64,
    pub max_steps: usize,
}

impl Default for Steady {
    /// 1e-8 per 250 steps: on the finest lattices here (relaxation times of a few thousand
    /// steps) the remaining drift is below 1e-6 of U, far below the errors being measured.
    fn default() -> Self {
        Self {
            every: 250,
            tol: 1e-8,
            max_steps: 400_000,
        }
    }
}

/// Sub-cell offsets per axis worth running at `n` cells per diameter: below 10 cells the answer
/// depends on where the grain sits on the lattice (3 × 3 positions), up to 20 less (2 × 2).
pub fn offsets_at(n: f64) -> usize {
    if n <= 10.0 {
        3
    } else if n <= 20.0 {
        2
    } else {
        1
    }
}

/// `k` × `k` sub-cell offsets of a grain (or assembly) centre, evenly over one cell:
/// (i/k, j/k), i, j < k. k = 1 is the unshifted case.
pub fn offsets(k: usize) -> Vec<[f64; 2]> {
    let k = k.max(1);
    (0..k * k)
        .map(|m| [(m % k) as f64 / k as f64, (m / k) as f64 / k as f64])
        .collect()
}

/// One steady run: superficial velocity U (lattice units, mean over every node as Sangani &
/// Acrivos's U), Eq. 14 drag on all grains over the force on the liquid g Σ(1 − B), steps taken
/// and wall time.
struct SteadyFlow {
    u: f64,
    balance: f64,
    steps: usize,
    seconds: f64,
}

/// Drive the liquid through fixed grains (`map`, `motions`) on an nx × ny periodic lattice with
/// the body force g along x until steady.
fn steady_flow(
    nx: usize,
    ny: usize,
    map: &SolidMap,
    motions: &[GrainMotion],
    tau: f64,
    g: f64,
    steady: &Steady,
) -> Result<SteadyFlow, CouplingError> {
    let t0 = Instant::now();
    let settings = PsmSettings {
        collision: Collision::Bgk { tau },
        force: [g, 0.0],
        limits: Limits::default(),
    };
    let mut fluid = PsmFluid::<f64>::new(&Domain::periodic([nx, ny, 1]), settings)?;
    let mut loads: Vec<Load> = Vec::new();
    let mean_u = |f: &PsmFluid<f64>| f.u.iter().map(|u| u[0]).sum::<f64>() / f.u.len() as f64;
    let (mut last, mut steps) = (f64::NAN, 0);
    loop {
        for _ in 0..steady.every {
            fluid.step(map, motions, &mut loads)?;
        }
        steps += steady.every;
        let u = mean_u(&fluid);
        if ((u - last) / u).abs() < steady.tol {
            break;
        }
        if steps >= steady.max_steps {
            return Err(CouplingError::Unsupported(format!(
                "not steady after {steps} steps on {nx} x {ny} nodes (U changes by {:.2e} per {} steps, \
                 limit {:.1e}): raise Steady::max_steps",
                ((u - last) / u).abs(),
                steady.every,
                steady.tol
            )));
        }
        last = u;
    }
    let liquid: f64 = map.total.iter().map(|&e| 1.0 - psm_weight(e, tau)).sum();
    let drag: f64 = loads.iter().map(|l| l.force[0]).sum();
    Ok(SteadyFlow {
        u: mean_u(&fluid),
        balance: drag / (g * liquid),
        steps,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Body force (lattice units): small enough for Stokes flow (Re ≪ 1 on every lattice here).
const G: f64 = 1e-6;

/// One run of the disk array.
#[derive(Clone, Copy, Debug)]
pub struct ArrayRun {
    pub phi: f64,
    /// Nodes per side of the periodic cell (one disk per cell).
    pub cells: usize,
    /// Disk diameter in lattice cells (the actual cells per diameter: the period must be a whole
    /// number of cells, so it differs from the nominal one by up to half a cell over the period).
    pub diameter_cells: f64,
    pub offset: [f64; 2],
    /// F/(μU) = g L² / (ν U) (ρ = 1; F = G L² includes the pressure's share on the disk).
    pub drag: f64,
    /// Eq. 14 drag over g Σ(1 − B): 1 in steady state.
    pub balance: f64,
    pub steps: usize,
    pub seconds: f64,
}

/// Stokes drag on a square array of disks at solid fraction `phi` with about `cells_per_diameter`
/// cells across a disk, the centre shifted by `offset` (fractions of a cell) from a node corner.
/// The period is L = round(n √(π/(4Φ))) nodes and the diameter 2L√(Φ/π), so Φ is exact.
pub fn disk_array(
    phi: f64,
    cells_per_diameter: f64,
    offset: [f64; 2],
    tau: f64,
    steady: &Steady,
) -> Result<ArrayRun, CouplingError> {
    if !(phi > 0.0 && phi < std::f64::consts::FRAC_PI_4) {
        return Err(CouplingError::Unsupported(format!(
            "disk array at solid fraction {phi}: must be in (0, π/4) so that the disks do not touch"
        )));
    }
    let cells = ((cells_per_diameter * (std::f64::consts::PI / (4.0 * phi)).sqrt()).round() as usize).max(2);
    let l = cells as f64;
    let r = l * (phi / std::f64::consts::PI).sqrt();
    let centre = [0.5 * l + offset[0], 0.5 * l + offset[1]];
    let circles = [GrainCircle {
        body: 0,
        centre,
        radius: r,
    }];
    let map = solid_map(&circles, 1.0, cells, cells, [true, true]);
    let motions = [GrainMotion {
        centre,
        ..Default::default()
    }];
    let flow = steady_flow(cells, cells, &map, &motions, tau, G, steady)?;
    let nu = (tau - 0.5) / 3.0;
    Ok(ArrayRun {
        phi,
        cells,
        diameter_cells: 2.0 * r,
        offset,
        drag: G * l * l / (nu * flow.u),
        balance: flow.balance,
        steps: flow.steps,
        seconds: flow.seconds,
    })
}

/// A periodic assembly of two-circle grains in units of the mean grain diameter d̄ (the diameter
/// of the mean grain area: the box holds `n` grains of mean area π d̄²/4).
#[derive(Clone, Debug, PartialEq)]
pub struct Packing {
    /// Box [0, Lx] × [0, Ly] in d̄.
    pub size: [f64; 2],
    /// Per grain, its circles (centre, radius) in d̄ (full DEM radii; r_hd is applied on the
    /// lattice).
    pub grains: Vec<Vec<([f64; 2], f64)>>,
    /// Grain area over box area (overlaps of contacting grains counted twice; they are small).
    pub packing_fraction: f64,
}

/// Box of the packing in mean diameters: 4 × 8 d̄ holds lattices of whole cells at 2, 2.4, 3, 5,
/// 10, 20 and 40 cells per hydrodynamic diameter (nx = 4 n / r_hd = 5 n).
pub const PACKING_BOX: [f64; 2] = [4.0, 8.0];
/// Grains in the box: 32 grains of mean area π d̄²/4 in 32 d̄² give packing fraction π/4.
pub const PACKING_GRAINS: usize = 32;

/// Two templates of elongated two-circle grains like Su's (Fig. 1d; aspect ratios 1.5 and 1.3,
/// sizes about 1 : 1.25), in arbitrary units: the generator rescales to d̄.
fn templates() -> Vec<ClumpShape<Vec2>> {
    let two = |r1: f64, r2: f64, s: f64| ClumpShape {
        balls: vec![
            Ball {
                centre: Vec2::new(-0.5 * s, 0.0),
                r: r1,
            },
            Ball {
                centre: Vec2::new(0.5 * s, 0.0),
                r: r2,
            },
        ],
    };
    vec![two(0.40, 0.34, 0.46), two(0.50, 0.46, 0.38)]
}

/// The packed assembly of [`PACKING_GRAINS`] two-circle grains: random sequential insertion
/// (`lbdem_dem::generate::random_insert`, seeded) in a loose box, frictionless affine compression
/// of the periodic box to π/4 with viscous damping (`generate::compress_periodic`), relaxation,
/// then a uniform rescaling to [`PACKING_BOX`] in units of d̄. Deterministic for a seed.
pub fn two_circle_packing(seed: u64) -> Result<Packing, CouplingError> {
    let t = templates();
    let (lo, hi) = (Vec2::ZERO, Vec2::new(8.0, 16.0));
    let bodies = generate::random_insert(&t, &[1.0, 1.0], 1.0, lo, hi, PACKING_GRAINS, seed)?;
    let mut sys = System::new(bodies, lbdem_dem::Domain::periodic(lo, hi));
    let law = LinearSpringDashpot::new(2e4, 2e4 * 2.0 / 7.0, Damping::Gamma(100.0), 0.0);
    let mut p = StepParams::new(2.5e-4, 0.05);
    p.viscous_damping = 2.0;
    let mut st = Stepper::new();
    let target = std::f64::consts::FRAC_PI_4;
    generate::compress_periodic(&mut sys, &law, &p, target, 6000, &mut st)?;
    for _ in 0..4000 {
        st.step_linear(&p, &law, &mut sys)?;
    }
    let size = sys.domain.size();
    let s = PACKING_BOX[0] / size.x;
    let b = &sys.bodies;
    let grains = (0..b.len())
        .map(|k| {
            (b.circle_start[k]..b.circle_start[k + 1])
                .map(|c| {
                    let q = b.circle_pos(c) - sys.domain.lo;
                    ([q.x * s, q.y * s], b.circle_r[c] * s)
                })
                .collect()
        })
        .collect();
    Ok(Packing {
        size: [size.x * s, size.y * s],
        grains,
        packing_fraction: b.total_area() / (size.x * size.y),
    })
}

/// One run of the packing.
#[derive(Clone, Copy, Debug)]
pub struct PackingRun {
    pub nx: usize,
    pub ny: usize,
    /// Cells per hydrodynamic diameter, r_hd d̄ / dx.
    pub cells_per_diameter: f64,
    pub offset: [f64; 2],
    /// Permeability k / d̄² (k = μ⟨u⟩/g, ⟨u⟩ the superficial velocity: Darcy's law with the body
    /// force as the pressure gradient).
    pub permeability: f64,
    /// Hydrodynamic solid fraction Σε / nodes (the grains with r_hd on the lattice).
    pub solid_fraction: f64,
    pub balance: f64,
    pub steps: usize,
    pub seconds: f64,
}

/// Permeability of `packing` on a lattice of `cells_per_diameter` cells per hydrodynamic diameter
/// (dx = r_hd d̄ / n; the box must hold a whole number of cells), the assembly shifted by
/// `offset` cells, circles scaled by `r_hd` (Su Sect. 2.3).
pub fn packing_permeability(
    packing: &Packing,
    cells_per_diameter: f64,
    r_hd: f64,
    offset: [f64; 2],
    tau: f64,
    steady: &Steady,
) -> Result<PackingRun, CouplingError> {
    let dx = r_hd / cells_per_diameter;
    let n = [packing.size[0] / dx, packing.size[1] / dx];
    let (nx, ny) = (n[0].round() as usize, n[1].round() as usize);
    if (n[0] - nx as f64).abs() > 1e-6 || (n[1] - ny as f64).abs() > 1e-6 || nx < 2 || ny < 2 {
        return Err(CouplingError::Unsupported(format!(
            "{cells_per_diameter} cells per hydrodynamic diameter put {:.4} x {:.4} cells on the {} x {} d̄ \
             box: choose a resolution that gives whole cells (5 n per 4 d̄ at r_hd = 0.8)",
            n[0], n[1], packing.size[0], packing.size[1]
        )));
    }
    let mut circles = Vec::new();
    let mut motions = Vec::new();
    for (k, g) in packing.grains.iter().enumerate() {
        let mut c = [0.0; 2];
        for &(p, r) in g {
            let at = [p[0] / dx + offset[0], p[1] / dx + offset[1]];
            c = [c[0] + at[0] / g.len() as f64, c[1] + at[1] / g.len() as f64];
            circles.push(GrainCircle {
                body: k as u32,
                centre: at,
                radius: r / dx,
            });
        }
        motions.push(GrainMotion {
            centre: c,
            ..Default::default()
        });
    }
    let map = solid_map(&circles, r_hd, nx, ny, [true, true]);
    let flow = steady_flow(nx, ny, &map, &motions, tau, G, steady)?;
    let nu = (tau - 0.5) / 3.0;
    Ok(PackingRun {
        nx,
        ny,
        cells_per_diameter: r_hd / dx,
        offset,
        permeability: nu * flow.u / G * dx * dx,
        solid_fraction: map.total.iter().sum::<f64>() / (nx * ny) as f64,
        balance: flow.balance,
        steps: flow.steps,
        seconds: flow.seconds,
    })
}

/// Mean, smallest and largest of a sample (NaN if empty).
pub fn spread(xs: &[f64]) -> (f64, f64, f64) {
    if xs.is_empty() {
        return (f64::NAN, f64::NAN, f64::NAN);
    }
    let mean = xs.iter().sum::<f64>() / xs.len() as f64;
    let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    (mean, lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Gebart's asymptote against Sangani & Acrivos where both exist: under it by 11.7 % at
    /// Φ = 0.4 and 8.7 % at 0.5, closing as Φ grows (the doc's figures).
    #[test]
    fn gebart_approaches_sangani_acrivos_toward_close_packing() {
        let gap = |phi: f64| 1.0 - gebart_square(phi).unwrap() / sangani_acrivos(phi).unwrap();
        assert!((gap(0.4) - 0.117).abs() < 0.001, "{}", gap(0.4));
        assert!((gap(0.5) - 0.087).abs() < 0.001, "{}", gap(0.5));
        assert!(gebart_square(0.8).is_none() && gebart_square(0.0).is_none());
    }

    #[test]
    fn offsets_cover_one_cell_evenly() {
        let o = offsets(3);
        assert_eq!(o.len(), 9);
        assert!(o.iter().all(|p| p.iter().all(|&x| (0.0..1.0).contains(&x))));
        assert_eq!(offsets(1), vec![[0.0, 0.0]]);
    }

    #[test]
    fn table_lookup() {
        assert_eq!(sangani_acrivos(0.3), Some(102.90));
        assert_eq!(sangani_acrivos(0.35), None);
    }
}
