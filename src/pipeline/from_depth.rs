//! Depth maps the user rendered -> visibility on the CPU, and the checks
//! and unit change both backends apply to such maps.

use crate::error::Result;
use crate::geom::light::MapGrid;
use crate::geom::units::{depth_unit, farthest};
use crate::memory::{check_fits, map_bytes};
use crate::methods::{Method, ShadowInputs};

use crate::frame::{check_depth_inputs, DepthInUnit};
use crate::methods::shade_map;
use crate::timing::{Stopwatch, Timings};

/// Soft shadow map from depth maps the user rendered.
pub fn from_depth(
    grid: &MapGrid,
    occluder_grid: &MapGrid,
    light_size: [f64; 2],
    front: &[f32],
    back: Option<&[f32]>,
    receiver: &[f32],
    method: Method,
) -> Result<(Vec<f32>, Timings)> {
    let light_size = check_depth_inputs(
        grid,
        occluder_grid,
        light_size,
        front,
        back,
        receiver,
        method,
    )?;
    let mut sw = Stopwatch::new();
    // The kernels' depth unit (see units.rs): copies only far from 1.
    let unit = depth_unit(farthest(receiver));
    // Visibility, the kernels' 1/depth layers, and the copies in that unit.
    let copies = if unit == 1.0 { 0 } else { 1 };
    let layers = 1 + back.is_some() as usize;
    check_fits(
        "receiver_depth",
        &format!("{}x{} maps", grid.width, grid.height),
        map_bytes(grid.len(), 1 + copies) + map_bytes(occluder_grid.len(), layers * (1 + copies)),
    )?;
    let d = DepthInUnit::new(unit, light_size, front, back, receiver)?;
    let mut layers: Vec<&[f32]> = vec![&d.front];
    if let Some(b) = &d.back {
        layers.push(b);
    }
    let inputs = ShadowInputs {
        grid: *grid,
        occluder_grid: *occluder_grid,
        light_size: d.light_size,
        receiver: &d.receiver,
        occluder_layers: layers,
        occluder_triangles: None,
    };
    let v = shade_map(method, &inputs);
    sw.lap("shadow");
    Ok((v, sw.timings))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;

    /// A texel-aligned plate at depth 2 over receivers at depth 4, times `s`.
    fn plate_maps(n: usize, s: f32) -> (Vec<f32>, Vec<f32>) {
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let front = (0..n * n)
            .map(|k| {
                let (x, y) = (grid.x_of(k % n), grid.y_of(k / n));
                if x.abs() < 0.25 && y.abs() < 0.2 {
                    2.0 * s
                } else {
                    f32::INFINITY
                }
            })
            .collect();
        (front, vec![4.0 * s; n * n])
    }

    #[test]
    fn depth_maps_at_any_power_of_two_scale_give_the_same_visibility() {
        // The kernels get depths in a unit near the receivers' (units.rs):
        // without it the SSM loses these shadows at 2^60 and 2^-70.
        let n = 24;
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let ssm = Method::Ssm {
            hierarchy: false,
            precision: Default::default(),
        };
        let bitmask = Method::Bitmask {
            samples: 64,
            hierarchy: true,
            gaps: Default::default(),
        };
        for method in [ssm, bitmask] {
            let (f, r) = plate_maps(n, 1.0);
            let (base, _) = from_depth(&grid, &grid, [1.0, 0.6], &f, None, &r, method).unwrap();
            assert!(base.iter().any(|&v| v < 1e-6));
            for k in [-90, -70, 50, 60, 90] {
                let s = 2f32.powi(k);
                let (f, r) = plate_maps(n, s);
                let size = [s as f64, 0.6 * s as f64];
                let (v, _) = from_depth(&grid, &grid, size, &f, None, &r, method).unwrap();
                assert_eq!(v, base, "{method:?} at 2^{k}");
            }
        }
    }

    #[test]
    fn light_sizes_beyond_f32_relative_to_depth_are_refused() {
        let n = 8;
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let (f, r) = plate_maps(n, 1.0);
        let err = from_depth(
            &grid,
            &grid,
            [1e-35, 1.0],
            &f,
            None,
            &r,
            Method::Ssm {
                hierarchy: false,
                precision: Default::default(),
            },
        )
        .unwrap_err();
        assert!(matches!(err, Error::InvalidArgument { ref arg, .. } if arg == "light_size"));
    }
}
