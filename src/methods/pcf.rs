//! Percentage-closer filtering (Reeves, Salesin & Cook 1987, "Rendering
//! Antialiased Shadows with Depth Maps", SIGGRAPH '87): filter the *results*
//! of the depth comparisons around a point, never the depths themselves.
//!
//! The map is piecewise constant: texel [j, i] covers the pixel square
//! [i, i+1] x [j, j+1] (continuous pixel coordinates of `MapGrid::to_pixel`)
//! and its comparison gives one value `test(k)`, k = j W + i (1 lit, 0 in
//! shadow, or anything a caller computes: a biased test, two layers...). The
//! filters here are the exact box filter of that piecewise-constant function:
//!
//! ```text
//!     F(px, py) = (1 / (4 hx hy)) ∫∫_{[px ± hx] x [py ± hy]} test(x, y) dx dy
//!               = Σ_{j,i} wy_j wx_i test(j W + i),
//!     wx_i = |[px - hx, px + hx] ∩ [i, i+1]| / (2 hx)   (the same along y),
//! ```
//!
//! separable, non-negative, each texel weighted by its overlap with the box.
//! Half-widths below half a texel are raised to half a texel: the box of one
//! texel around (px, py) is exactly bilinear interpolation of the four nearest
//! texel tests (2x2 bilinear PCF, as shadow-map hardware does it), since
//! |[p - 1/2, p + 1/2] ∩ [i, i+1]| is the linear "tent" weight of texel i.
//!
//! Bounded work (`max_taps` = m): per axis, when the box overlaps at most m
//! texels every one is read with its exact weight (at most m x m reads).
//! Otherwise the part of the box inside the map, [a, b], is split into m equal
//! strata and sampled at their centres a + (k + 1/2)(b - a)/m, k = 0..m, each
//! tap the bilinear interpolation of its two nearest texels (the box filter
//! over one texel around the tap) with weight (b - a) / (2 h m): m x m taps,
//! at most 2m x 2m texel reads. That is the box of width 2h sampled by
//! stratified, area-weighted taps, each pre-filtered over one texel; its error
//! near a straight edge is of the order of a stratum's share, 1/m.
//!
//! Outside the map: `Border::Constant(c)` gives that part of the box the
//! value c (c = 1: no occluder outside the map, the shadow maps' case);
//! `Border::Clamp` folds it onto the edge texels (clamp-to-edge sampling).
//! The result is Σ w test / Σ w over the very same weights, so a test that is
//! 1 everywhere (border included) gives exactly 1 and one that is 0
//! everywhere gives exactly 0, whatever the rounding of the weights.
//!
//! [`Pcf`] is the hard shadow map's PCF: a size x size box of taps one texel
//! apart centred on the point, each tap bilinearly interpolated between its
//! four texel tests, weight 1/size² each. The unit boxes of taps one texel
//! apart tile the interval of `size` texels, so that kernel *is* the box
//! filter above with half-width size/2 texels: texel i gets the weight
//! |[p - size/2, p + size/2] ∩ [i, i+1]| / size per axis (size 1: the 2x2
//! bilinear PCF; a straight edge becomes a linear ramp `size` texels wide).

use crate::geom::light::MapGrid;

/// The most taps per axis a filter may take (m <= 256: at most 65 536 taps,
/// 262 144 texel reads, per filter). Larger requests are clamped to it.
pub const MAX_TAPS: u32 = 256;

/// What the box reads where it leaves the map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Border {
    /// The edge texels (clamp-to-edge).
    Clamp,
    /// A constant test value (1: lit, nothing occludes outside the map).
    Constant(f32),
}

/// The largest half-width (texels) the weights are computed with: a wider box
/// holds a map of at most 2^28 texels per axis in a fraction below 1e-22 of
/// its width (invisible in f32), and a finite half-width keeps the weights finite.
const MAX_HALF: f64 = 1e30;

/// One axis of a box filter: its texel weights, visited without storage.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Axis {
    /// Texels along the axis.
    n: usize,
    /// The box clipped to the map, [a, b] (pixel units); empty when !(a < b).
    a: f64,
    b: f64,
    /// The box's centre p and half-width h (after the raise to 1/2).
    p: f64,
    half: f64,
    /// 1 / (2h): a length in pixels -> a weight.
    inv_full: f64,
    /// Exact mode: texels i0..=i1. Stratified mode: `taps` > 0 taps.
    i0: usize,
    i1: usize,
    taps: u32,
    /// Clamp border: weights folded onto texel 0 (left) and n-1 (right);
    /// false: texels outside the map are dropped (the caller adds the border).
    clamp: bool,
    left: f64,
    right: f64,
    /// The fraction of the box outside the map (exactly 0 when inside).
    outside: f64,
}

