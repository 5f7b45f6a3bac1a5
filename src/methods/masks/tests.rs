//! The masks against `exact`'s rays on the same samples: random scenes of
//! the kinds users build (open meshes, flipped and mixed winding, shared
//! and T-junction edges, degenerate triangles, meshes through each other,
//! triangles touching the receivers and the light), one origin a receiver
//! (the light view) and two (the eye view's above/below starts).

use super::super::bvh::tests::rng;
use super::super::bvh::Bvh;
use super::super::shadow_rays::{
    tile_order, visibilities_weighted as traced, Jitter, Origins, RayOrigin, Sampling,
    SurfacePoint, RAY_EPS,
};
use super::visibilities_weighted as masked;
use crate::geom::light_shape::LightShape;
use glam::Vec3;

/// An eye-view receiver: origins a hair above and below a surface point,
/// the side plane its tangent plane (`eye::rays::RayStart`'s rule).
#[derive(Clone, Copy)]
struct Start {
    above: Vec3,
    below: Vec3,
    side: [f32; 3],
}

impl RayOrigin for Start {
    fn bounds(&self) -> (Vec3, Vec3) {
        (self.above.min(self.below), self.above.max(self.below))
    }
    fn origin(&self, x: f32, y: f32) -> Vec3 {
        if self.side[0] + x * self.side[1] + y * self.side[2] >= 0.0 {
            self.above
        } else {
            self.below
        }
    }
    const WEIGHTED: bool = true;
    fn weight(&self, x: f32, y: f32) -> f32 {
        SurfacePoint {
            p: 0.5 * (self.above + self.below),
            side: self.side,
        }
        .weight(x, y)
    }
    fn origins(&self) -> Origins {
        Origins::Two {
            above: self.above,
            below: self.below,
            side: self.side,
        }
    }
}

/// A random scene of `kind` between depth 0.3 and 3.5 (the light at 0),
/// receivers on a floor at depth 4 and a wall through the occluders.
fn scene(kind: u32, seed: u64) -> Vec<[Vec3; 3]> {
    let mut r1 = rng(seed);
    let mut v = |s: f32| Vec3::new((r1() - 0.5) * s, (r1() - 0.5) * s, 0.0);
    let mut r = rng(seed ^ 0xAA);
    let mut tris = vec![];
    let mut r2 = rng(seed ^ 0x55);
    let mut z = move || 0.3 + 3.2 * r2();
    match kind {
        // Open grids (height fields) with flipped and mixed winding.
        0 => {
            let n = 12;
            let zs: Vec<f32> = (0..(n + 1) * (n + 1)).map(|_| 1.5 + z() * 0.3).collect();
            let p = |i: usize, j: usize| {
                Vec3::new(
                    (i as f32 / n as f32 - 0.5) * 2.0,
                    (j as f32 / n as f32 - 0.5) * 2.0,
                    zs[j * (n + 1) + i],
                )
            };
            for j in 0..n {
                for i in 0..n {
                    let (a, b, c, d) = (p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1));
                    if (i * 7 + j * 3) % 5 == 0 {
                        tris.push([a, c, b]);
                        tris.push([a, d, c]);
                    } else {
                        tris.push([a, b, c]);
                        tris.push([a, c, d]);
                    }
                }
            }
        }
        // Random triangles of all sizes, some degenerate (a repeated
        // corner, collinear corners), some passing through each other.
        1 => {
            for k in 0..300 {
                let c = v(3.0) + Vec3::Z * z();
                let s = if k % 3 == 0 { 0.8 } else { 0.15 };
                let (a, b) = (v(s) + Vec3::Z * (z() - 1.9) * 0.2, v(s));
                match k % 17 {
                    0 => tris.push([c, c, c + a]),
                    1 => tris.push([c, c + a, c + 2.0 * a]),
                    _ => tris.push([c, c + a, c + b + Vec3::Z * 0.1]),
                }
            }
        }
        // Closed boxes touching and intersecting, and a T-junction strip.
        _ => {
            for _ in 0..12 {
                let c = v(2.5) + Vec3::Z * (1.0 + z() * 0.7);
                let h = Vec3::new(0.1 + 0.3 * r(), 0.1 + 0.3 * r(), 0.1 + 0.3 * r());
                tris.extend(cube(c, h));
            }
            // A long triangle whose edge the two short ones share a corner on.
            let (a, b, m) = (
                Vec3::new(-1.0, 0.2, 2.0),
                Vec3::new(1.0, 0.2, 2.0),
                Vec3::new(0.0, 0.2, 2.0),
            );
            tris.push([a, b, Vec3::new(0.0, 0.6, 2.0)]);
            tris.push([a, m, Vec3::new(-0.5, -0.3, 2.0)]);
            tris.push([m, b, Vec3::new(0.5, -0.3, 2.0)]);
        }
    }
    // The floor the receivers lie on, and a wall through the occluders.
    let f = |x: f32, y: f32| Vec3::new(x, y, 4.0);
    tris.push([f(-5.0, -5.0), f(5.0, -5.0), f(5.0, 5.0)]);
    tris.push([f(-5.0, -5.0), f(5.0, 5.0), f(-5.0, 5.0)]);
    let w = |y: f32, zz: f32| Vec3::new(0.9, y, zz);
    tris.push([w(-5.0, 0.5), w(5.0, 0.5), w(5.0, 4.0)]);
    tris.push([w(-5.0, 0.5), w(5.0, 4.0), w(-5.0, 4.0)]);
    tris
}

