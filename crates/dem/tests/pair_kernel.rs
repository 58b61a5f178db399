//! The batched (eight pairs per instruction) pair kernel of the linear and elastic-plastic laws
//! against the generic pair loop: the same trajectories bit for bit, and the same on 1 and 2
//! threads.

use crate::common;
use common::bits;
use lbdem_dem::contact::{ContactInput, ContactOutput, ElasticPlastic, LinearSpringDashpot, Rolling};
use lbdem_dem::*;

/// A law without [`ContactLaw::batched`]: the stepper takes its generic pair loop.
struct Generic<L>(L);

impl<L: ContactLaw<History = History>> ContactLaw for Generic<L> {
    type History = History;
    fn force(&self, c: &ContactInput, h: &mut History) -> ContactOutput {
        self.0.force(c, h)
    }
    fn max_stiffness(&self, r_eff: f64) -> f64 {
        self.0.max_stiffness(r_eff)
    }
    fn friction(&self) -> f64 {
        self.0.friction()
    }
}

/// 24 x 24 periodic bidisperse disks compressed to φ = 0.8, then sheared (sliding contacts,
/// list rebuilds, periodic images).
fn sheared<L: ContactLaw>(law: &L, threads: usize) -> System {
    let mut s = generate::bidisperse_lattice(24, 1.0, 1.4, 1.42, 7).unwrap();
    let p = StepParams::new(2.5e-4, 0.1);
    common::on_threads(threads, || {
        let mut st = Stepper::new();
        generate::compress_periodic(&mut s, law, &p, 0.8, 1200, &mut st).unwrap();
        for _ in 0..4 {
            let (lo, hi) = (s.domain.lo, s.domain.hi);
            let mut d = s.domain;
            d.remap_affine(lo, Vec2::new(hi.x * 1.003, hi.y / 1.003), &mut s.bodies);
            s.domain = d;
            for _ in 0..250 {
                st.step(&p, law, law, &mut s).unwrap();
            }
        }
    });
    s
}

fn hist_bits(s: &System) -> Vec<u64> {
    s.contacts
        .hist
        .as_slice::<History>()
        .unwrap()
        .iter()
        .flat_map(|h| [h.xi_t.x, h.xi_t.y, h.theta_r, h.delta_p].map(f64::to_bits))
        .collect()
}

#[test]
fn batched_kernel_matches_generic_loop_bitwise() {
    let gamma = LinearSpringDashpot::new(2e4, 2e4 * 2.0 / 7.0, Damping::Gamma(100.0), 0.5);
    let mut ratio = LinearSpringDashpot::new(2e4, 1e4, Damping::Ratio(0.3), 0.3);
    ratio.clip = false;
    for law in [gamma, ratio] {
        let (a, b) = (sheared(&law, 1), sheared(&Generic(law), 1));
        let sliding = a
            .contacts
            .hist
            .as_slice::<History>()
            .unwrap()
            .iter()
            .filter(|h| h.xi_t.norm() > 0.0)
            .count();
        assert!(
            sliding > 50,
            "test must exercise tangential history: {sliding} pairs"
        );
        assert!(
            a.contacts.pairs.len() % 8 != 0,
            "test must exercise a partial batch"
        );
        assert_eq!(bits(&a), bits(&b));
        assert_eq!(hist_bits(&a), hist_bits(&b));
        assert_eq!(a.contacts.pairs, b.contacts.pairs);
    }
}

#[test]
fn batched_kernel_identical_for_one_and_two_threads() {
    let law = LinearSpringDashpot::new(2e4, 2e4 * 2.0 / 7.0, Damping::Gamma(100.0), 0.5);
    let (a, b) = (sheared(&law, 1), sheared(&law, 2));
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(hist_bits(&a), hist_bits(&b));
}

/// Two-circle clumps and disks under gravity in a walled open box (arms, no periodic images).
#[test]
fn batched_kernel_matches_generic_loop_for_clumps() {
    let (s0, law, p) = common::clumps_in_walled_box(20.0, 300, 9);
    let go = |l: &dyn Fn(&mut Stepper, &mut System)| {
        let mut s = s0.clone();
        let mut st = Stepper::new();
        for _ in 0..2500 {
            l(&mut st, &mut s);
        }
        s
    };
    let a = go(&|st, s| st.step(&p, &law, &law, s).unwrap());
    let g = Generic(law);
    let b = go(&|st, s| st.step(&p, &g, &g, s).unwrap());
    assert!(
        a.contacts
            .hist
            .as_slice::<History>()
            .unwrap()
            .iter()
            .any(|h| h.xi_t.norm() > 0.0),
        "grains must touch each other"
    );
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(hist_bits(&a), hist_bits(&b));
}

/// Su et al. 2020's elastic-plastic law with a rolling spring, as the Su scenes run it, and the
/// linear law with one: yielding, plastic unloading and capped rolling torques bit for bit.
#[test]
fn batched_kernel_matches_generic_loop_for_plastic_and_rolling_laws() {
    let rolling = Some(Rolling { k_r: 20.0, mu_r: 0.1 });
    let plastic = ElasticPlastic {
        k_e: 2e4,
        k_p: 2e3,
        f_y: 20.0,
        k_t: 1e4,
        damping: Damping::Ratio(0.3),
        mu: 0.3,
        rolling,
    };
    let mut linear = LinearSpringDashpot::new(2e4, 1e4, Damping::Gamma(100.0), 0.5);
    linear.rolling = rolling;
    let (a, b) = (sheared(&plastic, 1), sheared(&Generic(plastic), 1));
    let h = a.contacts.hist.as_slice::<History>().unwrap();
    let yielded = h.iter().filter(|h| h.delta_p > 0.0).count();
    let capped = h.iter().filter(|h| h.theta_r != 0.0).count();
    // Measured: 598 of 1 103 pairs carry a plastic overlap, 206 a rolling angle (a kernel that
    // drops the rolling cap, or divides the yield overlap wrongly, fails the bits below).
    assert!(
        yielded > 50,
        "test must exercise the yield envelope: {yielded} pairs"
    );
    assert!(
        capped > 50,
        "test must exercise the rolling spring: {capped} pairs"
    );
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(hist_bits(&a), hist_bits(&b));
    assert_eq!(a.contacts.pairs, b.contacts.pairs);
    let (a, b) = (sheared(&linear, 1), sheared(&Generic(linear), 1));
    assert_eq!(bits(&a), bits(&b));
    assert_eq!(hist_bits(&a), hist_bits(&b));
    let (c, d) = (sheared(&plastic, 1), sheared(&plastic, 2));
    assert_eq!(bits(&c), bits(&d));
    assert_eq!(hist_bits(&c), hist_bits(&d));
}