impl Axis {
    /// The box [p - h, p + h] (pixels) over `n` texels, read with at most
    /// `max_taps` taps (clamped to 1..=MAX_TAPS). `h` below 1/2 (or NaN) is
    /// raised to 1/2. A non-finite `p` gives no texel inside the map.
    pub(crate) fn new(p: f64, h: f64, n: usize, max_taps: u32, clamp: bool) -> Axis {
        let h = if h >= 0.5 { h.min(MAX_HALF) } else { 0.5 };
        let inv_full = 0.5 / h;
        let m = max_taps.clamp(1, MAX_TAPS);
        let nf = n as f64;
        let mut axis = Axis {
            n,
            p,
            half: h,
            a: 0.0,
            b: 0.0,
            inv_full,
            i0: 0,
            i1: 0,
            taps: 0,
            clamp,
            left: 0.0,
            right: 0.0,
            outside: 1.0,
        };
        if n == 0 {
            return axis;
        }
        if !p.is_finite() {
            // Entirely off the map: the clamp border reads one edge texel.
            if clamp && p == f64::NEG_INFINITY {
                axis.left = 1.0;
            } else if clamp && p == f64::INFINITY {
                axis.right = 1.0;
            }
            return axis;
        }
        let (lo, hi) = (p - h, p + h);
        let left = (-lo).clamp(0.0, 2.0 * h) * inv_full;
        let right = (hi - nf).clamp(0.0, 2.0 * h) * inv_full;
        axis.outside = (left + right).min(1.0);
        if clamp {
            axis.left = left;
            axis.right = right;
        }
        let (a, b) = (lo.max(0.0), hi.min(nf));
        if !(a < b) {
            return axis;
        }
        axis.a = a;
        axis.b = b;
        axis.i0 = (a.floor() as usize).min(n - 1);
        axis.i1 = ((b.ceil() as usize).max(1) - 1).min(n - 1);
        if axis.i1 - axis.i0 >= m as usize {
            axis.taps = m;
        }
        axis
    }

    /// How many texels `for_each` reads (with repeats): an upper bound on
    /// its calls, what a box filter's cost is counted in.
    pub(crate) fn reads(&self) -> usize {
        let borders = usize::from(self.left > 0.0) + usize::from(self.right > 0.0);
        let inside = if !(self.a < self.b) {
            0
        } else if self.taps == 0 {
            self.i1 - self.i0 + 1
        } else {
            // A tap straddles two texels.
            2 * self.taps as usize
        };
        borders + inside
    }

    /// Calls `f(texel, weight)` for every weighted texel (a texel may come
    /// more than once in stratified mode). The weights sum to the fraction
    /// of the box inside the map (to 1 with the clamp border).
    #[inline]
    pub(crate) fn for_each(&self, mut f: impl FnMut(usize, f64)) {
        if self.left > 0.0 {
            f(0, self.left);
        }
        if self.right > 0.0 {
            f(self.n - 1, self.right);
        }
        if !(self.a < self.b) {
            return;
        }
        if self.taps == 0 {
            for i in self.i0..=self.i1 {
                let x0 = (i as f64).max(self.a);
                let x1 = ((i + 1) as f64).min(self.b);
                let w = (x1 - x0) * self.inv_full;
                if w > 0.0 {
                    f(i, w);
                }
            }
            return;
        }
        let m = self.taps as f64;
        let step = (self.b - self.a) / m;
        let wt = step * self.inv_full;
        let last = self.n as isize - 1;
        for k in 0..self.taps {
            // The tap's one-texel box [p - 1/2, p + 1/2] overlaps texels
            // floor(p - 1/2) and the next by 1 - t and t.
            let q = self.a + (k as f64 + 0.5) * step - 0.5;
            let fi = q.floor();
            let t = q - fi;
            let i = fi as isize;
            for (idx, w) in [(i, wt * (1.0 - t)), (i + 1, wt * t)] {
                if !(w > 0.0) {
                    continue;
                }
                if (0..=last).contains(&idx) {
                    f(idx as usize, w);
                } else if self.clamp {
                    f(idx.clamp(0, last) as usize, w);
                }
            }
        }
    }

