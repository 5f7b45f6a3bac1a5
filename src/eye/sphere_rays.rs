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
//! (`methods/probe.rs`), the others trace every sample (the rays whatever
//! the engine: the masks need one pattern shared by every pixel).
//!
//! The rays go through the BVH of every triangle, relative to the sphere's
//! centre in f32, eight neighbouring pixels' rays of one stratum together
//! (`trace/packet.rs`, with its shadow cache; no shafts: each pixel's rays
//! go to its own cap). Each ray is the segment from its origin to its point
//! on the sphere, t in (0, 1 − RAY_EPS).

use super::gbuffer::GBuffer;
use super::rays::{tiled, RAY_EPSILON};
use crate::geom::light_shape::sphere::CapFrame;
use crate::geom::light_shape::{disk, sphere, LightShape};
use crate::geom::sphere_light::SphereLight;
use crate::methods::probe::certain_by_pixel;
use crate::trace::bvh::Bvh;
use crate::trace::packet::{Mask, Rays, LANES};
use crate::trace::shadow_rays::{Jitter, Sampling, RAY_EPS};
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

/// The cap sample of stratum (sa, sb) of `s` for the jitter key `key`:
/// [u1, cos φ, sin φ]. The unit square's point (shifted from [-1/2, 1/2)
/// to [0, 1)) goes onto the unit disk by the concentric map, then the disk
/// onto the cap: u1 = ρ² (so 1 − cos θ = ρ² (1 − cos α)), the azimuth the
/// disk's angle. Both maps keep areas, so equal strata keep equal solid
/// angles, and the strata stay compact (polar strata in (1 − cos θ, φ)
/// erred 0.0050 against Mitsuba on contact_boxes' sphere at 256 samples,
/// these 0.0048).
fn cap_sample(s: &Sampling, key: u64, sa: u32, sb: u32) -> [f64; 3] {
    let (x, y) = s.sample(key, sa, sb);
    let (dx, dy) = disk::sample_point(1.0, (1, 1), 0, 0, x + 0.5, y + 0.5);
    let (dx, dy) = (f64::from(dx), f64::from(dy));
    let rho = (dx * dx + dy * dy).sqrt();
    if rho > 0.0 {
        [(rho * rho).min(1.0), dx / rho, dy / rho]
    } else {
        [0.0, 1.0, 0.0]
    }
}

/// The shared pattern of `samples` strata (`Jitter::Shared`): its grid
/// na x nb and the cap sample of each stratum, sb * na + sa (`cap_sample`),
/// which every pixel traces; the GPU's table (gpu/sphere_rays.rs).
pub fn shared_cap_samples(samples: u32) -> ((u32, u32), Vec<[f64; 3]>) {
    let s = pattern(samples, Jitter::Shared);
    (s.light.grid, cap_table(&s))
}

/// Each stratum's cap sample of `s`'s pattern for jitter key 0, row-major.
fn cap_table(s: &Sampling) -> Vec<[f64; 3]> {
    let (na, nb) = s.light.grid;
    (0..nb)
        .flat_map(|sb| (0..na).map(move |sa| (sa, sb)))
        .map(|(sa, sb)| cap_sample(s, 0, sa, sb))
        .collect()
}

/// A ray's two origins from surface point `p` with normal `n` (after
/// Mitsuba's `spawn_ray_to`, as rays.rs's): moved off the surface along n,
/// for a ray leaving on n's side, and against it.
pub fn ray_origins(p: DVec3, n: DVec3) -> [DVec3; 2] {
    let mag = (1.0 + p.abs().max_element()) * RAY_EPSILON;
    [p + mag * n, p - mag * n]
}

/// A pixel's surface point `p` and normal `n` (facing the camera), and its
/// jitter key.
#[derive(Clone, Copy)]
struct Pixel {
    p: DVec3,
    n: DVec3,
    key: u64,
}

/// Wide levels above the leaf that blocked a packet's last blocked ray
/// whose subtree is searched first (`shadow_rays.rs`'s shadow cache).
const CACHE_LEVELS: u32 = 1;

