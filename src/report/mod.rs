//! Reports: plots (plotters, with an embedded font so PNGs are the same everywhere),
//! tables (polars, eager) and the HTML page with its provenance block.

pub mod grid_map;
pub mod legend;
pub mod lines;
pub mod mechanism_map;
pub mod panels;
pub mod plot;
pub mod table;
