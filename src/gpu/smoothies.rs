//! Smoothies (Chan & Durand 2003, §3, §3.1, Fig. 11) on the GPU: the
//! smoothie buffer (step 4) and the lookup (step 5) run in `smoothies.wgsl`;
//! their CPU twins are `methods/smoothies/buffer.rs` and `lookup.rs`.
//!
//! What stays on the CPU, in f64 and shared with the CPU backend: the
//! silhouette (step 2, `silhouette.rs`: a weld and an adjacency walk, not a
//! per-texel stage) and the smoothie edges and corners (step 3,
//! `construct.rs`), which depend on the silhouette and are few. They go up
//! once as `GpuSmoothie`s, with each one binned to the 8x8 tiles its hull
//! overlaps (a texel of margin on every side, so that the f32 test decides
//! and never the binning), and the q coordinates of the map's texel centres
//! (computed in f64 as buffer.rs computes them). The front occluder layer
//! (the shadow map) is rasterized on the device by `raster.wgsl`, bit for bit
//! the CPU's. Both views run as `SmoothiesKernel` (its `GpuKernel`).
//!
//! Work bound: one invocation per shadow-map texel reads the smoothies of its
//! tile, at most `PER_CHUNK` a dispatch (lavapipe stops an invocation after
//! 65535 loop iterations); a tile holding more (a dense silhouette) takes
//! `chunks` dispatches, each resuming from the buffer. `Prepared::chunks`
//! says how many a scene took.
//!
//! Precision: the device tests a texel centre against a smoothie in f32
//! where buffer.rs does in f64, so a texel whose centre lies within f32
//! rounding (about 1e-7 relative to q) of a smoothie's border, or whose two
//! candidate alphas tie within it, may differ; the device test counts them.

use super::context::Gpu;
use super::dispatch::{bind, groups_1d, module, pipeline, storage, uniform, upload};
use super::front_layer::FrontLayer;
use super::method_kernel::{
    mismatch, needs_triangles, EyeInputs, GpuKernel, LightViewInputs, MakeStage, Stage,
};
use super::raster::NONE;
#[cfg(test)]
use super::readback::{submit_and_read, with_error_scopes};
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::eye::MapShading;
use crate::frame::light_space_triangles;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::plane_gradient::Plane;
use crate::methods::smoothies::lookup::tent_depths;
use crate::methods::smoothies::method::soup;
use crate::methods::smoothies::{Falloff, Shape, Smoothies};
use crate::methods::{LightPoint, Method};
use crate::timing::{Stopwatch, Timings};
use bytemuck::{Pod, Zeroable};
use glam::{DVec2, DVec3};
use rayon::prelude::*;
use std::sync::OnceLock;

pub const SOURCE: &str = include_str!("smoothies.wgsl");
/// The side of a bin in texels: one workgroup (8 x 8 invocations) a tile.
const TILE: usize = 8;
/// Smoothies one invocation reads per dispatch: half of lavapipe's 65535
/// loop iterations.
pub const PER_CHUNK: u32 = 32768;

/// `SmoothieParams` of smoothies.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct SmoothieParams {
    pub occ_w: u32,
    pub occ_h: u32,
    pub rec_w: u32,
    pub rec_h: u32,
    pub rec_offset: u32,
    pub front_offset: u32,
    pub merge: u32,
    pub tiles_x: u32,
    pub t: f32,
    pub falloff: u32,
    pub per_chunk: u32,
    pub _pad: u32,
}

/// `SmoothieChunk` of smoothies.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct SmoothieChunk {
    pub chunk: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// `Smoothie` of smoothies.wgsl: a `Shape` in f32.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct GpuSmoothie {
    pub kind: u32,
    pub len: f32,
    pub z0: f32,
    pub z1: f32,
    pub px: f32,
    pub py: f32,
    pub ax: f32,
    pub ay: f32,
    pub bx: f32,
    pub by: f32,
    pub _pad0: u32,
    pub _pad1: u32,
}

