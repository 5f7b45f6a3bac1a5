//! The SSM's weighted occlusion: each micro-patch's back-projection
//! weighted by its share of a Lambertian receiver's irradiance, for the eye
//! view's shaded image (eye/shading.rs).
//!
//! Maths. A surface point p with unit normal n under a planar light of
//! radiance L receives E = L ∫ V(y) w(y) dA(y), w = cos θ cos θ' / r²
//! (`RayOrigin::weight`, 0 behind the tangent plane). The SSM hides, per
//! layer, the light area O = Σ_k A_k, A_k the back-projection of
//! micro-patch k clipped to the light (§3.4; in units where the light is
//! [-1, 1]², so O = 4 is all of it). Weighting each A_k by w at its centre
//! c_k (the midpoint rule on the clipped rectangle),
//!
//!   O_w = Σ_k A_k w(c_k) / ∫ w dA,   E ≈ E_0 (1 - min(O_w, 1)),
//!
//! E_0 the closed-form unshadowed irradiance, ∫ w dA the same weights over
//! the whole light (`shadow_rays::light_weight`, a midpoint rule): the ratio estimator of Heitz,
//! Hill & McGuire 2018 ("Combining analytic direct illumination and
//! stochastic shadows", §3) with the SSM's occlusion in place of V. The
//! layers merge as the plain occlusions do (§3.5): the layer whose plain
//! occlusion is the largest gives O_w. A point whose plain visibility is 0
//! or 1 keeps it (the shading then needs no weights).
//!
//! The weighted sums run beside the method's own (whatever its precision,
//! in f64), so the plain visibility keeps its bits.

use super::contributions;
use crate::geom::light_shape::LightShape;
use crate::methods::gather::{
    self, max, min, Accumulator, Group, Hierarchy, Lanes, RowLanes, LANES,
};
use crate::methods::{LightPoint, ShadowInputs};
use crate::trace::shadow_rays::{light_weight, RayOrigin};
use std::sync::atomic::{AtomicU64, Ordering};

/// The centre of micro-patch [x0, x1] x (row)'s back-projection clipped to
/// the light, seen from lane l, in half-light units: the clipped interval
/// [max(x0 - xr, -d), min(x1 - xr, d)] / d, its midpoint (and y's). Under a
/// disk, the centre of the patch clipped to the disk's square: off the
/// clipped part's centroid on a patch across the rim only, by at most the
/// patch's size, where w changes little.
#[inline(always)]
fn centre(l: usize, w: f32, x0: f32, x1: f32, r: &RowLanes, g: &Group) -> (f32, f32) {
    let d = w - g.wr[l];
    let h = 0.5 / d;
    (
        (min(x1 - r.xr[l], d) - min(r.xr[l] - x0, d)) * h,
        (min(r.ay1[l], d) - min(r.nay0[l], d)) * h,
    )
}

/// The group's receivers as the weights read them, a lane per entry: p
/// and the side coefficients (`SurfacePoint`); a lane without one weighs 0
/// (p = (0, 0, 1), side 0), so the loop over lanes has no branch.
#[derive(Clone, Copy)]
pub struct LaneSurfaces {
    p: [Lanes; 3],
    side: [Lanes; 3],
    some: [bool; LANES],
}

/// A layer's state: the method's own, and the weighted sums in two levels
/// (f32 over an occluder row, then f64, as the SSM's own `TwoLevel`).
pub struct State<S> {
    inner: S,
    done: [f64; LANES],
    open: Lanes,
    lanes: LaneSurfaces,
}

/// The SSM accumulator `A`, summing the weighted occlusion beside its own
/// (its micro-patches clipped to a disk where `DISK`, as `A`'s are).
struct Weighted<'a, A, R, const DISK: bool> {
    inner: &'a A,
    half: [f32; 2],
    /// Per point, in the caller's order.
    receivers: &'a [Option<R>],
    /// The shading order: lane l of a group is point order[first + l].
    order: &'a [u32],
    /// Per point (caller's order): the largest plain occlusion of a layer
    /// so far (f32 bits, -1 before any) and that layer's weighted sum (f64
    /// bits). Each point is one group's lane: one thread writes it.
    best: &'a [AtomicU64],
    sums: &'a [AtomicU64],
}