/// The 12 triangles of the box centred at `c` with half-sides `h`.
fn cube(c: Vec3, h: Vec3) -> Vec<[Vec3; 3]> {
    let p = |i: u32| {
        c + Vec3::new(
            if i & 1 == 0 { -h.x } else { h.x },
            if i & 2 == 0 { -h.y } else { h.y },
            if i & 4 == 0 { -h.z } else { h.z },
        )
    };
    let quads = [
        [0, 1, 3, 2],
        [4, 6, 7, 5],
        [0, 4, 5, 1],
        [2, 3, 7, 6],
        [0, 2, 6, 4],
        [1, 5, 7, 3],
    ];
    quads
        .iter()
        .flat_map(|q| [[p(q[0]), p(q[1]), p(q[2])], [p(q[0]), p(q[2]), p(q[3])]])
        .collect()
}

/// A w x w grid of receivers on the floor (depth 4, a hair above it toward
/// the light) and on the wall's light side.
fn floor_points(w: usize) -> Vec<Option<Vec3>> {
    (0..w * w)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            let x = (i as f32 + 0.5) / w as f32 * 4.0 - 2.0;
            let y = (j as f32 + 0.5) / w as f32 * 4.0 - 2.0;
            Some(if i % 9 == 4 {
                Vec3::new(0.9 - 1e-4, y, 0.6 + 3.2 * (j as f32 / w as f32))
            } else {
                Vec3::new(x, y, 4.0 - 1e-4)
            })
        })
        .collect()
}

/// Eye-view starts over the floor's points, the surface facing the light
/// (normal -Z, so every light point is above) or tilted so that the
/// tangent plane cuts the light.
fn starts(w: usize) -> Vec<Option<Start>> {
    let mut r = rng(99);
    floor_points(w)
        .into_iter()
        .enumerate()
        .map(|(k, p)| {
            let p = p.unwrap();
            let n = if k % 3 == 0 {
                Vec3::new(r() - 0.5, r() - 0.5, -0.3).normalize()
            } else {
                -Vec3::Z
            };
            let eps = 1e-4;
            Some(Start {
                above: p + n * eps,
                below: p - n * eps,
                // n · ((x, y, 0) - p) >= 0 above.
                side: [-n.dot(p), n.x, n.y],
            })
        })
        .collect()
}

/// The share of receivers whose V differs, and the largest |dV|, |dV_w|.
fn compare(a: &[[f32; 2]], b: &[[f32; 2]]) -> (usize, f32, f32) {
    let mut differ = 0;
    let (mut dv, mut dw) = (0f32, 0f32);
    for (x, y) in a.iter().zip(b) {
        if x[0] != y[0] {
            differ += 1;
        }
        dv = dv.max((x[0] - y[0]).abs());
        dw = dw.max((x[1] - y[1]).abs());
    }
    (differ, dv, dw)
}

