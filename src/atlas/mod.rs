//! The speed-against-accuracy atlas (issue 16): for each knob a user can turn, runs of a case
//! with a published or converged answer, each one point (error, wall time), and the
//! non-dominated settings among them. The studies compute; the `tradeoffs` stage writes.

pub mod chart;
pub mod pareto;
pub mod run_pairs;
pub mod studies;

/// One run of a study: a setting, its error against the study's reference and its wall time.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Point {
    /// The knob the study varies ("resolution", "precision", "method", "collision", ...).
    pub study: String,
    /// The series the point belongs to in the chart (e.g. "PSM f64", "TRT Λ = 3/16").
    pub setting: String,
    /// The value along the series (cells per diameter, τ, mass scale ...).
    pub value: f64,
    /// |error| against the study's reference (the measure is in the study's caption).
    pub error: f64,
    pub wall_seconds: f64,
}
