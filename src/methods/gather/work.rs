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
use crate::error::Error;
use crate::geom::light::MapGrid;
use crate::geom::light_shape::LightShape;
use crate::methods::inputs::MIN_RECEIVERS;
use crate::methods::{LightPoint, ShadowInputs};
use rayon::prelude::*;

/// The weighted visits (`BITMASK_VISIT`) a fitted map is planned under
/// (`eye::gather_budget`). Set above every case of the as-built scenes
/// (calibration and held out, 640x480, `ssm` and `bitmask`: up to about
/// 4.7e8, inferred from the coarsening an earlier 4e7 made), which it
/// leaves as they were: at 4e7 it coarsened 7 of those 32 cases 2-4x a
/// side, 4-9x faster but 0.0004-0.0037 worse over shadowed pixels (blinds
/// 0.0293 -> 0.0330), because the bound predicts time poorly: 3.6 ns (a
/// shelf) to 210 ns (a closed box) of `bitmask` per bounded visit. What it
/// still catches grows with the square of the pixels: a camera inside a
/// closed box at 1080p. What bounds a call is the count of the visits it
/// makes (`meter::Meter`, `VISITS_PER_RECEIVER`), not this prediction.
pub const PLANNED_VISITS: f64 = 6e8;

/// The weighted visits (`BITMASK_VISIT`) a call may make per receiver it
/// shades, counted as they are made (`meter::Meter`), with at least
/// `inputs::MIN_RECEIVERS` receivers' worth: so the work a call may do grows
/// with its answer, not with a map size or sample count that no answer
/// needs. A weighted visit took 50-250 ns on 2 cores (every method, map
/// and light measured; 230 ns on the as-built blinds), and a stopped call
/// up to 320 ns a weighted visit of the limit, its maps' rasterizing and
/// set-up included (benchmarks/calibrate_visits.py: a closed room with
/// 5600² maps), twice that on one core (`threads=1`, fuzz seed 14 call
/// 393): so the floor, 7.7e7 weighted visits, stops a call within about
/// 25 s on 2 cores and 50 s on one. The as-built scenes' calls (640x480,
/// `ssm` and `bitmask`, calibration and held out) count at most 7.0e7 (the
/// held-out blinds' bitmask, 16 s), which it leaves as they were; the count
/// does not depend on the machine. A call past it is stopped: refused
/// naming the option that set its map size, or where the map was fitted to
/// the pixels, run again on a coarser one (`pipeline::eye_view`).
pub const VISITS_PER_RECEIVER: f64 = 250.0;

/// What one visit of a gather kernel costs (`Kernel::visit_cost`), in
/// visits of `bitmask` with 256 samples, as measured per counted visit
/// (benchmarks/calibrate_visits.py, on 2 cores): about 200 ns for the
/// bitmask's masks of up to 256 samples (16 and 64 samples cost as much:
/// the kernel's masks are 256 bits), 1.5-2.3 us for 1 024 samples' (counted
/// as 12), 7-11 ns for `ssm`'s sums: counted as an eighth, above what it
/// measures, which is the weight the plan's threshold (`PLANNED_VISITS`)
/// was judged with on the as-built scenes.
pub const BITMASK_VISIT: f64 = 1.0;
/// `BITMASK_VISIT` for more than 256 samples.
pub const BITMASK_1024_VISIT: f64 = 12.0;
/// `BITMASK_VISIT` for `ssm`'s sums.
pub const SSM_VISIT: f64 = 0.125;

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

/// The raw visits (`meter::Meter`) a call of a kernel whose visit costs
/// `cost` (`Kernel::visit_cost`) shading `receivers` receivers may make:
/// `VISITS_PER_RECEIVER` each (at least `MIN_RECEIVERS`), weighted by the
/// cost.
pub fn visit_limit(cost: f64, receivers: usize) -> u64 {
    (VISITS_PER_RECEIVER * receivers.max(MIN_RECEIVERS) as f64 / cost) as u64
}

/// The refusal of a call of a kernel of visit cost `cost` that passed
/// `visit_limit`, naming `arg`, the option whose map size drove the visits.
pub fn refusal(cost: f64, inputs: &ShadowInputs, receivers: usize, arg: &str) -> Error {
    let limit = visit_limit(cost, receivers) as f64;
    let og = &inputs.occluder_grid;
    Error::too_costly(
        arg,
        format!(
            "{}x{} occluder maps: the light reaches so far across them that the kernel \
             visited more texels than a call with {receivers} receivers may ({:.1e}: \
             {VISITS_PER_RECEIVER} a receiver, at least {MIN_RECEIVERS} receivers' worth, \
             weighted by the method's cost per texel) and was stopped; set a coarser {arg} \
             (so wide a light casts only wide shadows: a coarser map loses little), fewer \
             samples, or use method=\"exact\"",
            og.width, og.height, limit,
        ),
    )
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
