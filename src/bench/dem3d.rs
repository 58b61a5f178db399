//! `lbdem bench dem3d`: particle-steps per second of the 3D sphere engine on dense frictional
//! spheres (issue 19 item 1), and with `--peer` LAMMPS `pair_style granular` on the same packing,
//! the same law and the same core count in the same run, with the ratio.
//!
//! The case: bidisperse spheres (d = 1 mm and 1.4 mm, 50/50 by number, ρ = 2500 kg/m³) in a
//! periodic box, Hertz-Mindlin with the Mindlin tangential spring (E = 5 MPa, ν = 0.3, μ = 0.5,
//! restitution e = 0.5), the step 0.2 of the Rayleigh step of the small spheres, jammed at
//! φ = 0.62, sheared slowly through Lees-Edwards faces at γ̇ = 1/s (inertial number about 1e-3:
//! the contacts persist and the packing rearranges slowly, as the 2D bench's pure shear does).
//! The packing is made here (radii grown from a loose cubic lattice under damping, then
//! relaxed) and written as a LAMMPS data file (positions, diameters, densities, velocities and
//! spins), so both codes start from the same state; the 85,184-sphere case tiles the 10,648-sphere
//! packing 2 × 2 × 2.
//!
//! LAMMPS's law is `hertz/material E e ν tangential mindlin NULL 1.0 μ damping tsuji`
//! (scripts/peers/lammps_3d.in): the same Hertz normal force, effective moduli and Mindlin
//! stiffness 8 G* √(R δ); its damping is Tsuji's form of the restitution coefficient where
//! ours is β's (both from e = 0.5), so the dissipation differs slightly; the contacts per
//! sphere of both runs are printed to show they work on the same network.

use super::{BenchArgs, lammps};
use anyhow::{Context, Result};
use lbdem_dem::generate::rng;
use lbdem_dem::spheres::{
    Domain3, Elastic, HertzMindlinSpring, SphereStepParams, SphereStepper, SphereSystem, Surface,
    max_time_step,
};
use lbdem_dem::{Vec3, Vector};
use rand::RngExt;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

const D_SMALL: f64 = 1.0e-3;
const RATIO: f64 = 1.4;
const RHO: f64 = 2500.0;
const PHI: f64 = 0.62;
const SHEAR_RATE: f64 = 1.0;

fn law(restitution: f64, mu: f64) -> HertzMindlinSpring {
    HertzMindlinSpring::uniform(
        Elastic {
            young: 5.0e6,
            poisson: 0.3,
        },
        Surface { mu, restitution },
    )
}

/// The benchmark's law (the timed runs).
fn bench_law() -> HertzMindlinSpring {
    law(0.5, 0.5)
}

/// The Verlet skin: 0.1 of the small diameter (LAMMPS: `neighbor 1e-4 bin`).
fn skin() -> f64 {
    0.1 * D_SMALL
}

/// Scale every sphere's radius by `f` (mass by f³, inertia by f⁵) and force a list rebuild.
fn grow(sys: &mut SphereSystem, f: f64) {
    let s = &mut sys.spheres;
    for k in 0..s.len() {
        s.radius[k] *= f;
        s.mass[k] *= f * f * f;
        s.inertia[k] *= f.powi(5);
    }
    sys.contacts.list_ref.clear();
}

fn packing_fraction(sys: &SphereSystem) -> f64 {
    let l = sys.domain.size();
    let v: f64 = sys
        .spheres
        .radius
        .iter()
        .map(|r| 4.0 / 3.0 * std::f64::consts::PI * r * r * r)
        .sum();
    v / (l.x * l.y * l.z)
}

