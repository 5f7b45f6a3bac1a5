//! The eye view on the GPU (`render(..., backend="gpu")`): `GpuEye`, the
//! twin of `eye::CpuEye` (src/eye/stages.rs) that `pipeline::eye_view`
//! runs, stage for stage, with the same answers.
//!
//! * First hits (`eye_hits.wgsl`): each pixel-centre ray o = 0 (eye-relative),
//!   d = `gbuffer::pixel_ray` (f32, uploaded) is cast through the camera BVH
//!   (`gbuffer::camera_bvh`, built on the CPU) for its nearest triangle,
//!   t in (0, best), as `Bvh::nearest` does; the slot comes back, is mapped to
//!   the input triangle (`Bvh::order`) and the G-buffer is built on the CPU
//!   in f64 (`gbuffer::from_hits`, shared). The cast's CPU twin is the
//!   camera BVH's `nearest` (the device tests find the same triangle at
//!   every pixel on lavapipe); the CPU's own G-buffer rasterizes the same
//!   pixel centres (`gbuffer::rasterized_hits`), so the two backends'
//!   G-buffers may differ where a pixel centre grazes an edge.
//! * Framing (CPU, shared with the CPU path: `eye::framing`):
//!   the light space, the depth unit, the triangles in kernel light space,
//!   the focused grid and its resolution.
//! * `exact` (`eye_rays.wgsl`): per visible point, stratified shadow rays
//!   from the two spawn_ray_to origins of `rays::ray_starts` (made on the
//!   CPU in f64, shared), t in (0, 1 - RAY_EPS), the jitter exact.rs's hash
//!   of the point's pixel (its flat index in the image) and the sample, as
//!   `rays::visibility`.
//! * `ssm`, `bitmask`: the occluder layers (front, peeled, back) rasterized
//!   on the device from the CPU's set-up triangles (`raster.wgsl`, bit for bit
//!   the CPU's `maps::occluder_layers`), the biased points and their
//!   tangent-plane bounds made on the CPU (`maps::shading_points`), sorted
//!   and cut into groups of 64 as `methods::gather::visibility_points` does
//!   (`point_order`,
//!   `point_group`), and shaded by the points mode of `gather.wgsl` (one
//!   workgroup per group, the group's window from its bounds, rows outward
//!   from its centre: `Kernel::shade_points`' traversal). No hierarchy, f32
//!   sums (configs resolve so on the GPU); then, on the CPU, maps::shade's
//!   last step (`maps::finish`: each point cut to its bound). Bitmask with
//!   closed gaps reads its micro-quads' corners, made on the CPU from the
//!   layers read back (`gather::layer_corners`, the CPU kernel's own
//!   function; stage "corners"), so its layers and its shading are two
//!   submissions.
//!   A hard light has no GPU map kernel and is refused (`exact` runs it,
//!   with one ray).
//!
//! Two submissions: the first hits (the CPU needs them to place everything
//! else), then the shading with one readback of the visibility (and maps);
//! three with closed gaps (the layers, then the shading).

use super::context::{gpu, Gpu};
use super::dispatch::{bind, groups_1d, module, pipeline, storage, uniform, upload};
use super::exact::{ExactParams, BUDGET, SAMPLES_PER_CHUNK};
use super::gather::{
    self, GatherBuffers, GpuGroup, GpuPoint, PointsBuffers, PointsParams, POINT_GROUP,
};
use super::light;
use super::raster::{GpuTri, RasterInput};
use super::readback::{submit_and_read, visibility, with_error_scopes, words};
use super::refusals::{check_method, check_side, point_light_on_gpu};
use super::shading::gather_params;
use super::timing::{merged, StageTimer};
use crate::backend::Backend;
use crate::error::{Error, Result};
use crate::eye::framing::resolve_at_camera;
use crate::eye::gbuffer::{self, GBuffer, SceneTriangles};
use crate::eye::maps::{self, LightTriangles};
use crate::eye::rays::{self, RayStart};
use crate::eye::{Bias, EyeCall, EyeMaps, EyeStages, Framed};
use crate::geom::camera::Camera;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::methods::exact::{Bvh, RAY_EPS};
use crate::methods::gather::{point_group, point_order, POINTS_PER_GROUP};
use crate::methods::shadow_mapping::config::ShadowMappingConfig;
use crate::methods::{Input, LightPoint, Method, MethodConfig};
use crate::raster::setup_triangles;
use crate::timing::{Stopwatch, Timings};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use rayon::prelude::*;
use std::sync::OnceLock;

