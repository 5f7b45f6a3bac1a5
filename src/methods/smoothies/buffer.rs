//! Step 4 of Chan & Durand 2003 (§3, §3.1, §4 passes 2-3, Fig. 11): the
//! smoothie buffer, a depth b and an alpha per texel of the shadow map's grid.
//!
//! Each smoothie is rasterized at texel centres (a scan of its convex hull,
//! row by row, then the exact test of `construct.rs` per texel). At a texel
//! with linear alpha a, smoothie depth b and shadow-map depth r = front[k]:
//! * b >= r: the smoothie lies behind (or on) a blocker: discarded (the
//!   Cg's `f = b/r; f > 1 ? 1`: alpha 1 never wins a minimum).
//! * otherwise alpha' = clamp(a / (1 - b/r), 0, 1), with b/r = 0 where r = inf
//!   (no surface behind: the smoothie keeps its linear alpha, width t).
//! * Minimum blending (§3.1, EXT_blend_minmax): the smaller alpha' wins and
//!   its depth b is kept with it, so the lookup compares a receiver with the
//!   depth of the smoothie whose alpha it reads; on equal alpha' the nearer
//!   depth is kept. alpha' = 1 writes nothing (depth stays inf there).
//!   (The paper's pass 2 keeps the nearest smoothie depth independently of
//!   pass 3's alpha; keeping the winner's depth makes the pair consistent.)
//!
//! Work: a smoothie is at most t wide and its edge is clipped to the map's
//! widened frustum, and each row visits only the texels of the hull's span
//! within the grid: at most min(hull area, W H) texels per smoothie, and no
//! allocation per smoothie.

use super::construct::Shape;
use crate::geom::light::MapGrid;
use glam::DVec2;

/// Rasterizes `shapes` (q space, width t) into depth/alpha; returns the
/// number of smoothie texels written (rasterized and not discarded).
pub(super) fn rasterize(
    grid: &MapGrid,
    light: [f64; 2],
    front: &[f32],
    shapes: &[Shape],
    t: f64,
    depth: &mut [f32],
    alpha: &mut [f32],
) -> usize {
    let qx: Vec<f64> = (0..grid.width).map(|i| grid.x_of(i) / light[0]).collect();
    let qy: Vec<f64> = (0..grid.height).map(|j| grid.y_of(j) / light[1]).collect();
    let (w, h) = (grid.width as f64, grid.height as f64);
    let to_px = |q: DVec2| -> DVec2 {
        let (px, py) = grid.to_pixel(q.x * light[0], q.y * light[1]);
        DVec2::new(px, py)
    };
    let mut texels = 0usize;
    for shape in shapes {
        let (hull, nv) = shape.hull(t);
        let px: Vec<DVec2> = hull[..nv].iter().map(|&q| to_px(q)).collect();
        if px.iter().any(|p| !p.is_finite()) {
            continue;
        }
        let (ymin, ymax) = px
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
                (a.min(p.y), b.max(p.y))
            });
        // Rows whose centre j + 1/2 lies in [ymin, ymax] (a small slack: the
        // exact test decides).
        let j0 = (ymin - 0.5 - 1e-7).ceil().clamp(0.0, h) as usize;
        let j1 = ((ymax - 0.5 + 1e-7).floor() + 1.0).clamp(0.0, h) as usize;
        for (j, &y) in qy.iter().enumerate().take(j1).skip(j0) {
            let yc = j as f64 + 0.5;
            let (mut xl, mut xr) = (f64::INFINITY, f64::NEG_INFINITY);
            for k in 0..nv {
                let (a, b) = (px[k], px[(k + 1) % nv]);
                if (a.y - yc) * (b.y - yc) <= 0.0 {
                    if a.y == b.y {
                        xl = xl.min(a.x.min(b.x));
                        xr = xr.max(a.x.max(b.x));
                    } else {
                        let x = a.x + (yc - a.y) * (b.x - a.x) / (b.y - a.y);
                        xl = xl.min(x);
                        xr = xr.max(x);
                    }
                }
            }
            if xl > xr {
                // The slack took a row the hull misses: widen to its x range.
                xl = px.iter().map(|p| p.x).fold(f64::INFINITY, f64::min);
                xr = px.iter().map(|p| p.x).fold(f64::NEG_INFINITY, f64::max);
            }
            let i0 = (xl - 0.5 - 1e-7).ceil().clamp(0.0, w) as usize;
            let i1 = ((xr - 0.5 + 1e-7).floor() + 1.0).clamp(0.0, w) as usize;
            let row = j * grid.width;
            for (i, &x) in qx.iter().enumerate().take(i1).skip(i0) {
                let Some((a, b)) = shape.sample(DVec2::new(x, y), t) else {
                    continue;
                };
                let k = row + i;
                let r = front.get(k).map_or(f64::INFINITY, |&r| r as f64);
                if !(b > 0.0 && b < r) {
                    continue; // behind or on a blocker: discarded
                }
                texels += 1;
                let a = if r.is_finite() { a / (1.0 - b / r) } else { a };
                // alpha > 0 inside a smoothie (h > 0), kept > 0 in f32 so
                // that v = 0 only in the umbra.
                let a = (a.clamp(0.0, 1.0) as f32).max(f32::MIN_POSITIVE);
                let b = b as f32;
                if a < 1.0 && (a < alpha[k] || (a == alpha[k] && b < depth[k])) {
                    alpha[k] = a;
                    depth[k] = b;
                }
            }
        }
    }
    texels
}
