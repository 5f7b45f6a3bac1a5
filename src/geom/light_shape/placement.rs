//! Where a light's shape lies in the world (a leaf of the light module:
//! each shape's facts read it).

use glam::DVec3;

/// Where a light's shape lies in the world: its centre and light.rs's
/// frame (u, v along its plane, n from the light into the scene).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Placement {
    pub center: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    pub n: DVec3,
}
