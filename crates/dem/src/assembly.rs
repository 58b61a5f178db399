//! The pieces of Su et al. 2020's assembly protocol (Sect. 2.4) that act on a whole [`System`]:
//! fitting a compressed assembly to the sample's box, reaching a target packing fraction by
//! scaling the grains, deleting grains or adding small grains in interstices, replacing the
//! box by the bonded membrane, and the measures the assembly file records (grain sizes, the mean
//! contact force F_0 of Table 1). The insertion and the servo compression are in
//! [`crate::generate`]; the stage `assemble` of the `lbdem` binary runs them in order.

use crate::body::Bodies;
use crate::contact::{Bond, BondParams};
use crate::error::DemError;
use crate::generate::{box_walls, rng, wall_box};
use crate::shape::ClumpShape;
use crate::stepper::Stepper;
use crate::system::{Membrane, System};
use crate::vector::{Vec2, Vector};
use rand::RngExt;
use serde::{Deserialize, Serialize};

/// Equivalent diameters of the grains, d = √(4A/π) of each clump's area (the size Su et al.'s
/// Table 2 lists as d_min : d̄ : d_max).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SizeStats {
    pub count: usize,
    pub d_min: f64,
    pub d_mean: f64,
    pub d_max: f64,
}

pub fn size_stats(b: &Bodies) -> SizeStats {
    let d: Vec<f64> = (0..b.len())
        .map(|k| (4.0 * b.mass[k] / b.density[k] / std::f64::consts::PI).sqrt())
        .collect();
    SizeStats {
        count: d.len(),
        d_min: d.iter().copied().fold(f64::INFINITY, f64::min),
        d_mean: d.iter().sum::<f64>() / d.len().max(1) as f64,
        d_max: d.iter().copied().fold(0.0, f64::max),
    }
}

/// Map the assembly inside the four box walls (0-3) onto the box [lo, hi]: centres affinely
/// along each axis, every grain's size by √(s_x s_y) about its centroid, so the packing fraction
/// is unchanged. Su's sample has the experiment's size (7.5 × 10 mm, Fig. 1a); a servo
/// compression ends wherever the grains balance the target stress, so this closes the gap.
/// Returns (s_x, s_y). Contacts are forgotten (their springs restart from the new overlaps).
pub fn fit_to_box(sys: &mut System, lo: Vec2, hi: Vec2) -> Result<(f64, f64), DemError> {
    if sys.walls.len() < 4 {
        return Err(DemError::BadParameter {
            name: "walls",
            value: sys.walls.len() as f64,
            why: "fitting to a box needs the four box walls (0-3) of a compression",
        });
    }
    let (a, b) = wall_box(sys);
    let (sx, sy) = ((hi.x - lo.x) / (b.x - a.x), (hi.y - lo.y) / (b.y - a.y));
    if !(sx > 0.0 && sy > 0.0 && sx.is_finite() && sy.is_finite()) {
        return Err(DemError::BadParameter {
            name: "sample box",
            value: sx.min(sy),
            why: "the sample box and the wall box must both have positive width and height",
        });
    }
    for p in sys.bodies.pos.iter_mut() {
        *p = Vec2::new(lo.x + (p.x - a.x) * sx, lo.y + (p.y - a.y) * sy);
    }
    sys.bodies.scale_sizes((sx * sy).sqrt());
    let fixed = box_walls(lo, hi);
    sys.walls[..4].copy_from_slice(&fixed);
    sys.contacts = Default::default();
    Ok((sx, sy))
}

/// How a target packing fraction is reached (Su Sect. 2.4: "by slightly reducing the radius of
/// all grains and/or by deleting some grains ... by slightly increasing the radius of all grains
/// and/or by adding smaller grains into some interstices").
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PackingMethod {
    /// Every grain's size scaled about its centroid.
    Scale,
    /// Grains deleted at random until the target is crossed, then a small size scaling.
    Delete,
    /// Small grains added in interstices until the target is crossed, then a small scaling.
    Add,
    /// Sizes scaled by at most `max_size_change`, grains deleted or added for the rest.
    #[default]
    Auto,
}

