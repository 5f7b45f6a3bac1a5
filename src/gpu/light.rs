//! The light's shape as the kernels read it: the one place that turns a
//! `LightShape` (geom/light_shape/) into their uniform fields. The ray
//! casters' are one uniform member, `GpuLightSamples` (the strata na x nb
//! and the rectangle (size_x, size_y), which `light_shape.wgsl`, its WGSL
//! twin, maps to light points), set by `ExactParams::set_light` (exact.rs).
//! The map kernels (gather.wgsl and its methods) clip in half-light units,
//! reading (2/sx, 2/sy), (sx/2, sy/2) and the column edges scaled by 2/sx.
//! Each value is the f32 the CPU kernels hold (one rounding from f64), so
//! both backends start from the same bits.

use super::gather::GatherParams;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::{LightSamples, LightShape};
use bytemuck::{Pod, Zeroable};

/// `LightSamples` of light_shape.wgsl: the ray casters' sample pattern
/// (`LightSamples`, geom/light_shape/), a member of their uniforms.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct GpuLightSamples {
    pub na: u32,
    pub nb: u32,
    pub size_x: f32,
    pub size_y: f32,
    /// 1 for a disk (`LightSamples::disk`).
    pub disk: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

impl GpuLightSamples {
    pub(super) fn new(s: LightSamples) -> GpuLightSamples {
        let ((na, nb), [size_x, size_y]) = (s.grid, s.size);
        GpuLightSamples {
            na,
            nb,
            size_x,
            size_y,
            disk: u32::from(s.disk),
            ..Default::default()
        }
    }
}

/// Sets the map kernels' half-light scales, and `wx`, the occluder
/// texel's width (2 hw, `hw` its half-width in tangent units) in them.
pub(super) fn set_half_light(p: &mut GatherParams, light: LightShape, hw: f64) {
    let h = light.half_light();
    [p.inv_half_lx, p.inv_half_ly] = h.inv_half;
    [p.half_lx, p.half_ly] = h.half;
    p.wx = 2.0 * hw as f32 * h.inv_half[0];
}

/// The occluder grid's column left edges in half-light units, as the CPU
/// kernel's `col_x0_scaled` (the f32 edge, scaled in f64: one rounding from
/// f64 differs from these two in the last bit now and then, which moved a
/// rank: a sample of one texel in 2000 on a 61-wide grid).
pub(super) fn column_edges(og: &MapGrid, light: LightShape) -> impl Iterator<Item = f32> + '_ {
    let (hw, _) = og.half_texel();
    (0..og.width).map(move |i| light.x_in_half_light((og.x_of(i) - hw) as f32))
}

#[cfg(test)]
mod tests {
    use super::super::shader_tests::{assert_same, rust_layout};
    use super::*;

    #[test]
    fn the_light_uniforms_have_the_same_layout_in_rust_and_wgsl() {
        assert_same(
            include_str!("light_shape.wgsl"),
            "LightSamples",
            rust_layout!(GpuLightSamples {
                na,
                nb,
                size_x,
                size_y,
                disk,
                _pad0,
                _pad1,
                _pad2
            }),
        );
    }
}
