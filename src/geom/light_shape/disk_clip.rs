//! The overlap of an axis-aligned rectangle with a disk, in f32: the SSM's
//! clipping of a micro-patch's back-projection to a disk light (Atty et al.
//! 2005 §3.4 clip it to the light's rectangle; `methods/ssm` and its device
//! twin `disk_overlap` in gpu/ssm.wgsl clip it to the disk).
//!
//! The maths is `disk::rect_overlap`'s, which stays the f64 reference the
//! tests hold this to: the disk's area with X <= a and Y <= b (`corner`),
//! by inclusion–exclusion, after a rectangle wholly inside or wholly
//! outside the disk (most micro-patches) is answered directly. In f32 the
//! corners are values of order r², so a patch across the rim carries an
//! absolute error of a few ulp of r² (a few 1e-8 of the disk's area); the
//! patches inside, which are most of a receiver's, are exact products.

use std::f32::consts::PI;

/// asin x for x in [-1, 1] by Abramowitz and Stegun's 4.4.46 (|error| <=
/// 2e-8 in exact arithmetic): π/2 − √(1 − |x|) (a0 + a1 |x| + … + a7 |x|⁷),
/// odd in x, with a0 = π/2 (the table's 1.5707963050 is 2e-8 from it) so
/// that asin 0 = 0. Not the library's asin: the device's (gpu/ssm.wgsl's
/// `asin_poly` is this, term for term) may be far looser (lavapipe's put
/// the GPU's light-view SSM 3e-4 off the CPU's under a disk), and with the
/// same additions, products and square root both backends agree to f32
/// rounding.
#[inline(always)]
pub fn asin_poly(x: f32) -> f32 {
    const A: [f32; 8] = [
        std::f32::consts::FRAC_PI_2,
        -0.214_598_8,
        0.088_978_99,
        -0.050_174_303,
        0.030_891_88,
        -0.017_088_126,
        0.006_670_09,
        -0.001_262_491_1,
    ];
    let t = x.abs().min(1.0);
    let mut p = A[7];
    for &a in A[..7].iter().rev() {
        p = p * t + a;
    }
    let y = 0.5 * PI - (1.0 - t).sqrt() * p;
    if x < 0.0 {
        -y
    } else {
        y
    }
}

/// ∫_{−r}^{a} √(r² − X²) dX for a in [−r, r].
#[inline(always)]
fn left_half_area(r: f32, a: f32) -> f32 {
    let a = a.clamp(-r, r);
    let s = (a / r).clamp(-1.0, 1.0);
    0.5 * (a * (r * r - a * a).max(0.0).sqrt() + r * r * asin_poly(s)) + 0.25 * PI * r * r
}

/// The area of the disk of radius `r` with X <= a and Y <= b.
#[inline(always)]
fn corner(r: f32, a: f32, b: f32) -> f32 {
    let a = a.clamp(-r, r);
    if b >= 0.0 {
        2.0 * left_half_area(r, a) - corner_below(r, a, -b)
    } else {
        corner_below(r, a, b)
    }
}

/// `corner` for b <= 0.
#[inline(always)]
fn corner_below(r: f32, a: f32, b: f32) -> f32 {
    let b = b.max(-r);
    let xb = (r * r - b * b).max(0.0).sqrt();
    let a = a.clamp(-xb, xb);
    (left_half_area(r, a) - left_half_area(r, -xb) + b * (a + xb)).max(0.0)
}

/// The area of [x0, x1] x [y0, y1] within the disk of radius `r` centred at
/// the origin; 0 for an empty rectangle or r <= 0.
#[inline(always)]
pub fn rect_overlap_f32(r: f32, [x0, x1]: [f32; 2], [y0, y1]: [f32; 2]) -> f32 {
    if !(r > 0.0) || !(x1 > x0) || !(y1 > y0) {
        return 0.0;
    }
    // The farthest and nearest points' squared distances from the centre
    // (squares, not hypot: this test is the kernels' inner loop).
    let (fx, fy) = (x0.abs().max(x1.abs()), y0.abs().max(y1.abs()));
    if fx * fx + fy * fy <= r * r {
        return (x1 - x0) * (y1 - y0);
    }
    let (nx, ny) = (0f32.clamp(x0, x1), 0f32.clamp(y0, y1));
    if nx * nx + ny * ny >= r * r {
        return 0.0;
    }
    let area = corner(r, x1, y1) - corner(r, x0, y1) - corner(r, x1, y0) + corner(r, x0, y0);
    area.clamp(0.0, ((x1 - x0) * (y1 - y0)).min(PI * r * r))
}

#[cfg(test)]
mod tests {
    use super::super::disk::rect_overlap;
    use super::*;

    #[test]
    fn asin_poly_is_asin() {
        let worst = (0..=20_000)
            .map(|i| -1.0 + i as f64 / 10_000.0)
            .map(|x| (f64::from(asin_poly(x as f32)) - (x as f32 as f64).asin()).abs())
            .fold(0f64, f64::max);
        assert!(worst < 5e-7, "{worst}");
        assert_eq!(asin_poly(0.0), 0.0);
        assert_eq!(asin_poly(1.0), 0.5 * PI);
    }

    /// Against the f64 reference at random rectangles about a unit disk
    /// (inside, outside, across the rim, larger than it): within a few ulp
    /// of the disk's area.
    #[test]
    fn matches_the_f64_overlap() {
        let mut s = 11u64;
        let mut u = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s % 1_000_000) as f64 / 1e6
        };
        let mut worst = 0f64;
        for _ in 0..200_000 {
            let (cx, cy) = (u() * 3.0 - 1.5, u() * 3.0 - 1.5);
            let size = 10f64.powf(u() * 3.0 - 3.0);
            let (hx, hy) = (size * u(), size * u());
            let (x, y) = ([cx - hx, cx + hx], [cy - hy, cy + hy]);
            let want = rect_overlap(1.0, x, y);
            let got = rect_overlap_f32(1.0, x.map(|v| v as f32), y.map(|v| v as f32));
            // The f32 rectangle is the f64 one rounded: its own area differs
            // by a few ulp of its sides.
            let err = (f64::from(got) - want).abs();
            worst = worst.max(err);
        }
        assert!(worst < 2e-6, "{worst}");
        assert_eq!(rect_overlap_f32(1.0, [-2.0, 2.0], [-2.0, 2.0]), PI);
        assert_eq!(rect_overlap_f32(1.0, [0.1, 0.2], [0.1, 0.3]), 0.1 * 0.2f32);
        assert_eq!(rect_overlap_f32(1.0, [1.0, 2.0], [-1.0, 1.0]), 0.0);
        assert_eq!(rect_overlap_f32(0.0, [-1.0, 1.0], [-1.0, 1.0]), 0.0);
    }
}
