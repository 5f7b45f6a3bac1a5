//! ShadowMapping (Scherzer 2005) in the eye view on the GPU: the twin of
//! `eye::shadow_mapping::render` (src/eye/shadow_mapping.rs), stage for
//! stage, with the same answers.
//!
//! * On the CPU, shared with the CPU path (`eye::shadow_mapping::prepare`):
//!   the first hits' G-buffer (cast on the device, `eye::first_hits`), the
//!   intersection body, the projection (uniform, focused or LiSPSM, §3-§6,
//!   `geom/shadow_projection.rs`), the clipping of every triangle against the
//!   light frustum and its set-up in f64 (`raster::setup_triangles`: snapped
//!   vertices, f32 limb planes, the bias's offsets baked in, §4.2), the
//!   N·L test. Each point's projection into the map is made on the CPU in
//!   f64 too (`lookup::query`): in f32 a point's texel coordinate would be
//!   off by up to 1e-3 texel on a 16384² map and its depth by an ulp, which
//!   flips depth tests on the lit surfaces themselves (acne where the CPU
//!   has none); uploading (texel, fraction, f32 depth) keeps the nearest
//!   lookup's answer identical and PCF's within f32 rounding.
//! * On the device (`shadow_mapping.wgsl`): the depth map (nearest and,
//!   for Woo's midpoint, the second-nearest layer) scanned from the
//!   triangles binned per 16x16 tile, in chunks of at most `CHUNK`
//!   triangles per dispatch; the lookup per visible point (nearest texel or
//!   `pcf.rs`'s box of size×size bilinear taps, §4.1); the eye-space blur
//!   (§4.3), one dispatch per iteration.
//!
//! Twins: the depth map is the CPU's bit for bit where the f32 operations
//! are exact or single (hyperbolic depths; linear depths of orthographic
//! maps), and within an ulp where a product may be fused into an fma (the
//! linear depth's slope term under a perspective or LiSPSM projection): the
//! device tests count the differing texels. The nearest lookup and the blur
//! are the CPU's operations in f32 (the blur's f64 tolerance test made
//! exact by rounding its bound down to f32); PCF sums its weights in f32
//! where the CPU sums in f64 (|dV| below 1e-6).

use super::context::Gpu;
use super::dispatch::{bind, groups_1d, module, pipeline, storage, uniform, upload};
use super::readback::{submit_and_read, visibility, with_error_scopes, words};
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::eye::gbuffer::{GBuffer, SceneTriangles};
use crate::eye::shadow_mapping::{self as sm, Prepared};
use crate::eye::EyeCall;
use crate::methods::shadow_mapping::blur::spacing;
use crate::methods::shadow_mapping::config::{
    DepthBias, EyeSpaceBlur, ShadowMappingConfig, DEPTH_TOLERANCE,
};
use crate::methods::shadow_mapping::lookup::{box_origin, query, Query, TapPlane};
use crate::methods::shadow_mapping::raster::{DepthMap, Distribution, SetupTri};
use crate::timing::{Stopwatch, Timings};
use bytemuck::{Pod, Zeroable};
use std::sync::OnceLock;

/// The module: the 64-bit helpers, then shadow_mapping.wgsl.
pub const SOURCE: &str = concat!(
    include_str!("u64.wgsl"),
    "\n",
    include_str!("shadow_mapping.wgsl")
);

/// A raster tile's side in texels (the workgroup is TILE x TILE).
pub const TILE: usize = 16;
/// Triangles a raster invocation tests per dispatch: with the bounding-box
/// and edge tests unrolled, one loop iteration each, far below lavapipe's
/// 65535.
pub const CHUNK: u32 = 16_384;
const GROUP: u32 = 64;
/// The most workgroups along one dispatch dimension.
const MAX_GROUPS_PER_DIM: u32 = 65535;

/// `SmParams` of shadow_mapping.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct SmParams {
    pub width: u32,
    pub height: u32,
    pub tiles_x: u32,
    pub linear: u32,
    pub two_layers: u32,
    pub _pad0: u32,
    pub chunk_start: u32,
    pub chunk_len: u32,
    pub work_offset: u32,
    pub work_count: u32,
    pub midpoint: u32,
    pub pcf: u32,
    pub n_points: u32,
    pub img_w: u32,
    pub img_h: u32,
    pub inf_bits: u32,
}

