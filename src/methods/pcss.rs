//! Percentage-closer soft shadows (Fernando 2005, "Percentage-Closer Soft
//! Shadows", SIGGRAPH 2005 Sketches): a blocker search, a penumbra estimate
//! from the blockers' average depth, and percentage-closer filtering
//! (Reeves et al. 1987; see `pcf.rs`) over a box of that size.
//!
//! Geometry, in kernel light space: the light is the rectangle
//! [-Lu/2, Lu/2] x [-Lv/2, Lv/2] in the plane z = 0; a point has tangent
//! coordinates t = (x/z, y/z) and planar depth z. The segment from a receiver
//! point R (tangent t_r, depth z_r) to a light point l (in z = 0) is
//! l + s (R - l), s in [0, 1]; at depth z (s = z / z_r) its tangent is
//!
//! ```text
//!     t(z) = l / z + t_r - l / z_r = t_r + l (1/z - 1/z_r).
//! ```
//!
//! So the occluder points at depth z that hide part of the light from R are
//! those whose tangent lies in the box t_r ± (L/2)(1/z - 1/z_r) (per axis,
//! Lu along x, Lv along y), and l -> t(z) is linear: the fraction of the
//! light hidden by occluders all at one depth z_o is the fraction of that box
//! they cover.
//!
//! 1. Blocker search. Occluders lie at depths z >= z_near, the nearest depth
//!    in the map (computed once per map), and the box grows as z falls, so
//!    every occluder that can hide part of the light from R lies within the
//!    search box t_r ± h_s, h_s = (L/2)(1/z_near - 1/z_r). The blockers are
//!    the map's texels in that box nearer than the receiver (depth d with
//!    0 < d < z_r, `pcf::occludes`); z_avg is their mean depth, each texel
//!    weighted by its overlap with the box (the same weights as the filter
//!    below). No blocker (or z_r <= z_near): visibility exactly 1.
//! 2. Penumbra estimate. Fernando's w_p = L (d_r - d_b) / d_b is the penumbra
//!    width on the light's side; mapped into the shadow map by the relation
//!    above it is the filter box t_r ± h_f, h_f = (L/2)(1/z_avg - 1/z_r).
//! 3. Filtering. Visibility is the box filter of the binary test "not
//!    occluded" (`!occludes(front, z_r)`, i.e. front >= z_r) over that box:
//!    every texel weighted by its overlap with the box (the exact box filter
//!    of the piecewise-constant map), the box's part outside the map lit.
//!
//! For a planar occluder parallel to the light at one depth z_o over a
//! parallel receiver this is exact: every blocker has depth z_o, so
//! z_avg = z_o and the filter box is exactly the set of occluder tangents
//! that hide the light; the covered fraction of the box is the hidden
//! fraction of the light (a straight edge gives the true linear ramp, a
//! rectangle the product of two ramps). With the occluder's edges on texel
//! edges only rounding remains (`plate_case` test). Elsewhere the method
//! makes Fernando's approximations: one average blocker depth per receiver,
//! and no account of occluders hiding one another.
//!
//! Under a disk light of radius ρ the same map takes the disk to the disk
//! t_r ± ρ (1/z - 1/z_r): both boxes become the ellipses inscribed in them
//! (circles when the texels are square), each cell weighted by its overlap
//! with the ellipse (`pcf_disk.rs`), and the plate case stays exact.
//!
//! Kernel details (both boxes, per axis, in texels of the occluder grid;
//! `pcf::box_filter` and `pcf::Axis`):
//! * A half-width below half a texel is raised to half a texel: the filter
//!   over one texel is the 2x2 bilinear PCF of the hard test (the limit of a
//!   small light or a blocker just above the receiver); the search box then
//!   reads the texels that bilinear filter reads.
//! * Bounded work, m = `max_taps` (clamped to 1..=MAX_TAPS): when the box
//!   overlaps at most m texels along an axis each is read with its exact
//!   overlap weight; otherwise its part inside the map is cut into m equal
//!   strata, one tap at each stratum's centre, the tap bilinear between its
//!   two nearest texels, weight (stratum width) / (box width). So a stage
//!   takes at most m x m taps per point (2m x 2m texel reads), still area
//!   weighted; the error is of the order of a stratum's share, 1/m, near
//!   an edge (measured on `plate_case`: 0.019 with 12 taps at 64², 0.21 with
//!   4 taps at 128²; 0 with 32).
//! * A light of size (0, 0) is a point light: the hard test of
//!   `point_light.rs` (what the pipeline runs for it). A non-finite or
//!   negative size component counts as 0 along that axis (an infinite one as
//!   a box far wider than the map, i.e. visibility 1).
//!
//! Only the front layer (`occluder_layers[0]`) is read.
//!
//! Receiver planes (the eye view). There every surface is an occluder, so
//! the front layer holds the receiver's own surface, and the boxes, many
//! texels wide, reach where a surface sloped to the light lies nearer the
//! light than the point: tested at the point's depth it counts as its own
//! blocker (measured: 48.7% of the lit pixels of shelf_with_objects darkened
//! at 320x240). `visibility_on_planes` tests each texel at the depth of the
//! point's tangent plane there instead (`plane_depth`; the receiver plane
//! depth bias of `geom/plane_gradient.rs`): 1/z is linear in the map's
//! pixel coordinates over a plane, z_k = z / (1 + z (a ox + b oy)), (a, b)
//! = ∂(1/z)/∂(px, py) and (ox, oy) the texel centre's offset from the
//! point. A plane of (0, 0) is the point's own depth (the light view).
//!
//! The eye view's shaded image weighs each filter cell by its light
//! point's share of the receiver's irradiance (`weighted_on_planes`,
//! `pcss_weighted.rs`): the scaling above says which light point a cell
//! stands for.
//!
//! Its config (`PcssConfig` and its `MethodSpec`: name, string form,
//! resolution, capabilities row) is at the end of this file.

