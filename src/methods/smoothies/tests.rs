//! The paper's claims, checked on a square plate over a floor (a 1 x 1
//! light; plate at depth 2 covering tangent [-1/4, 1/4]^2, its edges on texel
//! edges of a 64 x 64 map of half-extent 1/2; width 1 so t = 1/4 tangent
//! units = 16 texels), and robustness on odd meshes.

use super::*;

const N: usize = 64;
const A: f64 = 0.25;
const ZO: f64 = 2.0;
const TEXEL: f64 = 1.0 / N as f64;

fn grid() -> MapGrid {
    MapGrid::new(N, N, [0.5, 0.5]).unwrap()
}

fn sm(falloff: Falloff) -> Smoothies {
    Smoothies {
        width: 1.0,
        falloff,
    }
}

/// A square plate of tangent half-size a at depth z, two triangles facing the light.
fn plate(a: f64, z: f64, c: [f64; 2]) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let p = |x: f64, y: f64| DVec3::new((c[0] + x) * z, (c[1] + y) * z, z);
    let v = vec![p(-a, -a), p(-a, a), p(a, a), p(a, -a)];
    (v, vec![[0, 1, 2], [0, 2, 3]])
}

/// The plate's front map (exact: its edges fall on texel edges).
fn plate_front(g: &MapGrid) -> Vec<f32> {
    (0..g.len())
        .map(|k| {
            let (x, y) = (g.x_of(k % g.width), g.y_of(k / g.width));
            if x.abs() < A && y.abs() < A {
                ZO as f32
            } else {
                f32::INFINITY
            }
        })
        .collect()
}

/// Buffer and visibility map of the plate over a floor at depth zr, the
/// floor in the shadow map (as in the paper).
fn plate_case(zr: f64, falloff: Falloff) -> (Vec<f32>, Vec<f32>, SmoothieBuffer) {
    let g = grid();
    let (v, f) = plate(A, ZO, [0.0, 0.0]);
    let receiver = vec![zr as f32; g.len()];
    let front = shadow_map(&plate_front(&g), &receiver);
    let s = sm(falloff);
    let buf = s.buffer(&g, LightShape::rect([1.0, 1.0]), &front, &v, &f);
    let vis = s.visibility_map(&g, &front, &buf, &receiver);
    (vis, front, buf)
}

/// Tangent distance from (x, y) to the plate square.
fn dist_to_plate(x: f64, y: f64) -> f64 {
    let (dx, dy) = ((x.abs() - A).max(0.0), (y.abs() - A).max(0.0));
    dx.hypot(dy)
}

fn hard(front: &[f32], z: f32, k: usize) -> bool {
    front[k] < z
}

#[test]
fn umbra_equals_the_hard_shadow() {
    let g = grid();
    for zr in [4.0, 8.0] {
        let (vis, front, buf) = plate_case(zr, Falloff::Linear);
        assert!(buf.stats.texels > 0);
        for (k, &v) in vis.iter().enumerate() {
            assert_eq!(v == 0.0, hard(&front, zr as f32, k), "texel {k}");
        }
        assert!(vis.contains(&0.0));
    }
    // At points: v = 0 only where the texel holding the point is in the hard
    // shadow, and a point in the hard shadow is never fully lit.
    let (_, front, buf) = plate_case(4.0, Falloff::Linear);
    let s = sm(Falloff::Linear);
    let mut seed = 7u64;
    let mut rnd = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    };
    let pts: Vec<LightPoint> = (0..4000)
        .map(|_| LightPoint {
            x: rnd() as f32,
            y: rnd() as f32,
            z: 4.0,
        })
        .collect();
    let vp = s.visibility_points(&g, &front, &buf, &pts, &[]);
    for (p, v) in pts.iter().zip(&vp) {
        let (px, py) = g.to_pixel(p.x as f64, p.y as f64);
        let k = (py.floor() as usize).min(N - 1) * N + (px.floor() as usize).min(N - 1);
        if *v == 0.0 {
            assert!(hard(&front, p.z, k), "{p:?}");
        }
        if hard(&front, p.z, k) {
            assert!(*v <= 0.75 + 1e-6, "{p:?}: {v}");
        }
        assert!((0.0..=1.0).contains(v));
    }
}