/// The jammed packing of `n_side`³ spheres in the periodic cube they fill at φ = 0.62: a cubic
/// lattice of spheres started at 0.75 of the spacing (the large ones) with random velocities,
/// the radii grown to the diameters over `grow_steps` with low friction and strong damping
/// (e = 0.1, μ = 0.1), then relaxed under the bench's friction.
pub fn packing(n_side: usize, grow_steps: usize, relax_steps: usize) -> Result<SphereSystem> {
    let mut r = rng(4821);
    let n = n_side * n_side * n_side;
    let diameters: Vec<f64> = (0..n)
        .map(|_| {
            if r.random::<f64>() < 0.5 {
                D_SMALL
            } else {
                RATIO * D_SMALL
            }
        })
        .collect();
    // The box that the final diameters fill at φ = PHI, and the lattice in it.
    let v_final: f64 = diameters
        .iter()
        .map(|d| std::f64::consts::PI / 6.0 * d * d * d)
        .sum();
    let l = (v_final / PHI).cbrt();
    let a = l / n_side as f64;
    let dom = Domain3::new(Vec3::ZERO, Vec3::new(l, l, l), [true; 3])?;
    let mut sys = SphereSystem::new(dom);
    // Start small enough that the largest spheres clear their lattice neighbours.
    let f_end = RATIO * D_SMALL / (0.75 * a);
    for (k, d) in diameters.iter().enumerate() {
        let (ix, iy, iz) = (k % n_side, (k / n_side) % n_side, k / (n_side * n_side));
        let p = Vec3::new(
            (ix as f64 + 0.5) * a,
            (iy as f64 + 0.5) * a,
            (iz as f64 + 0.5) * a,
        );
        let v = Vec3::new(
            r.random::<f64>() - 0.5,
            r.random::<f64>() - 0.5,
            r.random::<f64>() - 0.5,
        ) * 1e-3;
        sys.add_sphere(p, v, Vec3::ZERO, 0.5 * d / f_end, RHO)?;
    }
    let soft = law(0.1, 0.1);
    let phi0 = packing_fraction(&sys);
    // The smallest spheres at the start set the step of the growth (the Rayleigh step ∝ r).
    let dt = max_time_step(&soft, &sys).context("no mobile sphere")?.1.dt;
    let p = SphereStepParams::new(dt, skin());
    let mut st = SphereStepper::new();
    let chunk = 10;
    let chunks = (grow_steps / chunk).max(1);
    let mut f_now = 1.0;
    for c in 1..=chunks {
        let target = (1.0 + (PHI / phi0 - 1.0) * c as f64 / chunks as f64).cbrt();
        grow(&mut sys, target / f_now);
        f_now = target;
        for _ in 0..chunk {
            st.step(&p, &soft, &mut sys)?;
        }
    }
    let mut st = SphereStepper::new();
    let relax = law(0.1, 0.5);
    for _ in 0..relax_steps {
        st.step(&p, &relax, &mut sys)?;
    }
    // The grown radii differ from the diameters by the growth's rounding (about 1e-14):
    // the final spheres take the diameters exactly, and their masses from them.
    let mut out = SphereSystem::new(sys.domain);
    let q = &sys.spheres;
    for (k, d) in diameters.iter().enumerate() {
        out.add_sphere(q.pos[k], q.vel[k], q.omega[k], 0.5 * d, RHO)?;
    }
    Ok(out)
}

/// The packing tiled `k` × `k` × `k` (a periodic packing stays one).
fn tile(sys: &SphereSystem, k: usize) -> Result<SphereSystem> {
    let l = sys.domain.size();
    let dom = Domain3::new(Vec3::ZERO, l * k as f64, [true; 3])?;
    let mut out = SphereSystem::new(dom);
    let s = &sys.spheres;
    for iz in 0..k {
        for iy in 0..k {
            for ix in 0..k {
                let shift = Vec3::new(ix as f64 * l.x, iy as f64 * l.y, iz as f64 * l.z);
                for j in 0..s.len() {
                    out.add_sphere(s.pos[j] + shift, s.vel[j], s.omega[j], s.radius[j], RHO)?;
                }
            }
        }
    }
    Ok(out)
}

/// The time step of the timed runs.
fn bench_dt(sys: &SphereSystem) -> Result<f64> {
    Ok(max_time_step(&bench_law(), sys).context("no mobile sphere")?.1.dt)
}

