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
pub fn unshadowed(lights: &[(&Light, [f64; 3])], g: &GBuffer, e: f64) -> Vec<(usize, f64)> {
    if lights.len() < 2 || !(e > 0.0) {
        return vec![];
    }
    let hits = g.hits();
    // Per light, per hit pixel, per channel: E_k,c(p).
    let each: Vec<Vec<[f64; 3]>> = lights
        .iter()
        .map(|(light, emission)| {
            hits.par_iter()
                .map(|&k| {
                    let x = DVec3::from_array(g.position[k]);
                    let n = Vec3::from_array(g.normal[k]).as_dvec3().normalize_or_zero();
                    let e = irradiance(light, x, n);
                    emission.map(|c| c * e)
                })
                .collect()
        })
        .collect();
    let total: Vec<[f64; 3]> = (0..hits.len())
        .into_par_iter()
        .map(|p| {
            let mut t = [0.0; 3];
            for e in &each {
                for c in 0..3 {
                    t[c] += e[p][c];
                }
            }
            t
        })
        .collect();
    // The worst share of the set `sum` at any pixel and channel; a channel
    // no light reaches is 0 / 0: no share.
    let worst = |sum: &[[f64; 3]]| -> f64 {
        sum.par_iter()
            .zip(&total)
            .map(|(s, t)| {
                (0..3)
                    .filter(|&c| t[c] > 0.0)
                    .map(|c| s[c] / t[c])
                    .fold(0.0, f64::max)
            })
            .reduce(|| 0.0, f64::max)
    };
    let mut order: Vec<(usize, f64)> = (1..lights.len()).map(|k| (k, worst(&each[k]))).collect();
    order.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut sum = vec![[0.0; 3]; hits.len()];
    let mut out = vec![];
    for (k, share) in order {
        if !(share <= e) {
            break;
        }
        let next: Vec<[f64; 3]> = sum
            .iter()
            .zip(&each[k])
            .map(|(s, x)| [s[0] + x[0], s[1] + x[1], s[2] + x[2]])
            .collect();
        let w = worst(&next);
        if !(w <= e) {
            continue;
        }
        sum = next;
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
