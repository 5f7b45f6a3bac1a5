//! The occluder hierarchy: the occluder maps as 1/depth layers at level 0
//! and, when a hierarchy is used, coarser levels (2x2 texels become one), with
//! the bounds the traversal prunes by (nearest depth per row and per
//! BLOCK-wide block) and the level choice, which reads coarser texels where
//! the penumbra is wide. Built once per call in `Kernel::new`.

use super::kernel::{Group, Kernel, Layer, Level, RowSpan, BLOCK};
use crate::methods::ShadowInputs;
use rayon::prelude::*;

impl Layer {
    /// Level 0: the occluder map as given.
    fn from_depth(depth: &[f32], width: usize) -> Layer {
        let w = super::corners::inverse_depth(depth);
        let w_far = w
            .iter()
            .map(|&x| if x > 0.0 { x } else { f32::INFINITY })
            .collect();
        let w_near = w.clone();
        Layer::new(w, w_far, w_near, width)
    }

    /// The next level: 2x2 texels become one (the last row or column of an
    /// odd size has fewer children). A coarse texel is occupied where most
    /// of its children are, so silhouettes neither grow nor shrink on
    /// average; its depth is the mean 1/depth of those children.
    fn downsample(&self, width: usize, height: usize) -> (Layer, usize, usize) {
        let (cw, ch) = (width.div_ceil(2), height.div_ceil(2));
        let mut w = vec![0f32; cw * ch];
        let mut w_far = vec![f32::INFINITY; cw * ch];
        let mut w_near = vec![0f32; cw * ch];
        for j in 0..ch {
            for i in 0..cw {
                let (mut n, mut occ, mut sum) = (0u32, 0u32, 0f32);
                let (mut far, mut near) = (f32::INFINITY, 0f32);
                for fj in 2 * j..(2 * j + 2).min(height) {
                    for fi in 2 * i..(2 * i + 2).min(width) {
                        let k = fj * width + fi;
                        n += 1;
                        if self.w[k] > 0.0 {
                            occ += 1;
                            sum += self.w[k];
                        }
                        far = far.min(self.w_far[k]);
                        near = near.max(self.w_near[k]);
                    }
                }
                let k = j * cw + i;
                // Ties (2 of 4) alternate in a checkerboard: always counting
                // them occupied grew silhouettes (measured: shadows 0.4%
                // darker on average per level).
                let tie_wins = (i + j) % 2 == 0;
                if occ > 0 && (2 * occ > n || (2 * occ == n && tie_wins)) {
                    w[k] = sum / occ as f32;
                }
                w_far[k] = far;
                w_near[k] = near;
            }
        }
        (Layer::new(w, w_far, w_near, cw), cw, ch)
    }

    fn new(w: Vec<f32>, w_far: Vec<f32>, w_near: Vec<f32>, width: usize) -> Layer {
        let block_w_max = w
            .par_chunks(width)
            .flat_map_iter(|row| {
                row.chunks(BLOCK)
                    .map(|b| b.iter().fold(0f32, |m, &x| m.max(x)))
            })
            .collect();
        let rows: Vec<RowSpan> = w
            .par_chunks(width)
            .map(|row| match row.iter().position(|&x| x > 0.0) {
                None => RowSpan {
                    w_max: 0.0,
                    first: 0,
                    last: 0,
                },
                Some(f) => {
                    let l = row.iter().rposition(|&x| x > 0.0).unwrap() + 1;
                    RowSpan {
                        w_max: row[f..l].iter().fold(0f32, |m, &x| m.max(x)),
                        first: f as u32,
                        last: l as u32,
                    }
                }
            })
            .collect();
        let w_max = rows.iter().fold(0f32, |m, r| m.max(r.w_max));
        let occupied: Vec<usize> = w
            .chunks(width)
            .map(|row| row.iter().filter(|&&x| x > 0.0).count())
            .collect();
        let m: usize = occupied.iter().sum();
        let per_batch = m.div_ceil(((m as f64).sqrt() as usize).max(1)).max(1);
        let mut before = 0;
        let row_batch = occupied
            .iter()
            .map(|&n| {
                let b = (before / per_batch) as u32;
                before += n;
                b
            })
            .collect();
        Layer {
            row_batch,
            corners: vec![],
            plane_invs: vec![],
            w,
            w_far,
            w_near,
            block_w_max,
            rows,
            w_max,
        }
    }
}

