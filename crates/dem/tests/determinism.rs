//! Determinism, checkpoint/resume, the cell list against brute force, and the time-step guard.

use crate::common;
use common::bits;
use lbdem_dem::contact::{LinearSpringDashpot, Rolling};
use lbdem_dem::neighbor::{CellList, brute_force_pairs};
use lbdem_dem::*;

fn packing() -> (System, LinearSpringDashpot, StepParams) {
    // 30 x 30 bidisperse disks (d = 1, 1.4) compressed toward φ = 0.8 in a periodic box.
    let mut s = generate::bidisperse_lattice(30, 1.0, 1.4, 1.42, 11).unwrap();
    let mut law = LinearSpringDashpot::new(2e4, 2e4 * 2.0 / 7.0, Damping::Gamma(100.0), 0.5);
    law.rolling = Some(Rolling {
        k_r: 100.0,
        mu_r: 0.1,
    });
    let p = StepParams::new(2.5e-4, 0.1);
    let mut st = Stepper::new();
    generate::compress_periodic(&mut s, &law, &p, 0.8, 1500, &mut st).unwrap();
    (s, law, p)
}

fn run(s: &mut System, law: &LinearSpringDashpot, p: &StepParams, n: usize) {
    let mut st = Stepper::new();
    for _ in 0..n {
        st.step(p, law, law, s).unwrap();
    }
}

/// Bitwise identical trajectories on 1 and 2 threads (fixed per-pair buffer + canonical gather).
#[test]
fn identical_for_one_and_two_threads() {
    let (s0, law, p) = packing();
    let go = |threads: usize| {
        common::on_threads(threads, || {
            let mut s = s0.clone();
            // Keep shearing a little so contacts slide and the list is rebuilt.
            for _ in 0..4 {
                let (lo, hi) = (s.domain.lo, s.domain.hi);
                let mut d = s.domain;
                d.remap_affine(lo, Vec2::new(hi.x * 1.002, hi.y / 1.002), &mut s.bodies);
                s.domain = d;
                run(&mut s, &law, &p, 300);
            }
            s
        })
    };
    let (a, b) = (go(1), go(2));
    assert!(
        a.contacts
            .hist
            .as_slice::<History>()
            .unwrap()
            .iter()
            .any(|h| h.xi_t.norm() > 0.0),
        "test must exercise tangential history"
    );
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.contacts, b.contacts);
}

/// A run checkpointed (JSON, exact f64 round trip) and resumed with a fresh stepper continues
/// bit for bit like the uninterrupted run.
#[test]
fn resume_from_checkpoint_is_bitwise_identical() {
    let (s0, law, p) = packing();
    let mut whole = s0.clone();
    run(&mut whole, &law, &p, 1000);
    let mut first = s0.clone();
    run(&mut first, &law, &p, 400);
    let text = serde_json::to_string(&first).unwrap();
    let mut resumed: System = serde_json::from_str(&text).unwrap();
    assert_eq!(resumed, first);
    run(&mut resumed, &law, &p, 600);
    assert_eq!(bits(&whole), bits(&resumed));
    assert_eq!(whole.step, resumed.step);
}

/// The cell list finds exactly the pairs of the all-pairs search (jax-md style check), periodic
/// and open, with clumps.
#[test]
fn cell_list_matches_brute_force() {
    let (s, _, _) = packing();
    let b = &s.bodies;
    let pos: Vec<Vec2> = (0..b.n_circles()).map(|c| b.circle_pos(c)).collect();
    for dom in [s.domain, Domain::open(s.domain.lo, s.domain.hi)] {
        let mut cl = CellList::default();
        let got = cl
            .build_pairs(&dom, &pos, &b.circle_r, &b.circle_body, 0.1)
            .unwrap();
        let want = brute_force_pairs(&dom, &pos, &b.circle_r, &b.circle_body, 0.1);
        assert_eq!(got, want);
    }
    let two = ClumpShape {
        balls: vec![
            Ball {
                centre: Vec2::new(-0.3, 0.0),
                r: 0.5,
            },
            Ball {
                centre: Vec2::new(0.3, 0.0),
                r: 0.4,
            },
        ],
    };
    let lo = Vec2::new(0.0, 0.0);
    let hi = Vec2::new(15.0, 15.0);
    let c = generate::random_insert(&[two, ClumpShape::disk(0.4)], &[2.0, 1.0], 1.0, lo, hi, 60, 5).unwrap();
    let pos: Vec<Vec2> = (0..c.n_circles()).map(|k| c.circle_pos(k)).collect();
    let mut cl = CellList::default();
    let got = cl
        .build_pairs(&Domain::open(lo, hi), &pos, &c.circle_r, &c.circle_body, 0.5)
        .unwrap();
    assert_eq!(
        got,
        brute_force_pairs(&Domain::open(lo, hi), &pos, &c.circle_r, &c.circle_body, 0.5)
    );
    assert!(!got.is_empty());
}

