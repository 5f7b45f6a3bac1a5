//! The gather methods' shading stage on the GPU (`GatherKernel`'s light
//! view, `gather_points.rs`), shared by both entry points (meshes, depth
//! maps): from occluder and receiver maps already in a `maps` buffer
//! (receiver at 0, then the occluder layers) to the visibility, in two passes
//! ("row_stats", "shadow"). Bitmask with closed gaps also reads the layers'
//! corners (`gather::layer_corners`, made on the CPU from the maps).

use super::context::Gpu;
use super::dispatch::{storage, upload};
use super::gather::{self, GatherBuffers, GatherParams};
use super::light;
use super::method_kernel::Stage;
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::methods::{BitmaskKernel, Method};

/// Refuses maps (and accumulators, and the corners) that do not fit one
/// buffer binding, or offsets beyond u32.
pub fn check_size(
    g: &Gpu,
    method: Method,
    grid: &MapGrid,
    og: &MapGrid,
    n_layers: u32,
) -> Result<()> {
    let texels = grid.len() as u64 + n_layers as u64 * og.len() as u64;
    // The accumulators: a sum per layer (ssm) or a mask (bitmask) per receiver.
    let acc = gather::accumulator_words(method, n_layers) as u64 * grid.len() as u64;
    // The corners: 4 1/depths per occluder texel (bitmask, closed gaps).
    let corners = if gather::needs_corners(method) {
        4 * n_layers as u64 * og.len() as u64
    } else {
        0
    };
    let bytes = 4 * texels.max(acc).max(corners);
    if texels >= u32::MAX as u64 || bytes > g.max_storage_binding {
        return Err(Error::too_large(
            "resolution",
            format!(
                "the maps need {bytes} bytes in one GPU buffer; the device binds at most {}",
                g.max_storage_binding
            ),
        ));
    }
    Ok(())
}

/// Tangent coordinates the shaders read, computed in f64 like the CPU
/// kernels' tables (so both sides start from the same f32 values), and
/// their offsets.
fn axes(grid: &MapGrid, og: &MapGrid, light_shape: LightShape, p: &mut GatherParams) -> Vec<f32> {
    let mut data = Vec::new();
    p.ax_rec_x = data.len() as u32;
    data.extend((0..grid.width).map(|i| grid.x_of(i) as f32));
    p.ax_rec_y = data.len() as u32;
    data.extend((0..grid.height).map(|j| grid.y_of(j) as f32));
    p.ax_col_x0s = data.len() as u32;
    // As the CPU's `col_x0_scaled`: the f32 left edge, scaled in f64 (one
    // rounding from f64 differs from these two in the last bit now and then,
    // which moved a rank: a sample of one texel in 2000 on a 61-wide grid).
    data.extend(light::column_edges(og, light_shape));
    p.ax_row_y = data.len() as u32;
    data.extend((0..og.height).map(|j| og.y_of(j) as f32));
    data
}

pub(super) fn gather_params(
    grid: &MapGrid,
    og: &MapGrid,
    light_shape: LightShape,
    n_layers: u32,
    method: Method,
) -> GatherParams {
    let (hw, hh) = og.half_texel();
    // The same f32 values as methods/gather.rs's Kernel::new.
    let mut p = GatherParams {
        rec_w: grid.width as u32,
        rec_h: grid.height as u32,
        occ_w: og.width as u32,
        occ_h: og.height as u32,
        n_layers,
        layer0_offset: grid.len() as u32,
        layer_stride: og.len() as u32,
        samples: match method {
            Method::Bitmask(BitmaskKernel { samples, .. }) => samples,
            _ => 0,
        },
        counted: match method {
            Method::Bitmask(BitmaskKernel { samples, .. }) => {
                crate::methods::bitmask::counted_samples(
                    samples,
                    matches!(light_shape, LightShape::Disk { .. }),
                )
            }
            _ => 0,
        },
        disk: u32::from(matches!(light_shape, LightShape::Disk { .. })),
        tx: og.tx as f32,
        ty: og.ty as f32,
        hw: hw as f32,
        hh: hh as f32,
        ..Default::default()
    };
    light::set_half_light(&mut p, light_shape, hw);
    p
}

