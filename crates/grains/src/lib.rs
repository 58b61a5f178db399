//! lbdem-grains: the digitise kernels. A grey image of grains in liquid (a radiograph's
//! solid-fraction map, or a photograph) becomes the grain assembly a simulation starts from,
//! as Su et al. (2020) do in Sect. 2.4: grains are measured (size, shape, orientation),
//! each is modelled as a pair of overlapping circles (their Fig. 1c-d), and the measured
//! distribution defines the grain templates (20 in their work).
//!
//! The chain, one module per step: [`threshold`] (Otsu) and [`mask`] (container) give the
//! solid pixels; [`binary`] cleans specks and pin-holes; [`edt`] gives the distance to the
//! liquid; [`watershed`] floods that distance map and splits touching grains; [`measure`]
//! takes moments; [`twocircle`] fits the circles; [`templates`] and [`stats`] summarise.
//! [`segment::digitise`] runs the chain. [`synth`] draws test images with a known answer.
//!
//! Pure computation on `ndarray` fields indexed `[row, col]` = `[y, x]` with row 0 at the top
//! (image convention, pixel units; pixel (r, c) covers x in [c, c+1), y in [r, r+1)). No file
//! I/O: the root crate's `digitise` stage reads images and writes files.

pub mod binary;
pub mod edt;
pub mod error;
pub mod mask;
pub mod measure;
pub mod segment;
pub mod smooth;
pub mod stats;
pub mod synth;
pub mod templates;
pub mod threshold;
pub mod twocircle;
pub mod watershed;

pub use error::GrainsError;
pub use mask::Container;
pub use measure::GrainMeasure;
pub use segment::{Digitised, Params, digitise};
pub use twocircle::{Fit, FitCircle};

pub type Result<T> = std::result::Result<T, GrainsError>;
