//! `exact` with a probe: trace every sample only where a cheap first pass
//! is not sure (issue 29, "exact where it matters").
//!
//! Most receivers that are not lit outright (their shaft to the light meets
//! a leaf of the BVH: `shaft.rs`) lie in an umbra or in light that merely
//! passes near an occluder; only the penumbra needs many samples. A first
//! pass traces `probe` stratified samples at every receiver. A receiver is
//! *certain* when its probe saw the whole light or none of it and so did
//! the probe of every neighbour in its 3 x 3 block of the image (of the map,
//! in the light view) that has a receiver: it keeps that answer, 1 or 0.
//! Every other receiver is decided on `samples` exactly as `exact` without
//! a probe decides it, by the same engine (`engine.rs`: the same rays and
//! jitter, or the same masks, so the same bits).
//!
//! What it can miss: an occluder, or a gap between occluders, that every
//! probe ray of nine neighbouring receivers passes by. With a 4 x 4 probe
//! that is a feature narrower than about a quarter of the light, as seen
//! from the receivers, that lies wholly between one stratum's rays for
//! three receivers in a row: a light seen through a slit, a thin wire far
//! from its shadow. The error estimate (`estimate_error=True`) traces its
//! own rays at random receivers and measures what was missed.
//!
//! Neighbours are found by the receivers' jitter keys, which are their
//! pixels (texels) in a `width` x `height` image: the receivers of points
//! the user gave have no neighbours and trace every sample.

use super::engine::{visibilities_weighted, Engine};
use crate::trace::bvh::Bvh;
use crate::trace::shadow_rays::{visibilities, RayOrigin, Sampling};
use rayon::prelude::*;

/// The visibility of each receiver of `receivers`, as
/// `engine::visibilities_weighted` with `fine` and `engine` gives it, except that a
/// receiver whose probe (`coarse`) and whose neighbours' probes saw all of
/// the light or none of it keeps the probe's answer. Receiver k's key
/// `key(k)` is its flat index in an image of `size` (width, height).
#[allow(clippy::too_many_arguments)]
pub(crate) fn probed_visibilities<R: RayOrigin + Copy>(
    bvh: &Bvh,
    receivers: &[Option<R>],
    key: impl Fn(usize) -> u64 + Sync,
    order: &[usize],
    (fine, engine): (&Sampling, Engine),
    coarse: &Sampling,
    absent: f32,
    size: (usize, usize),
) -> Vec<f32> {
    probed_visibilities_weighted(
        bvh,
        receivers,
        key,
        order,
        (fine, engine),
        coarse,
        absent,
        size,
    )
    .into_iter()
    .map(|[v, _]| v)
    .collect()
}

/// `probed_visibilities` with the weighted fractions beside them
/// (`shadow_rays::visibilities_weighted`): a certain receiver's are its
/// probe's 0 or 1, both.
#[allow(clippy::too_many_arguments)]
pub(crate) fn probed_visibilities_weighted<R: RayOrigin + Copy>(
    bvh: &Bvh,
    receivers: &[Option<R>],
    key: impl Fn(usize) -> u64 + Sync,
    order: &[usize],
    (fine, engine): (&Sampling, Engine),
    coarse: &Sampling,
    absent: f32,
    size: (usize, usize),
) -> Vec<[f32; 2]> {
    let probe = visibilities(bvh, receivers, &key, order, coarse, absent);
    let certain = certain(receivers, &key, &probe, size);
    let unsure: Vec<Option<R>> = receivers
        .iter()
        .zip(&certain)
        .map(|(r, &c)| if c { None } else { *r })
        .collect();
    let traced = visibilities_weighted(engine, bvh, &unsure, &key, order, fine, absent);
    probe
        .into_iter()
        .zip(traced)
        .zip(certain)
        .map(|((p, t), c)| if c { [p; 2] } else { t })
        .collect()
}

/// `certain` for receivers that are the pixels `pixels` (flat indices of
/// an image of `size`, each its own key), every one a receiver.
pub(crate) fn certain_by_pixel(pixels: &[usize], probe: &[f32], size: (usize, usize)) -> Vec<bool> {
    let receivers = vec![Some(()); pixels.len()];
    certain(&receivers, |k| pixels[k] as u64, probe, size)
}