#[test]
fn the_penumbra_lies_outside_the_hard_shadow_next_to_it() {
    let g = grid();
    for zr in [4.0, 8.0] {
        let (vis, front, _) = plate_case(zr, Falloff::Linear);
        let width = 0.25 * (1.0 - ZO / zr);
        let mut n = 0;
        for (k, &v) in vis.iter().enumerate() {
            let d = dist_to_plate(g.x_of(k % N), g.y_of(k / N));
            if v > 0.0 && v < 1.0 {
                n += 1;
                assert!(!hard(&front, zr as f32, k), "texel {k}");
                assert!(d > 0.0 && d < width + 1e-9, "texel {k}: {d} vs {width}");
            }
            if d > 0.0 && d < width - 1e-9 {
                assert!(v > 0.0 && v < 1.0, "texel {k} at {d}: {v}");
            }
            if d > width + 1e-9 {
                assert_eq!(v, 1.0, "texel {k} at {d}: beyond the penumbra");
            }
        }
        assert!(n > 0);
    }
}

/// Penumbra texels right of the plate along the row just above y = 0, and
/// the visibility of the first of them.
fn penumbra_row(vis: &[f32]) -> (usize, Vec<f32>) {
    let j = N / 2 - 1;
    let row: Vec<f32> = (N / 2..N).map(|i| vis[j * N + i]).collect();
    let pen: Vec<f32> = row
        .iter()
        .copied()
        .filter(|v| *v > 0.0 && *v < 1.0)
        .collect();
    (pen.len(), pen)
}

#[test]
fn the_penumbra_widens_with_the_receiver_distance_as_t_times_1_minus_b_over_r() {
    let mut widths = Vec::new();
    for zr in [4.0, 8.0] {
        let (vis, _, _) = plate_case(zr, Falloff::Linear);
        let (n, pen) = penumbra_row(&vis);
        let measured = n as f64 * TEXEL;
        let expect = 0.25 * (1.0 - ZO / zr);
        assert!(
            (measured - expect).abs() <= 2.0 * TEXEL,
            "{zr}: {measured} vs {expect}"
        );
        // Monotone from the edge outward.
        assert!(pen.windows(2).all(|w| w[0] < w[1]), "{pen:?}");
        widths.push(measured);
    }
    assert!(widths[1] > widths[0]);
    // With nothing behind the smoothies (r = inf), the penumbra is t wide.
    let g = grid();
    let (v, f) = plate(A, ZO, [0.0, 0.0]);
    let front = plate_front(&g);
    let s = sm(Falloff::Linear);
    let buf = s.buffer(&g, LightShape::rect([1.0, 1.0]), &front, &v, &f);
    let vis = s.visibility_map(&g, &front, &buf, &vec![4.0; g.len()]);
    let (n, _) = penumbra_row(&vis);
    assert!((n as f64 * TEXEL - 0.25).abs() <= 2.0 * TEXEL, "{n}");
}

#[test]
fn the_remap_divides_by_1_minus_b_over_r() {
    // Texel centre h from the plate's right edge: alpha = h / t, alpha' =
    // alpha / (1 - b/r) (a flipped 1 - r/b would be negative: 0).
    let g = grid();
    for zr in [4.0, 8.0] {
        let (vis, _, buf) = plate_case(zr, Falloff::Linear);
        let j = N / 2 - 1;
        for i in N / 2 + 16..N / 2 + 20 {
            let h = g.x_of(i) - A;
            let expect = (h / 0.25 / (1.0 - ZO / zr)).min(1.0);
            let k = j * N + i;
            assert!(
                (vis[k] as f64 - expect).abs() < 1e-5,
                "{zr} {i}: {} vs {expect}",
                vis[k]
            );
            if expect < 1.0 {
                assert!((buf.depth[k] as f64 - ZO).abs() < 1e-6);
            }
        }
    }
}

