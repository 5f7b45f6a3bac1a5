//! Exact visibility by ray casting: stratified light samples per receiver,
//! shadow rays against a BVH over the occluder triangles (`bvh.rs`), culled
//! by shafts and traced in packets of neighbouring receivers
//! (`shadow_rays.rs`), all cores.
//!
//! Not a soft shadow map: it reads the occluder triangles (not the occluder
//! maps) and the receiver points. It converges to the true visibility as
//! 1/sqrt(samples) (stratified: faster on smooth penumbrae), is deterministic
//! and free of per-pixel grain (every receiver's rays go to one jittered
//! pattern, a hash of the sample's index: `shadow_rays::Jitter`), and is the
//! in-package reference that needs no Mitsuba.
//!
//! Geometry is in light space (relative to the light's center, computed in
//! f64 and then stored in f32), so a scene far from the world origin keeps its
//! precision. The light is its shape at Z = 0 (geom/light_shape/: where the
//! samples lie).
//!
//! Its config (`ExactConfig`, its checks and its `MethodSpec`: name, string
//! form, resolution, capabilities row) is at the end of this file.

use super::config::{
    check_passes, CallContext, LooseOptions, MethodSpec, DEFAULT_SAMPLES, MAX_SAMPLES,
    PRECISION_SSM_ONLY,
};
use super::engine::{visibilities_weighted, Engine};
use super::info::{Kind, MethodInfo, OptionInfo, Value};
use super::kernel::Kernel;
use super::keywords::{count, KeywordForm, Keywords};
use super::probe::probed_visibilities;
use super::Input;
use super::{LightPoint, ShadowInputs, ShadowMethod};
use crate::backend::Backend;
use crate::error::{Error, Result};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightSamples;
pub use crate::trace::bvh::Bvh;
pub(crate) use crate::trace::shadow_rays::RAY_EPS;
use crate::trace::shadow_rays::{tile_order, Jitter, Sampling};
use glam::Vec3;

/// The exact method with `samples` light samples per receiver, decided by
/// `engine` (`engine.rs`); with a `probe` (rays), receivers whose first
/// `probe` samples (and their neighbours') agree keep that answer, the
/// others are decided by `engine` (`probe.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Exact {
    pub samples: u32,
    pub probe: Option<u32>,
    pub engine: Engine,
}

/// The light point (x, y) that `exact`'s ray of stratum (sa, sb) of
/// `light` (the light's sample pattern, `LightShape::samples`) goes to,
/// from any receiver (they share one pattern): for tracing the same rays
/// elsewhere (benchmarks/bvh_crates compares BVH crates on them).
pub fn light_sample(sa: u32, sb: u32, light: LightSamples) -> (f32, f32) {
    Sampling {
        light,
        t0: RAY_EPS,
        jitter: Jitter::Shared,
    }
    .sample(0, sa, sb)
}

impl Exact {
    /// The visibility of receivers `pts` (light-space points; `None`: lit;
    /// the jitter key is the index: a map's texel, as exact.wgsl's), traced
    /// in `order`; `grid` the map they are the texels of (None for points,
    /// which have no neighbours for a probe).
    fn shade(
        &self,
        inputs: &ShadowInputs,
        pts: &[Option<Vec3>],
        order: &[usize],
        grid: Option<&MapGrid>,
    ) -> Vec<f32> {
        let Some(tris) = inputs.occluder_triangles else {
            // Nothing to occlude with: callers check before (the pipeline
            // refuses exact without meshes), so this is all-lit by definition.
            return vec![1.0; pts.len()];
        };
        let bvh = Bvh::build(tris.to_vec());
        let sampling = |n, jitter| Sampling {
            light: inputs.light_shape.samples(n),
            t0: RAY_EPS,
            jitter,
        };
        let fine = sampling(self.samples, Jitter::Shared);
        match (self.probe, grid) {
            (Some(p), Some(g)) => probed_visibilities(
                &bvh,
                pts,
                |k| k as u64,
                order,
                (&fine, self.engine),
                &sampling(p, Jitter::PerReceiver),
                1.0,
                (g.width, g.height),
            ),
            _ => visibilities_weighted(self.engine, &bvh, pts, |k| k as u64, order, &fine, 1.0)
                .into_iter()
                .map(|[v, _]| v)
                .collect(),
        }
    }
}

/// A receiver texel's point in the kernels' light space (tangents times
/// depth), None where there is no receiver: where `exact`'s rays start
/// (the light view's error estimate starts its own there too).
pub(crate) fn light_point(p: &LightPoint) -> Option<Vec3> {
    (p.z.is_finite() && p.z > 0.0).then(|| Vec3::new(p.x * p.z, p.y * p.z, p.z))
}