/// The spheres of `sys` in `domain`, without contact history, each sphere's mass and inertia
/// recomputed from its radius and ρ (as LAMMPS computes them from the data file).
fn fresh(sys: &SphereSystem, domain: Domain3) -> Result<SphereSystem> {
    let mut s = SphereSystem::new(domain);
    let p = &sys.spheres;
    for j in 0..p.len() {
        s.add_sphere(p.pos[j], p.vel[j], p.omega[j], p.radius[j], RHO)?;
    }
    Ok(s)
}

/// The packing with Lees-Edwards shear set (the same start as LAMMPS).
fn sheared(sys: &SphereSystem) -> Result<SphereSystem> {
    fresh(sys, sys.domain.with_lees_edwards(SHEAR_RATE)?)
}

/// Timed shear: (particle-steps/s, contacts per sphere at the end).
fn timed(start: &SphereSystem, steps: usize, threads: usize) -> Result<(f64, f64)> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
    pool.install(|| {
        let mut s = sheared(start)?;
        let law = bench_law();
        let p = SphereStepParams::new(bench_dt(start)?, skin());
        let mut st = SphereStepper::new();
        for _ in 0..200 {
            st.step(&p, &law, &mut s)?;
        }
        let t0 = Instant::now();
        for _ in 0..steps {
            st.step(&p, &law, &mut s)?;
        }
        let el = t0.elapsed().as_secs_f64();
        Ok((
            s.spheres.len() as f64 * steps as f64 / el,
            contacts_per_sphere(&s),
        ))
    })
}

/// Touching pairs per sphere × 2 (LAMMPS `compute contact/atom`, averaged).
fn contacts_per_sphere(sys: &SphereSystem) -> f64 {
    let s = &sys.spheres;
    let touching = sys
        .contacts
        .pairs
        .iter()
        .filter(|[i, j]| {
            let (i, j) = (*i as usize, *j as usize);
            let (d, _) = sys.domain.min_image_moving(s.pos[j] - s.pos[i]);
            let reach = s.radius[i] + s.radius[j];
            d.norm2() < reach * reach
        })
        .count();
    2.0 * touching as f64 / s.len() as f64
}

/// The packing as a LAMMPS data file (atom_style sphere, triclinic with zero tilt so that
/// `fix deform xy` can shear it).
fn write_data(sys: &SphereSystem, path: &Path) -> Result<()> {
    let s = &sys.spheres;
    let l = sys.domain.size();
    let mut t = String::new();
    writeln!(
        t,
        "lbdem bench dem3d packing, {} spheres, phi {:.4}\n",
        s.len(),
        packing_fraction(sys)
    )?;
    writeln!(t, "{} atoms\n1 atom types\n", s.len())?;
    writeln!(
        t,
        "0 {:.17e} xlo xhi\n0 {:.17e} ylo yhi\n0 {:.17e} zlo zhi",
        l.x, l.y, l.z
    )?;
    writeln!(t, "0 0 0 xy xz yz\n\nAtoms # sphere\n")?;
    for k in 0..s.len() {
        let p = s.pos[k];
        writeln!(
            t,
            "{} 1 {:.17e} {RHO} {:.17e} {:.17e} {:.17e}",
            k + 1,
            2.0 * s.radius[k],
            p.x,
            p.y,
            p.z
        )?;
    }
    writeln!(t, "\nVelocities\n")?;
    for k in 0..s.len() {
        let (v, w) = (s.vel[k], s.omega[k]);
        writeln!(
            t,
            "{} {:.17e} {:.17e} {:.17e} {:.17e} {:.17e} {:.17e}",
            k + 1,
            v.x,
            v.y,
            v.z,
            w.x,
            w.y,
            w.z
        )?;
    }
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    lbdem_core::atomic::write_atomic(path, t.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))
}

/// LAMMPS on the data file: (particle-steps/s, contacts per sphere).
fn peer(data: &Path, np: usize, steps: usize, dt: f64) -> Result<(f64, f64)> {
    lammps::run_script(
        "peer-lammps-3d.sh",
        &[
            data.display().to_string(),
            np.to_string(),
            steps.to_string(),
            format!("{dt:.17e}"),
            format!("{SHEAR_RATE}"),
        ],
    )
}