/// The first-hit module: the 64-bit helpers, the light's sampling (which
/// exact.wgsl's ray caster calls), exact.wgsl (BVH access, Möller-Trumbore),
/// then eye_hits.wgsl.
pub const HITS_SOURCE: &str = concat!(
    include_str!("u64.wgsl"),
    "\n",
    include_str!("light_shape.wgsl"),
    "\n",
    include_str!("exact.wgsl"),
    "\n",
    include_str!("eye_hits.wgsl")
);
/// The shadow-ray module: the light's sampling, exact.wgsl's traversal and
/// jitter, then eye_rays.wgsl.
pub const RAYS_SOURCE: &str = concat!(
    include_str!("u64.wgsl"),
    "\n",
    include_str!("light_shape.wgsl"),
    "\n",
    include_str!("exact.wgsl"),
    "\n",
    include_str!("eye_rays.wgsl")
);

/// Loop iterations (nodes visited and triangles tested) a first-hit
/// invocation may run; lavapipe stops an invocation after 65535.
const HITS_BUDGET: u32 = 50_000;
/// Invocations per workgroup of the first hits and the shadow rays.
const GROUP: u32 = 64;

/// `HitsParams` of eye_hits.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct HitsParams {
    pub n: u32,
    pub budget: u32,
    pub _pad0: u32,
    pub _pad1: u32,
}

/// `RayStart` of eye_rays.wgsl: a point's two origins (kernel light space)
/// and the side test choosing between them; `valid` 0: visibility 0;
/// `key`: the jitter key, the point's pixel (`rays::visibility`'s).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct GpuRayStart {
    pub ax: f32,
    pub ay: f32,
    pub az: f32,
    pub valid: u32,
    pub bx: f32,
    pub by: f32,
    pub bz: f32,
    pub a0: f32,
    pub au: f32,
    pub av: f32,
    pub key: u32,
    pub _pad1: u32,
}

struct EyePipelines {
    hits: wgpu::ComputePipeline,
    rays: wgpu::ComputePipeline,
    rays_resolve: wgpu::ComputePipeline,
}

fn pipelines(device: &wgpu::Device) -> &'static EyePipelines {
    static P: OnceLock<EyePipelines> = OnceLock::new();
    P.get_or_init(|| {
        let h = module(device, "eye_hits.wgsl", HITS_SOURCE);
        let r = module(device, "eye_rays.wgsl", RAYS_SOURCE);
        EyePipelines {
            hits: pipeline(device, &h, "eye_hits"),
            rays: pipeline(device, &r, "eye_exact"),
            rays_resolve: pipeline(device, &r, "eye_exact_resolve"),
        }
    })
}

/// Refuses a buffer that one binding cannot hold.
fn fits(g: &Gpu, arg: &str, bytes: u64) -> Result<()> {
    if bytes > g.max_storage_binding {
        return Err(Error::too_large(
            arg,
            format!(
                "the eye view needs {bytes} bytes in one GPU buffer; the device binds at most {}; \
                 use backend=\"cpu\"",
                g.max_storage_binding
            ),
        ));
    }
    Ok(())
}

fn budget_error() -> Error {
    Error::gpu(
        "a ray visited more BVH nodes than one invocation may (lavapipe stops an \
         invocation after 65535 loop iterations); use backend=\"cpu\" for this scene",
    )
}

/// The eye view's stages on the GPU (`eye::EyeStages`): the first hits,
/// the shadow rays, the occluder layers and the gather on the device, the
/// framing shared with the CPU; the device's stage times are kept here
/// until the orchestrator asks for them.
#[derive(Default)]
pub struct GpuEye {
    device_timings: Timings,
}

impl EyeStages for GpuEye {
    const BACKEND: Backend = Backend::Gpu;

    // Refuses what the GPU cannot run before any GPU work: a config that
    // does not resolve there, a hard light for the map methods.
    fn check(&self, call: &EyeCall) -> Result<()> {
        let kernel = resolve_at_camera(call, Backend::Gpu)?.kernel();
        if !kernel.traces() && call.light.is_hard() {
            return Err(point_light_on_gpu("size"));
        }
        check_method(kernel)
    }

