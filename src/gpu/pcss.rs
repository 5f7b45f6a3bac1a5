//! PCSS on the GPU (Fernando 2005: blocker search, penumbra estimate, box
//! PCF; the maths in `pcss.wgsl` and `methods/pcss.rs`, its CPU twin). Both
//! views:
//!
//! * light view (`soft_shadow_map`, from meshes or depth maps): map mode,
//!   one invocation per output texel reading the receiver map and the front
//!   occluder layer already on the device (`PcssShading::maps`);
//! * eye view (`render`): the front layer rasterized on the device as the
//!   map methods' (`raster.wgsl`, bit for bit `maps::occluder_layers`), the
//!   biased points made on the CPU (`maps::shading_points`), shaded in
//!   points mode, then `maps::finish` (`shade_points`).
//!
//! Both run as `PcssKernel` (its `GpuKernel`). One compute pass ("shadow"):
//! z_near, the search's chunks, the filter's chunks, the resolve. The CPU
//! does in f64 what sets every point up: the pixel coordinates (split into
//! texel + fraction, see pcss.wgsl) and the half-widths per unit of 1/depth
//! (`methods::pcss::half_per_w`).

use super::context::Gpu;
use super::dispatch::{bind, groups_1d, module, pipeline, storage, upload};
use super::front_layer::FrontLayer;
use super::irradiance_weight::GpuWeighPoint;
use super::method_kernel::{mismatch, EyeInputs, GpuKernel, LightViewInputs, MakeStage, Stage};
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::eye::rays::ray_starts;
use crate::eye::MapShading;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::light_space::LightSpace;
use crate::geom::plane_gradient::{split, Plane};
use crate::methods::pcss::{half_per_w, MAX_TAPS};
use crate::methods::{LightPoint, Method, Pcss};
use crate::timing::{Stopwatch, Timings};
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;
use std::sync::OnceLock;

/// pcss.wgsl after the disk overlap it weighs cells by under a disk and
/// the receivers' weights of its weighted resolve.
pub const SOURCE: &str = concat!(
    include_str!("disk_overlap.wgsl"),
    "\n",
    include_str!("irradiance_weight.wgsl"),
    "\n",
    include_str!("pcss.wgsl")
);

/// Invocations per workgroup (pcss.wgsl's @workgroup_size).
const GROUP: u32 = 64;
/// Front texels per invocation of `pcss_near` (pcss.wgsl's NEAR_SPAN).
const NEAR_SPAN: u32 = 256;
/// Loop iterations one invocation may run per dispatch: half of lavapipe's
/// 65535 (llvmpipe counts every iteration of every loop of an invocation).
const ITERATION_BUDGET: u32 = 32768;

/// `PcssParams` of pcss.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct PcssParams {
    pub n: u32,
    pub mode: u32,
    pub out_w: u32,
    pub rec_offset: u32,
    pub occ_w: u32,
    pub occ_h: u32,
    pub front_offset: u32,
    pub front_len: u32,
    pub taps: u32,
    pub rows_per_chunk: u32,
    pub half_per_w_x: f32,
    pub half_per_w_y: f32,
    /// 1 under a disk light: the boxes' inscribed ellipses (`pcf_disk.rs`).
    pub disk: u32,
    /// 1: the weighted visibility too (points mode, `pcss_weighted.rs`).
    pub weigh: u32,
    /// The light's half-extents (kernel units), for the weights.
    pub half_lx: f32,
    pub half_ly: f32,
}

/// `PcssChunk` of pcss.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct PcssChunk {
    pub chunk: u32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// `Coord` of pcss.wgsl: a continuous pixel coordinate as base + frac.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct Coord {
    pub base: i32,
    pub frac: f32,
}

impl Coord {
    /// `p` (finite) split at its texel (`geom::plane_gradient::split`).
    pub fn new(p: f64) -> Coord {
        let (base, frac) = split(p);
        Coord { base, frac }
    }
}

/// `PcssPoint` of pcss.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default, PartialEq)]
pub struct GpuPcssPoint {
    pub bx: i32,
    pub fx: f32,
    pub by: i32,
    pub fy: f32,
    pub z: f32,
    pub live: u32,
    /// The receiver's tangent plane (`geom::plane_gradient::Plane`).
    pub pa: f32,
    pub pb: f32,
}

