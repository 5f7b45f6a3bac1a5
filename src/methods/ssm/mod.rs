//! Soft shadow maps as published (Atty et al. 2005, §3): every occluder texel
//! becomes a micro-patch parallel to the light at its depth; its occlusion of
//! the light seen from a receiver point is the overlap of its back-projection
//! onto the light with the light rectangle (§3.4); occlusions are summed and
//! clamped; with two occluder layers (§3.5) the larger occlusion wins.
//!
//! Geometry in light space. A receiver point at tangent (xr, yr), depth zR, and
//! a micro-patch covering tangent [x0, x1] x [y0, y1] at depth zO < zR. The ray
//! from the receiver through the patch point at tangent xq meets the light's
//! plane at X = k (xq - xr) with k = zR zO / (zR - zO) = 1 / (1/zO - 1/zR).
//! In units of the light's width, shifted so the light is [0, 1]:
//!     [a, b] = [(x0 - xr) r / Lx + 1/2, (x1 - xr) r / Lx + 1/2],  r = 1/(wO - wR)
//! with w = 1/z; the same along y; the occlusion is `|[a,b] ∩ [0,1]| |[c,d] ∩ [0,1]|`
//! (the paper's SAT trick). The patch reaches receivers within
//!     |xq - xr| < L/2 (wO - wR)
//! which is its penumbra extent (§3.3) in tangent units.
//!
//! The traversal is the shared gather of `gather/`; this module adds the
//! published arithmetic: each pair adds its clipped area, the layers merge by max.
//!
//! Its config (`SsmConfig`, its checks and its `MethodSpec`: name, string
//! form, resolution, capabilities row) is at the end of this file.

use super::config::{
    check_passes, check_resolution, hierarchy_option, occluder_resolution_option, passes_option,
    resolve_maps, CallContext, LooseOptions, MethodSpec, DEFAULT_PASSES, SAMPLES_ONLY,
};
use super::gather::work::SSM_VISIT;
use super::gather::{
    self, maps_with_levels, max, min, Accumulator, Group, Hierarchy, Lanes, RowLanes, HIERARCHY,
    LANES, ROWS_PER_GROUP, TILE_W,
};
use super::info::{Kind, MethodInfo, OptionInfo, Value};
use super::kernel::Kernel;
use super::keywords::{count, flag, resolution, KeywordForm, Keywords};
use super::Input;
use super::{EyePoints, LightPoint, ShadowInputs, ShadowMethod};
use crate::backend::Backend;
use crate::error::{Error, Result};
use crate::geom::light_shape::disk_clip::rect_overlap_f32;
use crate::geom::light_shape::LightShape;
use crate::trace::shadow_rays::RayOrigin;

/// The published method; with a hierarchy, occluder texels are read at a
/// coarser level where the penumbra is wide (not in the paper).
#[derive(Default)]
pub struct Ssm {
    pub hierarchy: Option<Hierarchy>,
    pub precision: Precision,
}

/// How the micro-patch occlusions are summed (Appendix A of the paper).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Precision {
    /// f32 sums, each occluder row summed on its own before joining the
    /// total: a two-level sum whose rounding error grows as sqrt(M) eps, not
    /// M eps, for M micro-patches (held to 1e-4 of f64 at 4096²).
    #[default]
    F32,
    /// f64 sums (the contributions themselves are computed in f32).
    F64,
    /// The 2005 GPUs' FP16 blending, emulated: every contribution rounded to
    /// binary16, added to a binary16 sum (to nearest), in the order the
    /// micro-patches were rasterized (occluder rows top to bottom, texels
    /// left to right).
    F16,
    /// Appendix A's workaround: FP16 sums over batches of about sqrt(M)
    /// micro-patches (runs of occluder rows), the batches added in f32.
    F16Batched,
}

impl Precision {
    /// Every precision, in the order the capabilities list them.
    pub const ALL: [Precision; 4] = [
        Precision::F32,
        Precision::F64,
        Precision::F16,
        Precision::F16Batched,
    ];

    /// The name a user passes as `precision=`.
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
            Precision::F16 => "f16",
            Precision::F16Batched => "f16-batched",
        }
    }

    pub fn parse(name: &str) -> Option<Precision> {
        Some(match name {
            "f32" => Precision::F32,
            "f64" => Precision::F64,
            "f16" => Precision::F16,
            "f16-batched" => Precision::F16Batched,
            _ => return None,
        })
    }
}

/// Added to d^2 (d = 1/zO - 1/zR) in the division: keeps 0 / 0 away where
/// occluder and receiver share a depth (there the clipped intervals are empty
/// and the contribution is exactly 0); negligible against any real d^2.
const D2_MIN: f32 = 1e-36;

