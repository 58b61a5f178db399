//! Reports: plots (plotters, with an embedded font so PNGs are the same everywhere),
//! tables (polars, eager) and the HTML page with its provenance block.

pub mod plot;
pub mod table;
