//! Validation cases with a known answer, run by tests and by the stability maps alike. Pure
//! computation: each returns its measured error and how it ended; callers draw and write.

pub mod bingham_poiseuille;
pub mod poiseuille;
pub mod taylor_green;

use crate::Collision;
use lbdem_core::units::lattice::{LatticeInput, LatticeUnits, TimeSpec};

/// What the set-up check scenes use (`LatticeUnits::derive`, lattice units dx = dt = ρ = 1)
/// says of a setting.
#[derive(Clone, Debug, PartialEq)]
pub enum Verdict {
    Accepted,
    Warned(Vec<String>),
    Refused(String),
}

/// The set-up check's verdict on `collision` for a flow whose largest expected speed is `u_max`
/// (lattice units).
pub fn setup_verdict(collision: Collision, u_max: f64) -> Verdict {
    let inp = LatticeInput::new(1.0, collision.nu(), 1.0, u_max, TimeSpec::Tau(collision.tau()));
    match LatticeUnits::derive(&inp) {
        Ok(u) if u.warnings.is_empty() => Verdict::Accepted,
        Ok(u) => Verdict::Warned(u.warnings),
        Err(e) => Verdict::Refused(e.to_string()),
    }
}
