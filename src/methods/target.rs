//! What `ss.Auto` aims at, apart from the planner that reads it
//! (`plan.rs`): the config enum holds a target, and the planner depends on
//! the configs, not the other way round.

use super::shadow_mapping::config::{check_real, Real};
use crate::error::{Error, Result};

/// What `ss.Auto` aims at: an error (the paper's §4.2.1 metric), a time
/// budget in seconds, or neither (the fixed rule).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Target {
    pub error: Option<Real>,
    pub time: Option<Real>,
}

/// Smallest error target accepted: below it only many samples of `exact`
/// help, which the plan can still give but not promise.
pub const MIN_ERROR: f64 = 1e-4;

impl Target {
    pub fn new(error: Option<f64>, time: Option<f64>) -> Result<Target> {
        let error = error
            .map(|e| check_real("error", e, MIN_ERROR, 1.0, "an error"))
            .transpose()?;
        let time = time
            .map(|t| check_real("time", t, 1e-6, 1e6, "a time in seconds"))
            .transpose()?;
        if error.is_some() && time.is_some() {
            return Err(Error::invalid(
                "time",
                "give an error target or a time budget, not both",
            ));
        }
        Ok(Target { error, time })
    }

    pub fn is_none(&self) -> bool {
        self.error.is_none() && self.time.is_none()
    }
}
