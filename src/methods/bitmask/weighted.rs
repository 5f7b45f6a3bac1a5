//! The bitmask's weighted visibility: each light sample weighted by its
//! share of a Lambertian receiver's irradiance, for the eye view's shaded
//! image (eye/shading.rs).
//!
//! Maths. A surface point p with unit normal n under a planar light of
//! radiance L receives E = L ∫ V(y) cos θ cos θ' / r² dA(y). The pattern's
//! samples y_i sample the light uniformly, so with w_i = cos θ_i cos θ'_i /
//! r_i² (`RayOrigin::weight`, 0 behind the tangent plane)
//!
//!   E ≈ E_0 · Σ_i w_i V_i / Σ_i w_i,
//!
//! E_0 the closed-form unshadowed irradiance: the ratio estimator of Heitz,
//! Hill & McGuire 2018 ("Combining analytic direct illumination and
//! stochastic shadows", §3), here with the mask's noise-free V_i. A mask
//! with no sample hidden weighs 1 and a full one 0, so only penumbra points
//! pay for the sum over their samples.
//!
//! The weights are computed where the gather has a group's final mask
//! (`Accumulator::occlusion_at`): the masks are never stored. The plain
//! visibility (the hidden samples' count) is returned beside it, unchanged.

use super::{sample_ranks, Bitmask, Gaps, MaskKernel, Masks, Patterns};
use crate::methods::gather::{self, Accumulator, Group, Lanes, RowLanes};
use crate::methods::{LightPoint, ShadowInputs};
use crate::trace::shadow_rays::RayOrigin;
use std::sync::atomic::{AtomicU32, Ordering};

/// A sample on the light: its bit in the masks and its point (x, y, 0) in
/// kernel units.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sample {
    pub bit: u32,
    pub x: f32,
    pub y: f32,
}

/// The samples of the n x n pattern on a light of half-extents `half`
/// (kernel units): rank k of S = n² at half-light coordinate
/// 2 (k + 1/2)/S - 1 (`RankBounds`), a `disk`'s those inside it.
pub(super) fn samples(n: usize, disk: bool, half: [f64; 2]) -> Vec<Sample> {
    let s = (n * n) as f64;
    let t = |k: usize| 2.0 * (k as f64 + 0.5) / s - 1.0;
    sample_ranks(n, disk)
        .map(|(bit, (xr, yr))| Sample {
            bit: bit as u32,
            x: (t(xr) * half[0]) as f32,
            y: (t(yr) * half[1]) as f32,
        })
        .collect()
}

/// The weighted visibility of lane `l` of `masks` (its hidden samples set)
/// seen from `r`: Σ w over the samples not hidden / Σ w over all (0 where
/// every sample lies behind the receiver's tangent plane).
fn weighted_lane<const W: usize, R: RayOrigin>(
    masks: &Masks<W>,
    l: usize,
    samples: &[Sample],
    r: &R,
) -> f32 {
    let (mut lit, mut all) = (0f64, 0f64);
    for s in samples {
        let w = f64::from(r.weight(s.x, s.y));
        all += w;
        let b = s.bit as usize;
        if (masks[b / 64][l] >> (b % 64)) & 1 == 0 {
            lit += w;
        }
    }
    if all > 0.0 {
        (lit / all) as f32
    } else {
        0.0
    }
}

/// The mask kernel, writing each point's weighted visibility as its group
/// finishes.
struct Weighted<'a, const W: usize, const Q: bool, R> {
    k: &'a MaskKernel<'a, W, Q>,
    samples: &'a [Sample],
    /// Per point, in the caller's order.
    receivers: &'a [Option<R>],
    /// The shading order: lane l of a group is point order[first + l].
    order: &'a [u32],
    /// The weighted visibility per point (f32 bits), in the caller's order.
    out: &'a [AtomicU32],
}

