//! `lbdem bench resolution [--out DIR]`: accuracy of the partially-saturated-cells coupling
//! (Su et al. 2020 Eqs. 9-14) from 2 to 40 lattice cells per hydrodynamic grain diameter, the
//! paper's own resolution being 2.4 (dx = 40 µm, d̄ = 120 µm, r_hd = 0.8), against wall time.
//!
//! Two cases (`lbdem_coupling::cases::resolution`): Stokes drag on a square array of disks at
//! Φ = 0.1, 0.3, 0.5 against Sangani & Acrivos 1982 Table 1, and the permeability of a packed
//! periodic box of 32 two-circle grains against the same assembly on fine lattices (the
//! Richardson extrapolation of 20 and 40 cells per diameter; the 40-cell value is 12 % above it). At
//! each resolution the grain (or the whole assembly) is shifted by k × k sub-cell offsets
//! (k = 3 up to 10 cells, 2 at 20, 1 at 40); the table gives the mean, the smallest and the
//! largest error over them, and the wall time is the median over those runs (each a full solve
//! to steady state, on the rayon pool). The paper's resolution is also run at other τ of Su's
//! Table 3 (0.59 to 1.57), because B of Eq. 10, and so the leak through partly covered cells,
//! depends on τ. Writes `resolution.csv` and two charts, `resolution_error.png` (|error| against
//! cells per diameter) and `resolution_cost.png` (|error| against wall time), to `--out`
//! (default `out/bench-resolution`).

use super::{BenchArgs, median};
use crate::report::plot::{Series, XyPlot, xy_png};
use crate::report::table::{Col, write_table};
use anyhow::{Context, Result};
use lbdem_coupling::cases::resolution::{
    PAPER_CELLS, R_HD, Steady, disk_array, offsets, offsets_at, packing_permeability, sangani_acrivos,
    spread, two_circle_packing,
};
use std::path::PathBuf;

/// Nominal cells per hydrodynamic diameter; the last two give the fine-lattice reference.
const CELLS: [f64; 7] = [2.0, PAPER_CELLS, 3.0, 5.0, 10.0, 20.0, 40.0];
const CELLS_QUICK: [f64; 4] = [2.0, PAPER_CELLS, 5.0, 10.0];
const PHIS: [f64; 3] = [0.1, 0.3, 0.5];
/// The reference τ (as `sangani_psm.rs` and `darcy.rs`) and the range of Su's Table 3: with
/// dx = 40 µm, ν = 5.7-6.8e-7 m²/s and δt = 7e-5 to 1e-3 s, τ = ½ + 3νδt/dx² = 0.59 to 1.57
/// (1.21-1.30 for the 30 µm/s and floating runs).
const TAU: f64 = 1.0;
const TAUS_SU: [f64; 3] = [0.59, 1.25, 1.57];
/// Seed of the packed assembly.
const SEED: u64 = 7;

/// A chart line: label, cells per diameter, wall time (s), |error| (%).
type Curve = (String, Vec<f64>, Vec<f64>, Vec<f64>);

/// One row of the table: a case at one resolution and τ, over its offsets.
struct Row {
    case: String,
    tau: f64,
    nominal: f64,
    actual: f64,
    runs: usize,
    /// F/(μU) (disk array) or k/d̄² (packing): mean, min, max over the offsets.
    value: (f64, f64, f64),
    published: f64,
    /// Richardson extrapolation of the two finest lattices (second order).
    fine: f64,
    /// The finest lattice's own value.
    finest: f64,
    seconds: f64,
    steps: f64,
    /// Largest |Eq. 14 drag / g Σ(1 − B) − 1| over the runs.
    balance: f64,
}

impl Row {
    fn err(&self, reference: f64, v: f64) -> f64 {
        v / reference - 1.0
    }
    /// (mean, min, max) error against `reference`.
    fn errors(&self, reference: f64) -> (f64, f64, f64) {
        let (m, lo, hi) = self.value;
        (
            self.err(reference, m),
            self.err(reference, lo),
            self.err(reference, hi),
        )
    }
    /// The error the charts show: against Sangani & Acrivos for the disks, the fine lattice for
    /// the packing.
    fn headline(&self) -> f64 {
        if self.published.is_finite() {
            self.errors(self.published).0
        } else {
            self.errors(self.fine).0
        }
    }
}