    /// Calls `f(x0, x1, reads)` for every cell of the box inside the map
    /// (pixel units): in exact mode each texel's part [max(i, a), min(i+1,
    /// b)], read from texel i alone; in stratified mode each stratum, read
    /// at its centre bilinearly from its two nearest texels (their shares
    /// summing to 1, a texel off the map dropped). The clamp border is no
    /// cell: `pcf_disk`, which weighs cells by their own area, takes the
    /// part outside the map apart.
    #[inline]
    pub(crate) fn cells(&self, mut f: impl FnMut(f64, f64, &[(usize, f64)])) {
        if !(self.a < self.b) {
            return;
        }
        if self.taps == 0 {
            for i in self.i0..=self.i1 {
                let x0 = (i as f64).max(self.a);
                let x1 = ((i + 1) as f64).min(self.b);
                if x1 > x0 {
                    f(x0, x1, &[(i, 1.0)]);
                }
            }
            return;
        }
        let step = (self.b - self.a) / self.taps as f64;
        let last = self.n as isize - 1;
        for k in 0..self.taps {
            let x0 = self.a + k as f64 * step;
            let q = x0 + 0.5 * step - 0.5;
            let fi = q.floor();
            let t = q - fi;
            let i = fi as isize;
            let mut reads = [(0usize, 0f64); 2];
            let mut count = 0;
            for (idx, w) in [(i, 1.0 - t), (i + 1, t)] {
                if w > 0.0 && (0..=last).contains(&idx) {
                    reads[count] = (idx as usize, w);
                    count += 1;
                }
            }
            f(x0, x0 + step, &reads[..count]);
        }
    }

    /// The box's centre and half-width (pixels), after the raise to 1/2.
    pub(crate) fn centre_half(&self) -> (f64, f64) {
        (self.p, self.half)
    }

    /// Texels along the axis.
    pub(crate) fn texels(&self) -> usize {
        self.n
    }

    /// The fraction of the box outside the map, computed from the box's
    /// ends (not as 1 minus the weights): exactly 0 for a box inside the map.
    pub(crate) fn outside(&self) -> f64 {
        self.outside
    }
}

/// Calls `f(k, w)` for every texel k = j W + i of the separable box `ax` x `ay`.
#[inline]
pub(crate) fn visit(ax: &Axis, ay: &Axis, width: usize, mut f: impl FnMut(usize, f64)) {
    ay.for_each(|j, wy| {
        let row = j * width;
        ax.for_each(|i, wx| f(row + i, wy * wx));
    });
}

/// The box filter of `test` over [px ± hx] x [py ± hy] (continuous pixel
/// coordinates of `grid`, half-widths in texels, each raised to at least 1/2),
/// with at most `max_taps` taps per axis (module doc). `test(k)` is read for
/// texels k inside the map only. A weighted mean of the tests (and border);
/// with a non-finite (px, py) the box is off the map.
pub fn box_filter<F: Fn(usize) -> f32>(
    grid: &MapGrid,
    px: f64,
    py: f64,
    half: [f64; 2],
    max_taps: u32,
    border: Border,
    test: F,
) -> f32 {
    let clamp = border == Border::Clamp;
    let ax = Axis::new(px, half[0], grid.width, max_taps, clamp);
    let ay = Axis::new(py, half[1], grid.height, max_taps, clamp);
    let (mut num, mut den) = (0f64, 0f64);
    visit(&ax, &ay, grid.width, |k, w| {
        num += w * test(k) as f64;
        den += w;
    });
    if let Border::Constant(c) = border {
        // The part of the box outside the map: 1 - (1 - ox)(1 - oy).
        let (ox, oy) = (ax.outside(), ay.outside());
        let out = (ox + oy - ox * oy).clamp(0.0, 1.0);
        num += out * c as f64;
        den += out;
        if !(den > 0.0) {
            return c;
        }
    }
    if den > 0.0 {
        (num / den) as f32
    } else {
        1.0
    }
}

/// Whether an occluder depth `d` is nearer the light than a receiver at `z`:
/// empty texels (inf), NaN and depths <= 0 (not in front of the light) never are.
#[inline]
pub fn occludes(d: f32, z: f32) -> bool {
    d > 0.0 && d < z
}