    fn first_hits(&mut self, camera: &Camera, scene: &SceneTriangles) -> Result<GBuffer> {
        let (hit, t) = first_hits(gpu()?, camera, scene)?;
        self.device_timings.extend(t);
        Ok(gbuffer::from_hits(camera, scene, &hit))
    }

    fn shadow_mapping(
        &mut self,
        call: &EyeCall,
        cfg: &ShadowMappingConfig,
        scene: &SceneTriangles,
        g: &GBuffer,
        sw: &mut Stopwatch,
    ) -> Result<Vec<f32>> {
        let (v, _) = super::shadow_mapping::render_prepared(
            gpu()?,
            call,
            cfg,
            scene,
            g,
            false,
            sw,
            &mut self.device_timings,
        )?;
        Ok(v)
    }

    fn trace(
        &mut self,
        f: &Framed,
        tris: Vec<[Vec3; 3]>,
        _camera: &Camera,
        samples: u32,
        sw: &mut Stopwatch,
    ) -> Result<Vec<f32>> {
        // Keyed by pixel, as the CPU's (`CpuEye::trace`).
        let starts: Vec<GpuRayStart> = rays::ray_starts(&f.space, f.unit, &f.points, &f.normals)
            .iter()
            .zip(&f.hits)
            .map(|(s, &pixel)| GpuRayStart::new(s, pixel))
            .collect();
        let (v, t) = exact_visibility(gpu()?, tris, &starts, samples, f.light_shape, sw)?;
        self.device_timings.extend(t);
        Ok(v)
    }

    fn shade_maps(
        &mut self,
        call: &EyeCall,
        f: &Framed,
        tris: &LightTriangles,
        grid: MapGrid,
        method: &MethodConfig,
        sw: &mut Stopwatch,
    ) -> Result<(Vec<f32>, EyeMaps)> {
        check_side("map_resolution", (grid.width, grid.height))?;
        let g = gpu()?;
        let kernel = method.kernel();
        let (v, m, t) = match (kernel, super::smoothies::options(kernel)) {
            // The one-layer methods' own kernels after the front layer
            // (front_layer.rs).
            (Method::Pcss { max_taps }, _) => {
                super::pcss::shade_points(g, f, tris, grid, max_taps, &call.bias, sw)?
            }
            (_, Some(s)) => super::smoothies::shade_eye(g, f, tris, grid, &s, &call.bias, sw)?,
            (kernel, None) => {
                shade_maps(g, f, tris, grid, method.passes(), kernel, &call.bias, sw)?
            }
        };
        self.device_timings.extend(t);
        Ok((v, m))
    }

    // Several submissions time some stages more than once: summed.
    fn timings(&mut self, host: Timings) -> Timings {
        let mut timings = host;
        timings.extend(std::mem::take(&mut self.device_timings));
        merged(timings)
    }
}

/// The triangle (input index) each pixel's ray hits first, cast on the
/// device; and the device's time ("gpu_first_hits").
pub(crate) fn first_hits(
    g: &Gpu,
    camera: &Camera,
    scene: &SceneTriangles,
) -> Result<(Vec<Option<u32>>, Timings)> {
    let bvh = gbuffer::camera_bvh(camera, scene);
    let n = camera.width * camera.height;
    fits(g, "resolution", n as u64 * 12)?;
    if n >= u32::MAX as usize {
        return Err(Error::too_large(
            "resolution",
            "too many pixels for the GPU",
        ));
    }
    let dirs: Vec<f32> = (0..n)
        .into_par_iter()
        .with_min_len(256)
        .flat_map_iter(|k| gbuffer::pixel_ray(camera, k).to_array())
        .collect();
    let mut sw = Stopwatch::new();
    let out = with_error_scopes(g, || {
        let device = &g.device;
        let p = pipelines(device);
        let nodes = upload(device, "camera bvh nodes", &bvh.node_words());
        let tris = upload(device, "camera bvh triangles", &bvh.triangle_floats());
        let dirs = upload(device, "ray directions", &dirs);
        let hits = storage(
            device,
            "first hits",
            n as u64 * 4,
            wgpu::BufferUsages::COPY_SRC,
        );
        let status = storage(
            device,
            "status",
            4,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let u = uniform(
            device,
            "hits params",
            &HitsParams {
                n: n as u32,
                budget: HITS_BUDGET,
                ..Default::default()
            },
        );
        let timer = StageTimer::new(g, 1);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("softshadow eye first hits"),
        });
        enc.clear_buffer(&status, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("first_hits"));
            let bg = bind(
                device,
                &p.hits,
                &[
                    None,
                    Some(&nodes),
                    Some(&tris),
                    None,
                    None,
                    None,
                    None,
                    Some(&status),
                    Some(&u),
                    Some(&dirs),
                    Some(&hits),
                ],
            );
            pass.set_pipeline(&p.hits);
            pass.set_bind_group(0, &bg, &[]);
            let (x, y) = groups_1d(n as u32, GROUP);
            pass.dispatch_workgroups(x, y, 1);
        }
        submit_and_read(
            g,
            enc,
            &timer,
            &[(&hits, n as u64 * 4), (&status, 4)],
            &mut sw,
        )
    })?;
    if words(&out.buffers[1])[0] != 0 {
        return Err(budget_error());
    }
    let order = bvh.order();
    let hit = words(&out.buffers[0])
        .into_iter()
        .map(|s| (s != u32::MAX).then(|| order[s as usize]))
        .collect();
    // Without timestamps the submission's wall time is named for its stage.
    let timings = out
        .device_timings
        .into_iter()
        .map(|(name, t)| {
            (
                if name == "gpu" {
                    "gpu_first_hits"
                } else {
                    name
                },
                t,
            )
        })
        .collect();
    Ok((hit, timings))
}

