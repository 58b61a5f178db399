//! Stop conditions: every grain slower than a threshold, a steady liquid, a wall moved far
//! enough (these end the run, whose final outputs are then written), and a wall-clock limit
//! (which interrupts it with a checkpoint for `--resume`).

use crate::scenes::timeloop::{Flow, LoopCtx, Model, Observer, Probe, Trigger};
use anyhow::Result;
use std::time::Instant;

/// Stop when every grain is slower than `v` (m/s).
pub struct SlowerThan {
    pub v: f64,
    pub trigger: Trigger,
}

impl Observer for SlowerThan {
    fn name(&self) -> &'static str {
        "until_slower_than"
    }
    fn trigger(&self) -> &Trigger {
        &self.trigger
    }
    fn observe(&mut self, m: &mut dyn Model, _cx: &LoopCtx) -> Result<Flow> {
        Ok(match m.probe(Probe::MaxGrainSpeed) {
            Some(s) if s < self.v => Flow::Stop(format!(
                "every grain slower than {:e} m/s at step {}",
                self.v,
                m.steps_done()
            )),
            _ => Flow::Continue,
        })
    }
}

/// Stop at the end of the first window of `over` seconds in which no grain moved more than
/// `speed` × the window (`until_slower_than = { speed, over }`; Su et al. 2020 Sect. 3.2: still
/// on the radiographs = under 2 µm in 10 s). Windows follow one another, each starting where the
/// last was judged, so the stop comes at most two windows after the grains stilled; the window's
/// start (its time and every centroid) is checkpointed, so a resumed run stops at the same step.
pub struct StillOver {
    pub speed: f64,
    pub over: f64,
    pub trigger: Trigger,
    pub start: Option<(f64, Vec<[f64; 2]>)>,
}

impl Observer for StillOver {
    fn name(&self) -> &'static str {
        "until_slower_than_over"
    }
    fn trigger(&self) -> &Trigger {
        &self.trigger
    }
    fn observe(&mut self, m: &mut dyn Model, _cx: &LoopCtx) -> Result<Flow> {
        let t = m.time();
        // A window ends after `over` s, less a step's rounding.
        let ended = match &self.start {
            None => true,
            Some((t0, then)) if t - t0 >= self.over - 0.5 * m.dt() => {
                let limit = self.speed * (t - t0);
                if let Some(moved) = m.max_grain_displacement(then).filter(|&d| d < limit) {
                    return Ok(Flow::Stop(format!(
                        "every grain moved less than {limit:.3e} m (at most {moved:.3e} m) in the {:.4} s to step {}: \
                         slower than {:e} m/s on average",
                        t - t0,
                        m.steps_done(),
                        self.speed
                    )));
                }
                true
            }
            Some(_) => false,
        };
        if ended {
            self.start = m.grain_centroids().map(|x| (t, x));
        }
        Ok(Flow::Continue)
    }
    fn save(&self) -> serde_json::Value {
        serde_json::json!(self.start)
    }
    fn restore(&mut self, v: serde_json::Value) -> Result<()> {
        self.start = serde_json::from_value(v)?;
        Ok(())
    }
}

/// Stop when the mean liquid speed changes by less than `tol` (relative) between two checks.
pub struct Steady {
    pub tol: f64,
    pub trigger: Trigger,
    pub last: Option<f64>,
}

impl Observer for Steady {
    fn name(&self) -> &'static str {
        "until_steady"
    }
    fn trigger(&self) -> &Trigger {
        &self.trigger
    }
    fn needs_fields(&self) -> bool {
        true
    }
    fn observe(&mut self, m: &mut dyn Model, _cx: &LoopCtx) -> Result<Flow> {
        let Some(mean) = m.probe(Probe::MeanLiquidSpeed) else {
            return Ok(Flow::Continue);
        };
        let steady = self
            .last
            .is_some_and(|prev| (mean - prev).abs() <= self.tol * mean.abs().max(f64::MIN_POSITIVE));
        self.last = Some(mean);
        Ok(if steady {
            Flow::Stop(format!(
                "steady: the mean liquid speed changed by less than {:e} at step {}",
                self.tol,
                m.steps_done()
            ))
        } else {
            Flow::Continue
        })
    }
    fn save(&self) -> serde_json::Value {
        serde_json::json!(self.last)
    }
    fn restore(&mut self, v: serde_json::Value) -> Result<()> {
        self.last = serde_json::from_value(v)?;
        Ok(())
    }
}

