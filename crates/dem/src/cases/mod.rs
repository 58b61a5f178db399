//! Cases with a checkable answer, run by tests and by the step map alike. Pure computation:
//! each returns what it measured; callers judge, draw and write.

pub mod head_on;
pub mod packing;
