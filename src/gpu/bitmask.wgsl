// The bitmask method on the GPU (appended to gather.wgsl, and followed by
// bitmask_open.wgsl or bitmask_closed.wgsl, the `gaps` option's add_texel):
// the arithmetic of MaskKernel::add_texel (flat micro-patches, `add_patch`
// here) and MaskKernel::add_quad (connected micro-quads, `add_quad`) in
// src/methods/bitmask.rs, per receiver texel. A mask is WORDS u32 words in
// `acc` (idx * WORDS + word): 8 for up to 256 light samples (the CPU's 4 u64),
// 32 for 1024 (16 u64); gather.rs's bitmask_source sets WORDS. The shader
// handles a mask as WORDS / 4 vec4s (fewer loop iterations per texel:
// gather.rs's texel_cost). The layers OR into one mask.

// The sample pattern's rank tables, WORDS words per entry: x_ge[k] (the
// samples whose x-rank is >= k, k in 0..=S) at k * WORDS, then y_ge[k] at
// (S + 1 + k) * WORDS (Bitmask::rank_tables).
@group(0) @binding(6) var<storage, read> tables: array<vec4<u32>>;

// Set by gather.rs (bitmask_source): 8 or 32.
const WORDS: u32 = 8u;
const VECS: u32 = WORDS / 4u;

fn x_ge(k: u32, v: u32) -> vec4<u32> {
    return tables[k * VECS + v];
}

fn y_ge(k: u32, v: u32) -> vec4<u32> {
    return tables[(gp.samples + 1u + k) * VECS + v];
}

// The receiver's mask while gather_chunk runs.
var<private> mask: array<vec4<u32>, VECS>;

// RankBounds::lo and hi: light coordinate t (in [-1, 1] once scaled by inv)
// -> sample units; the first rank at or above a lower bound, one past the
// last at or below an upper bound, clamped to [0, S].
fn rank_lo(t: f32, inv: f32) -> u32 {
    let s = f32(gp.samples);
    let half = 0.5 * s;
    return u32(clamp(ceil((t * inv + 1.0) * half - 0.5), 0.0, s));
}

fn rank_hi(t: f32, inv: f32) -> u32 {
    let s = f32(gp.samples);
    let half = 0.5 * s;
    return u32(clamp(floor((t * inv + 1.0) * half - 0.5) + 1.0, 0.0, s));
}

// MaskKernel::mark: ORs the samples of ranks [ka, kb) x [kc, kd) into the mask.
fn mark(ka: u32, kb: u32, kc: u32, kd: u32) {
    for (var v = 0u; v < VECS; v++) {
        mask[v] |= x_ge(ka, v) & ~x_ge(kb, v) & y_ge(kc, v) & ~y_ge(kd, v);
    }
}

// MaskKernel::add_texel's arithmetic for the flat micro-patch [x0, x1] x
// (row r) at 1/depth w: the samples whose ranks its back-projection covers.
fn add_patch(w: f32, x0: f32, x1: f32, xr_s: f32, r: RowReach, rc: Receiver) {
    let d = w - rc.wr;
    let inv = select(0.0, 1.0 / d, d > 0.0);
    mark(
        rank_lo(x0 - xr_s, inv),
        rank_hi(x1 - xr_s, inv),
        rank_lo(-r.nay0, inv),
        rank_hi(r.ay1, inv),
    );
}

// bitmask.rs's corner_inv: 1/(wc - wR) for a corner at 1/depth wc, given
// d = w - wR of the quad's centre; 0 when the centre is not in front of the
// receiver (every bound the empty range), the centre's 1/d for a corner at
// or behind the receiver.
fn corner_inv(wc: f32, wr: f32, d: f32) -> f32 {
    let dc = wc - wr;
    return select(0.0, 1.0 / select(d, dc, dc > 0.0), d > 0.0);
}

// gather::min and gather::max (a < b ? a : b), whatever WGSL's min and max
// do with signed zeros.
fn min_of(a: f32, b: f32) -> f32 {
    return select(b, a, a < b);
}

fn max_of(a: f32, b: f32) -> f32 {
    return select(b, a, a > b);
}

// bitmask.rs's span: the bounding interval of 4 projected corners, as
// (min(min(t0, t1), min(t2, t3)), max(max(t0, t1), max(t2, t3))).
fn corner_span(t: vec4<f32>) -> vec2<f32> {
    return vec2<f32>(
        min_of(min_of(t.x, t.y), min_of(t.z, t.w)),
        max_of(max_of(t.x, t.y), max_of(t.z, t.w)),
    );
}

// MaskKernel::add_quad's arithmetic for the quad [x0, x1] x (row r) with
// centre 1/depth w and corner 1/depths c (top-left, top-right, bottom-left,
// bottom-right; top the row above, larger y): the bounding rectangle of its
// four corners projected from the receiver, ranks with inv = 1.
fn add_quad(c: vec4<f32>, w: f32, x0: f32, x1: f32, xr_s: f32, r: RowReach, rc: Receiver) {
    let wr = rc.wr;
    let d = w - wr;
    let i0 = corner_inv(c.x, wr, d);
    let i1 = corner_inv(c.y, wr, d);
    let i2 = corner_inv(c.z, wr, d);
    let i3 = corner_inv(c.w, wr, d);
    let a = x0 - xr_s;
    let e = x1 - xr_s;
    let bottom = -r.nay0;
    let top = r.ay1;
    let xs = corner_span(vec4<f32>(a * i0, e * i1, a * i2, e * i3));
    let ys = corner_span(vec4<f32>(top * i0, top * i1, bottom * i2, bottom * i3));
    mark(rank_lo(xs.x, 1.0), rank_hi(xs.y, 1.0), rank_lo(ys.x, 1.0), rank_hi(ys.y, 1.0));
}

