//! Dense bidisperse suspensions for the Lees-Edwards and simple-shear tests: Ness et al.
//! (2017)'s mixture (diameters d and 1.5 d, 1:1 by number) placed at random in a periodic cube
//! at a volume fraction φ, overlaps then removed by steepest descent on the harmonic overlap
//! energy (a geometric relaxation, not dynamics; converges below the frictionless jamming
//! fraction ≈ 0.64), then sheared from the affine velocity profile.
#![allow(dead_code)]

use lbdem_dem::spheres::cells::CellList3;
use lbdem_dem::spheres::{Domain3, LinearSpring, Lubricated, Lubrication, SphereSystem};
use lbdem_dem::{Vec3, Vector};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Small-sphere diameter (the length unit), density and liquid viscosity (simulation units).
pub const D: f64 = 1.0;
pub const RHO: f64 = 1.0;
pub const ETA: f64 = 1.0;
/// Diameter ratio of Ness et al. (2017): d and 1.5 d, 1:1 by number.
pub const RATIO: f64 = 1.5;

/// Ness et al.'s law: lubrication (Eqs. 3-5) plus the linear spring (Eq. 6), k_t = (2/7) k_n,
/// μ_w = μ_p (no plane walls here).
pub fn ness_law(k_n: f64, mu_p: f64) -> Lubricated<LinearSpring> {
    Lubricated {
        lubrication: Lubrication::ness(ETA),
        contact: LinearSpring::ness(k_n, mu_p, mu_p),
    }
}

/// The side of the cube holding `n` spheres (half d, half 1.5 d) at volume fraction `phi`.
pub fn box_side(n: usize, phi: f64) -> f64 {
    let v: f64 = (0..n).map(|k| sphere_volume(radius_of(k))).sum();
    (v / phi).cbrt()
}

/// Radius of sphere `k` (even: small, odd: large).
pub fn radius_of(k: usize) -> f64 {
    if k.is_multiple_of(2) {
        0.5 * D
    } else {
        0.5 * RATIO * D
    }
}

pub fn sphere_volume(r: f64) -> f64 {
    4.0 / 3.0 * std::f64::consts::PI * r * r * r
}

/// Positions of `n` spheres at volume fraction `phi` in the periodic cube of [`box_side`],
/// overlaps below 1e-4 d (seeded).
pub fn relaxed_positions(n: usize, phi: f64, seed: u64) -> (Domain3, Vec<Vec3>, Vec<f64>) {
    let l = box_side(n, phi);
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(l, l, l), [true; 3]).unwrap();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut pos: Vec<Vec3> = (0..n)
        .map(|_| {
            Vec3::new(
                l * rng.random::<f64>(),
                l * rng.random::<f64>(),
                l * rng.random::<f64>(),
            )
        })
        .collect();
    let r: Vec<f64> = (0..n).map(radius_of).collect();
    let mut cells = CellList3::default();
    let mut pairs = Vec::new();
    let mut push = vec![Vec3::ZERO; n];
    let skin = 0.2 * D;
    let mut since = f64::INFINITY;
    for _ in 0..200_000 {
        if since > 0.4 * skin {
            cells
                .build_pairs(&dom, &pos, &r, &[], skin, |_, _| 0.0, &mut pairs)
                .unwrap();
            since = 0.0;
        }
        push.fill(Vec3::ZERO);
        let mut worst = 0.0f64;
        for &[i, j] in &pairs {
            let (i, j) = (i as usize, j as usize);
            let d = dom.min_image(pos[j] - pos[i]);
            let dist = d.norm();
            let overlap = r[i] + r[j] - dist;
            if overlap > 0.0 && dist > 0.0 {
                worst = worst.max(overlap);
                let m = d * (0.3 * overlap / dist);
                push[i] -= m;
                push[j] += m;
            }
        }
        if worst < 1e-4 * D {
            return (dom, pos, r);
        }
        let step = push.iter().map(|p| p.norm()).fold(0.0, f64::max);
        since += 2.0 * step;
        for (p, q) in pos.iter_mut().zip(&push) {
            *p = dom.wrap(*p + *q);
        }
    }
    panic!("overlap removal did not converge at phi = {phi}");
}

/// A sheared suspension: the relaxed packing on a Lees-Edwards box at rate `rate`, every
/// sphere moving with the affine profile v_x = γ̇ (y − L/2).
pub fn sheared(n: usize, phi: f64, rate: f64, seed: u64) -> SphereSystem {
    let (dom, pos, r) = relaxed_positions(n, phi, seed);
    let l = dom.size().y;
    let mut sys = SphereSystem::new(dom.with_lees_edwards(rate).unwrap());
    for (p, r) in pos.iter().zip(&r) {
        let v = Vec3::new(rate * (p.y - 0.5 * l), 0.0, 0.0);
        sys.add_sphere(*p, v, Vec3::ZERO, *r, RHO).unwrap();
    }
    sys
}