use super::config::{
    check_resolution, occluder_resolution_option, resolve_maps, CallContext, LooseOptions,
    MethodSpec,
};
use super::info::{Kind, MethodInfo, OptionInfo, Value};
use super::inputs::{is_receiver, MIN_RECEIVERS};
use super::keywords::{count, resolution, KeywordForm, Keywords};
use super::pcf::{self, occludes, Axis, Border};
use super::pcf_disk;
use super::pcss_weighted::{weighted_visibility, Weigh};
use super::Input;
use super::{point_light, EyePoints, LightPoint, ShadowInputs, ShadowMethod};
use crate::backend::Backend;
use crate::error::{Error, Result};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::plane_gradient::{plane_depth, split, Plane};
use crate::trace::shadow_rays::RayOrigin;
use rayon::prelude::*;

/// The default taps per axis per stage (at most 16 x 16 taps per stage per
/// point). Measured against 256-sample `exact` (light view at 256², and the
/// eye scenes at 320x240): 16 taps are within 1% of 32's error on every
/// scene at a quarter of the time or less; 8 lose up to 10% (contact_boxes)
/// and 4 up to 40%.
pub const DEFAULT_MAX_TAPS: u32 = 16;

/// The most taps per axis a configuration may ask for (256 x 256 taps per
/// stage per point); larger values are clamped to it, 0 counts as 1.
pub const MAX_TAPS: u32 = pcf::MAX_TAPS;

/// PCSS with at most `max_taps` x `max_taps` taps per stage per point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Pcss {
    pub max_taps: u32,
}

impl Default for Pcss {
    fn default() -> Self {
        Pcss {
            max_taps: DEFAULT_MAX_TAPS,
        }
    }
}

/// What every point reads: the front map and the per-map constants.
struct Kernel<'a> {
    grid: MapGrid,
    front: &'a [f32],
    /// The nearest occluder depth in the map (inf when it holds none).
    z_near: f32,
    /// L/2 per axis divided by the texel's tangent width: (1/z - 1/z_r)
    /// times this is a half-width in texels.
    half_per_w: [f64; 2],
    max_taps: u32,
    /// A disk light: both boxes are the ellipses inscribed in them
    /// (`pcf_disk`).
    disk: bool,
}

/// A light size component usable in the kernel: NaN and negatives are 0.
fn size_component(l: f64) -> f64 {
    if l > 0.0 {
        l
    } else {
        0.0
    }
}

/// L/2 per axis divided by the texel's tangent width on `grid`, light sizes
/// as the kernel reads them (`size_component`): (1/z - 1/z_r) times this is
/// a box's half-width in texels. The GPU twin (src/gpu/pcss.rs) reads the same.
pub(crate) fn half_per_w(grid: &MapGrid, light_shape: LightShape) -> [f64; 2] {
    let (hx, hy) = grid.half_texel();
    let [lu, lv] = light_shape.extent().map(size_component);
    // (L/2) / (2 half-texel)
    [0.25 * lu / hx, 0.25 * lv / hy]
}

/// The nearest occluder depth of a front layer (inf when it holds none):
/// the search box's reach. The GPU twin reduces the same f32 minimum.
pub(crate) fn nearest_depth(front: &[f32]) -> f32 {
    front
        .par_iter()
        .copied()
        .filter(|d| d.is_finite() && *d > 0.0)
        .reduce(|| f32::INFINITY, f32::min)
}

