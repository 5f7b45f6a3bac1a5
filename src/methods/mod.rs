//! Shadow methods. Each method is one module behind [`ShadowMethod`],
//! configured by one typed config (`config.rs`) and declaring what it reads
//! ([`Method::reads`]); every method writes the same outputs (visibility per
//! receiver texel, or per receiver point). `capabilities.rs` publishes the
//! table of methods, options, defaults and limits.

pub mod bitmask;
pub mod bvh;
mod bvh_node;
pub(crate) mod bvh_wide;
pub mod capabilities;
pub mod config;
pub mod exact;
pub(crate) mod gather;
pub mod info;
pub mod inputs;
pub(crate) mod packet;
pub mod pcf;
pub mod pcss;
pub mod point_light;
pub mod registry;
pub mod shadow_mapping;
pub(crate) mod shadow_rays;
pub(crate) mod shaft;
pub mod smoothies;
pub mod ssm;
pub mod target;

pub use config::{BitmaskConfig, ExactConfig, MethodConfig, SsmConfig};
pub use gather::Hierarchy;
pub use inputs::{Input, LightPoint, ShadowInputs, ShadowMethod};
pub use registry::{
    shade_map, shade_points, Method, HIERARCHY, HIERARCHY_DEFAULT_BITMASK, HIERARCHY_DEFAULT_SSM,
};

#[cfg(test)]
pub(crate) mod plate_case {
    use super::{ShadowInputs, ShadowMethod};
    use crate::geom::light::MapGrid;
    use crate::geom::light_shape::LightShape;

    /// Largest |V - V_exact| of `method` on an n x n map of a plate covering
    /// tangent [-1/4, 1/4]^2 at depth 2 over a floor at depth 4 (light 1 x 1).
    /// The plate's edges fall on texel edges, so the occluder map holds it
    /// exactly and any error is the method's.
    pub fn max_error(method: &dyn ShadowMethod, n: usize) -> f64 {
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let (zo, zr, a) = (2.0f64, 4.0f64, 0.25f64);
        let front: Vec<f32> = (0..n * n)
            .map(|k| {
                let (x, y) = (grid.x_of(k % n), grid.y_of(k / n));
                if x.abs() < a && y.abs() < a {
                    zo as f32
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let receiver = vec![zr as f32; n * n];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect([1.0, 1.0]),
            receiver: &receiver,
            occluder_layers: vec![&front],
            occluder_triangles: None,
        };
        let v = method.visibility_map(&inputs);
        // The back-projection of the plate seen from the floor point at
        // tangent c is k [-a - c, a - c], k = zr zo / (zr - zo), on the light
        // [-1/2, 1/2] (per axis).
        let k = zr * zo / (zr - zo);
        let ov = |c: f64| {
            ((k * (a - c) + 0.5).clamp(0.0, 1.0) - (k * (-a - c) + 0.5).clamp(0.0, 1.0)).max(0.0)
        };
        let mut max = 0f64;
        for j in 0..n {
            for i in 0..n {
                let exact = 1.0 - ov(grid.x_of(i)) * ov(grid.y_of(j));
                max = max.max((v[j * n + i] as f64 - exact).abs());
            }
        }
        max
    }
}
