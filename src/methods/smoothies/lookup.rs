//! Step 5 of Chan & Durand 2003 (§3 step 5, §3.1, Fig. 11 pass 4): the
//! visibility of a receiver from the shadow map and the smoothie buffer.
//!
//! At a texel k, for a receiver at planar depth z:
//!     v_k = 0          if z > front[k]          (behind a blocker: umbra)
//!         = alpha[k]   else if z > depth[k]     (behind a smoothie: penumbra)
//!         = 1          otherwise                (lit)
//! then the four nearest texels' v_k are interpolated bilinearly (the 2x2
//! tent of percentage-closer filtering, as the text of §3 says; the Cg
//! listing instead filters each comparison first and lets any umbra tap win),
//! with the map's edge texels repeated beyond its border. At a texel centre
//! the tent is that texel alone, so `visibility_map` reads it directly.
//! Last the falloff (see `Falloff`). Only an outer penumbra: the umbra is the
//! hard shadow's. Non-finite or non-positive z: nothing to shade, v = 1.
//!
//! Receiver planes (the eye view): there every surface is in the shadow
//! map, and a surface sloped to the light lies a texel away at another
//! depth than the point's: tested at the point's own z, one tap of four
//! falls behind the surface itself (acne: 8% of the lit pixels of
//! stairs_low_sun at 320x240, V about 0.89, far from any shadow). Each tap
//! is tested at the depth of the point's tangent plane at its texel
//! instead (`tent_depths`, as PCSS's boxes: `geom/plane_gradient.rs`), but
//! never deeper than the point: on the side where the plane recedes from
//! the light it reaches its horizon within a texel near a silhouette, and
//! every occluder there would darken the tap (measured on the calibration
//! scenes at 320x240: acne on spheres_sun_high 2.48% with the plane's full
//! depth, 1.76% with this bound, as without planes; stairs_low_sun 8.1% ->
//! 0.30%). A plane of (0, 0) is the point's own depth (the light view).

use super::{Falloff, SmoothieBuffer};
use crate::geom::light::MapGrid;
use crate::geom::plane_gradient::{plane_depth, split, Plane, MAX_BASE};

#[inline]
fn tap(front: &[f32], buf: &SmoothieBuffer, k: usize, z: f32) -> f32 {
    if z > front[k] {
        0.0
    } else if z > buf.depth[k] {
        buf.alpha[k]
    } else {
        1.0
    }
}

fn shadable(z: f32) -> bool {
    z.is_finite() && z > 0.0
}

/// The visibility at the texel centre k.
#[inline]
pub(super) fn at_texel(
    front: &[f32],
    buf: &SmoothieBuffer,
    falloff: Falloff,
    k: usize,
    z: f32,
) -> f32 {
    if !shadable(z) {
        return 1.0;
    }
    falloff.apply(tap(front, buf, k, z))
}

/// The receiver's depth at the tent's four texels, (a, a), (b, a), (a, b),
/// (b, b) (a = floor(p - 1/2), b = a + 1 along each axis, before the
/// border's clamp), for a point at map pixel (px, py), depth z, tangent
/// plane `plane`, at most z (module docs): z for a plane of (0, 0) or a
/// point off the map by more than `MAX_BASE` texels. The GPU twin reads these depths (`TentPoint`).
#[inline]
pub(crate) fn tent_depths(px: f64, py: f64, z: f32, plane: Plane) -> [f32; 4] {
    if plane == [0.0, 0.0] || !(px.abs() < MAX_BASE && py.abs() < MAX_BASE) {
        return [z; 4];
    }
    let (sx, sy) = (split(px), split(py));
    let (a, b) = ((px - 0.5).floor() as i64, (py - 0.5).floor() as i64);
    let d = |i: i64, j: i64| plane_depth(z, plane, sx, sy, i, j).min(z);
    [d(a, b), d(a + 1, b), d(a, b + 1), d(a + 1, b + 1)]
}

/// The visibility at tangent (x, y), depth z, tangent plane `plane`: the
/// 2x2 tent.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(super) fn at_point(
    grid: &MapGrid,
    front: &[f32],
    buf: &SmoothieBuffer,
    falloff: Falloff,
    x: f32,
    y: f32,
    z: f32,
    plane: Plane,
) -> f32 {
    if !(shadable(z) && x.is_finite() && y.is_finite()) {
        return 1.0;
    }
    let (px, py) = grid.to_pixel(x as f64, y as f64);
    let zs = tent_depths(px, py, z, plane);
    let (fx, fy) = (px - 0.5, py - 0.5);
    let (i0, j0) = (fx.floor(), fy.floor());
    let (wx, wy) = (fx - i0, fy - j0);
    let clamp = |c: f64, n: usize| c.clamp(0.0, (n - 1) as f64) as usize;
    let (ia, ib) = (clamp(i0, grid.width), clamp(i0 + 1.0, grid.width));
    let (ja, jb) = (clamp(j0, grid.height), clamp(j0 + 1.0, grid.height));
    let v = |i: usize, j: usize, z: f32| tap(front, buf, j * grid.width + i, z) as f64;
    let top = v(ia, ja, zs[0]) * (1.0 - wx) + v(ib, ja, zs[1]) * wx;
    let bottom = v(ia, jb, zs[2]) * (1.0 - wx) + v(ib, jb, zs[3]) * wx;
    let s = top * (1.0 - wy) + bottom * wy;
    falloff.apply(s.clamp(0.0, 1.0) as f32)
}
