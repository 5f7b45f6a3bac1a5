//! The occluder-map methods on the GPU: per-row statistics of the occluder
//! layers (`row_stats`), then one invocation per receiver texel gathering the
//! micro-patches in reach (`gather.wgsl` + the method's file). The CPU twins
//! are `methods/gather.rs` with `methods/ssm.rs` and `methods/bitmask.rs`.

use super::dispatch::{bind, groups_1d, module, pipeline, uniform};
use crate::error::{Error, Result};
use crate::methods::Method;
use bytemuck::{Pod, Zeroable};
use std::sync::OnceLock;

pub const GATHER_SOURCE: &str = include_str!("gather.wgsl");
pub const SSM_SOURCE: &str = include_str!("ssm.wgsl");
pub const BITMASK_SOURCE: &str = include_str!("bitmask.wgsl");

/// The WGSL of the module that runs `method`: the shared gather part and the
/// method's own file.
pub fn module_source(method_source: &str) -> String {
    format!("{GATHER_SOURCE}\n{method_source}")
}

/// `GatherParams` of gather.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct GatherParams {
    pub rec_w: u32,
    pub rec_h: u32,
    pub occ_w: u32,
    pub occ_h: u32,
    pub n_layers: u32,
    pub layer0_offset: u32,
    pub layer_stride: u32,
    pub ax_rec_x: u32,
    pub ax_rec_y: u32,
    pub ax_col_x0s: u32,
    pub ax_row_y: u32,
    pub samples: u32,
    pub tx: f32,
    pub ty: f32,
    pub hw: f32,
    pub hh: f32,
    pub inv_half_lx: f32,
    pub inv_half_ly: f32,
    pub half_lx: f32,
    pub half_ly: f32,
    pub wx: f32,
    pub _pad0: u32,
    pub _pad1: u32,
    pub _pad2: u32,
}

/// `RowSpan` of gather.wgsl (written by the GPU; 16 bytes a row).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct RowSpan {
    pub w_max: f32,
    pub first: u32,
    pub last: u32,
    pub _pad: u32,
}

struct MethodPipelines {
    row_stats: wgpu::ComputePipeline,
    shade: wgpu::ComputePipeline,
}

/// The methods that run on the GPU, and the error for the others.
fn method_source(method: Method) -> Result<(&'static str, &'static str)> {
    match method {
        Method::Ssm => Ok(("ssm", SSM_SOURCE)),
        Method::Bitmask { .. } => Ok(("bitmask", BITMASK_SOURCE)),
        Method::Exact { .. } => Err(Error::invalid(
            "method",
            format!(
                "{:?} is not implemented on the GPU backend yet; use backend=\"cpu\" (GPU methods: \"ssm\", \"bitmask\")",
                method.name()
            ),
        )),
    }
}

/// Refuses a method the GPU cannot run, before any GPU work.
pub fn check_method(method: Method) -> Result<()> {
    method_source(method).map(|_| ())
}

fn pipelines(device: &wgpu::Device, method: Method) -> Result<&'static MethodPipelines> {
    static SSM: OnceLock<MethodPipelines> = OnceLock::new();
    static BITMASK: OnceLock<MethodPipelines> = OnceLock::new();
    let (name, source) = method_source(method)?;
    let cell = match method {
        Method::Ssm => &SSM,
        Method::Bitmask { .. } => &BITMASK,
        Method::Exact { .. } => unreachable!("method_source refused it"),
    };
    Ok(cell.get_or_init(|| {
        let m = module(device, name, &module_source(source));
        MethodPipelines {
            row_stats: pipeline(device, &m, "row_stats"),
            shade: pipeline(device, &m, name),
        }
    }))
}

/// The buffers a gather stage reads and writes.
pub struct GatherBuffers<'a> {
    pub maps: &'a wgpu::Buffer,
    pub rows: &'a wgpu::Buffer,
    pub layer_w_max: &'a wgpu::Buffer,
    pub axes: &'a wgpu::Buffer,
    pub vis: &'a wgpu::Buffer,
    /// The bitmask method's rank tables (None for the others).
    pub tables: Option<&'a wgpu::Buffer>,
}

/// The method's constant tables, as the shader reads them (bitmask's rank
/// tables), or None.
pub fn method_tables(method: Method) -> Option<Vec<u32>> {
    match method {
        Method::Bitmask { samples } => {
            Some(crate::methods::bitmask::Bitmask::new(samples).rank_tables())
        }
        _ => None,
    }
}

/// Records the row statistics pass body.
pub fn record_row_stats(
    device: &wgpu::Device,
    pass: &mut wgpu::ComputePass,
    method: Method,
    b: &GatherBuffers,
    params: &GatherParams,
) -> Result<()> {
    let p = pipelines(device, method)?;
    let u = uniform(device, "gather params", params);
    let bg = bind(
        device,
        &p.row_stats,
        &[Some(b.maps), Some(b.rows), Some(b.layer_w_max), Some(&u)],
    );
    pass.set_pipeline(&p.row_stats);
    pass.set_bind_group(0, &bg, &[]);
    let (x, y) = groups_1d(params.n_layers * params.occ_h, 64);
    debug_assert_eq!(y, 1, "rows x layers stay below 65535 x 64");
    pass.dispatch_workgroups(x, y, 1);
    Ok(())
}

/// Records the shading pass body: one invocation per receiver texel.
pub fn record_shade(
    device: &wgpu::Device,
    pass: &mut wgpu::ComputePass,
    method: Method,
    b: &GatherBuffers,
    params: &GatherParams,
) -> Result<()> {
    let p = pipelines(device, method)?;
    let u = uniform(device, "gather params", params);
    let bg = bind(
        device,
        &p.shade,
        &[
            Some(b.maps),
            Some(b.rows),
            Some(b.layer_w_max),
            Some(&u),
            Some(b.axes),
            Some(b.vis),
            b.tables,
        ],
    );
    pass.set_pipeline(&p.shade);
    pass.set_bind_group(0, &bg, &[]);
    pass.dispatch_workgroups(params.rec_w.div_ceil(8), params.rec_h.div_ceil(8), 1);
    Ok(())
}