/// A step above sqrt(m_min/k_max) is refused with both numbers in the message (the step as
/// given, the critical step to four decimals).
#[test]
fn step_above_critical_is_refused() {
    let (mut s, law, _) = packing();
    let (crit, _, _) = Stepper::critical_time_step(&s, &law, &law);
    let p = StepParams::new(1.5 * crit, 0.1);
    let err = Stepper::new().step(&p, &law, &law, &mut s).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, DemError::TimeStepTooLarge { .. }));
    assert!(
        msg.contains(&format!("{:e}", 1.5 * crit)) && msg.contains(&format!("{crit:.4e}")),
        "{msg}"
    );
}

/// Su et al. 2020 Sect. 2.4 membrane: inward force F_N only beyond the outward threshold.
#[test]
fn membrane_pushes_back_only_beyond_threshold() {
    let mut b = Bodies::new();
    for k in 0..8 {
        let a = k as f64 * std::f64::consts::TAU / 8.0;
        b.add(&ClumpShape::disk(0.1), 1.0, Vec2::new(a.cos(), a.sin()), 0.0)
            .unwrap();
    }
    let m = Membrane::new((0..8).collect(), &b, 0.05, 2.0);
    assert_eq!(m.force_on(0, Vec2::new(1.04, 0.0)), Vec2::ZERO);
    assert_eq!(m.force_on(0, Vec2::new(0.9, 0.3)), Vec2::ZERO);
    let f = m.force_on(0, Vec2::new(1.06, 0.0));
    assert!((f.x + 2.0).abs() < 1e-12 && f.y.abs() < 1e-12);
}

/// Su et al. 2020 Sect. 2.4 packing-fraction adjustment: deleting grains lowers φ by exactly
/// their area; grains added into interstices do not overlap anything.
#[test]
fn grain_removal_and_addition_change_packing_fraction() {
    let shapes = [ClumpShape::disk(0.5), ClumpShape::disk(0.7)];
    let (lo, hi) = (Vec2::ZERO, Vec2::new(20.0, 20.0));
    let bodies = generate::random_insert(&shapes, &[1.0, 1.0], 1.0, lo, hi, 150, 9).unwrap();
    let mut s = System::new(bodies, Domain::open(lo, hi));
    s.walls = generate::box_walls(lo, hi);
    let (n0, phi0) = (s.bodies.len(), s.packing_fraction());
    generate::remove_random(&mut s, 10, 1);
    assert_eq!(s.bodies.len(), n0 - 10);
    assert!(s.packing_fraction() < phi0);
    let phi1 = s.packing_fraction();
    let added = generate::add_in_voids(&mut s, &ClumpShape::disk(0.3), 1.0, 20, 2).unwrap();
    assert_eq!(added, 20);
    let expect = phi1 + 20.0 * std::f64::consts::PI * 0.09 / 400.0;
    assert!((s.packing_fraction() - expect).abs() < 1e-12);
    let b = &s.bodies;
    for i in 0..b.n_circles() {
        for j in i + 1..b.n_circles() {
            assert!((b.circle_pos(j) - b.circle_pos(i)).norm() >= b.circle_r[i] + b.circle_r[j]);
        }
    }
}

