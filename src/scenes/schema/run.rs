//! `[run]` (how long, when to stop) and `[output]` (what to write, when): the time loop's
//! stop conditions and the triggers of its observers (`crate::scenes::timeloop`).

use serde::{Deserialize, Serialize};

/// `[run]`. A step is the scene's outer step: one DEM step (grains only), one LBM step
/// (liquid only), or one LBM step with its DEM sub-steps (coupled).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RunSection {
    /// Number of steps; give this or `time`.
    #[serde(default)]
    pub steps: Option<u64>,
    /// Simulated time (s).
    #[serde(default)]
    pub time: Option<f64>,
    /// Stop when every grain is slower than a speed (m/s): instantaneously, checked at every
    /// series sample, or as a displacement over a time window (`{ speed, over }`).
    #[serde(default)]
    pub until_slower_than: Option<SlowerThan>,
    /// Stop when the mean liquid speed changes by less than this fraction between series samples.
    #[serde(default)]
    pub until_steady: Option<f64>,
    /// Stop when a wall has moved this far from where it started.
    #[serde(default)]
    pub until_wall_moved: Option<WallMoved>,
    /// Wall-clock limit (s): the run stops with a checkpoint, to be continued with `--resume`.
    #[serde(default)]
    pub wall_clock: Option<f64>,
    /// rayon threads (0 = all cores). Results do not depend on it.
    #[serde(default)]
    pub threads: usize,
}

/// `until_slower_than = 1e-7` stops at the first series sample at which every grain's speed is
/// below 1e-7 m/s. `until_slower_than = { speed = 1e-7, over = 10.0 }` stops at the end of the
/// first window of `over` seconds (windows follow one another from the start, checked at the
/// series samples) in which no grain moved more than `speed` × the window: Su et al. 2020 read
/// still grains off the radiographs this way (Sect. 3.2, under 2 µm in 10 s), and a packed layer
/// of elastic grains, whose rattlers vibrate in place faster than 1e-7 m/s for ever, ends only
/// under this form.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(
    untagged,
    expecting = "a speed in m/s (until_slower_than = 1e-7) or a speed over a window \
                 (until_slower_than = { speed = 1e-7, over = 10.0 }, m/s and s)"
)]
pub enum SlowerThan {
    Speed(f64),
    Window(SlowerOver),
}

/// The windowed form of [`SlowerThan`].
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct SlowerOver {
    /// Mean speed over the window (m/s).
    pub speed: f64,
    /// Window (s).
    pub over: f64,
}

/// `until_wall_moved = { wall = "plate", distance = 1e-3 }`: the wall by its `name` in
/// `[[walls]]`, or by its index among the DEM walls (a box counts as four: left, right, bottom,
/// top).
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct WallMoved {
    pub wall: WallRef,
    pub distance: f64,
}

/// A wall by index or by name.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(untagged)]
pub enum WallRef {
    Index(usize),
    Name(String),
}

/// A condition trigger: acts at the first step after `quantity` has crossed each of the values
/// in `crosses` (ascending), e.g. snapshots at given push-plate displacements:
/// `{ when = { quantity = "wall_displacement", wall = "plate", crosses = [1e-3, 2e-3] } }`.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct When {
    /// "wall_displacement" (m, needs `wall`), "max_grain_speed" (m/s) or "mean_liquid_speed" (m/s).
    pub quantity: String,
    #[serde(default)]
    pub wall: Option<WallRef>,
    pub crosses: Vec<f64>,
}

/// `[output]`: when the series, snapshots and checkpoints are written.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSection {
    /// One row of the time series (`series.csv`); the last step always gets one.
    #[serde(default = "series")]
    pub series: TriggerSpec,
    /// Particle and fluid snapshots (tables that can be read back, and VTK); the last step
    /// always gets one.
    #[serde(default = "snapshots")]
    pub snapshots: TriggerSpec,
    /// Checkpoints for `--resume`.
    #[serde(default = "checkpoints")]
    pub checkpoints: TriggerSpec,
    /// Pressure-change threshold (Pa) of the "area below" statistic of coupled scenes (Su
    /// Sect. 2.5, Eq. 19).
    #[serde(default = "threshold")]
    pub pressure_threshold: f64,
}

impl Default for OutputSection {
    fn default() -> Self {
        Self {
            series: series(),
            snapshots: snapshots(),
            checkpoints: checkpoints(),
            pressure_threshold: threshold(),
        }
    }
}

fn series() -> TriggerSpec {
    TriggerSpec {
        count: Some(200),
        ..Default::default()
    }
}
fn snapshots() -> TriggerSpec {
    TriggerSpec {
        count: Some(4),
        ..Default::default()
    }
}
fn checkpoints() -> TriggerSpec {
    TriggerSpec {
        wall_seconds: Some(600.0),
        ..Default::default()
    }
}
fn threshold() -> f64 {
    -1000.0
}

/// When an observer acts; exactly one key: `{ every = 100 }` steps, `{ count = 20 }` times
/// spread evenly over the run, `{ at = [0.1, 0.2] }` simulated seconds, `{ when = {...} }` a
/// condition ([`When`]), `{ wall_seconds = 600 }` of wall-clock time (checkpoints only), or
/// `{ never = true }`.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TriggerSpec {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub every: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub at: Option<Vec<f64>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub when: Option<When>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wall_seconds: Option<f64>,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub never: bool,
}
