//! The table of methods: their options, defaults, limits, the backends that
//! run them and what they read. Built from the constants the configs check
//! against (`config.rs`), so the table cannot drift from the checks; the
//! Python package reads it from `_core` and copies nothing.

use super::config::{DEFAULT_SAMPLES, MAX_PASSES, MAX_SAMPLES};
use super::{bitmask, ssm::Precision, Input, HIERARCHY_DEFAULT_BITMASK, HIERARCHY_DEFAULT_SSM};
use crate::backend::Backend;
use crate::geom::light::{MAX_EXTENT, MAX_TEXELS};

/// An option's value, for defaults and allowed values.
#[derive(Debug, Clone, PartialEq)]
pub enum Value {
    /// Resolved when the config runs (see the option's `default_doc`).
    Resolved,
    Int(i64),
    Bool(bool),
    Str(&'static str),
    Float(f64),
}

/// What values an option takes.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// An integer in [min, max].
    Int {
        min: i64,
        max: i64,
    },
    /// One of these integers.
    OneOf(Vec<i64>),
    Bool,
    /// One of these names.
    Choice(Vec<&'static str>),
    /// A map resolution: an int (square) or (W, H), each at least 1, at most
    /// `max_texels` texels.
    Resolution {
        max_texels: i64,
    },
    /// An instance of one of these config classes (their own options are
    /// checked by their constructors).
    Config(Vec<&'static str>),
    /// A real number (its limits in the option's doc).
    Float,
}

/// One option of a method's config.
#[derive(Debug, Clone, PartialEq)]
pub struct OptionInfo {
    pub name: &'static str,
    pub kind: Kind,
    pub default: Value,
    /// The default in words (how a `Resolved` default is chosen).
    pub default_doc: &'static str,
    pub doc: &'static str,
    /// Backends that accept only some values of it: (backend, the values).
    pub restricted_on: Vec<(Backend, Vec<Value>)>,
}

/// One method.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodInfo {
    /// The name given as `method=`.
    pub name: &'static str,
    /// The config class (`softshadow.Ssm`, ...).
    pub config: &'static str,
    pub summary: &'static str,
    /// What it reads of the occluders (the receivers are always read).
    pub reads: Vec<Input>,
    /// The backends of this build that run it.
    pub backends: Vec<Backend>,
    pub options: Vec<OptionInfo>,
}

/// Limits that are not one method's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Texels per map.
    pub max_texels: usize,
    /// Tangent half-extent of a light-view map.
    pub max_extent: f64,
    /// Occluder depth layers.
    pub max_passes: u32,
    /// Light samples of `exact`.
    pub max_samples: u32,
    /// Worker threads per call (`threads=`).
    pub max_threads: usize,
    /// Largest map side on the GPU backend (0 without one).
    pub gpu_max_side: usize,
}

pub fn limits() -> Limits {
    Limits {
        max_texels: MAX_TEXELS,
        max_extent: MAX_EXTENT,
        max_passes: MAX_PASSES,
        max_samples: MAX_SAMPLES,
        max_threads: crate::threads::MAX_THREADS,
        gpu_max_side: if cfg!(feature = "gpu") {
            crate::backend::GPU_MAX_SIDE
        } else {
            0
        },
    }
}

fn passes() -> OptionInfo {
    OptionInfo {
        name: "passes",
        kind: Kind::Int {
            min: 1,
            max: MAX_PASSES as i64,
        },
        default: Value::Resolved,
        default_doc: "2 (front and back) from meshes; the layers given from depth maps",
        doc: "occluder depth layers: 1, the front; 2, front and back (paper §3.5); 3 to 8, \
              front, passes - 2 layers found by depth peeling, and back",
        restricted_on: vec![],
    }
}

fn occluder_resolution() -> OptionInfo {
    OptionInfo {
        name: "occluder_resolution",
        kind: Kind::Resolution {
            max_texels: MAX_TEXELS as i64,
        },
        default: Value::Resolved,
        default_doc: "the output's resolution; from depth maps, the occluder maps' shape",
        doc: "resolution of the occluder maps (same extent as the output): coarser maps \
              cost less, their error is the discretization of paper §4.1.1",
        restricted_on: vec![],
    }
}

fn hierarchy(default_on: bool) -> OptionInfo {
    OptionInfo {
        name: "hierarchy",
        kind: Kind::Bool,
        default: Value::Resolved,
        default_doc: if default_on {
            "on on the CPU; off on the GPU, which has no hierarchy"
        } else {
            "off (the paper's method, reproduced as published)"
        },
        doc: "read the occluder maps through a min/max pyramid: each 8x8 tile of receivers \
              reads the coarsest level whose texels cover at most 3% of the light's width",
        restricted_on: vec![(Backend::Gpu, vec![Value::Bool(false)])],
    }
}