/// Every texel's `light_point` on `grid`, its depth from the receiver map
/// `receiver`.
pub(crate) fn receiver_points(grid: &MapGrid, receiver: &[f32]) -> Vec<Option<Vec3>> {
    (0..grid.len())
        .map(|k| {
            light_point(&LightPoint {
                x: grid.x_of(k % grid.width) as f32,
                y: grid.y_of(k / grid.width) as f32,
                z: receiver[k],
            })
        })
        .collect()
}

/// `Exact` is its own kernel (`kernel.rs`): its options are all it runs.
impl Kernel for Exact {
    const READS: &'static [Input] = &[Input::OccluderTriangles];

    fn rays(&self) -> Option<(u32, Option<u32>, Engine)> {
        Some((self.samples, self.probe, self.engine))
    }

    fn implementation(&self) -> Box<dyn ShadowMethod> {
        Box::new(*self)
    }
}

impl ShadowMethod for Exact {
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32> {
        let g = &inputs.grid;
        let pts = receiver_points(g, inputs.receiver);
        self.shade(inputs, &pts, &tile_order(g.width, g.height), Some(g))
    }

    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
        let pts: Vec<Option<Vec3>> = points.iter().map(light_point).collect();
        let order: Vec<usize> = (0..pts.len()).collect();
        self.shade(inputs, &pts, &order, None)
    }
}

/// The fewest samples at which an unset `engine` is the masks (on the
/// CPU, without a probe). Measured with `benchmarks/bench_masks.py` on the
/// sixteen as-built scenes, both sets, one run each (docs/benchmarks/
/// masks_320x240.md, masks_640x480.md), the masks leaving a receiver to
/// the rays where its triangles would cost more (`masks/mod.rs`): at 256
/// samples they took 1.11-7.9x less time than the rays on every scene at
/// 320x240 (1.22-7.6x at 640x480; table_and_chairs' thin panels under a
/// 3 m light the least), at 1024 2.3-25x (2.3-26x). On the scale scenes
/// at 640x480 and 256 samples: mesh_125k 1.4x, mesh_2m 1.26x, many_meshes
/// 6.4x, crowd 7.6x less. A speed rule: the answer is the same either way
/// but for grazing rays. The eye view's; the light view's is
/// `MASKS_FROM_LIGHT_VIEW`.
pub const MASKS_FROM: u32 = 256;

/// `MASKS_FROM` in the light view (no camera), where the receivers lie on
/// the occluders: on the study's scenes at 256² (`scenes.SCENES`, one run,
/// medians of 3) the masks took more time than the rays at 256 samples on
/// bunny_floating (1.39x), bunny_on_floor (1.19x) and torus (1.53x), less
/// on square_plate (2.6x) and two_spheres (1.02x); at 1024 still more on
/// the bunnies (1.41x, 1.06x) and the torus (1.83x), and 3.4-5x less on
/// the other two. It stays where it was set from the eye view's tables.
pub const MASKS_FROM_LIGHT_VIEW: u32 = 1024;

/// Ray casting through a BVH of the occluder triangles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ExactConfig {
    pub samples: u32,
    /// Light samples of a first pass at every receiver (`probe.rs`); None:
    /// every receiver traces `samples`.
    pub probe: Option<u32>,
    /// How the samples are decided (`engine.rs`); None: resolved when run
    /// (`ExactConfig::engine_for`).
    pub engine: Option<Engine>,
}

/// Light samples of the option `arg` (`samples`, and a `probe`, which saves
/// time only when fewer than `samples` but is right with any): 1 to
/// MAX_SAMPLES.
pub fn check_exact_samples(arg: &str, n: i64) -> Result<u32> {
    if (1..=MAX_SAMPLES as i64).contains(&n) {
        Ok(n as u32)
    } else {
        Err(Error::invalid(
            arg,
            format!("must be in [1, {MAX_SAMPLES}], got {n}"),
        ))
    }
}

impl ExactConfig {
    pub fn new(samples: Option<i64>, probe: Option<i64>, engine: Option<&str>) -> Result<Self> {
        let samples = samples
            .map(|n| check_exact_samples("samples", n))
            .transpose()?
            .unwrap_or(DEFAULT_SAMPLES);
        let probe = probe.map(|p| check_exact_samples("probe", p)).transpose()?;
        let engine = engine
            .map(|e| {
                Engine::parse(e).ok_or_else(|| {
                    let names: Vec<&str> = Engine::ALL.iter().map(|e| e.name()).collect();
                    Error::invalid("engine", format!("must be one of {names:?}, got {e:?}"))
                })
            })
            .transpose()?;
        Ok(ExactConfig {
            samples,
            probe,
            engine,
        })
    }

    /// `samples` light samples at every receiver, no probe, the engine
    /// resolved when run.
    pub const fn of(samples: u32) -> Self {
        ExactConfig {
            samples,
            probe: None,
            engine: None,
        }
    }

