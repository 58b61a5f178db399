//! Errors of the analysis kernels: each names what was wrong, the value and what to do.

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum AnalysisError {
    #[error(
        "{what}: {n_ref} reference points but {n_def} deformed points; the two snapshots must list \
         the same grains in the same order (compare snapshots of one run)"
    )]
    CountMismatch {
        what: String,
        n_ref: usize,
        n_def: usize,
    },
    #[error(
        "triangulation of {points} points gave no usable triangle (all collinear, or every triangle \
         longer than max_edge = {max_edge:e}); need at least 3 grains not on one line"
    )]
    NoTriangles { points: usize, max_edge: f64 },
    #[error("parameter '{name}' = {value}: {reason}")]
    Invalid {
        name: String,
        value: String,
        reason: String,
    },
}

impl AnalysisError {
    pub fn invalid(name: &str, value: impl std::fmt::Display, reason: &str) -> Self {
        Self::Invalid {
            name: name.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }
}