impl<'a> Kernel<'a> {
    /// None when the map is missing or does not fit its grid: nothing occludes.
    fn new(inputs: &'a ShadowInputs, max_taps: u32) -> Option<Kernel<'a>> {
        let grid = inputs.occluder_grid;
        let front = *inputs.occluder_layers.first()?;
        if front.len() != grid.len() || grid.is_empty() {
            return None;
        }
        let z_near = nearest_depth(front);
        Some(Kernel {
            grid,
            front,
            z_near,
            half_per_w: half_per_w(&grid, inputs.light_shape),
            max_taps,
            disk: matches!(inputs.light_shape, LightShape::Disk { .. }),
        })
    }

    /// Half-widths (texels) of the box of occluders at 1/depth `w` seen from
    /// a receiver at 1/depth `wr`.
    #[inline]
    fn half(&self, w: f64, wr: f64) -> [f64; 2] {
        let d = w - wr;
        [self.half_per_w[0] * d, self.half_per_w[1] * d]
    }

    /// An upper bound on the texels `visibility` reads for a receiver at
    /// tangent (x, y), planar depth z: the blocker search's box, and the
    /// filter's, which is no wider (its 1/z_avg is at most 1/z_near).
    fn reads(&self, x: f32, y: f32, z: f32) -> f64 {
        if !(z.is_finite() && z > 0.0 && self.z_near < z) {
            return 0.0;
        }
        let (px, py) = self.grid.to_pixel(x as f64, y as f64);
        if !(px.is_finite() && py.is_finite()) {
            return 0.0;
        }
        let hs = self.half(1.0 / self.z_near as f64, 1.0 / z as f64);
        let ax = Axis::new(px, hs[0], self.grid.width, self.max_taps, false);
        let ay = Axis::new(py, hs[1], self.grid.height, self.max_taps, false);
        2.0 * ax.reads() as f64 * ay.reads() as f64
    }

    /// Visibility of a receiver at tangent (x, y), planar depth z, its
    /// tangent plane `plane` (module docs).
    fn visibility(&self, x: f32, y: f32, z: f32, plane: Plane) -> f32 {
        self.shade(x, y, z, plane, None).0
    }

    /// `visibility`, and with `weigh` its weighted visibility beside it
    /// (`pcss_weighted.rs`; else the plain one twice).
    fn shade(&self, x: f32, y: f32, z: f32, plane: Plane, weigh: Option<&Weigh>) -> (f32, f32) {
        if !(z.is_finite() && z > 0.0 && self.z_near < z) {
            return (1.0, 1.0);
        }
        let (px, py) = self.grid.to_pixel(x as f64, y as f64);
        if !(px.is_finite() && py.is_finite()) {
            return (1.0, 1.0);
        }
        let (sx, sy) = (split(px), split(py));
        let w = self.grid.width;
        let z_at = |k: usize| plane_depth(z, plane, sx, sy, (k % w) as i64, (k / w) as i64);
        let (g, m) = (&self.grid, self.max_taps);
        let wr = 1.0 / z as f64;
        // 1. Blocker search over t_r ± (L/2)(1/z_near - 1/z_r).
        let hs = self.half(1.0 / self.z_near as f64, wr);
        let ax = Axis::new(px, hs[0], g.width, m, false);
        let ay = Axis::new(py, hs[1], g.height, m, false);
        let (mut sw, mut swz) = (0f64, 0f64);
        let blocker = |k: usize, w: f64| {
            let d = self.front[k];
            if occludes(d, z_at(k)) {
                sw += w;
                swz += w * d as f64;
            }
        };
        if self.disk {
            pcf_disk::visit(&ax, &ay, g.width, blocker);
        } else {
            pcf::visit(&ax, &ay, g.width, blocker);
        }
        if !(sw > 0.0) {
            return (1.0, 1.0);
        }
        // 2. Penumbra: t_r ± (L/2)(1/z_avg - 1/z_r).
        let z_avg = swz / sw;
        let hf = self.half(1.0 / z_avg, wr);
        // 3. PCF of the binary test over that box; outside the map is lit.
        let lit = |k: usize| {
            if occludes(self.front[k], z_at(k)) {
                0.0
            } else {
                1.0
            }
        };
        let ax = Axis::new(px, hf[0], g.width, m, false);
        let ay = Axis::new(py, hf[1], g.height, m, false);
        let v = if self.disk {
            pcf_disk::filter(&ax, &ay, g.width, lit)
        } else {
            pcf::box_filter(g, px, py, hf, m, Border::Constant(1.0), lit)
        }
        .clamp(0.0, 1.0);
        let vw = match weigh {
            Some(wt) => weighted_visibility(v, &ax, &ay, g.width, self.disk, lit, wt),
            None => v,
        };
        (v, vw)
    }
}

/// `Pcss` is its own kernel (`kernel.rs`; `Kernel` here is the taps'
/// own, below).
impl super::kernel::Kernel for Pcss {
    const READS: &'static [Input] = &[Input::OccluderLayers];
    const TESTS_PLANES: bool = true;

    /// Its texel reads, bounded before any receiver is shaded.
    fn check_cost(&self, inputs: &ShadowInputs, points: Option<&[LightPoint]>) -> Result<()> {
        self.check_reads(inputs, points)
    }

    fn implementation(&self) -> Box<dyn ShadowMethod> {
        Box::new(*self)
    }
}

impl ShadowMethod for Pcss {
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32> {
        if inputs.light_shape.is_point() {
            return point_light::visibility_map(inputs);
        }
        let g = inputs.grid;
        let Some(kernel) = Kernel::new(inputs, self.max_taps) else {
            return vec![1.0; g.len()];
        };
        let stop = crate::cancel::current();
        (0..g.len())
            .into_par_iter()
            .map(|k| {
                if stop.is_cancelled() {
                    return 1.0;
                }
                let z = inputs.receiver.get(k).copied().unwrap_or(f32::INFINITY);
                let (x, y) = (g.x_of(k % g.width) as f32, g.y_of(k / g.width) as f32);
                kernel.visibility(x, y, z, [0.0; 2])
            })
            .collect()
    }

    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
        // No planes: every texel tested at the point's own depth.
        self.visibility_on_planes(inputs, points, &[])
    }

    /// On each point's tangent plane; weighted where asked for
    /// (`pcss_weighted.rs`).
    fn visibility_eye(
        &self,
        inputs: &ShadowInputs,
        eye: &EyePoints,
    ) -> (Vec<f32>, Option<Vec<f32>>) {
        match eye.starts {
            Some(r) => {
                let (v, w) = self.weighted_on_planes(inputs, eye.points, eye.planes, r);
                (v, Some(w))
            }
            None => (
                self.visibility_on_planes(inputs, eye.points, eye.planes),
                None,
            ),
        }
    }
}

impl Pcss {
    /// `visibility_points` with each point's tangent plane (module docs):
    /// `planes[i]` for `points[i]` ((0, 0) where missing).
    pub fn visibility_on_planes(
        &self,
        inputs: &ShadowInputs,
        points: &[LightPoint],
        planes: &[Plane],
    ) -> Vec<f32> {
        if inputs.light_shape.is_point() {
            return point_light::visibility_points(inputs, points);
        }
        let Some(kernel) = Kernel::new(inputs, self.max_taps) else {
            return vec![1.0; points.len()];
        };
        let stop = crate::cancel::current();
        points
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                if stop.is_cancelled() {
                    return 1.0;
                }
                let plane = planes.get(i).copied().unwrap_or([0.0; 2]);
                kernel.visibility(p.x, p.y, p.z, plane)
            })
            .collect()
    }
}

