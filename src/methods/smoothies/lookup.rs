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

use super::{Falloff, SmoothieBuffer};
use crate::geom::light::MapGrid;

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

/// The visibility at tangent (x, y), depth z: the 2x2 tent.
#[inline]
pub(super) fn at_point(
    grid: &MapGrid,
    front: &[f32],
    buf: &SmoothieBuffer,
    falloff: Falloff,
    x: f32,
    y: f32,
    z: f32,
) -> f32 {
    if !(shadable(z) && x.is_finite() && y.is_finite()) {
        return 1.0;
    }
    let (px, py) = grid.to_pixel(x as f64, y as f64);
    let (fx, fy) = (px - 0.5, py - 0.5);
    let (i0, j0) = (fx.floor(), fy.floor());
    let (wx, wy) = (fx - i0, fy - j0);
    let clamp = |c: f64, n: usize| c.clamp(0.0, (n - 1) as f64) as usize;
    let (ia, ib) = (clamp(i0, grid.width), clamp(i0 + 1.0, grid.width));
    let (ja, jb) = (clamp(j0, grid.height), clamp(j0 + 1.0, grid.height));
    let v = |i: usize, j: usize| tap(front, buf, j * grid.width + i, z) as f64;
    let top = v(ia, ja) * (1.0 - wx) + v(ib, ja) * wx;
    let bottom = v(ia, jb) * (1.0 - wx) + v(ib, jb) * wx;
    let s = top * (1.0 - wy) + bottom * wy;
    falloff.apply(s.clamp(0.0, 1.0) as f32)
}
