//! Shadow methods. Each method is one module behind [`ShadowMethod`]; every
//! method reads the same inputs (the light-view maps) and writes the same
//! outputs (visibility per receiver texel, or per receiver point).

pub mod ssm;

use crate::error::{Error, Result};
use crate::light::MapGrid;

/// What every method reads: the light-view maps and the light's size.
#[derive(Debug, Clone)]
pub struct ShadowInputs<'a> {
    pub grid: MapGrid,
    /// Full light width along u and height along v (world units).
    pub light_size: [f64; 2],
    /// Receiver planar depth per texel, `inf` where there is no receiver.
    pub receiver: &'a [f32],
    /// Occluder depth layers: the front (nearest) map, then the back (farthest) one.
    pub occluder_layers: Vec<&'a [f32]>,
}

/// A receiver point in light space: tangent coordinates and planar depth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightPoint {
    pub x: f32,
    pub y: f32,
    pub z: f32,
}

/// The interface of a shadow method.
pub trait ShadowMethod: Sync {
    /// Visibility of the light (fraction of its area) for every receiver texel;
    /// 1 where there is no receiver. Row-major (H, W).
    fn visibility_map(&self, inputs: &ShadowInputs) -> Vec<f32>;
    /// Visibility at receiver points given in light space.
    fn visibility_points(&self, inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32>;
}

/// The methods a user can pick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// Soft shadow maps, Atty et al. 2005, as published (additive micro-patches).
    Ssm,
}

impl Method {
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "ssm" => Ok(Method::Ssm),
            other => Err(Error::invalid(
                "method",
                format!("unknown method {other:?}; available: \"ssm\""),
            )),
        }
    }

    pub fn implementation(&self) -> &'static dyn ShadowMethod {
        match self {
            Method::Ssm => &ssm::Ssm,
        }
    }
}