    /// The engine that runs on `backend` in the eye view (`eye`) or the
    /// light view: the one given, else the masks on the CPU from
    /// `MASKS_FROM` samples (`MASKS_FROM_LIGHT_VIEW` in the light view),
    /// with or without a probe (the probe's own samples are rays; the
    /// receivers it is unsure of are decided by this engine), the rays
    /// otherwise (and on the GPU, whose kernel traces rays).
    pub fn engine_for(&self, backend: Backend, eye: bool) -> Engine {
        let from = if eye {
            MASKS_FROM
        } else {
            MASKS_FROM_LIGHT_VIEW
        };
        match self.engine {
            Some(e) => e,
            None if backend == Backend::Cpu && self.samples >= from => Engine::Masks,
            None => Engine::Rays,
        }
    }
}

impl Default for ExactConfig {
    fn default() -> Self {
        ExactConfig::of(DEFAULT_SAMPLES)
    }
}

impl KeywordForm for ExactConfig {
    fn from_keywords(k: &Keywords) -> Result<Self> {
        ExactConfig::new(k.int("samples")?, k.int("probe")?, k.str("engine")?)
    }
    fn keywords(&self) -> Vec<(&'static str, Value)> {
        vec![
            ("samples", count(Some(self.samples))),
            ("probe", count(self.probe)),
            (
                "engine",
                self.engine
                    .map_or(Value::Resolved, |e| Value::Str(e.name())),
            ),
        ]
    }
}