/// 4x the light fraction micro-patch [x0, x1] x (row) hides from lane l.
/// The patch seen from the receiver covers, on the light, r [x0 - xr, x1 - xr]
/// with r = 1/d, d = wO - wR, intersected with the light [-1, 1];
/// equivalently [x0 - xr, x1 - xr] is clipped to [-d, d] and the length
/// scaled by r. The area fraction is cx cy / (4 d^2): one division per pair
/// and no mask, since for d <= 0 the clipped intervals are empty. Under a
/// disk (`DISK`; half-light units make it the unit disk inscribed in that
/// square) the patch [x0 - xr, x1 - xr] x [-nay0, ay1] is clipped to the
/// disk of radius d instead (`disk_clip`), and its area over π d² is the
/// fraction: 4 A / (π d²), so that 4 is still the whole light.
#[inline(always)]
fn contribution<const DISK: bool>(
    l: usize,
    w: f32,
    x0: f32,
    x1: f32,
    r: &RowLanes,
    g: &Group,
) -> f32 {
    let d = w - g.wr[l];
    if DISK {
        let a = rect_overlap_f32(d, [x0 - r.xr[l], x1 - r.xr[l]], [-r.nay0[l], r.ay1[l]]);
        return FOUR_OVER_PI * a / d.mul_add(d, D2_MIN);
    }
    // |[a, b] ∩ [-d, d]| = min(b, d) + min(-a, d) when >= 0.
    let cx = min(x1 - r.xr[l], d) + min(r.xr[l] - x0, d);
    let cy = min(r.ay1[l], d) + min(r.nay0[l], d);
    // d^2 + D2_MIN keeps 0/0 away where d = 0 (then cx, cy <= 0).
    max(cx, 0.0) * max(cy, 0.0) / d.mul_add(d, D2_MIN)
}

/// Under a disk, lane l's contribution where micro-patch [x0, x1] x (row)
/// lies wholly inside the disk (else 0), and whether it lies across the
/// disk's rim instead (inside the light's square, not inside the disk):
/// there `contribution::<true>` is the lane's. Branch-free, so a loop over
/// the lanes vectorizes; the inside value has `contribution::<true>`'s bits
/// (`rect_overlap_f32`'s first answer, the same operations).
#[inline(always)]
fn disk_inside(l: usize, w: f32, x0: f32, x1: f32, r: &RowLanes, g: &Group) -> (f32, bool) {
    let d = w - g.wr[l];
    let (xa, xb) = (x0 - r.xr[l], x1 - r.xr[l]);
    let (ya, yb) = (-r.nay0[l], r.ay1[l]);
    let (fx, fy) = (max(xa.abs(), xb.abs()), max(ya.abs(), yb.abs()));
    let inside = d > 0.0 && fx * fx + fy * fy <= d * d;
    let c = FOUR_OVER_PI * ((xb - xa) * (yb - ya)) / d.mul_add(d, D2_MIN);
    let cx = min(xb, d) + min(r.xr[l] - x0, d);
    let cy = min(yb, d) + min(r.nay0[l], d);
    (
        if inside { c } else { 0.0 },
        !inside && cx > 0.0 && cy > 0.0,
    )
}

/// `contribution::<DISK>` of every lane. Under a disk most pairs lie
/// wholly inside it or miss the light: those in one pass over the lanes
/// (`disk_inside`), then the few across the rim one by one.
#[inline(always)]
fn contributions<const DISK: bool>(w: f32, x0: f32, x1: f32, r: &RowLanes, g: &Group) -> Lanes {
    if !DISK {
        return std::array::from_fn(|l| contribution::<false>(l, w, x0, x1, r, g));
    }
    let mut c = [0f32; LANES];
    let mut rim = 0u64;
    for (l, cl) in c.iter_mut().enumerate() {
        let (v, on_rim) = disk_inside(l, w, x0, x1, r, g);
        *cl = v;
        rim |= u64::from(on_rim) << l;
    }
    while rim != 0 {
        let l = rim.trailing_zeros() as usize;
        rim &= rim - 1;
        c[l] = contribution::<true>(l, w, x0, x1, r, g);
    }
    c
}

/// 4/π, rounded once (the device's `FOUR_OVER_PI` is the same f32).
const FOUR_OVER_PI: f32 = (4.0 / std::f64::consts::PI) as f32;

/// A sum per lane in two levels: `open` collects the current group of
/// contributions (an occluder row, or an FP16 batch), `done` the groups closed
/// so far. Adding small terms to a small open sum keeps the rounding error
/// near sqrt(M) eps for M terms, where one running sum reaches M eps.
#[derive(Clone, Copy)]
struct TwoLevel {
    done: Lanes,
    open: Lanes,
}

impl TwoLevel {
    fn new() -> TwoLevel {
        TwoLevel {
            done: [0.0; LANES],
            open: [0.0; LANES],
        }
    }

    #[inline(always)]
    fn total(&self, l: usize) -> f32 {
        self.done[l] + self.open[l]
    }

    /// Moves the open sums into the closed ones.
    #[inline(always)]
    fn close(&mut self) {
        for l in 0..LANES {
            self.done[l] += self.open[l];
            self.open[l] = 0.0;
        }
    }

