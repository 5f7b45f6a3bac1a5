//! What a method's kernel says of itself: the value a resolved config runs
//! (`Method`, made by the registry from one line per method: `mod.rs`,
//! `registry.rs`), with the options that change what it computes. Every
//! stage that must tell the methods apart asks the kernel through this
//! trait (what it reads, how its work is bounded, how many rays it traces
//! a receiver), so that no stage names a method and a new method is its
//! module, its registry line and its GPU kernel.
//!
//! Implemented in each method's own module, beside its `ShadowMethod`.

use super::engine::Engine;
use super::inputs::{Input, LightPoint, ShadowInputs, ShadowMethod};
use crate::error::Result;

/// A method's kernel: see the module's doc.
pub trait Kernel: Copy + Eq + std::hash::Hash + std::fmt::Debug {
    /// What the method reads of the occluders.
    const READS: &'static [Input];

    /// Whether the kernel tests its texels on each receiver point's tangent
    /// plane where the eye view gives one (`geom/plane_gradient.rs`): the
    /// methods whose taps reach texels beside the point's. (The gather
    /// methods bound a receiver by its tangent plane already, and
    /// ShadowMapping has its own.)
    const TESTS_PLANES: bool = false;

    /// Whether, in the eye view, every face is an occluder, even those that
    /// cannot shadow a visible point (`eye::framing::casting_faces`): the
    /// smoothies read the depth of the receiver behind each silhouette from
    /// the map.
    const READS_EVERY_FACE: bool = false;

    /// f32 maps the kernel keeps per occluder layer, each of the occluder
    /// grid's size (`Method::kernel_maps_per_layer`, the memory estimate).
    fn maps_per_layer(&self) -> usize {
        1
    }

    /// The cost of one visit of a gather kernel in visits of `bitmask` with
    /// 256 samples (`gather::work::visit_cost`); `None` for a kernel that
    /// does not gather over the occluder maps.
    fn visit_cost(&self) -> Option<f64> {
        None
    }

    /// The light samples a receiver of a ray-traced kernel, its probe's and
    /// the engine that decides them; `None` for a kernel that traces no
    /// rays per light sample.
    fn rays(&self) -> Option<(u32, Option<u32>, Engine)> {
        None
    }

    /// Refuses, naming the option that drives it, a call whose work a bound
    /// known before any receiver is shaded puts past the kernel's limit
    /// (`points`: the receivers; None, the receiver map's texels).
    fn check_cost(&self, _inputs: &ShadowInputs, _points: Option<&[LightPoint]>) -> Result<()> {
        Ok(())
    }

    /// The CPU implementation.
    fn implementation(&self) -> Box<dyn ShadowMethod>;
}