#[test]
fn points_interpolate_the_texels_bilinearly_and_depth_tests_both_maps() {
    let g = grid();
    let (vis, front, buf) = plate_case(4.0, Falloff::Linear);
    let s = sm(Falloff::Linear);
    let j = N / 2 - 1;
    let y = g.y_of(j) as f32;
    for i in N / 2 + 14..N / 2 + 26 {
        let (k, x0, x1) = (j * N + i, g.x_of(i), g.x_of(i + 1));
        let pts: Vec<LightPoint> = [0.0, 0.25, 0.5]
            .iter()
            .map(|f| LightPoint {
                x: (x0 + f * (x1 - x0)) as f32,
                y,
                z: 4.0,
            })
            .collect();
        let v = s.visibility_points(&g, &front, &buf, &pts, &[]);
        for (f, got) in [0.0f32, 0.25, 0.5].iter().zip(&v) {
            let expect = (1.0 - f) * vis[k] + f * vis[k + 1];
            assert!((got - expect).abs() < 1e-5, "{i} +{f}: {got} vs {expect}");
        }
    }
    // A receiver nearer the light than the smoothie (1.5 < b = 2) is lit;
    // one between the smoothie and the floor reads the penumbra, remapped
    // against the shadow map's r = 4 (not its own depth).
    let k = j * N + N / 2 + 18;
    assert!(buf.alpha[k] > 0.0 && buf.alpha[k] < 1.0);
    let at = |z: f32| s.visibility_map(&g, &front, &buf, &vec![z; g.len()])[k];
    assert_eq!(at(1.5), 1.0);
    assert_eq!(at(3.0), buf.alpha[k]);
}

#[test]
fn falloffs_are_as_specified_and_monotone() {
    let (l, s) = (Falloff::Linear, Falloff::Sine);
    assert!(s.apply(0.25) < 0.25 && s.apply(0.75) > 0.75);
    assert!((s.apply(0.25) - 0.146_446_6).abs() < 1e-6);
    assert!((s.apply(0.5) - 0.5).abs() < 1e-6);
    assert_eq!([s.apply(0.0), s.apply(1.0)], [0.0, 1.0]);
    assert_eq!(l.apply(0.3), 0.3);
    for f in Falloff::ALL {
        assert_eq!(Falloff::parse(f.name()), Some(f));
        let vals: Vec<f32> = (0..=1000).map(|k| f.apply(k as f32 / 1000.0)).collect();
        assert!(vals.windows(2).all(|w| w[0] <= w[1]), "{f:?}");
    }
    assert_eq!(Falloff::parse("cubic"), None);
    // The lookup applies it to the linear visibility.
    let (lin, _, _) = plate_case(4.0, Falloff::Linear);
    let (sin, _, _) = plate_case(4.0, Falloff::Sine);
    for (a, b) in lin.iter().zip(&sin) {
        assert!((s.apply(*a) - b).abs() < 1e-6);
    }
    assert_ne!(lin, sin);
}

#[test]
fn corners_are_round_and_present() {
    let g = grid();
    let (vis, _, buf) = plate_case(4.0, Falloff::Linear);
    assert_eq!(buf.stats.corners, 4);
    let width = 0.25 * 0.5; // 8 texels
                            // Diagonally outside each plate corner: texel centres (±(A + d), ±(A + d)).
    for (sx, sy) in [(1.0, 1.0), (-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)] {
        for m in 0..8usize {
            // Column and row 16.5 + m texels beyond the corner's x and y.
            let i = if sx > 0.0 {
                N / 2 + 16 + m
            } else {
                N / 2 - 17 - m
            };
            let j = if sy > 0.0 {
                N / 2 - 17 - m
            } else {
                N / 2 + 16 + m
            };
            let (x, y) = (g.x_of(i), g.y_of(j));
            let d = dist_to_plate(x, y);
            let v = vis[j * N + i] as f64;
            if d < width {
                assert!(
                    (v - d / width).abs() < 1e-5,
                    "({x}, {y}): {v} vs {}",
                    d / width
                );
            } else {
                assert_eq!(v, 1.0, "({x}, {y}) at {d}: round, not square");
            }
        }
    }
}

#[test]
fn the_light_size_sets_the_width_per_axis() {
    // Lv = 2 Lu: the penumbra across v is twice that across u.
    let g = grid();
    let (v, f) = plate(A, ZO, [0.0, 0.0]);
    let front = plate_front(&g);
    let s = sm(Falloff::Linear);
    assert_eq!(
        s.tangent_width(LightShape::rect([0.5, 1.0]), &v, &f),
        Some([0.125, 0.25])
    );
    let buf = s.buffer(&g, LightShape::rect([0.5, 1.0]), &front, &v, &f);
    let vis = s.visibility_map(&g, &front, &buf, &vec![4.0; g.len()]);
    let across_u = (N / 2..N).filter(|i| vis[(N / 2) * N + i] < 1.0 && vis[(N / 2) * N + i] > 0.0);
    let across_v = (0..N / 2).filter(|j| vis[j * N + N / 2] < 1.0 && vis[j * N + N / 2] > 0.0);
    let (nu, nv) = (across_u.count(), across_v.count());
    assert!(
        (nu as i64 - 8).abs() <= 1 && (nv as i64 - 16).abs() <= 1,
        "{nu} {nv}"
    );
}

