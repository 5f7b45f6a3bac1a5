//! The gather traversal shared by the occluder-map methods (`ssm`, `bitmask`).
//!
//! Groups of LANES receivers (an 8x8 tile of the output map, or 64
//! neighbouring sample points) visit the occluder texels inside the union of
//! their possible extents: a micro-patch at 1/depth w reaches receivers within
//! (L/2)(w - wR) in tangent units (§3.3 of Atty et al. 2005), so occluder rows
//! and BLOCK-wide runs of them, which carry their nearest depth, bound what
//! can reach. What a pair contributes is the method's (an `Accumulator`).
//! The lanes are receivers, so the inner loop over occluder texels is long and
//! branch-free; bands of output rows are split across threads without locks.
//! The same source is compiled for AVX-512, AVX2+FMA and the baseline and
//! picked at run time.
//!
//! Here: the interface the methods implement and call (`Accumulator`,
//! `RowLanes`, the lane and tile sizes, `visibility_map`,
//! `visibility_points`) and the `Kernel` they share. `group.rs`: groups of
//! receivers and the per-group loops; `hierarchy.rs`: the occluder pyramid
//! (built in `Kernel::new`) and the level choice; `traverse.rs`: the
//! traversal over occluder texels for one group; `simd.rs`: the runtime
//! dispatch; `work.rs`: what a call's visits cost and may cost; `meter.rs`:
//! the count of them as they are made.

pub mod corners;
mod group;
mod hierarchy;
mod kernel;
pub mod meter;
mod simd;
mod traverse;
pub mod work;

pub use hierarchy::{maps_with_levels, Hierarchy, HIERARCHY};
use kernel::Kernel;
pub(in crate::methods) use kernel::{
    max, min, Accumulator, Group, Lanes, RowLanes, LANES, ROWS_PER_GROUP, TILE_W,
};

use super::{EyePoints, LightPoint, ShadowInputs};
use crate::geom::light::MapGrid;
use crate::trace::ray_start::RayStart;
use rayon::prelude::*;

/// The eye view's points shaded by a gather method (`ShadowMethod::
/// visibility_eye` of `ssm` and `bitmask`): weighted by `weighted` where
/// `eye` asks for it, plain by `plain` otherwise; under a point light, its
/// hard shadow (`point_light.rs`), unweighted.
pub(in crate::methods) fn visibility_eye(
    inputs: &ShadowInputs,
    eye: &EyePoints,
    plain: impl FnOnce(&[LightPoint]) -> Vec<f32>,
    weighted: impl FnOnce(&[LightPoint], &[Option<RayStart>]) -> (Vec<f32>, Vec<f32>),
) -> (Vec<f32>, Option<Vec<f32>>) {
    if inputs.light_shape.is_point() {
        return (
            crate::methods::point_light::visibility_points(inputs, eye.points),
            None,
        );
    }
    match eye.starts {
        Some(r) => {
            let (v, w) = weighted(eye.points, r);
            (v, Some(w))
        }
        None => (plain(eye.points), None),
    }
}

/// Shades every receiver texel of the output map with accumulator `a`.
pub(super) fn visibility_map<A: Accumulator>(
    a: &A,
    inputs: &ShadowInputs,
    hierarchy: Option<Hierarchy>,
) -> Vec<f32> {
    let mut k = Kernel::new(inputs, hierarchy, A::CORNERS);
    if A::CORNERS {
        k.set_plane(inputs.receiver);
    }
    let w = k.rec_width;
    let mut out = vec![1f32; inputs.grid.len()];
    out.par_chunks_mut(w * ROWS_PER_GROUP)
        .zip(inputs.receiver.par_chunks(w * ROWS_PER_GROUP))
        .enumerate()
        .for_each(|(t, (o, r))| k.shade_row(a, t * ROWS_PER_GROUP, r, o));
    out
}

/// The order `visibility_points` shades `points` in: sorted by the texel of
/// the occluder grid `og` each falls in, tile-major, so that each run of
/// LANES points (a group) forms a compact tile and its union of extents
/// stays small. The GPU twin (`gpu/eye.rs`) groups points by it too.
pub(crate) fn point_order(og: &MapGrid, points: &[LightPoint]) -> Vec<u32> {
    // Kernel::row_coord and col_coord at level 0 (scale 1).
    let (tx, ty) = (og.tx as f32, og.ty as f32);
    let (width, height) = (og.width as f32, og.height as f32);
    let key = |p: &LightPoint| {
        let j = ((1.0 - p.y / ty) * 0.5 * height - 0.5)
            .round()
            .clamp(0.0, height - 1.0) as u64;
        let i = ((p.x / tx + 1.0) * 0.5 * width - 0.5)
            .round()
            .clamp(0.0, width - 1.0) as u64;
        // Tile-major order, so that runs of LANES points form compact tiles.
        let (t, r) = (TILE_W as u64, ROWS_PER_GROUP as u64);
        let tiles_x = (og.width as u64).div_ceil(t);
        (((j / r) * tiles_x + i / t) * r + j % r) * t + i % t
    };
    // Each key computed once (evaluating it in every comparison cost more
    // than the shading), then the order of a stable sort by key: ties keep
    // the input order.
    let keys: Vec<u64> = points.par_iter().map(key).collect();
    let top = keys.iter().copied().max().unwrap_or(0);
    if top < 4 * points.len() as u64 + 1024 {
        // Keys are texel indices: a counting sort when they are few.
        let mut start = vec![0u32; top as usize + 2];
        for &k in &keys {
            start[k as usize + 1] += 1;
        }
        for b in 1..start.len() {
            start[b] += start[b - 1];
        }
        let mut order = vec![0u32; points.len()];
        for (n, &k) in keys.iter().enumerate() {
            order[start[k as usize] as usize] = n as u32;
            start[k as usize] += 1;
        }
        return order;
    }
    let mut keyed: Vec<(u64, u32)> = keys.into_iter().zip(0u32..).collect();
    keyed.par_sort_unstable();
    keyed.into_iter().map(|(_, n)| n).collect()
}

