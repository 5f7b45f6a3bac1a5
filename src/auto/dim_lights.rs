//! Lights too dim to shadow under an error target (`Auto(error=e)` with
//! several lights in one call).
//!
//! A light's shadow changes a pixel's shaded colour by at most the light's
//! own unshadowed contribution there: shading is Σ_k (ρ/π) E_k V_k, and
//! leaving light k unshadowed (V_k = 1) errs by (ρ/π) E_k (1 − V_k) ≤
//! (ρ/π) E_k. So a set D of lights may stay unshadowed wherever, at every
//! pixel p that sees a surface and in every colour channel c,
//!
//! ```text
//!     Σ_{k ∈ D} E_k,c(p) <= e · Σ_k E_k,c(p),
//! ```
//!
//! the unshadowed irradiances in closed form (`eye::shading::irradiance`,
//! the emission included): the shaded image then errs by at most e of its
//! unshadowed radiance at every pixel, whatever the albedo (it cancels per
//! channel). D is grown greedily, the lights of the smallest worst share
//! first, while the sum stays within e.
//!
//! The first light is always shadowed: its run casts the first hits the
//! others share (`api::render_lights`), so the shares are computed on its
//! G-buffer, after it.

use crate::eye::gbuffer::GBuffer;
use crate::eye::shading::irradiance;
use crate::geom::light_space::Light;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// Which of `lights` (with their RGB emissions) may stay unshadowed under
/// the error target `e` on the surface points of `g` (module doc), each
/// with the worst share of the irradiance the unshadowed set then has
/// where it is added; never the first light. In the order found.
///
/// Memory: two RGB images of the visible points (the total and the set's
/// sum) whatever the number of lights; each light's irradiance is
/// evaluated again where needed (at most three times a point: the total,
/// its own worst share, its trial in the set).
pub fn unshadowed(lights: &[(&Light, [f64; 3])], g: &GBuffer, e: f64) -> Vec<(usize, f64)> {
    if lights.len() < 2 || !(e > 0.0) {
        return vec![];
    }
    let hits = g.hits();
    let at = |k: usize| {
        (
            DVec3::from_array(g.position[k]),
            Vec3::from_array(g.normal[k]).as_dvec3().normalize_or_zero(),
        )
    };
    // E_k,c at visible point p: the closed form times the emission.
    let each = |light: usize, p: usize| -> [f64; 3] {
        let (l, emission) = lights[light];
        let (x, n) = at(hits[p]);
        let e = irradiance(l, x, n);
        emission.map(|c| c * e)
    };
    let total: Vec<[f64; 3]> = (0..hits.len())
        .into_par_iter()
        .map(|p| {
            let mut t = [0.0; 3];
            for k in 0..lights.len() {
                let x = each(k, p);
                for c in 0..3 {
                    t[c] += x[c];
                }
            }
            t
        })
        .collect();
    // The worst share at any point and channel of the set whose sum at
    // point p is `sum(p)`; a channel no light reaches is 0 / 0: no share.
    let worst = |sum: &(dyn Fn(usize) -> [f64; 3] + Sync)| -> f64 {
        (0..hits.len())
            .into_par_iter()
            .map(|p| {
                let (s, t) = (sum(p), total[p]);
                (0..3)
                    .filter(|&c| t[c] > 0.0)
                    .map(|c| s[c] / t[c])
                    .fold(0.0, f64::max)
            })
            .reduce(|| 0.0, f64::max)
    };
    let mut order: Vec<(usize, f64)> = (1..lights.len())
        .map(|k| (k, worst(&|p| each(k, p))))
        .collect();
    order.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut sum = vec![[0.0; 3]; hits.len()];
    let mut out = vec![];
    for (k, share) in order {
        if !(share <= e) {
            break;
        }
        let with = |p: usize| {
            let (s, x) = (sum[p], each(k, p));
            [s[0] + x[0], s[1] + x[1], s[2] + x[2]]
        };
        let w = worst(&with);
        if !(w <= e) {
            continue;
        }
        sum = (0..hits.len()).into_par_iter().map(with).collect();
        out.push((k, w));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::AreaLight;

    fn floor(n: usize) -> GBuffer {
        let len = n * n;
        GBuffer {
            width: n,
            height: n,
            depth: vec![1.0; len],
            position: (0..len)
                .map(|k| {
                    [
                        (k % n) as f64 / n as f64 - 0.5,
                        0.0,
                        (k / n) as f64 / n as f64 - 0.5,
                    ]
                })
                .collect(),
            normal: vec![[0.0, 1.0, 0.0]; len],
            mesh_id: vec![0; len],
            face: vec![0; len],
            bary: vec![[0.0; 2]; len],
        }
    }

    fn light(x: f64) -> Light {
        AreaLight::rect([x, 2.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.5, 0.5])
            .unwrap()
            .into()
    }

    /// A light a hundredth as bright as the first stays unshadowed under
    /// 0.02, not under 0.005; two such lights fit 0.05 together, and the
    /// first light never goes, however dim.
    #[test]
    fn dim_lights_within_the_target_stay_unshadowed() {
        let g = floor(16);
        let (a, b, c) = (light(0.0), light(0.3), light(-0.3));
        let bright = [1.0, 1.0, 1.0];
        let dim = [0.01, 0.01, 0.01];
        let got = unshadowed(&[(&a, bright), (&b, dim)], &g, 0.02);
        assert_eq!(got.len(), 1);
        assert_eq!(got[0].0, 1);
        assert!(got[0].1 > 0.005 && got[0].1 <= 0.02, "{got:?}");
        assert!(unshadowed(&[(&a, bright), (&b, dim)], &g, 0.005).is_empty());
        let three = [(&a, bright), (&b, dim), (&c, dim)];
        let two = unshadowed(&three, &g, 0.05);
        assert_eq!(two.len(), 2, "{two:?}");
        // The pair's worst share is over each one's: a target between them
        // leaves one of the two unshadowed.
        let (first, pair) = (two[0].1, two[1].1);
        assert!(first < pair, "{two:?}");
        assert_eq!(unshadowed(&three, &g, 0.5 * (first + pair)).len(), 1);
        // The first light is never left unshadowed, however dim.
        let got = unshadowed(&[(&b, dim), (&a, bright)], &g, 1.0);
        assert_eq!(got.iter().map(|x| x.0).collect::<Vec<_>>(), vec![1]);
        // One colour channel that only the dim light lights: not dim there.
        let red = [1.0, 1.0, 0.0];
        let blue = [0.0, 0.0, 0.01];
        assert!(unshadowed(&[(&a, red), (&b, blue)], &g, 0.5).is_empty());
    }
}
