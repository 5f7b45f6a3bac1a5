//! `ss.Auto(error=..., time=...)`: the planner. `plan.rs` holds the pure
//! decisions (scene facts and a target in, a config and the reasons out),
//! `measure.rs` what they read of a framed scene (depth ranges, thin
//! features, the layers tried on coarse maps), `driver.rs` the order in
//! which a planned light-view call frames, measures, plans and runs,
//! `refine.rs` the runs after it while its error estimate misses the
//! target, `dim_lights.rs` the lights of a call too dim to shadow.
//! Above the orchestrators (it runs them), below the API.

pub mod dim_lights;
pub mod driver;
pub mod measure;
pub mod plan;
pub mod refine;

pub use plan::{plan, plan_eye, Decision, Plan, SceneStats};
