//! The occluder-map methods on the GPU: per-row statistics of the occluder
//! layers (`row_stats`), then one invocation per receiver texel gathering the
//! micro-patches in reach (`gather.wgsl` + the method's file). The CPU twins
//! are `methods/gather.rs` with `methods/ssm.rs` and `methods/bitmask.rs`.
//! Points mode (the eye view): one workgroup per group of 64 sorted points,
//! twin of `visibility_points` (`record_shade_points`).
//!
//! `bitmask` has four modules (`Variant`): masks of 8 u32 words (up to 256
//! samples) or 32 (1024 samples), set in the WGSL by `bitmask_source`, and
//! flat micro-patches (`gaps="open"`, `bitmask_open.wgsl`) or connected
//! micro-quads (`gaps="closed"`, `bitmask_closed.wgsl`). The quads' corner
//! 1/depths come from the CPU kernel's own function (`layer_corners`: the
//! same bits), uploaded as one more buffer; row_stats widens the rows' bounds
//! to them as the CPU's `Layer::connect` does.

use super::dispatch::{bind, groups_1d, module, pipeline, uniform};
use crate::error::{Error, Result};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::methods::bitmask::Gaps;
use crate::methods::ssm::Precision;
use crate::methods::{BitmaskKernel, Method, SsmKernel};
use bytemuck::{Pod, Zeroable};
use rayon::prelude::*;
use std::sync::OnceLock;

/// gather.wgsl after the receivers' weights its weighted resolves read.
pub const GATHER_SOURCE: &str = concat!(
    include_str!("irradiance_weight.wgsl"),
    "\n",
    include_str!("gather.wgsl")
);
pub const SSM_SOURCE: &str = concat!(
    include_str!("disk_overlap.wgsl"),
    "\n",
    include_str!("ssm.wgsl")
);
pub const BITMASK_SOURCE: &str = include_str!("bitmask.wgsl");
pub const BITMASK_OPEN_SOURCE: &str = include_str!("bitmask_open.wgsl");
pub const BITMASK_CLOSED_SOURCE: &str = include_str!("bitmask_closed.wgsl");

/// The WGSL of the module that runs `method`: the shared gather part and the
/// method's own file.
pub fn module_source(method_source: &str) -> String {
    format!("{GATHER_SOURCE}\n{method_source}")
}

/// bitmask.wgsl's line that sets the mask's words.
const WORDS_LINE: &str = "const WORDS: u32 = 8u;";

/// The bitmask module with masks of `words` u32 words and the `gaps`
/// option's add_texel.
pub fn bitmask_source(words: u32, gaps: Gaps) -> String {
    assert!(
        BITMASK_SOURCE.matches(WORDS_LINE).count() == 1 && words.is_multiple_of(4),
        "bitmask.wgsl sets WORDS once, to a multiple of 4"
    );
    let body = BITMASK_SOURCE.replace(WORDS_LINE, &format!("const WORDS: u32 = {words}u;"));
    let tail = match gaps {
        Gaps::Open => BITMASK_OPEN_SOURCE,
        Gaps::Closed => BITMASK_CLOSED_SOURCE,
    };
    module_source(&format!("{body}\n{tail}"))
}

/// u32 words of a bitmask mask with `samples` light samples, as
/// `Bitmask::rank_tables` lays its entries out: the CPU's 4 u64 up to 256
/// samples, 16 u64 for 1024.
pub fn mask_words(samples: u32) -> u32 {
    if samples <= 256 {
        8
    } else {
        32
    }
}

/// The shader modules of the occluder-map methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    Ssm,
    Bitmask { words: u32, gaps: Gaps },
}

impl Variant {
    /// Every variant, in the order of `index`.
    #[cfg(test)]
    pub const ALL: [Variant; 5] = [
        Variant::Ssm,
        Variant::Bitmask {
            words: 8,
            gaps: Gaps::Open,
        },
        Variant::Bitmask {
            words: 8,
            gaps: Gaps::Closed,
        },
        Variant::Bitmask {
            words: 32,
            gaps: Gaps::Open,
        },
        Variant::Bitmask {
            words: 32,
            gaps: Gaps::Closed,
        },
    ];