/// The limit h → 0 of the two finest rows' means, assuming second order (the packing's
/// successive differences shrink 4.0× from 10 to 20 to 40 cells): v₂ + (v₂ − v₁)/(r² − 1),
/// r = n₂/n₁ (actual cells per diameter); and the finest value itself.
fn extrapolated(two: &[Row]) -> (f64, f64) {
    let (a, b) = (&two[0], &two[1]);
    let r = b.actual / a.actual;
    (b.value.0 + (b.value.0 - a.value.0) / (r * r - 1.0), b.value.0)
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let out = a
        .out
        .clone()
        .unwrap_or_else(|| PathBuf::from("out/bench-resolution"));
    std::fs::create_dir_all(&out).with_context(|| format!("cannot create {}", out.display()))?;
    let cells: &[f64] = if a.quick { &CELLS_QUICK } else { &CELLS };
    let steady = Steady {
        tol: 1e-7,
        ..Steady::default()
    };
    println!(
        "PSM accuracy against cells per hydrodynamic diameter (Su et al. 2020: {PAPER_CELLS}), BGK, tau {TAU}; \
         steady when U changes by < {:.0e} per {} steps{}",
        steady.tol,
        steady.every,
        if a.quick {
            "; quick: the reference is extrapolated from 5 and 10 cells"
        } else {
            ""
        }
    );
    let mut rows: Vec<Row> = Vec::new();

    // Disk arrays against Sangani & Acrivos and the finest lattice.
    for phi in PHIS {
        let published = sangani_acrivos(phi).context("Φ not in the Sangani-Acrivos table")?;
        let start = rows.len();
        let mut plan: Vec<(f64, f64)> = cells.iter().map(|&n| (n, TAU)).collect();
        plan.extend(TAUS_SU.iter().map(|&t| (PAPER_CELLS, t)));
        for (n, tau) in plan {
            let runs = offsets(offsets_at(n))
                .into_iter()
                .map(|o| disk_array(phi, n, o, tau, &steady))
                .collect::<Result<Vec<_>, _>>()?;
            let v: Vec<f64> = runs.iter().map(|r| r.drag).collect();
            rows.push(Row {
                case: format!("disk array phi {phi}"),
                tau,
                nominal: n,
                actual: runs[0].diameter_cells,
                runs: runs.len(),
                value: spread(&v),
                published,
                fine: f64::NAN,
                finest: f64::NAN,
                seconds: median(&runs.iter().map(|r| r.seconds).collect::<Vec<_>>()),
                steps: median(&runs.iter().map(|r| r.steps as f64).collect::<Vec<_>>()),
                balance: runs.iter().map(|r| (r.balance - 1.0).abs()).fold(0.0, f64::max),
            });
        }
        let (fine, finest) = extrapolated(&rows[start + cells.len() - 2..start + cells.len()]);
        for r in &mut rows[start..] {
            (r.fine, r.finest) = (fine, finest);
        }
    }

    // The packed two-circle assembly against its finest lattice.
    let packing = two_circle_packing(SEED)?;
    println!(
        "packing: {} two-circle grains, box {} x {} d̄, packing fraction {:.3}, r_hd {R_HD}, seed {SEED}",
        packing.grains.len(),
        packing.size[0],
        packing.size[1],
        packing.packing_fraction
    );
    let start = rows.len();
    let mut plan: Vec<(f64, f64)> = cells.iter().map(|&n| (n, TAU)).collect();
    plan.extend(TAUS_SU.iter().map(|&t| (PAPER_CELLS, t)));
    for (n, tau) in plan {
        let runs = offsets(offsets_at(n))
            .into_iter()
            .map(|o| packing_permeability(&packing, n, R_HD, o, tau, &steady))
            .collect::<Result<Vec<_>, _>>()?;
        let v: Vec<f64> = runs.iter().map(|r| r.permeability).collect();
        rows.push(Row {
            case: "packing".into(),
            tau,
            nominal: n,
            actual: runs[0].cells_per_diameter,
            runs: runs.len(),
            value: spread(&v),
            published: f64::NAN,
            fine: f64::NAN,
            finest: f64::NAN,
            seconds: median(&runs.iter().map(|r| r.seconds).collect::<Vec<_>>()),
            steps: median(&runs.iter().map(|r| r.steps as f64).collect::<Vec<_>>()),
            balance: runs.iter().map(|r| (r.balance - 1.0).abs()).fold(0.0, f64::max),
        });
    }
    let (fine, finest) = extrapolated(&rows[start + cells.len() - 2..start + cells.len()]);
    for r in &mut rows[start..] {
        (r.fine, r.finest) = (fine, finest);
    }

    println!(
        "{:<20} {:>5} {:>6} {:>6} {:>4} {:>11} {:>22} {:>22} {:>9} {:>8}",
        "case",
        "tau",
        "n",
        "n_act",
        "runs",
        "value",
        "err vs published %",
        "err vs extrapolated %",
        "time s",
        "balance"
    );
    for r in &rows {
        let fmt = |e: (f64, f64, f64)| {
            if e.0.is_finite() {
                format!("{:+.2} [{:+.2},{:+.2}]", 100.0 * e.0, 100.0 * e.1, 100.0 * e.2)
            } else {
                "-".into()
            }
        };
        println!(
            "{:<20} {:>5} {:>6} {:>6.2} {:>4} {:>11.5e} {:>22} {:>22} {:>9.2e} {:>8.1e}",
            r.case,
            r.tau,
            r.nominal,
            r.actual,
            r.runs,
            r.value.0,
            fmt(r.errors(r.published)),
            fmt(r.errors(r.fine)),
            r.seconds,
            r.balance
        );
    }

    // CSV through the project's polars writer.
    let col = |f: &dyn Fn(&Row) -> f64| rows.iter().map(f).collect::<Vec<f64>>();
    let case: Vec<String> = rows.iter().map(|r| r.case.clone()).collect();
    let runs: Vec<u64> = rows.iter().map(|r| r.runs as u64).collect();
    let (tau, nominal, actual) = (col(&|r| r.tau), col(&|r| r.nominal), col(&|r| r.actual));
    let (mean, lo, hi) = (col(&|r| r.value.0), col(&|r| r.value.1), col(&|r| r.value.2));
    let (published, fine, finest) = (col(&|r| r.published), col(&|r| r.fine), col(&|r| r.finest));
    let e_finest = col(&|r| r.errors(r.finest).0);
    let ep = col(&|r| r.errors(r.published).0);
    let (ef, ef_lo, ef_hi) = (
        col(&|r| r.errors(r.fine).0),
        col(&|r| r.errors(r.fine).1),
        col(&|r| r.errors(r.fine).2),
    );
    let (ep_lo, ep_hi) = (
        col(&|r| r.errors(r.published).1),
        col(&|r| r.errors(r.published).2),
    );
    let (secs, steps, bal) = (col(&|r| r.seconds), col(&|r| r.steps), col(&|r| r.balance));
    let csv = out.join("resolution.csv");
    write_table(
        &csv,
        &[
            ("case", Col::Str(&case)),
            ("tau", Col::F64(&tau)),
            ("cells_per_diameter", Col::F64(&nominal)),
            ("cells_per_diameter_actual", Col::F64(&actual)),
            ("runs", Col::U64(&runs)),
            ("value_mean", Col::F64(&mean)),
            ("value_min", Col::F64(&lo)),
            ("value_max", Col::F64(&hi)),
            ("published", Col::F64(&published)),
            ("fine_extrapolated", Col::F64(&fine)),
            ("finest_lattice", Col::F64(&finest)),
            ("error_finest_lattice", Col::F64(&e_finest)),
            ("error_published", Col::F64(&ep)),
            ("error_published_min", Col::F64(&ep_lo)),
            ("error_published_max", Col::F64(&ep_hi)),
            ("error_fine", Col::F64(&ef)),
            ("error_fine_min", Col::F64(&ef_lo)),
            ("error_fine_max", Col::F64(&ef_hi)),
            ("seconds_median", Col::F64(&secs)),
            ("steps_median", Col::F64(&steps)),
            ("balance_max_deviation", Col::F64(&bal)),
        ],
    )?;

    // Charts: |error| in % (against the published table for the disks, the extrapolated fine lattice for
    // the packing), τ = 1 rows only.
    let cases: Vec<String> = {
        let mut c = case.clone();
        c.dedup();
        c
    };
    let mut data: Vec<Curve> = Vec::new();
    for c in &cases {
        let sel: Vec<&Row> = rows.iter().filter(|r| &r.case == c && r.tau == TAU).collect();
        let label = if c == "packing" {
            "packing k (vs extrapolated fine lattice)".to_string()
        } else {
            format!("{c} F (vs Sangani-Acrivos)")
        };
        data.push((
            label,
            sel.iter().map(|r| r.actual).collect(),
            sel.iter().map(|r| r.seconds).collect(),
            sel.iter().map(|r| 100.0 * r.headline().abs()).collect(),
        ));
    }
    let by_cells: Vec<Series> = data
        .iter()
        .map(|(l, n, _, e)| Series {
            label: l,
            x: n,
            y: e,
            points: false,
        })
        .collect();
    let err_png = out.join("resolution_error.png");
    xy_png(
        &err_png,
        &by_cells,
        &XyPlot {
            title: "PSM error against resolution (Su et al.: 2.4 cells per hydrodynamic diameter)",
            x_label: "cells per hydrodynamic diameter",
            y_label: "|error| (%)",
            log_x: true,
            log_y: true,
        },
    )?;
    let by_time: Vec<Series> = data
        .iter()
        .map(|(l, _, t, e)| Series {
            label: l,
            x: t,
            y: e,
            points: false,
        })
        .collect();
    let cost_png = out.join("resolution_cost.png");
    xy_png(
        &cost_png,
        &by_time,
        &XyPlot {
            title: "PSM error against wall time per steady solve",
            x_label: "wall time (s, median over sub-cell offsets)",
            y_label: "|error| (%)",
            log_x: true,
            log_y: true,
        },
    )?;
    println!(
        "wrote {}, {} and {}",
        csv.display(),
        err_png.display(),
        cost_png.display()
    );
    Ok(())
}
