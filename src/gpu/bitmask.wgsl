// The bitmask method on the GPU (appended to gather.wgsl): the arithmetic of
// Bitmask::add_texel in src/methods/bitmask.rs, per receiver texel. A mask of
// up to 256 light samples is 8 u32 words in `acc` (idx * 8 + word); the
// layers OR into one mask.

// The sample pattern's rank tables, 8 words per entry: x_ge[k] (the samples
// whose x-rank is >= k, k in 0..=S) at k * 8, then y_ge[k] at (S + 1 + k) * 8.
@group(0) @binding(6) var<storage, read> tables: array<u32>;

const WORDS: u32 = 8u;

fn x_ge(k: u32, q: u32) -> u32 {
    return tables[k * WORDS + q];
}

fn y_ge(k: u32, q: u32) -> u32 {
    return tables[(gp.samples + 1u + k) * WORDS + q];
}

// The receiver's mask while gather_chunk runs.
var<private> mask: array<u32, 8>;

// Bitmask::add_texel's arithmetic for micro-patch [x0, x1] x (row r) at
// 1/depth w: the samples whose ranks its back-projection covers.
fn add_texel(w: f32, x0: f32, x1: f32, xr_s: f32, r: RowReach, rc: Receiver) {
    let s = f32(gp.samples);
    let half = 0.5 * s;
    let d = w - rc.wr;
    let inv = select(0.0, 1.0 / d, d > 0.0);
    // Light coordinate t in [-1, 1] -> sample units; first rank at or above a
    // lower bound, one past the last at or below an upper bound, clamped to
    // [0, S].
    let ka = u32(clamp(ceil(((x0 - xr_s) * inv + 1.0) * half - 0.5), 0.0, s));
    let kb = u32(clamp(floor(((x1 - xr_s) * inv + 1.0) * half - 0.5) + 1.0, 0.0, s));
    let kc = u32(clamp(ceil(((-r.nay0) * inv + 1.0) * half - 0.5), 0.0, s));
    let kd = u32(clamp(floor((r.ay1 * inv + 1.0) * half - 0.5) + 1.0, 0.0, s));
    for (var q = 0u; q < WORDS; q++) {
        mask[q] |= x_ge(ka, q) & ~x_ge(kb, q) & y_ge(kc, q) & ~y_ge(kd, q);
    }
}

// Ors this dispatch's chunk of rows of its layer into every receiver's mask.
@compute @workgroup_size(8, 8)
fn bitmask(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rc = receiver(gid);
    if !rc.ok {
        return;
    }
    var full = true;
    for (var q = 0u; q < WORDS; q++) {
        mask[q] = acc[rc.idx * WORDS + q];
        full = full && mask[q] == x_ge(0u, q);
    }
    // Every sample hidden: nothing left to add.
    if full {
        return;
    }
    gather_chunk(rc);
    for (var q = 0u; q < WORDS; q++) {
        acc[rc.idx * WORDS + q] = mask[q];
    }
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
    var hidden = 0u;
    for (var q = 0u; q < WORDS; q++) {
        hidden += countOneBits(acc[idx * WORDS + q]);
    }
    vis[idx] = 1.0 - f32(hidden) / f32(gp.samples);
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
    var full = true;
    for (var q = 0u; q < WORDS; q++) {
        mask[q] = acc[rc.idx * WORDS + q];
        full = full && mask[q] == x_ge(0u, q);
    }
    if full {
        return;
    }
    gather_points_chunk(rc);
    for (var q = 0u; q < WORDS; q++) {
        acc[rc.idx * WORDS + q] = mask[q];
    }
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
    var hidden = 0u;
    for (var q = 0u; q < WORDS; q++) {
        hidden += countOneBits(acc[idx * WORDS + q]);
    }
    vis[idx] = 1.0 - f32(hidden) / f32(gp.samples);
}