/// `TentAxis` of smoothies.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct TentAxis {
    pub a: u32,
    pub b: u32,
    pub w: f32,
    pub _pad: u32,
}

/// `TentPoint` of smoothies.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct TentPoint {
    pub ia: u32,
    pub ib: u32,
    pub ja: u32,
    pub jb: u32,
    pub wx: f32,
    pub wy: f32,
    /// The receiver's depth at the taps (a, a), (b, a), (a, b), (b, b)
    /// (`methods::smoothies::tent_depths`).
    pub z_aa: f32,
    pub z_ba: f32,
    pub z_ab: f32,
    pub z_bb: f32,
    pub live: u32,
}

impl GpuSmoothie {
    fn new(s: &Shape) -> GpuSmoothie {
        let f = |v: DVec2| (v.x as f32, v.y as f32);
        let base = |kind: u32, p: DVec2, a: DVec2, b: DVec2| {
            let ((px, py), (ax, ay), (bx, by)) = (f(p), f(a), f(b));
            GpuSmoothie {
                kind,
                px,
                py,
                ax,
                ay,
                bx,
                by,
                ..Default::default()
            }
        };
        match *s {
            Shape::Edge {
                p0,
                d,
                len,
                n,
                inv_z0,
                inv_z1,
            } => GpuSmoothie {
                len: len as f32,
                z0: inv_z0 as f32,
                z1: inv_z1 as f32,
                ..base(0, p0, d, n)
            },
            Shape::Corner { v, z, da, db } => GpuSmoothie {
                z0: z as f32,
                ..base(1, v, da, db)
            },
            Shape::Fan { v, z, o, m } => GpuSmoothie {
                z0: z as f32,
                ..base(2, v, o, m)
            },
        }
    }
}

/// The texel range [lo, hi] (clamped to [0, n - 1]) whose centres k + 1/2
/// lie in [a - 1, b + 1] (pixel units), or None.
fn texel_range(a: f64, b: f64, n: usize) -> Option<(usize, usize)> {
    let lo = (a - 1.5).ceil().max(0.0);
    let hi = (b + 0.5).floor().min(n as f64 - 1.0);
    (lo <= hi).then_some((lo as usize, hi as usize))
}