/// Two-circle clumps settling under gravity in a walled box (the general, non-disk path of the
/// stepper: circle sums per body, wall contacts): bitwise identical on 1 and 2 threads.
#[test]
fn clumps_with_walls_identical_for_one_and_two_threads() {
    let (s0, law, p) = common::clumps_in_walled_box(30.0, 600, 5);
    let go = |threads: usize| {
        common::on_threads(threads, || {
            let mut s = s0.clone();
            run(&mut s, &law, &p, 3000);
            s
        })
    };
    let (a, b) = (go(1), go(2));
    assert!(
        a.walls[2].n_contacts > 0
            && a.contacts
                .hist
                .as_slice::<History>()
                .unwrap()
                .iter()
                .any(|h| h.xi_t.norm() > 0.0),
        "grains must reach the floor and touch each other"
    );
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(a.contacts, b.contacts);
}

/// A checkpoint whose clump circle sits 2^32 m from its body (found by the `checkpoint_coupled`
/// fuzz harness, where it made the coupled solid-fraction pass loop for minutes) is refused by
/// `check_state`, naming the circle; the undamaged state passes.
#[test]
fn a_circle_beyond_the_domain_is_refused() {
    let s = generate::bidisperse_lattice(4, 1.0, 1.4, 1.42, 11).unwrap();
    assert_eq!(s.check_state(), Ok(()));
    let mut bad = s.clone();
    bad.bodies.circle_offset[3].x = 4294967296.0;
    let err = bad.check_state().unwrap_err();
    assert!(err.contains("circle 3") && err.contains("diagonal"), "{err}");
}

/// The wall pass evaluates only the circles its search found near a wall (within the reach plus
/// the skin, searched again when the pair list is rebuilt or a wall moved half the skin). A
/// push-plate (segment) moving into a row of two-circle clumps at rest, no gravity: nothing else
/// moves, so the pair list is not rebuilt, and only the plate's own motion can start the search
/// that finds the clumps it reaches. The same bits with a skin of 0.05 (the plate moves 1.2, 48
/// half-skins) as with a skin of 100 (every circle near the plate at every step).
#[test]
fn walls_give_the_same_bits_at_any_skin() {
    use lbdem_dem::wall::{Wall, WallMotion, WallShape};
    let grain = common::two_circle_grain();
    let mut bodies = Bodies::new();
    for k in 0..6 {
        bodies
            .add(&grain, 1.0, Vec2::new(1.0 + 1.5 * k as f64, 1.0), 0.3 * k as f64)
            .unwrap();
    }
    let mut s0 = System::new(bodies, Domain::open(Vec2::new(-5.0, -5.0), Vec2::new(15.0, 15.0)));
    s0.walls.push(Wall::new(
        WallShape::Segment {
            a: Vec2::new(0.0, 0.0),
            b: Vec2::new(10.0, 0.0),
        },
        WallMotion::Velocity {
            v: Vec2::new(0.0, 2.0),
        },
    ));
    let law = LinearSpringDashpot::new(2e4, 2e4 * 2.0 / 7.0, Damping::Gamma(50.0), 0.5);
    let go = |skin: f64| {
        let p = StepParams::new(2.0e-4, skin);
        let (mut s, mut st) = (s0.clone(), Stepper::new());
        let mut plate_contacts = 0;
        for _ in 0..3000 {
            st.step(&p, &law, &law, &mut s).unwrap();
            plate_contacts = plate_contacts.max(s.walls[0].n_contacts);
        }
        (s, plate_contacts)
    };
    let ((a, na), (b, nb)) = (go(0.05), go(100.0));
    // 3 at once at most (the grains are knocked off as it reaches them); 0 if the plate's motion
    // did not start the search (checked by disabling it).
    assert!(na >= 2, "the plate must push the grains: {na} at most in contact");
    assert_eq!(na, nb);
    assert_eq!(bits(&a), bits(&b));
    let wall_bits = |s: &System| {
        s.walls
            .iter()
            .flat_map(|w| [w.force.x, w.force.y].map(f64::to_bits))
            .collect::<Vec<_>>()
    };
    assert_eq!(wall_bits(&a), wall_bits(&b));
}
