//! The seams of the engine: a contact law defined outside the crate acting across a gap, a law
//! with more history than the 4 f64 of the built-in laws, and a user force hook, all through
//! the normal `Stepper` (no stepper or kernel edit).

use crate::common;
use lbdem_dem::contact::{ContactInput, ContactOutput, LinearSpringDashpot};
use lbdem_dem::*;

/// Linear "gap spring": F_n = k (h + δ) for δ > −h (repulsive, acting across gaps up to h), no
/// history. Defined only here.
struct GapSpring {
    k: f64,
    h: f64,
}

impl ContactLaw for GapSpring {
    type History = ();
    fn force(&self, c: &ContactInput, _h: &mut ()) -> ContactOutput {
        let f_n = self.k * (self.h + c.delta);
        ContactOutput {
            f: c.n * (-f_n),
            m_roll: 0.0,
            f_n,
        }
    }
    fn max_stiffness(&self, _r_eff: f64) -> f64 {
        self.k
    }
    fn friction(&self) -> f64 {
        0.0
    }
    fn range(&self, _r_i: f64, _r_j: f64) -> f64 {
        self.h
    }
}

/// Two unit disks (mass π) at rest with centre distance 2 + gap, one step of the gap spring:
/// (force on disk 0 from the last evaluation, the analytic force at the final positions, the
/// number of interacting pairs).
fn gap_run(gap: f64, skin: f64) -> (Vec2, Vec2, usize, usize) {
    let d = ClumpShape::disk(1.0);
    let mut s = common::two(&d, &d, Vec2::new(0.0, 0.0), Vec2::new(2.0 + gap, 0.0));
    let law = GapSpring { k: 100.0, h: 0.2 };
    let mut st = Stepper::new();
    st.step(&StepParams::new(1e-3, skin), &law, &law, &mut s).unwrap();
    let dist = (s.bodies.pos[1] - s.bodies.pos[0]).norm();
    let analytic = if dist < 2.0 + law.h {
        Vec2::new(-law.k * (law.h - (dist - 2.0)), 0.0)
    } else {
        Vec2::ZERO
    };
    let listed = st.contact_forces(&s).count();
    (
        s.bodies.force[0],
        analytic,
        st.n_contacts(),
        listed + 10 * s.contacts.pairs.len(),
    )
}

#[test]
fn gap_law_defined_outside_the_crate_acts_across_its_range_only() {
    // Gap 0.15 < h = 0.2 with a skin of 0.01: the pair is listed only because the list reaches
    // the law's range; the force is k (h − gap) = 5 N pushing the disks apart.
    let (f, want, n, listed) = gap_run(0.15, 0.01);
    println!("gap 0.15: force on 0 = {:?}, analytic {:?}", f, want);
    assert!(want.x < -4.99 && want.x > -5.0, "analytic {want:?}");
    assert!((f - want).norm() <= 1e-12 * want.norm(), "{f:?} vs {want:?}");
    assert_eq!(n, 1);
    assert_eq!(listed, 11, "one listed pair, reported by contact_forces");
    // Gap 0.25 > h (in the Verlet list thanks to the skin 0.1): no force at all.
    let (f, want, n, listed) = gap_run(0.25, 0.1);
    assert_eq!(want, Vec2::ZERO);
    assert_eq!(f, Vec2::ZERO, "no force beyond the range");
    assert_eq!((n, listed), (0, 10), "listed, not acting");
}

/// History of [`Counting`]: the linear law's own four slots plus two more (six f64 slots).
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
struct Counted {
    base: History,
    steps: u64,
    peak: f64,
}

/// The linear law that also counts its force evaluations in contact and keeps the peak overlap.
struct Counting(LinearSpringDashpot);

impl ContactLaw for Counting {
    type History = Counted;
    fn force(&self, c: &ContactInput, h: &mut Counted) -> ContactOutput {
        h.steps += 1;
        h.peak = h.peak.max(c.delta);
        self.0.force(c, &mut h.base)
    }
    fn max_stiffness(&self, r_eff: f64) -> f64 {
        self.0.max_stiffness(r_eff)
    }
    fn friction(&self) -> f64 {
        self.0.friction()
    }
}