    pub fn index(self) -> usize {
        match self {
            Variant::Ssm => 0,
            Variant::Bitmask { words, gaps } => {
                1 + 2 * (words == 32) as usize + (gaps == Gaps::Closed) as usize
            }
        }
    }

    /// The entry points' prefix ("ssm", "bitmask").
    pub fn name(self) -> &'static str {
        match self {
            Variant::Ssm => "ssm",
            Variant::Bitmask { .. } => "bitmask",
        }
    }

    pub fn source(self) -> String {
        match self {
            Variant::Ssm => module_source(SSM_SOURCE),
            Variant::Bitmask { words, gaps } => bitmask_source(words, gaps),
        }
    }

    /// Whether the module reads the corners buffer (binding 13).
    pub fn reads_corners(self) -> bool {
        matches!(
            self,
            Variant::Bitmask {
                gaps: Gaps::Closed,
                ..
            }
        )
    }
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
    pub rows_per_chunk: u32,
    /// The light samples on the light (bitmask): `samples`, or a disk's.
    pub counted: u32,
    /// 1 under a disk light (ssm clips its micro-patches to it).
    pub disk: u32,
}

/// `ChunkParams` of gather.wgsl: which layer and chunk of rows a dispatch adds.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable)]
pub struct ChunkParams {
    pub layer: u32,
    pub chunk: u32,
    pub _pad0: u32,
    pub _pad1: u32,
}

/// Points per workgroup in points mode (gather.wgsl's POINTS_GROUP): the
/// CPU's group of `visibility_points`.
pub const POINT_GROUP: u32 = 64;
const _: () = assert!(POINT_GROUP as usize == crate::methods::gather::POINTS_PER_GROUP);

/// `PointsParams` of gather.wgsl (points mode).
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct PointsParams {
    pub n_points: u32,
    pub steps_per_chunk: u32,
    pub chunks: u32,
    /// 1 where the points are weighed (`PointsBuffers::weigh_points`).
    pub weigh: u32,
}

/// `GatherPoint` of gather.wgsl: a lane's tangent (x, y) and 1/depth.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct GpuPoint {
    pub x: f32,
    pub y: f32,
    pub wr: f32,
    pub live: u32,
}

/// `GroupBounds` of gather.wgsl: a group's bounds over its active lanes.
#[repr(C)]
#[derive(Debug, Clone, Copy, Pod, Zeroable, Default)]
pub struct GpuGroup {
    pub x_lo: f32,
    pub x_hi: f32,
    pub y_lo: f32,
    pub y_hi: f32,
    pub wr_min: f32,
    pub live: u32,
    pub _pad0: u32,
    pub _pad1: u32,
}

/// Loop iterations we let one invocation run per dispatch: half of lavapipe's
/// limit of 65535 (llvmpipe's loop limiter counts every iteration of every
/// loop of an invocation), leaving room for the loops around the texel loop.
const ITERATION_BUDGET: usize = 32768;

/// How the rows in reach are cut into chunks: rows per chunk and the number
/// of chunks that covers any receiver's rows. `w_max` bounds the occluders'
/// 1/depth (from their vertices: 1/Z is linear over a triangle, so its
/// largest value is at a vertex), which bounds how far a micro-patch reaches.
pub fn chunking(og: &MapGrid, light_shape: LightShape, w_max: f64, method: Method) -> (u32, u32) {
    let (hw, hh) = og.half_texel();
    // Texels in reach along a row (rows in reach along a column): a patch
    // reaches half_texel + (L/2) w_max in tangent units, and the rounding of
    // both ends adds up to 3 texels.
    let reach = |half_texel: f64, half_light: f64, n: usize| -> usize {
        let t = (1.0 + half_light * w_max / half_texel).ceil() + 3.0;
        if t.is_finite() {
            (t as usize).min(n)
        } else {
            n
        }
    };
    let [hx, hy] = light_shape.half_extent();
    let cols = reach(hw, hx, og.width);
    let rows = reach(hh, hy, og.height);
    let per_texel = texel_cost(method);
    let rows_per_chunk = (ITERATION_BUDGET / (cols * per_texel + 2)).max(1);
    (rows_per_chunk as u32, rows.div_ceil(rows_per_chunk) as u32)
}

