//! A Lambertian receiver's weights over a planar light on the device
//! (`irradiance_weight.wgsl`, which gather.rs and pcss.rs prepend with
//! `concat!` to the modules whose weighted resolves read it), and the
//! per-point struct they read. The CPU twins are `SurfacePoint::weight` and
//! `shadow_rays::light_weight` (trace/shadow_rays.rs).

use crate::eye::rays::RayStart;
use crate::trace::shadow_rays::SurfacePoint;
use bytemuck::{Pod, Zeroable};

/// `WeighPoint` of irradiance_weight.wgsl: a point's surface point (kernel
/// space) and tangent plane, for a weighted resolve (`RayStart`: the
/// midpoint of its starts, its `side`); valid 0 where it has none.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct GpuWeighPoint {
    pub p: [f32; 3],
    pub valid: u32,
    pub side: [f32; 3],
    pub _pad: u32,
}

impl GpuWeighPoint {
    pub fn new(r: Option<&RayStart>) -> GpuWeighPoint {
        GpuWeighPoint::from_surface(r.map(RayStart::surface_point))
    }

    /// A surface point's (none: not valid).
    pub fn from_surface(s: Option<SurfacePoint>) -> GpuWeighPoint {
        s.map_or_else(GpuWeighPoint::default, |s| GpuWeighPoint {
            p: s.p.to_array(),
            valid: 1,
            side: s.side,
            _pad: 0,
        })
    }
}