impl Layer {
    /// Connects the texels into micro-quads (`corners.rs`; `dx`, `dy`: a
    /// texel's tangent size) and widens the pruning bounds to the corners:
    /// a quad reaches as far as its nearest corner does.
    fn connect(&mut self, width: usize, height: usize, dx: f32, dy: f32) {
        self.corners = super::corners::corners(&self.w, width, height, dx, dy);
        let reach: Vec<f32> = self
            .w
            .par_iter()
            .zip(&self.corners)
            .map(|(&w, c)| c.iter().fold(w, |m, &x| m.max(x)))
            .collect();
        self.block_w_max = reach
            .par_chunks(width)
            .flat_map_iter(|row| {
                row.chunks(BLOCK)
                    .map(|b| b.iter().fold(0f32, |m, &x| m.max(x)))
            })
            .collect();
        for (span, row) in self.rows.iter_mut().zip(reach.chunks(width)) {
            span.w_max = row.iter().fold(0f32, |m, &x| m.max(x));
        }
        self.w_max = self.rows.iter().fold(0f32, |m, r| m.max(r.w_max));
    }
}

/// The level whose texels the level choice reads (8x8 level-0 texels each):
/// coarse enough that the search is cheap next to the shading, fine enough
/// that its distance bounds are tight.
const QUERY_LEVEL: usize = 3;
/// Levels stop when a map is this small.
const COARSEST_SIZE: usize = 4;

/// How the hierarchy picks a level for a tile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hierarchy {
    /// The largest back-projection of one texel onto the light a level may
    /// have, as a fraction of the light's width (and height), for the
    /// nearest occluder that can reach the tile.
    pub max_texel_on_light: f32,
}

/// The level choice of the occluder hierarchy: a texel may back-project onto
/// at most this fraction of the light's width, seen from the receiver it is
/// nearest to. Measured with bitmask (256 samples, two passes) against
/// Mitsuba on the study's scenes (`benchmarks/bench_hierarchy.py`): at 3% the
/// error moves by at most 0.001 while 512² maps take 1.2-4.4x less time; at
/// 6% the error grew by up to 0.003 (a coarse texel misplaces an edge by half
/// its back-projection), at 12.5% by up to 0.02.
pub const HIERARCHY: Hierarchy = Hierarchy {
    max_texel_on_light: 0.03,
};

/// f32 maps a gather kernel keeps per occluder layer, `maps` at the finest
/// level; with a hierarchy its coarser levels add a third.
pub fn maps_with_levels(maps: usize, hierarchy: bool) -> usize {
    if hierarchy {
        maps + maps.div_ceil(3)
    } else {
        maps
    }
}

