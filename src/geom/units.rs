//! The depth unit the kernels compute in.
//!
//! Visibility does not change when every depth and the light's size are
//! scaled by one factor (tangents do not move). The kernels compute in f32
//! with fixed tolerances (the SSM adds 1e-36 to (1/zO - 1/zR)^2; the ray
//! caster's determinants are cubes of lengths), so a scene whose depths lie
//! far from 1 (receivers at 1e15 or at 1e-20) would lose its shadows to
//! underflow or overflow there. The pipeline therefore hands the kernels
//! depths and light sizes divided by a power of two near the receivers'
//! depth: exact in floating point, so an ordinary scene gives the same bits,
//! and one at any scale the same visibility. Depth maps returned to the user
//! stay in the user's units.

use crate::error::{Error, Result};

/// Receivers whose farthest depth lies in [1/2^16, 2^16] are left in the
/// user's units (no copies): the kernels' tolerances are far below that range.
const KEEP: f64 = 65536.0;

/// Light sizes the kernels' f32 arithmetic resolves, relative to the
/// receivers' depth: beyond them 2/L or L/2 leave the f32 range.
pub const MIN_RELATIVE_SIZE: f64 = 1e-30;
pub const MAX_RELATIVE_SIZE: f64 = 1e30;

/// The unit (a power of two) for receivers whose farthest finite, positive
/// depth is `far`; 1 when there is none or it needs no change.
pub fn depth_unit(far: f64) -> f64 {
    if !(far.is_finite() && far > 0.0) || (1.0 / KEEP..=KEEP).contains(&far) {
        return 1.0;
    }
    // 2^floor(log2 far), from the exponent bits (exact; far is normal here).
    let e = ((far.to_bits() >> 52) & 0x7ff) as i32 - 1023;
    2f64.powi(e)
}

/// The farthest finite, positive depth of an f32 map (0 when none).
pub fn farthest(depth: &[f32]) -> f64 {
    depth
        .iter()
        .filter(|z| z.is_finite() && **z > 0.0)
        .fold(0f64, |m, &z| m.max(z as f64))
}

/// Refuses a unit whose depths the f32 maps cannot hold (a scene 1e300 away
/// from the light, or 1e-300 from it): its depth maps would overflow, or
/// underflow to 0.
pub fn check_unit(arg: &str, unit: f64) -> Result<()> {
    if (2f64.powi(-149)..=2f64.powi(127)).contains(&unit) {
        Ok(())
    } else {
        Err(Error::invalid(
            arg,
            format!(
                "lie about {unit:e} from the light: beyond the float32 range of the depth maps \
                 (scale the scene and the light)"
            ),
        ))
    }
}

/// The farthest a vertex may lie from the light's axis, in the kernels' unit
/// (about the receivers' depth). Beyond, a triangle's vertices are so large
/// that clipping it to the map in f64 loses its interior (measured: a
/// triangle 1e19 wide over the map vanished) and the ray caster's f32
/// determinants overflow; 1e15 keeps a margin of 1e3.
pub const MAX_LATERAL: f64 = 1e15;

/// Refuses vertices (light space, in the kernels' unit) beyond MAX_LATERAL
/// from the light's axis, naming the mesh set and the vertex.
pub fn check_lateral(arg: &str, verts: &[glam::DVec3], unit: f64) -> Result<()> {
    match verts
        .iter()
        .position(|q| q.x.abs().max(q.y.abs()) > MAX_LATERAL)
    {
        None => Ok(()),
        Some(k) => Err(Error::invalid(
            arg,
            format!(
                "vertex {k} lies {:e} from the light's axis, beyond {MAX_LATERAL:e} times the \
                 depth unit {unit:e} (a power of two near the receivers' depth): so large a \
                 triangle loses its shape in the rasterizer and the ray caster; split it or drop \
                 what lies that far",
                verts[k].x.abs().max(verts[k].y.abs()) * unit
            ),
        )),
    }
}

/// A depth map in unit `unit`, borrowed when the unit is 1.
pub fn scaled_map(depth: &[f32], unit: f64) -> std::borrow::Cow<'_, [f32]> {
    if unit == 1.0 {
        std::borrow::Cow::Borrowed(depth)
    } else {
        // A power of two, divided in f64: exact unless the result leaves the
        // f32 range, where it becomes 0 (at the light: occludes nothing) or
        // inf (far beyond the receivers: empty).
        std::borrow::Cow::Owned(depth.iter().map(|&z| (z as f64 / unit) as f32).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_are_powers_of_two_and_ordinary_scenes_keep_theirs() {
        assert_eq!(depth_unit(4.0), 1.0);
        assert_eq!(depth_unit(f64::INFINITY), 1.0);
        assert_eq!(depth_unit(0.0), 1.0);
        assert_eq!(depth_unit(3.0e15), 2f64.powi(51));
        assert_eq!(depth_unit(1.5e-20), 2f64.powi(-66));
        let u = depth_unit(1e9);
        assert!((1.0..2.0).contains(&(1e9 / u)));
    }

    #[test]
    fn scaling_is_exact() {
        let m = [3.0f32, f32::INFINITY, 1e-3];
        let s = scaled_map(&m, 1024.0);
        assert_eq!(&s[..], &[3.0 / 1024.0, f32::INFINITY, 1e-3 / 1024.0]);
        // The deepest f32 depth and the shallowest normal one keep their unit.
        assert!(check_unit("points", depth_unit(f32::MAX as f64)).is_ok());
        assert!(check_unit("points", depth_unit(1e-45f32 as f64)).is_ok());
        assert!(check_unit("receivers", depth_unit(1e300)).is_err());
        // A subnormal receiver depth scales to 1 without overflowing.
        let tiny = [1e-45f32];
        assert_eq!(scaled_map(&tiny, depth_unit(tiny[0] as f64))[0], 1.0);
    }
}
