//! Fitting the light-view map to where shadows can fall (`extent=None`).
//!
//! A light point at tangent offset X_L (|X_L| <= hx, the half-extent of the light's shape, geom/light_shape/)
//! and an occluder point at tangent x_O, depth Z_O cast a shadow on depth z_R
//! at tangent  x_O + X_L (1/z_R - 1/Z_O)  (seen from the light's center). So
//! every shadow point lies within  |x| <= |x_O| + hx (1/Z_O - 1/z_far)  where
//! z_far is the farthest receiver depth. Over a triangle |x| is convex and 1/Z
//! is linear in the map's plane, so the bound's maximum is at a vertex: the
//! extent is the largest bound over occluder vertices (and likewise in y). It
//! is then cut, when every receiver vertex lies in front of the light, to the
//! receivers' own tangent extent -- shadows land on receivers only -- or to
//! the occluders' own (their vertices' largest |x|) where that is wider: the
//! map methods see only occluders inside the map, and one just outside the
//! receivers can shadow them. Never wider than the receivers' extent plus
//! the largest penumbra reach hx (1/Z_O - 1/z_far): occluder points farther
//! out cannot shadow a receiver.

use crate::error::{Error, Result};
use crate::geom::light_shape::LightShape;
use glam::DVec3;
use rayon::prelude::*;

/// The smallest extent we return (a scene whose shadow shrinks to the axis).
const MIN_EXTENT: f64 = 1e-9;

/// What the extent reads of the receivers: over those in front of the
/// light, the farthest depth and the largest tangents, and whether all are
/// in front.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReceiverBounds {
    /// -inf when none is in front.
    pub z_far: f64,
    pub tangent: [f64; 2],
    pub all_in_front: bool,
}

impl ReceiverBounds {
    pub const EMPTY: ReceiverBounds = ReceiverBounds {
        z_far: f64::NEG_INFINITY,
        tangent: [0.0; 2],
        all_in_front: true,
    };

    /// The bounds of `receivers`, in one parallel pass.
    pub fn of(receivers: &[DVec3]) -> ReceiverBounds {
        receivers
            .par_iter()
            .with_min_len(4096)
            .fold(|| Self::EMPTY, |b, q| b.with(*q))
            .reduce(|| Self::EMPTY, Self::union)
    }

    /// These bounds with the receiver `q` added.
    #[inline]
    pub fn with(self, q: DVec3) -> ReceiverBounds {
        if q.z > 0.0 {
            ReceiverBounds {
                z_far: self.z_far.max(q.z),
                tangent: [
                    self.tangent[0].max((q.x / q.z).abs()),
                    self.tangent[1].max((q.y / q.z).abs()),
                ],
                all_in_front: self.all_in_front,
            }
        } else {
            ReceiverBounds {
                all_in_front: false,
                ..self
            }
        }
    }

    pub fn union(a: ReceiverBounds, b: ReceiverBounds) -> ReceiverBounds {
        ReceiverBounds {
            z_far: a.z_far.max(b.z_far),
            tangent: [
                a.tangent[0].max(b.tangent[0]),
                a.tangent[1].max(b.tangent[1]),
            ],
            all_in_front: a.all_in_front && b.all_in_front,
        }
    }
}

/// Tangent half-extents (tx, ty) that contain every umbra and penumbra the
/// occluders can cast on the receivers.
pub fn fit_extent(occluders: &[DVec3], receivers: &[DVec3], light: LightShape) -> Result<[f64; 2]> {
    fit_extent_within(occluders, &ReceiverBounds::of(receivers), light)
}

/// `fit_extent` for receivers known by their bounds.
pub fn fit_extent_within(
    occluders: &[DVec3],
    receivers: &ReceiverBounds,
    light: LightShape,
) -> Result<[f64; 2]> {
    if let Some(q) = occluders.iter().find(|q| !(q.z > 0.0)) {
        return Err(Error::invalid(
            "occluders",
            format!(
                "a vertex lies at or behind the light's plane (depth {}), so no finite map holds \
                 its shadow; pass extent=(tx, ty) explicitly",
                q.z
            ),
        ));
    }
    let z_far = receivers.z_far;
    if !z_far.is_finite() {
        return Err(Error::invalid(
            "receivers",
            "no receiver vertex lies in front of the light",
        ));
    }
    let inv_far = 1.0 / z_far;
    let mut ext = [0f64; 2];
    // The occluders' own tangent extent, and their largest penumbra reach.
    let mut own = [0f64; 2];
    let mut reach = [0f64; 2];
    // The light's half-extents h: a penumbra reaches h (1/z - 1/z_far).
    let h = light.half_extent();
    for q in occluders {
        let pen = (1.0 / q.z - inv_far).max(0.0);
        let r = [h[0] * pen, h[1] * pen];
        let t = [(q.x / q.z).abs(), (q.y / q.z).abs()];
        for a in 0..2 {
            ext[a] = ext[a].max(t[a] + r[a]);
            own[a] = own[a].max(t[a]);
            reach[a] = reach[a].max(r[a]);
        }
    }
    if receivers.all_in_front {
        for (a, r) in receivers.tangent.into_iter().enumerate() {
            ext[a] = ext[a].min(r.max(own[a]).min(r + reach[a]));
        }
    }
    Ok([ext[0].max(MIN_EXTENT), ext[1].max(MIN_EXTENT)])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plate_extent_matches_the_hand_computation() {
        // Plate of half-size 0.25 at depth 2, receivers at depth 4 reaching far.
        let occ = [DVec3::new(0.25, -0.25, 2.0), DVec3::new(-0.25, 0.25, 2.0)];
        let rec = [DVec3::new(-40.0, -40.0, 4.0), DVec3::new(40.0, 40.0, 4.0)];
        let e = fit_extent(&occ, &rec, LightShape::rect([1.0, 0.5])).unwrap();
        // |x| = 0.125; penumbra 0.5 * (1/2 - 1/4) = 0.125 -> 0.25; y: 0.125 + 0.0625.
        assert!((e[0] - 0.25).abs() < 1e-15 && (e[1] - 0.1875).abs() < 1e-15);
        // Small receivers cut it, but not below the occluders' own extent
        // (0.125: the map methods see only occluders inside the map, and
        // this one's penumbra reaches the receivers).
        let rec = [DVec3::new(-0.4, -0.4, 4.0), DVec3::new(0.4, 0.4, 4.0)];
        let e = fit_extent(&occ, &rec, LightShape::rect([1.0, 0.5])).unwrap();
        assert!((e[0] - 0.125).abs() < 1e-15, "{e:?}");
        // Smaller receivers still: no wider than them plus the reach (an
        // occluder point farther out cannot shadow them).
        let rec = [DVec3::new(-0.1, -0.1, 4.0), DVec3::new(0.1, 0.1, 4.0)];
        let e = fit_extent(&occ, &rec, LightShape::rect([0.2, 0.2])).unwrap();
        assert!((e[0] - (0.025 + 0.025)).abs() < 1e-15, "{e:?}");
    }

    #[test]
    fn occluders_behind_the_light_need_an_explicit_extent() {
        let occ = [DVec3::new(0.0, 0.0, -1.0)];
        let rec = [DVec3::new(0.0, 0.0, 4.0)];
        assert!(fit_extent(&occ, &rec, LightShape::rect([1.0, 1.0])).is_err());
        assert!(fit_extent(
            &[DVec3::new(0.0, 0.0, 1.0)],
            &[DVec3::new(0.0, 0.0, -4.0)],
            LightShape::rect([1.0, 1.0])
        )
        .is_err());
    }
}