/// `SmTri` of shadow_mapping.wgsl: a `SetupTri`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuSmTri {
    pub x: [i32; 3],
    pub y: [i32; 3],
    pub i0: u32,
    pub i1: u32,
    pub j0: u32,
    pub j1: u32,
    pub planes: [f32; 21],
    pub k: [f32; 7],
}

/// `SmPoint` of shadow_mapping.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct GpuSmPoint {
    pub pixel: u32,
    pub i: i32,
    pub j: i32,
    pub fx: f32,
    pub fy: f32,
    pub depth: f32,
    /// The receiver's depth gradient per texel and the offsets of the
    /// box's first texel from the point (`lookup::TapPlane`).
    pub gx: f32,
    pub gy: f32,
    pub ox: f32,
    pub oy: f32,
}

/// `BlurPixel` of shadow_mapping.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct GpuBlurPixel {
    pub spacing: i32,
    pub z: f32,
    pub tol: f32,
    pub surface: u32,
}

impl GpuSmTri {
    pub fn new(t: &SetupTri) -> GpuSmTri {
        let mut planes = [0f32; 21];
        for (p, plane) in [t.zh, t.iw, t.lw].iter().enumerate() {
            planes[7 * p] = plane.w_ref;
            planes[7 * p + 1..7 * p + 4].copy_from_slice(&plane.gx);
            planes[7 * p + 4..7 * p + 7].copy_from_slice(&plane.gy);
        }
        GpuSmTri {
            x: t.x,
            y: t.y,
            i0: t.i0,
            i1: t.i1,
            j0: t.j0,
            j1: t.j1,
            planes,
            k: [
                t.zh_offset,
                t.slope,
                t.constant,
                t.lw_a,
                t.lw_b,
                t.iw_a,
                t.iw_b,
            ],
        }
    }
}

struct SmPipelines {
    raster: wgpu::ComputePipeline,
    clear: wgpu::ComputePipeline,
    lookup: wgpu::ComputePipeline,
    blur: wgpu::ComputePipeline,
}

fn pipelines(device: &wgpu::Device) -> &'static SmPipelines {
    static P: OnceLock<SmPipelines> = OnceLock::new();
    P.get_or_init(|| {
        let m = module(device, "shadow_mapping.wgsl", SOURCE);
        SmPipelines {
            raster: pipeline(device, &m, "sm_raster"),
            clear: pipeline(device, &m, "sm_clear"),
            lookup: pipeline(device, &m, "sm_lookup"),
            blur: pipeline(device, &m, "sm_blur"),
        }
    })
}

/// The triangles binned per tile (CSR: `start[t]..start[t + 1]` of `list`,
/// in triangle order) and, per chunk of CHUNK triangles, the tiles that
/// have triangles in it (`work`, chunk c at `chunks[c]..chunks[c + 1]`).
pub struct Bins {
    pub tiles_x: usize,
    pub start: Vec<u32>,
    pub list: Vec<u32>,
    pub work: Vec<u32>,
    pub chunks: Vec<u32>,
}

pub fn bins(tris: &[SetupTri], (width, height): (usize, usize)) -> Result<Bins> {
    let (tx, ty) = (width.div_ceil(TILE), height.div_ceil(TILE));
    let mut count = vec![0u64; tx * ty + 1];
    let live = |t: &SetupTri| t.i0 <= t.i1 && t.j0 <= t.j1;
    let tiles = |t: &SetupTri| {
        let (a, b) = (t.i0 as usize / TILE, t.i1 as usize / TILE);
        let (c, d) = (t.j0 as usize / TILE, t.j1 as usize / TILE);
        (c..=d).flat_map(move |y| (a..=b).map(move |x| y * tx + x))
    };
    for t in tris.iter().filter(|t| live(t)) {
        for k in tiles(t) {
            count[k + 1] += 1;
        }
    }
    for k in 0..tx * ty {
        count[k + 1] += count[k];
    }
    let total = count[tx * ty];
    if total >= u32::MAX as u64 {
        return Err(Error::too_large(
            "resolution",
            "the shadow map's triangles cover more tiles than the GPU's u32 offsets; \
             use backend=\"cpu\"",
        ));
    }
    let start: Vec<u32> = count.iter().map(|&c| c as u32).collect();
    let mut fill: Vec<u32> = start.clone();
    let mut list = vec![0u32; total as usize];
    for (n, t) in tris.iter().enumerate().filter(|(_, t)| live(t)) {
        for k in tiles(t) {
            list[fill[k] as usize] = n as u32;
            fill[k] += 1;
        }
    }
    let longest = (0..tx * ty)
        .map(|k| start[k + 1] - start[k])
        .max()
        .unwrap_or(0);
    let mut work = Vec::new();
    let mut chunks = vec![0u32];
    for c in 0..longest.div_ceil(CHUNK) {
        work.extend(
            (0..tx * ty)
                .filter(|&k| start[k + 1] - start[k] > c * CHUNK)
                .map(|k| k as u32),
        );
        chunks.push(work.len() as u32);
    }
    Ok(Bins {
        tiles_x: tx,
        start,
        list,
        work,
        chunks,
    })
}

