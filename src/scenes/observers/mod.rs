//! The observers of the time loop (`super::timeloop`): writers, stop conditions and the
//! progress display. Adding one is a new file here implementing
//! [`super::timeloop::Observer`] and one line in [`crate::scenes::run::observers`].

mod progress;
mod series;
mod snapshots;
mod stop;

pub use progress::Progress;
pub use series::{FILE as SERIES_FILE, Series};
pub use snapshots::Snapshots;
pub use stop::{MassBalanced, PasteStopped, SlowerThan, Steady, StillOver, WallClock, WallMoved};