// The receiver's mask from `acc` at slot idx; true when every sample is
// already hidden (nothing left to add).
fn load_mask(idx: u32) -> bool {
    var full = true;
    for (var v = 0u; v < VECS; v++) {
        let b = idx * WORDS + 4u * v;
        mask[v] = vec4<u32>(acc[b], acc[b + 1u], acc[b + 2u], acc[b + 3u]);
        full = full && all(mask[v] == x_ge(0u, v));
    }
    return full;
}

fn store_mask(idx: u32) {
    for (var v = 0u; v < VECS; v++) {
        let b = idx * WORDS + 4u * v;
        acc[b] = mask[v].x;
        acc[b + 1u] = mask[v].y;
        acc[b + 2u] = mask[v].z;
        acc[b + 3u] = mask[v].w;
    }
}

// The hidden samples in the mask at slot idx of `acc`.
fn hidden_samples(idx: u32) -> u32 {
    var hidden = 0u;
    for (var q = 0u; q < WORDS; q++) {
        hidden += countOneBits(acc[idx * WORDS + q]);
    }
    return hidden;
}

// Ors this dispatch's chunk of rows of its layer into every receiver's mask.
@compute @workgroup_size(8, 8)
fn bitmask(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rc = receiver(gid);
    if !rc.ok {
        return;
    }
    if load_mask(rc.idx) {
        return;
    }
    gather_chunk(rc);
    store_mask(rc.idx);
}

// Occlusion: the hidden samples' fraction.
@compute @workgroup_size(8, 8)
fn bitmask_resolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= gp.rec_w || gid.y >= gp.rec_h {
        return;
    }
    let rc = receiver(gid);
    let idx = gid.y * gp.rec_w + gid.x;
    if !rc.ok {
        vis[idx] = 1.0;
        return;
    }
    vis[idx] = 1.0 - f32(hidden_samples(idx)) / f32(gp.counted);
}

// Points mode (gather.wgsl): masks need no per-row step.
fn points_begin_row() {}

fn points_end_row() {}

// Ors this dispatch's chunk of its layer into every point's mask.
@compute @workgroup_size(64)
fn bitmask_points(@builtin(global_invocation_id) gid: vec3<u32>,
                  @builtin(num_workgroups) groups: vec3<u32>) {
    let rc = point_receiver(point_index(gid, groups));
    if !rc.ok {
        return;
    }
    if load_mask(rc.idx) {
        return;
    }
    gather_points_chunk(rc);
    store_mask(rc.idx);
}

@compute @workgroup_size(64)
fn bitmask_points_resolve(@builtin(global_invocation_id) gid: vec3<u32>,
                          @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = point_index(gid, groups);
    if idx >= pp.n_points {
        return;
    }
    let rc = point_receiver(idx);
    if !rc.ok {
        vis[idx] = 1.0;
        return;
    }
    vis[idx] = 1.0 - f32(hidden_samples(idx)) / f32(gp.counted);
}

// The weighted visibility (methods/bitmask/weighted.rs): each sample not
// hidden weighted by its share of the surface point's irradiance
// (`irradiance_weight`, gather.wgsl), over every sample's. A point with no
// sample hidden gives 1, with all 0, so only penumbra points loop
// (gp.counted <= 1024 iterations).

// The counted samples: (x, y) on the light in kernel units, their bit in
// the masks (as f32, exact below 2^24), 0 (`bitmask::light_samples`).
@group(0) @binding(15) var<storage, read> light_samples: array<vec4<f32>>;

// After bitmask_points_resolve: vis[n_points + idx], the weighted
// visibility (1 where no receiver).
@compute @workgroup_size(64)
fn bitmask_points_weigh(@builtin(global_invocation_id) gid: vec3<u32>,
                        @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = point_index(gid, groups);
    if idx >= pp.n_points {
        return;
    }
    let out = pp.n_points + idx;
    let rc = point_receiver(idx);
    let wp = weigh_points[idx];
    if !rc.ok || wp.valid == 0u {
        vis[out] = 1.0;
        return;
    }
    let hidden = hidden_samples(idx);
    if hidden == 0u {
        vis[out] = 1.0;
        return;
    }
    if hidden >= gp.counted {
        vis[out] = 0.0;
        return;
    }
    var lit = 0.0;
    var all = 0.0;
    for (var k = 0u; k < gp.counted; k++) {
        let s = light_samples[k];
        let w = irradiance_weight(wp, s.x, s.y);
        all += w;
        let b = u32(s.z);
        if ((acc[idx * WORDS + b / 32u] >> (b % 32u)) & 1u) == 0u {
            lit += w;
        }
    }
    vis[out] = select(0.0, lit / all, all > 0.0);
}
