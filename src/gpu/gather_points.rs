//! The gather methods (`ssm`, `bitmask`) on the GPU as one kernel,
//! `GatherKernel`: the light view's shading is `shading.rs`'s `Shading`
//! over the maps; the eye view's, at arbitrary points, is here.
//!
//! The eye view: the occluder layers (front, peeled, back) rasterized on
//! the device from the CPU's set-up triangles (`raster.wgsl`, bit for bit
//! the CPU's `maps::occluder_layers`), the biased points and their
//! tangent-plane bounds made on the CPU (`maps::shading_points`), sorted
//! and cut into groups of 64 as `methods::gather::visibility_points` does
//! (`point_order`, `point_group`), and shaded by the points mode of
//! `gather.wgsl` (one workgroup per group, the group's window from its
//! bounds, rows outward from its centre: `Kernel::shade_points`'
//! traversal). No hierarchy, f32 sums (configs resolve so on the GPU);
//! then, on the CPU, maps::shade's last step (`maps::finish`: each point
//! cut to its bound). Bitmask with closed gaps reads its micro-quads'
//! corners, made on the CPU from the layers read back
//! (`gather::layer_corners`, the CPU kernel's own function; stage
//! "corners"), so its layers and its shading are two submissions.

use super::context::Gpu;
use super::dispatch::{storage, upload};
use super::gather::{
    self, GatherBuffers, GpuGroup, GpuPoint, PointsBuffers, PointsParams, POINT_GROUP,
};
use super::irradiance_weight::GpuWeighPoint;
use super::light;
use super::method_kernel::{EyeInputs, GpuKernel, LightViewInputs, MakeStage, Stage};
use super::raster::{GpuTri, RasterInput};
use super::readback::{submit_and_read, visibility, with_error_scopes, words};
use super::refusals::fits;
use super::shading::{gather_params, Shading};
use super::timing::StageTimer;
use crate::error::{Error, Result};
use crate::eye::framing::Framed;
use crate::eye::maps;
use crate::eye::rays::ray_starts;
use crate::eye::{EyeMaps, MapShading};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::light_space::LightSpace;
use crate::methods::bitmask::Bitmask;
use crate::methods::gather::{point_group, point_order, POINTS_PER_GROUP};
use crate::methods::{BitmaskKernel, Input, LightPoint, Method};
use crate::raster::setup_triangles;
use crate::timing::{Stopwatch, Timings};
use rayon::prelude::*;

/// The gather methods' kernel; which module runs (ssm, bitmask's masks and
/// gaps) follows the method's options (`gather::Variant`).
pub(super) struct GatherKernel;

impl GpuKernel for GatherKernel {
    fn check(&self, method: Method) -> Result<()> {
        gather::check_method(method)
    }

