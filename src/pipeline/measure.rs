//! What the planner measures of a scene's occluders before the planned run
//! (`methods/plan.rs`): how many distinct surfaces the occluder texels see
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

use crate::geom::light::MapGrid;
use crate::methods::plan::{layer_change, LAYER_CHANGE, THIN_TEXELS};
use crate::methods::{Method, ShadowInputs};
use crate::raster::{rasterize, Prepared, PEEL_GAP};

use super::frame::FramedScene;
use super::from_meshes::shade_map;

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
                light_size: f.light_size,
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