    /// Whether every lane's total reached `limit`.
    #[inline(always)]
    fn all_reach(&self, limit: f32) -> bool {
        (0..LANES).all(|l| self.total(l) >= limit)
    }
}

/// f32 sums of 4x the occluded fraction (the 1/4 is applied in `occlusion`),
/// closed after every occluder row; under a disk where `DISK`.
struct Sum<const DISK: bool>;

impl<const DISK: bool> Accumulator for Sum<DISK> {
    type State = TwoLevel;
    const LAYERS_SHARE_STATE: bool = false;

    fn empty(&self) -> TwoLevel {
        TwoLevel::new()
    }

    #[inline(always)]
    #[allow(clippy::needless_range_loop)] // one index over several lane arrays: what vectorizes
    fn add_texel(&self, acc: &mut TwoLevel, w: f32, x0: f32, x1: f32, r: &RowLanes, g: &Group) {
        let c = contributions::<DISK>(w, x0, x1, r, g);
        for l in 0..LANES {
            acc.open[l] += c[l];
        }
    }

    /// One depth for the whole tile: the clipped x-length depends on the
    /// column only and the y-length on the row only, so 8 + 8 lengths and 8
    /// divisions replace 64 of each (a different rounding than `add_texel`:
    /// cx (cy / d^2) against (cx cy) / d^2). A disk's clipped area is not
    /// a product of lengths: lane by lane.
    #[inline(always)]
    fn add_texel_tile(
        &self,
        acc: &mut TwoLevel,
        w: f32,
        x0: f32,
        x1: f32,
        r: &RowLanes,
        g: &Group,
    ) -> bool {
        if DISK {
            self.add_texel(acc, w, x0, x1, r, g);
            return true;
        }
        let d = w - g.wr[0];
        let dd = d.mul_add(d, D2_MIN);
        let cx: [f32; TILE_W] =
            std::array::from_fn(|c| max(min(x1 - r.xr[c], d) + min(r.xr[c] - x0, d), 0.0));
        let cy: [f32; ROWS_PER_GROUP] = std::array::from_fn(|row| {
            let l = row * TILE_W;
            max(min(r.ay1[l], d) + min(r.nay0[l], d), 0.0) / dd
        });
        for (row, y) in cy.iter().enumerate() {
            for (c, x) in cx.iter().enumerate() {
                acc.open[row * TILE_W + c] += x * y;
            }
        }
        true
    }

    /// The gather calls `full` after every row it shades: the row's sums
    /// join the totals there. Contributions are non-negative and the result
    /// is clamped, so a total that reached 1 is final.
    #[inline(always)]
    fn full(&self, acc: &TwoLevel, _g: &Group) -> bool {
        acc.all_reach(4.0)
    }

    #[inline(always)]
    fn occlusion(&self, acc: &TwoLevel) -> Lanes {
        std::array::from_fn(|l| (0.25 * acc.total(l)).min(1.0))
    }

    #[inline(always)]
    fn end_row(&self, acc: &mut TwoLevel) {
        acc.close();
    }
}

/// f64 sums of 4x the occluded fraction.
struct Sum64<const DISK: bool>;

impl<const DISK: bool> Accumulator for Sum64<DISK> {
    type State = [f64; LANES];
    const LAYERS_SHARE_STATE: bool = false;

    fn empty(&self) -> Self::State {
        [0.0; LANES]
    }

    #[inline(always)]
    fn add_texel(&self, acc: &mut Self::State, w: f32, x0: f32, x1: f32, r: &RowLanes, g: &Group) {
        let c = contributions::<DISK>(w, x0, x1, r, g);
        for (a, c) in acc.iter_mut().zip(c) {
            *a += c as f64;
        }
    }

    fn full(&self, acc: &Self::State, _g: &Group) -> bool {
        acc.iter().all(|&a| a >= 4.0)
    }

    fn occlusion(&self, acc: &Self::State) -> Lanes {
        acc.map(|a| (0.25 * a).min(1.0) as f32)
    }
}

/// A finite x >= 0 rounded to the nearest binary16 value, ties to even (10
/// mantissa bits, normals from 2^-14, subnormals in steps of 2^-24, largest
/// 65504), as f32. Appendix A states the rule X + e = X for e < 2^-10 X
/// (one ulp); to nearest, e is lost below half an ulp. Rounding toward zero
/// instead was measured to break the floating bunny already at 128² (12%
/// errors where condition (4) holds everywhere), which Figure 14 does not
/// show; to nearest reproduces it (docs/precision/fp16.md).
pub fn round_to_f16(x: f32) -> f32 {
    const MIN_NORMAL: f32 = 1.0 / 16384.0; // 2^-14
    if x < MIN_NORMAL {
        return (x * 16_777_216.0).round_ties_even() / 16_777_216.0; // steps of 2^-24
    }
    // Drop 13 of f32's 23 mantissa bits, rounding to nearest even.
    let bits = x.to_bits();
    let rounded = f32::from_bits((bits + 0x0fff + ((bits >> 13) & 1)) & !0x1fff);
    if rounded > 65504.0 {
        f32::INFINITY
    } else {
        rounded
    }
}

