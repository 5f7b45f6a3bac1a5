//! What a gather kernel's call (`ssm`, `bitmask`) costs, bounded before it
//! runs, so that a call whose cost no answer needs is refused or planned
//! around instead of running for minutes.
//!
//! The kernel (`traverse.rs`) visits, for each group of LANES receivers and
//! each occluder layer, the texels whose micro-patch can reach a receiver:
//! rows and columns within hw + (Lx / 2)(w_max - wr) of it in tangent
//! units (w = 1/depth: the back-projection of the light from the receiver
//! onto the nearest occluder depth 1/w_max; `add_layer`, `add_row`), cut to
//! the map. The bound here is that box's texel count per receiver, summed
//! and divided by LANES (a group's receivers are neighbours, and their
//! boxes nearly one), times the layers: an upper bound where the traversal
//! trims runs of empty texels, stops at full occlusion and takes coarser
//! levels far away, close where the light is wide and every receiver's box
//! is the whole map (a 179° sun).

use super::kernel::LANES;
use crate::error::{Error, Result};
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::methods::pcss::nearest_depth;
use crate::methods::{LightPoint, Method, ShadowInputs};
use rayon::prelude::*;

/// The weighted visits (`visit_cost`) a fitted map is planned under
/// (`eye::gather_budget`). Set above every case of the as-built scenes
/// (calibration and held out, 640x480, `ssm` and `bitmask`: up to about
/// 4.7e8, inferred from the coarsening an earlier 4e7 made), which it
/// leaves as they were: at 4e7 it coarsened 7 of those 32 cases 2-4x a
/// side, 4-9x faster but 0.0004-0.0037 worse over shadowed pixels (blinds
/// 0.0293 -> 0.0330), because the bound predicts time poorly: 3.6 ns (a
/// shelf) to 210 ns (a closed box) of `bitmask` per bounded visit. What it
/// still catches grows with the square of the pixels: a camera inside a
/// closed box at 1080p.
pub const PLANNED_VISITS: f64 = 6e8;

/// The most weighted visits a call may be asked to make by the map size its
/// caller set: past it the call is refused (`check_visits`). A 179° sun's
/// bitmask light view at 512² bounds 1.9e9 (118 s); at 256², 1.2e8 (11 s),
/// which runs.
pub const MAX_VISITS: f64 = 1.5e9;

/// What one visit of `method`'s kernel costs, in visits of `bitmask` with
/// 256 samples: its masks' words (the 1 024-sample bitmask of 6 layers on
/// 355x715 maps took 44 s where the bound was counted unweighted); `ssm`
/// sums a number per lane, about a twentieth of the 256-sample mask's time
/// on the closed box (counted as an eighth).
pub fn visit_cost(method: Method) -> f64 {
    match method {
        Method::Bitmask { samples, .. } => (samples as f64 / 256.0).max(0.25),
        _ => 0.125,
    }
}

/// The bound on the kernel's visits for receivers `points` (kernel light
/// space: tangents and depth; an empty point has z = inf) on occluder grid
/// `grid`, lit by `light`, with `layers` occluder layers whose nearest
/// occluder depth is at least `z_near` (> 0).
pub fn visits_bound(
    grid: &MapGrid,
    light: LightShape,
    z_near: f64,
    layers: usize,
    points: &[LightPoint],
) -> f64 {
    let (hw, hh) = grid.half_texel();
    let [lx, ly] = light.extent();
    let w_max = 1.0 / z_near;
    let (cols, rows) = (grid.width as f64, grid.height as f64);
    let per_receiver: f64 = points
        .par_iter()
        .map(|p| {
            let z = p.z as f64;
            if !(z.is_finite() && z > 0.0) || 1.0 / z >= w_max {
                return 0.0;
            }
            let dw = w_max - 1.0 / z;
            // Texels across the box [x - reach, x + reach], plus the one
            // each end of it lands in.
            let across = |half_texel: f64, half_light: f64, n: f64| {
                let reach = half_texel + half_light * dw;
                (reach / half_texel + 2.0).min(n)
            };
            across(hw, 0.5 * lx, cols) * across(hh, 0.5 * ly, rows)
        })
        .sum();
    per_receiver / LANES as f64 * layers as f64
}

/// Refuses, naming `occluder_resolution`, a call of a gather kernel whose
/// visits `visits_bound` puts over `MAX_VISITS` (weighted by `visit_cost`
/// of `method`), from its inputs: the
/// nearest occluder texel of its layers, and the receivers `points` (None:
/// the receiver map's texels). The eye view plans its fitted maps under the
/// bound first (`eye::gather_budget`, with a margin): this refuses the maps
/// a light view was asked for.
pub fn check_visits(
    method: Method,
    inputs: &ShadowInputs,
    points: Option<&[LightPoint]>,
) -> Result<()> {
    let z_near = inputs
        .occluder_layers
        .iter()
        .map(|l| nearest_depth(l))
        .fold(f32::INFINITY, f32::min) as f64;
    if !z_near.is_finite() {
        return Ok(());
    }
    let layers = inputs.occluder_layers.len();
    let (g, og) = (&inputs.grid, &inputs.occluder_grid);
    let visits = visit_cost(method)
        * match points {
            Some(p) => visits_bound(og, inputs.light_shape, z_near, layers, p),
            None => {
                let texels: Vec<LightPoint> = (0..g.len())
                    .into_par_iter()
                    .map(|k| LightPoint {
                        x: g.x_of(k % g.width) as f32,
                        y: g.y_of(k / g.width) as f32,
                        z: inputs.receiver.get(k).copied().unwrap_or(f32::INFINITY),
                    })
                    .collect();
                visits_bound(og, inputs.light_shape, z_near, layers, &texels)
            }
        };
    if visits > MAX_VISITS {
        return Err(Error::invalid(
            "occluder_resolution",
            format!(
                "{}x{} occluder maps: the light reaches so far across them that the kernel \
                 would visit about {visits:.1e} texels, more than the {MAX_VISITS:.1e} a call \
                 may make; set a coarser occluder_resolution (the output keeps its \
                 resolution: so wide a light casts only wide shadows), or use method=\"exact\"",
                og.width, og.height
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(z: f32) -> LightPoint {
        LightPoint { x: 0.0, y: 0.0, z }
    }

    #[test]
    fn a_wide_light_reaches_the_whole_map_and_a_small_one_a_few_texels() {
        let grid = MapGrid::new(100, 100, [1.0, 1.0]).unwrap();
        let pts = vec![at(2.0); LANES];
        // Occluders at depth 1, receivers at 2: dw = 1/2.
        let wide = visits_bound(&grid, LightShape::rect([1e6, 1e6]), 1.0, 1, &pts);
        assert_eq!(wide, 100.0 * 100.0);
        // A light 0.02 wide: reach = 0.01 + 0.01 * 0.5 (texels 0.02 wide).
        let small = visits_bound(&grid, LightShape::rect([0.02, 0.02]), 1.0, 2, &pts);
        assert!(
            (small - 2.0 * (1.5 + 2.0f64).powi(2)).abs() < 1e-9,
            "{small}"
        );
        // Nothing in front of a receiver, or no receiver: no visit.
        assert_eq!(
            visits_bound(&grid, LightShape::rect([1.0, 1.0]), 3.0, 1, &pts),
            0.0
        );
        let empty = vec![at(f32::INFINITY); LANES];
        assert_eq!(
            visits_bound(&grid, LightShape::rect([1.0, 1.0]), 1.0, 1, &empty),
            0.0
        );
    }
}