/// Hardware-style PCF of a hard shadow map: size x size taps one texel apart
/// centred on the point, each the bilinear interpolation of its four texel
/// tests, weight 1/size² each; equivalently (module doc) the box filter of
/// half-width size/2 texels. `size` 0 counts as 1 (the 2x2 bilinear PCF);
/// above [`MAX_TAPS`], the box is sampled by MAX_TAPS stratified taps per axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Pcf {
    pub size: u32,
}

impl Default for Pcf {
    fn default() -> Self {
        Pcf { size: 1 }
    }
}

impl Pcf {
    /// The filtered test at continuous pixel coordinates (px, py) of `grid`
    /// (`MapGrid::to_pixel`); `test(texel_index)` compares one texel (1 lit,
    /// 0 shadowed, or any value: the result is their weighted mean).
    pub fn filter<F: Fn(usize) -> f32>(
        &self,
        grid: &MapGrid,
        px: f64,
        py: f64,
        border: Border,
        test: F,
    ) -> f32 {
        let h = 0.5 * self.size.max(1) as f64;
        box_filter(grid, px, py, [h, h], MAX_TAPS, border, test)
    }

    /// Visibility of a receiver at tangent (x, y), planar depth z, from the
    /// depth map `map` on `grid`: the filtered test "not occluded"
    /// ([`occludes`]), nothing outside the map. 1 for z not finite or <= 0,
    /// or a map of the wrong length.
    pub fn visibility(&self, grid: &MapGrid, map: &[f32], x: f32, y: f32, z: f32) -> f32 {
        if !(z.is_finite() && z > 0.0) || map.len() != grid.len() {
            return 1.0;
        }
        let (px, py) = grid.to_pixel(x as f64, y as f64);
        self.filter(grid, px, py, Border::Constant(1.0), |k| {
            if occludes(map[k], z) {
                0.0
            } else {
                1.0
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A map lit (1) left of pixel column `e`, shadowed right of it.
    fn half_plane(grid: &MapGrid, e: usize) -> impl Fn(usize) -> f32 + '_ {
        move |k| if k % grid.width < e { 1.0 } else { 0.0 }
    }

    #[test]
    fn size_1_is_the_bilinear_ramp_over_one_texel() {
        let grid = MapGrid::new(16, 8, [1.0, 0.5]).unwrap();
        let e = 9usize;
        for s in 0..=400 {
            let px = 5.0 + 8.0 * s as f64 / 400.0;
            let v = Pcf { size: 1 }.filter(&grid, px, 3.3, Border::Clamp, half_plane(&grid, e));
            // 1 up to the centre of the last lit texel, 0 from the centre of
            // the first shadowed one, linear between.
            let want = (e as f64 - px + 0.5).clamp(0.0, 1.0);
            assert!((v as f64 - want).abs() < 1e-6, "px {px}: {v} vs {want}");
        }
    }

    #[test]
    fn size_3_spreads_the_ramp_over_three_texels() {
        let grid = MapGrid::new(32, 8, [1.0, 0.5]).unwrap();
        let e = 15usize;
        for s in 0..=400 {
            let px = 10.0 + 10.0 * s as f64 / 400.0;
            let v = Pcf { size: 3 }.filter(&grid, px, 4.0, Border::Clamp, half_plane(&grid, e));
            let want = ((e as f64 - px) / 3.0 + 0.5).clamp(0.0, 1.0);
            assert!((v as f64 - want).abs() < 1e-6, "px {px}: {v} vs {want}");
        }
    }

    #[test]
    fn pcf_is_size_squared_bilinear_taps_one_texel_apart() {
        // The kernel as hardware PCF computes it, written out: size² taps,
        // each bilinear between its four texels (clamp to edge).
        let (w, h) = (19usize, 13usize);
        let grid = MapGrid::new(w, h, [0.6, 0.4]).unwrap();
        let mut seed = 1u64;
        let vals: Vec<f32> = (0..w * h)
            .map(|_| if lcg(&mut seed) < 0.5 { 1.0 } else { 0.0 })
            .collect();
        let at = |i: isize, j: isize| {
            let i = i.clamp(0, w as isize - 1) as usize;
            let j = j.clamp(0, h as isize - 1) as usize;
            vals[j * w + i] as f64
        };
        let bilinear = |px: f64, py: f64| {
            let (qx, qy) = (px - 0.5, py - 0.5);
            let (fx, fy) = (qx.floor(), qy.floor());
            let (tx, ty) = (qx - fx, qy - fy);
            let (i, j) = (fx as isize, fy as isize);
            (1.0 - ty) * ((1.0 - tx) * at(i, j) + tx * at(i + 1, j))
                + ty * ((1.0 - tx) * at(i, j + 1) + tx * at(i + 1, j + 1))
        };
        for size in [1u32, 2, 3, 4, 7] {
            for _ in 0..200 {
                let px = -2.0 + (w as f64 + 4.0) * lcg(&mut seed);
                let py = -2.0 + (h as f64 + 4.0) * lcg(&mut seed);
                let c = (size as f64 - 1.0) / 2.0;
                let mut want = 0.0;
                for b in 0..size {
                    for a in 0..size {
                        want += bilinear(px + a as f64 - c, py + b as f64 - c);
                    }
                }
                want /= (size * size) as f64;
                let v = Pcf { size }.filter(&grid, px, py, Border::Clamp, |k| vals[k]);
                assert!((v as f64 - want).abs() < 1e-6, "size {size}: {v} vs {want}");
            }
        }
    }

    #[test]
    fn weights_sum_to_one_lit_is_exactly_1_and_shadowed_exactly_0() {
        let grid = MapGrid::new(23, 17, [0.7, 0.3]).unwrap();
        let mut seed = 4u64;
        for size in [0u32, 1, 2, 3, 5, 40, 300] {
            for _ in 0..100 {
                let px = -5.0 + 33.0 * lcg(&mut seed);
                let py = -5.0 + 27.0 * lcg(&mut seed);
                let pcf = Pcf { size };
                for border in [Border::Clamp, Border::Constant(1.0)] {
                    assert_eq!(pcf.filter(&grid, px, py, border, |_| 1.0), 1.0);
                }
                assert_eq!(pcf.filter(&grid, px, py, Border::Clamp, |_| 0.0), 0.0);
                // The weights: a constant test c gives c back.
                let v = pcf.filter(&grid, px, py, Border::Clamp, |_| 0.375);
                assert!((v - 0.375).abs() < 1e-6);
                // Inside the map, a shadowed map with a lit border is 0.
                if (size as f64) < 10.0 && (5.0..18.0).contains(&px) && (5.0..12.0).contains(&py) {
                    assert_eq!(
                        pcf.filter(&grid, px, py, Border::Constant(1.0), |_| 0.0),
                        0.0
                    );
                }
            }
        }
        // A shadowed map seen from far outside with a lit border: 1.
        let v = Pcf { size: 3 }.filter(&grid, -50.0, 3.0, Border::Constant(1.0), |_| 0.0);
        assert_eq!(v, 1.0);
    }

    #[test]
    fn the_depth_test_visibility_and_odd_inputs() {
        let grid = MapGrid::new(8, 8, [0.5, 0.5]).unwrap();
        let mut map = vec![f32::INFINITY; 64];
        for j in 0..8 {
            for i in 0..4 {
                map[j * 8 + i] = 2.0;
            }
        }
        let pcf = Pcf { size: 1 };
        // Left half occluded at depth 2: a receiver at 3 deep on the left is
        // shadowed, one at 1.5 (in front) is lit.
        assert_eq!(pcf.visibility(&grid, &map, -0.3, 0.0, 3.0), 0.0);
        assert_eq!(pcf.visibility(&grid, &map, 0.3, 0.0, 3.0), 1.0);
        assert_eq!(pcf.visibility(&grid, &map, -0.3, 0.0, 1.5), 1.0);
        // On the edge (tangent 0): halfway.
        assert!((pcf.visibility(&grid, &map, 0.0, 0.0, 3.0) - 0.5).abs() < 1e-6);
        for (x, y, z) in [
            (0.0, 0.0, f32::NAN),
            (0.0, 0.0, -1.0),
            (f32::NAN, 0.0, 3.0),
            (f32::INFINITY, 0.0, 3.0),
            (1e30, -1e30, 3.0),
        ] {
            assert_eq!(pcf.visibility(&grid, &map, x, y, z), 1.0);
        }
        assert_eq!(pcf.visibility(&grid, &map[..10], -0.3, 0.0, 3.0), 1.0);
        let huge = Pcf { size: u32::MAX };
        let v = huge.visibility(&grid, &map, -0.3, 0.0, 3.0);
        assert!((0.0..=1.0).contains(&v), "{v}");
    }
}