/// Iterations one texel costs the method's loop: the texel, and the
/// bitmask's mask words as vec4s (bitmask.wgsl's `mark`; 2 for 8 words, 8 for
/// 32), in case the compiler keeps them a loop.
pub fn texel_cost(method: Method) -> usize {
    match method {
        Method::Bitmask(BitmaskKernel { samples, .. }) => mask_words(samples) as usize / 4 + 1,
        _ => 1,
    }
}

/// Points mode: outward steps (two occluder rows each) per chunk when a
/// group's window is at most `cols` columns wide, and the chunks that cover
/// `steps` steps.
pub fn points_chunking(cols: usize, steps: usize, method: Method) -> (u32, u32) {
    let per_step = 2 * (cols * texel_cost(method) + 2);
    let steps_per_chunk = (ITERATION_BUDGET / per_step).max(1);
    (
        steps_per_chunk as u32,
        steps.div_ceil(steps_per_chunk).max(1) as u32,
    )
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
    /// Adds one chunk of one layer to the accumulators.
    chunk: wgpu::ComputePipeline,
    /// Accumulators -> visibility.
    resolve: wgpu::ComputePipeline,
}

/// The methods that run on occluder maps, and the error for the others
/// (`exact` traces triangles: `exact.rs`, never through here).
/// The GPU kernels have neither the occluder hierarchy nor the other
/// precisions of the CPU's ssm (its one-level f32 sum is the CPU's
/// two-level one up to rounding).
fn variant(method: Method) -> Result<Variant> {
    let no_hierarchy = || {
        Error::invalid(
            "hierarchy",
            "the GPU backend has no occluder hierarchy yet; use backend=\"cpu\"",
        )
    };
    match method {
        Method::Ssm(SsmKernel {
            hierarchy: true, ..
        })
        | Method::Bitmask(BitmaskKernel {
            hierarchy: true, ..
        }) => Err(no_hierarchy()),
        Method::Ssm(SsmKernel {
            precision: Precision::F32,
            ..
        }) => Ok(Variant::Ssm),
        Method::Ssm(SsmKernel { precision, .. }) => Err(Error::invalid(
            "precision",
            format!("the GPU backend sums in f32 only, got {precision:?}; use backend=\"cpu\""),
        )),
        Method::Bitmask(BitmaskKernel { samples, gaps, .. }) => Ok(Variant::Bitmask {
            words: mask_words(samples),
            gaps,
        }),
        Method::Exact(_) => Err(Error::invalid(
            "method",
            format!(
                "{:?} does not shade occluder maps (GPU map methods: \"ssm\", \"bitmask\")",
                method.name()
            ),
        )),
        _ => Err(Error::invalid(
            "backend",
            format!(
                "{:?} runs on the CPU only in this version; use backend=\"cpu\"",
                method.name()
            ),
        )),
    }
}

/// Refuses options of a gather method the GPU has no module for, before
/// any GPU work.
pub fn check_method(method: Method) -> Result<()> {
    variant(method).map(|_| ())
}

/// Whether the method's kernel reads the occluder layers' corners
/// (`layer_corners`: bitmask with closed gaps).
pub fn needs_corners(method: Method) -> bool {
    variant(method).is_ok_and(Variant::reads_corners)
}

