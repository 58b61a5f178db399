//! Validation cases built from the engines, shared by the tests, the benchmark and the
//! speed-versus-error study (no I/O: callers write what they need).

pub mod dkt;
pub mod settling;