/// FP16 blending, emulated: occluded fractions (not 4x: the GPU blended the
/// fraction) rounded to binary16 and summed in binary16 (see
/// `round_to_f16`), in rasterization order; with `batched`, the FP16 sum restarts every batch and the batches
/// add in f32.
struct SumF16<const DISK: bool> {
    batched: bool,
}

/// The state is a `TwoLevel` whose `open` sums are binary16 values (the
/// current batch) and whose `done` sums are the closed batches, in f32.
impl<const DISK: bool> Accumulator for SumF16<DISK> {
    type State = TwoLevel;
    const LAYERS_SHARE_STATE: bool = false;
    const ROW_MAJOR: bool = true;

    fn empty(&self) -> TwoLevel {
        TwoLevel::new()
    }

    #[inline(always)]
    fn add_texel(&self, acc: &mut TwoLevel, w: f32, x0: f32, x1: f32, r: &RowLanes, g: &Group) {
        let cs = contributions::<DISK>(w, x0, x1, r, g);
        for (open, c) in acc.open.iter_mut().zip(cs) {
            // Exact in binary: the 1/4 only moves the exponent.
            *open = round_to_f16(*open + round_to_f16(0.25 * c));
        }
    }

    fn full(&self, acc: &TwoLevel, _g: &Group) -> bool {
        acc.all_reach(1.0)
    }

    fn occlusion(&self, acc: &TwoLevel) -> Lanes {
        std::array::from_fn(|l| acc.total(l).min(1.0))
    }

    fn end_batch(&self, acc: &mut TwoLevel) {
        if self.batched {
            acc.close();
        }
    }
}

mod weighted;

/// `$body` with `$a` the accumulator of `$ssm`'s precision for the light of
/// `$inputs` (a disk's or a rectangle's clipping, chosen once per call).
macro_rules! with_sum {
    ($ssm:expr, $inputs:expr, |$a:ident| $body:expr) => {{
        let disk = matches!($inputs.light_shape, LightShape::Disk { .. });
        match ($ssm.precision, disk) {
            (Precision::F32, false) => {
                let $a = Sum::<false>;
                $body
            }
            (Precision::F32, true) => {
                let $a = Sum::<true>;
                $body
            }
            (Precision::F64, false) => {
                let $a = Sum64::<false>;
                $body
            }
            (Precision::F64, true) => {
                let $a = Sum64::<true>;
                $body
            }
            (Precision::F16 | Precision::F16Batched, false) => {
                let $a = SumF16::<false> {
                    batched: $ssm.precision == Precision::F16Batched,
                };
                $body
            }
            (Precision::F16 | Precision::F16Batched, true) => {
                let $a = SumF16::<true> {
                    batched: $ssm.precision == Precision::F16Batched,
                };
                $body
            }
        }
    }};
}

impl Ssm {
    /// `visibility_points`, and beside it each point's weighted visibility
    /// seen from `receivers[k]` (its surface point and tangent plane:
    /// `weighted.rs`). The plain visibility has the same bits as
    /// `visibility_points`'.
    pub(crate) fn weighted_points<R: RayOrigin + Copy + Sync>(
        &self,
        inputs: &ShadowInputs,
        points: &[LightPoint],
        receivers: &[Option<R>],
    ) -> (Vec<f32>, Vec<f32>) {
        let h = self.hierarchy;
        let (i, p, r) = (inputs, points, receivers);
        with_sum!(self, inputs, |a| weighted::weighted_points(&a, i, p, r, h))
    }
}

impl ShadowMethod for Ssm {
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32> {
        let h = self.hierarchy;
        with_sum!(self, inputs, |a| gather::visibility_map(&a, inputs, h))
    }

    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
        let h = self.hierarchy;
        with_sum!(self, inputs, |a| gather::visibility_points(
            &a, inputs, points, h
        ))
    }

    /// Weighted where asked for (`weighted.rs`): `gather::visibility_eye`.
    fn visibility_eye(
        &self,
        inputs: &ShadowInputs,
        eye: &EyePoints,
    ) -> (Vec<f32>, Option<Vec<f32>>) {
        gather::visibility_eye(
            inputs,
            eye,
            |p| self.visibility_points(inputs, p),
            |p, r| self.weighted_points(inputs, p, r),
        )
    }
}

/// The kernel a resolved `SsmConfig` runs (`kernel.rs`): the hierarchy on
/// or off, and the sums' precision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct SsmKernel {
    pub hierarchy: bool,
    pub precision: Precision,
}

impl Kernel for SsmKernel {
    const READS: &'static [Input] = &[Input::OccluderLayers];

    /// The 1/depth copy and its nearest and farthest bounds
    /// (`gather/hierarchy.rs`), and the hierarchy's levels.
    fn maps_per_layer(&self) -> usize {
        maps_with_levels(3, self.hierarchy)
    }

    fn visit_cost(&self) -> Option<f64> {
        Some(SSM_VISIT)
    }