/// Whether two depth maps hold the same bits.
fn same_bits(a: &[f32], b: &[f32]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

impl Kernel {
    /// `corners`: connect each layer's texels into micro-quads (what an
    /// accumulator with `CORNERS` reads).
    pub(super) fn new(
        inputs: &ShadowInputs,
        hierarchy: Option<Hierarchy>,
        corners: bool,
    ) -> Kernel {
        // Occluder texels live on the occluder grid; receivers on the output grid.
        let g = &inputs.occluder_grid;
        let r = &inputs.grid;
        let (hw, hh) = g.half_texel();
        // The rectangle's clipping: half-light units (geom/light_shape/).
        let light = inputs.light_shape;
        let [lx, ly] = light.extent();
        let half_light = light.half_light();
        // A layer equal to one already kept changes nothing (sums merge by
        // max, masks by OR), so it is not shaded: single-sided or flat
        // occluders make the back map equal the front one, and such a scene
        // then costs one pass whatever `passes` says.
        let distinct: Vec<&[f32]> = inputs
            .occluder_layers
            .iter()
            .enumerate()
            .filter(|&(i, d)| !inputs.occluder_layers[..i].iter().any(|e| same_bits(e, d)))
            .map(|(_, d)| *d)
            .collect();
        let mut layers: Vec<Layer> = distinct
            .iter()
            .map(|d| Layer::from_depth(d, g.width))
            .collect();
        let mut levels = vec![];
        let (mut width, mut height) = (g.width, g.height);
        loop {
            let f = (1usize << levels.len()) as f64;
            let next = hierarchy.is_some() && width.max(height) > COARSEST_SIZE;
            let coarser: Vec<(Layer, usize, usize)> = if next {
                layers.iter().map(|l| l.downsample(width, height)).collect()
            } else {
                vec![]
            };
            // Level 0 keeps the grid's own arithmetic (the same bits as
            // without a hierarchy); coarser levels follow the same formulas.
            let col_x0: Vec<f32> = (0..width)
                .map(|i| {
                    if levels.is_empty() {
                        (g.x_of(i) - hw) as f32
                    } else {
                        (g.tx * (2.0 * i as f64 * f / g.width as f64 - 1.0)) as f32
                    }
                })
                .collect();
            let row_y: Vec<f32> = (0..height)
                .map(|j| {
                    if levels.is_empty() {
                        g.y_of(j) as f32
                    } else {
                        (g.ty * (1.0 - (2 * j + 1) as f64 * f / g.height as f64)) as f32
                    }
                })
                .collect();
            if corners {
                let (dx, dy) = ((2.0 * hw * f) as f32, (2.0 * hh * f) as f32);
                layers
                    .iter_mut()
                    .for_each(|l| l.connect(width, height, dx, dy));
            }
            levels.push(Level {
                width,
                height,
                blocks_per_row: width.div_ceil(BLOCK),
                scale: f as f32,
                col_x0_scaled: col_x0.iter().map(|&x| light.x_in_half_light(x)).collect(),
                col_x0,
                row_y,
                hw: (hw * f) as f32,
                hh: (hh * f) as f32,
                layers,
            });
            if !next {
                break;
            }
            (width, height) = (coarser[0].1, coarser[0].2);
            layers = coarser.into_iter().map(|c| c.0).collect();
        }
        Kernel {
            rec_width: r.width,
            rec_col_x: (0..r.width).map(|i| r.x_of(i) as f32).collect(),
            rec_row_y: (0..r.height).map(|j| r.y_of(j) as f32).collect(),
            tx: g.tx as f32,
            ty: g.ty as f32,
            width: g.width as f32,
            height: g.height as f32,
            inv_half_lx: half_light.inv_half[0],
            inv_half_ly: half_light.inv_half[1],
            half_lx: half_light.half[0],
            half_ly: half_light.half[1],
            levels,
            texel_per_d: (4.0 * (hw / lx).max(hh / ly)) as f32,
            max_on_light: 2.0 * hierarchy.map_or(0.0, |h| h.max_texel_on_light),
            plane_wr: None,
            stop: crate::cancel::current(),
            meter: super::meter::current_meter(),
        }
    }

    /// Picks the receiver 1/depth the most whole tiles of `receiver` (the
    /// output map's depths) share, as `Group` computes it, and gives every
    /// connected layer its quads' corner reciprocals from there: on the
    /// study's floors most tiles are such, and the per-(quad, tile) 4-wide
    /// division was the closed kernel's largest cost over the open one's.
    pub(super) fn set_plane(&mut self, receiver: &[f32]) {
        use super::{ROWS_PER_GROUP, TILE_W};
        let w = self.rec_width;
        let h = receiver.len() / w.max(1);
        let mut counts: std::collections::HashMap<u32, usize> = Default::default();
        for tj in 0..h / ROWS_PER_GROUP {
            for ti in 0..w / TILE_W {
                let z = receiver[tj * ROWS_PER_GROUP * w + ti * TILE_W];
                let same = (0..ROWS_PER_GROUP).all(|r| {
                    let row = (tj * ROWS_PER_GROUP + r) * w + ti * TILE_W;
                    receiver[row..row + TILE_W]
                        .iter()
                        .all(|v| v.to_bits() == z.to_bits())
                });
                if same && z.is_finite() && z > 0.0 {
                    *counts.entry((1.0 / z).to_bits()).or_default() += 1;
                }
            }
        }
        // The most tiles; ties to the smaller bits (no hash-order dependence).
        let Some((bits, _)) = counts
            .into_iter()
            .max_by_key(|&(b, n)| (n, std::cmp::Reverse(b)))
        else {
            return;
        };
        let wr = f32::from_bits(bits);
        for lv in &mut self.levels {
            for layer in &mut lv.layers {
                layer.plane_invs = layer
                    .w
                    .par_iter()
                    .zip(&layer.corners)
                    .map(|(&wo, c)| super::corners::corner_invs(c, wr, wo - wr))
                    .collect();
            }
        }
        self.plane_wr = Some(wr);
    }

    /// Continuous row coordinate of tangent y at level `lv`, in units where
    /// row j's center is j.
    #[inline(always)]
    pub(super) fn row_coord(&self, lv: &Level, y: f32) -> f32 {
        ((1.0 - y / self.ty) * 0.5 * self.height) / lv.scale - 0.5
    }

    #[inline(always)]
    pub(super) fn col_coord(&self, lv: &Level, x: f32) -> f32 {
        ((x / self.tx + 1.0) * 0.5 * self.width) / lv.scale - 0.5
    }

    /// The level to shade layer `li` with for group `g`, or None when no
    /// texel of the layer can reach it. The level is the coarsest whose
    /// texels, back-projected onto the light from the nearest occluder that
    /// can reach the group (smallest d = wO - wR), stay within
    /// `max_texel_on_light`: wide penumbrae (large d) get coarse texels,
    /// contact shadows (small d) keep the finest. A lower bound on d comes
    /// from the query level: each texel's farthest occupied descendant, and
    /// how far it lies from the group (a micro-patch at d reaches only
    /// receivers within (L/2) d plus a texel).
    pub(super) fn level_for(&self, li: usize, g: &Group) -> Option<usize> {
        let w_max = self.levels[0].layers[li].w_max;
        if w_max <= g.wr_min {
            return None;
        }
        if self.levels.len() == 1 {
            return Some(0);
        }
        let q = &self.levels[QUERY_LEVEL.min(self.levels.len() - 1)];
        let layer = &q.layers[li];
        let (hw0, hh0) = (self.levels[0].hw, self.levels[0].hh);
        let reach_x = q.hw + self.half_lx * (w_max - g.wr_min);
        let reach_y = q.hh + self.half_ly * (w_max - g.wr_min);
        let (rows, cols) = (q.height as isize - 1, q.width as isize - 1);
        let j_lo = (self.row_coord(q, g.y_hi + reach_y).floor() as isize).clamp(0, rows) as usize;
        let j_hi = (self.row_coord(q, g.y_lo - reach_y).ceil() as isize).clamp(0, rows) as usize;
        let i_lo = (self.col_coord(q, g.x_lo - reach_x).floor() as isize).clamp(0, cols) as usize;
        let i_hi = (self.col_coord(q, g.x_hi + reach_x).ceil() as isize).clamp(0, cols) as usize;
        let mut d_lo = f32::INFINITY;
        for j in j_lo..=j_hi {
            let yc = q.row_y[j];
            let dy = (g.y_lo - (yc + q.hh)).max(yc - q.hh - g.y_hi).max(0.0);
            for i in i_lo..=i_hi {
                let k = j * q.width + i;
                let dw = layer.w_near[k] - g.wr_min;
                let x0 = q.col_x0[i];
                let dx = (g.x_lo - (x0 + 2.0 * q.hw)).max(x0 - g.x_hi).max(0.0);
                if dw <= 0.0 || dx >= hw0 + self.half_lx * dw || dy >= hh0 + self.half_ly * dw {
                    continue;
                }
                let bound = (layer.w_far[k] - g.wr_max)
                    .max((dx - hw0) / self.half_lx)
                    .max((dy - hh0) / self.half_ly)
                    .max(0.0);
                d_lo = d_lo.min(bound);
            }
        }
        if d_lo == f32::INFINITY {
            return None;
        }
        // Texel size on the light at level l: 2^l texel_per_d / d.
        let ratio = self.max_on_light * d_lo / self.texel_per_d;
        let level = if ratio >= 1.0 {
            ratio.log2().floor() as usize
        } else {
            0
        };
        Some(level.min(self.levels.len() - 1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::light::MapGrid;
    use crate::geom::light_shape::LightShape;

    /// Layers the kernel keeps for the occluder maps `layers`.
    fn kept(layers: Vec<&[f32]>) -> usize {
        let grid = MapGrid::new(8, 8, [0.5, 0.5]).unwrap();
        let receiver = vec![4.0f32; 64];
        let inputs = ShadowInputs {
            grid,
            occluder_grid: grid,
            light_shape: LightShape::rect([1.0, 1.0]),
            receiver: &receiver,
            occluder_layers: layers,
            occluder_triangles: None,
        };
        Kernel::new(&inputs, None, false).levels[0].layers.len()
    }

    #[test]
    fn a_layer_equal_to_an_earlier_one_is_not_shaded_again() {
        let front = vec![2.0f32; 64];
        let mut back = front.clone();
        assert_eq!(kept(vec![&front, &back, &front]), 1);
        back[5] = 3.0;
        assert_eq!(kept(vec![&front, &back, &front]), 2);
    }
}
