//! The light-view maps of an image, fitted to what the camera sees
//! (Scherzer et al. 2005, §4.1: focusing; no texels on parts of the scene
//! no pixel shows) and sized from the pixels' footprint.
//!
//! * Extent. The visible points (kernel light space) span tangents up to
//!   r = max |x/z|. An occluder between a point at depth zR and the light
//!   (size L) lies within tangent r + (L/2)(1/zO - 1/zR) of the axis
//!   (extent.rs), so `fit_extent` over the occluders in front of the light
//!   and the visible points bounds every texel that can shadow a pixel.
//!   The occluders are the meshes that can shadow a visible point
//!   (casters.rs), and the extent holds them and their reach only: a point
//!   beyond every occluder's reach finds no texel near it and is lit.
//!   Occluders nearer the light than `NEAREST_OCCLUDER` of the nearest
//!   visible point's depth would widen it without bound (a wall meeting a
//!   ceiling light): the reach is cut there, and such occluders are seen
//!   only inside the map.
//! * Resolution. A pixel at distance d along the optical axis covers
//!   d / focal world units; at the point, a texel covers its tangent width
//!   times the point's light depth (a rectangle) or times the orthographic
//!   scale (the sun). The map's texel is the median pixel footprint (over a
//!   regular subsample of at most 16384 pixels, mod.rs), so that
//!   about one texel falls on a pixel, but no finer than the map's area
//!   shared among TEXELS_PER_PIXEL texels per visible pixel (the map also
//!   covers what can shadow the visible points, which no pixel shows), the
//!   sides clamped to [MIN_SIDE, MAX_SIDE].

use crate::error::Result;
use crate::geom::extent::{fit_extent_within, ReceiverBounds};
use crate::geom::light::MAX_EXTENT;
use crate::geom::light_shape::LightShape;
use glam::DVec3;
use rayon::prelude::*;

/// The nearest occluder depth the extent makes room for, as a fraction of
/// the nearest visible point's depth.
pub const NEAREST_OCCLUDER: f64 = 1.0 / 16.0;
/// Sides of a fitted map.
pub const MIN_SIDE: usize = 64;
pub const MAX_SIDE: usize = 4096;

/// What the extent reads of the visible points (kernel light space, those
/// in front of the light): their bounds and their nearest depth.
#[derive(Debug, Clone, Copy)]
pub struct VisibleBounds {
    pub bounds: ReceiverBounds,
    pub z_min: f64,
}

impl VisibleBounds {
    /// The bounds of the points of `points` in front of the light, each
    /// divided by `unit`; `None` when none is.
    pub fn of(points: &[DVec3], unit: f64) -> Option<VisibleBounds> {
        let empty = || (ReceiverBounds::EMPTY, f64::INFINITY);
        let (bounds, z_min) = points
            .par_iter()
            .with_min_len(4096)
            .filter(|q| q.z > 0.0)
            .fold(empty, |(b, z), q| (b.with(*q / unit), z.min(q.z / unit)))
            .reduce(empty, |(a, za), (b, zb)| {
                (ReceiverBounds::union(a, b), za.min(zb))
            });
        z_min.is_finite().then_some(VisibleBounds { bounds, z_min })
    }
}

/// Tangent half-extents holding every occluder texel that can shadow the
/// visible points `points` (kernel light space).
pub fn focused_extent(
    occluders: &[DVec3],
    points: &VisibleBounds,
    light_shape: LightShape,
) -> Result<[f64; 2]> {
    let cut = points.z_min * NEAREST_OCCLUDER;
    let occ: Vec<DVec3> = occluders
        .iter()
        .filter(|q| q.z > 0.0)
        .map(|q| {
            if q.z < cut {
                DVec3::new(q.x / q.z * cut, q.y / q.z * cut, cut)
            } else {
                *q
            }
        })
        .collect();
    if occ.is_empty() {
        // Nothing casts a shadow (casters.rs): the points' own extent.
        return Ok(points
            .bounds
            .tangent
            .map(|t| (t * 1.01).clamp(1e-6, MAX_EXTENT)));
    }
    // Only the occluders and their reach: a visible point beyond every
    // occluder's reach finds no texel near it and is lit, so points need no
    // texels of their own (visible ground reaching toward the light's plane
    // once widened the maps to tangents of 40-56, docs/eye_view.md).
    let e = fit_extent_within(&occ, &points.bounds, light_shape)?;
    Ok(e.map(|t| (t * 1.01).min(MAX_EXTENT)))
}