impl Pcss {
    /// `visibility_on_planes`, and beside it each point's weighted
    /// visibility (`pcss_weighted.rs`) seen from `receivers[k]` (the plain
    /// one where `None`, or where it has no surface point): what the eye
    /// view's shaded image reads under an area light.
    pub(crate) fn weighted_on_planes<R: RayOrigin + Copy + Sync>(
        &self,
        inputs: &ShadowInputs,
        points: &[LightPoint],
        planes: &[Plane],
        receivers: &[Option<R>],
    ) -> (Vec<f32>, Vec<f32>) {
        assert_eq!(points.len(), receivers.len(), "a receiver per point");
        if inputs.light_shape.is_point() {
            let v = point_light::visibility_points(inputs, points);
            return (v.clone(), v);
        }
        let Some(kernel) = Kernel::new(inputs, self.max_taps) else {
            return (vec![1.0; points.len()], vec![1.0; points.len()]);
        };
        let half = inputs.light_shape.half_extent().map(|h| h as f32);
        let stop = crate::cancel::current();
        points
            .par_iter()
            .zip(receivers)
            .enumerate()
            .map(|(i, (p, r))| {
                if stop.is_cancelled() {
                    return (1.0, 1.0);
                }
                let plane = planes.get(i).copied().unwrap_or([0.0; 2]);
                let weigh = r
                    .as_ref()
                    .and_then(R::surface)
                    .map(|surface| Weigh { surface, half });
                kernel.shade(p.x, p.y, p.z, plane, weigh.as_ref())
            })
            .unzip()
    }
}

/// The texel reads one PCSS call may be planned to make per receiver
/// (`Pcss::check_reads`), with at least `inputs::MIN_RECEIVERS`
/// receivers' worth: 5.0e9 at 640x480 and below. The bound's reads took
/// 1.4 ns each (4.7e9 in 6.7 s at 512² with `max_taps=64`) to 3.3 ns (a
/// 640x480 image whose 1e10 took 33 s, fuzz seed 13 call 793) on 2 cores,
/// so at most about 17 s there. The default `max_taps` never reaches it:
/// 16 taps a side read at most 2 x 34² = 2 312 texels a receiver.
pub const READS_PER_RECEIVER: f64 = 16384.0;

impl Pcss {
    /// Refuses, naming `max_taps`, a call whose receivers would read more
    /// than `READS_PER_RECEIVER` texels each, summed over the receivers
    /// (at least `MIN_RECEIVERS` of them) before any is
    /// shaded (`Kernel::reads`): a wide box read with many taps costs
    /// max_taps² reads a receiver, twice. `points`: the receivers (None:
    /// the texels of the receiver map `inputs.receiver`).
    pub fn check_reads(&self, inputs: &ShadowInputs, points: Option<&[LightPoint]>) -> Result<()> {
        if inputs.light_shape.is_point() {
            return Ok(());
        }
        let Some(kernel) = Kernel::new(inputs, self.max_taps) else {
            return Ok(());
        };
        let (reads, receivers): (f64, usize) = match points {
            Some(p) => p
                .par_iter()
                .map(|p| (kernel.reads(p.x, p.y, p.z), is_receiver(p.z) as usize))
                .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1)),
            None => {
                let g = inputs.grid;
                (0..g.len())
                    .into_par_iter()
                    .map(|k| {
                        let z = inputs.receiver.get(k).copied().unwrap_or(f32::INFINITY);
                        let (x, y) = (g.x_of(k % g.width) as f32, g.y_of(k / g.width) as f32);
                        (kernel.reads(x, y, z), is_receiver(z) as usize)
                    })
                    .reduce(|| (0.0, 0), |a, b| (a.0 + b.0, a.1 + b.1))
            }
        };
        let max_reads = READS_PER_RECEIVER * receivers.max(MIN_RECEIVERS) as f64;
        if reads > max_reads {
            return Err(Error::invalid(
                "max_taps",
                format!(
                    "{}: the receivers' blocker searches and filters would read about {reads:.1e} \
                     texels, more than the {max_reads:.1e} a call with {receivers} receivers may \
                     ({READS_PER_RECEIVER} a receiver); lower max_taps or the map resolution",
                    self.max_taps
                ),
            ));
        }
        Ok(())
    }
}

/// PCSS: blocker search, penumbra estimate and PCF on the shadow map.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PcssConfig {
    /// Taps per axis of the blocker search and of the filter (each box
    /// wider than this many texels is sampled by as many strata).
    pub max_taps: u32,
    /// The shadow map's (W, H); `None`: the output's.
    pub occluder_resolution: Option<(usize, usize)>,
}

impl PcssConfig {
    pub fn new(max_taps: Option<i64>, occluder_resolution: Option<(i64, i64)>) -> Result<Self> {
        let t = max_taps.unwrap_or(DEFAULT_MAX_TAPS as i64);
        let max = MAX_TAPS as i64;
        if !(1..=max).contains(&t) {
            return Err(Error::invalid(
                "max_taps",
                format!("must be in [1, {max}], got {t}"),
            ));
        }
        Ok(PcssConfig {
            max_taps: t as u32,
            occluder_resolution: occluder_resolution
                .map(|r| check_resolution("occluder_resolution", r))
                .transpose()?,
        })
    }
}

impl Default for PcssConfig {
    fn default() -> Self {
        PcssConfig {
            max_taps: DEFAULT_MAX_TAPS,
            occluder_resolution: None,
        }
    }
}

impl KeywordForm for PcssConfig {
    fn from_keywords(k: &Keywords) -> Result<Self> {
        PcssConfig::new(k.int("max_taps")?, k.resolution("occluder_resolution")?)
    }
    fn keywords(&self) -> Vec<(&'static str, Value)> {
        vec![
            ("max_taps", count(Some(self.max_taps))),
            ("occluder_resolution", resolution(self.occluder_resolution)),
        ]
    }
}