impl GpuPcssPoint {
    /// A light-space point as the kernel reads it on `og`; not live where
    /// pcss.rs's visibility returns 1 whatever the map (z not in (0, inf),
    /// non-finite pixel coordinates). z_near is the device's test.
    pub fn new(og: &MapGrid, p: &LightPoint, plane: Plane) -> GpuPcssPoint {
        if !(p.z.is_finite() && p.z > 0.0) {
            return GpuPcssPoint::default();
        }
        let (px, py) = og.to_pixel(p.x as f64, p.y as f64);
        if !(px.is_finite() && py.is_finite()) {
            return GpuPcssPoint::default();
        }
        let (cx, cy) = (Coord::new(px), Coord::new(py));
        GpuPcssPoint {
            bx: cx.base,
            fx: cx.frac,
            by: cy.base,
            fy: cy.frac,
            z: p.z,
            live: 1,
            pa: plane[0],
            pb: plane[1],
        }
    }
}

/// y entries per dispatch and the dispatches that cover an axis of at most
/// `taps` entries (each y entry runs an x loop of at most `taps`).
pub fn chunking(taps: u32) -> (u32, u32) {
    let rows = (ITERATION_BUDGET / (taps + 2)).max(1);
    (rows, taps.div_ceil(rows).max(1))
}

struct Pipelines {
    near: wgpu::ComputePipeline,
    search: wgpu::ComputePipeline,
    filter: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
}

fn pipelines(device: &wgpu::Device) -> &'static Pipelines {
    static P: OnceLock<Pipelines> = OnceLock::new();
    P.get_or_init(|| {
        let m = module(device, "pcss.wgsl", SOURCE);
        Pipelines {
            near: pipeline(device, &m, "pcss_near"),
            search: pipeline(device, &m, "pcss_search"),
            filter: pipeline(device, &m, "pcss_filter"),
            resolve: pipeline(device, &m, "pcss_resolve"),
        }
    })
}

/// The buffers and parameters of the PCSS shading stage.
pub struct PcssShading {
    params: PcssParams,
    chunks: u32,
    coords: wgpu::Buffer,
    points: wgpu::Buffer,
    weigh_points: wgpu::Buffer,
    near: wgpu::Buffer,
    acc: wgpu::Buffer,
    pub vis: wgpu::Buffer,
    pub vis_bytes: u64,
}

/// Refuses `n` points whose accumulators (16 bytes each, twice where
/// weighed) do not fit one binding.
fn check_points(g: &Gpu, arg: &str, n: usize, weigh: bool) -> Result<()> {
    let bytes = 16 * n as u64 * (1 + weigh as u64);
    if n as u64 >= u32::MAX as u64 || bytes > g.max_storage_binding {
        return Err(Error::too_large(
            arg,
            format!(
                "PCSS needs {bytes} bytes in one GPU buffer; the device binds at most {}; \
                 use backend=\"cpu\"",
                g.max_storage_binding
            ),
        ));
    }
    Ok(())
}

impl PcssShading {
    #[allow(clippy::too_many_arguments)]
    fn new(
        g: &Gpu,
        og: &MapGrid,
        light_shape: LightShape,
        max_taps: u32,
        front_offset: u32,
        mut params: PcssParams,
        coords: &[Coord],
        points: &[GpuPcssPoint],
        weigh: Option<&[GpuWeighPoint]>,
    ) -> PcssShading {
        let device = &g.device;
        let taps = max_taps.clamp(1, MAX_TAPS);
        let (rows_per_chunk, chunks) = chunking(taps);
        let [hx, hy] = half_per_w(og, light_shape);
        params.occ_w = og.width as u32;
        params.occ_h = og.height as u32;
        params.front_offset = front_offset;
        params.front_len = og.len() as u32;
        params.taps = taps;
        params.rows_per_chunk = rows_per_chunk;
        params.half_per_w_x = hx as f32;
        params.half_per_w_y = hy as f32;
        params.disk = u32::from(matches!(light_shape, LightShape::Disk { .. }));
        let [lx, ly] = light_shape.half_extent();
        params.half_lx = lx as f32;
        params.half_ly = ly as f32;
        params.weigh = u32::from(weigh.is_some());
        // Weighing, the weighted accumulators and visibility follow the plain.
        let copies = 1 + params.weigh as u64;
        let vis_bytes = params.n as u64 * 4 * copies;
        PcssShading {
            params,
            chunks,
            coords: upload(device, "pcss coords", coords),
            points: upload(device, "pcss points", points),
            weigh_points: upload(
                device,
                "pcss weighed points",
                weigh.unwrap_or(&[GpuWeighPoint::default()]),
            ),
            near: storage(device, "pcss z_near", 4, wgpu::BufferUsages::COPY_DST),
            acc: storage(
                device,
                "pcss accumulators",
                params.n as u64 * 16 * copies,
                wgpu::BufferUsages::COPY_DST,
            ),
            vis: storage(
                device,
                "visibility",
                vis_bytes,
                wgpu::BufferUsages::COPY_SRC,
            ),
            vis_bytes,
        }
    }

