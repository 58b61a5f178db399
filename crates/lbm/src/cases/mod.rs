//! Validation cases with a known answer, run by tests and by the stability maps alike. Pure
//! computation: each returns its measured error and how it ended; callers draw and write.

pub mod poiseuille;
pub mod taylor_green;