impl<A: Accumulator, R: RayOrigin + Copy + Sync, const DISK: bool> Weighted<'_, A, R, DISK> {
    /// Adds each lane's contribution times the weight at its centre.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // one index over several lane arrays: what vectorizes
    fn add_weights(
        &self,
        acc: &mut State<A::State>,
        w: f32,
        x0: f32,
        x1: f32,
        r: &RowLanes,
        g: &Group,
    ) {
        let s = &acc.lanes;
        let cs = contributions::<DISK>(w, x0, x1, r, g);
        for l in 0..LANES {
            let c = cs[l];
            let (x, y) = centre(l, w, x0, x1, r, g);
            let (x, y) = (x * self.half[0], y * self.half[1]);
            let side = s.side[0][l] + x * s.side[1][l] + y * s.side[2][l];
            let (dx, dy, dz) = (x - s.p[0][l], y - s.p[1][l], s.p[2][l]);
            let r2 = dx * dx + dy * dy + dz * dz;
            let wt = max(side, 0.0) * s.p[2][l] / (r2 * r2);
            // c = 0 where the patch misses the lane (its centre may then be
            // anything, even NaN): a select, not a product.
            acc.open[l] += if c > 0.0 { c * wt } else { 0.0 };
        }
    }
}

impl<A: Accumulator, R: RayOrigin + Copy + Sync, const DISK: bool> Accumulator
    for Weighted<'_, A, R, DISK>
{
    type State = State<A::State>;
    const LAYERS_SHARE_STATE: bool = A::LAYERS_SHARE_STATE;
    const ROW_MAJOR: bool = A::ROW_MAJOR;

    fn empty(&self) -> Self::State {
        State {
            inner: self.inner.empty(),
            done: [0.0; LANES],
            open: [0.0; LANES],
            lanes: LaneSurfaces {
                p: [[0.0; LANES], [0.0; LANES], [1.0; LANES]],
                side: [[0.0; LANES]; 3],
                some: [false; LANES],
            },
        }
    }

    fn empty_at(&self, g: &Group) -> Self::State {
        let mut st = self.empty();
        let s = &mut st.lanes;
        for l in 0..LANES {
            let Some(&n) = self.order.get(g.first + l) else {
                break;
            };
            if !g.wr[l].is_finite() {
                continue;
            }
            if let Some(sp) = self.receivers[n as usize].as_ref().and_then(R::surface) {
                for k in 0..3 {
                    s.p[k][l] = sp.p[k];
                    s.side[k][l] = sp.side[k];
                }
                s.some[l] = true;
            }
        }
        st
    }

    #[inline(always)]
    fn add_texel(&self, acc: &mut Self::State, w: f32, x0: f32, x1: f32, r: &RowLanes, g: &Group) {
        self.inner.add_texel(&mut acc.inner, w, x0, x1, r, g);
        self.add_weights(acc, w, x0, x1, r, g);
    }

    #[inline(always)]
    fn add_texel_tile(
        &self,
        acc: &mut Self::State,
        w: f32,
        x0: f32,
        x1: f32,
        r: &RowLanes,
        g: &Group,
    ) -> bool {
        let visited = self.inner.add_texel_tile(&mut acc.inner, w, x0, x1, r, g);
        if visited {
            self.add_weights(acc, w, x0, x1, r, g);
        }
        visited
    }

    fn full(&self, acc: &Self::State, g: &Group) -> bool {
        self.inner.full(&acc.inner, g)
    }

    fn occlusion(&self, acc: &Self::State) -> Lanes {
        self.inner.occlusion(&acc.inner)
    }

    /// Each layer in turn: where its plain occlusion beats the layers'
    /// before, its weighted sum is the point's.
    fn occlusion_at(&self, acc: &Self::State, g: &Group) -> Lanes {
        let occ = self.inner.occlusion(&acc.inner);
        for (l, &o) in occ.iter().enumerate() {
            let Some(&n) = self.order.get(g.first + l) else {
                break;
            };
            let n = n as usize;
            if !acc.lanes.some[l] {
                continue;
            }
            let best = f32::from_bits(self.best[n].load(Ordering::Relaxed) as u32);
            if o > best {
                let sum = acc.done[l] + f64::from(acc.open[l]);
                self.best[n].store(u64::from(o.to_bits()), Ordering::Relaxed);
                self.sums[n].store(sum.to_bits(), Ordering::Relaxed);
            }
        }
        occ
    }

    fn end_batch(&self, acc: &mut Self::State) {
        self.inner.end_batch(&mut acc.inner)
    }

    fn end_row(&self, acc: &mut Self::State) {
        self.inner.end_row(&mut acc.inner);
        for (d, o) in acc.done.iter_mut().zip(acc.open.iter_mut()) {
            *d += f64::from(*o);
            *o = 0.0;
        }
    }
}