fn sampling(shape: LightShape, n: u32, t0: f32) -> Sampling {
    Sampling {
        light: shape.samples(n),
        t0,
        jitter: Jitter::Shared,
    }
}

#[test]
fn the_same_bits_as_the_rays_on_random_scenes() {
    let w = 40;
    let order = tile_order(w, w);
    let (mut total, mut differ, mut penumbra) = (0usize, 0usize, 0usize);
    for kind in 0..3 {
        for seed in 0..2u64 {
            let bvh = Bvh::build(scene(kind, 11 + seed * 7 + u64::from(kind)));
            for (shape, n) in [
                (LightShape::rect([1.0, 0.7]), 64),
                (LightShape::rect([1.2, 1.2]), 256),
                (LightShape::Disk { radius: 0.5 }, 256),
                (LightShape::rect([0.8, 0.8]), 1024),
            ] {
                // The light view: one origin, segments from RAY_EPS.
                let s = sampling(shape, n, RAY_EPS);
                let pts = floor_points(w);
                let a = traced(&bvh, &pts, |k| k as u64, &order, &s, 1.0);
                let b = masked(&bvh, &pts, &order, &s, 1.0).unwrap();
                let (d, dv, _) = compare(&a, &b);
                assert!(dv <= 2.0 / n as f32, "kind {kind} n {n}: |dV| {dv}");
                total += a.len();
                differ += d;
                penumbra += a.iter().filter(|v| v[0] > 0.0 && v[0] < 1.0).count();
                // The eye view: two origins, segments from 0, weighted.
                let s = sampling(shape, n, 0.0);
                let st = starts(w);
                let a = traced(&bvh, &st, |k| k as u64, &order, &s, 0.0);
                let b = masked(&bvh, &st, &order, &s, 0.0).unwrap();
                let (d, dv, dw) = compare(&a, &b);
                assert!(dv <= 2.0 / n as f32, "kind {kind} n {n}: eye |dV| {dv}");
                assert!(dw <= 4.0 / n as f32, "kind {kind} n {n}: eye |dV_w| {dw}");
                total += a.len();
                differ += d;
                penumbra += a.iter().filter(|v| v[0] > 0.0 && v[0] < 1.0).count();
            }
        }
    }
    eprintln!("{differ} of {total} receivers differ ({penumbra} in a penumbra)");
    // The scenes have penumbrae to get wrong, and at most 0.1% differ.
    assert!(penumbra * 5 > total, "penumbra {penumbra} of {total}");
    assert!(
        differ * 1000 <= total,
        "{differ} of {total} receivers differ"
    );
}

#[test]
fn a_clear_light_is_lit_and_an_absent_receiver_keeps_absent() {
    let bvh = Bvh::build(vec![[
        Vec3::new(5.0, 5.0, 1.0),
        Vec3::new(6.0, 5.0, 1.0),
        Vec3::new(5.0, 6.0, 1.0),
    ]]);
    let s = sampling(LightShape::rect([1.0, 1.0]), 256, RAY_EPS);
    let pts = vec![Some(Vec3::new(0.0, 0.0, 3.0)), None];
    let v = masked(&bvh, &pts, &[0, 1], &s, 0.25).unwrap();
    assert_eq!(v, vec![[1.0, 1.0], [0.25, 0.25]]);
    let empty = Bvh::build(vec![]);
    assert_eq!(
        masked(&empty, &pts, &[0, 1], &s, 0.25).unwrap()[0],
        [1.0, 1.0]
    );
}

#[test]
fn a_plate_over_the_whole_light_is_an_umbra() {
    let big = cube(Vec3::new(0.0, 0.0, 1.5), Vec3::new(3.0, 3.0, 0.01));
    let bvh = Bvh::build(big);
    let s = sampling(LightShape::rect([1.0, 1.0]), 1024, RAY_EPS);
    let pts = vec![Some(Vec3::new(0.1, -0.2, 3.0))];
    assert_eq!(masked(&bvh, &pts, &[0], &s, 1.0), Some(vec![[0.0, 0.0]]));
}