#[test]
fn minimum_blending_keeps_the_winners_depth() {
    // Two plates side by side at depths 2 and 3: between them both smoothies
    // overlap; each texel keeps the smaller alpha and that smoothie's depth.
    let g = grid();
    let (mut v, mut f) = plate(0.1, 2.0, [-0.2, 0.0]);
    let (v2, f2) = plate(0.1, 3.0, [0.2, 0.0]);
    f.extend(f2.iter().map(|t| t.map(|i| i + v.len() as u32)));
    v.extend(v2);
    let front = vec![f32::INFINITY; g.len()];
    let s = sm(Falloff::Linear);
    let buf = s.buffer(&g, LightShape::rect([1.0, 1.0]), &front, &v, &f);
    let t = s
        .tangent_width(LightShape::rect([1.0, 1.0]), &v, &f)
        .unwrap()[0];
    let j = N / 2;
    let mut both = 0;
    for i in 0..N {
        let x = g.x_of(i);
        let (h1, h2) = (x - (-0.1), 0.1 - x); // outward of plate 1's right edge, plate 2's left
        let a1 = if h1 > 0.0 && h1 < t { h1 / t } else { 1.0 };
        let a2 = if h2 > 0.0 && h2 < t { h2 / t } else { 1.0 };
        if a1 < 1.0 && a2 < 1.0 {
            both += 1;
            let k = j * N + i;
            assert!((buf.alpha[k] as f64 - a1.min(a2)).abs() < 1e-6);
            let z = if a1 < a2 { 2.0 } else { 3.0 };
            assert!((buf.depth[k] as f64 - z).abs() < 1e-6, "{i}");
        }
    }
    assert!(both > 2);
}

#[test]
fn smoothies_behind_a_blocker_are_discarded() {
    // A small plate at depth 3 under a large one at depth 1: the small
    // plate's smoothies lie behind the large plate and leave no trace.
    let g = grid();
    let (mut v, mut f) = plate(0.45, 1.0, [0.0, 0.0]);
    let (v2, f2) = plate(0.1, 3.0, [0.0, 0.0]);
    f.extend(f2.iter().map(|t| t.map(|i| i + v.len() as u32)));
    v.extend(v2);
    let front = crate::raster::rasterize(&g, &v, &f, 1e-9, false).nearest;
    let s = sm(Falloff::Linear);
    let buf = s.buffer(&g, LightShape::rect([1.0, 1.0]), &front, &v, &f);
    assert_eq!(buf.stats.silhouette_edges, 8);
    // Only the large plate's smoothies (whose width is set by b_ref = 3 here).
    assert!(buf.stats.texels > 0);
    for (k, (a, z)) in buf.alpha.iter().zip(&buf.depth).enumerate() {
        let (x, y) = (g.x_of(k % N), g.y_of(k / N));
        if x.abs().max(y.abs()) < 0.44 {
            assert_eq!((*a, *z), (1.0, f32::INFINITY), "texel {k}");
        }
    }
}

fn finite_unit(v: &[f32]) -> bool {
    v.iter().all(|v| v.is_finite() && (0.0..=1.0).contains(v))
}

/// Buffer and visibility (floor at 4, front from the mesh's own raster) for a mesh.
fn run(v: &[DVec3], f: &[[u32; 3]]) -> (SmoothieBuffer, Vec<f32>) {
    let g = grid();
    // The rasterizer is handed only the faces it can read.
    let ok: Vec<[u32; 3]> = f
        .iter()
        .copied()
        .filter(|t| {
            t.iter()
                .all(|&i| v.get(i as usize).is_some_and(|p| p.is_finite()))
        })
        .collect();
    let front = crate::raster::rasterize(&g, v, &ok, 1e-9, false).nearest;
    let receiver = vec![4.0f32; g.len()];
    let front = shadow_map(&front, &receiver);
    let s = sm(Falloff::Sine);
    let buf = s.buffer(&g, LightShape::rect([1.0, 1.0]), &front, v, f);
    let vis = s.visibility_map(&g, &front, &buf, &receiver);
    assert!(finite_unit(&vis));
    assert!(buf
        .alpha
        .iter()
        .all(|a| a.is_finite() && (0.0..=1.0).contains(a)));
    assert!(buf.depth.iter().all(|z| !z.is_nan() && *z > 0.0));
    (buf, vis)
}