/// The x range of convex polygon `px` within the band y in [y0, y1].
fn band_x(px: &[DVec2], y0: f64, y1: f64) -> Option<(f64, f64)> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut add = |x: f64| {
        lo = lo.min(x);
        hi = hi.max(x);
    };
    for (k, &a) in px.iter().enumerate() {
        if a.y >= y0 && a.y <= y1 {
            add(a.x);
        }
        let b = px[(k + 1) % px.len()];
        for y in [y0, y1] {
            if (a.y - y) * (b.y - y) < 0.0 {
                add(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y));
            }
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// Steps 2-3 on the CPU, ready for the device: the smoothies, their bins,
/// the q axes of the shadow map's grid.
pub struct Prepared {
    smoothies: Vec<GpuSmoothie>,
    tile_start: Vec<u32>,
    tile_items: Vec<u32>,
    q_axes: Vec<f32>,
    params: SmoothieParams,
    og: MapGrid,
    /// The stats known before rasterizing (`texels` comes back from the
    /// device; the device tests compare them).
    #[cfg(test)]
    pub stats: crate::methods::smoothies::SmoothieStats,
    /// Dispatches of the buffer pass: the most smoothies in one tile over
    /// `per_chunk`, rounded up (at least 1).
    pub chunks: u32,
}

impl Prepared {
    /// The smoothies of the occluders (`verts`, `faces` in kernel light
    /// space) on the shadow map's grid `og`, read `per_chunk` per dispatch.
    pub fn new(
        s: &Smoothies,
        og: &MapGrid,
        light: LightShape,
        verts: &[DVec3],
        faces: &[[u32; 3]],
        per_chunk: u32,
    ) -> Prepared {
        let built = s.smoothies(og, light, verts, faces);
        // q units scale tangents by the light's box (smoothies/construct.rs).
        let light = light.extent();
        let t = built.t;
        let (w, h) = (og.width, og.height);
        let (tiles_x, tiles_y) = (w.div_ceil(TILE), h.div_ceil(TILE));
        let to_px = |q: DVec2| {
            let (px, py) = og.to_pixel(q.x * light[0], q.y * light[1]);
            DVec2::new(px, py)
        };
        // (tile, smoothie) for every tile a smoothie's hull (widened by a
        // texel) overlaps, one band of tile rows at a time.
        let mut smoothies = Vec::with_capacity(built.shapes.len());
        let mut pairs: Vec<(u32, u32)> = Vec::new();
        for shape in &built.shapes {
            let (hull, nv) = shape.hull(t);
            let px: Vec<DVec2> = hull[..nv].iter().map(|&q| to_px(q)).collect();
            if px.iter().any(|p| !p.is_finite()) {
                continue; // buffer.rs skips it too
            }
            let idx = smoothies.len() as u32;
            smoothies.push(GpuSmoothie::new(shape));
            let (ymin, ymax) = px.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |m, p| {
                (m.0.min(p.y), m.1.max(p.y))
            });
            let Some((j0, j1)) = texel_range(ymin, ymax, h) else {
                continue;
            };
            for tj in j0 / TILE..=j1 / TILE {
                // The band of this tile row's centres, a texel wider.
                let y0 = (tj * TILE) as f64 + 0.5 - 1.0;
                let y1 = (tj * TILE + TILE - 1) as f64 + 0.5 + 1.0;
                let Some((xl, xr)) = band_x(&px, y0, y1) else {
                    continue;
                };
                let Some((i0, i1)) = texel_range(xl, xr, w) else {
                    continue;
                };
                for ti in i0 / TILE..=i1 / TILE {
                    pairs.push(((tj * tiles_x + ti) as u32, idx));
                }
            }
        }
        pairs.par_sort_unstable();
        let n_tiles = tiles_x * tiles_y;
        let mut tile_start = vec![0u32; n_tiles + 1];
        for &(tile, _) in &pairs {
            tile_start[tile as usize + 1] += 1;
        }
        let most = tile_start.iter().copied().max().unwrap_or(0);
        for k in 0..n_tiles {
            tile_start[k + 1] += tile_start[k];
        }
        let tile_items = pairs.into_iter().map(|(_, s)| s).collect();
        let per_chunk = per_chunk.max(1);
        let mut q_axes: Vec<f32> = (0..w).map(|i| (og.x_of(i) / light[0]) as f32).collect();
        q_axes.extend((0..h).map(|j| (og.y_of(j) / light[1]) as f32));
        Prepared {
            smoothies,
            tile_start,
            tile_items,
            q_axes,
            params: SmoothieParams {
                occ_w: w as u32,
                occ_h: h as u32,
                tiles_x: tiles_x as u32,
                t: t as f32,
                falloff: match s.falloff {
                    Falloff::Linear => 0,
                    Falloff::Sine => 1,
                },
                per_chunk,
                rec_offset: NONE,
                ..Default::default()
            },
            og: *og,
            #[cfg(test)]
            stats: built.stats,
            chunks: most.div_ceil(per_chunk).max(1),
        }
    }
}

impl Prepared {
    /// Refuses smoothies (or bins) that one buffer binding cannot hold: a
    /// silhouette of very many smoothies, each wider than much of the map.
    pub fn check_fits(&self, g: &Gpu) -> Result<()> {
        let bytes = [
            std::mem::size_of_val(&self.smoothies[..]),
            std::mem::size_of_val(&self.tile_items[..]),
        ]
        .into_iter()
        .max()
        .unwrap_or(0) as u64;
        if bytes > g.max_storage_binding || self.tile_items.len() >= u32::MAX as usize {
            return Err(Error::too_large(
                "width",
                format!(
                    "the smoothies and their tiles need {bytes} bytes in one GPU buffer; the \
                     device binds at most {}; use backend=\"cpu\" or a smaller width",
                    g.max_storage_binding
                ),
            ));
        }
        Ok(())
    }
}

