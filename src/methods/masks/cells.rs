//! The shared light-sample pattern sorted into cells, so that a triangle's
//! shadow on the light is found cell by cell rather than sample by sample.
//!
//! The light's box is cut into a C x C grid. Every sample of the pattern
//! (`exact`'s points: `Sampling::sample`, the same for every receiver) goes
//! to the cell it lies in; a cell keeps the tight box of its samples and
//! their coordinates side by side (structure of arrays, padded to `LANE`).
//! A receiver's blocked samples are one `u64` a cell, bit j the cell's j-th
//! sample, so a cell is at most 64 samples: C grows until none holds more.
//!
//! C is about √(samples / 16): 4 for 256 samples, 8 for 1024. The cells a
//! triangle's edges cross are tested sample by sample, the cells inside it
//! cost one OR whatever they hold, and every cell its box reaches costs a
//! test of its box. Chosen on the calibration scenes of the eye view
//! (room_window, bunny_on_slab, shelf_with_objects at 320x240, 256 and 1024
//! samples; `benchmarks/bench_masks.py`): 16 a cell took 829 ms in all, 32
//! a cell 839 and 64 a cell 860; 8 x 8 cells at 256 samples (4 a cell, the
//! first rule) 895. On held-out scenes 64 a cell did best (fence_slats,
//! blinds, table_and_chairs, crowd: 1863, 1826 and 1758 ms for 16, 32 and
//! 64 a cell): the choice is not sharp.

/// Samples evaluated side by side (the partial cells' loop).
pub(crate) const LANE: usize = 8;

/// The most cells a side: 256² cells hold `MAX_SAMPLES` (65 536) samples
/// one a cell, so a pattern that still crowds one past 64 at that size has
/// samples that coincide.
const MAX_SIDE: usize = 256;

/// The pattern in cells.
pub(crate) struct Cells {
    /// Cells per side.
    pub c: usize,
    /// The light's box [[x0, x1], [y0, y1]] the grid covers.
    pub rect: [[f32; 2]; 2],
    /// Cells per unit of x and of y (a product where `cell_of` would
    /// divide; the samples are placed by the same function, so a box
    /// holding a sample still reaches its cell).
    per: [f32; 2],
    /// Per cell: the tight box of its samples (empty cells: inverted).
    pub lo: Vec<[f32; 2]>,
    pub hi: Vec<[f32; 2]>,
    /// Per cell: its first slot in `xs`/`ys` (a multiple of `LANE`) and its
    /// sample count.
    pub start: Vec<u32>,
    pub count: Vec<u32>,
    /// Per cell: the bits of its samples (`count` low bits).
    pub full: Vec<u64>,
    /// The cells holding a sample.
    pub open: usize,
    /// Per row of cells: the span of its samples' y (inverted where it has
    /// none).
    pub row_y: Vec<[f32; 2]>,
    /// The samples' coordinates in cell order, each cell padded to `LANE`
    /// with copies of its last sample (their bits are masked off).
    pub xs: Vec<f32>,
    pub ys: Vec<f32>,
    /// Sample i of the pattern (row-major by stratum, `exact`'s order): its
    /// cell and bit.
    pub slot: Vec<(u32, u32)>,
}

impl Cells {
    /// The cells of `points` (the pattern, row-major by stratum) inside the
    /// box `rect`, C doubled while a cell holds more than 64 samples; None
    /// where one still does at `MAX_SIDE` (samples that coincide: a point
    /// light's), which the caller traces instead.
    pub(crate) fn new(points: &[(f32, f32)], rect: [[f32; 2]; 2]) -> Option<Cells> {
        let n = points.len().max(1);
        // About 16 samples a cell (module doc).
        let mut c = (((n as f64) / 16.0).sqrt().ceil() as usize).max(1);
        c = c.min((n as f64).sqrt().floor().max(1.0) as usize);
        while c <= MAX_SIDE {
            let cells = Cells::with_side(points, rect, c);
            if cells.count.iter().all(|&k| k <= 64) {
                return Some(cells);
            }
            c *= 2;
        }
        None
    }

    /// The cell (ix, iy) of the coordinate (x, y), clamped into the grid.
    #[inline(always)]
    pub(crate) fn cell_of(&self, x: f32, y: f32) -> (usize, usize) {
        let f = |v: f32, [a, _]: [f32; 2], per: f32| {
            let t = (v - a) * per;
            if t.is_nan() {
                0
            } else {
                (t.max(0.0) as usize).min(self.c - 1)
            }
        };
        (
            f(x, self.rect[0], self.per[0]),
            f(y, self.rect[1], self.per[1]),
        )
    }