/// What [`adjust_packing`] did.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PackingChange {
    pub from: f64,
    pub to: f64,
    /// Product of the size scalings applied.
    pub size_scale: f64,
    pub deleted: usize,
    pub added: usize,
}

/// The sample a packing fraction refers to: the grains' area over `area`. Grains are added in
/// interstices of the box [lo, hi] and, with a `ring` (a membrane's polygon), inside the ring.
#[derive(Clone, Copy, Debug)]
pub struct Sample<'a> {
    pub lo: Vec2,
    pub hi: Vec2,
    pub area: f64,
    pub ring: Option<&'a [Vec2]>,
}

impl Sample<'_> {
    /// The box [lo, hi] itself (a sample inside walls).
    pub fn boxed(lo: Vec2, hi: Vec2) -> Self {
        Self {
            lo,
            hi,
            area: (hi.x - lo.x) * (hi.y - lo.y),
            ring: None,
        }
    }
}

/// Reach packing fraction `target` (grain area over the sample's area) by `method`. `small` is
/// the shape added in interstices (Su: "smaller grains"); `max_size_change` bounds the first
/// size scaling of [`PackingMethod::Auto`] (e.g. 0.03: ±3 %). Membrane grains (tag 1) are never
/// deleted; deleting grains renumbers them, so bonds and the membrane are dropped (install them
/// after, on the grains tagged 1).
#[allow(clippy::too_many_arguments)]
pub fn adjust_packing(
    sys: &mut System,
    sample: &Sample,
    target: f64,
    method: PackingMethod,
    max_size_change: f64,
    small: &ClumpShape<Vec2>,
    density: f64,
    seed: u64,
) -> Result<PackingChange, DemError> {
    if !(target > 0.0 && target < 1.0) {
        return Err(DemError::BadParameter {
            name: "target packing fraction",
            value: target,
            why: "must lie in (0, 1)",
        });
    }
    let area = sample.area;
    let phi = |sys: &System| sys.bodies.total_area() / area;
    let from = phi(sys);
    let mut change = PackingChange {
        from,
        to: from,
        size_scale: 1.0,
        deleted: 0,
        added: 0,
    };
    let scale = |sys: &mut System, s: f64, change: &mut PackingChange| {
        sys.bodies.scale_sizes(s);
        change.size_scale *= s;
    };
    let exact = (target / from).sqrt();
    let (delete, add) = match method {
        PackingMethod::Scale => (false, false),
        PackingMethod::Delete if target > from => {
            return Err(DemError::BadParameter {
                name: "target packing fraction",
                value: target,
                why: "deleting grains lowers the packing fraction; the target is above the assembly's: use method \"add\" or \"scale\"",
            });
        }
        PackingMethod::Add if target < from => {
            return Err(DemError::BadParameter {
                name: "target packing fraction",
                value: target,
                why: "adding grains raises the packing fraction; the target is below the assembly's: use method \"delete\" or \"scale\"",
            });
        }
        PackingMethod::Delete => (true, false),
        PackingMethod::Add => (false, true),
        PackingMethod::Auto => {
            let s = exact.clamp(1.0 - max_size_change, 1.0 + max_size_change);
            if s != 1.0 {
                scale(sys, s, &mut change);
            }
            let now = phi(sys);
            (now > target * (1.0 + 1e-12), now < target * (1.0 - 1e-12))
        }
    };
    if delete {
        change.deleted = delete_until(sys, area, target, seed);
        sys.bonds.clear();
        sys.bond_params = None;
        sys.membrane = None;
    }
    if add {
        change.added = add_until(sys, sample, target, small, density, seed)?;
    }
    let s = (target / phi(sys)).sqrt();
    scale(sys, s, &mut change);
    sys.contacts = Default::default();
    change.to = phi(sys);
    Ok(change)
}