/// lookup.rs's tent along one axis at continuous pixel coordinate `p` on
/// an axis of `n` texels, in f64 as at_point computes it.
fn tent_axis(p: f64, n: usize) -> TentAxis {
    let f = p - 0.5;
    let i0 = f.floor();
    let clamp = |c: f64| c.clamp(0.0, (n - 1) as f64) as u32;
    TentAxis {
        a: clamp(i0),
        b: clamp(i0 + 1.0),
        w: (f - i0) as f32,
        _pad: 0,
    }
}

/// The tent of every output column then row of `grid` on the shadow map's
/// grid `og`, at the texel centres `ShadowMethod::visibility_map` shades
/// (their f32 tangents).
pub fn map_tents(grid: &MapGrid, og: &MapGrid) -> Vec<TentAxis> {
    let mut v: Vec<TentAxis> = (0..grid.width)
        .map(|i| tent_axis(og.to_pixel(grid.x_of(i) as f32 as f64, 0.0).0, og.width))
        .collect();
    v.extend(
        (0..grid.height)
            .map(|j| tent_axis(og.to_pixel(0.0, grid.y_of(j) as f32 as f64).1, og.height)),
    );
    v
}

/// The tent of each point on `og`, each tap's depth on the point's tangent
/// plane `planes[i]` ((0, 0) where missing; lookup.rs's at_point up to the
/// taps); not live where at_point returns 1 without looking.
pub fn point_tents(og: &MapGrid, points: &[LightPoint], planes: &[Plane]) -> Vec<TentPoint> {
    points
        .par_iter()
        .enumerate()
        .with_min_len(1024)
        .map(|(i, p)| {
            if !(p.z.is_finite() && p.z > 0.0 && p.x.is_finite() && p.y.is_finite()) {
                return TentPoint::default();
            }
            let (px, py) = og.to_pixel(p.x as f64, p.y as f64);
            let (cx, cy) = (tent_axis(px, og.width), tent_axis(py, og.height));
            let plane = planes.get(i).copied().unwrap_or([0.0; 2]);
            let [z_aa, z_ba, z_ab, z_bb] = tent_depths(px, py, p.z, plane);
            TentPoint {
                ia: cx.a,
                ib: cx.b,
                ja: cy.a,
                jb: cy.b,
                wx: cx.w,
                wy: cy.w,
                z_aa,
                z_ba,
                z_ab,
                z_bb,
                live: 1,
            }
        })
        .collect()
}

struct Pipelines {
    map: wgpu::ComputePipeline,
    buffer: wgpu::ComputePipeline,
    lookup_map: wgpu::ComputePipeline,
    lookup_points: wgpu::ComputePipeline,
}

fn pipelines(device: &wgpu::Device) -> &'static Pipelines {
    static P: OnceLock<Pipelines> = OnceLock::new();
    P.get_or_init(|| {
        let m = module(device, "smoothies.wgsl", SOURCE);
        Pipelines {
            map: pipeline(device, &m, "smoothie_map"),
            buffer: pipeline(device, &m, "smoothie_buffer"),
            lookup_map: pipeline(device, &m, "smoothie_lookup_map"),
            lookup_points: pipeline(device, &m, "smoothie_lookup_points"),
        }
    })
}

/// Where the receivers come from: the receiver map of the output grid in
/// `maps` (light view), or points (eye view), or none (the buffer alone).
pub enum Receivers<'a> {
    Map {
        grid: &'a MapGrid,
        offset: u32,
    },
    Points(&'a [TentPoint]),
    /// The buffer alone (the device tests read it).
    #[cfg(test)]
    None,
}

