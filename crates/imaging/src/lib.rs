//! lbdem-imaging: radiograph kernels of Su et al. (2020) Sect. 2.2 — Beer-Lambert solid
//! fraction (Eqs. 1, 4), sample-thickness correction (Eqs. 2, 3), REV averaging and
//! volumetric strain (Eq. 5), profiles and the meniscus line scan (Eqs. 22, 23), detector
//! corrections, and the forward model that makes synthetic radiographs with a known answer.
//!
//! Pure computation on `ndarray` fields indexed `[row, col]` = `[y, x]`: no file I/O here
//! (TIFF reading and writing live in the root crate's `io::tiff`, the one TIFF reader).

pub mod beer_lambert;
pub mod correct;
pub mod edge;
pub mod error;
pub mod profile;
pub mod rev;
pub mod roi;
pub mod synth;

pub use error::ImagingError;
pub use roi::Roi;
pub type Result<T> = std::result::Result<T, ImagingError>;