/// Workgroup counts (x, y) for `n` workgroups.
fn groups_2d(n: u32) -> (u32, u32) {
    if n <= MAX_GROUPS_PER_DIM {
        (n.max(1), 1)
    } else {
        let y = n.div_ceil(MAX_GROUPS_PER_DIM);
        (n.div_ceil(y), y)
    }
}

/// A point's lookup as the device reads it (`None`: lit, nothing to read).
pub fn point(
    q: Query,
    pixel: usize,
    pcf: u32,
    (w, h): (usize, usize),
    gradient: [f32; 2],
) -> Option<GpuSmPoint> {
    let Query::At { x, y, depth } = q else {
        return None;
    };
    // Positions far off the map are clamped to where every texel read is
    // still outside it (the answer is then 1, as the CPU's).
    let clamp = |v: f64, n: usize| v.clamp(-(pcf as f64) - 2.0, n as f64 + 1.0);
    let (i, j, fx, fy) = if pcf == 0 {
        (clamp(x.round(), w), clamp(y.round(), h), 0.0, 0.0)
    } else {
        // pcf.rs's box [p - size/2, p + size/2], p = x + 1/2: texels from
        // floor(a) on, the first weighted 1 - f and the last f.
        let ax = x + 0.5 - 0.5 * pcf as f64;
        let ay = y + 0.5 - 0.5 * pcf as f64;
        let (fx, fy) = (clamp(box_origin(x, pcf), w), clamp(box_origin(y, pcf), h));
        (fx, fy, (ax - fx).clamp(0.0, 1.0), (ay - fy).clamp(0.0, 1.0))
    };
    // The tangent plane over the box (a clamped box reads no texel of the
    // map: its offsets do not matter).
    let plane = TapPlane::new(x, y, depth, gradient, pcf);
    Some(GpuSmPoint {
        pixel: pixel as u32,
        i: i as i32,
        j: j as i32,
        fx: fx as f32,
        fy: fy as f32,
        depth,
        gx: gradient[0],
        gy: gradient[1],
        ox: plane.ox,
        oy: plane.oy,
    })
}

/// The largest f32 not above `v` (v >= 0 finite): for any f32 a,
/// `a <= bound_down(v)` exactly when `a as f64 <= v`.
pub fn bound_down(v: f64) -> f32 {
    let t = v as f32;
    if t as f64 > v {
        t.next_down()
    } else {
        t
    }
}

/// blur.rs's per-pixel data: the tap spacing, the depth and the tolerance.
pub fn blur_pixels(b: &EyeSpaceBlur, depth: &[f32]) -> (Vec<GpuBlurPixel>, bool) {
    let z0 = depth
        .iter()
        .copied()
        .filter(|z| z.is_finite() && *z > 0.0)
        .fold(f32::INFINITY, f32::min);
    let px = depth
        .iter()
        .map(|&z| GpuBlurPixel {
            spacing: spacing(b, z0, z).clamp(0, i32::MAX as i64) as i32,
            z: if z.is_finite() { z } else { 0.0 },
            tol: if z.is_finite() {
                bound_down(DEPTH_TOLERANCE * z as f64)
            } else {
                0.0
            },
            surface: z.is_finite() as u32,
        })
        .collect();
    (px, z0.is_finite())
}