/// Delete grains in a seeded random order until their area over `area` is at most `target`;
/// membrane grains (tag 1) stay.
fn delete_until(sys: &mut System, area: f64, target: f64, seed: u64) -> usize {
    let n = sys.bodies.len();
    let mut order: Vec<usize> = (0..n).collect();
    let mut r = rng(seed);
    for i in (1..n).rev() {
        order.swap(i, r.random_range(0..=i));
    }
    let mut left = sys.bodies.total_area();
    let mut drop = vec![false; n];
    let mut deleted = 0;
    for &k in &order {
        if left / area <= target {
            break;
        }
        if sys.bodies.tag[k] == 1 {
            continue;
        }
        drop[k] = true;
        left -= sys.bodies.mass[k] / sys.bodies.density[k];
        deleted += 1;
    }
    sys.bodies.retain(|k| !drop[k]);
    deleted
}

/// Add copies of `small` in interstices until the packing fraction is at least `target`.
fn add_until(
    sys: &mut System,
    sample: &Sample,
    target: f64,
    small: &ClumpShape<Vec2>,
    density: f64,
    seed: u64,
) -> Result<usize, DemError> {
    let (lo, hi, area) = (sample.lo, sample.hi, sample.area);
    let (shape, _) = small.centred()?;
    let br = shape.bounding_radius();
    let mut r = rng(seed ^ 0x5eed_add0);
    let mut added = 0;
    let mut trials = 0u64;
    let max_trials = 2_000_000u64;
    // Existing circles in a uniform grid of side 2 × the largest radius, for the overlap test.
    let r_max = sys.bodies.circle_r.iter().copied().fold(br, f64::max);
    let cell = 2.0 * r_max;
    let nx = (((hi.x - lo.x) / cell).ceil() as usize).max(1);
    let ny = (((hi.y - lo.y) / cell).ceil() as usize).max(1);
    let mut grid: Vec<Vec<(Vec2, f64)>> = vec![Vec::new(); nx * ny];
    let at_cell = |p: Vec2| {
        let i = (((p.x - lo.x) / cell).floor().max(0.0) as usize).min(nx - 1);
        let j = (((p.y - lo.y) / cell).floor().max(0.0) as usize).min(ny - 1);
        (i, j)
    };
    for c in 0..sys.bodies.n_circles() {
        let p = sys.bodies.circle_pos(c);
        let (i, j) = at_cell(p);
        grid[j * nx + i].push((p, sys.bodies.circle_r[c]));
    }
    while sys.bodies.total_area() / area < target {
        if trials >= max_trials {
            return Err(DemError::BadParameter {
                name: "target packing fraction",
                value: target,
                why: "no free interstice left for another small grain after 2e6 trials; lower the target, \
                      make the added grain smaller, or let method \"auto\" scale the sizes more (max_size_change)",
            });
        }
        trials += 1;
        let at = Vec2::new(
            lo.x + br + (hi.x - lo.x - 2.0 * br) * r.random::<f64>(),
            lo.y + br + (hi.y - lo.y - 2.0 * br) * r.random::<f64>(),
        );
        let ang = std::f64::consts::TAU * r.random::<f64>();
        let mine: Vec<(Vec2, f64)> = shape
            .balls
            .iter()
            .map(|b| (at + b.centre.rotated(ang), b.r))
            .collect();
        let outside = sample
            .ring
            .is_some_and(|ring| mine.iter().any(|&(p, _)| !crate::polygon::contains(ring, p)));
        let clash = outside
            || mine.iter().any(|&(p, rr)| {
                let (i, j) = at_cell(p);
                (j.saturating_sub(1)..=(j + 1).min(ny - 1)).any(|jj| {
                    (i.saturating_sub(1)..=(i + 1).min(nx - 1)).any(|ii| {
                        grid[jj * nx + ii]
                            .iter()
                            .any(|&(q, rq)| (p - q).norm2() < (rr + rq).powi(2))
                    })
                })
            });
        if !clash {
            sys.bodies.add(&shape, density, at, ang)?;
            for &(p, rr) in &mine {
                let (i, j) = at_cell(p);
                grid[j * nx + i].push((p, rr));
            }
            added += 1;
        }
    }
    Ok(added)
}