impl<const W: usize, const Q: bool, R: RayOrigin> Accumulator for Weighted<'_, W, Q, R> {
    type State = Masks<W>;
    const LAYERS_SHARE_STATE: bool = true;
    const CORNERS: bool = Q;

    fn empty(&self) -> Masks<W> {
        self.k.empty()
    }

    #[inline(always)]
    fn add_texel(&self, acc: &mut Masks<W>, w: f32, x0: f32, x1: f32, r: &RowLanes, g: &Group) {
        self.k.add_texel(acc, w, x0, x1, r, g)
    }

    fn full(&self, acc: &Masks<W>, g: &Group) -> bool {
        self.k.full(acc, g)
    }

    fn occlusion(&self, acc: &Masks<W>) -> Lanes {
        self.k.occlusion(acc)
    }

    fn occlusion_at(&self, acc: &Masks<W>, g: &Group) -> Lanes {
        let occ = self.k.occlusion(acc);
        for (l, &o) in occ.iter().enumerate() {
            let Some(&n) = self.order.get(g.first + l) else {
                break;
            };
            let n = n as usize;
            let Some(r) = self.receivers[n].as_ref() else {
                continue;
            };
            if !g.wr[l].is_finite() {
                continue;
            }
            let v = if o <= 0.0 {
                1.0
            } else if o >= 1.0 {
                0.0
            } else {
                weighted_lane(acc, l, self.samples, r)
            };
            self.out[n].store(v.to_bits(), Ordering::Relaxed);
        }
        occ
    }

    #[inline(always)]
    fn add_texel_tile(
        &self,
        acc: &mut Masks<W>,
        w: f32,
        x0: f32,
        x1: f32,
        r: &RowLanes,
        g: &Group,
    ) -> bool {
        self.k.add_texel_tile(acc, w, x0, x1, r, g)
    }

    #[inline(always)]
    fn add_quad(
        &self,
        acc: &mut Masks<W>,
        w: f32,
        c: &[f32; 4],
        x0: f32,
        x1: f32,
        r: &RowLanes,
        g: &Group,
    ) {
        self.k.add_quad(acc, w, c, x0, x1, r, g)
    }

    #[inline(always)]
    fn add_quad_tile(
        &self,
        acc: &mut Masks<W>,
        w: f32,
        c: &[f32; 4],
        inv: &[f32; 4],
        x0: f32,
        x1: f32,
        r: &RowLanes,
        g: &Group,
    ) -> bool {
        self.k.add_quad_tile(acc, w, c, inv, x0, x1, r, g)
    }
}

impl Bitmask {
    /// n, the pattern's side (n x n samples).
    fn side(&self) -> usize {
        match &self.pattern {
            Patterns::Small(p) => p.n,
            Patterns::Large(p) => p.n,
        }
    }

    /// The counted samples as the GPU's weighted resolve reads them
    /// (bitmask.wgsl's `light_samples`): (x, y) in kernel units on a light
    /// of half-extents `half`, the sample's bit as f32, 0.
    pub fn light_samples(&self, half: [f64; 2]) -> Vec<[f32; 4]> {
        samples(self.side(), self.disk, half)
            .iter()
            .map(|s| [s.x, s.y, s.bit as f32, 0.0])
            .collect()
    }

    /// `visibility_points`, and beside it each point's weighted visibility
    /// (module doc) seen from `receivers[k]` (its surface point and tangent
    /// plane; 1 where `None`). The plain visibility has the same bits as
    /// `visibility_points`'.
    pub(crate) fn weighted_points<R: RayOrigin>(
        &self,
        inputs: &ShadowInputs,
        points: &[LightPoint],
        receivers: &[Option<R>],
    ) -> (Vec<f32>, Vec<f32>) {
        assert_eq!(points.len(), receivers.len(), "a receiver per point");
        if let Some(disk) = self.on(inputs) {
            return disk.weighted_points(inputs, points, receivers);
        }
        let samples = samples(self.side(), self.disk, inputs.light_shape.half_extent());
        let order = gather::point_order(&inputs.occluder_grid, points);
        let out: Vec<AtomicU32> = (0..points.len())
            .map(|_| AtomicU32::new(1f32.to_bits()))
            .collect();
        let v = with_kernel!(self, |k| {
            let a = Weighted {
                k,
                samples: &samples,
                receivers,
                order: &order,
                out: &out,
            };
            gather::visibility_points_in(&a, inputs, points, &order, self.hierarchy)
        });
        let weighted = out
            .into_iter()
            .map(|w| f32::from_bits(w.into_inner()))
            .collect();
        (v, weighted)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::plate_case::WeightedPlate;
    use crate::methods::ShadowMethod;
    use glam::Vec3;

    /// The floor under the plate of `plate_case`, its points' normal
    /// tilted: each penumbra point's weighted visibility against the
    /// integral, where the plain fraction is far from it.
    #[test]
    fn weighted_visibility_matches_the_integral() {
        let plate = WeightedPlate::new(32, Vec3::new(0.7, 0.2, -1.0));
        let inputs = plate.inputs();
        for gaps in Gaps::ALL {
            let m = Bitmask::new(1024, gaps, None);
            let (v, w) = m.weighted_points(&inputs, &plate.pts, &plate.surfaces);
            assert_eq!(v, m.visibility_points(&inputs, &plate.pts), "{gaps:?}");
            let (worst, plain_worst, penumbra) = plate.errors(&v, &w);
            assert!(penumbra > 50, "{penumbra} penumbra points");
            assert!(worst < 0.02, "{gaps:?}: weighted off by {worst}");
            assert!(
                plain_worst > 0.05,
                "{gaps:?}: plain off by only {plain_worst}"
            );
        }
    }
}