/// What the device computed: the image's visibility and, if asked, the map.
pub struct SmOutput {
    pub visibility: Vec<f32>,
    pub map: Option<DepthMap>,
    pub timings: Timings,
}

/// The depth map, the lookups and the blur of `p` on the device.
pub fn run(
    g: &Gpu,
    cfg: &ShadowMappingConfig,
    p: &Prepared,
    gb: &GBuffer,
    want_map: bool,
    sw: &mut Stopwatch,
) -> Result<SmOutput> {
    let (w, h) = cfg.resolution;
    let texels = w as u64 * h as u64;
    let two_layers = cfg.bias == DepthBias::Midpoint;
    let fits = |arg: &str, bytes: u64| {
        if bytes > g.max_storage_binding {
            Err(Error::too_large(
                arg,
                format!(
                    "ShadowMapping needs {bytes} bytes in one GPU buffer; the device binds at \
                     most {}; use backend=\"cpu\"",
                    g.max_storage_binding
                ),
            ))
        } else {
            Ok(())
        }
    };
    fits("resolution", texels * 4)?;
    let tris: Vec<GpuSmTri> = p.triangles.iter().map(GpuSmTri::new).collect();
    fits("meshes", tris.len() as u64 * size_of::<GpuSmTri>() as u64)?;
    let b = bins(&p.triangles, cfg.resolution)?;
    fits("meshes", b.list.len() as u64 * 4)?;
    let pcf = cfg.filter.map_or(0, |f| f.size.max(1));
    let points: Vec<GpuSmPoint> = p
        .lookups
        .iter()
        .filter_map(|&(k, q, gradient)| {
            point(
                query(&p.projection, cfg.bias, w, h, q),
                k,
                pcf,
                cfg.resolution,
                gradient,
            )
        })
        .collect();
    // Points that project nowhere on the map are lit (lookup.rs).
    let mut base = p.visibility.clone();
    for &(k, _, _) in &p.lookups {
        base[k] = 1.0;
    }
    let npix = gb.len();
    fits("resolution", npix as u64 * 16)?;
    let blur = cfg.blur.map(|bl| (bl, blur_pixels(&bl, &gb.depth)));
    sw.lap("setup");
    let img_bytes = npix as u64 * 4;
    let map_bytes = texels * 4;
    let out = with_error_scopes(g, || {
        let device = &g.device;
        let pl = pipelines(device);
        let tri_buf = upload(device, "sm triangles", &tris);
        let start_buf = upload(device, "sm bin starts", &b.start);
        let list_buf = upload(device, "sm bins", &b.list);
        let work_buf = upload(device, "sm work", &b.work);
        let near = storage(
            device,
            "sm nearest",
            map_bytes,
            wgpu::BufferUsages::COPY_SRC,
        );
        let second = storage(
            device,
            "sm second",
            if two_layers { map_bytes } else { 16 },
            wgpu::BufferUsages::COPY_SRC,
        );
        let points_buf = upload(device, "sm points", &points);
        let img = [
            upload_rw(device, "sm image", &base),
            storage(
                device,
                "sm image 2",
                img_bytes,
                wgpu::BufferUsages::COPY_SRC,
            ),
        ];
        let pixels = upload(
            device,
            "sm blur pixels",
            blur.as_ref().map_or(&[][..], |(_, (px, _))| px),
        );
        sw.lap("upload");
        let base_params = SmParams {
            width: w as u32,
            height: h as u32,
            tiles_x: b.tiles_x as u32,
            linear: (cfg.bias.distribution() == Distribution::Linear) as u32,
            two_layers: two_layers as u32,
            midpoint: two_layers as u32,
            pcf,
            n_points: points.len() as u32,
            img_w: gb.width as u32,
            img_h: gb.height as u32,
            inf_bits: f32::INFINITY.to_bits(),
            ..Default::default()
        };
        let timer = StageTimer::new(g, 3);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("softshadow shadow mapping"),
        });
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("raster_occluders"));
            let u = uniform(device, "sm params", &base_params);
            let bg = bind(
                device,
                &pl.clear,
                &[None, None, None, None, Some(&near), Some(&second), Some(&u)],
            );
            pass.set_pipeline(&pl.clear);
            pass.set_bind_group(0, &bg, &[]);
            let (x, y) = groups_1d(texels as u32, GROUP);
            pass.dispatch_workgroups(x, y, 1);
            pass.set_pipeline(&pl.raster);
            for c in 0..b.chunks.len() - 1 {
                let count = b.chunks[c + 1] - b.chunks[c];
                let u = uniform(
                    device,
                    "sm params",
                    &SmParams {
                        chunk_start: c as u32 * CHUNK,
                        chunk_len: CHUNK,
                        work_offset: b.chunks[c],
                        work_count: count,
                        ..base_params
                    },
                );
                let bg = bind(
                    device,
                    &pl.raster,
                    &[
                        Some(&tri_buf),
                        Some(&start_buf),
                        Some(&list_buf),
                        Some(&work_buf),
                        Some(&near),
                        Some(&second),
                        Some(&u),
                    ],
                );
                pass.set_bind_group(0, &bg, &[]);
                let (x, y) = groups_2d(count);
                pass.dispatch_workgroups(x, y, 1);
            }
        }
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
            if !points.is_empty() {
                let u = uniform(device, "sm params", &base_params);
                let bg = bind(
                    device,
                    &pl.lookup,
                    &[
                        None,
                        None,
                        None,
                        None,
                        Some(&near),
                        Some(&second),
                        Some(&u),
                        Some(&points_buf),
                        Some(&img[0]),
                    ],
                );
                pass.set_pipeline(&pl.lookup);
                pass.set_bind_group(0, &bg, &[]);
                let (x, y) = groups_1d(points.len() as u32, GROUP);
                pass.dispatch_workgroups(x, y, 1);
            }
        }
        let mut result = 0;
        if let Some((bl, (_, any))) = &blur {
            let mut pass = enc.begin_compute_pass(&timer.pass("blur"));
            if *any {
                let u = uniform(device, "sm params", &base_params);
                pass.set_pipeline(&pl.blur);
                for _ in 0..bl.iterations {
                    let bg = bind(
                        device,
                        &pl.blur,
                        &[
                            None,
                            None,
                            None,
                            None,
                            None,
                            None,
                            Some(&u),
                            None,
                            Some(&img[1 - result]),
                            Some(&img[result]),
                            Some(&pixels),
                        ],
                    );
                    pass.set_bind_group(0, &bg, &[]);
                    let (x, y) = groups_1d(npix as u32, GROUP);
                    pass.dispatch_workgroups(x, y, 1);
                    result = 1 - result;
                }
            }
        }
        let mut sources = vec![(&img[result], img_bytes)];
        if want_map {
            sources.push((&near, map_bytes));
            if two_layers {
                sources.push((&second, map_bytes));
            }
        }
        submit_and_read(g, enc, &timer, &sources, sw)
    })?;
    let vis = visibility(&out.buffers[0])?;
    let floats = |b: &[u8]| words(b).into_iter().map(f32::from_bits).collect::<Vec<_>>();
    let map = want_map.then(|| DepthMap {
        width: w,
        height: h,
        nearest: floats(&out.buffers[1]),
        second: two_layers.then(|| floats(&out.buffers[2])),
        triangles: p.triangles.len(),
    });
    Ok(SmOutput {
        visibility: vis,
        map,
        timings: out.device_timings,
    })
}

/// A storage buffer holding `items` that shaders may write.
fn upload_rw(device: &wgpu::Device, label: &str, items: &[f32]) -> wgpu::Buffer {
    use wgpu::util::DeviceExt;
    let one = [0f32; 4];
    let data: &[f32] = if items.is_empty() { &one } else { items };
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some(label),
        contents: bytemuck::cast_slice(data),
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
    })
}

/// The visibility (and, if asked, the device's map) of G-buffer `gb`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn render_prepared(
    g: &Gpu,
    call: &EyeCall,
    cfg: &ShadowMappingConfig,
    scene: &SceneTriangles,
    gb: &GBuffer,
    want_map: bool,
    sw: &mut Stopwatch,
    device_timings: &mut Timings,
) -> Result<(Vec<f32>, Option<DepthMap>)> {
    let p = match sm::prepare(call, cfg, scene, gb, sw)? {
        Ok(p) => p,
        Err(v) => return Ok((v, None)),
    };
    let out = run(g, cfg, &p, gb, want_map, sw)?;
    device_timings.extend(out.timings);
    Ok((out.visibility, out.map))
}
