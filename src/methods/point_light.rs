//! The point-light limit of the map methods: hard shadows from the occluder
//! maps.
//!
//! As the light shrinks, a micro-patch's back-projection either covers the
//! whole light (the receiver's direction falls inside the patch) or misses
//! it, so the SSM and the bitmask converge to the hard shadow map: a receiver
//! is in shadow when the occluder texel in its direction, in any layer, is
//! nearer the light than it. Their kernels divide by the light's size, so a
//! light of size exactly (0, 0) takes this path instead. (`exact` needs no
//! special case: all its rays go to the light's center.)

use crate::geom::light::MapGrid;
use crate::methods::{LightPoint, ShadowInputs};
use rayon::prelude::*;

/// 0 where an occluder layer is nearer than the receiver at tangent (x, y),
/// depth z; 1 elsewhere (and where there is no receiver).
fn hard(og: &MapGrid, layers: &[&[f32]], x: f32, y: f32, z: f32) -> f32 {
    if !(z.is_finite() && z > 0.0) {
        return 1.0;
    }
    let (px, py) = og.to_pixel(x as f64, y as f64);
    let i = (px.floor().max(0.0) as usize).min(og.width - 1);
    let j = (py.floor().max(0.0) as usize).min(og.height - 1);
    let k = j * og.width + i;
    if layers.iter().any(|l| l[k] < z) {
        0.0
    } else {
        1.0
    }
}

/// The hard shadow of every receiver texel of the output grid.
pub fn visibility_map(inputs: &ShadowInputs) -> Vec<f32> {
    let (g, og) = (&inputs.grid, &inputs.occluder_grid);
    (0..g.len())
        .into_par_iter()
        .map(|k| {
            let (x, y) = (g.x_of(k % g.width) as f32, g.y_of(k / g.width) as f32);
            hard(og, &inputs.occluder_layers, x, y, inputs.receiver[k])
        })
        .collect()
}

/// The hard shadow at receiver points (light space).
pub fn visibility_points(inputs: &ShadowInputs, points: &[LightPoint]) -> Vec<f32> {
    points
        .par_iter()
        .map(|p| {
            hard(
                &inputs.occluder_grid,
                &inputs.occluder_layers,
                p.x,
                p.y,
                p.z,
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light_shape::LightShape;
    use crate::methods::ssm::Ssm;
    use crate::methods::ShadowMethod;

    #[test]
    fn the_ssm_converges_to_the_hard_shadow() {
        // Random occluder and receiver depths; a light 1e-6 wide.
        let grid = MapGrid::new(23, 17, [0.4, 0.3]).unwrap();
        let mut seed = 3u64;
        let mut r = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f32 / (1u64 << 53) as f32
        };
        let front: Vec<f32> = (0..grid.len())
            .map(|_| {
                if r() < 0.5 {
                    1.0 + 3.0 * r()
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        let receiver: Vec<f32> = (0..grid.len()).map(|_| 2.0 + 2.0 * r()).collect();
        let mut inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect([1e-6, 1e-6]),
            receiver: &receiver,
            occluder_layers: vec![&front],
            occluder_triangles: None,
        };
        let soft = Ssm::default().visibility_map(&inputs);
        inputs.light_shape = LightShape::rect([0.0, 0.0]);
        let hard = visibility_map(&inputs);
        for (k, (s, h)) in soft.iter().zip(&hard).enumerate() {
            // Pairs within 1e-5 in depth are too close for a 1e-6 light to
            // have hardened: skip them.
            if (front[k] - receiver[k]).abs() > 1e-3 {
                assert!((s - h).abs() < 1e-5, "texel {k}: {s} vs {h}");
            }
        }
        assert!(hard.contains(&0.0) && hard.contains(&1.0));
    }
}