fn pipelines(device: &wgpu::Device, method: Method) -> Result<&'static MethodPipelines> {
    static CELLS: [OnceLock<MethodPipelines>; 5] = [const { OnceLock::new() }; 5];
    let v = variant(method)?;
    let name = v.name();
    Ok(CELLS[v.index()].get_or_init(|| {
        let m = module(device, name, &v.source());
        MethodPipelines {
            row_stats: pipeline(device, &m, "row_stats"),
            chunk: pipeline(device, &m, name),
            resolve: pipeline(device, &m, &format!("{name}_resolve")),
        }
    }))
}

struct PointsPipelines {
    /// Adds one chunk of one layer to the points' accumulators.
    chunk: wgpu::ComputePipeline,
    resolve: wgpu::ComputePipeline,
    /// The weighted resolve (`{name}_points_weigh`).
    weigh: wgpu::ComputePipeline,
}

fn points_pipelines(device: &wgpu::Device, method: Method) -> Result<&'static PointsPipelines> {
    static CELLS: [OnceLock<PointsPipelines>; 5] = [const { OnceLock::new() }; 5];
    let v = variant(method)?;
    let name = v.name();
    Ok(CELLS[v.index()].get_or_init(|| {
        let m = module(device, name, &v.source());
        PointsPipelines {
            chunk: pipeline(device, &m, &format!("{name}_points")),
            resolve: pipeline(device, &m, &format!("{name}_points_resolve")),
            weigh: pipeline(device, &m, &format!("{name}_points_weigh")),
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
    /// Per-receiver accumulators, zeroed (`accumulator_words` u32 a receiver).
    pub acc: &'a wgpu::Buffer,
    /// The occluder layers' corners (`layer_corners`), where the method reads
    /// them (`needs_corners`).
    pub corners: Option<&'a wgpu::Buffer>,
}

impl GatherBuffers<'_> {
    /// `buffers` for bindings 0, 1, ... with the corners at binding 13 where
    /// the module reads them.
    fn with_corners<'b>(
        &'b self,
        method: Method,
        mut buffers: Vec<Option<&'b wgpu::Buffer>>,
    ) -> Result<Vec<Option<&'b wgpu::Buffer>>> {
        if variant(method)?.reads_corners() {
            let c = self.corners.ok_or_else(|| {
                Error::gpu("bitmask with closed gaps needs the occluder layers' corners")
            })?;
            buffers.resize(CORNERS_BINDING, None);
            buffers.push(Some(c));
        }
        Ok(buffers)
    }
}

/// bitmask_closed.wgsl's binding of the corners.
const CORNERS_BINDING: usize = 13;

/// u32 words of accumulator per receiver texel: a sum per layer (ssm), or
/// one mask (bitmask: `mask_words`).
pub fn accumulator_words(method: Method, n_layers: u32) -> u32 {
    match method {
        Method::Bitmask(BitmaskKernel { samples, .. }) => mask_words(samples),
        _ => n_layers,
    }
}

/// The method's constant tables for a light of `light`, as the shader
/// reads them (bitmask's rank tables: a disk's hold its samples only), or
/// None.
pub fn method_tables(method: Method, light: LightShape) -> Option<Vec<u32>> {
    match method {
        Method::Bitmask(BitmaskKernel { samples, gaps, .. }) => {
            let disk = matches!(light, LightShape::Disk { .. });
            let t = crate::methods::bitmask::Bitmask::for_shape(samples, gaps, None, disk)
                .rank_tables();
            // x_ge and y_ge, S + 1 entries each of mask_words words.
            assert_eq!(
                t.len(),
                2 * (samples as usize + 1) * mask_words(samples) as usize
            );
            Some(t)
        }
        _ => None,
    }
}

/// The connected micro-quads' corner 1/depths of every occluder layer
/// (bitmask with closed gaps), as bitmask_closed.wgsl reads them: layer
/// after layer, 4 per texel; and the largest of them.
pub struct LayerCorners {
    pub corners: Vec<[f32; 4]>,
    pub w_max: f32,
}

