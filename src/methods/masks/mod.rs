//! `exact`'s answer without a ray per light sample: each receiver's
//! blocked samples found from the triangles that cross its light, one bit
//! mask a receiver (the backprojection of Drettakis & Fiume 1994, on the
//! fixed sample pattern of `exact`, as the soft irregular shadow maps of
//! Sintorn, Eisemann & Assarsson 2008 build their masks from triangles).
//!
//! Each receiver traverses the BVH with its shaft to the whole light
//! (`shaft.rs`), nearer children first (the light at depth 0, the receiver
//! deepest: what lies near it casts the largest shadow on the light). A
//! node is skipped where its shaft misses it, or where every cell of the
//! pattern its box's shadow on the light covers is marked already (an
//! occlusion cull: the triangles behind an umbra cost one box test). Per
//! triangle, the samples it hides are the ones inside a handful of
//! half-planes of the light (`cover.rs`), found a cell of the pattern at a
//! time (`cells.rs`): cells the triangle's shadow covers are marked whole,
//! cells it misses are skipped, and only the cells its edges cross are
//! tested sample by sample. A receiver stops when every sample is marked
//! (an umbra). Its visibility is the unmarked share.
//!
//! Two shortcuts keep whole groups of triangles from that per-triangle
//! work. A closed convex piece (a box, a slat, a wall: `pieces.rs`, found
//! once a call in the triangles' input order) is marked by its outline
//! seen from the origin, one convex polygon, where it lies between the
//! light and the origin; its triangles are then skipped (thin boxes whose
//! twelve triangles' shadows shared one outline cost 2-2.4x less). And a
//! triangle reaching behind the origin or past the light whose plane has
//! the origin and the whole light on one side hides nothing (`beside`):
//! the floor a receiver lies on, or the wall a light is set in, no longer
//! sends every cell of the light to the row loop. A closed piece of more
//! triangles (a tessellated sphere, a cylinder: `solids.rs`) is marked by
//! its silhouette seen from the origin where that is one convex loop, row
//! by row from the edges crossing each row (`polygon.rs`), and a node
//! whose triangles all belong to an outlined piece is skipped whole: the
//! sphere of room_window, 2 208 triangles a receiver behind it, became one
//! polygon of about 60 edges.
//!
//! A receiver whose triangles would cost more than its rays is left to
//! them: each counts its work (a node visited `NODE`, a shadow marked
//! `MARK`, about one shadow ray's time and eight) and stops past
//! `RAYS_PER_SAMPLE` times its samples; `engine.rs` traces the receivers
//! left. The count caps the marking, not the time: the weights are a
//! model (a mark's cost varies with its cells), so a receiver left to the
//! rays pays its capped marks and then its rays. Without it, a sphere of
//! 2 million triangles, each one's shadow far smaller than a cell, took
//! 51 s at 640x480 and 256 samples against the rays' 2.3 s; with it 1.7 s.
//! After a receiver is left, the next one in its chunk (its neighbour in
//! the tile order) stops at a `TIGHT`th of that: a dense mesh's shadow
//! costs its receivers little waste (8 was set, not tuned). Chosen on the
//! calibration scenes and mesh_125k at 640x480 (`benchmarks/
//! bench_masks.py`'s scenes, medians of 3): 2, 4 and 8 rays a sample, and
//! none, took 168, 157, 155 and 206 ms on bunny_on_slab at 256 samples,
//! 262, 274, 365 and 366 on torus_on_slab, 777, 759, 811 and 3 427 on
//! mesh_125k; on the five others 4 took room_window from 286 to 245 ms
//! and blocks_on_table from 217 to 197 and kept the rest within 4% of
//! none (2 was slower: shelf_with_objects 230 against 194, open_assets
//! 123 against 103). At 1024
//! samples 4 and none were within 6% on all but mesh_125k (2 227 against
//! 3 315). Held out (the eight held-out as-built scenes, many_meshes,
//! crowd): 4 against none within 6% on every one at 256 and 1024 samples
//! but courtyard_low_sun at 1024 (147 against 134 ms, 10%); on mesh_2m
//! 1.7 s against the rays' 2.2 s. The answers are the rays' where a
//! receiver is left, so the error over shadowed pixels does not move
//! (the `exact` rows of docs/benchmarks/scenes_*.md: the same errors).
//!
//! What it computes is what `exact` computes with the same samples
//! (`shadow_rays::visibilities_weighted`, the shared pattern): a sample is
//! marked where its segment crosses a triangle at t in (t0, t1), edges
//! included; the two decide in different floating-point operations, so a
//! ray that grazes an edge (within rounding) may be answered differently
//! (`tests.rs` counts the pixels that differ). Its cost grows with the
//! triangles crossing the light and the cells their edges cross, not with
//! the samples: a receiver whose shaft meets no leaf is lit with no test
//! at all, and four times the samples cost the partial cells' tests only.
//!
//! The weighted visibility (the eye view's shaded image) is `exact`'s: the
//! unmarked samples' weights over all of theirs, summed in the same order.