impl MethodSpec for ExactConfig {
    const NAME: &'static str = "exact";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        // `passes` beside "exact" is accepted and has no effect (the
        // string form always allowed it: it reads no layers).
        if let Some(p) = o.passes {
            check_passes(p)?;
        }
        for (given, opt) in [
            (o.occluder_resolution.is_some(), "occluder_resolution"),
            (o.hierarchy.is_some(), "hierarchy"),
        ] {
            if given {
                return Err(refuse(
                    opt,
                    "the occluder-map methods (\"ssm\", \"bitmask\"); \"exact\" traces the occluder triangles",
                ));
            }
        }
        if o.precision.is_some() {
            return Err(refuse("precision", PRECISION_SSM_ONLY));
        }
        ExactConfig::new(o.samples, None, None)
    }
    type Resolved = Self;
    type Kernel = Exact;
    fn kernel(&self) -> Exact {
        Exact {
            samples: self.samples,
            probe: self.probe,
            // Resolved configs hold their engine; an unresolved one's is
            // the CPU's in the light view (the eye view resolves first).
            engine: self.engine_for(Backend::Cpu, false),
        }
    }
    fn resolve(self, ctx: &CallContext) -> Result<Self::Resolved> {
        if ctx.depth_layers.is_some() {
            return Err(Error::invalid(
                "method",
                "\"exact\" traces the occluder triangles, which depth maps do not have; \
                 use soft_shadow_map with meshes",
            ));
        }
        if self.probe.is_some() && ctx.backend == Backend::Gpu {
            return Err(Error::invalid(
                "probe",
                "the GPU backend traces every sample at every receiver (it has no probe); \
                 use backend=\"cpu\" or leave probe unset",
            ));
        }
        if self.engine == Some(Engine::Masks) && ctx.backend == Backend::Gpu {
            return Err(Error::invalid(
                "engine",
                "the GPU backend traces rays (engine=\"rays\"); the masks run on the CPU: \
                 use backend=\"cpu\" or leave engine unset",
            ));
        }
        Ok(ExactConfig {
            engine: Some(self.engine_for(ctx.backend, ctx.eye)),
            ..self
        })
    }

    fn info() -> MethodInfo {
        MethodInfo {
            name: "exact",
            config: "Exact",
            summary: "Ray casting against the occluder triangles (a BVH) with stratified light \
                      samples, jittered deterministically: converges to the true visibility",
            // The kernel's (`Kernel::READS`).
            reads: Exact::READS.to_vec(),
            backends: Backend::built().to_vec(),
            options: vec![
                OptionInfo {
                    name: "samples",
                    kind: Kind::Int {
                        min: 1,
                        max: MAX_SAMPLES as i64,
                    },
                    default: Value::Int(DEFAULT_SAMPLES as i64),
                    default_doc: "256 (a 16x16 stratification)",
                    doc: "light samples per receiver",
                    restricted_on: vec![],
                },
                OptionInfo {
                    name: "probe",
                    kind: Kind::Int {
                        min: 1,
                        max: MAX_SAMPLES as i64,
                    },
                    default: Value::Resolved,
                    default_doc: "None: every receiver is decided on `samples`",
                    doc: "light samples of a first pass at every receiver (pixel, texel); one \
                          whose probe and whose 3x3 neighbours' probes all see the whole light \
                          or none of it keeps that answer, the others are decided on `samples` \
                          by `engine` (it saves time when fewer than `samples`; points given as arrays have no \
                          neighbours and trace every sample; the CPU only)",
                    restricted_on: vec![(Backend::Gpu, vec![Value::Resolved])],
                },
                OptionInfo {
                    name: "engine",
                    kind: Kind::Choice(Engine::ALL.iter().map(|e| e.name()).collect()),
                    default: Value::Resolved,
                    default_doc: "None: \"masks\" on the CPU from 256 samples in the eye view \
                                  and 1024 in the light view (behind a probe, for the receivers it \
                                  is unsure of), else \"rays\"",
                    doc: "how the samples are decided, with the same answer but for rays that \
                          graze an edge: \"rays\", a shadow ray a sample through the BVH (the \
                          reference); \"masks\", each receiver's samples marked by the \
                          triangles that cross its light, a cell of samples at a time (its cost \
                          grows with that geometry, not with the samples; the CPU only)",
                    restricted_on: vec![(
                        Backend::Gpu,
                        vec![Value::Resolved, Value::Str(Engine::Rays.name())],
                    )],
                },
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::MapGrid;
    use crate::geom::light_shape::LightShape;

    fn plate(z: f32, lo: [f32; 2], hi: [f32; 2]) -> Vec<[Vec3; 3]> {
        let v = [
            Vec3::new(lo[0], lo[1], z),
            Vec3::new(hi[0], lo[1], z),
            Vec3::new(hi[0], hi[1], z),
            Vec3::new(lo[0], hi[1], z),
        ];
        vec![[v[0], v[1], v[2]], [v[0], v[2], v[3]]]
    }

    #[test]
    fn plate_matches_the_closed_form_within_the_stratified_bound() {
        // Plate tangent [-0.1, 0.15] x [-0.05, 0.2] at depth 2, receivers at depth 4.
        let (zo, zr) = (2.0f64, 4.0f64);
        let tris = plate(
            zo as f32,
            [-0.1 * 2.0, -0.05 * 2.0],
            [0.15 * 2.0, 0.2 * 2.0],
        );
        let n = 24;
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let receiver = vec![zr as f32; n * n];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect([1.0, 1.0]),
            receiver: &receiver,
            occluder_layers: vec![],
            occluder_triangles: Some(&tris),
        };
        let samples = 1024;
        for engine in Engine::ALL {
            let v = Exact {
                samples,
                probe: None,
                engine,
            }
            .visibility_map(&inputs);
            let k = zr * zo / (zr - zo);
            let ov = |lo: f64, hi: f64, c: f64| {
                ((k * (hi - c) + 0.5).clamp(0.0, 1.0) - (k * (lo - c) + 0.5).clamp(0.0, 1.0))
                    .max(0.0)
            };
            let mut max = 0f64;
            for j in 0..n {
                for i in 0..n {
                    let (x, y) = (grid.x_of(i), grid.y_of(j));
                    let exact = 1.0 - ov(-0.1, 0.15, x) * ov(-0.05, 0.2, y);
                    max = max.max((v[j * n + i] as f64 - exact).abs());
                }
            }
            // A 32x32 stratification: the shadow's edges cross at most 2 x 32
            // strata per axis, each wrong by at most 1/1024 -> 4 * 32 / 1024.
            assert!(max <= 4.0 * 32.0 / 1024.0, "{engine:?}: max error {max}");
        }
    }

    #[test]
    fn deterministic_and_lit_without_occluders() {
        let tris = plate(2.0, [-0.3, -0.3], [0.3, 0.3]);
        let pts = [
            LightPoint {
                x: 0.05,
                y: 0.0,
                z: 4.0,
            },
            LightPoint {
                x: 0.0,
                y: 0.0,
                z: f32::INFINITY,
            },
        ];
        let grid = MapGrid::new(1, 1, [1.0, 1.0]).unwrap();
        let mk = |t| ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect([1.0, 1.0]),
            receiver: &[],
            occluder_layers: vec![],
            occluder_triangles: t,
        };
        let a = Exact {
            samples: 64,
            probe: None,
            engine: Engine::Rays,
        }
        .visibility_points(&mk(Some(&tris)), &pts);
        let b = Exact {
            samples: 64,
            probe: None,
            engine: Engine::Rays,
        }
        .visibility_points(&mk(Some(&tris)), &pts);
        assert_eq!(a, b);
        assert!(a[0] < 1.0 && a[1] == 1.0);
        let empty: Vec<[Vec3; 3]> = vec![];
        for engine in Engine::ALL {
            let exact = Exact {
                samples: 64,
                probe: None,
                engine,
            };
            assert_eq!(exact.visibility_points(&mk(Some(&tris)), &pts), a);
            assert_eq!(
                exact.visibility_points(&mk(Some(&empty)), &pts),
                vec![1.0, 1.0]
            );
        }
    }
}
