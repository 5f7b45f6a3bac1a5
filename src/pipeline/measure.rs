//! What the planner measures of a scene's occluder raster before shading
//! (`methods/plan.rs`, `OccluderRaster`): how many distinct surfaces each
//! texel sees along the light's central ray (front and back layers, then
//! depth peeling until a peeled layer holds nothing but the back), and how
//! much of the front layer lies in features at most `THIN_TEXELS` wide.
//!
//! The counts are per texel of the occluder maps the plan will read; the
//! rasterization is the pipeline's own (`raster::Prepared`), so a layer
//! counted here is a layer the kernels would receive.

use crate::geom::light::MapGrid;
use crate::methods::plan::{OccluderRaster, THIN_TEXELS};
use crate::raster::{Prepared, PEEL_GAP};

use super::frame::FramedScene;

/// The occluder raster of `f` on `grid`: the front and back layers, the
/// texels where they differ and the front's thin features; `Peeler` goes on
/// with the layers between them, one at a time.
pub(crate) fn occluder_raster<'g>(
    f: &FramedScene,
    faces: &[[u32; 3]],
    grid: &'g MapGrid,
) -> (OccluderRaster, Peeler<'g>) {
    let prepared = Prepared::new(grid, &f.occ_ls, faces, f.near);
    let layers = prepared.nearest_farthest(true);
    let front = layers.nearest;
    let back = layers.farthest.unwrap_or_else(|| front.clone());
    let raster = OccluderRaster {
        surfaces: [
            front.iter().filter(|z| z.is_finite()).count(),
            front
                .iter()
                .zip(&back)
                .filter(|(&f, &b)| b.is_finite() && b > f * (1.0 + PEEL_GAP))
                .count(),
        ],
        thin: thin_texels(&front, grid.width, grid.height),
    };
    let peeler = Peeler {
        prepared,
        back,
        previous: front,
    };
    (raster, peeler)
}

/// Depth peeling between the front and the back layer.
pub(crate) struct Peeler<'g> {
    prepared: Prepared<'g>,
    back: Vec<f32>,
    previous: Vec<f32>,
}

impl Peeler<'_> {
    /// The next layer: the texels where it holds a surface before the back
    /// (0: the back is the last surface everywhere).
    pub(crate) fn next_surfaces(&mut self) -> usize {
        let next = self.prepared.peel(&self.previous);
        let n = next
            .iter()
            .zip(&self.back)
            .filter(|(&z, &b)| z.is_finite() && z < b * (1.0 - PEEL_GAP))
            .count();
        self.previous = next;
        n
    }
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