/// The device buffers of steps 4-5.
pub struct SmoothieShading {
    params: SmoothieParams,
    chunks: u32,
    smoothies: wgpu::Buffer,
    tile_start: wgpu::Buffer,
    tile_items: wgpu::Buffer,
    q_axes: wgpu::Buffer,
    smap: wgpu::Buffer,
    pub alpha: wgpu::Buffer,
    pub depth: wgpu::Buffer,
    pub counters: wgpu::Buffer,
    tents: Option<wgpu::Buffer>,
    points: Option<wgpu::Buffer>,
    pub vis: wgpu::Buffer,
    /// Bytes of `vis` (0 without receivers).
    pub vis_bytes: u64,
}

impl SmoothieShading {
    /// Uploads `p` and makes the buffers; the front layer lies at
    /// `front_offset` in the `maps` that `record` reads.
    pub fn new(g: &Gpu, p: &Prepared, front_offset: u32, rec: Receivers) -> SmoothieShading {
        let device = &g.device;
        let mut params = SmoothieParams {
            front_offset,
            ..p.params
        };
        let occ_len = (params.occ_w as u64) * (params.occ_h as u64);
        let (tents, points, n_vis) = match rec {
            Receivers::Map { grid, offset } => {
                let og = p.og;
                params.rec_w = grid.width as u32;
                params.rec_h = grid.height as u32;
                params.rec_offset = offset;
                // The paper's shadow map holds the receivers where they share a grid.
                params.merge = (*grid == og) as u32;
                let tents = upload(device, "smoothie tents", &map_tents(grid, &og));
                (Some(tents), None, grid.len() as u64)
            }
            Receivers::Points(pts) => {
                params.rec_w = pts.len() as u32;
                params.rec_h = 1;
                let points = upload(device, "smoothie points", pts);
                (None, Some(points), pts.len() as u64)
            }
            #[cfg(test)]
            Receivers::None => (None, None, 0),
        };
        let rw = wgpu::BufferUsages::COPY_SRC;
        SmoothieShading {
            params,
            chunks: p.chunks,
            smoothies: upload(device, "smoothies", &p.smoothies),
            tile_start: upload(device, "smoothie tiles", &p.tile_start),
            tile_items: upload(device, "smoothie tile items", &p.tile_items),
            q_axes: upload(device, "smoothie q axes", &p.q_axes),
            smap: storage(device, "shadow map", occ_len * 4, rw),
            alpha: storage(device, "smoothie alpha", occ_len * 4, rw),
            depth: storage(device, "smoothie depth", occ_len * 4, rw),
            counters: storage(
                device,
                "smoothie counters",
                16,
                wgpu::BufferUsages::COPY_DST | rw,
            ),
            tents,
            points,
            vis: storage(device, "visibility", n_vis * 4, rw),
            vis_bytes: n_vis * 4,
        }
    }

