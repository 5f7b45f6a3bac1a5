//! Kernel benches: `cargo bench --bench kernels`.
//!
//! Every input is made here, in-process: a UV sphere (radius 0.3, centered
//! 1 unit over the floor) over an 8x8 floor quad, under a 1x1 light at height
//! 4 looking down (the conventions of `python/softshadow/scenes.py`:
//! `sphere`, `floor`, `default_light`), at 256².
//!
//! Three groups:
//! - `shadow_map`: the whole CPU call (framing, rasterization, shading) of
//!   each method through `softshadow::api::shadow_map`;
//! - `kernel`: the shading kernels alone on light-view maps rasterized once
//!   beforehand (front and back layers, flat receiver: whole tiles on one
//!   depth take the tile path);
//! - `raster`: the occluder rasterization alone (nearest and farthest maps).
//!
//! Sample counts and times are small so the whole run takes about a minute
//! on two cores; pass criterion's own options to change them.

use std::f64::consts::PI;
use std::hint::black_box;
use std::time::Duration;

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion};
use softshadow::api::{shadow_map, MeshCall};
use softshadow::frame::{light_space_triangles, ShadowResult};
use softshadow::geom::mesh::MeshRef;
use softshadow::methods::bitmask::Gaps;
use softshadow::methods::ssm::Precision;
use softshadow::methods::{BitmaskKernel, Exact, Method, ShadowInputs, SsmKernel};
use softshadow::raster::rasterize;
use softshadow::{AreaLight, BackendChoice, BitmaskConfig, ExactConfig, MethodConfig, SsmConfig};

const RESOLUTION: usize = 256;
const LIGHT_HEIGHT: f64 = 4.0;

/// An owned triangle mesh.
struct Mesh {
    vertices: Vec<[f64; 3]>,
    faces: Vec<[u32; 3]>,
}

impl Mesh {
    fn as_ref(&self) -> MeshRef<'_> {
        MeshRef {
            vertices: &self.vertices,
            faces: &self.faces,
        }
    }
}

/// A horizontal square (normal +y) of half-size `half` (scenes.py's `quad`).
fn quad(center: [f64; 3], half: f64) -> Mesh {
    let [cx, cy, cz] = center;
    Mesh {
        vertices: vec![
            [cx - half, cy, cz - half],
            [cx + half, cy, cz - half],
            [cx + half, cy, cz + half],
            [cx - half, cy, cz + half],
        ],
        faces: vec![[0, 2, 1], [0, 3, 2]],
    }
}

/// The 8x8 floor at y = 0 (scenes.py's `floor`).
fn floor() -> Mesh {
    quad([0.0, 0.0, 0.0], 4.0)
}

/// A UV sphere with `n` segments around and `n / 2` rings (scenes.py's
/// `sphere`: same vertex order and winding).
fn sphere(center: [f64; 3], radius: f64, n: u32) -> Mesh {
    let rings = (n / 2).max(2);
    let mut unit = vec![[0.0, 1.0, 0.0]];
    for r in 1..rings {
        let t = PI * r as f64 / rings as f64;
        for s in 0..n {
            let p = 2.0 * PI * s as f64 / n as f64;
            unit.push([t.sin() * p.cos(), t.cos(), t.sin() * p.sin()]);
        }
    }
    unit.push([0.0, -1.0, 0.0]);
    let vertices = unit
        .iter()
        .map(|u| [0, 1, 2].map(|k| u[k] * radius + center[k]))
        .collect::<Vec<_>>();
    let (top, bottom) = (0, vertices.len() as u32 - 1);
    let idx = |r: u32, s: u32| 1 + r * n + s % n;
    let mut faces = vec![];
    for s in 0..n {
        faces.push([top, idx(0, s + 1), idx(0, s)]);
        faces.push([bottom, idx(rings - 2, s), idx(rings - 2, s + 1)]);
        for r in 0..rings - 2 {
            let (a, b, c, d) = (idx(r, s), idx(r, s + 1), idx(r + 1, s + 1), idx(r + 1, s));
            faces.push([a, b, c]);
            faces.push([a, c, d]);
        }
    }
    Mesh { vertices, faces }
}

/// The 1x1 light at height 4 looking down (scenes.py's `default_light`).
fn default_light() -> AreaLight {
    AreaLight::rect(
        [0.0, LIGHT_HEIGHT, 0.0],
        [0.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 1.0],
    )
    .expect("a valid light")
}

struct Scene {
    occluders: Mesh,
    receivers: Mesh,
    light: softshadow::Light,
    rect: AreaLight,
}

fn scene() -> Scene {
    Scene {
        occluders: sphere([0.0, 1.0, 0.0], 0.3, 48),
        receivers: floor(),
        light: softshadow::Light::Area(default_light()),
        rect: default_light(),
    }
}

fn call<'a>(s: &'a Scene, method: MethodConfig) -> MeshCall<'a> {
    MeshCall {
        occluders: s.occluders.as_ref(),
        receivers: s.receivers.as_ref(),
        light: &s.light,
        resolution: (RESOLUTION as i64, RESOLUTION as i64),
        extent: None,
        method,
        backend: BackendChoice::Cpu,
        threads: None,
        estimate_error: None,
    }
}

