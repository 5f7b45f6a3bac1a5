//! The gradient of a depth over a map, along a surface's tangent plane.
//!
//! A map method tests a receiver point against occluder texels around it
//! (PCF's taps, PCSS's boxes). The receiver's own surface lies in those
//! texels at depths that differ from the point's by its slope to the light
//! times the distance: tested at the point's depth, a surface sloped to the
//! light shadows itself (acne). Testing each texel at the depth of the
//! point's tangent plane there (receiver plane depth bias: Isidoro 2006,
//! "Shadow Mapping: GPU-based Tips and Techniques", GDC) needs the plane's
//! depth gradient in texels, which this computes from any projection
//! `at(q) = (map x, map y, depth)` of world points: with two tangents t1,
//! t2 of the plane and J = [∂(x, y)/∂t1, ∂(x, y)/∂t2] (central differences
//! of `at`), the depth moves by ∂d/∂(t1, t2) J⁻¹ per texel. Where J is near
//! singular the plane is edge-on to the map and says nothing.

use glam::DVec3;

/// (∂d/∂x, ∂d/∂y) per map texel of the tangent plane at `p` (normal `n`),
/// by central differences of `at` over steps of `h` (world units) along two
/// tangents; None where the plane is edge-on to the map (|det J| under 1e-6
/// of its columns' squared length), a step projects nowhere, or the result
/// is not finite.
pub fn plane_gradient(
    at: impl Fn(DVec3) -> Option<DVec3>,
    p: DVec3,
    n: DVec3,
    h: f64,
) -> Option<[f64; 2]> {
    let n = n.try_normalize()?;
    let (t1, t2) = n.any_orthonormal_pair();
    let diff = |t: DVec3| Some((at(p + h * t)? - at(p - h * t)?) / (2.0 * h));
    let (a, b) = (diff(t1)?, diff(t2)?);
    // [a.x b.x; a.y b.y] (s, t) = (Δx, Δy): the tangent steps for a texel.
    let det = a.x * b.y - b.x * a.y;
    let scale = (a.x * a.x + a.y * a.y).max(b.x * b.x + b.y * b.y);
    if !(det.abs() > 1e-6 * scale) {
        return None;
    }
    let gx = (a.z * b.y - b.z * a.y) / det;
    let gy = (b.z * a.x - a.z * b.x) / det;
    (gx.is_finite() && gy.is_finite()).then_some([gx, gy])
}

/// A receiver's tangent plane on the occluder grid: (∂(1/z)/∂px,
/// ∂(1/z)/∂py) per texel.
pub type Plane = [f32; 2];

/// The largest |texel| of a split coordinate: f32 holds it exactly, so the
/// map's ends relative to it are exact; a point farther off is carried by
/// its fraction (its box then reaches the map only when far wider than it).
pub const MAX_BASE: f64 = (1 << 24) as f64;

/// A continuous pixel coordinate `p` (finite) split at its texel, in f64 so
/// that only the fraction rounds (the GPU twin reads it so).
pub fn split(p: f64) -> (i32, f32) {
    let base = p.floor().clamp(-MAX_BASE, MAX_BASE);
    (base as i32, (p - base) as f32)
}

/// The depth of the receiver's plane at texel (i, j) (its centre at
/// (i + 1/2, j + 1/2)) for a point split as `sx`, `sy` at depth z: z itself
/// for a plane of (0, 0), +inf past the plane's horizon; in the f32
/// operations pcss.wgsl's `plane_z` repeats.
#[inline]
pub fn plane_depth(z: f32, plane: Plane, sx: (i32, f32), sy: (i32, f32), i: i64, j: i64) -> f32 {
    if plane == [0.0, 0.0] {
        return z;
    }
    let ox = ((i - sx.0 as i64) as f32 + 0.5) - sx.1;
    let oy = ((j - sy.0 as i64) as f32 + 0.5) - sy.1;
    let den = 1.0 + z * (plane[0] * ox + plane[1] * oy);
    if den > 0.0 {
        z / den
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_under_an_affine_map_has_its_own_slope() {
        // Map x = 2 X, y = 3 Y, depth Z; the plane Z = 0.5 X - 0.25 Y + 1.
        let at = |q: DVec3| Some(DVec3::new(2.0 * q.x, 3.0 * q.y, q.z));
        let p = DVec3::new(0.3, -0.2, 1.0 + 0.15 + 0.05);
        let n = DVec3::new(-0.5, 0.25, 1.0);
        let [gx, gy] = plane_gradient(at, p, n, 0.01).unwrap();
        assert!(
            (gx - 0.25).abs() < 1e-12 && (gy + 0.25 / 3.0).abs() < 1e-12,
            "{gx} {gy}"
        );
        // Edge-on: the plane contains the depth axis.
        assert!(plane_gradient(at, p, DVec3::X, 0.01).is_none());
        assert!(plane_gradient(at, p, DVec3::ZERO, 0.01).is_none());
    }
}
