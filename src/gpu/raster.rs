//! Rasterization on the GPU: the set-up triangles of the CPU rasterizer
//! (projected, clipped and snapped in f64 on the CPU, since WGSL has no f64)
//! are uploaded once and drawn by `raster.wgsl` into depth layers held as u32
//! bits in one `maps` buffer. The CPU twin is `raster::scan::raster_tri`.

use super::context::Gpu;
use super::dispatch::{bind, groups_1d, module, pipeline, uniform, upload};
use super::timing::StageTimer;
use crate::geom::light::MapGrid;
use crate::raster::{SetupTri, PEEL_GAP};
use bytemuck::{Pod, Zeroable};
use std::sync::OnceLock;

/// The module: the 64-bit helpers it calls (u64.wgsl), then raster.wgsl.
pub const SOURCE: &str = concat!(include_str!("u64.wgsl"), "\n", include_str!("raster.wgsl"));
/// No layer (WGSL `NONE`).
pub const NONE: u32 = u32::MAX;
const GROUP: u32 = 64;
/// The bits of +inf: the start of a nearest-depth layer.
pub const INF_BITS: u32 = 0x7f80_0000;

/// `RasterParams` of raster.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct RasterParams {
    pub tile_count: u32,
    pub width: u32,
    pub height: u32,
    pub out_offset: u32,
    pub far_offset: u32,
    pub prev_offset: u32,
    pub peel_factor: f32,
    pub _pad: u32,
}

/// `Tri` of raster.wgsl: a `SetupTri` with 32-bit coordinates.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct GpuTri {
    pub x: [i32; 3],
    pub y: [i32; 3],
    pub i0: u32,
    pub i1: u32,
    pub j0: u32,
    pub j1: u32,
    pub w_ref: f32,
    pub gx: [f32; 3],
    pub gy: [f32; 3],
}

/// `Tile` of raster.wgsl: texels [i0, i1] x [j0, j1] of triangle `tri`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct RasterTile {
    pub tri: u32,
    pub i0: u32,
    pub i1: u32,
    pub j0: u32,
    pub j1: u32,
}

/// The side of a raster tile in texels: TILE^2 + TILE loop iterations an
/// invocation, far below lavapipe's 65535.
pub const TILE: u32 = 64;

/// Cuts every triangle's bounding box into tiles of at most TILE x TILE texels.
pub fn tiles(tris: &[GpuTri]) -> Vec<RasterTile> {
    let mut out = Vec::with_capacity(tris.len());
    for (k, t) in tris.iter().enumerate() {
        for j0 in (t.j0..=t.j1).step_by(TILE as usize) {
            for i0 in (t.i0..=t.i1).step_by(TILE as usize) {
                out.push(RasterTile {
                    tri: k as u32,
                    i0,
                    i1: (i0 + TILE - 1).min(t.i1),
                    j0,
                    j1: (j0 + TILE - 1).min(t.j1),
                });
            }
        }
    }
    out
}

/// `FillParams` of raster.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct FillParams {
    pub offset: u32,
    pub len: u32,
    pub value: u32,
    pub _pad: u32,
}

impl GpuTri {
    /// Fixed-point coordinates stay within (side + 2 guard bands) x 256, below
    /// 2^31 for the map sides the GPU backend accepts (see `MAX_SIDE`).
    pub fn from_setup(t: &SetupTri) -> GpuTri {
        GpuTri {
            x: t.x.map(|v| v as i32),
            y: t.y.map(|v| v as i32),
            i0: t.i0,
            i1: t.i1,
            j0: t.j0,
            j1: t.j1,
            w_ref: t.depth.w_ref,
            gx: t.depth.gx,
            gy: t.depth.gy,
        }
    }
}

/// 1 + PEEL_GAP rounded as the CPU rasterizer rounds it.
pub fn peel_factor() -> f32 {
    1.0 + PEEL_GAP
}

pub struct RasterPipelines {
    raster: wgpu::ComputePipeline,
    fill: wgpu::ComputePipeline,
}

impl RasterPipelines {
    /// Compiled once per process.
    pub fn get(device: &wgpu::Device) -> &'static RasterPipelines {
        static P: OnceLock<RasterPipelines> = OnceLock::new();
        P.get_or_init(|| {
            let m = module(device, "raster.wgsl", SOURCE);
            RasterPipelines {
                raster: pipeline(device, &m, "raster"),
                fill: pipeline(device, &m, "fill"),
            }
        })
    }

    /// Records maps[offset .. offset + len] = value.
    pub fn fill(
        &self,
        device: &wgpu::Device,
        pass: &mut wgpu::ComputePass,
        maps: &wgpu::Buffer,
        offset: u32,
        len: u32,
        value: u32,
    ) {
        let p = uniform(
            device,
            "fill params",
            &FillParams {
                offset,
                len,
                value,
                _pad: 0,
            },
        );
        let bg = bind(device, &self.fill, &[Some(maps), None, None, Some(&p)]);
        pass.set_pipeline(&self.fill);
        pass.set_bind_group(0, &bg, &[]);
        let (x, y) = groups_1d(len, GROUP);
        pass.dispatch_workgroups(x, y, 1);
    }

    /// Records the drawing of `tile_count` tiles of `tiles` (of triangles
    /// `tris`) with `params`.
    pub fn raster(
        &self,
        device: &wgpu::Device,
        pass: &mut wgpu::ComputePass,
        maps: &wgpu::Buffer,
        tris: &wgpu::Buffer,
        tiles: &wgpu::Buffer,
        params: &RasterParams,
    ) {
        if params.tile_count == 0 {
            return;
        }
        let p = uniform(device, "raster params", params);
        let bg = bind(
            device,
            &self.raster,
            &[Some(maps), Some(tris), Some(&p), None, Some(tiles)],
        );
        pass.set_pipeline(&self.raster);
        pass.set_bind_group(0, &bg, &[]);
        let (x, y) = groups_1d(params.tile_count, GROUP);
        pass.dispatch_workgroups(x, y, 1);
    }
}

