//! The decaying Taylor-Green vortex on a periodic L × L box (D2Q9): with k = 2π/L the kinetic
//! energy decays as exp(−4νk²t) (Taylor & Green, Proc. R. Soc. A 158 (1937) 499; REFERENCES.md,
//! LBM), so the viscosity a run actually has is measured from two energies and compared with the
//! one its τ asks for, ν = c_s²(τ − ½) (Su et al. 2020 Eq. 15).
//!
//! Used by `crates/lbm/tests/stability.rs` and the `stability-map` stage: the set-up check
//! verdict ([`setup_verdict`], the check scenes use) is reported apart from the run, and a run
//! can be forced past the engine's own τ > ½ refusal, so a map shows what a refused setting would
//! have done.

use crate::{
    Collision, D2Q9, Domain, Fluid, LbmError, Limits, Macro, Real, Settings, Stepper, StepperAa, Storage,
};
use std::f64::consts::PI;
use std::time::Instant;

/// One run: the collision, the velocity amplitude u0 (lattice units, Ma = u0/c_s) and the box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spec {
    pub collision: Collision,
    pub u0: f64,
    /// Box side L in nodes.
    pub size: usize,
    /// Run τ ≤ ½ although the engine refuses it ([`Stepper::new_past_tau_check`]).
    pub force_past_refusal: bool,
}

impl Spec {
    /// The 32 × 32 box of the stability tests, not forced.
    pub fn new(collision: Collision, u0: f64) -> Self {
        Self {
            collision,
            u0,
            size: 32,
            force_past_refusal: false,
        }
    }
}

/// How a run ended.
#[derive(Debug)]
pub struct Run {
    /// |ν_measured − ν| / |ν|; `None` when the run was stopped.
    pub nu_error: Option<f64>,
    /// The engine's diagnosis when it stopped the run (always [`LbmError::Unstable`]).
    pub stopped: Option<LbmError>,
    /// Steps run: to the stop, or the whole run.
    pub steps: u64,
}

pub use super::Verdict;

/// The set-up check's verdict on `collision` at amplitude `u0` (u_max = u0).
pub fn setup_verdict(collision: Collision, u0: f64) -> Verdict {
    super::setup_verdict(collision, u0)
}

/// Run the vortex. Errors are the engine's refusals at set-up (τ ≤ ½ unless forced); a run that
/// leaves the engine's limits is not an error but a [`Run`] with `stopped` set.
pub fn run(spec: &Spec) -> Result<Run, LbmError> {
    let (l, u0, collision) = (spec.size, spec.u0, spec.collision);
    let k = 2.0 * PI / l as f64;
    let mut fl = Fluid::<D2Q9, f64>::new(Domain::periodic([l, l, 1]), Vec::new());
    fl.init_equilibrium(|p| {
        let (x, y) = (p[0] as f64, p[1] as f64);
        let u = [
            -u0 * (k * x).cos() * (k * y).sin(),
            u0 * (k * x).sin() * (k * y).cos(),
            0.0,
        ];
        // the pressure of the vortex, p = −ρ u0²/4 (cos 2kx + cos 2ky), as a density (p = c_s² ρ)
        (
            1.0 - 0.75 * u0 * u0 * ((2.0 * k * x).cos() + (2.0 * k * y).cos()),
            u,
        )
    });
    let settings = Settings {
        collision,
        force: [0.0; 3],
        limits: Limits::default(),
    };
    let (mut st, (wp, wm)) = if spec.force_past_refusal {
        (
            Stepper::new_past_tau_check(&fl, settings)?,
            collision.rates_past_tau_check()?,
        )
    } else {
        (Stepper::new(&fl, settings)?, collision.rates()?)
    };
    let nu = collision.nu();
    // Start after the initial non-equilibrium transient, ten times the slower relaxation time;
    // end two energy e-folding times 1/(4νk²) later, within [50, 4000] steps.
    let t1 = (10.0 / wp.min(wm)).max(50.0) as u64;
    let t2 = t1 + ((0.5 / (nu.abs() * k * k)) as u64).clamp(50, 4000);
    let mut m = Macro::default();
    let mut e = [0.0; 2];
    for s in 1..=t2 {
        let want = s == t1 || s == t2;
        if let Err(err) = st.step(&mut fl, if want { Some(&mut m) } else { None }) {
            return Ok(Run {
                nu_error: None,
                stopped: Some(err),
                steps: s,
            });
        }
        if want {
            e[usize::from(s == t2)] = m.u.iter().map(|v| v * v).sum();
        }
    }
    let nu_meas = (e[0] / e[1]).ln() / (4.0 * k * k * (t2 - t1) as f64);
    Ok(Run {
        nu_error: Some((nu_meas - nu).abs() / nu.abs()),
        stopped: None,
        steps: t2,
    })
}