mod cells;
mod cover;
mod pieces;
mod polygon;
mod solids;
#[cfg(test)]
mod tests;

use crate::trace::bvh::Bvh;
use crate::trace::shadow_rays::{Jitter, Origins, RayOrigin, Sampling, SurfacePoint, RAY_EPS};
use crate::trace::shaft::Shaft;
use cells::Cells;
use cover::{all_marked, beside, box_shadow, cell_range, cover, mark, shadow_box, HalfPlane};
use pieces::Pieces;
use rayon::prelude::*;

/// Receivers per parallel task.
const CHUNK: usize = 64;
/// A receiver's work, in about the time of one shadow ray: a node visited
/// costs `NODE`, a triangle's or a piece's shadow marked `MARK`. Where it
/// passes `RAYS_PER_SAMPLE` times its samples, the receiver is left to the
/// rays (`engine.rs`), which answer the same question: a mesh of millions
/// of triangles smaller than a cell of the pattern costs each receiver in
/// its shadow thousands of marks, and its rays a few dozen nodes each.
const NODE: u32 = 1;
const MARK: u32 = 8;
const RAYS_PER_SAMPLE: u32 = 4;
const TIGHT: u32 = 8;
/// Receivers whose weights are summed side by side.
const WEIGH: usize = 8;

/// `shadow_rays::visibilities_weighted` for the shared pattern (`s.jitter`
/// must be `Jitter::Shared`): `[V, V_w]` of each receiver, `absent` for
/// `None`, computed from the triangles instead of a ray per sample, and
/// the receivers left to the rays (their work passed its budget: `MARK`;
/// their entries are to be filled); None where the pattern has no cells
/// (its samples coincide: a point light's), for the caller to trace.
pub(crate) fn visibilities_weighted<R: RayOrigin>(
    bvh: &Bvh,
    receivers: &[Option<R>],
    order: &[usize],
    s: &Sampling,
    absent: f32,
) -> Option<(Vec<[f32; 2]>, Vec<usize>)> {
    let (na, nb) = s.light.grid;
    let budget = RAYS_PER_SAMPLE.saturating_mul(na.saturating_mul(nb));
    with_budget(bvh, receivers, order, s, absent, budget)
}