    fn light_view<'a>(
        &self,
        g: &'a Gpu,
        method: Method,
        i: LightViewInputs<'a>,
    ) -> Result<Option<MakeStage<'a>>> {
        if gather::needs_corners(method) && i.corners.is_none() {
            return Ok(None);
        }
        Ok(Some(Box::new(move || {
            let sh = Shading::new(
                g,
                method,
                i.grid,
                i.occluder_grid,
                i.light_shape,
                i.layers,
                i.w_max,
                i.corners,
            );
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
        shade_points(g, method, inputs, sw)
    }
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

/// What the weighted resolve reads.
struct Weighing {
    /// Each sorted lane's surface point and tangent plane.
    points: Vec<GpuWeighPoint>,
    /// The bitmask's light samples.
    light_samples: Option<Vec<[f32; 4]>>,
}

/// The weighted resolve's inputs under an area light (as `maps::shade`'s
/// receivers) for the methods that weigh (`bitmask`, `ssm`); None for the
/// others and other lights.
fn weigh_inputs(method: Method, f: &Framed, order: &[u32], n_lanes: usize) -> Option<Weighing> {
    if !matches!(method, Method::Bitmask(_) | Method::Ssm(_))
        || !matches!(f.space, LightSpace::Area(_))
        || f.light_shape.is_point()
    {
        return None;
    }
    let starts = ray_starts(&f.space, f.unit, &f.points, &f.normals);
    let mut lanes: Vec<GpuWeighPoint> = order
        .par_iter()
        .map(|&n| GpuWeighPoint::new(starts[n as usize].as_ref()))
        .collect();
    lanes.resize(n_lanes, GpuWeighPoint::default());
    let light_samples = match method {
        Method::Bitmask(BitmaskKernel { samples, gaps, .. }) => {
            let disk = matches!(f.light_shape, LightShape::Disk { .. });
            let b = Bitmask::for_shape(samples, gaps, None, disk);
            Some(b.light_samples(f.light_shape.half_extent()))
        }
        _ => None,
    };
    Some(Weighing {
        points: lanes,
        light_samples,
    })
}

/// The gather methods in the eye view: `maps::shade`'s visibility per
/// point (and the bitmask's weighted visibility under an area light) and
/// maps, and the device's stage times.
fn shade_points(
    g: &Gpu,
    method: Method,
    e: &EyeInputs,
    sw: &mut Stopwatch,
) -> Result<(MapShading, Timings)> {
    debug_assert!(method.reads_input(Input::OccluderLayers));
    let (f, tris, grid, passes, bias) = (e.f, e.tris, e.grid, e.passes, e.bias);
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
    let sp = f.shading_points(&grid, bias, false);
    let valid = &sp.points;
    let order = point_order(&grid, valid);
    let sorted: Vec<LightPoint> = order.iter().map(|&n| valid[n as usize]).collect();
    let (lanes, groups) = point_lanes(&sorted);
    let n_points = lanes.len();
    let weigh = weigh_inputs(method, f, &order, n_points);
    let ssm = matches!(method, Method::Ssm(_));
    // Weighed, the SSM's weighted sums follow its plain ones.
    let acc_words = gather::accumulator_words(method, passes) as u64
        * n_points as u64
        * (1 + (ssm && weigh.is_some()) as u64);
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
    // The weighted visibility follows the plain one.
    let vis_bytes = n_points as u64 * 4 * (1 + weigh.is_some() as u64);
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
        let tables = gather::method_tables(method, f.light_shape)
            .map(|t| upload(device, "method tables", &t));
        let vis = storage(
            device,
            "visibility",
            vis_bytes,
            wgpu::BufferUsages::COPY_SRC,
        );
        let points_buf = upload(device, "points", &lanes);
        let groups_buf = upload(device, "point groups", &groups);
        // The SSM's chunks bind the weights even unweighed: one entry then.
        let weigh_points = match &weigh {
            Some(w) => Some(upload(device, "weighed points", &w.points)),
            None => ssm.then(|| upload(device, "weighed points", &[GpuWeighPoint::default()])),
        };
        let light_samples = weigh
            .as_ref()
            .and_then(|w| w.light_samples.as_ref())
            .map(|s| upload(device, "light samples", s));
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
                    weigh: weigh.is_some() as u32,
                },
                weigh_points: weigh_points.as_ref(),
                light_samples: light_samples.as_ref(),
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
    let unsort = |from: &[f32]| {
        let mut v = vec![1f32; valid.len()];
        for (&n, &s) in order.iter().zip(from) {
            v[n as usize] = s;
        }
        v
    };
    let mut v = unsort(&shaded[..n_points]);
    // As maps::shade.
    maps::finish(&mut v, &sp.bound);
    let weighted = weigh.is_some().then(|| {
        let mut w = unsort(&shaded[n_points..]);
        maps::finish_weighted(&mut w, &sp.bound);
        w
    });
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
    Ok((
        MapShading {
            visibility: v,
            weighted,
            maps: EyeMaps { grid, layers },
        },
        out.device_timings,
    ))
}

/// Points per group and per workgroup agree (gather.wgsl's POINTS_GROUP).
const _: () = assert!(POINT_GROUP as usize == POINTS_PER_GROUP);