/// The fraction of `s`'s rays from each of up to `LANES` pixels that reach
/// the sphere, and the weighted fraction (each ray by the cosine n · d: the
/// cap is sampled uniformly in solid angle, so that is its share of the
/// irradiance; V where every ray lies below the horizon); 0 for a pixel
/// inside the sphere. The pixels' rays of one stratum are traced together
/// (`packet.rs`), each the segment from its origin to its point on the
/// sphere, t in (0, 1 - RAY_EPS).
fn trace_packet(
    bvh: &Bvh,
    light: &SphereLight,
    pixels: &[Pixel],
    s: &Sampling,
    table: Option<&[[f64; 3]]>,
) -> [[f32; 2]; LANES] {
    let m = pixels.len();
    debug_assert!((1..=LANES).contains(&m));
    let (c, r) = (light.center, light.radius);
    let lane = |i: usize| pixels[i.min(m - 1)];
    let mut live: Mask = 0;
    for (i, px) in pixels.iter().enumerate() {
        if light.is_outside(px.p) {
            live |= 1 << i;
        }
    }
    let origins: [[DVec3; 2]; LANES] = std::array::from_fn(|i| ray_origins(lane(i).p, lane(i).n));
    let frames: [Option<CapFrame>; LANES] = std::array::from_fn(|i| CapFrame::new(c, r, lane(i).p));
    let (na, nb) = s.light.grid;
    let mut clear = [0u32; LANES];
    let (mut w_clear, mut w_all) = ([0f64; LANES], [0f64; LANES]);
    let mut cache: Option<u32> = None;
    for sb in 0..nb {
        for sa in 0..na {
            let mut open = live;
            // Lanes without a ray keep a harmless segment (masked off).
            let mut o = [Vec3::ZERO; LANES];
            let mut d = [Vec3::ONE; LANES];
            let mut w = [0f64; LANES];
            let shared = table.map(|t| t[(sb * na + sa) as usize]);
            for i in 0..LANES {
                let (Some(frame), true) = (frames[i], open & (1 << i) != 0) else {
                    open &= !(1 << i);
                    continue;
                };
                let px = lane(i);
                let [u1, cos_phi, sin_phi] =
                    shared.unwrap_or_else(|| cap_sample(s, px.key, sa, sb));
                let dir = frame.direction(u1, cos_phi, sin_phi);
                w[i] = px.n.dot(dir).max(0.0);
                w_all[i] += w[i];
                let origin = origins[i][usize::from(px.n.dot(dir) < 0.0)];
                let t = sphere::cap_hit(c, r, origin, dir);
                if !(t.is_finite() && t > 0.0) {
                    open &= !(1 << i);
                    continue;
                }
                o[i] = (origin - c).as_vec3();
                d[i] = (t * dir).as_vec3();
            }
            let hit_open = open;
            let rays = Rays::new(o, d);
            for from in [cache, Some(0)].into_iter().flatten() {
                if open == 0 {
                    break;
                }
                let (blocked, node) = bvh.occluded_lanes(from, &rays, open, 0.0, 1.0 - RAY_EPS);
                open &= !blocked;
                if let Some(k) = node {
                    cache = Some(bvh.wide_ancestor(k, CACHE_LEVELS));
                }
            }
            for i in 0..LANES {
                if hit_open & open & (1 << i) != 0 {
                    clear[i] += 1;
                    w_clear[i] += w[i];
                }
            }
        }
    }
    std::array::from_fn(|i| {
        if live & (1 << i) == 0 {
            return [0.0; 2];
        }
        let v = clear[i] as f32 / (na * nb) as f32;
        let vw = if w_all[i] > 0.0 {
            (w_clear[i] / w_all[i]) as f32
        } else {
            v
        };
        [v, vw]
    })
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
    let at = |k: usize| Pixel {
        p: DVec3::from_array(g.position[k]),
        n: Vec3::from_array(g.normal[k]).as_dvec3(),
        key: k as u64,
    };
    // The call's token, read on this thread (it is thread-local): a
    // cancelled call skips its remaining pixels, and the orchestrator
    // returns the cancellation, not the image.
    let token = crate::cancel::current();
    // Pixels in 4 x 2 tiles (`rays::tiled`), `LANES` neighbours a packet;
    // a shared pattern's cap samples computed once.
    let run = |pixels: &[usize], s: &Sampling| -> Vec<[f32; 2]> {
        let order = tiled(pixels, g.width, g.height);
        let table: Option<Vec<[f64; 3]>> = (s.jitter == Jitter::Shared).then(|| cap_table(s));
        let packets: Vec<(Vec<usize>, [[f32; 2]; LANES])> = order
            .par_chunks(LANES)
            .with_min_len(4)
            .map(|group| {
                if token.is_cancelled() {
                    return (group.to_vec(), [[1.0; 2]; LANES]);
                }
                let px: Vec<Pixel> = group.iter().map(|&j| at(pixels[j])).collect();
                (
                    group.to_vec(),
                    trace_packet(bvh, light, &px, s, table.as_deref()),
                )
            })
            .collect();
        let mut out = vec![[1.0f32; 2]; pixels.len()];
        for (group, v) in packets {
            for (&j, v) in group.iter().zip(v) {
                out[j] = v;
            }
        }
        out
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