/// `visibilities_weighted` with a receiver's work capped at `budget`.
fn with_budget<R: RayOrigin>(
    bvh: &Bvh,
    receivers: &[Option<R>],
    order: &[usize],
    s: &Sampling,
    absent: f32,
    budget: u32,
) -> Option<(Vec<[f32; 2]>, Vec<usize>)> {
    debug_assert_eq!(s.jitter, Jitter::Shared);
    debug_assert_eq!(order.len(), receivers.len());
    let (na, nb) = s.light.grid;
    let light = s.light.region(0, na, 0, nb);
    let points = s.shared_points();
    let cells = Cells::new(&points, light)?;
    let stop = crate::cancel::current();
    let pieces = Pieces::find(bvh);
    let ctx = Ctx {
        bvh,
        pieces: &pieces,
        cells: &cells,
        points: &points,
        t0: s.t0,
        t1: 1.0 - RAY_EPS,
        light,
        budget,
    };
    let shaded: Vec<Vec<(usize, [f32; 2])>> = order
        .par_chunks(CHUNK)
        .map_init(Scratch::default, |scratch, chunk| {
            if stop.is_cancelled() {
                return vec![];
            }
            ctx.dispatch(receivers, chunk, scratch)
        })
        .collect();
    let mut v = vec![[absent; 2]; receivers.len()];
    let mut left = vec![];
    for (k, x) in shaded.into_iter().flatten() {
        if x[0].is_nan() {
            left.push(k);
        } else {
            v[k] = x;
        }
    }
    Some((v, left))
}

/// `SurfacePoint::weight` of `WEIGH` points at the light point (x, y),
/// the same operations in the same order (so the same bits), a lane each.
#[inline(always)]
fn weights(sp: &[SurfacePoint; WEIGH], x: f32, y: f32) -> [f32; WEIGH] {
    std::array::from_fn(|j| {
        let s = &sp[j];
        let side = s.side[0] + x * s.side[1] + y * s.side[2];
        let (dx, dy, dz) = (x - s.p.x, y - s.p.y, 0.0 - s.p.z);
        let r2 = dx * dx + dy * dy + dz * dz;
        side.max(0.0) * s.p.z / (r2 * r2)
    })
}

/// What every receiver reads.
struct Ctx<'a> {
    bvh: &'a Bvh,
    pieces: &'a Pieces,
    cells: &'a Cells,
    points: &'a [(f32, f32)],
    t0: f32,
    t1: f32,
    light: [[f32; 2]; 2],
    /// The work after which a receiver is left to the rays.
    budget: u32,
}

/// A worker's buffers, reused from receiver to receiver.
#[derive(Default)]
struct Scratch {
    mask: Vec<u64>,
    stack: Vec<u32>,
    /// Per piece: the origin (`round`) that last met it, and whether its
    /// outline was marked then (its triangles skipped).
    met: Vec<(u32, bool)>,
    round: u32,
    /// The solids' silhouettes (`solids.rs`).
    solids: solids::Scratch,
    /// A chunk's receivers whose weights are to be summed (their place in
    /// its output, their index) and their masks, one after the other.
    pending: Vec<(usize, usize)>,
    masks: Vec<u64>,
    /// The current receiver's work (`NODE`, `MARK`), and its cap: a
    /// `TIGHT`th of the budget after a receiver left to the rays.
    work: u32,
    cap: u32,
}