/// Disk 0 moves obliquely onto disk 1 and the two are pressed together by a hook (20 N each);
/// a third disk far away keeps moving so the Verlet list is rebuilt every few steps.
fn counting_setup() -> (System, Counting, StepParams) {
    let d = ClumpShape::disk(0.5);
    let mut b = Bodies::new();
    b.add(&d, 1.0, Vec2::new(0.0, 0.0), 0.0).unwrap();
    b.add(&d, 1.0, Vec2::new(1.02, 0.0), 0.0).unwrap();
    b.add(&d, 1.0, Vec2::new(-5.0, -5.0), 0.0).unwrap();
    b.vel[0] = Vec2::new(0.3, 0.05);
    b.vel[2] = Vec2::new(0.0, 2.0);
    let s = System::new(b, Domain::open(Vec2::new(-10.0, -10.0), Vec2::new(10.0, 10.0)));
    let law = Counting(LinearSpringDashpot::new(1e3, 400.0, Damping::Ratio(0.3), 0.3));
    (s, law, StepParams::new(1e-3, 0.02))
}

/// Steps `s` by `n` steps; returns the number of steps after which the pair (0, 1) touched.
fn run_counting(st: &mut Stepper, s: &mut System, law: &Counting, p: &StepParams, n: usize) -> u64 {
    let mut touched = 0;
    let mut press = |_t: f64, _s: &System, force: &mut [Vec2], _torque: &mut [f64]| {
        force[0].x += 20.0;
        force[1].x -= 20.0;
    };
    for _ in 0..n {
        st.step_with(p, law, law, s, &mut press).unwrap();
        touched += st.contact_forces(s).filter(|&(i, j, _)| (i, j) == (0, 1)).count() as u64;
    }
    touched
}

fn pair01(s: &System) -> Counted {
    let k = s
        .contacts
        .pairs
        .iter()
        .position(|p| *p == [0, 1])
        .expect("pair (0, 1) listed");
    s.contacts.hist.as_slice::<Counted>().expect("Counted layout")[k]
}

#[test]
fn law_with_six_slot_history_keeps_it_across_rebuilds_and_checkpoints() {
    let (mut a, law, p) = counting_setup();
    let mut st = Stepper::new();
    let n1 = run_counting(&mut st, &mut a, &law, &p, 150);
    let mid = a.to_checkpoint();
    let n2 = run_counting(&mut st, &mut a, &law, &p, 150);
    let h = pair01(&a);
    println!(
        "touched {} steps, count {}, peak overlap {:.3e}, xi_t {:?}, rebuilds {}, stride {}",
        n1 + n2,
        h.steps,
        h.peak,
        h.base.xi_t,
        st.rebuilds,
        a.contacts.hist.stride()
    );
    assert_eq!(a.contacts.hist.stride(), 6);
    assert!(
        n1 > 0 && n2 == 150,
        "the disks must touch from the first half on: {n1}, {n2}"
    );
    assert!(
        st.rebuilds > 10,
        "the list must be rebuilt while in contact: {}",
        st.rebuilds
    );
    assert_eq!(
        h.steps,
        n1 + n2,
        "one count per step in contact, carried across every rebuild"
    );
    assert!(
        h.peak > 0.0 && h.base.xi_t.norm() > 0.0,
        "the base history is kept too"
    );
    // Resume from the checkpoint with a fresh stepper: the same bits, history included.
    let mut b = System::from_checkpoint(&mid).unwrap();
    assert_eq!(pair01(&b).steps, n1, "the checkpoint holds the six-slot history");
    run_counting(&mut Stepper::new(), &mut b, &law, &p, 150);
    assert_eq!(common::bits(&a), common::bits(&b));
    assert_eq!(a.contacts, b.contacts);
}

