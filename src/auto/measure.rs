//! What the planner measures of a scene's occluders before the planned run
//! (`plan.rs`): how many distinct surfaces the occluder texels see
//! along the light's central ray (front and back layers, then depth
//! peeling), what each peeled layer changes in the shadow, and how much of
//! the front layer lies in features at most `THIN_TEXELS` wide.
//!
//! The layers are tried on coarse maps (receivers at an eighth of the
//! output's side, occluders at a quarter of the planned maps', 256 samples,
//! no hierarchy),
//! rasterized once (one `Prepared` serves every peel) and shaded on the CPU
//! whatever the backend: on the bunnies the change measured so is within
//! 0.0003 of the full maps' (0.0005-0.0009). The thin features need the
//! planned maps' own texels: only the front layer, at their resolution.

use super::plan::{layer_change, SceneStats, LAYER_CHANGE, THIN_TEXELS};
use crate::geom::light::MapGrid;
use crate::methods::{Method, ShadowInputs};
use crate::raster::{rasterize, Prepared, PEEL_GAP};

use crate::frame::FramedScene;
use crate::methods::shade_map;
use glam::DVec3;

/// The planned maps' front layer on `grid`: its covered and thin texels.
pub(crate) fn thin_features(f: &FramedScene, faces: &[[u32; 3]], grid: &MapGrid) -> (usize, usize) {
    let front = rasterize(grid, &f.occ_ls, faces, f.near, false).nearest;
    (
        front.iter().filter(|z| z.is_finite()).count(),
        thin_texels(&front, grid.width, grid.height),
    )
}

/// What the coarse layer tries found.
pub(crate) struct LayerTries {
    /// Coarse occluder texels that see a surface, and a back behind the
    /// front.
    pub surfaces: [usize; 2],
    /// Per peeled layer tried, the texels where it holds a surface before
    /// the back, and what adding it changed (the last may be 0 texels,
    /// untried).
    pub peeled: Vec<usize>,
    pub changes: Vec<f64>,
    /// The layers to keep: 1, 2, or 2 + the peeled layers that changed the
    /// shadow by LAYER_CHANGE or more.
    pub passes: u32,
    /// What closing the gaps changed in the shadow of the layers kept
    /// (`layer_change` of the open and the closed kernels' maps).
    pub gap_change: f64,
}

/// Tries the occluder layers of `f` on the coarse grids (`receivers` for
/// the receivers, `occluders` for the occluders) with `methods` (a union
/// kernel with gaps closed, and the same with gaps open), peeling at most
/// `max_layers`, then what opening the gaps changes with the layers kept.
pub(crate) fn layer_tries(
    f: &FramedScene,
    faces: (&[[u32; 3]], &[[u32; 3]]),
    grids: (MapGrid, MapGrid),
    methods: (Method, Method),
    max_layers: u32,
) -> LayerTries {
    let (method, open) = methods;
    let (occ_faces, rec_faces) = faces;
    let (grid, occluder_grid) = grids;
    let prepared = Prepared::new(&occluder_grid, &f.occ_ls, occ_faces, f.near);
    let layers = prepared.nearest_farthest(true);
    let front = layers.nearest;
    let back = layers.farthest.unwrap_or_else(|| front.clone());
    let surfaces = [
        front.iter().filter(|z| z.is_finite()).count(),
        front
            .iter()
            .zip(&back)
            .filter(|(&f, &b)| b.is_finite() && b > f * (1.0 + PEEL_GAP))
            .count(),
    ];
    let mut tries = LayerTries {
        surfaces,
        peeled: vec![],
        changes: vec![],
        passes: if surfaces[1] == 0 { 1 } else { 2 },
        gap_change: 0.0,
    };
    let receiver = rasterize(&grid, &f.rec_ls, rec_faces, f.near, false).nearest;
    let shade_with = |method: Method, middle: &[Vec<f32>], back: Option<&[f32]>| {
        let mut layers: Vec<&[f32]> = vec![&front];
        layers.extend(middle.iter().map(|m| m.as_slice()));
        layers.extend(back);
        shade_map(
            method,
            &ShadowInputs {
                grid,
                occluder_grid,
                light_shape: f.light_shape,
                receiver: &receiver,
                occluder_layers: layers,
                occluder_triangles: None,
            },
        )
    };
    if tries.passes == 1 {
        let closed = shade_with(method, &[], None);
        tries.gap_change = layer_change(&closed, &shade_with(open, &[], None));
        return tries;
    }
    let shade = |middle: &[Vec<f32>]| shade_with(method, middle, Some(&back));
    let mut middle: Vec<Vec<f32>> = vec![];
    let mut before = shade(&middle);
    while tries.passes < max_layers {
        let next = prepared.peel(middle.last().unwrap_or(&front));
        let n = next
            .iter()
            .zip(&back)
            .filter(|(&z, &b)| z.is_finite() && z < b * (1.0 - PEEL_GAP))
            .count();
        tries.peeled.push(n);
        if n == 0 {
            break;
        }
        middle.push(next);
        let after = shade(&middle);
        let change = layer_change(&before, &after);
        tries.changes.push(change);
        if change < LAYER_CHANGE {
            break;
        }
        tries.passes += 1;
        before = after;
    }
    // `before` holds the closed kernel's shadow of the layers kept.
    let kept = &middle[..(tries.passes - 2) as usize];
    tries.gap_change = layer_change(&before, &shade_with(open, kept, Some(&back)));
    tries
}