/// The buffers and parameters of the shading stage.
pub struct Shading {
    method: Method,
    params: GatherParams,
    chunks: u32,
    rows: wgpu::Buffer,
    layer_w_max: wgpu::Buffer,
    acc: wgpu::Buffer,
    axes: wgpu::Buffer,
    tables: Option<wgpu::Buffer>,
    corners: Option<wgpu::Buffer>,
    vis: wgpu::Buffer,
    vis_bytes: u64,
}

impl Shading {
    /// Uploads the axes (and the method's tables, and the layers' `corners`
    /// where the method reads them) and makes the buffers. `w_max` bounds
    /// the occluders' 1/depth (it sets the chunking; the corners widen it).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        g: &Gpu,
        method: Method,
        grid: &MapGrid,
        og: &MapGrid,
        light_shape: LightShape,
        n_layers: u32,
        w_max: f64,
        corners: Option<&gather::LayerCorners>,
    ) -> Shading {
        let device = &g.device;
        debug_assert_eq!(corners.is_some(), gather::needs_corners(method));
        let mut params = gather_params(grid, og, light_shape, n_layers, method);
        let ax = axes(grid, og, light_shape, &mut params);
        let w_max = corners.map_or(w_max, |c| w_max.max(c.w_max as f64));
        let (rows_per_chunk, chunks) = gather::chunking(og, light_shape, w_max, method);
        params.rows_per_chunk = rows_per_chunk;
        let acc_words = gather::accumulator_words(method, n_layers) as u64 * grid.len() as u64;
        let vis_bytes = grid.len() as u64 * 4;
        Shading {
            method,
            params,
            chunks,
            rows: storage(
                device,
                "row spans",
                n_layers as u64 * og.height as u64 * 16,
                wgpu::BufferUsages::empty(),
            ),
            layer_w_max: storage(
                device,
                "layer w max",
                n_layers as u64 * 4,
                wgpu::BufferUsages::COPY_DST,
            ),
            acc: storage(
                device,
                "accumulators",
                acc_words * 4,
                wgpu::BufferUsages::COPY_DST,
            ),
            axes: upload(device, "axes", &ax),
            tables: gather::method_tables(method, light_shape)
                .map(|t| upload(device, "method tables", &t)),
            corners: corners.map(|c| upload(device, "corners", &c.corners)),
            vis: storage(
                device,
                "visibility",
                vis_bytes,
                wgpu::BufferUsages::COPY_SRC,
            ),
            vis_bytes,
        }
    }
}

impl Stage for Shading {
    /// Records the passes "row_stats" and "shadow" reading `maps`.
    fn record(
        &self,
        g: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        timer: &StageTimer,
        maps: &wgpu::Buffer,
    ) -> Result<()> {
        let device = &g.device;
        enc.clear_buffer(&self.layer_w_max, 0, None);
        enc.clear_buffer(&self.acc, 0, None);
        let b = GatherBuffers {
            maps,
            rows: &self.rows,
            layer_w_max: &self.layer_w_max,
            axes: &self.axes,
            vis: &self.vis,
            tables: self.tables.as_ref(),
            acc: &self.acc,
            corners: self.corners.as_ref(),
        };
        {
            let mut pass = enc.begin_compute_pass(&timer.pass("row_stats"));
            gather::record_row_stats(device, &mut pass, self.method, &b, &self.params)?;
        }
        let mut pass = enc.begin_compute_pass(&timer.pass("shadow"));
        gather::record_shade(
            device,
            &mut pass,
            self.method,
            &b,
            &self.params,
            self.chunks,
        )
    }

    fn outputs(&self) -> Vec<(&wgpu::Buffer, u64)> {
        vec![(&self.vis, self.vis_bytes)]
    }
}
