//! Scherzer 2005 §4.3: the eye-space blur of the shadow image, depth
//! dependent so that shadows near the viewer (where projection aliasing is
//! large in pixels) are blurred more and distant ones keep their detail.
//!
//! Each iteration replaces a pixel's visibility by the weighted mean of a
//! 3×3 grid of taps with weights [1 2 1] ⊗ [1 2 1], the taps `s` pixels
//! apart, `s = round(radius · z₀ / z)` for a pixel at depth z (z₀ the
//! nearest visible depth): the blur's radius falls as 1/z. A tap counts
//! only where it sees a surface within `DEPTH_TOLERANCE · z` of the
//! pixel's depth, so shadows do not bleed across silhouettes or onto the
//! background; the weights of the taps left are renormalised.

use super::config::{EyeSpaceBlur, DEPTH_TOLERANCE};
use rayon::prelude::*;

/// The tap spacing of a pixel at depth z.
pub fn spacing(blur: &EyeSpaceBlur, z0: f32, z: f32) -> i64 {
    if !(z.is_finite() && z > 0.0 && z0 > 0.0) {
        return 0;
    }
    (blur.radius.0 * (z0 / z) as f64).round() as i64
}

/// Blurs `vis` (H×W, row-major) in place; `depth` holds each pixel's depth
/// along the camera's axis (inf where no surface, which is left alone).
pub fn blur(blur: &EyeSpaceBlur, width: usize, height: usize, depth: &[f32], vis: &mut [f32]) {
    let z0 = depth
        .par_iter()
        .copied()
        .filter(|z| z.is_finite() && *z > 0.0)
        .reduce(|| f32::INFINITY, f32::min);
    if !z0.is_finite() || width == 0 {
        return;
    }
    const W: [f32; 3] = [1.0, 2.0, 1.0];
    let mut next = vis.to_vec();
    for _ in 0..blur.iterations {
        next.par_chunks_mut(width).enumerate().for_each(|(j, row)| {
            for (i, out) in row.iter_mut().enumerate() {
                let k = j * width + i;
                let z = depth[k];
                let s = spacing(blur, z0, z);
                if s == 0 {
                    *out = vis[k];
                    continue;
                }
                let (mut sum, mut wsum) = (0f32, 0f32);
                for (b, wb) in W.iter().enumerate() {
                    let jj = j as i64 + (b as i64 - 1) * s;
                    if jj < 0 || jj >= height as i64 {
                        continue;
                    }
                    for (a, wa) in W.iter().enumerate() {
                        let ii = i as i64 + (a as i64 - 1) * s;
                        if ii < 0 || ii >= width as i64 {
                            continue;
                        }
                        let t = jj as usize * width + ii as usize;
                        let zt = depth[t];
                        if zt.is_finite() && ((zt - z).abs() as f64) <= DEPTH_TOLERANCE * z as f64 {
                            sum += wa * wb * vis[t];
                            wsum += wa * wb;
                        }
                    }
                }
                *out = if wsum > 0.0 { sum / wsum } else { vis[k] };
            }
        });
        vis.copy_from_slice(&next);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::shadow_mapping::config::Real;

    /// The width of the ramp (pixels with 0.02 < v < 0.98) that the blur
    /// makes of a vertical shadow edge on a plane at depth z.
    fn ramp(z: f32, blur_cfg: &EyeSpaceBlur, z0: f32) -> usize {
        let (w, h) = (64, 8);
        // Row 0 holds the nearest depth z0 (so the spacing refers to it),
        // away from the rows measured.
        let mut depth = vec![z; w * h];
        depth[..w].fill(z0);
        let mut vis: Vec<f32> = (0..w * h)
            .map(|k| if k % w < 32 { 0.0 } else { 1.0 })
            .collect();
        blur(blur_cfg, w, h, &depth, &mut vis);
        (0..w)
            .filter(|i| vis[4 * w + i] > 0.02 && vis[4 * w + i] < 0.98)
            .count()
    }

    #[test]
    fn the_blur_radius_falls_with_depth() {
        let b = EyeSpaceBlur {
            iterations: 4,
            radius: Real(4.0),
        };
        let near = ramp(1.0, &b, 1.0);
        let mid = ramp(2.0, &b, 1.0);
        let far = ramp(16.0, &b, 1.0);
        assert!(near > mid && mid > far, "{near} {mid} {far}");
        // At 16x the nearest depth the spacing rounds to 0: untouched.
        assert_eq!(far, 0);
        assert_eq!(spacing(&b, 1.0, 1.0), 4);
        assert_eq!(spacing(&b, 1.0, 2.0), 2);
    }

    #[test]
    fn more_iterations_blur_more_and_the_background_is_left_alone() {
        let one = EyeSpaceBlur {
            iterations: 1,
            radius: Real(1.0),
        };
        let eight = EyeSpaceBlur {
            iterations: 8,
            radius: Real(1.0),
        };
        assert!(ramp(1.0, &eight, 1.0) > ramp(1.0, &one, 1.0));
        // A pixel with no surface keeps its value; its neighbours ignore it.
        let depth = [1.0, f32::INFINITY, 1.0];
        let mut vis = [0.0, 1.0, 0.0];
        blur(&one, 3, 1, &depth, &mut vis);
        assert_eq!(vis, [0.0, 1.0, 0.0]);
    }
}