/// At most TEXELS_PER_PIXEL texels per visible pixel: a footprint no
/// finer than the map's area shared out among them.
pub const TEXELS_PER_PIXEL: f64 = 2.0;

/// `footprint` coarsened so that the map holds at most TEXELS_PER_PIXEL
/// texels per visible pixel (`pixels` of them).
pub fn capped_footprint(extent: [f64; 2], footprint: f64, pixels: usize) -> f64 {
    let area = 4.0 * extent[0] * extent[1];
    footprint.max((area / (TEXELS_PER_PIXEL * pixels.max(1) as f64)).sqrt())
}

/// Map sides (W, H) for `extent` whose texel matches `footprint` (the
/// median tangent size of a pixel at its point).
pub fn footprint_resolution(extent: [f64; 2], footprint: f64) -> (usize, usize) {
    let side = |t: f64| {
        let n = (2.0 * t / footprint).ceil();
        if n.is_finite() {
            (n as usize).clamp(MIN_SIDE, MAX_SIDE)
        } else {
            MAX_SIDE
        }
    };
    let (w, h) = (side(extent[0]), side(extent[1]));
    // Keep texels square-ish when one side hits a clamp: scale the other.
    let aspect = extent[0] / extent[1];
    if w == MAX_SIDE || h == MAX_SIDE {
        if aspect >= 1.0 {
            (
                MAX_SIDE,
                ((MAX_SIDE as f64 / aspect).ceil() as usize).clamp(MIN_SIDE, MAX_SIDE),
            )
        } else {
            (
                ((MAX_SIDE as f64 * aspect).ceil() as usize).clamp(MIN_SIDE, MAX_SIDE),
                MAX_SIDE,
            )
        }
    } else {
        (w, h)
    }
}

/// The median of `values` (NaN-free), or None when empty.
pub fn median(mut values: Vec<f64>) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let mid = values.len() / 2;
    let (_, m, _) = values.select_nth_unstable_by(mid, |a, b| a.total_cmp(b));
    Some(*m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resolution_follows_the_footprint_and_its_clamps() {
        assert_eq!(footprint_resolution([0.5, 0.25], 1.0 / 512.0), (512, 256));
        assert_eq!(footprint_resolution([0.5, 0.5], 1.0), (MIN_SIDE, MIN_SIDE));
        assert_eq!(
            footprint_resolution([1.0, 0.5], 1e-9),
            (MAX_SIDE, MAX_SIDE / 2)
        );
        assert_eq!(median(vec![3.0, 1.0, 2.0]), Some(2.0));
    }

    #[test]
    fn extent_holds_the_points_and_cuts_occluders_at_the_light() {
        let pts = [DVec3::new(0.1, 0.0, 1.0), DVec3::new(-0.2, 0.1, 2.0)];
        // An occluder touching the light's plane would need an unbounded map.
        let occ = [DVec3::new(0.0, 0.0, 1e-12), DVec3::new(0.05, 0.05, 0.5)];
        let vis = VisibleBounds::of(&pts, 1.0).unwrap();
        let e = focused_extent(&occ, &vis, LightShape::rect([0.5, 0.5])).unwrap();
        assert!(e[0] >= 0.1 && e[1] >= 0.05, "{e:?}");
        assert!(e[0] < 0.25 * 16.0 + 0.2, "{e:?}");
    }
}
