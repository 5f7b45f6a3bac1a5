//! The typed config of `ShadowMapping` and its parts, as a user writes
//! them; every value is checked here, once, when the config is built.
//!
//! `ShadowMappingConfig`'s `MethodSpec` (name, string form, resolution,
//! capabilities row) is at the end of this file.

use crate::backend::Backend;
use crate::error::{Error, Result};
use crate::geom::shadow_projection::ViewVector;
use crate::methods::config::{CallContext, LooseOptions, MethodSpec};
use crate::methods::info::{Kind, MethodInfo, OptionInfo, Value};
use crate::methods::kernel::Kernel;
use crate::methods::shadow_mapping::raster::{Distribution, Offset};
use crate::methods::{Input, ShadowMethod};

/// A finite f64 that configs can hash and compare (by its bits).
#[derive(Debug, Clone, Copy, PartialEq, PartialOrd, Default)]
pub struct Real(pub f64);
impl Eq for Real {}
impl std::hash::Hash for Real {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        // 0.0 and -0.0 compare equal: hash them alike.
        (self.0 + 0.0).to_bits().hash(h)
    }
}

/// A finite number in [lo, hi], or an error naming `arg`.
pub fn check_real(arg: &str, v: f64, lo: f64, hi: f64, what: &str) -> Result<Real> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(Real(v))
    } else {
        Err(Error::invalid(
            arg,
            format!("must be {what} in [{lo}, {hi}], got {v}"),
        ))
    }
}

/// How the depth test avoids surfaces shadowing themselves (Scherzer 2005
/// §4.2 compares them), each named after what it does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DepthBias {
    /// The same offset everywhere, in depth steps of a 24-bit buffer.
    Constant { constant: Real },
    /// glPolygonOffset on the z-buffer's own (hyperbolic) depth: `slope`
    /// times the depth's slope per texel plus `constant` steps.
    SlopeScale { constant: Real, slope: Real },
    /// The same on a linear depth distribution (the TSM paper's, which
    /// Scherzer found best).
    LinearDepth { constant: Real, slope: Real },
    /// Only faces turned away from the light are written (the map holds the
    /// far side of solid casters); no offset.
    BackFaces,
    /// Woo's midpoint: the test depth halfway between the nearest and the
    /// second nearest surface.
    Midpoint,
}

/// The largest `constant` (depth steps: 2²⁰ is 1/16 of the depth range).
pub const MAX_CONSTANT: f64 = (1u64 << 20) as f64;
/// The largest `slope` factor.
pub const MAX_SLOPE: f64 = 64.0;
/// glPolygonOffset(2, 4), Scherzer's setting for his scene ("a relatively
/// small slope-scale bias of 2.0/4.0").
pub const DEFAULT_SLOPE: f64 = 2.0;
pub const DEFAULT_CONSTANT: f64 = 4.0;

impl DepthBias {
    pub fn constant(constant: f64) -> Result<Self> {
        Ok(DepthBias::Constant {
            constant: check_real(
                "constant",
                constant,
                0.0,
                MAX_CONSTANT,
                "a number of depth steps",
            )?,
        })
    }
    fn pair(constant: Option<f64>, slope: Option<f64>) -> Result<(Real, Real)> {
        Ok((
            check_real(
                "constant",
                constant.unwrap_or(DEFAULT_CONSTANT),
                0.0,
                MAX_CONSTANT,
                "a number of depth steps",
            )?,
            check_real(
                "slope",
                slope.unwrap_or(DEFAULT_SLOPE),
                0.0,
                MAX_SLOPE,
                "a factor",
            )?,
        ))
    }
    pub fn slope_scale(constant: Option<f64>, slope: Option<f64>) -> Result<Self> {
        let (constant, slope) = Self::pair(constant, slope)?;
        Ok(DepthBias::SlopeScale { constant, slope })
    }
    pub fn linear_depth(constant: Option<f64>, slope: Option<f64>) -> Result<Self> {
        let (constant, slope) = Self::pair(constant, slope)?;
        Ok(DepthBias::LinearDepth { constant, slope })
    }