    /// Records the passes "smoothie_buffer" (the shadow map, then the
    /// buffer in `chunks` dispatches) and, with receivers, "shadow".
    pub fn record(
        &self,
        g: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        timer: &StageTimer,
        maps: &wgpu::Buffer,
    ) {
        let device = &g.device;
        let p = pipelines(device);
        let u = uniform(device, "smoothie params", &self.params);
        let occ_groups = (
            self.params.occ_w.div_ceil(TILE as u32),
            self.params.occ_h.div_ceil(TILE as u32),
        );
        enc.clear_buffer(&self.counters, 0, None);
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("smoothie_buffer"));
            let bg = bind(device, &p.map, &[Some(maps), Some(&self.smap), Some(&u)]);
            pass.set_pipeline(&p.map);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(occ_groups.0, occ_groups.1, 1);
            pass.set_pipeline(&p.buffer);
            for chunk in 0..self.chunks {
                let c = uniform(
                    device,
                    "smoothie chunk",
                    &SmoothieChunk {
                        chunk,
                        ..Default::default()
                    },
                );
                let bg = bind(
                    device,
                    &p.buffer,
                    &[
                        None,
                        Some(&self.smap),
                        Some(&u),
                        Some(&self.smoothies),
                        Some(&self.tile_start),
                        Some(&self.tile_items),
                        Some(&self.q_axes),
                        Some(&self.alpha),
                        Some(&self.depth),
                        Some(&self.counters),
                        Some(&c),
                    ],
                );
                pass.set_bind_group(0, &bg, &[]);
                pass.dispatch_workgroups(occ_groups.0, occ_groups.1, 1);
            }
        }
        if self.vis_bytes == 0 {
            return;
        }
        let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
        let mut entries: Vec<Option<&wgpu::Buffer>> = vec![None; 14];
        entries[1] = Some(&self.smap);
        entries[2] = Some(&u);
        entries[7] = Some(&self.alpha);
        entries[8] = Some(&self.depth);
        entries[13] = Some(&self.vis);
        if let Some(t) = &self.tents {
            entries[0] = Some(maps);
            entries[11] = Some(t);
            let bg = bind(device, &p.lookup_map, &entries);
            pass.set_pipeline(&p.lookup_map);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(
                self.params.rec_w.div_ceil(8),
                self.params.rec_h.div_ceil(8),
                1,
            );
        } else if let Some(pts) = &self.points {
            entries[12] = Some(pts);
            let bg = bind(device, &p.lookup_points, &entries);
            pass.set_pipeline(&p.lookup_points);
            pass.set_bind_group(0, &bg, &[]);
            let (x, y) = groups_1d(self.params.rec_w, 64);
            pass.dispatch_workgroups(x, y, 1);
        }
    }
}

/// The smoothies' options of `method`.
fn options(method: Method) -> Result<Smoothies> {
    match method {
        Method::Smoothies(k) => Ok(Smoothies {
            width: k.width.0,
            falloff: k.falloff,
        }),
        _ => Err(mismatch(method)),
    }
}

/// The light view's steps 2-3: the occluders as `method.rs` hands them to
/// the CPU method (f32 light-space triangles, a soup the silhouette welds).
fn prepare_light_view(
    g: &Gpu,
    s: &Smoothies,
    og: &MapGrid,
    light_shape: LightShape,
    occ_ls: &[DVec3],
    faces: &[[u32; 3]],
) -> Result<Prepared> {
    let tris = light_space_triangles(occ_ls, faces);
    let (verts, faces) = soup(&tris);
    let p = Prepared::new(s, og, light_shape, &verts, &faces, PER_CHUNK);
    p.check_fits(g)?;
    Ok(p)
}

/// The eye view's Smoothies on the device (`maps::shade`'s Smoothies arm):
/// the front layer of every mesh on `e.grid` (raster.wgsl), the smoothies
/// of the scene's silhouette (CPU), the buffer and the lookup at the biased
/// points; the visibility per point (unweighted: the smoothies' ramp has
/// no light point per texel), the maps, the device's stage times.
fn shade_eye(
    g: &Gpu,
    e: &EyeInputs,
    s: &Smoothies,
    sw: &mut Stopwatch,
) -> Result<(MapShading, Timings)> {
    let (f, tris, grid) = (e.f, e.tris, e.grid);
    let front = FrontLayer::new(g, f, tris, grid, e.bias, true)?;
    // Every mesh is an occluder: the silhouette straight from the mesh.
    let prepared = Prepared::new(s, &grid, f.light_shape, &tris.verts, tris.faces, PER_CHUNK);
    prepared.check_fits(g)?;
    let tents = point_tents(&grid, &front.points.points, &front.points.planes);
    sw.lap("setup");
    front.shade(
        g,
        f,
        "softshadow eye smoothies",
        3,
        || {
            Ok(SmoothieShading::new(
                g,
                &prepared,
                0,
                Receivers::Points(&tents),
            ))
        },
        sw,
    )
}

