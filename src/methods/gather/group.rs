//! Groups of receivers: up to LANES receivers shaded together, either an
//! 8x8 tile of the output map (TILE_W x ROWS_PER_GROUP) or a run of LANES
//! neighbouring sample points, with the bounds over them that the traversal
//! prunes by; and the per-group loops that cut the output rows into tiles and
//! the sorted points into runs (`shade_row_generic`, `shade_points_generic`:
//! the source that `simd.rs` compiles for each instruction set).

use super::kernel::{Accumulator, Group, Kernel, LANES, ROWS_PER_GROUP, TILE_W};
use crate::methods::LightPoint;

impl Group {
    /// `None` when no lane has a receiver in front of the light. `tile`:
    /// the points are a whole tile of the output grid, row by row.
    pub(super) fn new(pts: impl Iterator<Item = (f32, f32, f32)>, tile: bool) -> Option<Group> {
        let mut g = Group {
            xr: [0.0; LANES],
            yr: [0.0; LANES],
            wr: [f32::INFINITY; LANES],
            wr_min: f32::INFINITY,
            wr_max: 0.0,
            uniform_tile: false,
            x_lo: f32::INFINITY,
            x_hi: f32::NEG_INFINITY,
            y_lo: f32::INFINITY,
            y_hi: f32::NEG_INFINITY,
            first: 0,
        };
        for (l, (x, y, z)) in pts.take(LANES).enumerate() {
            if !(z.is_finite() && z > 0.0) {
                continue;
            }
            let wr = 1.0 / z;
            g.xr[l] = x;
            g.yr[l] = y;
            g.wr[l] = wr;
            g.wr_min = g.wr_min.min(wr);
            g.wr_max = g.wr_max.max(wr);
            g.x_lo = g.x_lo.min(x);
            g.x_hi = g.x_hi.max(x);
            g.y_lo = g.y_lo.min(y);
            g.y_hi = g.y_hi.max(y);
        }
        let first = g.wr[0].to_bits();
        g.uniform_tile = tile && g.wr[0].is_finite() && g.wr.iter().all(|w| w.to_bits() == first);
        g.wr_min.is_finite().then_some(g)
    }
}

impl Kernel {
    /// Whether the remaining groups are to be skipped: the call was
    /// cancelled, or its visits passed the meter's limit.
    #[inline(always)]
    fn stopped(&self) -> bool {
        self.stop.is_cancelled() || self.meter.as_ref().is_some_and(|m| m.over())
    }

    /// `shade_group`, its visits charged to the meter.
    #[inline(always)]
    fn shade_counted<A: Accumulator>(&self, a: &A, g: &Group) -> super::kernel::Lanes {
        let mut visits = 0u64;
        let v = self.shade_group(a, g, &mut visits);
        if let Some(m) = &self.meter {
            m.charge(visits);
        }
        v
    }

    #[inline(always)]
    /// Shades output rows j0 and j0 + 1 (when present): each group is a tile
    /// of TILE_W columns by ROWS_PER_GROUP rows, so that a visit of an
    /// occluder row serves both output rows.
    pub(super) fn shade_row_generic<A: Accumulator>(
        &self,
        a: &A,
        j0: usize,
        receiver: &[f32],
        out: &mut [f32],
    ) {
        let w = self.rec_width;
        let rows = receiver.len() / w;
        for c in (0..w).step_by(TILE_W) {
            if self.stopped() {
                return;
            }
            let e = (c + TILE_W).min(w);
            let pts = (0..ROWS_PER_GROUP).flat_map(|r| {
                (0..TILE_W).map(move |k| {
                    let i = c + k;
                    if r < rows && i < e {
                        (
                            self.rec_col_x[i],
                            self.rec_row_y[j0 + r],
                            receiver[r * w + i],
                        )
                    } else {
                        (0.0, 0.0, f32::INFINITY)
                    }
                })
            });
            if let Some(g) = Group::new(pts, e - c == TILE_W && rows == ROWS_PER_GROUP) {
                let v = self.shade_counted(a, &g);
                for r in 0..rows {
                    out[r * w + c..r * w + e].copy_from_slice(&v[r * TILE_W..r * TILE_W + (e - c)]);
                }
            }
        }
    }

    #[inline(always)]
    pub(super) fn shade_points_generic<A: Accumulator>(
        &self,
        a: &A,
        pts: &[LightPoint],
        first: usize,
        out: &mut [f32],
    ) {
        for (n, (o, p)) in out.chunks_mut(LANES).zip(pts.chunks(LANES)).enumerate() {
            if self.stopped() {
                return;
            }
            if let Some(mut g) = Group::new(p.iter().map(|p| (p.x, p.y, p.z)), false) {
                g.first = first + n * LANES;
                let v = self.shade_counted(a, &g);
                o.copy_from_slice(&v[..o.len()]);
            }
        }
    }
}