/// Which receivers are certain: a probe of 0 or 1 that every neighbour
/// with a receiver shares (a receiver without one, or with a key outside
/// the image, is never certain).
fn certain<R: Sync>(
    receivers: &[Option<R>],
    key: impl Fn(usize) -> u64 + Sync,
    probe: &[f32],
    (width, height): (usize, usize),
) -> Vec<bool> {
    // The probe by pixel; NaN where no receiver.
    let mut image = vec![f32::NAN; width * height];
    let pixel = |k: usize| usize::try_from(key(k)).ok().filter(|&p| p < width * height);
    for (k, r) in receivers.iter().enumerate() {
        if let (Some(_), Some(p)) = (r, pixel(k)) {
            image[p] = probe[k];
        }
    }
    (0..receivers.len())
        .into_par_iter()
        .map(|k| {
            let (Some(_), Some(p)) = (&receivers[k], pixel(k)) else {
                return false;
            };
            let v = image[p];
            if v != 0.0 && v != 1.0 {
                return false;
            }
            let (x, y) = (p % width, p / width);
            (y.saturating_sub(1)..(y + 2).min(height)).all(|j| {
                (x.saturating_sub(1)..(x + 2).min(width)).all(|i| {
                    let w = image[j * width + i];
                    w.is_nan() || w == v
                })
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light_shape::LightShape;
    use crate::trace::shadow_rays::Jitter;
    use glam::Vec3;

    /// A plate of half-width `h` at depth 1 over receivers at depth 2, a
    /// unit light: umbra in the middle, penumbra around it, lit outside.
    fn scene(h: f32) -> Bvh {
        let v = [
            Vec3::new(-h, -h, 1.0),
            Vec3::new(h, -h, 1.0),
            Vec3::new(h, h, 1.0),
            Vec3::new(-h, h, 1.0),
        ];
        Bvh::build(vec![[v[0], v[1], v[2]], [v[0], v[2], v[3]]])
    }

    fn receivers(n: usize) -> Vec<Option<Vec3>> {
        (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as f32, (k / n) as f32);
                let t = |i: f32| (i + 0.5) / n as f32 * 6.0 - 3.0;
                Some(Vec3::new(t(i), t(j), 2.0))
            })
            .collect()
    }

    fn sampling(light: LightShape, samples: u32, jitter: Jitter) -> Sampling {
        Sampling {
            light: light.samples(samples),
            t0: 1e-5,
            jitter,
        }
    }

    #[test]
    fn unsure_receivers_get_exacts_bits_and_certain_ones_are_right() {
        for engine in Engine::ALL {
            unsure_receivers_get_the_engines_bits(engine);
        }
    }

    fn unsure_receivers_get_the_engines_bits(engine: Engine) {
        let n = 48;
        let bvh = scene(0.8);
        let r = receivers(n);
        let order: Vec<usize> = (0..r.len()).collect();
        let light = LightShape::rect([1.0, 1.0]);
        let (fine, coarse) = (
            sampling(light, 256, Jitter::Shared),
            sampling(light, 16, Jitter::PerReceiver),
        );
        let key = |k: usize| k as u64;
        let all: Vec<f32> = visibilities_weighted(engine, &bvh, &r, key, &order, &fine, 1.0)
            .into_iter()
            .map(|[v, _]| v)
            .collect();
        if engine == Engine::Rays {
            assert_eq!(all, visibilities(&bvh, &r, key, &order, &fine, 1.0));
        }
        let got = probed_visibilities(&bvh, &r, key, &order, (&fine, engine), &coarse, 1.0, (n, n));
        // Every receiver the probe was unsure of has exact's bits; a certain
        // one may miss a sliver of penumbra no probe ray met.
        let (mut kept, mut off, mut worst) = (0, 0f64, 0f32);
        for (g, a) in got.iter().zip(&all) {
            if g != a {
                assert!(*g == 0.0 || *g == 1.0, "{g} {a}");
                worst = worst.max((g - a).abs());
            }
            if *g == 0.0 || *g == 1.0 {
                kept += 1;
            }
            off += (g - a).abs() as f64;
        }
        let shadowed = all.iter().filter(|&&a| a < 1.0).count();
        // Measured: 1476 of 2304 certain, one receiver off by 1/256.
        assert!(kept > n * n / 2, "{engine:?}: {kept} certain");
        assert!(worst <= 1.0 / 16.0, "worst {worst}");
        assert!(
            off / (shadowed as f64) < 1e-3,
            "mean {}",
            off / shadowed as f64
        );
    }

    #[test]
    fn a_neighbour_that_differs_makes_a_receiver_unsure() {
        let r = vec![Some(Vec3::Z); 9];
        let key = |k: usize| k as u64;
        let mut probe = vec![1.0; 9];
        assert!(certain(&r, key, &probe, (3, 3)).iter().all(|&c| c));
        probe[8] = 0.0;
        let c = certain(&r, key, &probe, (3, 3));
        // The centre and the corner's other neighbours see it; the far
        // corner does not.
        assert!(!c[4] && !c[5] && !c[7] && !c[8]);
        assert!(c[0] && c[1] && c[2] && c[3] && c[6]);
        // A partial probe is never certain; a missing receiver is ignored.
        let mut r2 = r.clone();
        r2[8] = None;
        probe[8] = 0.5;
        let c = certain(&r2, key, &probe, (3, 3));
        assert!(c[..8].iter().all(|&c| c) && !c[8]);
    }

    #[test]
    fn a_key_outside_the_image_is_never_certain() {
        let r = vec![Some(Vec3::Z); 2];
        let c = certain(&r, |k| (k * 100) as u64, &[1.0, 1.0], (3, 3));
        assert_eq!(c, vec![true, false]);
    }
}
