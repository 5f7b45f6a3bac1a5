//! Stage timings: every call reports seconds per stage, in the order the
//! stages ran, so that a user sees what accuracy costs and where. A leaf:
//! every layer times its own stages with the same stopwatch.

use std::time::Instant;

/// Named stage durations in seconds, in the order they ran.
pub type Timings = Vec<(&'static str, f64)>;

/// Laps of one call's stages.
pub struct Stopwatch {
    t: Instant,
    pub timings: Timings,
}

impl Default for Stopwatch {
    fn default() -> Self {
        Stopwatch::new()
    }
}

impl Stopwatch {
    pub fn new() -> Self {
        Stopwatch {
            t: Instant::now(),
            timings: Vec::new(),
        }
    }
    /// Records the time since the last lap as stage `name`.
    pub fn lap(&mut self, name: &'static str) {
        let now = Instant::now();
        self.timings.push((name, (now - self.t).as_secs_f64()));
        self.t = now;
    }
}
