//! Errors of the extruder driver: each names the parameter, its value, the limit and the fix.

use super::super::error::SphereError;
use thiserror::Error;

#[derive(Debug, Error, PartialEq)]
pub enum ExtruderError {
    /// A geometry or driver parameter out of its range.
    #[error("{name} = {value:e} is invalid: {why}; {fix}")]
    Parameter {
        name: &'static str,
        value: f64,
        why: String,
        fix: String,
    },
    /// A mobile grain got through a wall line (the wall grains are too sparse).
    #[error(
        "grain {grain} at ({x:e}, {y:e}) m left the extruder through a wall at step {step}; \
         the wall grains are too sparse or the contact too soft: lower wall_spacing or wall_jitter, \
         or lower the body force"
    )]
    Leak { grain: usize, x: f64, y: f64, step: u64 },
    #[error(transparent)]
    Engine(#[from] SphereError),
}
