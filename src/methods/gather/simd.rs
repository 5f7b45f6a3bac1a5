//! Runtime dispatch: the same source compiled for AVX-512, AVX2+FMA or the
//! baseline. The lanes are fixed in the source, so all three give the same bits.
//!
//! The source is the per-group loop of `group.rs` (`shade_row_generic`,
//! `shade_points_generic`), which inlines the traversal; each entry here picks
//! the best compiled copy the CPU can run.

use super::kernel::{Accumulator, Kernel};
use crate::methods::LightPoint;

impl Kernel {
    pub(super) fn shade_row<A: Accumulator>(
        &self,
        a: &A,
        j: usize,
        receiver: &[f32],
        out: &mut [f32],
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl") {
                // SAFETY: the CPU has the features the function is compiled for.
                return unsafe { self.shade_row_avx512(a, j, receiver, out) };
            }
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                // SAFETY: as above.
                return unsafe { self.shade_row_avx2(a, j, receiver, out) };
            }
        }
        self.shade_row_generic(a, j, receiver, out)
    }

    /// Shades `pts`, the points of ranks `first..` in the shading order.
    pub(super) fn shade_points<A: Accumulator>(
        &self,
        a: &A,
        pts: &[LightPoint],
        first: usize,
        out: &mut [f32],
    ) {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx512f") && is_x86_feature_detected!("avx512vl") {
                // SAFETY: the CPU has the features the function is compiled for.
                return unsafe { self.shade_points_avx512(a, pts, first, out) };
            }
            if is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma") {
                // SAFETY: as above.
                return unsafe { self.shade_points_avx2(a, pts, first, out) };
            }
        }
        self.shade_points_generic(a, pts, first, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
    unsafe fn shade_row_avx512<A: Accumulator>(
        &self,
        a: &A,
        j: usize,
        receiver: &[f32],
        out: &mut [f32],
    ) {
        self.shade_row_generic(a, j, receiver, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn shade_row_avx2<A: Accumulator>(
        &self,
        a: &A,
        j: usize,
        receiver: &[f32],
        out: &mut [f32],
    ) {
        self.shade_row_generic(a, j, receiver, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,avx512vl,avx2,fma")]
    unsafe fn shade_points_avx512<A: Accumulator>(
        &self,
        a: &A,
        pts: &[LightPoint],
        first: usize,
        out: &mut [f32],
    ) {
        self.shade_points_generic(a, pts, first, out)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn shade_points_avx2<A: Accumulator>(
        &self,
        a: &A,
        pts: &[LightPoint],
        first: usize,
        out: &mut [f32],
    ) {
        self.shade_points_generic(a, pts, first, out)
    }
}
