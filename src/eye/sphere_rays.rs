//! `exact` in the eye view for a sphere light (geom/sphere_light.rs):
//! stratified shadow rays from every pixel's surface point over the cap of
//! the sphere that point sees.
//!
//! From a point x outside the sphere (centre c, radius R, d = |c − x|) the
//! light is the cap of directions within α of c − x, sin α = R/d. Its
//! a x b strata are equal in solid angle: the sample in [0, 1)² of stratum
//! (sa, sb) goes onto the unit disk by the concentric map (disk.rs), and
//! the disk's point (ρ, φ) onto the cap at cos θ = 1 − ρ² (1 − cos α),
//! azimuth φ about c − x (`light_shape::sphere::cap_direction`); its ray
//! stops at the sphere's near surface (`cap_hit`), a hair short. The
//! fraction of clear rays is the visibility: the fraction of the cap's
//! solid angle seen, as a planar light's is the fraction of its area.
//!
//! (u1, u2) take the rectangle's shared multi-jittered pattern
//! (`shadow_rays::Jitter::Shared` on the unit square), so that a penumbra
//! changes from pixel to pixel as the geometry does. Rays leave the surface
//! as the planar lights' do (rays.rs, after Mitsuba's `spawn_ray_to`): the
//! origin moves off the surface along the geometric normal, to the side
//! the ray leaves by. With a `probe`, a pixel whose probe and whose 3 x 3
//! neighbours' probes saw all of the cap or none of it keeps that answer
//! (`methods/probe.rs`), the others trace every sample.
//!
//! The rays are traced one at a time through the BVH of every triangle,
//! relative to the sphere's centre in f32 (no packets or shafts: each
//! pixel's rays go to its own cap).

use super::gbuffer::GBuffer;
use super::rays::RAY_EPSILON;
use crate::geom::light_shape::{disk, sphere, LightShape};
use crate::geom::sphere_light::SphereLight;
use crate::methods::bvh::Bvh;
use crate::methods::probe::certain_by_pixel;
use crate::methods::shadow_rays::{Jitter, Sampling, RAY_EPS};
use glam::{DVec3, Vec3};
use rayon::prelude::*;

/// The BVH of `corners` (world) relative to the sphere's centre, in f32.
pub fn sphere_bvh(light: &SphereLight, corners: &[[DVec3; 3]]) -> Bvh {
    Bvh::build(
        corners
            .par_iter()
            .map(|t| t.map(|p| (p - light.center).as_vec3()))
            .collect(),
    )
}

/// The cap's sample pattern: `samples` strata of the unit square, shared
/// (`Jitter::Shared`) or per pixel (the probe's, `Jitter::PerReceiver`).
fn pattern(samples: u32, jitter: Jitter) -> Sampling {
    Sampling {
        light: LightShape::rect([1.0, 1.0]).samples(samples),
        t0: 0.0,
        jitter,
    }
}

/// The fraction of `sampling`'s rays from surface point `p` (normal `n`,
/// facing the camera) that reach the sphere, and the weighted fraction
/// (each ray by the cosine n · d: the cap is sampled uniformly in solid
/// angle, so that is its share of the irradiance; V where every ray lies
/// below the horizon); 0 inside it.
fn trace(bvh: &Bvh, light: &SphereLight, p: DVec3, n: DVec3, key: u64, s: &Sampling) -> [f32; 2] {
    if !light.is_outside(p) {
        return [0.0; 2];
    }
    let (c, r) = (light.center, light.radius);
    let mag = (1.0 + p.abs().max_element()) * RAY_EPSILON;
    let (na, nb) = s.light.grid;
    let mut clear = 0u32;
    let (mut w_clear, mut w_all) = (0f64, 0f64);
    for sb in 0..nb {
        for sa in 0..na {
            // The unit square's point (shifted from [-1/2, 1/2) to
            // [0, 1)) onto the unit disk by the concentric map, then the
            // disk onto the cap: 1 - cos θ = ρ² (1 - cos α), the azimuth
            // the disk's angle. Both maps keep areas, so equal strata keep
            // equal solid angles, and the strata stay compact (polar
            // strata in (1 - cos θ, φ) erred 0.0050 against Mitsuba on
            // contact_boxes' sphere at 256 samples).
            let (x, y) = s.sample(key, sa, sb);
            let (dx, dy) = disk::sample_point(1.0, (1, 1), 0, 0, x + 0.5, y + 0.5);
            let (dx, dy) = (f64::from(dx), f64::from(dy));
            let rho2 = (dx * dx + dy * dy).min(1.0);
            let turn = dy.atan2(dx) / std::f64::consts::TAU;
            let Some(d) = sphere::cap_direction(c, r, p, rho2, turn.rem_euclid(1.0)) else {
                continue;
            };
            let w = n.dot(d).max(0.0);
            w_all += w;
            let o = if n.dot(d) >= 0.0 {
                p + mag * n
            } else {
                p - mag * n
            };
            let t = sphere::cap_hit(c, r, o, d);
            if !(t.is_finite() && t > 0.0) {
                continue;
            }
            let t1 = (t * (1.0 - f64::from(RAY_EPS))) as f32;
            if !bvh.occluded((o - c).as_vec3(), d.as_vec3(), 0.0, t1) {
                clear += 1;
                w_clear += w;
            }
        }
    }
    let v = clear as f32 / (na * nb) as f32;
    [
        v,
        if w_all > 0.0 {
            (w_clear / w_all) as f32
        } else {
            v
        },
    ]
}