pub fn run(a: &BenchArgs) -> Result<()> {
    let reps = a.reps.max(1);
    let (n_side, grow_steps, relax_steps) = if a.quick {
        (10, 1500, 500)
    } else {
        (22, 6000, 2000)
    };
    eprintln!(
        "bench dem3d: preparing the jammed packing of {} spheres ...",
        n_side * n_side * n_side
    );
    let base = packing(n_side, grow_steps, relax_steps)?;
    let mut cases = vec![(
        if a.quick { "1k" } else { "10k" },
        base.clone(),
        if a.quick { 100 } else { 1000 },
    )];
    if !a.quick {
        cases.push(("85k", tile(&base, 2)?, 150));
    }
    let dir: PathBuf = Path::new(env!("CARGO_MANIFEST_DIR")).join("out/peer-lammps");
    println!(
        "dense frictional spheres, Hertz-Mindlin, phi {:.4}, Lees-Edwards shear {SHEAR_RATE}/s, dt {:.3e} s",
        packing_fraction(&base),
        bench_dt(&base)?
    );
    lammps::header(reps);
    let mut rows = Vec::new();
    for (name, s, steps) in &cases {
        let data = dir.join(format!("lmp3d_{name}.data"));
        if a.peer {
            write_data(s, &data)?;
        }
        let dt = bench_dt(s)?;
        for threads in [1usize, 2] {
            rows.push(lammps::row(
                name,
                s.spheres.len(),
                threads,
                reps,
                a.peer,
                3,
                || timed(s, *steps, threads),
                || peer(&data, threads, *steps, dt),
            )?);
        }
    }
    lammps::write_json(a.json.as_ref(), "dem3d", rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The bench's case is what its doc says: grown to φ = 0.62 exactly, with the final
    /// diameters, and jammed (every sphere's network rigid: contacts per sphere above the
    /// frictional isostatic 4; `bench dem3d --quick --peer` on this packing measured 5.20 after
    /// its 300 steps, LAMMPS 5.19, on 2026-11-30).
    #[test]
    fn the_quick_packing_is_jammed_at_its_packing_fraction() {
        let s = packing(10, 1500, 500).unwrap();
        assert!(
            (packing_fraction(&s) - PHI).abs() < 1e-12,
            "{}",
            packing_fraction(&s)
        );
        let d: Vec<f64> = s.spheres.radius.iter().map(|r| 2.0 * r / D_SMALL).collect();
        assert!(
            d.iter()
                .all(|&x| (x - 1.0).abs() < 1e-12 || (x - RATIO).abs() < 1e-12)
        );
        // One step builds the contact list the count reads.
        let mut t = sheared(&s).unwrap();
        let p = SphereStepParams::new(bench_dt(&s).unwrap(), skin());
        SphereStepper::new().step(&p, &bench_law(), &mut t).unwrap();
        let z = contacts_per_sphere(&t);
        assert!(z > 4.5 && z < 6.5, "contacts per sphere {z}");
    }

    #[test]
    fn the_lammps_data_file_holds_every_sphere_and_its_velocity() {
        let s = packing(4, 100, 10).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.data");
        write_data(&s, &path).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("64 atoms") && text.contains("0 0 0 xy xz yz"));
        let atoms = text
            .split("Atoms # sphere")
            .nth(1)
            .unwrap()
            .split("Velocities")
            .next()
            .unwrap();
        let rows: Vec<Vec<f64>> = atoms
            .lines()
            .filter(|l| !l.trim().is_empty())
            .map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect())
            .collect();
        assert_eq!(rows.len(), 64);
        // id type diameter density x y z, positions and diameters to the last bit.
        assert_eq!(rows[5][2], 2.0 * s.spheres.radius[5]);
        assert_eq!(rows[5][6], s.spheres.pos[5].z);
        let vel = text.split("Velocities").nth(1).unwrap();
        assert_eq!(vel.lines().filter(|l| !l.trim().is_empty()).count(), 64);
    }
}