#[test]
fn odd_meshes_neither_panic_nor_give_nan() {
    // An open mesh: one triangle; 3 boundary silhouette edges, 3 corners.
    let tri = vec![
        DVec3::new(-0.4, -0.4, 2.0),
        DVec3::new(0.0, 0.4, 2.0),
        DVec3::new(0.4, -0.3, 2.0),
    ];
    let (buf, vis) = run(&tri, &[[0, 1, 2]]);
    assert_eq!((buf.stats.silhouette_edges, buf.stats.corners), (3, 3));
    assert!(vis.iter().any(|v| *v > 0.0 && *v < 1.0));

    // Degenerate faces (collinear, repeated index, out of range, a NaN
    // vertex) are ignored: the same buffer as the triangle alone.
    let mut v = tri.clone();
    v.push(DVec3::new(0.8, 0.8, 2.0)); // 3: collinear with 0 and 4
    v.push(DVec3::new(1.2, 1.2, 2.0)); // 4
    v.push(DVec3::new(f64::NAN, 0.0, 2.0)); // 5
    let faces = [[0, 1, 2], [0, 3, 4], [1, 1, 2], [0, 1, 99], [0, 1, 5]];
    let (buf2, _) = run(&v, &faces);
    assert_eq!(buf2, buf);

    // A non-manifold edge: three faces on edge (0, 1), two facing the light
    // and one away: a silhouette (both orientations), its other edges
    // boundaries.
    let mut v = tri.clone();
    v.push(DVec3::new(-0.6, 0.2, 2.5)); // 3
    v.push(DVec3::new(-0.2, 0.0, 1.5)); // 4
    let (buf, _) = run(&v, &[[0, 1, 2], [0, 1, 3], [1, 0, 4]]);
    assert_eq!(buf.stats.silhouette_edges, 7);

    // A vertex behind the light plane: clipped, nothing projected from behind.
    let v = vec![
        DVec3::new(-0.2, -0.2, 2.0),
        DVec3::new(0.2, -0.2, 2.0),
        DVec3::new(0.0, 0.5, -1.0),
    ];
    let (buf, vis) = run(&v, &[[0, 1, 2]]);
    assert_eq!(buf.stats.silhouette_edges, 3);
    assert!(buf.stats.texels > 0 && vis.iter().any(|v| *v > 0.0 && *v < 1.0));
    // All behind: nothing.
    let v: Vec<DVec3> = v
        .iter()
        .map(|p| DVec3::new(p.x, p.y, -p.z.abs() - 1.0))
        .collect();
    let (buf, vis) = run(&v, &[[0, 1, 2]]);
    assert_eq!(buf.stats.texels, 0);
    assert!(vis.iter().all(|v| *v == 1.0));

    // Two triangles sharing one vertex: 4 silhouette edges meet there (the
    // special case: a fan along the mean outward normal), 4 ordinary corners
    // elsewhere.
    let v = vec![
        DVec3::new(0.0, 0.0, 2.0),
        DVec3::new(-0.6, 0.3, 2.0),
        DVec3::new(-0.6, -0.3, 2.0),
        DVec3::new(0.6, -0.6, 2.0),
        DVec3::new(0.6, 0.0, 2.0),
    ];
    let (buf, vis) = run(&v, &[[0, 2, 1], [0, 4, 3]]);
    assert_eq!((buf.stats.silhouette_edges, buf.stats.corners), (6, 5));
    // Straight above and below the shared vertex the fan shades within t.
    let g = grid();
    let k = (N / 2 - 3) * N + N / 2;
    assert!(vis[k] > 0.0 && vis[k] < 1.0, "{}", vis[k]);

    // A huge width: bounded work (one map per smoothie at most), no NaN.
    let s = Smoothies {
        width: 1e12,
        falloff: Falloff::Linear,
    };
    let front = vec![4.0f32; g.len()];
    let b = s.buffer(&g, LightShape::rect([1.0, 1.0]), &front, &tri, &[[0, 1, 2]]);
    assert!(b.stats.texels <= 6 * g.len());
    assert!(finite_unit(&s.visibility_map(
        &g,
        &front,
        &b,
        &vec![4.0; g.len()]
    )));
}