/// The corners of the occluder depth `layers` on `og`, made by the CPU
/// kernel's own function with its inputs (`Kernel::new` at level 0: the
/// texels' 1/depth as `Layer::from_depth` takes it, a texel's tangent size
/// 2 half_texel in f64 then f32), so the GPU reads the CPU's bits.
pub fn layer_corners(layers: &[&[f32]], og: &MapGrid) -> LayerCorners {
    let (hw, hh) = og.half_texel();
    // Kernel::new's (2 hw f) as f32 with f = 1 at level 0.
    let (dx, dy) = ((2.0 * hw * 1.0) as f32, (2.0 * hh * 1.0) as f32);
    let mut corners = Vec::with_capacity(layers.len() * og.len());
    for depth in layers {
        debug_assert_eq!(depth.len(), og.len());
        let w = crate::methods::gather::corners::inverse_depth(depth);
        corners.extend(crate::methods::gather::corners::corners(
            &w, og.width, og.height, dx, dy,
        ));
    }
    let w_max = corners
        .par_iter()
        .map(|c| c.iter().fold(0f32, |m, &x| m.max(x)))
        .reduce(|| 0.0, f32::max);
    LayerCorners { corners, w_max }
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
        &b.with_corners(
            method,
            vec![Some(b.maps), Some(b.rows), Some(b.layer_w_max), Some(&u)],
        )?,
    );
    pass.set_pipeline(&p.row_stats);
    pass.set_bind_group(0, &bg, &[]);
    let (x, y) = groups_1d(params.n_layers * params.occ_h, 64);
    debug_assert_eq!(y, 1, "rows x layers stay below 65535 x 64");
    pass.dispatch_workgroups(x, y, 1);
    Ok(())
}

/// Records the shading pass body: for every layer and chunk of rows, one
/// dispatch adding it to the accumulators (one invocation per receiver
/// texel), then the resolve into visibility.
pub fn record_shade(
    device: &wgpu::Device,
    pass: &mut wgpu::ComputePass,
    method: Method,
    b: &GatherBuffers,
    params: &GatherParams,
    chunks: u32,
) -> Result<()> {
    let p = pipelines(device, method)?;
    let u = uniform(device, "gather params", params);
    let groups = (params.rec_w.div_ceil(8), params.rec_h.div_ceil(8));
    pass.set_pipeline(&p.chunk);
    for layer in 0..params.n_layers {
        for chunk in 0..chunks {
            let c = uniform(
                device,
                "chunk params",
                &ChunkParams {
                    layer,
                    chunk,
                    _pad0: 0,
                    _pad1: 0,
                },
            );
            let bg = bind(
                device,
                &p.chunk,
                &b.with_corners(
                    method,
                    vec![
                        Some(b.maps),
                        Some(b.rows),
                        Some(b.layer_w_max),
                        Some(&u),
                        Some(b.axes),
                        None,
                        b.tables,
                        Some(b.acc),
                        Some(&c),
                    ],
                )?,
            );
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
    }
    let bg = bind(
        device,
        &p.resolve,
        &[
            Some(b.maps),
            None,
            None,
            Some(&u),
            Some(b.axes),
            Some(b.vis),
            None,
            Some(b.acc),
        ],
    );
    pass.set_pipeline(&p.resolve);
    pass.set_bind_group(0, &bg, &[]);
    pass.dispatch_workgroups(groups.0, groups.1, 1);
    Ok(())
}

/// The points-mode buffers beside `GatherBuffers`: the sorted points, their
/// groups' bounds, the status word (zeroed) and the points' parameters
/// (`params.chunks` dispatches per layer).
pub struct PointsBuffers<'a> {
    pub points: &'a wgpu::Buffer,
    pub groups: &'a wgpu::Buffer,
    pub status: &'a wgpu::Buffer,
    pub params: PointsParams,
    /// The sorted points' `GpuWeighPoint`s where `params.weigh` (one unread
    /// entry where not: the SSM's chunks bind it always). Weighed, the
    /// weighted resolve writes `vis[n_points + k]`, so `vis` holds 2
    /// n_points, and the SSM's accumulators twice its layers' sums.
    pub weigh_points: Option<&'a wgpu::Buffer>,
    /// The bitmask's light samples (`Bitmask::light_samples`), weighed.
    pub light_samples: Option<&'a wgpu::Buffer>,
}