fn bitmask(hierarchy: bool) -> MethodConfig {
    MethodConfig::Bitmask(BitmaskConfig::new(Some(256), None, None, Some(hierarchy), None).unwrap())
}

/// The methods the end-to-end group runs, by bench name.
fn configs() -> Vec<(&'static str, MethodConfig)> {
    vec![
        ("ssm", MethodConfig::Ssm(SsmConfig::default())),
        ("bitmask256", bitmask(false)),
        ("bitmask256_hierarchy", bitmask(true)),
        ("exact64", MethodConfig::Exact(ExactConfig::of(64))),
    ]
}

/// Refuses a scene that casts no shadow (a bench of nothing).
fn check_shadowed(name: &str, visibility: &[f32]) {
    assert_eq!(visibility.len(), RESOLUTION * RESOLUTION, "{name}");
    let shadowed = visibility.iter().filter(|&&v| v < 0.5).count();
    assert!(shadowed > 0, "{name}: no texel in shadow");
    assert!(
        visibility.iter().all(|v| (0.0..=1.0).contains(v)),
        "{name}: visibility outside [0, 1]"
    );
}

fn configure<'a>(c: &'a mut Criterion, group: &str) -> BenchmarkGroup<'a, WallTime> {
    let mut g = c.benchmark_group(group);
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    g
}

fn bench_shadow_map(c: &mut Criterion) {
    let s = scene();
    let mut g = configure(c, "shadow_map");
    for (name, method) in configs() {
        let call = call(&s, method);
        let run = shadow_map(&call).unwrap_or_else(|e| panic!("{name}: {e}"));
        check_shadowed(name, &run.output.visibility);
        g.bench_function(name, |b| {
            b.iter(|| shadow_map(black_box(&call)).unwrap().output.visibility)
        });
    }
    g.finish();
}

/// The two-pass light-view maps of the scene, rasterized once.
fn maps(s: &Scene) -> ShadowResult {
    let call = call(s, MethodConfig::Ssm(SsmConfig::default()));
    let r = shadow_map(&call).expect("the maps").output;
    assert!(r.occluder_front.is_some() && r.occluder_back.is_some());
    r
}

fn bench_kernels(c: &mut Criterion) {
    let s = scene();
    let maps = maps(&s);
    let (front, back) = (
        maps.occluder_front.as_deref().unwrap(),
        maps.occluder_back.as_deref().unwrap(),
    );
    let occ_ls = s.occluders.as_ref().to_light_space(&s.rect.into());
    let triangles = light_space_triangles(&occ_ls, &s.occluders.faces);
    let inputs = ShadowInputs {
        grid: maps.grid,
        occluder_grid: maps.occluder_grid,
        light_shape: s.rect.shape(),
        receiver: &maps.receiver,
        occluder_layers: vec![front, back],
        occluder_triangles: Some(&triangles),
    };
    let kernels = [
        (
            "ssm",
            Method::Ssm(SsmKernel {
                hierarchy: false,
                precision: Precision::F32,
            }),
        ),
        (
            "ssm_hierarchy",
            Method::Ssm(SsmKernel {
                hierarchy: true,
                precision: Precision::F32,
            }),
        ),
        (
            "bitmask256",
            Method::Bitmask(BitmaskKernel {
                samples: 256,
                hierarchy: false,
                gaps: Gaps::Closed,
            }),
        ),
        (
            "bitmask256_open",
            Method::Bitmask(BitmaskKernel {
                samples: 256,
                hierarchy: false,
                gaps: Gaps::Open,
            }),
        ),
        (
            "bitmask256_hierarchy",
            Method::Bitmask(BitmaskKernel {
                samples: 256,
                hierarchy: true,
                gaps: Gaps::Closed,
            }),
        ),
        (
            "exact64",
            Method::Exact(Exact {
                samples: 64,
                probe: None,
                engine: softshadow::methods::engine::Engine::Rays,
            }),
        ),
        (
            "masks64",
            Method::Exact(Exact {
                samples: 64,
                probe: None,
                engine: softshadow::methods::engine::Engine::Masks,
            }),
        ),
    ];
    let mut g = configure(c, "kernel");
    for (name, method) in kernels {
        let kernel = method.implementation();
        check_shadowed(name, &kernel.visibility_map(&inputs));
        g.bench_function(name, |b| {
            b.iter(|| kernel.visibility_map(black_box(&inputs)))
        });
    }
    g.finish();
}

fn bench_raster(c: &mut Criterion) {
    let s = scene();
    let grid = maps(&s).occluder_grid;
    let verts = s.occluders.as_ref().to_light_space(&s.rect.into());
    let faces = &s.occluders.faces;
    let d = rasterize(&grid, &verts, faces, 1e-9, true);
    assert!(d.nearest.iter().any(|z| z.is_finite()));
    assert!(d.farthest.is_some());
    let mut g = configure(c, "raster");
    g.bench_function("occluders_front_back", |b| {
        b.iter(|| rasterize(black_box(&grid), black_box(&verts), faces, 1e-9, true))
    });
    g.finish();
}

criterion_group!(benches, bench_shadow_map, bench_kernels, bench_raster);
criterion_main!(benches);
