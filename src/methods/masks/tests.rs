//! The masks against `exact`'s rays on the same samples: random scenes of
//! the kinds users build (open meshes, flipped and mixed winding, shared
//! and T-junction edges, degenerate triangles, meshes through each other,
//! triangles touching the receivers and the light), one origin a receiver
//! (the light view) and two (the eye view's above/below starts).

use crate::trace::bvh::tests::rng;
use crate::trace::bvh::Bvh;
use crate::trace::shadow_rays::{
    tile_order, visibilities_weighted as traced, Jitter, Origins, RayOrigin, Sampling,
    SurfacePoint, RAY_EPS,
};

/// The masks' answer with no receiver left to the rays.
fn masked<R: super::RayOrigin>(
    bvh: &Bvh,
    receivers: &[Option<R>],
    order: &[usize],
    s: &Sampling,
    absent: f32,
) -> Option<Vec<[f32; 2]>> {
    super::with_budget(bvh, receivers, order, s, absent, u32::MAX).map(|(v, left)| {
        assert!(left.is_empty());
        v
    })
}
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
        // Closed convex pieces (`pieces.rs`): turned boxes, thin slats and
        // plates, tetrahedra, a box wound inside out, boxes stacked on
        // shared corners, and what is not a piece beside them (an open
        // box, a closed L-shaped prism).
        3 => {
            for k in 0..14 {
                let c = v(2.5) + Vec3::Z * (0.6 + z() * 0.8);
                let h = match k % 3 {
                    0 => Vec3::new(0.6 * r() + 0.1, 0.01, 0.08),
                    1 => Vec3::new(0.4 * r() + 0.1, 0.3 * r() + 0.1, 0.01 + 0.02 * r()),
                    _ => Vec3::new(0.1 + 0.3 * r(), 0.1 + 0.3 * r(), 0.1 + 0.3 * r()),
                };
                let q =
                    glam::Quat::from_euler(glam::EulerRot::XYZ, 3.0 * r(), 3.0 * r(), 3.0 * r());
                let mut b: Vec<[Vec3; 3]> = cube(Vec3::ZERO, h)
                    .iter()
                    .map(|t| t.map(|p| c + q * p))
                    .collect();
                if k == 4 {
                    b.iter_mut().for_each(|t| t.swap(1, 2));
                }
                tris.extend(b);
            }
            for _ in 0..6 {
                let c = v(2.5) + Vec3::Z * (0.6 + z() * 0.8);
                let p = [v(0.6), v(0.6), v(0.6)].map(|d| c + d + Vec3::Z * (r() - 0.5) * 0.4);
                let t = [c, p[0], p[1], p[2]];
                tris.extend([
                    [t[0], t[1], t[2]],
                    [t[0], t[2], t[3]],
                    [t[0], t[3], t[1]],
                    [t[1], t[3], t[2]],
                ]);
            }
            // Two boxes stacked: the upper one's bottom corners are the
            // lower one's top corners, bit for bit.
            let (lo, hi) = (Vec3::new(0.3, -0.4, 2.6), Vec3::new(0.6, -0.1, 2.9));
            tris.extend(cube(0.5 * (lo + hi), 0.5 * (hi - lo)));
            tris.extend(cube(0.5 * (lo + hi) - Vec3::Z * 0.3, 0.5 * (hi - lo)));
            let mut open = cube(Vec3::new(-0.7, 0.6, 2.2), Vec3::new(0.3, 0.2, 0.05));
            open.truncate(10);
            tris.extend(open);
            tris.extend(l_prism(Vec3::new(0.5, 0.8, 1.8)));
        }
        // Solids (`solids.rs`): tessellated spheres, one inside out, one
        // through the wall the receivers lie on, one crossing the floor's
        // depth, a capped cylinder; and closed surfaces that are none: a
        // torus, a dented sphere, an open hemisphere.
        4 => {
            for k in 0..5 {
                let c = v(2.4) + Vec3::Z * (1.0 + z() * 0.6);
                let mut t = uv_sphere(c, 0.15 + 0.25 * r(), 5 + k, 8 + 3 * k);
                if k == 2 {
                    t.iter_mut().for_each(|t| t.swap(1, 2));
                }
                tris.extend(t);
            }
            tris.extend(uv_sphere(Vec3::new(0.9, 0.3, 2.0), 0.3, 8, 12));
            tris.extend(uv_sphere(Vec3::new(-1.2, -1.1, 3.85), 0.3, 6, 10));
            tris.extend(cylinder(Vec3::new(-0.6, 0.9, 2.4), 0.2, 0.5, 16));
            tris.extend(torus(Vec3::new(0.4, -0.7, 2.2), 0.35, 0.1, 16, 8));
            let mut dented = uv_sphere(Vec3::new(-0.3, -0.2, 1.4), 0.3, 6, 10);
            let dent = dented[20][1];
            for t in dented.iter_mut() {
                for p in t.iter_mut() {
                    if *p == dent {
                        *p = Vec3::new(-0.3, -0.2, 1.4) + (dent - Vec3::new(-0.3, -0.2, 1.4)) * 0.6;
                    }
                }
            }
            tris.extend(dented);
            let open = uv_sphere(Vec3::new(1.4, 1.2, 2.6), 0.25, 6, 10);
            tris.extend(open[..open.len() / 2].iter().copied());
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
pub(super) fn cube(c: Vec3, h: Vec3) -> Vec<[Vec3; 3]> {
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

/// A closed sphere of `rings` bands of `segs` quads (triangles at the
/// poles), wound outward.
pub(super) fn uv_sphere(c: Vec3, r: f32, rings: usize, segs: usize) -> Vec<[Vec3; 3]> {
    use std::f32::consts::{PI, TAU};
    let p = |i: usize, j: usize| {
        let (th, ph) = (
            PI * i as f32 / rings as f32,
            TAU * (j % segs) as f32 / segs as f32,
        );
        if i == 0 {
            return c + Vec3::Z * r;
        }
        if i == rings {
            return c - Vec3::Z * r;
        }
        c + r * Vec3::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos())
    };
    let mut t = vec![];
    for i in 0..rings {
        for j in 0..segs {
            let (a, b, d, e) = (p(i, j), p(i, j + 1), p(i + 1, j), p(i + 1, j + 1));
            if i > 0 {
                t.push([a, d, b]);
            }
            if i + 1 < rings {
                t.push([b, d, e]);
            }
        }
    }
    t
}

/// A closed cylinder along z of radius `r` and height `h`, `segs` sides,
/// its caps fanned from their centres.
pub(super) fn cylinder(c: Vec3, r: f32, h: f32, segs: usize) -> Vec<[Vec3; 3]> {
    use std::f32::consts::TAU;
    let p = |j: usize, top: bool| {
        let ph = TAU * (j % segs) as f32 / segs as f32;
        c + Vec3::new(r * ph.cos(), r * ph.sin(), if top { h } else { 0.0 })
    };
    let (bottom, top) = (c, c + Vec3::Z * h);
    let mut t = vec![];
    for j in 0..segs {
        t.push([p(j, false), p(j + 1, false), p(j + 1, true)]);
        t.push([p(j, false), p(j + 1, true), p(j, true)]);
        t.push([top, p(j, true), p(j + 1, true)]);
        t.push([bottom, p(j + 1, false), p(j, false)]);
    }
    t
}

/// A closed torus around z (not convex).
pub(super) fn torus(c: Vec3, big: f32, small: f32, segs: usize, sides: usize) -> Vec<[Vec3; 3]> {
    use std::f32::consts::TAU;
    let p = |i: usize, j: usize| {
        let (u, w) = (
            TAU * (i % segs) as f32 / segs as f32,
            TAU * (j % sides) as f32 / sides as f32,
        );
        let rr = big + small * w.cos();
        c + Vec3::new(rr * u.cos(), rr * u.sin(), small * w.sin())
    };
    let mut t = vec![];
    for i in 0..segs {
        for j in 0..sides {
            t.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            t.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    t
}

/// A closed L-shaped prism (not convex) with its corner at `c`.
pub(super) fn l_prism(c: Vec3) -> Vec<[Vec3; 3]> {
    let outline = [
        (0.0, 0.0),
        (0.4, 0.0),
        (0.4, 0.1),
        (0.1, 0.1),
        (0.1, 0.4),
        (0.0, 0.4),
    ];
    let p = |k: usize, top: bool| {
        c + Vec3::new(outline[k].0, outline[k].1, if top { 0.1 } else { 0.0 })
    };
    // The L as four triangles (fanned from the inner corner), twice.
    let fan = [(3, 0, 1), (3, 1, 2), (3, 4, 5), (3, 5, 0)];
    let mut t = vec![];
    for (a, b, d) in fan {
        t.push([p(a, false), p(d, false), p(b, false)]);
        t.push([p(a, true), p(b, true), p(d, true)]);
    }
    for k in 0..6 {
        let j = (k + 1) % 6;
        t.push([p(k, false), p(j, false), p(j, true)]);
        t.push([p(k, false), p(j, true), p(k, true)]);
    }
    t
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
    for kind in 0..5 {
        for seed in 0..2u64 {
            let bvh = Bvh::build(scene(kind, 11 + seed * 7 + u64::from(kind)));
            if kind == 3 {
                // 14 boxes (one inside out), 6 tetrahedra, 2 stacked.
                assert_eq!(super::pieces::Pieces::find(&bvh).len(), 22);
            }
            if kind == 4 {
                // 7 spheres and the cylinder (no torus, dent or hemisphere).
                let p = super::pieces::Pieces::find(&bvh);
                assert_eq!(p.solids(), 8);
            }
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

#[test]
fn closed_convex_pieces_are_found_and_nothing_else() {
    use super::pieces::{Pieces, NONE};
    let b = |x: f32| cube(Vec3::new(x, 0.0, 2.0), Vec3::new(0.2, 0.1, 0.05));
    let mut flipped = b(1.0);
    flipped.iter_mut().for_each(|t| t.swap(1, 2));
    let mut open = b(2.0);
    open.truncate(10);
    let tetra = {
        let t = [
            Vec3::new(3.0, 0.0, 2.0),
            Vec3::new(3.3, 0.0, 2.0),
            Vec3::new(3.0, 0.3, 2.0),
            Vec3::new(3.0, 0.0, 2.3),
        ];
        vec![
            [t[0], t[2], t[1]],
            [t[0], t[1], t[3]],
            [t[0], t[3], t[2]],
            [t[1], t[2], t[3]],
        ]
    };
    // What each group is: a piece or not.
    let groups: Vec<(Vec<[Vec3; 3]>, bool)> = vec![
        (b(0.0), true),
        (flipped, true),
        (open, false),
        (tetra, true),
        (l_prism(Vec3::new(4.0, 0.0, 2.0)), false),
        // Stacked on shared corners: two pieces.
        (cube(Vec3::new(5.0, 0.0, 2.0), Vec3::splat(0.1)), true),
        (cube(Vec3::new(5.0, 0.0, 2.2), Vec3::splat(0.1)), true),
    ];
    let tris: Vec<[Vec3; 3]> = groups.iter().flat_map(|(g, _)| g.clone()).collect();
    let bvh = Bvh::build(tris);
    let pieces = Pieces::find(&bvh);
    assert_eq!(pieces.len(), groups.iter().filter(|g| g.1).count());
    // Each input triangle's piece, through the tree's order.
    let mut of_input = vec![NONE; bvh.triangles().len()];
    for (slot, &i) in bvh.order().iter().enumerate() {
        of_input[i as usize] = pieces.of()[slot];
    }
    let mut at = 0;
    for (g, is) in &groups {
        let ids = &of_input[at..at + g.len()];
        if *is {
            assert!(
                ids[0] != NONE && ids.iter().all(|&k| k == ids[0]),
                "{ids:?}"
            );
        } else {
            assert!(ids.iter().all(|&k| k == NONE), "{ids:?}");
        }
        at += g.len();
    }
}

#[test]
fn a_piece_is_outlined_only_between_the_light_and_the_origin() {
    use super::pieces::{outline, Pieces};
    let bvh = Bvh::build(cube(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.3, 0.2, 0.1)));
    let pieces = Pieces::find(&bvh);
    let corners = pieces.corners(0);
    assert_eq!(corners.len(), 8);
    // Seen from above its middle: the outline is the top face's 4 edges
    // (its near face's corners hide the far ones inside).
    let c = outline(corners, Vec3::new(0.0, 0.0, 3.0), 0.0, 1.0 - RAY_EPS, None).unwrap();
    assert_eq!(c.n, 4);
    // Seen from the side: six.
    let c = outline(corners, Vec3::new(2.0, 1.5, 3.0), 0.0, 1.0 - RAY_EPS, None).unwrap();
    assert_eq!(c.n, 6);
    // An origin inside its depths, or one whose segments start past it: none.
    assert!(outline(corners, Vec3::new(0.0, 0.0, 1.05), 0.0, 1.0 - RAY_EPS, None).is_none());
    assert!(outline(corners, Vec3::new(0.0, 0.0, 3.0), 0.7, 1.0 - RAY_EPS, None).is_none());
}

#[test]
fn a_solid_is_outlined_by_its_silhouette_from_outside_only() {
    use super::pieces::Pieces;
    use super::solids::{outline, Scratch};
    let c = Vec3::new(0.0, 0.0, 1.0);
    let bvh = Bvh::build(uv_sphere(c, 0.3, 8, 12));
    let pieces = Pieces::find(&bvh);
    assert_eq!(pieces.len(), 1);
    let solid = pieces.solid(0).expect("a solid");
    assert!(pieces.live(0));
    let (corners, bounds) = (pieces.corners(0), pieces.bounds[0]);
    assert_eq!(corners.len(), 2 + 7 * 12);
    let mut s = Scratch::default();
    let t1 = 1.0 - RAY_EPS;
    // Seen from above its pole: the silhouette is one ring of 12 edges.
    assert!(outline(
        solid,
        corners,
        bounds,
        Vec3::new(0.0, 0.0, 3.0),
        0.0,
        t1,
        None,
        &mut s
    ));
    assert_eq!(s.planes.len(), 12);
    // Its polygon holds the projected centre and not a point past its rim
    // (from (0, 0, 3), the sphere spans about 0.3 * 3 / 2 of the light).
    let holds = |s: &Scratch, x: f32, y: f32| s.planes.iter().all(|p| p.at(x, y) >= 0.0);
    assert!(holds(&s, 0.0, 0.0));
    assert!(!holds(&s, 0.6, 0.0) && holds(&s, 0.35, 0.0));
    // From aside, with the eye view's side plane: one more plane.
    let side = super::cover::HalfPlane {
        a: 1.0,
        b: 0.1,
        c: 0.0,
        strict: false,
    };
    assert!(outline(
        solid,
        corners,
        bounds,
        Vec3::new(1.0, 0.5, 3.0),
        0.0,
        t1,
        Some(side),
        &mut s
    ));
    assert_eq!(s.planes.last(), Some(&side));
    // An origin within its depths, or segments starting past it: none.
    assert!(!outline(
        solid,
        corners,
        bounds,
        Vec3::new(0.0, 0.0, 1.1),
        0.0,
        t1,
        None,
        &mut s
    ));
    assert!(!outline(
        solid,
        corners,
        bounds,
        Vec3::new(0.0, 0.0, 3.0),
        0.7,
        t1,
        None,
        &mut s
    ));
    // A torus, a dented sphere, an open one, two spheres in one mesh
    // whose second is inside out half way: closed or not, no solids.
    let mut dented = uv_sphere(c, 0.3, 8, 12);
    let dent = dented[30][1];
    for t in dented.iter_mut() {
        for p in t.iter_mut() {
            if *p == dent {
                *p = c + (dent - c) * 0.7;
            }
        }
    }
    let mut mixed = uv_sphere(c + Vec3::X, 0.3, 8, 12);
    let half = mixed.len() / 2;
    mixed[..half].iter_mut().for_each(|t| t.swap(1, 2));
    let open = uv_sphere(c, 0.3, 8, 12)[1..].to_vec();
    for tris in [torus(c, 0.4, 0.1, 16, 8), dented, mixed, open] {
        let bvh = Bvh::build(tris);
        let p = Pieces::find(&bvh);
        assert_eq!(p.solids(), 0);
    }
}

#[test]
fn the_shapes_are_found_once_a_tree_shape_and_tested_again_where_they_move() {
    use super::pieces::Pieces;
    let mut tris = cube(Vec3::new(0.0, 0.0, 2.0), Vec3::new(0.3, 0.2, 0.1));
    tris.extend(uv_sphere(Vec3::new(1.0, 0.0, 2.0), 0.3, 6, 10));
    let bvh = Bvh::build(tris.clone());
    let first = Pieces::find(&bvh);
    assert_eq!((first.len(), first.solids()), (2, 1));
    // The same triangles moved (another light space): the tree refitted
    // from the first one's shape reuses its shapes, at the new corners.
    let moved: Vec<[Vec3; 3]> = tris
        .iter()
        .map(|t| t.map(|v| 1.5 * v + Vec3::new(0.2, -0.1, 0.5)))
        .collect();
    let refit = bvh.topology().refit(&moved).unwrap();
    let again = Pieces::find(&refit);
    assert!(std::ptr::eq(first.of(), again.of()), "found again");
    assert!(again.live(0) && again.live(1));
    assert_eq!(
        again.bounds[0][0],
        first.bounds[0][0] * 1.5 + Vec3::new(0.2, -0.1, 0.5)
    );
    // A box pressed in at one corner is no longer convex: its triangles
    // are marked one by one.
    let dent = tris[0][0];
    let pressed: Vec<[Vec3; 3]> = tris
        .iter()
        .map(|t| {
            t.map(|v| {
                if v == dent {
                    Vec3::new(0.0, 0.0, 2.0)
                } else {
                    v
                }
            })
        })
        .collect();
    let refit = bvh.topology().refit(&pressed).unwrap();
    let pressed = Pieces::find(&refit);
    let box_piece = pressed.of()[bvh.order().iter().position(|&i| i == 0).unwrap()];
    assert!(!pressed.live(box_piece));
}

/// A mesh of thousands of triangles far smaller than a cell of the
/// pattern: each receiver in its shadow would mark thousands of them, so
/// it is left to the rays once its work passes the budget (`MARK`), and
/// the engine's answer is the rays' where it is and the masks' elsewhere,
/// in both views.
#[test]
fn receivers_whose_triangles_cost_more_than_their_rays_are_left_to_the_rays() {
    use super::super::engine::{visibilities_weighted as engine, Engine};
    // A bumpy open grid of 2 x 100 x 100 triangles at depth 2 over part
    // of the receivers' light; the floor behind it.
    let n = 100;
    let p = |i: usize, j: usize| {
        let (x, y) = (i as f32 / n as f32, j as f32 / n as f32);
        Vec3::new(
            -1.5 + 1.6 * x,
            -1.0 + 2.0 * y,
            2.0 + 0.01 * ((i * 7 + j * 3) % 5) as f32,
        )
    };
    let mut tris = vec![];
    for j in 0..n {
        for i in 0..n {
            tris.push([p(i, j), p(i + 1, j), p(i + 1, j + 1)]);
            tris.push([p(i, j), p(i + 1, j + 1), p(i, j + 1)]);
        }
    }
    let f = |x: f32, y: f32| Vec3::new(x, y, 4.0);
    tris.push([f(-5.0, -5.0), f(5.0, -5.0), f(5.0, 5.0)]);
    tris.push([f(-5.0, -5.0), f(5.0, 5.0), f(-5.0, 5.0)]);
    let bvh = Bvh::build(tris);
    let w = 30;
    let order = tile_order(w, w);
    for (samples, t0) in [(64, RAY_EPS), (256, 0.0)] {
        let s = sampling(LightShape::rect([1.0, 1.0]), samples, t0);
        let pts = floor_points(w);
        let st = starts(w);
        let (_, left) = super::visibilities_weighted(&bvh, &pts, &order, &s, 1.0).unwrap();
        // Some are left to the rays, not all (the lit ones cost nothing).
        assert!(
            !left.is_empty() && left.len() < w * w,
            "{} left",
            left.len()
        );
        let a = traced(&bvh, &pts, |k| k as u64, &order, &s, 1.0);
        let b = engine(Engine::Masks, &bvh, &pts, |k| k as u64, &order, &s, 1.0);
        let (d, dv, _) = compare(&a, &b);
        assert!(
            d * 1000 <= a.len() && dv <= 2.0 / samples as f32,
            "{d} differ, |dV| {dv}"
        );
        // The receivers left to the rays have the rays' bits.
        assert!(left.iter().all(|&k| a[k] == b[k]));
        let a = traced(&bvh, &st, |k| k as u64, &order, &s, 0.0);
        let b = engine(Engine::Masks, &bvh, &st, |k| k as u64, &order, &s, 0.0);
        let (d, dv, dw) = compare(&a, &b);
        assert!(
            d * 1000 <= a.len() && dv <= 2.0 / samples as f32,
            "eye: {d} differ, |dV| {dv}"
        );
        assert!(dw <= 4.0 / samples as f32, "eye: |dV_w| {dw}");
        // What is left is traced whole: no receiver stays absent.
        assert!(b.iter().all(|v| v[0].is_finite() && v[1].is_finite()));
    }
}