    fn implementation(&self) -> Box<dyn ShadowMethod> {
        Box::new(Ssm {
            hierarchy: self.hierarchy.then_some(HIERARCHY),
            precision: self.precision,
        })
    }
}

/// Whether the hierarchy is on by default on the CPU: off for the paper's
/// method (reproduced as published).
pub const HIERARCHY_DEFAULT_SSM: bool = false;

/// The paper's soft shadow maps (Atty et al. 2005): additive micro-patches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SsmConfig {
    /// Occluder depth layers; `None`: 2 from meshes, the layers given from
    /// depth maps.
    pub passes: Option<u32>,
    /// Occluder maps' (W, H); `None`: the output's.
    pub occluder_resolution: Option<(usize, usize)>,
    /// The occluder hierarchy; `None`: off (the paper has none).
    pub hierarchy: Option<bool>,
    pub precision: Precision,
}

/// `precision=` by name.
pub fn check_precision(name: &str) -> Result<Precision> {
    Precision::parse(name).ok_or_else(|| {
        Error::invalid(
            "precision",
            format!(
                "must be one of {:?}, got {name:?}",
                Precision::ALL.map(|p| p.name())
            ),
        )
    })
}

impl SsmConfig {
    /// Checks each given option; `None` keeps the default.
    pub fn new(
        passes: Option<i64>,
        occluder_resolution: Option<(i64, i64)>,
        hierarchy: Option<bool>,
        precision: Option<&str>,
    ) -> Result<Self> {
        Ok(SsmConfig {
            passes: passes.map(check_passes).transpose()?,
            occluder_resolution: occluder_resolution
                .map(|r| check_resolution("occluder_resolution", r))
                .transpose()?,
            hierarchy,
            precision: precision
                .map(check_precision)
                .transpose()?
                .unwrap_or_default(),
        })
    }
}

impl KeywordForm for SsmConfig {
    fn from_keywords(k: &Keywords) -> Result<Self> {
        SsmConfig::new(
            k.int("passes")?,
            k.resolution("occluder_resolution")?,
            k.bool("hierarchy")?,
            k.str("precision")?,
        )
    }
    fn keywords(&self) -> Vec<(&'static str, Value)> {
        vec![
            ("passes", count(self.passes)),
            ("occluder_resolution", resolution(self.occluder_resolution)),
            ("hierarchy", flag(self.hierarchy)),
            ("precision", Value::Str(self.precision.name())),
        ]
    }
}