/// The methods, in the order a user meets them.
pub fn methods() -> Vec<MethodInfo> {
    let backends = Backend::built().to_vec();
    let sampling_default = DEFAULT_SAMPLES as i64;
    vec![
        MethodInfo {
            name: "ssm",
            config: "Ssm",
            summary: "Soft shadow maps (Atty et al. 2005) as published: micro-patches of the \
                      occluder maps back-projected onto the light, their occlusions summed",
            reads: vec![Input::OccluderLayers],
            backends: backends.clone(),
            options: vec![
                passes(),
                occluder_resolution(),
                hierarchy(HIERARCHY_DEFAULT_SSM),
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
        },
        MethodInfo {
            name: "bitmask",
            config: "Bitmask",
            summary: "The same micro-patches marking the light samples they hide in a bit mask \
                      per receiver, merged by OR (Schwarz & Stamminger 2007)",
            reads: vec![Input::OccluderLayers],
            backends: backends.clone(),
            options: vec![
                OptionInfo {
                    name: "samples",
                    kind: Kind::OneOf(bitmask::SAMPLE_COUNTS.iter().map(|&n| n as i64).collect()),
                    default: Value::Int(sampling_default),
                    default_doc: "256",
                    doc: "light samples per receiver, a multi-jittered pattern shared by all \
                          receivers",
                    restricted_on: vec![],
                },
                passes(),
                occluder_resolution(),
                hierarchy(HIERARCHY_DEFAULT_BITMASK),
                OptionInfo {
                    name: "gaps",
                    kind: Kind::Choice(bitmask::Gaps::ALL.iter().map(|g| g.name()).collect()),
                    default: Value::Str(bitmask::Gaps::default().name()),
                    default_doc: "closed",
                    doc: "how neighbouring micro-patches meet: closed, connected micro-quads \
                          (no light between neighbours on one surface; a depth step steeper \
                          than 76° from the light's direction stays open); open, the flat \
                          per-texel micro-patches of the paper, whose gaps leak light (§4.1.2)",
                    restricted_on: vec![],
                },
            ],
        },
        MethodInfo {
            name: "exact",
            config: "Exact",
            summary: "Ray casting against the occluder triangles (a BVH) with stratified light \
                      samples, jittered deterministically: converges to the true visibility",
            reads: vec![Input::OccluderTriangles],
            backends: backends.clone(),
            options: vec![OptionInfo {
                name: "samples",
                kind: Kind::Int {
                    min: 1,
                    max: MAX_SAMPLES as i64,
                },
                default: Value::Int(sampling_default),
                default_doc: "256 (a 16x16 stratification)",
                doc: "light samples per receiver",
                restricted_on: vec![],
            }],
        },
        MethodInfo {
            name: "pcss",
            config: "PCSS",
            summary: "Percentage-closer soft shadows (Fernando 2005), what real-time engines \
                      ship: a blocker search on the shadow map, the penumbra estimated from the \
                      mean blocker depth, a box PCF of that width",
            reads: vec![Input::OccluderLayers],
            backends: backends.clone(),
            options: vec![
                OptionInfo {
                    name: "max_taps",
                    kind: Kind::Int {
                        min: 1,
                        max: super::pcss::MAX_TAPS as i64,
                    },
                    default: Value::Int(super::pcss::DEFAULT_MAX_TAPS as i64),
                    default_doc: "16",
                    doc: "taps per axis of the blocker search and of the filter: a box spanning \
                          more texels is sampled by this many strata (bounded work per point)",
                    restricted_on: vec![],
                },
                occluder_resolution(),
            ],
        },
        MethodInfo {
            name: "smoothies",
            config: "Smoothies",
            summary: "Fake soft shadows (Chan & Durand 2003): the hard shadow map's umbra and an \
                      outer penumbra from smoothies on the occluders' silhouette edges, their \
                      alpha remapped by 1/(1 - b/r)",
            reads: vec![Input::OccluderLayers, Input::OccluderTriangles],
            backends: backends.clone(),
            options: vec![
                OptionInfo {
                    name: "width",
                    kind: Kind::Float,
                    default: Value::Float(super::config::DEFAULT_SMOOTHIE_WIDTH),
                    default_doc:
                        "0.5, measured against exact on the eye scenes (1.0 is the penumbra of \
                         the light's size for blockers at the median silhouette depth)",
                    doc: "the smoothies' width in the light's image plane, as a factor of the \
                          light-matched width, in (0, 16]",
                    restricted_on: vec![],
                },
                OptionInfo {
                    name: "falloff",
                    kind: Kind::Choice(
                        super::smoothies::Falloff::ALL
                            .iter()
                            .map(|f| f.name())
                            .collect(),
                    ),
                    default: Value::Str("linear"),
                    default_doc: "linear",
                    doc:
                        "the penumbra's profile: linear alpha, or the sinusoidal (1 - cos(pi v))/2",
                    restricted_on: vec![],
                },
                OptionInfo {
                    name: "filter",
                    kind: Kind::Choice(super::config::SMOOTHIE_FILTERS.to_vec()),
                    default: Value::Str("bilinear"),
                    default_doc: "bilinear",
                    doc: "the lookup: the paper's 2x2 tent over the shadow map and smoothie buffer",
                    restricted_on: vec![],
                },
                occluder_resolution(),
            ],
        },
        shadow_mapping_row(),
        MethodInfo {
            name: "auto",
            config: "Auto",
            summary: "A plan, not a method: without a target, \"ssm\" with two passes and \
                      occluder maps at a quarter of the output's resolution (at least 64, at \
                      most the output's), the point of the study's accuracy-time plane furthest \
                      ahead of ray tracing; with error= or time=, the setting planned from the \
                      scene (light-view maps from meshes; sm.plan says why)",
            reads: vec![Input::OccluderLayers],
            backends,
            options: vec![
                OptionInfo {
                    name: "error",
                    kind: Kind::Float,
                    default: Value::Resolved,
                    default_doc: "None (no target)",
                    doc: "the error to reach (the paper's §4.2.1 metric, mean |V - V_ref| over \
                          the shadow), in [1e-4, 1]: the cheapest setting measured within it",
                    restricted_on: vec![],
                },
                OptionInfo {
                    name: "time",
                    kind: Kind::Float,
                    default: Value::Resolved,
                    default_doc: "None (no budget)",
                    doc: "a time budget in seconds, in [1e-6, 1e6]: a timed probe, then the most \
                          accurate setting predicted to fit; not with error",
                    restricted_on: vec![],
                },
            ],
        },
    ]
}

/// ShadowMapping's row: the eye view, every backend, its parts as config classes.
fn shadow_mapping_row() -> MethodInfo {
    use super::shadow_mapping::config::{DEFAULT_SM_RESOLUTION, MAX_SM_SIDE};
    let part = |name, classes: Vec<&'static str>, doc| OptionInfo {
        name,
        kind: Kind::Config(classes),
        default: Value::Resolved,
        default_doc: "None (off)",
        doc,
        restricted_on: vec![],
    };
    MethodInfo {
        name: "shadow_mapping",
        config: "ShadowMapping",
        summary: "The standard shadow map from the light's centre or direction with Scherzer \
                  2005's practical extensions: bias methods, PCF, focusing on the \
                  intersection body, LiSPSM (directional lights), the eye-space blur; hard \
                  shadows, the eye view only",
        reads: vec![Input::SceneTriangles, Input::Camera],
        backends: Backend::built().to_vec(),
        options: vec![
            OptionInfo {
                name: "resolution",
                kind: Kind::Resolution {
                    max_texels: (MAX_SM_SIDE * MAX_SM_SIDE) as i64,
                },
                default: Value::Int(DEFAULT_SM_RESOLUTION as i64),
                default_doc: "2048 x 2048 (Scherzer's)",
                doc: "the shadow map's (W, H), each side at most 16384",
                restricted_on: vec![],
            },
            OptionInfo {
                name: "bias",
                kind: Kind::Config(vec![
                    "ConstantBias",
                    "SlopeScaleBias",
                    "LinearDepthBias",
                    "BackFaces",
                    "MidpointBias",
                ]),
                default: Value::Str("SlopeScaleBias"),
                default_doc:
                    "SlopeScaleBias(constant=4, slope=2): glPolygonOffset(2, 4), Scherzer's",
                doc: "how the depth test keeps surfaces from shadowing themselves (Scherzer §4.2)",
                restricted_on: vec![],
            },
            part(
                "filter",
                vec!["PCF"],
                "percentage-closer filtering of the depth test",
            ),
            part(
                "warp",
                vec!["LiSPSM"],
                "LiSPSM (directional lights only): more texels near the camera",
            ),
            OptionInfo {
                name: "focus",
                kind: Kind::Bool,
                default: Value::Bool(true),
                default_doc: "True",
                doc: "fit the map to the intersection body B (view frustum and scene bounds, \
                      extended toward the light); False: to the whole scene",
                restricted_on: vec![],
            },
            part(
                "blur",
                vec!["EyeSpaceBlur"],
                "the depth-dependent eye-space blur of the shadow image (Scherzer §4.3)",
            ),
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_method_name_has_one_row() {
        let names: Vec<_> = methods().iter().map(|m| m.name).collect();
        assert_eq!(names, super::super::config::METHOD_NAMES);
    }

    /// A default written out as a number in the docs is the default the
    /// config takes (the text is hand-written beside the value).
    #[test]
    fn numeric_default_docs_match_the_defaults() {
        for m in methods() {
            for o in &m.options {
                let lead: String = o
                    .default_doc
                    .chars()
                    .take_while(|c| c.is_ascii_digit() || *c == '.')
                    .collect();
                match (&o.default, lead.parse::<f64>()) {
                    (Value::Int(v), Ok(d)) => assert_eq!(*v as f64, d, "{}.{}", m.name, o.name),
                    (Value::Float(v), Ok(d)) => assert_eq!(*v, d, "{}.{}", m.name, o.name),
                    _ => {}
                }
            }
        }
    }
}