/// The grains within `shell` of the assembly's outline (the bounding box of the grain centres):
/// the membrane of Su Sect. 2.4 (red grains of Fig. 1b).
pub fn shell_members(b: &Bodies, shell: f64) -> Vec<u32> {
    let lo = b.pos.iter().fold(Vec2::new(f64::MAX, f64::MAX), |a, p| {
        Vec2::new(a.x.min(p.x), a.y.min(p.y))
    });
    let hi = b.pos.iter().fold(Vec2::new(f64::MIN, f64::MIN), |a, p| {
        Vec2::new(a.x.max(p.x), a.y.max(p.y))
    });
    (0..b.len())
        .filter(|&k| {
            let p = b.pos[k];
            p.x - lo.x < shell || hi.x - p.x < shell || p.y - lo.y < shell || hi.y - p.y < shell
        })
        .map(|k| k as u32)
        .collect()
}

/// Parallel bonds between the circles of membrane grains closer than r_i + r_j + `gap`.
pub fn ring_bonds(b: &Bodies, members: &[u32], gap: f64) -> Vec<Bond> {
    let mut bonds = Vec::new();
    for (x, &i) in members.iter().enumerate() {
        for &j in &members[x + 1..] {
            for ci in b.circle_start[i as usize]..b.circle_start[i as usize + 1] {
                for cj in b.circle_start[j as usize]..b.circle_start[j as usize + 1] {
                    let d = (b.circle_pos(cj) - b.circle_pos(ci)).norm();
                    if d < b.circle_r[ci] + b.circle_r[cj] + gap {
                        bonds.push(Bond::new(ci as u32, cj as u32));
                    }
                }
            }
        }
    }
    bonds
}

/// The membrane settings of a scene or an assembly (Su Sect. 2.4, Table 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MembraneSpec {
    /// Grains whose centre is within this distance of the outline are membrane grains (m).
    pub shell: f64,
    /// Outward displacement beyond which F_N acts (Su: 50 µm).
    pub threshold: f64,
    /// F_N (Su: 0.25 F_y).
    pub force: f64,
    /// Distance over which F_N rises beyond the threshold (0: the paper's step; see [`Membrane`]).
    pub ramp: f64,
    /// Parallel bonds between membrane circles closer than r_i + r_j + gap.
    pub bonds: Option<(BondParams, f64)>,
}

/// Make the membrane: tag its grains 1 (the others 0), bond them, install the inward driver.
/// Existing bonds are replaced.
pub fn install_membrane(sys: &mut System, m: &MembraneSpec) {
    let members = shell_members(&sys.bodies, m.shell);
    install_membrane_on(sys, members, m);
}

/// [`install_membrane`] on given grains (e.g. those tagged 1 after a packing change inside a
/// membrane that has deformed, where the outline's shell would pick others): their bonds made
/// afresh as they now lie, and the outward displacement of F_N counted from here.
pub fn install_membrane_on(sys: &mut System, members: Vec<u32>, m: &MembraneSpec) {
    for t in sys.bodies.tag.iter_mut() {
        *t = 0;
    }
    for &k in &members {
        sys.bodies.tag[k as usize] = 1;
    }
    match &m.bonds {
        Some((params, gap)) => {
            sys.bonds = ring_bonds(&sys.bodies, &members, *gap);
            sys.bond_params = Some(*params);
        }
        None => {
            sys.bonds.clear();
            sys.bond_params = None;
        }
    }
    let mut mem = Membrane::new(members, &sys.bodies, m.threshold, m.force);
    mem.ramp = m.ramp;
    sys.membrane = Some(mem);
}