/// The visibility of each pixel of `hits` (flat indices into `g`, each
/// pixel's jitter key) under `light`, and its weighted visibility (`trace`):
/// `samples` rays over its cap, behind a `probe` where given (module doc;
/// a certain pixel's are its probe's 0 or 1, both). `bvh` from
/// `sphere_bvh`.
pub fn sphere_visibility(
    bvh: &Bvh,
    light: &SphereLight,
    g: &GBuffer,
    hits: &[usize],
    samples: u32,
    probe: Option<u32>,
) -> Vec<[f32; 2]> {
    let at = |k: usize| {
        (
            DVec3::from_array(g.position[k]),
            Vec3::from_array(g.normal[k]).as_dvec3(),
        )
    };
    // The call's token, read on this thread (it is thread-local): a
    // cancelled call skips its remaining pixels, and the orchestrator
    // returns the cancellation, not the image.
    let token = crate::cancel::current();
    let run = |pixels: &[usize], s: &Sampling| -> Vec<[f32; 2]> {
        pixels
            .par_iter()
            .with_min_len(16)
            .map(|&k| {
                if token.is_cancelled() {
                    return [1.0; 2];
                }
                let (p, n) = at(k);
                trace(bvh, light, p, n, k as u64, s)
            })
            .collect()
    };
    let fine = pattern(samples, Jitter::Shared);
    let Some(p) = probe.filter(|&p| p < samples) else {
        return run(hits, &fine);
    };
    let coarse = run(hits, &pattern(p, Jitter::PerReceiver));
    let probe: Vec<f32> = coarse.iter().map(|[v, _]| *v).collect();
    let certain = certain_by_pixel(hits, &probe, (g.width, g.height));
    let unsure: Vec<usize> = hits
        .iter()
        .zip(&certain)
        .filter(|(_, &c)| !c)
        .map(|(&k, _)| k)
        .collect();
    let traced = run(&unsure, &fine);
    let mut out = coarse;
    let mut next = traced.into_iter();
    for (v, &c) in out.iter_mut().zip(&certain) {
        if c {
            *v = [v[0]; 2];
        } else {
            *v = next.next().unwrap_or(*v);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plate_halfway_shades_the_cap_it_covers() {
        // A sphere of radius 1 at height 10 over a floor point at the
        // origin; a plate at height 5 covering directions within
        // atan(h / 5) of the axis. The cap's half-angle is asin(1/10).
        let light = SphereLight::new([0.0, 0.0, 10.0], 1.0).unwrap();
        let plate = |h: f64| {
            let q = |x: f64, y: f64| DVec3::new(x, y, 5.0);
            vec![
                [q(-h, -h), q(h, -h), q(h, h)],
                [q(-h, -h), q(h, h), q(-h, h)],
            ]
        };
        let g = GBuffer {
            width: 1,
            height: 1,
            depth: vec![1.0],
            position: vec![[0.0; 3]],
            normal: vec![[0.0, 0.0, 1.0]],
            mesh_id: vec![0],
            face: vec![0],
            bary: vec![[0.0; 2]],
        };
        let v = |h: f64| {
            let bvh = sphere_bvh(&light, &plate(h));
            sphere_visibility(&bvh, &light, &g, &[0], 1024, None)[0][0]
        };
        // Wider than the cap: umbra; far narrower: lit.
        assert_eq!(v(1.0), 0.0);
        assert_eq!(v(0.001), 1.0);
        // A square covering the cap's middle: about its share of the cap's
        // solid angle (a square of half-width 0.25 at 5 is ~0.05 rad a
        // side against the cap's 0.1002 rad radius: 4 (0.05)^2 / (pi 0.1^2)
        // = 0.318 of it).
        let share = 4.0 * (0.25f64 / 5.0).powi(2) / (std::f64::consts::PI * 0.1002f64.powi(2));
        assert!(
            (f64::from(v(0.25)) - (1.0 - share)).abs() < 0.02,
            "{}",
            v(0.25)
        );
        // Inside the sphere: dark.
        let inside = GBuffer {
            position: vec![[0.0, 0.0, 10.5]],
            ..g.clone()
        };
        let bvh = sphere_bvh(&light, &plate(0.001));
        assert_eq!(
            sphere_visibility(&bvh, &light, &inside, &[0], 16, None)[0],
            [0.0; 2]
        );
    }
}