#[test]
fn no_occluders_and_no_receivers_are_lit() {
    let g = grid();
    let front = vec![f32::INFINITY; g.len()];
    for s in [sm(Falloff::Linear), sm(Falloff::Sine)] {
        let buf = s.buffer(&g, LightShape::rect([1.0, 1.0]), &front, &[], &[]);
        assert_eq!(buf.stats, SmoothieStats::default());
        assert!(s
            .visibility_map(&g, &front, &buf, &vec![3.0; g.len()])
            .iter()
            .all(|v| *v == 1.0));
    }
    // Points with nothing to shade: z inf, NaN, 0, < 0 (even in the umbra).
    let (_, front, buf) = plate_case(4.0, Falloff::Linear);
    let s = sm(Falloff::Linear);
    let pts: Vec<LightPoint> = [f32::INFINITY, f32::NAN, 0.0, -1.0, 4.0]
        .iter()
        .map(|&z| LightPoint { x: 0.0, y: 0.0, z })
        .collect();
    assert_eq!(
        s.visibility_points(&g, &front, &buf, &pts, &[]),
        vec![1.0, 1.0, 1.0, 1.0, 0.0]
    );
    let mut receiver = vec![f32::INFINITY; g.len()];
    receiver[0] = f32::NAN;
    assert!(s
        .visibility_map(&g, &front, &buf, &receiver)
        .iter()
        .all(|v| *v == 1.0));
    // A point light (size 0) or width 0: no smoothies, the hard shadow.
    let (v, f) = plate(A, ZO, [0.0, 0.0]);
    for (s, size) in [
        (sm(Falloff::Linear), [0.0, 0.0]),
        (
            Smoothies {
                width: 0.0,
                falloff: Falloff::Linear,
            },
            [1.0, 1.0],
        ),
    ] {
        let buf = s.buffer(&g, LightShape::rect(size), &front, &v, &f);
        assert_eq!(buf.stats.texels, 0);
        let vis = s.visibility_map(&g, &front, &buf, &vec![4.0; g.len()]);
        assert!(vis.iter().all(|v| *v == 0.0 || *v == 1.0));
    }
}

/// A cube of half-size h centred at c, 8 vertices, 12 outward-wound triangles.
fn cube(c: DVec3, h: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let v: Vec<DVec3> = (0..8)
        .map(|k| {
            let s = |b: usize| if k & b != 0 { h } else { -h };
            c + DVec3::new(s(1), s(2), s(4))
        })
        .collect();
    // Faces as quads (outward normals by the right-hand rule).
    let quads = [
        [0, 2, 3, 1], // -z
        [4, 5, 7, 6], // +z
        [0, 1, 5, 4], // -y
        [2, 6, 7, 3], // +y
        [0, 4, 6, 2], // -x
        [1, 3, 7, 5], // +x
    ];
    let mut f = Vec::new();
    for q in quads {
        f.push([q[0], q[1], q[2]]);
        f.push([q[0], q[2], q[3]]);
    }
    (v, f)
}