/// Mean magnitude of the contact forces between grains at the last force evaluation (Su
/// Table 1: F_0, "average contact force magnitude" prior to deformation), and how many
/// contacts carried a force. Each touching pair of circles of different grains is one contact.
pub fn mean_contact_force(stepper: &Stepper, sys: &System) -> (f64, usize) {
    let (mut sum, mut n) = (0.0, 0usize);
    for (_, _, f) in stepper.contact_forces(sys) {
        let m = f.norm();
        if m > 0.0 {
            sum += m;
            n += 1;
        }
    }
    (if n > 0 { sum / n as f64 } else { 0.0 }, n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::box_walls;
    use crate::shape::Ball;

    fn grid_of_disks(n: usize, r: f64, a: f64) -> System {
        let mut b = Bodies::new();
        for j in 0..n {
            for i in 0..n {
                b.add(
                    &ClumpShape::disk(r),
                    1.0,
                    Vec2::new((i as f64 + 0.5) * a, (j as f64 + 0.5) * a),
                    0.0,
                )
                .unwrap();
            }
        }
        let l = n as f64 * a;
        let mut s = System::new(b, crate::domain::Domain::open(Vec2::ZERO, Vec2::new(l, l)));
        s.walls = box_walls(Vec2::ZERO, Vec2::new(l, l));
        s
    }

    #[test]
    fn fitting_to_a_box_keeps_the_packing_fraction() {
        let mut s = grid_of_disks(10, 0.4, 1.0);
        let phi = s.packing_fraction();
        let (sx, sy) = fit_to_box(&mut s, Vec2::new(1.0, 2.0), Vec2::new(6.0, 14.0)).unwrap();
        assert_eq!((sx, sy), (0.5, 1.2));
        assert!((s.packing_fraction() / phi - 1.0).abs() < 1e-12);
        // The first grain's centre moved affinely: (0.5, 0.5) -> (1 + 0.25, 2 + 0.6).
        assert!((s.bodies.pos[0] - Vec2::new(1.25, 2.6)).norm() < 1e-12);
    }

    #[test]
    fn each_method_reaches_the_target_packing_fraction() {
        let small = ClumpShape::disk(0.15);
        for (method, target) in [
            (PackingMethod::Scale, 0.40),
            (PackingMethod::Delete, 0.40),
            (PackingMethod::Add, 0.55),
            (PackingMethod::Auto, 0.30),
            (PackingMethod::Auto, 0.60),
        ] {
            let mut s = grid_of_disks(10, 0.4, 1.0);
            let c = adjust_packing(
                &mut s,
                &Sample::boxed(Vec2::ZERO, Vec2::new(10.0, 10.0)),
                target,
                method,
                0.03,
                &small,
                1.0,
                3,
            )
            .unwrap();
            assert!((c.to - target).abs() < 1e-12, "{method:?}: {c:?}");
            match method {
                PackingMethod::Scale => assert_eq!((c.deleted, c.added), (0, 0)),
                PackingMethod::Delete => assert!(c.deleted > 0 && c.size_scale >= 1.0),
                PackingMethod::Add => assert!(c.added > 0 && c.size_scale <= 1.0),
                PackingMethod::Auto if target < c.from => {
                    // 0.503 -> 0.30 needs a 23 % size cut; auto scales by 3 % and deletes the rest.
                    assert!(c.deleted > 0 && (c.size_scale - 0.97).abs() < 0.03, "{c:?}")
                }
                PackingMethod::Auto => assert!(c.added > 0, "{c:?}"),
            }
        }
    }

    #[test]
    fn added_grains_go_into_interstices_without_overlap() {
        let mut s = grid_of_disks(6, 0.45, 1.0);
        let small = ClumpShape {
            balls: vec![
                Ball {
                    centre: Vec2::new(-0.05, 0.0),
                    r: 0.1,
                },
                Ball {
                    centre: Vec2::new(0.05, 0.0),
                    r: 0.1,
                },
            ],
        };
        let c = adjust_packing(
            &mut s,
            &Sample::boxed(Vec2::ZERO, Vec2::new(6.0, 6.0)),
            0.66,
            PackingMethod::Add,
            0.0,
            &small,
            1.0,
            9,
        )
        .unwrap();
        assert!(c.added > 0);
        // Before the final (shrinking) scaling no circles overlapped; after it none may either.
        let b = &s.bodies;
        for i in 0..b.n_circles() {
            for j in i + 1..b.n_circles() {
                if b.circle_body[i] != b.circle_body[j] {
                    let d = (b.circle_pos(i) - b.circle_pos(j)).norm();
                    assert!(
                        d >= b.circle_r[i] + b.circle_r[j] - 1e-12,
                        "circles {i} and {j} overlap"
                    );
                }
            }
        }
    }

    #[test]
    fn inside_a_membrane_its_grains_stay_and_added_grains_go_inside_its_ring() {
        // 8 x 8 disks on a unit grid; the outer ring of 28 is the membrane (tag 1); the sample
        // is the polygon through its centres, [0.5, 7.5]², area 49.
        let mut s = grid_of_disks(8, 0.45, 1.0);
        let edge = |p: Vec2| p.x < 1.0 || p.x > 7.0 || p.y < 1.0 || p.y > 7.0;
        for k in 0..s.bodies.len() {
            s.bodies.tag[k] = edge(s.bodies.pos[k]) as u32;
        }
        let ring = [
            Vec2::new(0.5, 0.5),
            Vec2::new(7.5, 0.5),
            Vec2::new(7.5, 7.5),
            Vec2::new(0.5, 7.5),
        ];
        let sample = Sample {
            lo: Vec2::ZERO,
            hi: Vec2::new(8.0, 8.0),
            area: 49.0,
            ring: Some(&ring),
        };
        let from = s.bodies.total_area() / 49.0; // 64 π 0.45² / 49 = 0.831
        let c = adjust_packing(
            &mut s,
            &sample,
            0.3,
            PackingMethod::Delete,
            0.0,
            &ClumpShape::disk(0.1),
            1.0,
            5,
        )
        .unwrap();
        assert!(
            (c.from - from).abs() < 1e-12 && (c.to - 0.3).abs() < 1e-12,
            "{c:?}"
        );
        // 0.831 -> 0.3 needs more than the 36 inner grains' share: all go, the 28 stay.
        assert_eq!(s.bodies.tag.iter().filter(|&&t| t == 1).count(), 28);
        let mut s = grid_of_disks(8, 0.3, 1.0);
        let n = s.bodies.len();
        let c = adjust_packing(
            &mut s,
            &sample,
            0.5,
            PackingMethod::Add,
            0.0,
            &ClumpShape::disk(0.1),
            1.0,
            5,
        )
        .unwrap();
        assert!(c.added > 0);
        // Without the ring some of them would land in the 0.5-wide band round it (a box of 8).
        for k in n..s.bodies.len() {
            assert!(
                crate::polygon::contains(&ring, s.bodies.pos[k]),
                "added grain {k} outside"
            );
        }
    }

    #[test]
    fn a_target_the_method_cannot_reach_is_refused() {
        let small = ClumpShape::disk(0.1);
        let mut s = grid_of_disks(4, 0.4, 1.0);
        let (lo, hi) = (Vec2::ZERO, Vec2::new(4.0, 4.0));
        // 0.503 now: deleting cannot raise it, adding cannot lower it, 1.2 is no packing fraction.
        for (target, method) in [
            (0.7, PackingMethod::Delete),
            (0.2, PackingMethod::Add),
            (1.2, PackingMethod::Scale),
        ] {
            let r = adjust_packing(
                &mut s,
                &Sample::boxed(lo, hi),
                target,
                method,
                0.0,
                &small,
                1.0,
                1,
            );
            assert!(r.is_err(), "{method:?} to {target}: {r:?}");
        }
    }

    #[test]
    fn the_membrane_is_the_outer_shell_and_its_neighbours_are_bonded() {
        let mut s = grid_of_disks(6, 0.5, 1.0);
        let params = BondParams {
            k_n: 1.0,
            k_s: 1.0,
            sigma_c: 1.0,
            cohesion: 1.0,
            lambda: 0.5,
            damping: 0.0,
        };
        install_membrane(
            &mut s,
            &MembraneSpec {
                shell: 0.5,
                threshold: 0.1,
                force: 1.0,
                ramp: 0.0,
                bonds: Some((params, 0.01)),
            },
        );
        // A 6 x 6 grid: 20 grains on the outer ring, each touching its two ring neighbours.
        assert_eq!(s.bodies.tag.iter().filter(|&&t| t == 1).count(), 20);
        assert_eq!(s.bonds.len(), 20);
        assert_eq!(s.membrane.as_ref().unwrap().bodies.len(), 20);
    }

    #[test]
    fn size_statistics_are_equivalent_diameters() {
        let s = grid_of_disks(3, 0.5, 1.0);
        let st = size_stats(&s.bodies);
        assert_eq!(st.count, 9);
        assert!((st.d_mean - 1.0).abs() < 1e-12 && (st.d_min - 1.0).abs() < 1e-12);
    }
}