    pub fn name(&self) -> &'static str {
        match self {
            DepthBias::Constant { .. } => "constant",
            DepthBias::SlopeScale { .. } => "slope_scale",
            DepthBias::LinearDepth { .. } => "linear_depth",
            DepthBias::BackFaces => "back_faces",
            DepthBias::Midpoint => "midpoint",
        }
    }

    /// The depth the map holds.
    pub fn distribution(&self) -> Distribution {
        match self {
            DepthBias::Constant { .. } | DepthBias::SlopeScale { .. } => Distribution::Hyperbolic,
            _ => Distribution::Linear,
        }
    }

    /// The offset written with each depth.
    pub fn offset(&self) -> Offset {
        match *self {
            DepthBias::Constant { constant } => Offset {
                constant: constant.0,
                slope: 0.0,
            },
            DepthBias::SlopeScale { constant, slope }
            | DepthBias::LinearDepth { constant, slope } => Offset {
                constant: constant.0,
                slope: slope.0,
            },
            DepthBias::BackFaces | DepthBias::Midpoint => Offset::default(),
        }
    }
}

/// Percentage-closer filtering (Reeves et al. 1987): `methods/pcf.rs`'s
/// `Pcf { size }`, size×size taps one texel apart centred on the point,
/// each the bilinear blend of its four nearest texels' tests (the box
/// filter of width `size` texels: a step edge becomes a linear ramp `size`
/// texels wide). `size` 1 is the 2×2 bilinear PCF of hardware.
pub use crate::methods::pcf::Pcf;
pub const MAX_PCF: u32 = 33;
pub const DEFAULT_PCF: u32 = 3;

/// `PCF(size=)`: 1 to MAX_PCF taps per axis.
pub fn check_pcf(size: Option<i64>) -> Result<Pcf> {
    let size = size.unwrap_or(DEFAULT_PCF as i64);
    if (1..=MAX_PCF as i64).contains(&size) {
        Ok(Pcf { size: size as u32 })
    } else {
        Err(Error::invalid(
            "size",
            format!("PCF's size must be a number of taps per axis in [1, {MAX_PCF}], got {size}"),
        ))
    }
}

/// Light-space perspective shadow maps (Wimmer, Scherzer & Purgathofer
/// 2004): `n` the warp's parameter (None: n_opt), `vector` the view vector
/// the warp follows (Scherzer's middle vector, or the camera's axis).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct LiSPSM {
    pub n: Option<Real>,
    pub vector: ViewVector,
}
pub const MAX_N: f64 = 1e12;

impl LiSPSM {
    pub fn new(n: Option<f64>, vector: Option<&str>) -> Result<Self> {
        let vector = match vector {
            None => ViewVector::Middle,
            Some(s) => ViewVector::parse(s).ok_or_else(|| {
                Error::invalid(
                    "vector",
                    format!(
                        "must be one of {:?}, got {s:?}",
                        ViewVector::ALL.map(|v| v.name())
                    ),
                )
            })?,
        };
        let n = match n {
            None => None,
            Some(n) if n.is_finite() && n > 0.0 && n <= MAX_N => Some(Real(n)),
            Some(n) => {
                return Err(Error::invalid(
                    "n",
                    format!(
                        "LiSPSM's n must be a distance in (0, {MAX_N:e}] (world units), got {n}"
                    ),
                ))
            }
        };
        Ok(LiSPSM { n, vector })
    }
}

/// Scherzer's eye-space blur of the shadow image (§4.3), depth-dependent:
/// `iterations` passes of a 3×3 [1 2 1]² kernel whose taps lie `radius`
/// pixels apart at the nearest visible depth z₀ and `radius · z₀/z` at
/// depth z (rounded; 0 leaves the pixel as it is), mixing only pixels that
/// see a surface at a similar depth (within `DEPTH_TOLERANCE` of z).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct EyeSpaceBlur {
    pub iterations: u32,
    pub radius: Real,
}
pub const MAX_ITERATIONS: u32 = 64;
pub const MAX_RADIUS: f64 = 32.0;
pub const DEFAULT_ITERATIONS: u32 = 4;
pub const DEFAULT_RADIUS: f64 = 2.0;
/// Neighbours further than this fraction of the pixel's depth are not mixed.
pub const DEPTH_TOLERANCE: f64 = 0.05;

impl EyeSpaceBlur {
    pub fn new(iterations: Option<i64>, radius: Option<f64>) -> Result<Self> {
        let it = iterations.unwrap_or(DEFAULT_ITERATIONS as i64);
        if !(1..=MAX_ITERATIONS as i64).contains(&it) {
            return Err(Error::invalid(
                "iterations",
                format!("must be in [1, {MAX_ITERATIONS}], got {it}"),
            ));
        }
        Ok(EyeSpaceBlur {
            iterations: it as u32,
            radius: check_real(
                "radius",
                radius.unwrap_or(DEFAULT_RADIUS),
                0.0,
                MAX_RADIUS,
                "a number of pixels",
            )?,
        })
    }
}