    fn with_side(points: &[(f32, f32)], rect: [[f32; 2]; 2], c: usize) -> Cells {
        let mut probe = Cells {
            c,
            rect,
            per: rect.map(|[a, b]| c as f32 / (b - a)),
            lo: vec![],
            hi: vec![],
            start: vec![],
            count: vec![],
            full: vec![],
            open: 0,
            row_y: vec![],
            xs: vec![],
            ys: vec![],
            slot: vec![],
        };
        let cell_index = |p: &(f32, f32)| {
            let (ix, iy) = probe.cell_of(p.0, p.1);
            iy * c + ix
        };
        let mut members: Vec<Vec<u32>> = vec![vec![]; c * c];
        for (i, p) in points.iter().enumerate() {
            members[cell_index(p)].push(i as u32);
        }
        let mut slot = vec![(0u32, 0u32); points.len()];
        let (mut lo, mut hi) = (
            vec![[f32::INFINITY; 2]; c * c],
            vec![[f32::NEG_INFINITY; 2]; c * c],
        );
        let (mut start, mut count, mut full) = (vec![0; c * c], vec![0; c * c], vec![0u64; c * c]);
        let (mut xs, mut ys) = (vec![], vec![]);
        for (k, m) in members.iter().enumerate() {
            start[k] = xs.len() as u32;
            count[k] = m.len() as u32;
            full[k] = if m.len() >= 64 {
                u64::MAX
            } else {
                (1u64 << m.len()) - 1
            };
            for (bit, &i) in m.iter().enumerate() {
                let (x, y) = points[i as usize];
                slot[i as usize] = (k as u32, bit as u32);
                lo[k] = [lo[k][0].min(x), lo[k][1].min(y)];
                hi[k] = [hi[k][0].max(x), hi[k][1].max(y)];
                xs.push(x);
                ys.push(y);
            }
            if let Some(&last) = m.last() {
                let (x, y) = points[last as usize];
                while xs.len() % LANE != 0 {
                    xs.push(x);
                    ys.push(y);
                }
            }
        }
        probe.row_y = (0..c)
            .map(|iy| {
                let row = iy * c..(iy + 1) * c;
                let y0 = lo[row.clone()]
                    .iter()
                    .fold(f32::INFINITY, |m, b| m.min(b[1]));
                let y1 = hi[row].iter().fold(f32::NEG_INFINITY, |m, b| m.max(b[1]));
                [y0, y1]
            })
            .collect();
        probe.lo = lo;
        probe.hi = hi;
        probe.start = start;
        probe.count = count;
        probe.open = full.iter().filter(|&&f| f != 0).count();
        probe.full = full;
        probe.xs = xs;
        probe.ys = ys;
        probe.slot = slot;
        probe
    }

    /// Cells in the grid.
    pub(crate) fn len(&self) -> usize {
        self.c * self.c
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sample_has_one_slot_inside_its_cells_box() {
        let mut pts = vec![];
        for j in 0..32 {
            for i in 0..32 {
                let x = (i as f32 + 0.37) / 32.0 - 0.5;
                let y = (j as f32 + 0.81) / 32.0 - 0.5;
                pts.push((x, y));
            }
        }
        let cells = Cells::new(&pts, [[-0.5, 0.5], [-0.5, 0.5]]).unwrap();
        assert_eq!(cells.c, 8);
        assert_eq!(
            Cells::new(&pts[..256], [[-0.5, 0.5], [-0.5, 0.5]])
                .unwrap()
                .c,
            4
        );
        let mut seen = std::collections::HashSet::new();
        for (i, &(k, bit)) in cells.slot.iter().enumerate() {
            assert!(seen.insert((k, bit)));
            let k = k as usize;
            assert!(bit < cells.count[k]);
            let s = cells.start[k] as usize + bit as usize;
            assert_eq!((cells.xs[s], cells.ys[s]), pts[i]);
            let (x, y) = pts[i];
            assert!(cells.lo[k][0] <= x && x <= cells.hi[k][0]);
            assert!(cells.lo[k][1] <= y && y <= cells.hi[k][1]);
        }
        assert_eq!(cells.xs.len() % LANE, 0);
    }

    #[test]
    fn crowded_cells_split_until_each_holds_64() {
        // Every sample in a tenth of the box's side.
        let pts: Vec<(f32, f32)> = (0..4096)
            .map(|i| {
                (
                    -0.5 + (i % 64) as f32 * 1.5e-3,
                    -0.5 + (i / 64) as f32 * 1.5e-3,
                )
            })
            .collect();
        let cells = Cells::new(&pts, [[-0.5, 0.5], [-0.5, 0.5]]).unwrap();
        assert!(cells.count.iter().all(|&k| k <= 64));
        assert_eq!(cells.count.iter().sum::<u32>(), 4096);
    }

    #[test]
    fn coinciding_samples_have_no_cells() {
        // A point light's pattern: every sample at its centre.
        assert!(Cells::new(&[(0.0, 0.0); 1024], [[0.0, 0.0], [0.0, 0.0]]).is_none());
        assert!(Cells::new(&[(0.0, 0.0); 64], [[0.0, 0.0], [0.0, 0.0]]).is_some());
    }
}