/// `gather::visibility_points` with `a`, and beside it each point's
/// weighted visibility (module doc) seen from `receivers[k]` (1 where
/// `None`).
pub(super) fn weighted_points<A: Accumulator, R: RayOrigin + Copy + Sync>(
    a: &A,
    inputs: &ShadowInputs,
    points: &[LightPoint],
    receivers: &[Option<R>],
    hierarchy: Option<Hierarchy>,
) -> (Vec<f32>, Vec<f32>) {
    assert_eq!(points.len(), receivers.len(), "a receiver per point");
    let [hx, hy] = inputs.light_shape.half_extent();
    let half = [hx as f32, hy as f32];
    let order = gather::point_order(&inputs.occluder_grid, points);
    let none = u64::from((-1f32).to_bits());
    let best: Vec<AtomicU64> = points.iter().map(|_| AtomicU64::new(none)).collect();
    let sums: Vec<AtomicU64> = points.iter().map(|_| AtomicU64::new(0)).collect();
    let disk = matches!(inputs.light_shape, LightShape::Disk { .. });
    macro_rules! weighted {
        ($disk:literal) => {{
            let w = Weighted::<A, R, $disk> {
                inner: a,
                half,
                receivers,
                order: &order,
                best: &best,
                sums: &sums,
            };
            gather::visibility_points_in(&w, inputs, points, &order, hierarchy)
        }};
    }
    let v = if disk {
        weighted!(true)
    } else {
        weighted!(false)
    };
    use rayon::prelude::*;
    let weighted = v
        .par_iter()
        .zip(receivers)
        .zip(&sums)
        .map(|((&v, r), s)| match r.as_ref().and_then(R::surface) {
            Some(sp) if v > 0.0 && v < 1.0 => {
                let all = light_weight(&sp, half, disk);
                let hidden = f64::from_bits(s.load(Ordering::Relaxed));
                if all > 0.0 {
                    (1.0 - (hidden / all).clamp(0.0, 1.0)) as f32
                } else {
                    0.0
                }
            }
            _ => v,
        })
        .collect();
    (v, weighted)
}

#[cfg(test)]
mod tests {
    use super::super::{Precision, Ssm};
    use crate::methods::plate_case::WeightedPlate;
    use crate::methods::ShadowMethod;
    use glam::Vec3;

    /// The floor under the plate of `plate_case` (where the SSM is exact),
    /// its points' normal tilted both ways: each penumbra point's weighted
    /// visibility against the integral, at every precision; the plain
    /// visibility keeps its bits.
    #[test]
    fn weighted_visibility_matches_the_integral() {
        let plate = WeightedPlate::new(32, Vec3::new(0.5, -0.6, -1.0));
        let inputs = plate.inputs();
        for precision in Precision::ALL {
            let m = Ssm {
                hierarchy: None,
                precision,
            };
            let (v, w) = m.weighted_points(&inputs, &plate.pts, &plate.surfaces);
            assert_eq!(v, m.visibility_points(&inputs, &plate.pts), "{precision:?}");
            let (worst, plain_worst, penumbra) = plate.errors(&v, &w);
            eprintln!("{precision:?}: weighted {worst}, plain {plain_worst}, {penumbra} points");
            assert!(penumbra > 50, "{penumbra} penumbra points");
            assert!(worst < 0.01, "{precision:?}: weighted off by {worst}");
            assert!(
                plain_worst > 0.05,
                "{precision:?}: plain off by only {plain_worst}"
            );
        }
    }

    /// The same under the disk inscribed in the light: the patches clipped
    /// to it, the weights' integral over it.
    #[test]
    fn weighted_visibility_under_a_disk_matches_the_integral() {
        use crate::geom::light_shape::LightShape;
        let plate = WeightedPlate::new(32, Vec3::new(0.5, -0.6, -1.0)).under(LightShape::disk(0.5));
        let inputs = plate.inputs();
        let m = Ssm::default();
        let (v, w) = m.weighted_points(&inputs, &plate.pts, &plate.surfaces);
        assert_eq!(v, m.visibility_points(&inputs, &plate.pts));
        let (worst, plain_worst, penumbra) = plate.errors(&v, &w);
        eprintln!("disk: weighted {worst}, plain {plain_worst}, {penumbra} points");
        assert!(penumbra > 50, "{penumbra} penumbra points");
        assert!(worst < 0.01, "weighted off by {worst}");
        assert!(plain_worst > 0.04, "plain off by only {plain_worst}");
    }
}