impl MethodSpec for SsmConfig {
    const NAME: &'static str = "ssm";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        if o.samples.is_some() {
            return Err(refuse("samples", SAMPLES_ONLY));
        }
        SsmConfig::new(o.passes, o.occluder_resolution, o.hierarchy, o.precision)
    }
    type Resolved = Self;
    type Kernel = SsmKernel;
    fn kernel(&self) -> SsmKernel {
        SsmKernel {
            hierarchy: self.hierarchy.unwrap_or(HIERARCHY_DEFAULT_SSM),
            precision: self.precision,
        }
    }
    fn resolve(self, ctx: &CallContext) -> Result<Self::Resolved> {
        let c = self;
        if ctx.backend == Backend::Gpu && c.precision != Precision::F32 {
            return Err(Error::invalid(
                "precision",
                format!(
                    "the GPU backend sums in \"f32\" only, got {:?}; use backend=\"cpu\"",
                    c.precision.name()
                ),
            ));
        }
        let (passes, occ, hierarchy) = resolve_maps(
            c.passes,
            c.occluder_resolution,
            c.hierarchy,
            HIERARCHY_DEFAULT_SSM,
            ctx,
        )?;
        Ok(SsmConfig {
            passes: Some(passes),
            occluder_resolution: Some(occ),
            hierarchy: Some(hierarchy),
            precision: c.precision,
        })
    }
    fn passes(&self) -> u32 {
        self.passes.unwrap_or(DEFAULT_PASSES)
    }
    fn occluder_resolution(&self) -> Option<(usize, usize)> {
        self.occluder_resolution
    }

    fn info() -> MethodInfo {
        MethodInfo {
            name: "ssm",
            config: "Ssm",
            summary: "Soft shadow maps (Atty et al. 2005) as published: micro-patches of the \
                      occluder maps back-projected onto the light, their occlusions summed",
            // The kernel's (`Kernel::READS`).
            reads: SsmKernel::READS.to_vec(),
            backends: Backend::built().to_vec(),
            options: vec![
                passes_option(),
                occluder_resolution_option(),
                hierarchy_option(HIERARCHY_DEFAULT_SSM),
                OptionInfo {
                    name: "precision",
                    kind: Kind::Choice(Precision::ALL.iter().map(|p| p.name()).collect()),
                    default: Value::Str(Precision::default().name()),
                    default_doc: "f32, each occluder row summed on its own",
                    doc: "how the occlusions are summed (paper Appendix A): f32 two-level, f64, \
                          emulated FP16 blending, or FP16 in batches of about sqrt(M)",
                    restricted_on: vec![(Backend::Gpu, vec![Value::Str(Precision::F32.name())])],
                },
            ],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::MapGrid;
    use crate::geom::light_shape::LightShape;

    /// The published method written as plainly as possible, in f64: every
    /// occluder texel against every receiver texel, no bounds, no early exit.
    fn brute_force(inputs: &ShadowInputs) -> Vec<f32> {
        let g = &inputs.grid;
        let og = &inputs.occluder_grid;
        let (hw, hh) = og.half_texel();
        let [lx, ly] = inputs.light_shape.extent();
        let overlap = |a: f64, b: f64| (b.clamp(0.0, 1.0) - a.clamp(0.0, 1.0)).max(0.0);
        let mut out = vec![1f32; g.len()];
        for jr in 0..g.height {
            for ir in 0..g.width {
                let zr = inputs.receiver[jr * g.width + ir] as f64;
                if !zr.is_finite() {
                    continue;
                }
                let (xr, yr) = (g.x_of(ir), g.y_of(jr));
                let mut occ = 0f64;
                for layer in &inputs.occluder_layers {
                    let mut sum = 0f64;
                    for jo in 0..og.height {
                        for io in 0..og.width {
                            let zo = layer[jo * og.width + io] as f64;
                            if !(zo < zr) {
                                continue;
                            }
                            let k = zr * zo / (zr - zo);
                            let (xc, yc) = (og.x_of(io), og.y_of(jo));
                            let ox = overlap(
                                k * (xc - hw - xr) / lx + 0.5,
                                k * (xc + hw - xr) / lx + 0.5,
                            );
                            let oy = overlap(
                                k * (yc - hh - yr) / ly + 0.5,
                                k * (yc + hh - yr) / ly + 0.5,
                            );
                            sum += ox * oy;
                        }
                    }
                    occ = occ.max(sum.min(1.0));
                }
                out[jr * g.width + ir] = (1.0 - occ) as f32;
            }
        }
        out
    }

    /// A small deterministic generator (no dev-dependency needed).
    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn kernel_matches_the_brute_force_sum() {
        let mut seed = 7u64;
        // The last case has one receiver depth: whole tiles take the
        // per-column, per-row path (`add_texel_tile`).
        for (w, h, flat) in [
            (37, 29, false),
            (16, 16, false),
            (1, 9, false),
            (50, 1, false),
            (37, 29, true),
        ] {
            let grid = MapGrid::new(w, h, [0.4, 0.3]).unwrap();
            let front: Vec<f32> = (0..w * h)
                .map(|_| {
                    if lcg(&mut seed) < 0.4 {
                        (2.0 + lcg(&mut seed)) as f32
                    } else {
                        f32::INFINITY
                    }
                })
                .collect();
            let back: Vec<f32> = front
                .iter()
                .map(|z| if z.is_finite() { z + 0.5 } else { *z })
                .collect();
            let receiver: Vec<f32> = (0..w * h)
                .map(|_| {
                    if flat {
                        3.7
                    } else if lcg(&mut seed) < 0.9 {
                        (3.2 + lcg(&mut seed)) as f32
                    } else {
                        f32::INFINITY
                    }
                })
                .collect();
            for layers in [vec![&front[..]], vec![&front[..], &back[..]]] {
                let inputs = ShadowInputs {
                    grid,
                    occluder_grid: grid,
                    light_shape: LightShape::rect([1.0, 0.7]),
                    receiver: &receiver,
                    occluder_layers: layers,
                    occluder_triangles: None,
                };
                let fast = Ssm::default().visibility_map(&inputs);
                let slow = brute_force(&inputs);
                let max = fast
                    .iter()
                    .zip(&slow)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0f32, f32::max);
                assert!(max < 2e-5, "{w}x{h}: max |fast - brute| = {max}");
                assert!(fast.iter().all(|v| (0.0..=1.0).contains(v)));
                // Points at the texel centers give the map's values.
                let pts: Vec<LightPoint> = (0..w * h)
                    .map(|k| LightPoint {
                        x: grid.x_of(k % w) as f32,
                        y: grid.y_of(k / w) as f32,
                        z: receiver[k],
                    })
                    .collect();
                let at_points = Ssm::default().visibility_points(&inputs, &pts);
                let max = at_points
                    .iter()
                    .zip(&fast)
                    .map(|(a, b)| (a - b).abs())
                    .fold(0f32, f32::max);
                // Same sums, grouped differently: only the summation order differs.
                assert!(max < 1e-5, "points vs map: {max}");
            }
        }
    }

    #[test]
    fn coarser_or_finer_occluder_grids_match_the_brute_force_sum() {
        let mut seed = 11u64;
        let grid = MapGrid::new(40, 24, [0.4, 0.3]).unwrap();
        let receiver: Vec<f32> = (0..grid.len())
            .map(|_| (3.2 + lcg(&mut seed)) as f32)
            .collect();
        for (ow, oh) in [(13, 9), (64, 50), (1, 1)] {
            let og = MapGrid::new(ow, oh, [0.4, 0.3]).unwrap();
            let front: Vec<f32> = (0..og.len())
                .map(|_| {
                    if lcg(&mut seed) < 0.5 {
                        (2.0 + lcg(&mut seed)) as f32
                    } else {
                        f32::INFINITY
                    }
                })
                .collect();
            let inputs = ShadowInputs {
                grid,
                occluder_grid: og,
                light_shape: LightShape::rect([0.8, 1.1]),
                receiver: &receiver,
                occluder_layers: vec![&front],
                occluder_triangles: None,
            };
            let fast = Ssm::default().visibility_map(&inputs);
            let slow = brute_force(&inputs);
            let max = fast
                .iter()
                .zip(&slow)
                .map(|(a, b)| (a - b).abs())
                .fold(0f32, f32::max);
            assert!(max < 2e-5, "{ow}x{oh}: {max}");
        }
    }

    /// Random occluder depths in [2, 3] with the given occupancy, inf elsewhere.
    fn random_occluders(n: usize, occupancy: f64, seed: &mut u64) -> Vec<f32> {
        (0..n)
            .map(|_| {
                if lcg(seed) < occupancy {
                    (2.0 + lcg(seed)) as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect()
    }

    #[test]
    fn a_hierarchy_held_at_level_0_changes_no_bit() {
        let mut seed = 5u64;
        let grid = MapGrid::new(45, 38, [0.4, 0.3]).unwrap();
        let front = random_occluders(grid.len(), 0.5, &mut seed);
        let receiver: Vec<f32> = (0..grid.len())
            .map(|_| (3.2 + lcg(&mut seed)) as f32)
            .collect();
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect([1.0, 0.7]),
            receiver: &receiver,
            occluder_layers: vec![&front],
            occluder_triangles: None,
        };
        let fine = Some(Hierarchy {
            max_texel_on_light: 1e-9,
        });
        let without = Ssm::default().visibility_map(&inputs);
        let with = Ssm {
            hierarchy: fine,
            ..Default::default()
        }
        .visibility_map(&inputs);
        assert_eq!(with, without);
    }

    #[test]
    fn a_coarse_level_reads_as_the_map_downsampled_by_majority() {
        // An 8x8 occluder map has levels 8x8 and 4x4; with no limit on the
        // texel's size on the light every tile reads the 4x4 level, which
        // must shade exactly as a 4x4 map over the same extent holding, per
        // 2x2 block, the mean 1/depth of the occupied texels where most are
        // occupied (ties: where block i + j is even).
        let mut seed = 9u64;
        let (n, c) = (8usize, 4usize);
        let og = MapGrid::new(n, n, [0.4, 0.4]).unwrap();
        let coarse_grid = MapGrid::new(c, c, [0.4, 0.4]).unwrap();
        let grid = MapGrid::new(24, 24, [0.4, 0.4]).unwrap();
        for occupancy in [0.3, 0.5, 0.8] {
            let front = random_occluders(og.len(), occupancy, &mut seed);
            let mut coarse = vec![f32::INFINITY; c * c];
            for j in 0..c {
                for i in 0..c {
                    let kids: Vec<f32> = [(0, 0), (0, 1), (1, 0), (1, 1)]
                        .iter()
                        .map(|(dj, di)| front[(2 * j + dj) * n + 2 * i + di])
                        .filter(|z| z.is_finite())
                        .collect();
                    let wins = kids.len() > 2 || (kids.len() == 2 && (i + j) % 2 == 0);
                    if wins {
                        let mean_w = kids.iter().map(|z| 1.0 / z).sum::<f32>() / kids.len() as f32;
                        coarse[j * c + i] = 1.0 / mean_w;
                    }
                }
            }
            let receiver = vec![4.0f32; grid.len()];
            let with_levels = ShadowInputs {
                grid,
                occluder_grid: og,
                light_shape: LightShape::rect([1.0, 0.8]),
                receiver: &receiver,
                occluder_layers: vec![&front],
                occluder_triangles: None,
            };
            let coarse_inputs = ShadowInputs {
                occluder_grid: coarse_grid,
                occluder_layers: vec![&coarse],
                ..with_levels.clone()
            };
            let any_size = Some(Hierarchy {
                max_texel_on_light: 1e9,
            });
            let fast = Ssm {
                hierarchy: any_size,
                ..Default::default()
            }
            .visibility_map(&with_levels);
            let slow = brute_force(&coarse_inputs);
            let max = fast
                .iter()
                .zip(&slow)
                .map(|(a, b)| (a - b).abs())
                .fold(0f32, f32::max);
            assert!(max < 2e-5, "occupancy {occupancy}: {max}");
        }
    }

    /// binary16 bits -> value, written independently of `round_to_f16`.
    fn decode_f16(bits: u16) -> f32 {
        let e = ((bits >> 10) & 0x1f) as i32;
        let m = (bits & 0x3ff) as f32;
        match e {
            0 => m * 2f32.powi(-24),
            _ => (1.0 + m / 1024.0) * 2f32.powi(e - 15),
        }
    }

    #[test]
    fn rounding_to_f16_keeps_every_f16_and_sends_midpoints_to_even() {
        // Every positive finite binary16 value, and the way to the next.
        for bits in 0u16..0x7bff {
            let (a, b) = (decode_f16(bits), decode_f16(bits + 1));
            assert_eq!(round_to_f16(a), a, "{bits:#x}");
            let mid = 0.5 * (a + b); // exact in f32
            let even = if bits % 2 == 0 { a } else { b };
            assert_eq!(round_to_f16(mid), even, "midpoint after {bits:#x}");
            assert_eq!(round_to_f16(mid - (b - a) / 64.0), a);
            assert_eq!(round_to_f16(mid + (b - a) / 64.0), b);
        }
        assert_eq!(round_to_f16(65504.0), 65504.0);
        assert_eq!(round_to_f16(65520.0), f32::INFINITY);
        // Appendix A: 2048 + 1 = 2048 (a tie, to even); 0.5 + 1/2049 is lost
        // to truncation, which the paper's rule describes, but not to
        // nearest, which goes up to 0.5 + 1/2048; below half an ulp it is lost.
        assert_eq!(round_to_f16(2048.0 + 1.0), 2048.0);
        assert_eq!(
            round_to_f16(0.5 + round_to_f16(1.0 / 2049.0)),
            0.5 + 1.0 / 2048.0
        );
        assert_eq!(round_to_f16(0.5 + round_to_f16(1.0 / 4097.0)), 0.5);
    }

    #[test]
    fn every_precision_meets_the_plate_closed_form_where_fp16_suffices() {
        // At 48² each micro-patch of the plate hides (1/24)² of the light,
        // above FP16's 2^-10 limit (Appendix A), so every precision holds;
        // f16 rounds each of about 300 contributions, each by 2^-11 at most.
        // Under the disk inscribed in the light the plate's back-projection
        // is a rectangle clipped to the disk, which the micro-patches'
        // clipped areas tile exactly again (the patches across the rim carry
        // a few ulp of the disk's area each); the square's answer there
        // errs by the corners' area.
        use crate::geom::light_shape::LightShape;
        for (shape, exact) in [
            (LightShape::rect([1.0, 1.0]), 1e-5),
            (LightShape::disk(0.5), 2e-5),
        ] {
            for (precision, bound) in [
                (Precision::F32, exact),
                (Precision::F64, exact),
                (Precision::F16, 2e-2),
                (Precision::F16Batched, 2e-2),
            ] {
                let ssm = Ssm {
                    precision,
                    ..Default::default()
                };
                let (mean, max) = crate::methods::plate_case::mean_and_max_error(&ssm, 48, shape);
                assert!(
                    max < bound,
                    "{shape:?} {precision:?}: max {max}, mean {mean}"
                );
            }
        }
    }

    #[test]
    fn plate_over_parallel_floor_matches_the_closed_form() {
        // Additive micro-patches of one flat plate tile its back-projection
        // exactly, so only f32 rounding remains.
        let max = crate::methods::plate_case::max_error(&Ssm::default(), 64);
        assert!(max < 1e-5, "max error {max}");
    }

    /// A plate over a floor under a light as wide as the map: every tile
    /// reaches most of the occluder map.
    fn wide_light_visibility(limit: u64, threads: usize) -> (Vec<f32>, u64) {
        let n = 64;
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let front: Vec<f32> = (0..n * n)
            .map(|k| {
                let (x, y) = (grid.x_of(k % n), grid.y_of(k / n));
                if x.abs() < 0.3 && y.abs() < 0.2 {
                    2.0
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let receiver = vec![4.0f32; n * n];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect([8.0, 8.0]),
            receiver: &receiver,
            occluder_layers: vec![&front],
            occluder_triangles: None,
        };
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            crate::methods::gather::meter::metered(limit, || Ssm::default().visibility_map(&inputs))
        })
    }

    #[test]
    fn the_meter_counts_the_same_visits_on_any_thread_count_and_stops_past_its_limit() {
        let (full, visits) = wide_light_visibility(u64::MAX, 1);
        assert!(visits > 10_000, "{visits}");
        // The count is the groups' own, whatever order they ran in.
        for threads in [2, 4] {
            assert_eq!(
                wide_light_visibility(u64::MAX, threads),
                (full.clone(), visits)
            );
        }
        // At the count the call finishes; one under, it is stopped (the
        // groups after the crossing skipped, leaving their texels at 1).
        let (v, at) = wide_light_visibility(visits, 3);
        assert_eq!((v, at), (full.clone(), visits));
        let (v, over) = wide_light_visibility(visits / 4, 3);
        assert!(over > visits / 4 && over < visits, "{over} of {visits}");
        assert_ne!(v, full);
        // Outside `metered` no kernel counts.
        assert!(crate::methods::gather::meter::current_meter().is_none());
    }
}