/// Covered texels of `front` (finite depth) in a run of at most
/// THIN_TEXELS along its row or its column with an empty texel at both
/// ends (a run cut by the map's border is not known to be thin).
pub(crate) fn thin_texels(front: &[f32], w: usize, h: usize) -> usize {
    let mut thin = vec![false; front.len()];
    let mut mark = |len: usize, at: &dyn Fn(usize) -> usize| {
        let mut i = 0;
        while i < len {
            if !front[at(i)].is_finite() {
                i += 1;
                continue;
            }
            let start = i;
            while i < len && front[at(i)].is_finite() {
                i += 1;
            }
            if start > 0 && i < len && i - start <= THIN_TEXELS {
                for k in start..i {
                    thin[at(k)] = true;
                }
            }
        }
    };
    for y in 0..h {
        mark(w, &|x| y * w + x);
    }
    for x in 0..w {
        mark(h, &|y| y * w + x);
    }
    thin.iter().filter(|&&t| t).count()
}

/// What a plan reads of a framed scene (`plan.rs`): its
/// light-space depth ranges and bounds, the map's extent and the light's
/// size, for an output of `resolution`. One pass over the vertices; the
/// ratios the planner forms do not depend on the depth unit.
pub(crate) fn scene_stats(f: &FramedScene, resolution: (usize, usize)) -> SceneStats {
    let z_range = |v: &[DVec3]| {
        v.iter().fold((f64::INFINITY, 0f64), |(lo, hi), q| {
            (lo.min(q.z), hi.max(q.z))
        })
    };
    let (oz0, oz1) = z_range(&f.occ_ls);
    let (rz0, rz1) = z_range(&f.rec_ls);
    let bounds = f.occ_ls.iter().fold(
        [
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ],
        |b, q| {
            let (x, y) = (q.x / q.z, q.y / q.z);
            [b[0].min(x), b[1].max(x), b[2].min(y), b[3].max(y)]
        },
    );
    let w = |z: f64| if z > 0.0 { 1.0 / z } else { f64::INFINITY };
    SceneStats {
        resolution,
        extent: [f.grid.tx, f.grid.ty],
        light_shape: f.light_shape,
        occ_w_near: w(oz0),
        occ_w_far: w(oz1),
        rec_w_near: w(rz0.max(0.0)),
        rec_w_far: w(rz1),
        occ_bounds: bounds,
        // One depth to 1e-9 of it: a plane parallel to the light.
        occ_flat: oz1 - oz0 <= 1e-9 * oz1,
        occ_planar: on_one_plane(&f.occ_ls),
    }
}

/// Whether every point lies on one plane, to 1e-9 of the points' span:
/// the plane through the first point, the farthest from it, and the one
/// farthest from the line through both.
fn on_one_plane(v: &[DVec3]) -> bool {
    let Some(&a) = v.first() else {
        return true;
    };
    let farthest = |key: &dyn Fn(DVec3) -> f64| {
        v.iter()
            .copied()
            .max_by(|p, q| key(*p).total_cmp(&key(*q)))
            .unwrap_or(a)
    };
    let b = farthest(&|p| (p - a).length_squared());
    let span = (b - a).length();
    if span == 0.0 {
        return true;
    }
    let axis = (b - a) / span;
    let c = farthest(&|p| (p - a).cross(axis).length_squared());
    let n = (b - a).cross(c - a);
    if n.length() <= 1e-12 * span * span {
        // Collinear: a line lies on a plane.
        return true;
    }
    let n = n.normalize();
    v.iter().all(|p| n.dot(*p - a).abs() <= 1e-9 * span)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thin_runs_between_empty_texels_count_and_border_runs_do_not() {
        let (t, inf) = (THIN_TEXELS, f32::INFINITY);
        let w = t + 4;
        let mut m = vec![inf; 3 * w];
        // Row 0: a bar THIN_TEXELS wide between empty texels (thin); row
        // 1: one texel wider (not thin along the row); row 2: a run
        // touching the left border.
        m[1..1 + t].fill(1.0);
        m[w + 1..w + 2 + t].fill(1.0);
        m[2 * w] = 1.0;
        // Columns 1..=t run over rows 0-1 from the top border (not known
        // thin); column t + 1 holds row 1's last texel alone between empty
        // texels (thin); column 0's texel touches the bottom border.
        assert_eq!(thin_texels(&m, w, 3), t + 1);
    }
}

#[cfg(test)]
mod plane_tests {
    use super::on_one_plane;
    use glam::DVec3;

    #[test]
    fn points_on_a_tilted_plane_are_planar_and_a_box_is_not() {
        let n = DVec3::new(0.3, 1.0, -0.2).normalize();
        let (u, v) = n.any_orthonormal_pair();
        let plane: Vec<DVec3> = (0..20)
            .map(|i| {
                DVec3::new(1.0, 2.0, 3.0) + u * (i as f64).sin() * 5.0 + v * (i as f64 * 0.7).cos()
            })
            .collect();
        assert!(on_one_plane(&plane));
        let mut off = plane.clone();
        off[7] += n * 1e-3;
        assert!(!on_one_plane(&off));
        let cube: Vec<DVec3> = (0..8)
            .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64))
            .collect();
        assert!(!on_one_plane(&cube));
        // Fewer than three distinct points, or a line: planar.
        assert!(on_one_plane(&[DVec3::ONE, DVec3::ONE]));
        assert!(on_one_plane(&[DVec3::ZERO, DVec3::X, DVec3::X * 2.0]));
    }
}
