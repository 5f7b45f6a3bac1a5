//! Practical shadow mapping for large scenes (Scherzer 2005): the standard
//! shadow map from the light's centre or direction, its bias methods, PCF,
//! focusing on the intersection body, LiSPSM and the eye-space blur.

pub mod blur;
pub mod config;
pub mod lookup;
pub mod raster;