#[test]
fn force_hook_adds_a_known_force_and_torque() {
    // One disk, no gravity: constant F and T from the hook. Velocity Verlet is exact for a
    // constant force, so x(t) = x0 + v0 t + F t²/(2m), ω(t) = T t / I to rounding.
    let d = ClumpShape::disk(0.5);
    let mut b = Bodies::new();
    b.add(&d, 2.0, Vec2::new(1.0, -1.0), 0.0).unwrap();
    b.vel[0] = Vec2::new(0.5, 0.0);
    let mut s = System::new(b, Domain::open(Vec2::new(-50.0, -50.0), Vec2::new(50.0, 50.0)));
    let law = Law::Linear(LinearSpringDashpot::new(1e3, 400.0, Damping::Ratio(0.1), 0.3));
    let (f, t) = (Vec2::new(3.0, -1.5), 0.25);
    let mut calls = 0u32;
    let mut hook = |_t: f64, _s: &System, force: &mut [Vec2], torque: &mut [f64]| {
        calls += 1;
        force[0] += f;
        torque[0] += t;
    };
    let p = StepParams::new(1e-3, 0.05);
    let mut st = Stepper::new();
    let n = 2000;
    for _ in 0..n {
        st.step_law_with(&p, &law, &law, &mut s, &mut hook).unwrap();
    }
    let (m, i) = (s.bodies.mass[0], s.bodies.inertia[0]);
    let time = n as f64 * p.dt;
    let x = Vec2::new(1.0 + 0.5 * time, -1.0) + f * (0.5 * time * time / m);
    let v = Vec2::new(0.5, 0.0) + f * (time / m);
    let (w, a) = (t * time / i, 0.5 * t * time * time / i);
    let err = (s.bodies.pos[0] - x).norm() / x.norm();
    println!(
        "t = {time}: x {:?} (analytic {:?}), rel. error {err:.2e}; ω {} (analytic {w}); hook calls {calls}",
        s.bodies.pos[0], x, s.bodies.omega[0]
    );
    assert_eq!(calls, n + 1, "once to prime F(0), then once per step");
    assert!(err < 1e-12, "position error {err:e}");
    assert!((s.bodies.vel[0] - v).norm() < 1e-12 * v.norm());
    assert!((s.bodies.omega[0] - w).abs() < 1e-12 * w.abs());
    assert!((s.bodies.angle[0] - a).abs() < 1e-12 * a.abs());
}

#[test]
fn registered_laws_keep_their_scene_names() {
    let l: Law = serde_json::from_str(
        r#"{"law": "linear", "k_n": 1e3, "k_t": 400.0, "damping": {"ratio": 0.1}, "mu": 0.3}"#,
    )
    .unwrap();
    assert_eq!(l.name(), "linear");
    assert!(matches!(l, Law::Linear(ref x) if x.k_n == 1e3));
    let back: Law = serde_json::from_str(&serde_json::to_string(&l).unwrap()).unwrap();
    assert_eq!(back, l);
    assert!(
        serde_json::to_string(&l)
            .unwrap()
            .starts_with(r#"{"law":"linear","#)
    );
}

#[test]
fn step_law_dispatch_matches_the_enum_law_bitwise() {
    // `step_law` runs the pass monomorphised for the pair law's variant (its own history type),
    // the wall law through the enum; `step::<Law, Law>` dispatches every contact through the
    // enum (LawHistory records). Same bits, different wall and pair laws.
    let (s0, lin, p) = common::clumps_in_walled_box(20.0, 200, 11);
    let mut pl = LinearSpringDashpot::new(1e4, 4e3, Damping::Ratio(0.2), 0.4);
    pl.rolling = Some(contact::Rolling { k_r: 20.0, mu_r: 0.1 });
    let (law, wall_law) = (Law::Linear(pl), Law::Linear(lin));
    let (mut a, mut b) = (s0.clone(), s0);
    let (mut sa, mut sb) = (Stepper::new(), Stepper::new());
    for _ in 0..6000 {
        sa.step_law(&p, &law, &wall_law, &mut a).unwrap();
        sb.step(&p, &law, &wall_law, &mut b).unwrap();
    }
    assert!(
        sa.n_contacts() > 50 && a.walls[2].n_contacts > 0,
        "{}",
        sa.n_contacts()
    );
    assert_eq!(common::bits(&a), common::bits(&b));
    let ha: Vec<_> = a.contacts.pairs_with_history().collect();
    let hb: Vec<_> = b.contacts.pairs_with_history().collect();
    println!(
        "{} pairs in contact, {} with history, {} floor contacts",
        sa.n_contacts(),
        ha.len(),
        a.walls[2].n_contacts
    );
    assert!(ha.len() > 50);
    assert_eq!(ha, hb);
}