/// Stop when wall `wall` has moved `distance` (m) from where it started.
pub struct WallMoved {
    pub wall: usize,
    pub distance: f64,
    pub trigger: Trigger,
}

impl Observer for WallMoved {
    fn name(&self) -> &'static str {
        "until_wall_moved"
    }
    fn trigger(&self) -> &Trigger {
        &self.trigger
    }
    fn observe(&mut self, m: &mut dyn Model, _cx: &LoopCtx) -> Result<Flow> {
        Ok(match m.probe(Probe::WallDisplacement(self.wall)) {
            Some(d) if d >= self.distance => Flow::Stop(format!(
                "wall {} moved {d:e} m (>= {:e}) at step {}",
                self.wall,
                self.distance,
                m.steps_done()
            )),
            _ => Flow::Continue,
        })
    }
}

/// Interrupt the run (with a checkpoint) after `seconds` of wall-clock time in this process.
pub struct WallClock {
    pub seconds: f64,
    pub start: Instant,
    pub trigger: Trigger,
}

impl Observer for WallClock {
    fn name(&self) -> &'static str {
        "wall_clock"
    }
    fn trigger(&self) -> &Trigger {
        &self.trigger
    }
    fn observe(&mut self, m: &mut dyn Model, _cx: &LoopCtx) -> Result<Flow> {
        Ok(if self.start.elapsed().as_secs_f64() >= self.seconds {
            Flow::Interrupt(format!(
                "stopped by the wall-clock limit [run] wall_clock = {} s at step {}",
                self.seconds,
                m.steps_done()
            ))
        } else {
            Flow::Continue
        })
    }
}

/// Stop when an extruder's mass balance holds (`[extruder] stop_when_steady`): the insertion
/// and removal rates over the trailing window agree within the tolerance (Ness et al. 2017's
/// steady-state check; `lbdem_dem::spheres::extruder::balance`).
/// Stops an incline once its paste has stopped: `share` of it at τ_max (Leonardi et al. 2014:
/// "stopped when 95 % of the fluid has reached the maximum viscosity").
pub struct PasteStopped {
    pub share: f64,
    pub trigger: Trigger,
}

impl Observer for PasteStopped {
    fn name(&self) -> &'static str {
        "stop_share"
    }
    fn trigger(&self) -> &Trigger {
        &self.trigger
    }
    fn observe(&mut self, m: &mut dyn Model, _cx: &LoopCtx) -> Result<Flow> {
        Ok(match m.probe(Probe::RigidShare) {
            Some(r) if r >= self.share => Flow::Stop(format!(
                "the paste stopped: {:.1} % of it at the largest viscosity (step {})",
                100.0 * r,
                m.steps_done()
            )),
            _ => Flow::Continue,
        })
    }
}

pub struct MassBalanced {
    pub trigger: Trigger,
}

impl Observer for MassBalanced {
    fn name(&self) -> &'static str {
        "stop_when_steady"
    }
    fn trigger(&self) -> &Trigger {
        &self.trigger
    }
    fn observe(&mut self, m: &mut dyn Model, _cx: &LoopCtx) -> Result<Flow> {
        Ok(match m.probe(Probe::SteadySince) {
            Some(t) => Flow::Stop(format!(
                "steady: the mass balance has held since t = {t:e} s (step {})",
                m.steps_done()
            )),
            None => Flow::Continue,
        })
    }
}