impl GpuRayStart {
    /// `rays::RayStart` of the point at flat index `pixel` of the image as
    /// eye_rays.wgsl reads it; `None`: not valid.
    pub fn new(s: &Option<RayStart>, pixel: usize) -> GpuRayStart {
        // An image has at most MAX_TEXELS < 2^32 pixels (`check_resolution`).
        let key = pixel as u32;
        match s {
            None => GpuRayStart {
                key,
                ..Default::default()
            },
            Some(s) => GpuRayStart {
                ax: s.above.x,
                ay: s.above.y,
                az: s.above.z,
                valid: 1,
                bx: s.below.x,
                by: s.below.y,
                bz: s.below.z,
                a0: s.side[0],
                au: s.side[1],
                av: s.side[2],
                key,
                _pad1: 0,
            },
        }
    }
}

/// `exact`'s visibility per ray start, through a BVH of `tris` (kernel
/// light space) on the device; and the device's stage times.
fn exact_visibility(
    g: &Gpu,
    tris: Vec<[Vec3; 3]>,
    starts: &[GpuRayStart],
    samples: u32,
    light_shape: LightShape,
    sw: &mut Stopwatch,
) -> Result<(Vec<f32>, Timings)> {
    let n = starts.len();
    if n == 0 {
        return Ok((vec![], vec![]));
    }
    fits(g, "resolution", n as u64 * size_of::<GpuRayStart>() as u64)?;
    let has_tris = !tris.is_empty();
    let bvh = Bvh::build(tris);
    let mut params = ExactParams {
        rec_w: n as u32,
        rec_h: 1,
        budget: BUDGET,
        has_tris: has_tris as u32,
        // rays.rs's segments: t in (0, 1 - RAY_EPS).
        t0: 0.0,
        t1: 1.0 - RAY_EPS,
        ..Default::default()
    };
    let r = light::ray_fields(light_shape, samples);
    (params.na, params.nb, params.size_x, params.size_y) = (r.na, r.nb, r.size_x, r.size_y);
    let (na, nb) = (params.na, params.nb);
    let bytes = n as u64 * 4;
    let out = with_error_scopes(g, || {
        let device = &g.device;
        let p = pipelines(device);
        let nodes = upload(device, "bvh nodes", &bvh.node_words());
        let tri_buf = upload(device, "bvh triangles", &bvh.triangle_floats());
        let start_buf = upload(device, "ray starts", starts);
        let seen = storage(device, "seen samples", bytes, wgpu::BufferUsages::COPY_DST);
        let status = storage(
            device,
            "status",
            4,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let vis = storage(device, "visibility", bytes, wgpu::BufferUsages::COPY_SRC);
        sw.lap("upload");
        let timer = StageTimer::new(g, 1);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("softshadow eye exact"),
        });
        enc.clear_buffer(&seen, 0, None);
        enc.clear_buffer(&status, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
            let groups = groups_1d(n as u32, GROUP);
            pass.set_pipeline(&p.rays);
            for chunk_start in (0..na * nb).step_by(SAMPLES_PER_CHUNK as usize) {
                let u = uniform(
                    device,
                    "exact params",
                    &ExactParams {
                        chunk_start,
                        chunk_len: SAMPLES_PER_CHUNK.min(na * nb - chunk_start),
                        ..params
                    },
                );
                let bg = bind(
                    device,
                    &p.rays,
                    &[
                        None,
                        Some(&nodes),
                        Some(&tri_buf),
                        Some(&u),
                        None,
                        None,
                        Some(&seen),
                        Some(&status),
                        Some(&start_buf),
                    ],
                );
                pass.set_bind_group(0, &bg, &[]);
                pass.dispatch_workgroups(groups.0, groups.1, 1);
            }
            let u = uniform(device, "exact params", &params);
            let bg = bind(
                device,
                &p.rays_resolve,
                &[
                    None,
                    None,
                    None,
                    Some(&u),
                    None,
                    Some(&vis),
                    Some(&seen),
                    None,
                    Some(&start_buf),
                ],
            );
            pass.set_pipeline(&p.rays_resolve);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
        submit_and_read(g, enc, &timer, &[(&vis, bytes), (&status, 4)], sw)
    })?;
    if words(&out.buffers[1])[0] != 0 {
        return Err(budget_error());
    }
    Ok((visibility(&out.buffers[0])?, out.device_timings))
}