impl Stage for SmoothieShading {
    fn record(
        &self,
        g: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        timer: &StageTimer,
        maps: &wgpu::Buffer,
    ) -> Result<()> {
        SmoothieShading::record(self, g, enc, timer, maps);
        Ok(())
    }

    fn outputs(&self) -> Vec<(&wgpu::Buffer, u64)> {
        vec![(&self.vis, self.vis_bytes)]
    }
}

/// Smoothies' kernel: steps 2-3 on the CPU, the buffer and the lookup on
/// the device, over the front layer (the light view's after the receiver
/// map, or rasterized for the eye view's points).
pub(super) struct SmoothiesKernel;

impl GpuKernel for SmoothiesKernel {
    fn light_view<'a>(
        &self,
        g: &'a Gpu,
        method: Method,
        i: LightViewInputs<'a>,
    ) -> Result<Option<MakeStage<'a>>> {
        let s = options(method)?;
        let (verts, faces) = i.occluders.ok_or_else(|| needs_triangles(method))?;
        let p = prepare_light_view(g, &s, i.occluder_grid, i.light_shape, verts, faces)?;
        Ok(Some(Box::new(move || {
            let receivers = Receivers::Map {
                grid: i.grid,
                offset: 0,
            };
            // The front layer follows the receiver map.
            let sh = SmoothieShading::new(g, &p, i.grid.len() as u32, receivers);
            Ok(Box::new(sh) as Box<dyn Stage>)
        })))
    }

    fn eye(
        &self,
        g: &Gpu,
        method: Method,
        inputs: &EyeInputs,
        sw: &mut Stopwatch,
    ) -> Result<(MapShading, Timings)> {
        shade_eye(g, inputs, &options(method)?, sw)
    }
}

/// Steps 1-4 alone on the device, from a shadow map the caller gives: the
/// twin of `Smoothies::buffer`, and the buffer pass's dispatches (tests).
#[cfg(test)]
pub fn buffer_on_device(
    s: &Smoothies,
    grid: &MapGrid,
    light_shape: LightShape,
    front: &[f32],
    verts: &[DVec3],
    faces: &[[u32; 3]],
    per_chunk: u32,
) -> Result<(crate::methods::smoothies::SmoothieBuffer, u32)> {
    let g = super::context::gpu()?;
    let p = Prepared::new(s, grid, light_shape, verts, faces, per_chunk);
    let words: Vec<u32> = front.iter().map(|z| z.to_bits()).collect();
    let mut sw = Stopwatch::new();
    let map_bytes = grid.len() as u64 * 4;
    let out = with_error_scopes(g, || {
        let maps = upload(&g.device, "maps", &words);
        let shading = SmoothieShading::new(g, &p, 0, Receivers::None);
        let timer = StageTimer::new(g, 1);
        let mut enc = g
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("smoothie buffer"),
            });
        shading.record(g, &mut enc, &timer, &maps);
        submit_and_read(
            g,
            enc,
            &timer,
            &[
                (&shading.alpha, map_bytes),
                (&shading.depth, map_bytes),
                (&shading.counters, 4),
            ],
            &mut sw,
        )
    })?;
    let f = |b: &[u8]| words_f32(b);
    let mut stats = p.stats;
    stats.texels = super::readback::words(&out.buffers[2])[0] as usize;
    Ok((
        crate::methods::smoothies::SmoothieBuffer {
            alpha: f(&out.buffers[0]),
            depth: f(&out.buffers[1]),
            stats,
        },
        p.chunks,
    ))
}

#[cfg(test)]
fn words_f32(b: &[u8]) -> Vec<f32> {
    super::readback::words(b)
        .into_iter()
        .map(f32::from_bits)
        .collect()
}
