//! Walk the method toward its failure: tau -> 1/2 and the Mach number upward. Every run must either
//! stay within its accuracy bound (Taylor-Green decay, REFERENCES.md: exp(-2 nu k^2 t)) or be
//! refused at set-up, or be stopped with a diagnosis naming the step, the node and the cause.
//! Never a silent NaN. The set-up check is the one scenes use (`lbdem_core::units::lattice`, Su
//! et al. 2020 Eqs. 15-16): Ma above 0.3 or tau <= 1/2 is refused, Ma above 0.1 warned. Runs the
//! check accepts without warning must keep the nu error below 5 %; warned runs (0.1 < Ma <= 0.3,
//! compressibility error of order Ma^2, or cell Reynolds number above 10, under-resolved) must end
//! finite or be stopped with the diagnosis.

#![allow(clippy::needless_range_loop)]
use crate::common;
use common::*;
use lbdem_lbm::cases::taylor_green::{self, Spec, Verdict};
use lbdem_lbm::{Collision, D2Q9, Fluid, LbmError, Stepper};

enum Outcome {
    Accurate(f64),
    Warned(f64),
    Stopped(LbmError),
    Refused(String),
}

/// Taylor-Green on 32x32 with amplitude u0 and the given collision (`lbdem_lbm::cases`), as the
/// set-up check and then the engine see it; ν error bound 5 %.
fn tg(collision: Collision, u0: f64) -> Outcome {
    let warned = match taylor_green::setup_verdict(collision, u0) {
        Verdict::Accepted => false,
        Verdict::Warned(_) => true,
        Verdict::Refused(e) => return Outcome::Refused(e),
    };
    match taylor_green::run(&Spec::new(collision, u0)) {
        Err(e) => Outcome::Refused(e.to_string()),
        Ok(r) => match (r.stopped, r.nu_error) {
            (Some(e), _) => Outcome::Stopped(e),
            (None, Some(err)) if warned => Outcome::Warned(err),
            (None, Some(err)) => Outcome::Accurate(err),
            (None, None) => unreachable!("a finished run has a nu error"),
        },
    }
}

fn assert_ok_or_diagnosed(o: &Outcome, what: &str) {
    match o {
        Outcome::Accurate(err) => assert!(*err < 0.05, "{what}: ran but nu error {err}"),
        Outcome::Warned(err) => {
            eprintln!("{what}: warned run, nu error {err:.3}");
            // A warned run still answers: its ν error is bounded, if less tightly than an
            // accurate one's. Measured up to 0.092 (BGK τ = 0.5005; the others 0.000-0.061, test
            // profile, which rounds as release); the bound is about twice that.
            assert!(*err < 0.2, "{what}: warned run with nu error {err}")
        }
        Outcome::Stopped(e) => {
            let LbmError::Unstable {
                step, node, cause, ..
            } = e
            else {
                panic!("{what}: unexpected error {e}")
            };
            assert!(*step > 0 && node[0] < 32 && node[1] < 32, "{what}: {e}");
            assert!(!cause.is_empty());
            let msg = e.to_string();
            assert!(
                msg.contains("step") && msg.contains("node") && msg.contains("likely cause"),
                "{msg}"
            );
        }
        Outcome::Refused(e) => assert!(
            e.contains("tau") || e.contains("Mach") || e.contains("viscosity"),
            "{what}: {e}"
        ),
    }
}

#[test]
fn tau_walk_toward_one_half() {
    let mut kinds = [0; 3];
    let mut accurate = 0;
    for tau in [0.6, 0.55, 0.52, 0.51, 0.505, 0.502, 0.5005, 0.5, 0.49] {
        for c in [Collision::Bgk { tau }, Collision::Trt { tau, magic: 0.25 }] {
            // lattice velocity 0.05 (Ma 0.087): Reynolds number up to 3200 near tau = 1/2
            let o = tg(c, 0.05);
            assert_ok_or_diagnosed(&o, &format!("{c:?}"));
            accurate += usize::from(matches!(o, Outcome::Accurate(_)));
            kinds[match o {
                Outcome::Accurate(_) | Outcome::Warned(_) => 0,
                Outcome::Stopped(_) => 1,
                Outcome::Refused(_) => 2,
            }] += 1;
        }
    }
    // the walk must reach the refusal at tau <= 1/2 and have accurate runs before it
    assert!(kinds[0] > 0 && kinds[2] == 4, "{kinds:?}");
    assert!(accurate >= 4, "{accurate}");
}

#[test]
fn mach_walk_upward() {
    let mut kinds = [0; 4];
    for u0 in [0.01, 0.03, 0.05, 0.1, 0.15, 0.2, 0.3, 0.45, 0.6] {
        let o = tg(Collision::Bgk { tau: 0.6 }, u0);
        assert_ok_or_diagnosed(&o, &format!("u0 {u0}"));
        kinds[match o {
            Outcome::Accurate(_) => 0,
            Outcome::Warned(_) => 1,
            Outcome::Stopped(_) => 2,
            Outcome::Refused(_) => 3,
        }] += 1;
    }
    // accurate at low Ma, warned in between, refused above Ma 0.3 (u0 > 0.173)
    assert!(kinds[0] >= 3 && kinds[1] >= 1 && kinds[3] >= 3, "{kinds:?}");
}

#[test]
fn blow_up_is_stopped_at_first_bad_step_with_node() {
    // BGK at tau = 0.5 + 1e-6 driven hard in a channel: the velocity runs away; the run stops
    // the first time a node leaves |u| < 0.4 and reports where and why.
    let dom = channel(8, 16);
    let mut fl = Fluid::<D2Q9, f64>::new(dom, no_obstacles());
    let mut st = Stepper::new(&fl, settings(Collision::Bgk { tau: 0.500001 }, [1e-3, 0.0, 0.0])).unwrap();
    let mut err = None;
    for _ in 0..100_000 {
        if let Err(e) = st.step(&mut fl, None) {
            err = Some(e);
            break;
        }
    }
    let e = err.expect("a diverging run must be stopped");
    let LbmError::Unstable { step, node, u, .. } = &e else {
        panic!("{e}")
    };
    // the step before was within limits: the reported node is the first violation
    assert!(u[0].abs() >= 0.4 || !u[0].is_finite(), "{e}");
    assert!(*step == fl.step && node[1] < 16);
    eprintln!("{e}");
}

#[test]
#[ignore]
fn explore_tau() {
    for tau in [0.52, 0.515, 0.51, 0.507, 0.505, 0.502, 0.5005] {
        for c in [
            Collision::Bgk { tau },
            Collision::Trt { tau, magic: 0.25 },
            Collision::Trt {
                tau,
                magic: 3.0 / 16.0,
            },
        ] {
            match tg(c, 0.05) {
                Outcome::Accurate(e) | Outcome::Warned(e) => eprintln!("{c:?} err {e:.4}"),
                Outcome::Stopped(e) => eprintln!("{c:?} stopped {e}"),
                Outcome::Refused(e) => eprintln!("{c:?} refused {e}"),
            }
        }
    }
}
