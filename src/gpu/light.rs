//! The light's shape as the map kernels read it: the one place that turns a
//! `LightShape` (geom/light_shape.rs) into their uniform fields (the ray
//! casters' are `ExactParams::set_light`, exact.rs: the strata na x nb and
//! the rectangle (size_x, size_y), which `light_shape.wgsl` maps to light
//! points). The map kernels (gather.wgsl and its methods) clip in
//! half-light units, reading (2/sx, 2/sy), (sx/2, sy/2) and the column
//! edges scaled by 2/sx. Each value is the f32 the CPU kernels hold (one
//! rounding from f64), so both backends start from the same bits.

use super::gather::GatherParams;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;

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