impl MethodSpec for PcssConfig {
    const NAME: &'static str = "pcss";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        if let Some(opt) = o.given().into_iter().find(|o| *o != "occluder_resolution") {
            return Err(refuse(opt, "other methods; give PCSS(...) its own options"));
        }
        PcssConfig::new(None, o.occluder_resolution)
    }
    type Resolved = Self;
    type Kernel = Pcss;
    fn kernel(&self) -> Pcss {
        Pcss {
            max_taps: self.max_taps,
        }
    }
    fn resolve(self, ctx: &CallContext) -> Result<Self::Resolved> {
        // From depth maps: the front layer the user gave.
        let (_, occ, _) = resolve_maps(
            Some(1),
            self.occluder_resolution,
            Some(false),
            false,
            &CallContext {
                depth_layers: ctx.depth_layers.map(|(_, shape)| (1, shape)),
                ..*ctx
            },
        )?;
        Ok(PcssConfig {
            occluder_resolution: Some(occ),
            ..self
        })
    }
    // The shadow map: the front layer.
    fn passes(&self) -> u32 {
        1
    }
    fn occluder_resolution(&self) -> Option<(usize, usize)> {
        self.occluder_resolution
    }

    fn info() -> MethodInfo {
        MethodInfo {
            name: "pcss",
            config: "PCSS",
            summary: "Percentage-closer soft shadows (Fernando 2005), what real-time engines \
                      ship: a blocker search on the shadow map, the penumbra estimated from the \
                      mean blocker depth, a box PCF of that width",
            // The kernel's (`Kernel::READS`).
            reads: <Pcss as super::kernel::Kernel>::READS.to_vec(),
            backends: Backend::built().to_vec(),
            options: vec![
                OptionInfo {
                    name: "max_taps",
                    kind: Kind::Int {
                        min: 1,
                        max: MAX_TAPS as i64,
                    },
                    default: Value::Int(DEFAULT_MAX_TAPS as i64),
                    default_doc: "16",
                    doc: "taps per axis of the blocker search and of the filter: a box spanning \
                          more texels is sampled by this many strata (bounded work per point)",
                    restricted_on: vec![],
                },
                occluder_resolution_option(),
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::methods::plate_case;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    fn inputs<'a>(
        grid: MapGrid,
        light: [f64; 2],
        receiver: &'a [f32],
        front: &'a [f32],
    ) -> ShadowInputs<'a> {
        ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect(light),
            receiver,
            occluder_layers: vec![front],
            occluder_triangles: None,
        }
    }

    /// A map holding depth `z(x, y)` at each texel centre (inf where None).
    fn map_of(grid: &MapGrid, z: impl Fn(f64, f64) -> Option<f32>) -> Vec<f32> {
        (0..grid.len())
            .map(|k| {
                z(grid.x_of(k % grid.width), grid.y_of(k / grid.width)).unwrap_or(f32::INFINITY)
            })
            .collect()
    }

    /// A receiver tilted to the light (1/z = 0.5 + 0.2 x) that is also the
    /// front layer, as in the eye view: each point, moved 0.1% toward the
    /// light, finds its own surface in the boxes when tested at its own
    /// depth, and nothing on its tangent plane.
    #[test]
    fn a_tilted_receiver_on_its_own_plane_does_not_shadow_itself() {
        let grid = MapGrid::new(64, 64, [1.0, 1.0]).unwrap();
        let inv_z = |x: f64| 0.5 + 0.2 * x;
        let front = map_of(&grid, |x, _| Some((1.0 / inv_z(x)) as f32));
        let inp = inputs(grid, [0.5, 0.5], &[], &front);
        // ∂(1/z)/∂px: 0.2 per unit of x, 2 tx / W units of x per texel.
        let plane = [(0.2 * 2.0 * grid.tx / grid.width as f64) as f32, 0.0];
        let pcss = Pcss::default();
        let (mut own, mut planar) = (0, 0);
        for s in 0..100 {
            let x = -0.8 + 1.6 * (s as f64 * 0.618).fract();
            let y = -0.8 + 1.6 * (s as f64 * 0.377).fract();
            let z = (0.999 / inv_z(x)) as f32;
            let p = [LightPoint {
                x: x as f32,
                y: y as f32,
                z,
            }];
            own += (pcss.visibility_points(&inp, &p)[0] < 1.0) as u32;
            planar += (pcss.visibility_on_planes(&inp, &p, &[plane])[0] < 1.0) as u32;
        }
        assert!(own > 40, "{own} of 100 shadowed at their own depth");
        assert_eq!(planar, 0);
        // A plane of (0, 0) is the point's own depth, bit for bit.
        let p = [LightPoint {
            x: 0.1,
            y: 0.2,
            z: 1.9,
        }];
        assert_eq!(
            pcss.visibility_points(&inp, &p),
            pcss.visibility_on_planes(&inp, &p, &[[0.0; 2]])
        );
    }

    fn at(inputs: &ShadowInputs, pcss: Pcss, x: f32, y: f32, z: f32) -> f32 {
        pcss.visibility_points(inputs, &[LightPoint { x, y, z }])[0]
    }

    #[test]
    fn plate_over_parallel_floor_matches_the_closed_form() {
        // One plate at one depth: the blocker average is its depth and the
        // filter box is its back-projection, so only rounding remains
        // (measured: 0 at 64² and at 128², where the 33-texel boxes are
        // sampled by 32 taps falling on texel edges, which reproduce the
        // exact weights; the f64 sums round to the exact f32 values). For
        // context: ssm is held to 1e-5 (f32 sums), the 256-sample bitmask to
        // 0.25 (its pattern's resolution).
        for n in [64, 128] {
            let max = plate_case::max_error(&Pcss { max_taps: 32 }, n);
            assert!(max < 1e-6, "{n}²: max error {max}");
        }
        // Fewer taps than the box's texels: stratified, an error of the
        // order of a stratum's share (measured 0.019 with 12 taps at 64²,
        // 0.21 with 4 taps at 128²).
        let max = plate_case::max_error(&Pcss { max_taps: 12 }, 64);
        assert!(max < 0.5 / 12.0, "12 taps: max error {max}");
        let max = plate_case::max_error(&Pcss { max_taps: 4 }, 128);
        assert!(max < 1.0 / 4.0, "4 taps: max error {max}");
    }

    /// Under a disk the filter's ellipse is the set of occluder points that
    /// hide part of the disk (pcf_disk.rs): exact up to rounding with every
    /// texel read (measured 3.0e-8 at 64² and at 128²); with strata each
    /// cell is weighted by its part inside the ellipse and read at its
    /// centre, so a stratum's share again bounds the error (measured 0.019
    /// with 12 taps at 64²).
    #[test]
    fn plate_under_a_disk_matches_the_closed_form() {
        let disk = LightShape::disk(0.5);
        for n in [64, 128] {
            let (_, max) = plate_case::mean_and_max_error(&Pcss { max_taps: 64 }, n, disk);
            assert!(max < 1e-6, "{n}²: max error {max}");
        }
        let (_, max) = plate_case::mean_and_max_error(&Pcss { max_taps: 12 }, 64, disk);
        assert!(max < 0.5 / 12.0, "12 taps: max error {max}");
    }

    /// The plate's floor points with their normal tilted both ways
    /// (`plate_case::WeightedPlate`): each penumbra point's weighted
    /// visibility against the integral of the weights over the light's
    /// lit part, under the square and under its inscribed disk, every
    /// texel read and with strata; the plain visibility keeps its bits.
    /// Measured: 2.6e-4 (square) and 4.0e-4 (disk) with every texel read,
    /// 0.051 and 0.054 with 5 taps, where the plain visibility is off by
    /// 0.053 and 0.049 (0.099 and 0.102 with 5 taps).
    #[test]
    fn weighted_visibility_matches_the_integral() {
        use crate::methods::plate_case::WeightedPlate;
        for (shape, taps, bound) in [
            (LightShape::rect([1.0, 1.0]), 64, 0.01),
            (LightShape::rect([1.0, 1.0]), 5, 0.5 / 5.0),
            (LightShape::disk(0.5), 64, 0.01),
            (LightShape::disk(0.5), 5, 0.5 / 5.0),
        ] {
            let plate = WeightedPlate::new(32, glam::Vec3::new(0.5, -0.6, -1.0)).under(shape);
            let inputs = plate.inputs();
            let pcss = Pcss { max_taps: taps };
            let (v, w) = pcss.weighted_on_planes(&inputs, &plate.pts, &[], &plate.surfaces);
            assert_eq!(v, pcss.visibility_points(&inputs, &plate.pts), "{shape:?}");
            let (worst, plain_worst, penumbra) = plate.errors(&v, &w);
            eprintln!("{shape:?} {taps}: weighted {worst}, plain {plain_worst}, {penumbra} points");
            assert!(penumbra > 50, "{penumbra} penumbra points");
            assert!(worst < bound, "{shape:?} {taps}: weighted off by {worst}");
            assert!(
                plain_worst > 0.04,
                "{shape:?}: plain off by only {plain_worst}"
            );
        }
    }

    #[test]
    fn umbra_is_0_and_far_outside_is_1() {
        let grid = MapGrid::new(128, 128, [1.0, 1.0]).unwrap();
        let front = map_of(&grid, |x, y| {
            (x.abs() < 0.5 && y.abs() < 0.5).then_some(2.0)
        });
        let receiver = vec![2.5f32; grid.len()];
        let inp = inputs(grid, [1.0, 1.0], &receiver, &front);
        // Seen from (0, 0) at 2.5 the light spans tangent ±0.05 at depth 2.
        assert_eq!(at(&inp, Pcss::default(), 0.0, 0.0, 2.5), 0.0);
        assert_eq!(at(&inp, Pcss::default(), 0.3, -0.2, 2.5), 0.0);
        assert_eq!(at(&inp, Pcss::default(), 0.9, 0.9, 2.5), 1.0);
        assert_eq!(at(&inp, Pcss::default(), 0.0, 0.8, 2.5), 1.0);
        // Beyond the map: lit.
        assert_eq!(at(&inp, Pcss::default(), 5.0, 0.0, 2.5), 1.0);
        // And the soft edge in between.
        let v = at(&inp, Pcss::default(), 0.5, 0.0, 2.5);
        assert!((v - 0.5).abs() < 1e-5, "{v}");
    }

    #[test]
    fn penumbra_width_grows_with_the_inverse_depth_difference() {
        // A half-plane (x < 0) at depth 2; from a receiver at tangent t,
        // depth zr, the exact visibility is the ramp clamp((t + h) / 2h),
        // h = (L/2)(1/2 - 1/zr): the penumbra is 2h = L (1/2 - 1/zr) wide.
        let grid = MapGrid::new(256, 16, [1.0, 0.5]).unwrap();
        // A strip at depth 1 at x > 0.95 sets z_near and so widens the
        // search (to ±(1/2)(1 - 1/zr) <= 0.42 around t in [-1/2, 1/2]), out
        // of reach of every receiver: the penumbra must come from the
        // blockers' depth 2, not from z_near.
        let front = map_of(&grid, |x, _| {
            if x < 0.0 {
                Some(2.0)
            } else if x > 0.95 {
                Some(1.0)
            } else {
                None
            }
        });
        let receiver = vec![0f32; grid.len()];
        let inp = inputs(grid, [1.0, 1.0], &receiver, &front);
        let texel = 2.0 / 256.0;
        let mut widths = vec![];
        for zr in [3.0f32, 6.0] {
            let h = 0.5 * (0.5 - 1.0 / zr as f64);
            let ts: Vec<f64> = (0..=800).map(|s| -0.5 + s as f64 / 800.0).collect();
            let pts: Vec<LightPoint> = ts
                .iter()
                .map(|&t| LightPoint {
                    x: t as f32,
                    y: 0.0,
                    z: zr,
                })
                .collect();
            let error = |pcss: Pcss| {
                let v = pcss.visibility_points(&inp, &pts);
                let mut max = 0f64;
                for (t, v) in ts.iter().zip(&v) {
                    let want = ((t + h) / (2.0 * h)).clamp(0.0, 1.0);
                    max = max.max((*v as f64 - want).abs());
                }
                (v, max)
            };
            // Every texel read (the box is 21 or 43 texels wide): the box
            // meets the edge exactly, only f32 rounding of the tangents
            // remains.
            let (_, max) = error(Pcss { max_taps: MAX_TAPS });
            assert!(max < 1e-4, "zr {zr}, every texel: {max}");
            // 32 taps: exact at zr 3; at zr 6 (43 texels) stratified, a
            // fraction of a stratum's share 1/32 (measured 0.00375).
            let (v, max) = error(Pcss { max_taps: 32 });
            assert!(max < 0.25 / 32.0, "zr {zr}, 32 taps: {max}");
            let partial: Vec<f64> = ts
                .iter()
                .zip(&v)
                .filter(|(_, v)| **v > 0.0 && **v < 1.0)
                .map(|(t, _)| *t)
                .collect();
            let width = partial.last().unwrap() - partial.first().unwrap();
            assert!(
                (width - 2.0 * h).abs() < texel,
                "zr {zr}: {width} vs {}",
                2.0 * h
            );
            widths.push(width);
        }
        // (1/2 - 1/6) / (1/2 - 1/3) = 2.
        let ratio = widths[1] / widths[0];
        assert!((ratio - 2.0).abs() < 0.05, "{ratio}");
    }

    #[test]
    fn no_blocker_gives_exactly_1() {
        let grid = MapGrid::new(40, 30, [0.5, 0.4]).unwrap();
        let mut seed = 2u64;
        let receiver: Vec<f32> = (0..grid.len())
            .map(|_| (1.0 + 3.0 * lcg(&mut seed)) as f32)
            .collect();
        // An empty map, and a map behind every receiver.
        let empty = vec![f32::INFINITY; grid.len()];
        let behind: Vec<f32> = (0..grid.len())
            .map(|_| (5.0 + lcg(&mut seed)) as f32)
            .collect();
        for front in [&empty, &behind] {
            let v = Pcss::default().visibility_map(&inputs(grid, [1.0, 1.0], &receiver, front));
            assert!(v.iter().all(|v| *v == 1.0));
        }
        // Occluders nearer than some receivers only: those behind them at
        // the same texel may be shadowed, the nearer ones never.
        let mid = vec![2.0f32; grid.len()];
        let v = Pcss::default().visibility_map(&inputs(grid, [1.0, 1.0], &receiver, &mid));
        for (v, z) in v.iter().zip(&receiver) {
            if *z <= 2.0 {
                assert_eq!(*v, 1.0);
            } else {
                assert!(*v < 1.0);
            }
        }
        // A blocker outside the search box: exactly 1. A plate at depth 2
        // over [0.2, 0.4] in x; a receiver at 2.5 at x = -0.1 searches
        // ±(1/2)(1/2 - 1/2.5) = ±0.05.
        let plate = map_of(&grid, |x, _| (0.2..0.4).contains(&x).then_some(2.0));
        let inp = inputs(grid, [1.0, 1.0], &receiver, &plate);
        assert_eq!(at(&inp, Pcss::default(), -0.1, 0.0, 2.5), 1.0);
        assert!(at(&inp, Pcss::default(), 0.3, 0.0, 2.5) < 1e-6);
    }

    #[test]
    fn huge_lights_stay_bounded_and_few_taps_stay_close() {
        let grid = MapGrid::new(64, 64, [0.5, 0.5]).unwrap();
        let mut seed = 8u64;
        let front: Vec<f32> = (0..grid.len())
            .map(|_| {
                if lcg(&mut seed) < 0.3 {
                    (1.0 + lcg(&mut seed)) as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let receiver: Vec<f32> = (0..grid.len())
            .map(|_| (2.5 + lcg(&mut seed)) as f32)
            .collect();
        // A light 1e4 wide: every box covers the map many times over.
        for light in [[1e4, 1e4], [1e4, 0.3], [1e300, 1e300], [f64::INFINITY; 2]] {
            let v = Pcss::default().visibility_map(&inputs(grid, light, &receiver, &front));
            assert!(v.iter().all(|v| (0.0..=1.0).contains(v)), "{light:?}");
        }
        // Boxes of about 10-40 texels: 6 stratified taps per axis against
        // the exact weights (measured: max 0.107, mean 0.0072; with 12
        // taps 0.0069, 0.00066). Rectangles at two depths: straight edges,
        // where a tap's error is largest.
        let rects = map_of(&grid, |x, y| {
            if (-0.3..-0.05).contains(&x) && (-0.2..0.25).contains(&y) {
                Some(1.5)
            } else if (0.1..0.35).contains(&x) && (-0.35..0.1).contains(&y) {
                Some(1.8)
            } else {
                None
            }
        });
        let flat = vec![2.6f32; grid.len()];
        let inp = inputs(grid, [0.8, 0.6], &flat, &rects);
        let exact = Pcss { max_taps: MAX_TAPS }.visibility_map(&inp);
        let few = Pcss { max_taps: 6 }.visibility_map(&inp);
        let (mut max, mut sum) = (0f32, 0f32);
        for (a, b) in exact.iter().zip(&few) {
            max = max.max((a - b).abs());
            sum += (a - b).abs();
        }
        let mean = sum / exact.len() as f32;
        assert!(max < 1.0 / 6.0 && mean < 0.012, "max {max}, mean {mean}");
        assert!(exact.contains(&0.0) && exact.iter().any(|v| *v > 0.0 && *v < 1.0));
    }

    #[test]
    fn the_map_agrees_with_points_at_texel_centres() {
        let grid = MapGrid::new(37, 29, [0.4, 0.3]).unwrap();
        let mut seed = 13u64;
        let front: Vec<f32> = (0..grid.len())
            .map(|_| {
                if lcg(&mut seed) < 0.4 {
                    (2.0 + lcg(&mut seed)) as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let receiver: Vec<f32> = (0..grid.len())
            .map(|_| {
                if lcg(&mut seed) < 0.9 {
                    (3.2 + lcg(&mut seed)) as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let inp = inputs(grid, [1.0, 0.7], &receiver, &front);
        for pcss in [Pcss::default(), Pcss { max_taps: 3 }] {
            let map = pcss.visibility_map(&inp);
            let pts: Vec<LightPoint> = (0..grid.len())
                .map(|k| LightPoint {
                    x: grid.x_of(k % grid.width) as f32,
                    y: grid.y_of(k / grid.width) as f32,
                    z: receiver[k],
                })
                .collect();
            assert_eq!(map, pcss.visibility_points(&inp, &pts));
            assert!(map.iter().any(|v| *v < 1.0));
        }
    }

    #[test]
    fn odd_inputs_neither_panic_nor_give_nan() {
        let grid = MapGrid::new(16, 12, [0.5, 0.5]).unwrap();
        let mut seed = 21u64;
        let front: Vec<f32> = (0..grid.len())
            .map(|_| match (lcg(&mut seed) * 6.0) as u32 {
                0 => f32::NAN,
                1 => -1.0,
                2 => 0.0,
                3 => f32::INFINITY,
                _ => (1.0 + lcg(&mut seed)) as f32,
            })
            .collect();
        let receiver: Vec<f32> = (0..grid.len())
            .map(|_| (0.5 + 3.0 * lcg(&mut seed)) as f32)
            .collect();
        let pts = [
            LightPoint {
                x: 0.0,
                y: 0.0,
                z: f32::NAN,
            },
            LightPoint {
                x: 0.0,
                y: 0.0,
                z: -2.0,
            },
            LightPoint {
                x: 0.0,
                y: 0.0,
                z: 0.0,
            },
            LightPoint {
                x: 0.0,
                y: 0.0,
                z: f32::INFINITY,
            },
            LightPoint {
                x: f32::NAN,
                y: 0.0,
                z: 3.0,
            },
            LightPoint {
                x: f32::INFINITY,
                y: -f32::INFINITY,
                z: 3.0,
            },
            LightPoint {
                x: 1e30,
                y: 0.0,
                z: 3.0,
            },
            LightPoint {
                x: 0.6,
                y: -0.6,
                z: 3.0,
            },
            LightPoint {
                x: 0.1,
                y: 0.1,
                z: 1e-30,
            },
            LightPoint {
                x: 0.1,
                y: 0.1,
                z: 1e30,
            },
            LightPoint {
                x: 0.1,
                y: 0.1,
                z: 3.0,
            },
        ];
        let ok = |v: &[f32]| v.iter().all(|v| (0.0..=1.0).contains(v));
        for light in [
            [1.0, 1.0],
            [1.0, 0.0],
            [f64::NAN, 1.0],
            [-1.0, 2.0],
            [f64::INFINITY, 1.0],
            [1e-12, 1e-12],
        ] {
            for max_taps in [0, 1, 2, DEFAULT_MAX_TAPS, MAX_TAPS, u32::MAX] {
                let pcss = Pcss { max_taps };
                let inp = inputs(grid, light, &receiver, &front);
                let v = pcss.visibility_points(&inp, &pts);
                assert!(ok(&v), "{light:?} {max_taps}: {v:?}");
                assert!(v[..7].iter().all(|v| *v == 1.0), "{light:?}: {v:?}");
                assert!(ok(&pcss.visibility_map(&inp)));
            }
        }
        // No layer, a layer of the wrong length, a short receiver map, a
        // 1x1 map: all lit or bounded.
        let mut inp = inputs(grid, [1.0, 1.0], &receiver, &front);
        inp.occluder_layers.clear();
        assert!(Pcss::default()
            .visibility_map(&inp)
            .iter()
            .all(|v| *v == 1.0));
        inp.occluder_layers = vec![&front[..5]];
        assert!(Pcss::default()
            .visibility_points(&inp, &pts)
            .iter()
            .all(|v| *v == 1.0));
        let inp = inputs(grid, [1.0, 1.0], &receiver[..7], &front);
        let v = Pcss::default().visibility_map(&inp);
        assert_eq!(v.len(), grid.len());
        assert!(ok(&v) && v[7..].iter().all(|v| *v == 1.0));
        let one = MapGrid::new(1, 1, [0.5, 0.5]).unwrap();
        let v = Pcss::default().visibility_points(&inputs(one, [1.0, 1.0], &[3.0], &[2.0]), &pts);
        assert!(ok(&v));
        // A point light: the hard test of point_light.rs.
        let inp = inputs(grid, [0.0, 0.0], &receiver, &front);
        assert_eq!(
            Pcss::default().visibility_map(&inp),
            point_light::visibility_map(&inp)
        );
    }
}
