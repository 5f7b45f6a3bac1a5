//! Depth maps the user rendered -> visibility, on either backend: the
//! checks and unit change of `crate::frame::depth`, then the backend's
//! shading stage (`crate::light_view`).

use crate::backend::Backend;
use crate::error::Result;
use crate::frame::{check_depth_inputs, DepthInUnit};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::geom::units::{depth_unit, farthest};
use crate::light_view::{CpuLightView, LightViewStages};
use crate::methods::Method;
use crate::timing::{Stopwatch, Timings};

/// The user's depth maps: the receiver map's grid (the output's), the
/// occluder maps' grid, the light's size in the depths' unit, the maps.
#[derive(Debug, Clone, Copy)]
pub struct DepthMaps<'a> {
    pub grid: &'a MapGrid,
    pub occluder_grid: &'a MapGrid,
    pub light_shape: LightShape,
    pub front: &'a [f32],
    pub back: Option<&'a [f32]>,
    pub receiver: &'a [f32],
}

/// Soft shadow map from depth maps the user rendered, on `backend`.
pub fn from_depth(
    maps: &DepthMaps,
    method: Method,
    backend: Backend,
) -> Result<(Vec<f32>, Timings)> {
    match backend {
        Backend::Cpu => from_depth_with(&mut CpuLightView, maps, method),
        #[cfg(feature = "gpu")]
        Backend::Gpu => from_depth_with(
            &mut crate::gpu::light_view::GpuLightView::default(),
            maps,
            method,
        ),
        #[cfg(not(feature = "gpu"))]
        Backend::Gpu => Err(crate::backend::not_built()),
    }
}

/// Soft shadow map from depth maps on `stages`' backend.
pub fn from_depth_with<S: LightViewStages>(
    stages: &mut S,
    m: &DepthMaps,
    method: Method,
) -> Result<(Vec<f32>, Timings)> {
    let light_shape = check_depth_inputs(
        m.grid,
        m.occluder_grid,
        m.light_shape,
        m.front,
        m.back,
        m.receiver,
        method,
    )?;
    stages.check_depth(method, m.grid, m.occluder_grid)?;
    let mut sw = Stopwatch::new();
    // The kernels' depth unit (see units.rs): copies only far from 1.
    let unit = depth_unit(farthest(m.receiver));
    let layers = 1 + m.back.is_some() as usize;
    stages.reserve_depth(method, (m.grid, m.occluder_grid), layers, unit)?;
    let d = DepthInUnit::new(unit, light_shape, m.front, m.back, m.receiver)?;
    let v = stages.depth((m.grid, m.occluder_grid), &d, method, &mut sw)?;
    Ok((v, stages.timings(sw.timings)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Error;
    use crate::methods::{BitmaskKernel, SsmKernel};

    /// `from_depth` on the CPU, the maps given one by one.
    fn cpu(
        grid: &MapGrid,
        og: &MapGrid,
        light_shape: LightShape,
        front: &[f32],
        back: Option<&[f32]>,
        receiver: &[f32],
        method: Method,
    ) -> Result<(Vec<f32>, Timings)> {
        let maps = DepthMaps {
            grid,
            occluder_grid: og,
            light_shape,
            front,
            back,
            receiver,
        };
        from_depth(&maps, method, Backend::Cpu)
    }

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
        let ssm = Method::Ssm(SsmKernel {
            hierarchy: false,
            precision: Default::default(),
        });
        let bitmask = Method::Bitmask(BitmaskKernel {
            samples: 64,
            hierarchy: true,
            gaps: Default::default(),
        });
        for method in [ssm, bitmask] {
            let (f, r) = plate_maps(n, 1.0);
            let (base, _) = cpu(
                &grid,
                &grid,
                LightShape::rect([1.0, 0.6]),
                &f,
                None,
                &r,
                method,
            )
            .unwrap();
            assert!(base.iter().any(|&v| v < 1e-6));
            for k in [-90, -70, 50, 60, 90] {
                let s = 2f32.powi(k);
                let (f, r) = plate_maps(n, s);
                let size = [s as f64, 0.6 * s as f64];
                let (v, _) =
                    cpu(&grid, &grid, LightShape::rect(size), &f, None, &r, method).unwrap();
                assert_eq!(v, base, "{method:?} at 2^{k}");
            }
        }
    }

    #[test]
    fn light_sizes_beyond_f32_relative_to_depth_are_refused() {
        let n = 8;
        let grid = MapGrid::new(n, n, [0.5, 0.5]).unwrap();
        let (f, r) = plate_maps(n, 1.0);
        let err = cpu(
            &grid,
            &grid,
            LightShape::rect([1e-35, 1.0]),
            &f,
            None,
            &r,
            Method::Ssm(SsmKernel {
                hierarchy: false,
                precision: Default::default(),
            }),
        )
        .unwrap_err();
        assert!(matches!(err, Error::InvalidArgument { ref arg, .. } if arg == "light_size"));
    }
}