/// Points a group of `visibility_points` holds (the GPU twin's workgroup).
#[cfg(feature = "gpu")]
pub(crate) const POINTS_PER_GROUP: usize = LANES;

/// A group of up to LANES points as `visibility_points` shades it, for the
/// GPU twin: per lane x, y and 1/depth (+inf: no receiver), and the bounds
/// over the lanes with a receiver.
#[cfg(feature = "gpu")]
pub(crate) struct PointGroup {
    pub xr: Lanes,
    pub yr: Lanes,
    pub wr: Lanes,
    pub x_lo: f32,
    pub x_hi: f32,
    pub y_lo: f32,
    pub y_hi: f32,
    pub wr_min: f32,
}

/// The group of `pts` (at most LANES, in `point_order`), or None when no
/// point has a receiver in front of the light.
#[cfg(feature = "gpu")]
pub(crate) fn point_group(pts: &[LightPoint]) -> Option<PointGroup> {
    Group::new(pts.iter().map(|p| (p.x, p.y, p.z)), false).map(|g| PointGroup {
        xr: g.xr,
        yr: g.yr,
        wr: g.wr,
        x_lo: g.x_lo,
        x_hi: g.x_hi,
        y_lo: g.y_lo,
        y_hi: g.y_hi,
        wr_min: g.wr_min,
    })
}

/// Shades receiver points (light space) with accumulator `a`.
pub(super) fn visibility_points<A: Accumulator>(
    a: &A,
    inputs: &ShadowInputs,
    points: &[LightPoint],
    hierarchy: Option<Hierarchy>,
) -> Vec<f32> {
    // Shade neighbours together: sort the points by the texel they fall in,
    // so that each group's union of extents stays small.
    let order = point_order(&inputs.occluder_grid, points);
    visibility_points_in(a, inputs, points, &order, hierarchy)
}

/// `visibility_points` in a given shading `order` (`point_order`'s): lane l
/// of a group is point `order[g.first + l]` (`Group::first`).
pub(super) fn visibility_points_in<A: Accumulator>(
    a: &A,
    inputs: &ShadowInputs,
    points: &[LightPoint],
    order: &[u32],
    hierarchy: Option<Hierarchy>,
) -> Vec<f32> {
    let k = Kernel::new(inputs, hierarchy, A::CORNERS);
    let sorted: Vec<LightPoint> = order.iter().map(|&n| points[n as usize]).collect();
    let mut shaded = vec![1f32; points.len()];
    const CHUNK: usize = LANES * 4;
    shaded
        .par_chunks_mut(CHUNK)
        .zip(sorted.par_chunks(CHUNK))
        .enumerate()
        .for_each(|(c, (o, p))| k.shade_points(a, p, c * CHUNK, o));
    let mut out = vec![1f32; points.len()];
    for (&n, &v) in order.iter().zip(&shaded) {
        out[n as usize] = v;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `point_order` is the stable sort by texel key, on both of its paths
    /// (the counting sort of few keys, the sort of many).
    #[test]
    fn point_order_is_the_stable_sort_by_texel() {
        let mut seed = 7u64;
        let mut r = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 40) as f32 / (1u64 << 24) as f32
        };
        let points: Vec<LightPoint> = (0..3000)
            .map(|_| LightPoint {
                // Some beyond the map (clamped), many sharing a texel.
                x: (r() * 2.4 - 1.2) * 0.5,
                y: (r() * 2.4 - 1.2) * 0.5,
                z: 1.0,
            })
            .collect();
        for side in [16usize, 4096] {
            let og = MapGrid::new(side, side, [0.5, 0.5]).unwrap();
            let (w, h) = (side as f32, side as f32);
            let key = |p: &LightPoint| {
                let j = ((1.0 - p.y / 0.5) * 0.5 * h - 0.5)
                    .round()
                    .clamp(0.0, h - 1.0) as u64;
                let i = ((p.x / 0.5 + 1.0) * 0.5 * w - 0.5)
                    .round()
                    .clamp(0.0, w - 1.0) as u64;
                let (t, rr) = (TILE_W as u64, ROWS_PER_GROUP as u64);
                let tiles_x = (side as u64).div_ceil(t);
                (((j / rr) * tiles_x + i / t) * rr + j % rr) * t + i % t
            };
            let mut want: Vec<u32> = (0..points.len() as u32).collect();
            want.sort_by_key(|&n| key(&points[n as usize]));
            assert_eq!(point_order(&og, &points), want, "side {side}");
        }
    }
}