/// The set-up triangles and their tiles on the device.
pub struct RasterInput {
    rec_tris: wgpu::Buffer,
    rec_tiles: wgpu::Buffer,
    rec_tile_count: u32,
    occ_tris: wgpu::Buffer,
    occ_tiles: wgpu::Buffer,
    occ_tile_count: u32,
}

impl RasterInput {
    /// The one upload of the geometry: triangles and tiles of both meshes.
    pub fn upload(g: &Gpu, rec: &[GpuTri], occ: &[GpuTri]) -> RasterInput {
        let d = &g.device;
        let (rt, ot) = (tiles(rec), tiles(occ));
        RasterInput {
            rec_tris: upload(d, "receiver triangles", rec),
            rec_tiles: upload(d, "receiver tiles", &rt),
            rec_tile_count: rt.len() as u32,
            occ_tris: upload(d, "occluder triangles", occ),
            occ_tiles: upload(d, "occluder tiles", &ot),
            occ_tile_count: ot.len() as u32,
        }
    }

    /// Records the passes "raster_receivers" (the receiver map at 0 in
    /// `maps`) and "raster_occluders" (`passes` layers after it: front, the
    /// peeled ones, back), as `pipeline::from_meshes` makes them; no
    /// occluder pass with `passes` = 0 (a method that traces triangles).
    #[allow(clippy::too_many_arguments)]
    pub fn record(
        &self,
        g: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        timer: &StageTimer,
        maps: &wgpu::Buffer,
        grid: &MapGrid,
        og: &MapGrid,
        passes: u32,
    ) {
        let device = &g.device;
        let rp = RasterPipelines::get(device);
        let rec_len = grid.len() as u32;
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("raster_receivers"));
            rp.fill(device, &mut pass, maps, 0, rec_len, INF_BITS);
            rp.raster(
                device,
                &mut pass,
                maps,
                &self.rec_tris,
                &self.rec_tiles,
                &RasterParams {
                    tile_count: self.rec_tile_count,
                    width: grid.width as u32,
                    height: grid.height as u32,
                    out_offset: 0,
                    far_offset: NONE,
                    prev_offset: NONE,
                    peel_factor: peel_factor(),
                    _pad: 0,
                },
            );
        }
        self.record_occluders(g, enc, timer, maps, rec_len, og, passes);
    }

    /// Records the pass "raster_occluders": `passes` layers of the occluder
    /// triangles on `og` at `offset` in `maps` (front, the peeled ones, back),
    /// as `pipeline::from_meshes` and `eye::maps::occluder_layers` make them;
    /// nothing with `passes` = 0.
    #[allow(clippy::too_many_arguments)]
    pub fn record_occluders(
        &self,
        g: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        timer: &StageTimer,
        maps: &wgpu::Buffer,
        offset: u32,
        og: &MapGrid,
        passes: u32,
    ) {
        if passes == 0 {
            return;
        }
        let device = &g.device;
        let rp = RasterPipelines::get(device);
        let occ_len = og.len() as u32;
        let mut pass = enc.begin_compute_pass(&timer.pass("raster_occluders"));
        let layer = |k: u32| offset + k * occ_len;
        // Nearest and peeled layers start at +inf (atomicMin), the farthest at 0 (atomicMax).
        let nearest_layers = if passes >= 2 { passes - 1 } else { 1 };
        rp.fill(
            device,
            &mut pass,
            maps,
            layer(0),
            occ_len * nearest_layers,
            INF_BITS,
        );
        let far = if passes >= 2 {
            rp.fill(device, &mut pass, maps, layer(passes - 1), occ_len, 0);
            layer(passes - 1)
        } else {
            NONE
        };
        let base = RasterParams {
            tile_count: self.occ_tile_count,
            width: og.width as u32,
            height: og.height as u32,
            out_offset: layer(0),
            far_offset: far,
            prev_offset: NONE,
            peel_factor: peel_factor(),
            _pad: 0,
        };
        rp.raster(
            device,
            &mut pass,
            maps,
            &self.occ_tris,
            &self.occ_tiles,
            &base,
        );
        // Depth peeling: layer k is the nearest surface beyond layer k - 1.
        for k in 1..passes.saturating_sub(1) {
            let peel = RasterParams {
                out_offset: layer(k),
                far_offset: NONE,
                prev_offset: layer(k - 1),
                ..base
            };
            rp.raster(
                device,
                &mut pass,
                maps,
                &self.occ_tris,
                &self.occ_tiles,
                &peel,
            );
        }
    }
}