/// The standard shadow map with Scherzer's practical extensions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ShadowMappingConfig {
    /// The map's (W, H).
    pub resolution: (usize, usize),
    pub bias: DepthBias,
    pub filter: Option<Pcf>,
    pub warp: Option<LiSPSM>,
    /// Fit the map to the intersection body B (needs a camera); false: to
    /// the whole scene.
    pub focus: bool,
    pub blur: Option<EyeSpaceBlur>,
}

pub const DEFAULT_SM_RESOLUTION: usize = 2048;
pub use crate::methods::shadow_mapping::raster::MAX_SM_SIDE;

impl Default for ShadowMappingConfig {
    fn default() -> Self {
        ShadowMappingConfig {
            resolution: (DEFAULT_SM_RESOLUTION, DEFAULT_SM_RESOLUTION),
            bias: DepthBias::SlopeScale {
                constant: Real(DEFAULT_CONSTANT),
                slope: Real(DEFAULT_SLOPE),
            },
            filter: None,
            warp: None,
            focus: true,
            blur: None,
        }
    }
}

impl ShadowMappingConfig {
    pub fn new(
        resolution: Option<(i64, i64)>,
        bias: Option<DepthBias>,
        filter: Option<Pcf>,
        warp: Option<LiSPSM>,
        focus: Option<bool>,
        blur: Option<EyeSpaceBlur>,
    ) -> Result<Self> {
        let d = ShadowMappingConfig::default();
        let resolution = match resolution {
            None => d.resolution,
            Some((w, h)) => {
                let ok = |s: i64| (1..=MAX_SM_SIDE as i64).contains(&s);
                if !(ok(w) && ok(h)) {
                    return Err(Error::invalid(
                        "resolution",
                        format!("each side must be in [1, {MAX_SM_SIDE}], got ({w}, {h})"),
                    ));
                }
                (w as usize, h as usize)
            }
        };
        Ok(ShadowMappingConfig {
            resolution,
            bias: bias.unwrap_or(d.bias),
            filter,
            warp,
            focus: focus.unwrap_or(d.focus),
            blur,
        })
    }

    /// What needs a camera: refused in the light view, by name.
    pub fn needs_camera(&self) -> Option<&'static str> {
        if self.warp.is_some() {
            Some("warp")
        } else if self.blur.is_some() {
            Some("blur")
        } else if self.focus {
            Some("focus")
        } else {
            None
        }
    }
}

/// Its own eye-view stage (`eye::shadow_mapping`): it reads every mesh and
/// the camera, and has no light-view kernel.
impl Kernel for ShadowMappingConfig {
    const READS: &'static [Input] = &[Input::SceneTriangles, Input::Camera];

    fn implementation(&self) -> Box<dyn ShadowMethod> {
        // Refused outside the eye view when the config is resolved.
        unreachable!("ShadowMapping has no light-view kernel")
    }
}

impl MethodSpec for ShadowMappingConfig {
    const NAME: &'static str = "shadow_mapping";
    fn from_loose(o: &LooseOptions, refuse: &dyn Fn(&str, &str) -> Error) -> Result<Self> {
        if let Some(opt) = o.given().first() {
            return Err(refuse(
                opt,
                "the soft shadow map methods; give ShadowMapping(...) its own options",
            ));
        }
        Ok(ShadowMappingConfig::default())
    }
    type Resolved = Self;
    /// Its options are its kernel's.
    type Kernel = Self;
    fn kernel(&self) -> Self {
        *self
    }
    fn resolve(self, ctx: &CallContext) -> Result<Self::Resolved> {
        if !ctx.eye {
            return Err(Error::invalid(
                "method",
                "ShadowMapping renders the eye view (ss.render): its map is focused, \
                 warped and blurred for a camera; in the light view use method=\"ssm\" \
                 or \"exact\" with a point light for hard shadows",
            ));
        }
        if ctx.depth_layers.is_some() {
            return Err(Error::invalid(
                "method",
                "ShadowMapping rasterizes its own map of the meshes; depth maps are not enough",
            ));
        }
        Ok(self)
    }
    fn info() -> MethodInfo {
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
            // The kernel's (`Kernel::READS`).
            reads: <Self as Kernel>::READS.to_vec(),
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
}
