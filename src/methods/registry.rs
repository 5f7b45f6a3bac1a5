//! The registry of methods: the kernel enum (`Method`) with each method's
//! names, what it reads and its implementation, and the dispatch of a map
//! or points to it (the point-light path included).

use super::gather::Hierarchy;
use super::inputs::{Input, LightPoint, ShadowInputs, ShadowMethod};
use super::{bitmask, exact, pcss, point_light, shadow_mapping, smoothies, ssm};

/// A method's kernel, with the options that change what it computes (the
/// options that change what it reads, layers and their resolution, are the
/// pipeline's: see `config.rs`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// Soft shadow maps, Atty et al. 2005, as published (additive
    /// micro-patches); `hierarchy` reads coarser occluder texels where the
    /// penumbra is wide (off by default: the paper has none).
    Ssm {
        hierarchy: bool,
        precision: ssm::Precision,
    },
    /// Ray casting against the occluder triangles with stratified light samples.
    Exact { samples: u32 },
    /// Micro-patches marking light samples in a bit mask per receiver (OR);
    /// `hierarchy` as for Ssm (on by default); `gaps` how neighbouring
    /// micro-patches meet (closed: connected micro-quads).
    Bitmask {
        samples: u32,
        hierarchy: bool,
        gaps: bitmask::Gaps,
    },
    /// Scherzer 2005's shadow mapping: its own map and depth test
    /// (`shadow_mapping/`, the eye view only).
    ShadowMapping(shadow_mapping::config::ShadowMappingConfig),
    /// Smoothies (Chan & Durand 2003) from the front layer and the
    /// occluders' silhouette.
    Smoothies {
        width: shadow_mapping::config::Real,
        falloff: smoothies::Falloff,
    },
    /// PCSS (Fernando 2005) on the front layer.
    Pcss { max_taps: u32 },
}

/// The level choice of the occluder hierarchy: a texel may back-project onto
/// at most this fraction of the light's width, seen from the receiver it is
/// nearest to. Measured with bitmask (256 samples, two passes) against
/// Mitsuba on the study's scenes (`benchmarks/bench_hierarchy.py`): at 3% the
/// error moves by at most 0.001 while 512² maps take 1.2-4.4x less time; at
/// 6% the error grew by up to 0.003 (a coarse texel misplaces an edge by half
/// its back-projection), at 12.5% by up to 0.02.
pub const HIERARCHY: Hierarchy = Hierarchy {
    max_texel_on_light: 0.03,
};

/// Whether the hierarchy is on by default on the CPU: off for the paper's
/// method (reproduced as published), on for bitmask.
pub const HIERARCHY_DEFAULT_SSM: bool = false;
pub const HIERARCHY_DEFAULT_BITMASK: bool = true;

impl Method {
    /// The name a user passes as `method=`.
    pub fn name(&self) -> &'static str {
        match self {
            Method::Ssm { .. } => "ssm",
            Method::Exact { .. } => "exact",
            Method::Bitmask { .. } => "bitmask",
            Method::ShadowMapping(_) => "shadow_mapping",
            Method::Smoothies { .. } => "smoothies",
            Method::Pcss { .. } => "pcss",
        }
    }

    /// What the method reads of the occluders.
    pub fn reads(&self) -> &'static [Input] {
        match self {
            Method::Ssm { .. } | Method::Bitmask { .. } | Method::Pcss { .. } => {
                &[Input::OccluderLayers]
            }
            Method::Exact { .. } => &[Input::OccluderTriangles],
            Method::ShadowMapping(_) => &[Input::SceneTriangles, Input::Camera],
            Method::Smoothies { .. } => &[Input::OccluderLayers, Input::OccluderTriangles],
        }
    }

    /// Whether the method only traces triangles (reads no occluder maps):
    /// `exact`.
    pub fn traces(&self) -> bool {
        self.reads_input(Input::OccluderTriangles) && !self.reads_input(Input::OccluderLayers)
    }

    /// Whether the method reads `input`.
    pub fn reads_input(&self, input: Input) -> bool {
        self.reads().contains(&input)
    }

    /// f32 maps the kernel keeps per occluder layer, each of the occluder
    /// grid's size: for the gather methods the 1/depth copy and its nearest
    /// and farthest bounds (`gather/hierarchy.rs`), and for connected
    /// micro-quads their corner 1/depths and those corners' reciprocals
    /// from the receivers' common plane (4 each); a hierarchy's levels add
    /// a third. Other methods: one map.
    pub fn kernel_maps_per_layer(&self) -> usize {
        let (maps, hierarchy): (usize, bool) = match *self {
            Method::Bitmask {
                hierarchy, gaps, ..
            } => (
                if gaps == bitmask::Gaps::Closed { 11 } else { 3 },
                hierarchy,
            ),
            Method::Ssm { hierarchy, .. } => (3, hierarchy),
            _ => (1, false),
        };
        if hierarchy {
            maps + maps.div_ceil(3)
        } else {
            maps
        }
    }

    pub fn implementation(&self) -> Box<dyn ShadowMethod> {
        match *self {
            Method::Ssm {
                hierarchy,
                precision,
            } => Box::new(ssm::Ssm {
                hierarchy: hierarchy.then_some(HIERARCHY),
                precision,
            }),
            Method::Exact { samples } => Box::new(exact::Exact { samples }),
            Method::Bitmask {
                samples,
                hierarchy,
                gaps,
            } => Box::new(bitmask::Bitmask::new(
                samples,
                gaps,
                hierarchy.then_some(HIERARCHY),
            )),
            // Refused outside the eye view when the config is resolved.
            Method::ShadowMapping(_) => unreachable!("ShadowMapping has no light-view kernel"),
            Method::Smoothies { width, falloff } => Box::new(smoothies::Smoothies {
                width: width.0,
                falloff,
            }),
            Method::Pcss { max_taps } => Box::new(pcss::Pcss { max_taps }),
        }
    }
}

/// A texel-aligned square plate over a parallel floor, whose visibility has
/// a closed form: the methods' shared accuracy check.
/// Visibility of every receiver texel: the method's, or for a point light
/// (size 0) on the map methods the hard shadow they converge to.
pub fn shade_map(method: Method, inputs: &ShadowInputs) -> Vec<f32> {
    if inputs.light_shape.is_point() && method.reads_input(Input::OccluderLayers) {
        point_light::visibility_map(inputs)
    } else {
        method.implementation().visibility_map(inputs)
    }
}

/// Visibility at receiver points, as `shade_map`.
pub fn shade_points(method: Method, inputs: &ShadowInputs, pts: &[LightPoint]) -> Vec<f32> {
    if inputs.light_shape.is_point() && method.reads_input(Input::OccluderLayers) {
        point_light::visibility_points(inputs, pts)
    } else {
        method.implementation().visibility_points(inputs, pts)
    }
}