    /// Light view: the visibility of every texel of `grid` (its receiver
    /// map at 0 in `maps`), from the front layer on `og` at `front_offset`.
    pub fn maps(
        g: &Gpu,
        grid: &MapGrid,
        og: &MapGrid,
        light_shape: LightShape,
        max_taps: u32,
        front_offset: u32,
    ) -> Result<PcssShading> {
        check_points(g, "resolution", grid.len(), false)?;
        // The CPU's receiver tangents (f32), then the occluder grid's pixels.
        let coords: Vec<Coord> = (0..grid.width)
            .map(|i| Coord::new(og.to_pixel(grid.x_of(i) as f32 as f64, 0.0).0))
            .chain(
                (0..grid.height)
                    .map(|j| Coord::new(og.to_pixel(0.0, grid.y_of(j) as f32 as f64).1)),
            )
            .collect();
        let params = PcssParams {
            n: grid.len() as u32,
            mode: 0,
            out_w: grid.width as u32,
            rec_offset: 0,
            ..Default::default()
        };
        Ok(PcssShading::new(
            g,
            og,
            light_shape,
            max_taps,
            front_offset,
            params,
            &coords,
            &[],
            None,
        ))
    }

    /// Points mode: the visibility of each of `points` (kernel light space),
    /// from the front layer on `og` at `front_offset`; with `weigh` (a
    /// receiver per point) the weighted visibility after it.
    #[allow(clippy::too_many_arguments)]
    pub fn points(
        g: &Gpu,
        og: &MapGrid,
        light_shape: LightShape,
        max_taps: u32,
        front_offset: u32,
        points: &[LightPoint],
        planes: &[Plane],
        weigh: Option<&[GpuWeighPoint]>,
    ) -> Result<PcssShading> {
        check_points(g, "resolution", points.len(), weigh.is_some())?;
        debug_assert!(weigh.is_none_or(|w| w.len() == points.len()));
        let pts: Vec<GpuPcssPoint> = points
            .par_iter()
            .enumerate()
            .with_min_len(1024)
            .map(|(i, p)| GpuPcssPoint::new(og, p, planes.get(i).copied().unwrap_or([0.0; 2])))
            .collect();
        let params = PcssParams {
            n: pts.len() as u32,
            mode: 1,
            ..Default::default()
        };
        Ok(PcssShading::new(
            g,
            og,
            light_shape,
            max_taps,
            front_offset,
            params,
            &[],
            &pts,
            weigh,
        ))
    }

