//! The depth of a triangle at a texel center, in the one f32 form that both
//! the CPU rasterizer (`raster/`) and the GPU one (`gpu/raster.wgsl`)
//! evaluate, so that their depth maps agree bit for bit.
//!
//! 1/Z is linear in the map's plane. Per triangle we keep 1/Z at the center
//! of its first covered texel (i0, j0) and its gradient per texel along i and
//! j, each split into three f32 limbs of at most 8 significant bits. At texel
//! (i0 + di, j0 + dj) with integer di, dj < 2^16 every product `limb * di` then
//! has at most 24 significant bits and is exact in f32, so a GPU compiler
//! that fuses `a * b + c` into an fma (which SPIR-V allows unless told
//! otherwise) gets the same bits as separate multiply and add. What is left
//! are additions in a fixed order (correctly rounded on both sides) and the
//! final 1/w.

/// Significant bits of each gradient limb: limb x offset must fit in 24 bits
/// with offsets below 2^16 (the GPU backend's largest map side).
const LIMB_BITS: i32 = 8;

/// 1/Z over a triangle: the value at the reference texel center and the
/// gradient per texel as three limbs each (summed, they are the gradient to
/// 24 bits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepthPlane {
    pub w_ref: f32,
    pub gx: [f32; 3],
    pub gy: [f32; 3],
}

/// `v` rounded to LIMB_BITS significant bits, halves away from zero (0
/// below f32's normal range, where a GPU may flush it).
fn round_to_limb(v: f64) -> f64 {
    if v == 0.0 || !v.is_finite() || v.abs() < f32::MIN_POSITIVE as f64 {
        return 0.0;
    }
    // On the bit pattern: keep the top LIMB_BITS - 1 stored mantissa bits
    // (LIMB_BITS significant with the implicit one) after adding half of the
    // last kept bit to the magnitude, so a carry rounds up into the exponent.
    // That is `round(v * 2^(7-e)) / 2^(7-e)` with e = floor(log2 |v|), bit
    // for bit (a test compares them), without the float round trip whose
    // dependent chain was a seventh of the camera's rasterization at
    // 1920x1080 on 2 000 000 triangles.
    const DROPPED: u32 = 52 - (LIMB_BITS as u32 - 1);
    let b = v.to_bits() + (1u64 << (DROPPED - 1));
    f64::from_bits(b & !((1u64 << DROPPED) - 1))
}

/// Three limbs whose sum is `v` to about 24 bits.
fn limbs(v: f64) -> [f32; 3] {
    let mut rest = v;
    let mut out = [0f32; 3];
    for o in &mut out {
        let l = round_to_limb(rest);
        *o = l as f32;
        rest -= l;
    }
    out
}

impl DepthPlane {
    /// The plane from 1/Z at the reference texel center and its gradient per
    /// texel, both in f64.
    pub fn new(w_ref: f64, grad_i: f64, grad_j: f64) -> DepthPlane {
        DepthPlane {
            w_ref: w_ref as f32,
            gx: limbs(grad_i),
            gy: limbs(grad_j),
        }
    }

    /// Planar depth Z at texel (i0 + di, j0 + dj); `None` where rounding left
    /// 1/Z not positive (a sliver seen edge-on at the near plane).
    #[inline(always)]
    pub fn depth(&self, di: u32, dj: u32) -> Option<f32> {
        let (di, dj) = (di as f32, dj as f32);
        // The order of these additions is the WGSL twin's (`depth_at`).
        let mut w = self.w_ref;
        for k in 0..3 {
            w += self.gx[k] * di;
            w += self.gy[k] * dj;
        }
        (w > 0.0).then(|| 1.0 / w)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limbs_are_short_and_sum_to_the_value() {
        for v in [0.3f64, -1.2345678e-3, 7.0e5, 1.0 / 3.0, 0.0] {
            let l = limbs(v);
            for x in l {
                // At most LIMB_BITS significant bits.
                let m = x.abs().to_bits() & 0x7f_ffff;
                assert_eq!(m & ((1 << (24 - LIMB_BITS)) - 1), 0, "{v}: limb {x}");
            }
            let sum: f64 = l.iter().map(|&x| x as f64).sum();
            assert!((sum - v).abs() <= v.abs() * 2f64.powi(-22), "{v}: {sum}");
        }
    }

    /// 2^n for n in f64's normal range.
    fn pow2(n: i32) -> f64 {
        f64::from_bits(((n + 1023) as u64) << 52)
    }

    /// The limb rounding gives the bits of the plain formula it replaced,
    /// `(v * s).round() / s`, over f32's normal range and both signs.
    #[test]
    fn limb_rounding_is_the_divided_form() {
        let mut x = f32::MIN_POSITIVE as f64;
        while x < 1.0e38 {
            for v in [x, -x, x * 1.0000001, x * 1.7531, -x * 1.5] {
                let e = ((v.to_bits() >> 52) & 0x7ff) as i32 - 1023;
                let s = pow2(LIMB_BITS - 1 - e);
                assert_eq!(
                    round_to_limb(v).to_bits(),
                    ((v * s).round() / s).to_bits(),
                    "{v}"
                );
                // Halves exactly: v with the ninth significant bit alone set
                // below the kept ones rounds away from zero.
                let half = f64::from_bits((v.to_bits() & !((1u64 << 45) - 1)) | (1u64 << 44));
                assert_eq!(
                    round_to_limb(half).to_bits(),
                    ((half * s).round() / s).to_bits(),
                    "{half}"
                );
            }
            x *= 1.0173;
        }
    }

    #[test]
    fn limb_products_with_texel_offsets_are_exact() {
        let l = limbs(0.123456789);
        for d in [1u32, 255, 4097, 65535] {
            for x in l {
                let p = x * d as f32;
                assert_eq!(p as f64, x as f64 * d as f64);
            }
        }
    }
}