/// The points of `valid` (light space, `point_order`ed into `sorted`) as
/// the GPU reads them: every lane of every group of 64, inactive where no
/// receiver, and each group's bounds (`methods::gather::point_group`).
fn point_lanes(sorted: &[LightPoint]) -> (Vec<GpuPoint>, Vec<GpuGroup>) {
    let per: Vec<(GpuGroup, Vec<GpuPoint>)> = sorted
        .par_chunks(POINTS_PER_GROUP)
        .map(|chunk| {
            let mut lanes = vec![GpuPoint::default(); POINTS_PER_GROUP];
            let Some(pg) = point_group(chunk) else {
                return (GpuGroup::default(), lanes);
            };
            for (l, lane) in lanes.iter_mut().enumerate().take(chunk.len()) {
                if pg.wr[l].is_finite() {
                    *lane = GpuPoint {
                        x: pg.xr[l],
                        y: pg.yr[l],
                        wr: pg.wr[l],
                        live: 1,
                    };
                }
            }
            let b = GpuGroup {
                x_lo: pg.x_lo,
                x_hi: pg.x_hi,
                y_lo: pg.y_lo,
                y_hi: pg.y_hi,
                wr_min: pg.wr_min,
                live: 1,
                ..Default::default()
            };
            (b, lanes)
        })
        .collect();
    let groups = per.iter().map(|(b, _)| *b).collect();
    let lanes = per.into_iter().flat_map(|(_, l)| l).collect();
    (lanes, groups)
}

/// How wide (columns) and tall (outward steps) a group's window can be:
/// the window of `add_layer` / `add_row` with every texel at 1/depth
/// `w_bound` (at least any layer's nearest), with 2 texels of margin for
/// the f32 rounding of the device's coordinates.
fn window_bounds(
    grid: &MapGrid,
    light_shape: LightShape,
    w_bound: f64,
    groups: &[GpuGroup],
) -> (usize, usize) {
    let (hw, hh) = grid.half_texel();
    // A micro-patch reaches the light's half-extent times dw further.
    let [hx, hy] = light_shape.half_extent();
    let (w, h) = (grid.width as f64, grid.height as f64);
    let row = |y: f64| (1.0 - y / grid.ty) * 0.5 * h - 0.5;
    let col = |x: f64| (x / grid.tx + 1.0) * 0.5 * w - 0.5;
    // At most n, also for an infinite or NaN span.
    let capped = |v: f64, n: f64| if v < n { v.max(0.0) } else { n };
    let w_bound = w_bound * (1.0 + 1e-3);
    groups
        .iter()
        .filter(|b| b.live != 0 && w_bound > b.wr_min as f64)
        .fold((1, 1), |(c, s), b| {
            let dw = w_bound - b.wr_min as f64;
            let reach_y = hh + hy * dw;
            let reach_x = hw + hx * dw;
            let rows = row(b.y_lo as f64 - reach_y).ceil() - row(b.y_hi as f64 + reach_y).floor();
            let cols = col(b.x_hi as f64 + reach_x).ceil() - col(b.x_lo as f64 - reach_x).floor();
            (
                c.max(capped(cols + 3.0, w) as usize),
                s.max(capped(rows + 3.0, h) as usize),
            )
        })
}