#[test]
fn a_cube_has_a_silhouette_of_four_or_six_edges() {
    let g = grid();
    let front = vec![f32::INFINITY; g.len()];
    let s = sm(Falloff::Linear);
    let count = |v: &[DVec3], f: &[[u32; 3]]| {
        s.buffer(&g, LightShape::rect([1.0, 1.0]), &front, v, f)
            .stats
    };
    // Check the winding: every face's normal points away from the centre.
    let (v, f) = cube(DVec3::new(0.0, 0.0, 3.0), 0.3);
    for t in &f {
        let [a, b, c] = t.map(|i| v[i as usize]);
        assert!((b - a).cross(c - a).dot(a - DVec3::new(0.0, 0.0, 3.0)) > 0.0);
    }
    // On the axis: only the near face is lit, a square silhouette.
    let st = count(&v, &f);
    assert_eq!((st.silhouette_edges, st.corners), (4, 4));
    // Off the axis in x (two faces lit) or x and y (three): a hexagon.
    for c in [DVec3::new(1.0, 0.0, 3.0), DVec3::new(1.0, 0.8, 3.0)] {
        let (v, f) = cube(c, 0.3);
        let st = count(&v, &f);
        assert_eq!((st.silhouette_edges, st.corners), (6, 6), "{c}");
    }
    // The same cube with split vertices (4 per face) welds to the same silhouette.
    let (v, f) = cube(DVec3::new(1.0, 0.8, 3.0), 0.3);
    let mut vs = Vec::new();
    let mut fs = Vec::new();
    for t in &f {
        let base = vs.len() as u32;
        vs.extend(t.map(|i| v[i as usize]));
        fs.push([base, base + 1, base + 2]);
    }
    assert_eq!(count(&vs, &fs), count(&v, &f));
    // And the closed cube shades: umbra = its hard shadow, with a penumbra.
    let (buf, vis) = run(&v, &f);
    assert!(buf.stats.texels > 0 && vis.iter().any(|v| *v > 0.0 && *v < 1.0));
}

/// A receiver tilted to the light (1/z = 0.5 + 0.2 x) that is also the
/// shadow map, as in the eye view, with no smoothie over it: points moved
/// 0.1% toward the light find their own surface behind one tap or more of
/// the tent when tested at their own depth, and none on their tangent
/// plane; a plane of (0, 0) is the point's own depth, bit for bit.
#[test]
fn a_tilted_receiver_on_its_own_plane_does_not_shadow_itself() {
    let g = MapGrid::new(64, 64, [1.0, 1.0]).unwrap();
    let inv_z = |x: f64| 0.5 + 0.2 * x;
    let front: Vec<f32> = (0..g.len())
        .map(|k| (1.0 / inv_z(g.x_of(k % g.width))) as f32)
        .collect();
    let buf = SmoothieBuffer {
        depth: vec![f32::INFINITY; g.len()],
        alpha: vec![1.0; g.len()],
        stats: Default::default(),
    };
    // ∂(1/z)/∂px: 0.2 per unit of x, 2 tx / W units of x per texel.
    let plane = [(0.2 * 2.0 * g.tx / g.width as f64) as f32, 0.0];
    let s = sm(Falloff::Linear);
    let (mut own, mut planar) = (0, 0);
    for i in 0..100 {
        let x = -0.8 + 1.6 * (i as f64 * 0.618).fract();
        let y = -0.8 + 1.6 * (i as f64 * 0.377).fract();
        let p = [LightPoint {
            x: x as f32,
            y: y as f32,
            z: (0.999 / inv_z(x)) as f32,
        }];
        own += (s.visibility_points(&g, &front, &buf, &p, &[])[0] < 1.0) as u32;
        planar += (s.visibility_points(&g, &front, &buf, &p, &[plane])[0] < 1.0) as u32;
    }
    assert!(own > 40, "{own} of 100 shadowed at their own depth");
    assert_eq!(planar, 0);
    let p = [LightPoint {
        x: 0.1,
        y: 0.2,
        z: 1.9,
    }];
    assert_eq!(
        s.visibility_points(&g, &front, &buf, &p, &[]),
        s.visibility_points(&g, &front, &buf, &p, &[[0.0; 2]])
    );
}

/// Under a disk of radius ρ the smoothies are those of the square of side
/// 2ρ (the penumbra across any straight edge is the disk's diameter wide):
/// the same buffer and visibility, bit for bit.
#[test]
fn a_disk_is_shaded_as_its_diameter_wide_square() {
    let g = grid();
    let (v, f) = plate(A, ZO, [0.0, 0.0]);
    let receiver = vec![4.0f32; g.len()];
    let front = shadow_map(&plate_front(&g), &receiver);
    let s = sm(Falloff::Linear);
    let run = |shape| {
        let buf = s.buffer(&g, shape, &front, &v, &f);
        (
            s.visibility_map(&g, &front, &buf, &receiver),
            buf.stats.texels,
        )
    };
    let (disk, texels) = run(LightShape::disk(0.5));
    let (square, _) = run(LightShape::rect([1.0, 1.0]));
    assert!(texels > 0 && disk.iter().any(|v| *v > 0.05 && *v < 0.95));
    assert_eq!(disk, square);
    let (small, _) = run(LightShape::disk(0.25));
    assert_ne!(disk, small);
}
