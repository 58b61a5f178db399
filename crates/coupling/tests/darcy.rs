//! Darcy flow through a fixed random packing of disks (periodic box, solid fraction 0.3) driven
//! by a body force g: the permeability k = ν U / g (U the superficial velocity; Darcy's law with
//! the force playing the pressure gradient) must converge as the lattice is refined, the
//! differences between successive levels shrinking at least by half per doubling, and the
//! Eq. 14 drag on all disks must balance the force on the liquid.

use crate::common;
use common::*;
use lbdem_coupling::PsmFluid;
use lbdem_coupling::solid_fraction::GrainCircle;
use lbdem_coupling::weighting::psm_weight;
use lbdem_lbm::Domain;

/// 14 non-overlapping disks (radii 0.07-0.10 of the box, at least 0.02 apart) from a fixed
/// pseudo-random sequence, in box units.
fn packing() -> Vec<(f64, f64, f64)> {
    let mut seed = 7u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut disks: Vec<(f64, f64, f64)> = Vec::new();
    while disks.len() < 14 {
        let (x, y, r) = (rnd(), rnd(), 0.07 + 0.03 * rnd());
        let ok = disks.iter().all(|&(a, b, s)| {
            let dx = (x - a) - (x - a).round();
            let dy = (y - b) - (y - b).round();
            (dx * dx + dy * dy).sqrt() > r + s + 0.02
        });
        if ok {
            disks.push((x, y, r));
        }
    }
    disks
}

/// (k / L², Eq. 14 drag over the force on the liquid) at L cells per box side.
fn permeability(l: usize) -> (f64, f64) {
    let tau = 1.0;
    let circles: Vec<GrainCircle> = packing()
        .iter()
        .enumerate()
        .map(|(k, &(x, y, r))| GrainCircle {
            body: k as u32,
            centre: [x * l as f64, y * l as f64],
            radius: r * l as f64,
        })
        .collect();
    let (map, motions) = fixed(&circles, l, l, [true, true]);
    let g = 1e-6;
    let mut fluid = PsmFluid::<f64>::new(&Domain::periodic([l, l, 1]), settings(tau, [g, 0.0])).unwrap();
    let (loads, _) = run_steady(&mut fluid, &map, &motions, 500, 1e-8, 400_000);
    let nu = (tau - 0.5) / 3.0;
    let u = mean_u(&fluid)[0];
    let liquid: f64 = map.total.iter().map(|&e| 1.0 - psm_weight(e, tau)).sum();
    let drag: f64 = loads.iter().map(|l| l.force[0]).sum();
    (nu * u / g / (l * l) as f64, drag / (g * liquid))
}

fn check(levels: &[usize]) {
    let solid: f64 = packing()
        .iter()
        .map(|&(_, _, r)| std::f64::consts::PI * r * r)
        .sum();
    let ks: Vec<f64> = levels
        .iter()
        .map(|&l| {
            let (k, balance) = permeability(l);
            eprintln!("L = {l}: k / L^2 = {k:.6e} (solid fraction {solid:.3}), drag balance {balance:.6}");
            assert!((balance - 1.0).abs() < 1e-4, "force balance {balance}");
            k
        })
        .collect();
    for w in ks.windows(3) {
        let (d1, d2) = ((w[1] - w[0]).abs(), (w[2] - w[1]).abs());
        let q = d1 / d2;
        eprintln!(
            "successive differences {d1:.3e} -> {d2:.3e} (ratio {q:.2}); Richardson estimate k / L^2 = {:.4e}",
            w[2] - (w[1] - w[2]) / (q - 1.0)
        );
        assert!(d2 < 0.5 * d1, "no convergence: {ks:?}");
    }
}

#[test]
fn permeability_converges_with_resolution() {
    check(&[32, 64, 128]);
}
