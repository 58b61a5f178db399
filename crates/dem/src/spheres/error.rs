//! Errors of the sphere engine: each names the parameter, its value, the limit and the fix.

use thiserror::Error;

#[derive(Debug, Error, PartialEq)]
pub enum SphereError {
    #[error("{name} = {value} is invalid: {why}")]
    BadParameter {
        name: &'static str,
        value: f64,
        why: &'static str,
    },
    #[error(
        "time step dt = {dt:e} s is above the contact law's limit {limit:e} s at sphere {sphere} \
         ({bound}); take dt at most {limit:e} s"
    )]
    TimeStepTooLarge {
        dt: f64,
        limit: f64,
        sphere: usize,
        bound: &'static str,
    },
    #[error("time step dt = {dt:e} s must be a positive, finite number of seconds")]
    BadTimeStep { dt: f64 },
    #[error(
        "periodic axis {axis}: the box length {length:e} m is below twice the pair cutoff {cutoff:e} m \
         (largest diameter + skin), so the minimum image is not unique; widen the box or shrink the skin"
    )]
    PeriodicBoxTooSmall { axis: usize, length: f64, cutoff: f64 },
    #[error(
        "the cell list would need {cells} cells (box / cutoff); the box is too large for the sphere size — \
         give a smaller box or larger spheres"
    )]
    TooManyCells { cells: usize },
    #[error(
        "sphere {sphere} is at {value:e} m on the open axis {axis}, outside the box [{lo:e}, {hi:e}) m: \
         the cell list would pile such spheres into the border cells; enlarge the box, confine the \
         spheres with walls, or make the axis periodic"
    )]
    OutsideBox {
        sphere: usize,
        axis: usize,
        value: f64,
        lo: f64,
        hi: f64,
    },
    #[error(
        "inconsistent sphere state (a corrupt checkpoint or a hand-edited system): {field} is {found}, \
         expected {expected}; regenerate the checkpoint or fix the field"
    )]
    Inconsistent {
        field: &'static str,
        found: String,
        expected: String,
    },
    #[error(
        "sphere index {sphere} is out of range: the system has {count} spheres; pass an index below {count}"
    )]
    NoSuchSphere { sphere: usize, count: usize },
    #[error(
        "sphere {sphere} belongs to clump {clump} and cannot be {action} by itself; act on free \
         spheres only"
    )]
    ClumpMember {
        sphere: usize,
        clump: usize,
        action: &'static str,
    },
    #[error("clump {clump}: non-finite position, velocity or spin given; pass finite values")]
    NonFiniteClump { clump: usize },
    #[error(
        "sphere {sphere}: non-finite state at step {step} (position, velocity or spin is NaN/inf); \
         a non-finite initial state or a blown-up run — check the initial state, then lower dt"
    )]
    NonFinite { sphere: usize, step: u64 },
}