/// The occluder grid's tables as the CPU kernel holds them at level 0
/// (`gather/hierarchy.rs`): column left edges in half-light units (from the
/// f32 edge, as `col_x0_scaled`), row centres; their offsets in `p`.
fn point_axes(og: &MapGrid, light_shape: LightShape, p: &mut gather::GatherParams) -> Vec<f32> {
    let mut data = Vec::with_capacity(og.width + og.height);
    p.ax_rec_x = 0;
    p.ax_rec_y = 0;
    p.ax_col_x0s = 0;
    data.extend(light::column_edges(og, light_shape));
    p.ax_row_y = data.len() as u32;
    data.extend((0..og.height).map(|j| og.y_of(j) as f32));
    data
}

/// The map methods on the device: `maps::shade`'s visibility per point and
/// maps, and the device's stage times.
#[allow(clippy::too_many_arguments)]
fn shade_maps(
    g: &Gpu,
    f: &Framed,
    tris: &LightTriangles,
    grid: MapGrid,
    passes: u32,
    method: Method,
    bias: &Bias,
    sw: &mut Stopwatch,
) -> Result<(Vec<f32>, EyeMaps, Timings)> {
    debug_assert!(method.reads_input(Input::OccluderLayers));
    let layer_len = grid.len();
    let texels = passes as u64 * layer_len as u64;
    if texels >= u32::MAX as u64 {
        return Err(Error::too_large(
            "map_resolution",
            "the occluder layers exceed the GPU's u32 offsets; use backend=\"cpu\"",
        ));
    }
    fits(g, "map_resolution", texels * 4)?;
    // maps::occluder_layers' near plane.
    let near = crate::raster::near_plane(&tris.verts);
    let occ_tris: Vec<GpuTri> = setup_triangles(&grid, &tris.verts, tris.faces, near)
        .iter()
        .map(GpuTri::from_setup)
        .collect();
    // The occluders' largest 1/depth, from their vertices in front of the
    // near plane (1/Z is linear over a triangle: largest at a vertex).
    let w_bound = tris
        .verts
        .iter()
        .fold(0f64, |m, q| m.max(1.0 / q.z.max(near)));
    // maps::shade's points: biased, `None` shaded as empty then 0.
    let sp = maps::shading_points(
        &f.space,
        f.unit,
        f.light_shape,
        &grid,
        &f.points,
        &f.pts_ls,
        &f.normals,
        bias,
        false,
    );
    let valid = &sp.points;
    let order = point_order(&grid, valid);
    let sorted: Vec<LightPoint> = order.iter().map(|&n| valid[n as usize]).collect();
    let (lanes, groups) = point_lanes(&sorted);
    let n_points = lanes.len();
    let acc_words = gather::accumulator_words(method, passes) as u64 * n_points as u64;
    fits(g, "resolution", (acc_words * 4).max(n_points as u64 * 16))?;
    let quads = gather::needs_corners(method);
    if quads {
        fits(g, "map_resolution", texels * 16)?;
    }
    let mut params = gather_params(&grid, &grid, f.light_shape, passes, method);
    params.rec_w = 0;
    params.rec_h = 0;
    params.layer0_offset = 0;
    let axes = point_axes(&grid, f.light_shape, &mut params);
    sw.lap("setup");
    let maps_bytes = texels * 4;
    let vis_bytes = n_points as u64 * 4;
    let out = with_error_scopes(g, || {
        let device = &g.device;
        let maps_buf = storage(device, "maps", maps_bytes, wgpu::BufferUsages::COPY_SRC);
        let raster = RasterInput::upload(g, &[], &occ_tris);
        let rows = storage(
            device,
            "row spans",
            passes as u64 * grid.height as u64 * 16,
            wgpu::BufferUsages::empty(),
        );
        let layer_w_max = storage(
            device,
            "layer w max",
            passes as u64 * 4,
            wgpu::BufferUsages::COPY_DST,
        );
        let acc = storage(
            device,
            "accumulators",
            acc_words * 4,
            wgpu::BufferUsages::COPY_DST,
        );
        let axes_buf = upload(device, "axes", &axes);
        let tables = gather::method_tables(method).map(|t| upload(device, "method tables", &t));
        let vis = storage(
            device,
            "visibility",
            vis_bytes,
            wgpu::BufferUsages::COPY_SRC,
        );
        let points_buf = upload(device, "points", &lanes);
        let groups_buf = upload(device, "point groups", &groups);
        let status = storage(
            device,
            "status",
            4,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        sw.lap("upload");
        let timer = StageTimer::new(g, 3);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("softshadow eye maps"),
        });
        enc.clear_buffer(&layer_w_max, 0, None);
        enc.clear_buffer(&acc, 0, None);
        enc.clear_buffer(&status, 0, None);
        raster.record_occluders(g, &mut enc, &timer, &maps_buf, 0, &grid, passes);
        // Closed gaps: the layers come back first, for their corners.
        let mut layers_read = None;
        let mut timer = timer;
        let mut w_bound = w_bound;
        let corners_buf = if quads {
            let first = submit_and_read(g, enc, &timer, &[(&maps_buf, maps_bytes)], sw)?;
            let m: Vec<f32> = words(&first.buffers[0])
                .into_iter()
                .map(f32::from_bits)
                .collect();
            let layer_maps: Vec<&[f32]> = m.chunks_exact(layer_len).collect();
            let corners = gather::layer_corners(&layer_maps, &grid);
            sw.lap("corners");
            w_bound = w_bound.max(corners.w_max as f64);
            let buf = upload(device, "corners", &corners.corners);
            sw.lap("upload");
            layers_read = Some(first);
            timer = StageTimer::new(g, 2);
            enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("softshadow eye quads"),
            });
            Some(buf)
        } else {
            None
        };
        let (cols, steps) = window_bounds(&grid, f.light_shape, w_bound, &groups);
        let (steps_per_chunk, chunks) = gather::points_chunking(cols, steps, method);
        let b = GatherBuffers {
            maps: &maps_buf,
            rows: &rows,
            layer_w_max: &layer_w_max,
            axes: &axes_buf,
            vis: &vis,
            tables: tables.as_ref(),
            acc: &acc,
            corners: corners_buf.as_ref(),
        };
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("row_stats"));
            gather::record_row_stats(device, &mut pass, method, &b, &params)?;
        }
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
            let pts = PointsBuffers {
                points: &points_buf,
                groups: &groups_buf,
                status: &status,
                params: PointsParams {
                    n_points: n_points as u32,
                    steps_per_chunk,
                    chunks,
                    _pad: 0,
                },
            };
            gather::record_shade_points(device, &mut pass, method, &b, &params, &pts)?;
        }
        match layers_read {
            None => submit_and_read(
                g,
                enc,
                &timer,
                &[(&maps_buf, maps_bytes), (&vis, vis_bytes), (&status, 4)],
                sw,
            ),
            Some(mut first) => {
                // The maps from the first readback, then the visibility and status.
                let out = submit_and_read(g, enc, &timer, &[(&vis, vis_bytes), (&status, 4)], sw)?;
                first.buffers.extend(out.buffers);
                first.device_timings.extend(out.device_timings);
                Ok(first)
            }
        }
    })?;
    if words(&out.buffers[2])[0] != 0 {
        return Err(Error::gpu(
            "an occluder window outgrew its bound on the GPU (a bug: please report it); \
             use backend=\"cpu\"",
        ));
    }
    let shaded = visibility(&out.buffers[1])?;
    let mut v = vec![1f32; valid.len()];
    for (&n, &s) in order.iter().zip(&shaded) {
        v[n as usize] = s;
    }
    // As maps::shade.
    maps::finish(&mut v, &sp.bound);
    // The layers back in the user's depth; the farthest starts at 0 bits
    // (before its atomicMax): 0 means empty.
    let m = words(&out.buffers[0]);
    let layers = (0..passes as usize)
        .map(|k| {
            let far_layer = passes >= 2 && k == passes as usize - 1;
            m[k * layer_len..(k + 1) * layer_len]
                .par_iter()
                .map(|&b| {
                    let z = if far_layer && b == 0 {
                        f32::INFINITY
                    } else {
                        f32::from_bits(b)
                    };
                    maps::user_depth(&f.space, f.unit, z)
                })
                .collect()
        })
        .collect();
    Ok((v, EyeMaps { grid, layers }, out.device_timings))
}

/// Points per group and per workgroup agree (gather.wgsl's POINTS_GROUP).
const _: () = assert!(POINT_GROUP as usize == POINTS_PER_GROUP);