/// A vortex run on the in-place AA stepper with its populations stored as `St` (arithmetic in
/// `T`): the storage study of the atlas (`lbdem tradeoffs`).
#[derive(Clone, Copy, Debug)]
pub struct StoredRun {
    /// max |u − u_exact| / (u0 e^(−2νk²t)) over the box at the end, u_exact the decaying vortex.
    pub error: f64,
    /// Wall time of the stepping (the set-up and the final readout left out).
    pub seconds: f64,
}

/// The vortex of amplitude `u0` on a periodic `size` × `size` box (BGK τ = 0.8), `steps` steps
/// of the AA stepper with populations stored as `St`, against the analytic field
/// u(x, t) = u(x, 0) e^(−2νk²t). At small u0 the stored form shows: f32 holds f itself (about
/// 0.1) to 6e-8 of it, far coarser than the vortex's share of it; the shifted forms store f − w_i.
pub fn stored<T: Real, St: Storage<T>>(size: usize, u0: f64, steps: usize) -> Result<StoredRun, LbmError> {
    let l = size;
    let k = 2.0 * PI / l as f64;
    let collision = Collision::Bgk { tau: 0.8 };
    let nu = collision.nu();
    let field = |x: f64, y: f64| [-(k * x).cos() * (k * y).sin(), (k * x).sin() * (k * y).cos()];
    let mut fl = Fluid::<D2Q9, T>::new(Domain::periodic([l, l, 1]), Vec::new());
    fl.init_equilibrium(|p| {
        let (x, y) = (p[0] as f64, p[1] as f64);
        let v = field(x, y);
        (
            1.0 - 0.75 * u0 * u0 * ((2.0 * k * x).cos() + (2.0 * k * y).cos()),
            [u0 * v[0], u0 * v[1], 0.0],
        )
    });
    let settings = Settings {
        collision,
        force: [0.0; 3],
        limits: Limits::default(),
    };
    let mut st = StepperAa::<D2Q9, T, St>::with_storage(&mut fl, settings)?;
    let mut m = Macro::default();
    let t0 = Instant::now();
    for s in 1..=steps {
        st.step(&mut fl, (s == steps).then_some(&mut m))?;
    }
    let seconds = t0.elapsed().as_secs_f64();
    let amp = u0 * (-2.0 * nu * k * k * steps as f64).exp();
    let mut error: f64 = 0.0;
    for y in 0..l {
        for x in 0..l {
            let v = field(x as f64, y as f64);
            let idx = x + l * y;
            for a in 0..2 {
                error = error.max((m.u[3 * idx + a] - amp * v[a]).abs() / amp);
            }
        }
    }
    Ok(StoredRun { error, seconds })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_refused_tau_runs_only_when_forced() {
        let c = Collision::Bgk { tau: 0.49 };
        assert!(matches!(setup_verdict(c, 0.05), Verdict::Refused(_)));
        let mut spec = Spec::new(c, 0.05);
        assert!(matches!(run(&spec), Err(LbmError::Tau { .. })));
        spec.force_past_refusal = true;
        let r = run(&spec).unwrap();
        // ω = 2.04 > 2 amplifies the non-equilibrium part each step: the run is stopped.
        assert!(matches!(r.stopped, Some(LbmError::Unstable { .. })), "{r:?}");
        assert!(r.nu_error.is_none() && r.steps > 0);
    }
}