/// Records the points-mode shading pass body: for every layer and chunk of
/// outward steps, one dispatch (a workgroup per group of points) adding it
/// to the accumulators, then the resolve into visibility (one value per
/// sorted point in `b.vis`).
pub fn record_shade_points(
    device: &wgpu::Device,
    pass: &mut wgpu::ComputePass,
    method: Method,
    b: &GatherBuffers,
    params: &GatherParams,
    pts: &PointsBuffers,
) -> Result<()> {
    let p = points_pipelines(device, method)?;
    let u = uniform(device, "gather params", params);
    let pu = uniform(device, "points params", &pts.params);
    let groups = groups_1d(pts.params.n_points, POINT_GROUP);
    let reads_weigh_points = variant(method)? == Variant::Ssm;
    pass.set_pipeline(&p.chunk);
    for layer in 0..params.n_layers {
        for chunk in 0..pts.params.chunks {
            let c = uniform(
                device,
                "chunk params",
                &ChunkParams {
                    layer,
                    chunk,
                    _pad0: 0,
                    _pad1: 0,
                },
            );
            let mut buffers = b.with_corners(
                method,
                vec![
                    Some(b.maps),
                    Some(b.rows),
                    Some(b.layer_w_max),
                    Some(&u),
                    Some(b.axes),
                    None,
                    b.tables,
                    Some(b.acc),
                    Some(&c),
                    Some(&pu),
                    Some(pts.points),
                    Some(pts.groups),
                    Some(pts.status),
                ],
            )?;
            // The SSM's chunks read the points' weights (an unread entry
            // where not weighed).
            if reads_weigh_points {
                buffers.resize(WEIGH_BINDING, None);
                buffers.push(pts.weigh_points);
            }
            let bg = bind(device, &p.chunk, &buffers);
            pass.set_bind_group(0, &bg, &[]);
            pass.dispatch_workgroups(groups.0, groups.1, 1);
        }
    }
    let bg = bind(
        device,
        &p.resolve,
        &[
            None,
            None,
            None,
            Some(&u),
            None,
            Some(b.vis),
            None,
            Some(b.acc),
            None,
            Some(&pu),
            Some(pts.points),
        ],
    );
    pass.set_pipeline(&p.resolve);
    pass.set_bind_group(0, &bg, &[]);
    pass.dispatch_workgroups(groups.0, groups.1, 1);
    if pts.params.weigh != 0 {
        let weigh_points = pts.weigh_points.ok_or_else(|| {
            Error::gpu("weighing without the points' weights (a bug: please report it)")
        })?;
        let mut buffers = vec![None; WEIGH_BINDING];
        buffers[3] = Some(&u);
        buffers[5] = Some(b.vis);
        buffers[7] = Some(b.acc);
        buffers[9] = Some(&pu);
        buffers[10] = Some(pts.points);
        buffers.push(Some(weigh_points));
        if matches!(variant(method)?, Variant::Bitmask { .. }) {
            buffers.push(Some(pts.light_samples.ok_or_else(|| {
                Error::gpu("the bitmask weighs without its samples (a bug: please report it)")
            })?));
        }
        let bg = bind(device, &p.weigh, &buffers);
        pass.set_pipeline(&p.weigh);
        pass.set_bind_group(0, &bg, &[]);
        pass.dispatch_workgroups(groups.0, groups.1, 1);
    }
    Ok(())
}

/// gather.wgsl's binding of the weighed points (bitmask.wgsl's light
/// samples follow).
const WEIGH_BINDING: usize = 14;