impl Ctx<'_> {
    /// `chunk`, compiled for AVX2 where the CPU has it (the cells' sample
    /// tests and the weights run eight lanes wide; the operations are the
    /// same, so are the bits).
    #[inline]
    fn dispatch<R: RayOrigin>(
        &self,
        receivers: &[Option<R>],
        chunk: &[usize],
        scratch: &mut Scratch,
    ) -> Vec<(usize, [f32; 2])> {
        #[cfg(target_arch = "x86_64")]
        {
            if is_x86_feature_detected!("avx2") {
                // SAFETY: the CPU has the features the function is compiled for.
                return unsafe { self.chunk_avx2(receivers, chunk, scratch) };
            }
        }
        self.chunk(receivers, chunk, scratch)
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn chunk_avx2<R: RayOrigin>(
        &self,
        receivers: &[Option<R>],
        chunk: &[usize],
        scratch: &mut Scratch,
    ) -> Vec<(usize, [f32; 2])> {
        self.chunk(receivers, chunk, scratch)
    }

    /// `[V, V_w]` of the receivers `chunk`: each one's mask, then the
    /// weights of those in a penumbra, eight receivers side by side.
    #[inline(always)]
    fn chunk<R: RayOrigin>(
        &self,
        receivers: &[Option<R>],
        chunk: &[usize],
        scratch: &mut Scratch,
    ) -> Vec<(usize, [f32; 2])> {
        let mut out = Vec::with_capacity(chunk.len());
        scratch.pending.clear();
        scratch.masks.clear();
        scratch.cap = self.budget;
        for &k in chunk {
            let Some(r) = receivers[k].as_ref() else {
                continue;
            };
            let v = self.receiver(r, scratch);
            // Its neighbour in the chunk likely costs as much: a receiver
            // after one left to the rays gives up sooner.
            scratch.cap = if v[0].is_nan() {
                self.budget / TIGHT
            } else {
                self.budget
            };
            if R::WEIGHTED && v[1].is_nan() && !v[0].is_nan() {
                scratch.pending.push((out.len(), k));
                scratch.masks.extend_from_slice(&scratch.mask);
            }
            out.push((k, v));
        }
        let words = self.cells.len();
        for (group, masks) in scratch
            .pending
            .chunks(WEIGH)
            .zip(scratch.masks.chunks(WEIGH * words))
        {
            let lane = |j: usize| {
                let (at, k) = group[j.min(group.len() - 1)];
                (at, receivers[k].as_ref().expect("a receiver"))
            };
            let rs: [&R; WEIGH] = std::array::from_fn(|j| lane(j).1);
            let ms: [&[u64]; WEIGH] = std::array::from_fn(|j| {
                let j = j.min(group.len() - 1);
                &masks[j * words..(j + 1) * words]
            });
            let vw = self.weigh(rs, ms);
            for (j, &(at, _)) in group.iter().enumerate() {
                let v = out[at].1[0];
                out[at].1[1] = vw[j].unwrap_or(v);
            }
        }
        out
    }

    /// `exact`'s weighted sums for `WEIGH` receivers and their masks:
    /// every sample's weight in pattern order, f64, each receiver's sums
    /// on their own (side by side, so that the adds of one do not wait on
    /// the one before); None where all the weights are 0.
    #[inline(always)]
    fn weigh<R: RayOrigin>(&self, rs: [&R; WEIGH], ms: [&[u64]; WEIGH]) -> [Option<f32>; WEIGH] {
        let (mut seen, mut all) = ([0f64; WEIGH], [0f64; WEIGH]);
        let surfaces: Option<Vec<SurfacePoint>> = rs.iter().map(|r| r.surface()).collect();
        let lanes = surfaces
            .as_deref()
            .and_then(|s| <&[SurfacePoint; WEIGH]>::try_from(s).ok());
        for (&(x, y), &(k, bit)) in self.points.iter().zip(&self.cells.slot) {
            let w: [f32; WEIGH] = match lanes {
                Some(sp) => weights(sp, x, y),
                None => std::array::from_fn(|j| rs[j].weight(x, y)),
            };
            for j in 0..WEIGH {
                let w = f64::from(w[j]);
                all[j] += w;
                // Adding 0 to a sum that starts at +0 leaves it as is.
                let clear = ms[j][k as usize] >> bit & 1 == 0;
                seen[j] += if clear { w } else { 0.0 };
            }
        }
        std::array::from_fn(|j| (all[j] > 0.0).then(|| (seen[j] / all[j]) as f32))
    }

    /// One receiver's `[V, V_w]`, V_w NaN where its weights are to be
    /// summed (a penumbra of a weighted receiver: its mask is left in
    /// `scratch.mask`).
    #[inline(always)]
    fn receiver<R: RayOrigin>(&self, r: &R, scratch: &mut Scratch) -> [f32; 2] {
        if self.bvh.is_empty() {
            return [1.0; 2];
        }
        let cells = self.cells;
        let (lo, hi) = r.bounds();
        // None where an origin lies at or behind the light's plane: no
        // shaft bounds its rays, every node is entered.
        let shaft = Shaft::new(self.bvh, lo, hi, self.light);
        scratch.mask.clear();
        scratch.mask.resize(cells.len(), 0);
        let mut open = cells.open;
        let [[x0, x1], [y0, y1]] = cells.rect;
        let origins: [(glam::Vec3, Option<HalfPlane>); 2];
        let origins: &[(glam::Vec3, Option<HalfPlane>)] = match r.origins() {
            Origins::One(o) => {
                origins = [(o, None); 2];
                &origins[..1]
            }
            Origins::Two { above, below, side } => {
                let side = HalfPlane {
                    a: side[0],
                    b: side[1],
                    c: side[2],
                    strict: false,
                };
                match side.on_box([x0, y0], [x1, y1]) {
                    Some(true) => {
                        origins = [(above, None); 2];
                        &origins[..1]
                    }
                    Some(false) => {
                        origins = [(below, None); 2];
                        &origins[..1]
                    }
                    None => {
                        origins = [(above, Some(side)), (below, Some(side.not()))];
                        &origins[..]
                    }
                }
            }
        };
        let mut touched = false;
        scratch.work = 0;
        for &(o, side) in origins {
            touched |= self.mark_from(o, side, shaft.as_ref(), scratch, &mut open);
            if scratch.work > scratch.cap {
                // Left to the rays.
                return [f32::NAN; 2];
            }
            if open == 0 {
                break;
            }
        }
        let mask = &scratch.mask;
        let n = self.points.len();
        if !touched {
            return [1.0; 2];
        }
        let blocked: u32 = mask.iter().map(|w| w.count_ones()).sum();
        let v = (n as u32 - blocked) as f32 / n as f32;
        if blocked == 0 {
            return [1.0; 2];
        }
        if !R::WEIGHTED || blocked as usize == n {
            return [v, v];
        }
        // The weights are summed by `chunk`, eight receivers at a time.
        [v, f32::NAN]
    }

    /// Marks the samples the triangles hide from origin `o` (those on
    /// `side` of the light, where given), traversing the BVH within
    /// `shaft`; whether a leaf was reached.
    #[inline(always)]
    fn mark_from(
        &self,
        o: glam::Vec3,
        side: Option<HalfPlane>,
        shaft: Option<&Shaft>,
        scratch: &mut Scratch,
        open: &mut usize,
    ) -> bool {
        let (cells, nodes, tris) = (self.cells, &self.bvh.nodes, self.bvh.triangles());
        let pieces = self.pieces;
        if scratch.met.len() != pieces.len() {
            scratch.met = vec![(0, false); pieces.len()];
            scratch.round = 0;
        }
        scratch.round = scratch.round.wrapping_add(1);
        if scratch.round == 0 {
            scratch.met.fill((0, false));
            scratch.round = 1;
        }
        let round = scratch.round;
        let (mask, stack, met, sil, work) = (
            &mut scratch.mask,
            &mut scratch.stack,
            &mut scratch.met,
            &mut scratch.solids,
            &mut scratch.work,
        );
        let budget = scratch.cap;
        stack.clear();
        stack.push(0);
        let mut touched = false;
        while let Some(k) = stack.pop() {
            *work += NODE;
            if *work > budget {
                return touched;
            }
            let n = &nodes[k as usize];
            if shaft.is_some_and(|s| !s.meets(n)) {
                continue;
            }
            if n.min.z >= o.z {
                continue;
            }
            // The occlusion cull, once a cell is marked whole (before, no
            // node's shadow can fall on marked cells only).
            if *open < cells.open {
                let Some(bbox) = box_shadow(n.min, n.max, o) else {
                    continue;
                };
                let Some(range) = cell_range(cells, bbox) else {
                    continue;
                };
                if all_marked(cells, mask, range) {
                    continue;
                }
            }
            // A node of one piece: its outline once, the node skipped
            // where it is marked.
            let whole = pieces.node()[k as usize];
            if whole != pieces::NONE
                && self.outlined(whole, (o, side), (round, met), (mask, open, work), sil)
            {
                if *open == 0 {
                    return true;
                }
                touched = true;
                continue;
            }
            if n.count == 0 {
                // Nearer the receiver (deeper) popped first.
                let (a, b) = (n.start, n.start + 1);
                let (near, far) = if nodes[a as usize].max.z >= nodes[b as usize].max.z {
                    (a, b)
                } else {
                    (b, a)
                };
                stack.push(far);
                stack.push(near);
                continue;
            }
            touched = true;
            let leaf = n.start as usize..(n.start + n.count) as usize;
            for (tri, &piece) in tris[leaf.clone()].iter().zip(&pieces.of()[leaf]) {
                if piece != pieces::NONE
                    && self.outlined(piece, (o, side), (round, met), (mask, open, work), sil)
                {
                    if *open == 0 {
                        return true;
                    }
                    continue;
                }
                let Some(bbox) = shadow_box(tri, o) else {
                    continue;
                };
                // A triangle reaching behind the origin (no box bounds its
                // shadow) or past the light: most such (the floor or the
                // wall a receiver lies on, a wall the light is set in) have
                // the origin and the light on one side of their plane.
                if (bbox.is_none() || tri.iter().any(|v| v.z <= 0.0)) && beside(tri, o, self.light)
                {
                    continue;
                }
                let Some(range) = cell_range(cells, bbox) else {
                    continue;
                };
                if all_marked(cells, mask, range) {
                    continue;
                }
                let Some(mut c) = cover(tri, o, self.t0, self.t1) else {
                    continue;
                };
                if let Some(p) = side {
                    c = c.and(p);
                }
                *work += MARK;
                if *work > budget {
                    return touched;
                }
                mark(&c, cells, range, mask, open);
                if *open == 0 {
                    return true;
                }
            }
        }
        touched
    }

    /// Whether piece `k` is marked by its outline from origin `o` (on
    /// `side`): `outline` the first time this origin (`round`) meets it,
    /// its answer kept in `met`.
    #[inline(always)]
    fn outlined(
        &self,
        k: u32,
        (o, side): (glam::Vec3, Option<HalfPlane>),
        (round, met): (u32, &mut [(u32, bool)]),
        (mask, open, work): (&mut [u64], &mut usize, &mut u32),
        sil: &mut solids::Scratch,
    ) -> bool {
        let m = &mut met[k as usize];
        if m.0 != round {
            *work += MARK;
            *m = (round, self.outline(k, o, side, mask, open, sil));
        }
        m.1
    }

    /// Marks the samples piece `k` hides from `o` (on `side`), by its
    /// outline; false where its triangles must be marked instead.
    #[inline(always)]
    fn outline(
        &self,
        k: u32,
        o: glam::Vec3,
        side: Option<HalfPlane>,
        mask: &mut [u64],
        open: &mut usize,
        sil: &mut solids::Scratch,
    ) -> bool {
        if !self.pieces.live(k) {
            return false;
        }
        let [lo, hi] = self.pieces.bounds[k as usize];
        let Some(Some(bbox)) = box_shadow(lo, hi, o) else {
            return false;
        };
        // Its triangles' shadows lie inside its box's: where that misses
        // the light or falls on marked cells only, so do theirs.
        let Some(range) = cell_range(self.cells, Some(bbox)) else {
            return true;
        };
        if all_marked(self.cells, mask, range) {
            return true;
        }
        let corners = self.pieces.corners(k);
        if let Some(solid) = self.pieces.solid(k) {
            let ok = solids::outline(solid, corners, [lo, hi], o, self.t0, self.t1, side, sil);
            if ok {
                polygon::mark_polygon(
                    &sil.planes,
                    &sil.ys,
                    self.cells,
                    range,
                    mask,
                    open,
                    &mut sil.active,
                );
            }
            return ok;
        }
        match pieces::outline(corners, o, self.t0, self.t1, side) {
            Some(c) => {
                mark(&c, self.cells, range, mask, open);
                true
            }
            None => false,
        }
    }
}
