//! GPU against CPU on a small scene (needs a device: lavapipe in CI). Without
//! an adapter these tests say so and pass, unless SOFTSHADOW_REQUIRE_GPU=1
//! (set by scripts/test.sh, which installs lavapipe) makes that a failure.

use crate::geom::light::RectLight;
use crate::geom::mesh::MeshRef;
use crate::methods::Method;
use crate::pipeline::{self, MapSettings, ShadowResult};

fn device_or_skip() -> bool {
    match super::info() {
        Ok(_) => true,
        Err(e) => {
            assert!(
                std::env::var("SOFTSHADOW_REQUIRE_GPU").as_deref() != Ok("1"),
                "SOFTSHADOW_REQUIRE_GPU=1 but {e}"
            );
            eprintln!("skipped: {e}");
            false
        }
    }
}

/// A UV sphere (radius r at c) with `n` segments: curved, closed, with
/// silhouette edges at every angle.
fn sphere(c: [f64; 3], r: f64, n: u32) -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let mut v = vec![];
    let mut f = vec![];
    let rings = n / 2;
    for a in 0..=rings {
        let th = std::f64::consts::PI * a as f64 / rings as f64;
        for b in 0..n {
            let ph = 2.0 * std::f64::consts::PI * b as f64 / n as f64;
            v.push([
                c[0] + r * th.sin() * ph.cos(),
                c[1] + r * th.cos(),
                c[2] + r * th.sin() * ph.sin(),
            ]);
        }
    }
    for a in 0..rings {
        for b in 0..n {
            let (p, q) = (a * n + b, a * n + (b + 1) % n);
            f.push([p, p + n, q]);
            f.push([q, p + n, q + n]);
        }
    }
    (v, f)
}

fn floor() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let s = 4.0;
    (
        vec![[-s, 0.0, -s], [s, 0.0, -s], [s, 0.0, s], [-s, 0.0, s]],
        vec![[0, 1, 2], [0, 2, 3]],
    )
}

fn run(gpu: bool, passes: u32, method: Method) -> ShadowResult {
    run_at(gpu, passes, method, (64, 48))
}

fn run_at(gpu: bool, passes: u32, method: Method, (width, height): (usize, usize)) -> ShadowResult {
    let (ov, of) = sphere([0.1, 1.0, -0.2], 0.5, 24);
    let (rv, rf) = floor();
    let light = RectLight::new(
        [0.0, 4.0, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0],
    )
    .unwrap();
    let s = MapSettings {
        width,
        height,
        extent: None,
        occluder_resolution: None,
        passes,
        method,
    };
    let occ = MeshRef {
        vertices: &ov,
        faces: &of,
    };
    let rec = MeshRef {
        vertices: &rv,
        faces: &rf,
    };
    if gpu {
        super::from_meshes(occ, rec, &light.into(), &s).unwrap()
    } else {
        pipeline::from_meshes(occ, rec, &light.into(), &s).unwrap()
    }
}

fn same_bits(a: &[f32], b: &[f32]) -> usize {
    a.iter()
        .zip(b)
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count()
}

/// The paper's method as the GPU runs it (no hierarchy, f32 sums).
const SSM: Method = Method::Ssm {
    hierarchy: false,
    precision: crate::methods::ssm::Precision::F32,
};

#[test]
fn gpu_maps_are_the_cpu_maps_bit_for_bit() {
    if !device_or_skip() {
        return;
    }
    let methods = [
        Method::Ssm {
            hierarchy: false,
            precision: Default::default(),
        },
        Method::Bitmask {
            samples: 16,
            hierarchy: false,
        },
        Method::Bitmask {
            samples: 256,
            hierarchy: false,
        },
        Method::Exact { samples: 16 },
    ];
    for (passes, method) in [1, 2, 4].into_iter().flat_map(|p| methods.map(|m| (p, m))) {
        let c = run(false, passes, method);
        let g = run(true, passes, method);
        // The scene must exercise every map: covered texels and a penumbra.
        let covered = |m: &[f32]| m.iter().filter(|z| z.is_finite()).count();
        assert!(covered(&c.receiver) > 100);
        assert!(
            c.visibility
                .iter()
                .filter(|&&v| v > 0.01 && v < 0.99)
                .count()
                > 50
        );
        assert_eq!(same_bits(&c.receiver, &g.receiver), 0, "receiver");
        match (c.occluder_front, g.occluder_front) {
            (Some(a), Some(b)) => assert_eq!(same_bits(&a, &b), 0, "front, passes {passes}"),
            (None, None) => assert!(method.reads_input(crate::methods::Input::OccluderTriangles)),
            _ => panic!("front layers differ in presence"),
        }
        assert_eq!(c.occluder_middle.len(), g.occluder_middle.len());
        for (k, (a, b)) in c.occluder_middle.iter().zip(&g.occluder_middle).enumerate() {
            assert_eq!(same_bits(a, b), 0, "middle {k}, passes {passes}");
        }
        match (c.occluder_back, g.occluder_back) {
            (Some(a), Some(b)) => assert_eq!(same_bits(&a, &b), 0, "back, passes {passes}"),
            (None, None) => {}
            _ => panic!("back layers differ in presence"),
        }
        let dv: Vec<f32> = c
            .visibility
            .iter()
            .zip(&g.visibility)
            .map(|(a, b)| (a - b).abs())
            .collect();
        let max = dv.iter().fold(0f32, |m, &x| m.max(x));
        let mean = dv.iter().sum::<f32>() / dv.len() as f32;
        assert!(
            max <= 2e-3 && mean <= 1e-4,
            "passes {passes}: max {max}, mean {mean}"
        );
    }
}

#[test]
fn triangles_larger_than_an_invocations_loop_budget_are_drawn_whole() {
    // The floor's two triangles cover 300 x 300 texels: one invocation per
    // triangle would stop after 65535 loop iterations on lavapipe.
    if !device_or_skip() {
        return;
    }
    let c = run_at(false, 1, SSM, (300, 300));
    let g = run_at(true, 1, SSM, (300, 300));
    assert!(c.receiver.iter().all(|z| z.is_finite()));
    assert_eq!(same_bits(&c.receiver, &g.receiver), 0);
}

#[test]
fn depth_maps_cannot_be_traced() {
    // `exact` traces triangles, which depth maps do not have: refused as on
    // the CPU, before any GPU work.
    let z = vec![2f32; 64];
    let g = crate::geom::light::MapGrid::new(8, 8, [0.5, 0.5]).unwrap();
    let e = super::from_depth(
        &g,
        &g,
        [1.0, 1.0],
        &z,
        None,
        &z,
        Method::Exact { samples: 4 },
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("method:"), "{e}");
}