    /// Records the pass "shadow" reading `maps`: z_near, every chunk of the
    /// search, every chunk of the filter, the resolve.
    pub fn record(
        &self,
        g: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        timer: &StageTimer,
        maps: &wgpu::Buffer,
    ) {
        let device = &g.device;
        let p = pipelines(device);
        enc.clear_buffer(&self.near, 0, None);
        enc.clear_buffer(&self.acc, 0, None);
        let u = super::dispatch::uniform(device, "pcss params", &self.params);
        let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
        // Bindings an entry point does not use are not in its layout.
        let only = |pl: &wgpu::ComputePipeline, used: [bool; 9], c: Option<&wgpu::Buffer>| {
            let all = [
                Some(maps),
                Some(&u),
                Some(&self.coords),
                Some(&self.points),
                Some(&self.near),
                Some(&self.acc),
                Some(&self.vis),
                c,
                Some(&self.weigh_points),
            ];
            let picked: Vec<Option<&wgpu::Buffer>> = all
                .iter()
                .zip(used)
                .map(|(b, keep)| if keep { *b } else { None })
                .collect();
            bind(device, pl, &picked)
        };
        let near_groups = groups_1d(self.params.front_len.div_ceil(NEAR_SPAN), GROUP);
        pass.set_pipeline(&p.near);
        pass.set_bind_group(
            0,
            &only(
                &p.near,
                [true, true, false, false, true, false, false, false, false],
                None,
            ),
            &[],
        );
        pass.dispatch_workgroups(near_groups.0, near_groups.1, 1);
        let groups = groups_1d(self.params.n, GROUP);
        for (stage, weighs) in [(&p.search, false), (&p.filter, true)] {
            let used = [true, true, true, true, true, true, false, true, weighs];
            pass.set_pipeline(stage);
            for chunk in 0..self.chunks {
                let c = super::dispatch::uniform(
                    device,
                    "pcss chunk",
                    &PcssChunk {
                        chunk,
                        ..Default::default()
                    },
                );
                pass.set_bind_group(0, &only(stage, used, Some(&c)), &[]);
                pass.dispatch_workgroups(groups.0, groups.1, 1);
            }
        }
        pass.set_pipeline(&p.resolve);
        pass.set_bind_group(
            0,
            &only(
                &p.resolve,
                [true, true, true, true, true, true, true, false, true],
                None,
            ),
            &[],
        );
        pass.dispatch_workgroups(groups.0, groups.1, 1);
    }
}

/// The eye view's PCSS (`maps::shade` with `Method::Pcss` on the device):
/// the visibility per visible point of `e.f` (under an area light its
/// weighted visibility too), the front layer (user depth), and the
/// device's stage times.
fn shade_points(
    g: &Gpu,
    e: &EyeInputs,
    max_taps: u32,
    sw: &mut Stopwatch,
) -> Result<(MapShading, Timings)> {
    let f = e.f;
    let mut front = FrontLayer::new(g, f, e.tris, e.grid, e.bias, true)?;
    // maps::shade's receivers: the unbiased surface points, under an area
    // light (the sun's shading has no weights).
    let weigh: Option<Vec<GpuWeighPoint>> =
        (matches!(f.space, LightSpace::Area(_)) && !f.light_shape.is_point()).then(|| {
            ray_starts(&f.space, f.unit, &f.points, &f.normals)
                .par_iter()
                .map(|r| GpuWeighPoint::new(r.as_ref()))
                .collect()
        });
    sw.lap("setup");
    // The points and planes are the kernel's alone (`shade` reads their
    // bounds only).
    let grid = front.grid;
    let points = std::mem::take(&mut front.points.points);
    let planes = std::mem::take(&mut front.points.planes);
    front.shade(
        g,
        f,
        "softshadow eye pcss",
        2,
        || {
            PcssShading::points(
                g,
                &grid,
                f.light_shape,
                max_taps,
                0,
                &points,
                &planes,
                weigh.as_deref(),
            )
        },
        sw,
    )
}

impl Stage for PcssShading {
    fn record(
        &self,
        g: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        timer: &StageTimer,
        maps: &wgpu::Buffer,
    ) -> Result<()> {
        PcssShading::record(self, g, enc, timer, maps);
        Ok(())
    }

    fn outputs(&self) -> Vec<(&wgpu::Buffer, u64)> {
        vec![(&self.vis, self.vis_bytes)]
    }
}

/// PCSS's kernel: the front layer, in the maps of the light view (after the
/// receiver map) or rasterized for the eye view's points.
pub(super) struct PcssKernel;

impl GpuKernel for PcssKernel {
    fn light_view<'a>(
        &self,
        g: &'a Gpu,
        method: Method,
        i: LightViewInputs<'a>,
    ) -> Result<Option<MakeStage<'a>>> {
        let Method::Pcss(Pcss { max_taps }) = method else {
            return Err(mismatch(method));
        };
        Ok(Some(Box::new(move || {
            // The front layer follows the receiver map.
            let front = i.grid.len() as u32;
            let sh = PcssShading::maps(g, i.grid, i.occluder_grid, i.light_shape, max_taps, front)?;
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
        let Method::Pcss(Pcss { max_taps }) = method else {
            return Err(mismatch(method));
        };
        shade_points(g, inputs, max_taps, sw)
    }
}
