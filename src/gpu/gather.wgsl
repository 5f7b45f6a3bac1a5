// The gather traversal on the GPU, shared by the occluder-map methods (the
// method's file is appended to this one): one invocation per receiver texel
// loops over the occluder texels that can reach it, like src/methods/gather.rs
// does for groups of 64 receivers. A gather, not a scatter: each invocation
// owns its receiver's sum (or mask), so it accumulates with no atomics. A
// scatter (one invocation per occluder texel adding into the receivers it
// reaches) would need float atomic adds, which WGSL lacks, and its sums would
// depend on the scheduling order.
//
// The work is cut into chunks: one dispatch per (layer, chunk of occluder
// rows), each invocation adding its chunk to its receiver's accumulator in
// `acc`, then a resolve dispatch turning accumulators into visibility. This
// bounds the loop iterations of an invocation (lavapipe stops an invocation
// after 65535 in all; real GPUs reset long-running dispatches) whatever the
// penumbra's size in texels.
//
// A method's file defines `add_texel(t, w, x0, x1, xr_s, r, rc)`, which adds
// occluder texel t (its index in `maps`) to its per-invocation state (a
// `var<private>`), `texel_reach(t, w)`, the 1/depth up to which texel t
// reaches (w for a flat micro-patch; the nearest of its centre and corners
// for bitmask's connected micro-quads, as the CPU's Layer::connect widens its
// bounds), which row_stats takes the rows' nearest 1/depth from, and its
// entry points, which load that state from `acc`, call `gather_chunk` and
// store it.
//
// Points mode (the eye view, src/gpu/eye.rs): the receivers are arbitrary
// light-space points (x, y tangents, 1/depth), sorted and cut into groups of
// 64 on the CPU as methods/gather/mod.rs's visibility_points does; one
// workgroup shades one group, one invocation a point. As the CPU's
// Kernel::shade_points (gather/traverse.rs's add_layer and add_row), every
// lane of a group visits the group's window: the rows in reach of the group's
// bounds, outward from the group's central row (j_c, j_c + 1, j_c - 1, ...),
// in each the columns in reach of the group's bounds, the texels nearer than
// the group's nearest receiver; each lane adds them to its own state, and
// `points_begin_row` / `points_end_row` (the method's) close a row's sum as
// the CPU's two-level sum does. The chunks here are runs of
// `steps_per_chunk` outward steps (two rows a step), so the lanes add the
// same terms in the same order as the CPU's one loop. Unlike the CPU, no
// BLOCK-wide runs are trimmed at the row's ends: a trimmed texel cannot reach
// any lane, and adds 0 (or at most a rounding error at the reach's edge).

// Shared with Rust (`GatherParams` in gather.rs; a test compares layouts).
struct GatherParams {
    rec_w: u32,
    rec_h: u32,
    occ_w: u32,
    occ_h: u32,
    n_layers: u32,
    // Layer k of the occluder maps starts at layer0_offset + k * layer_stride
    // in `maps` (the receiver map is at 0).
    layer0_offset: u32,
    layer_stride: u32,
    // Offsets in `axes`: receiver column x, receiver row y (tangent), occluder
    // column left edge in half-light units (2 x0 / Lx), occluder row center y.
    ax_rec_x: u32,
    ax_rec_y: u32,
    ax_col_x0s: u32,
    ax_row_y: u32,
    // Light samples (bitmask).
    samples: u32,
    // The occluder grid: tangent half-extents and half texel sizes.
    tx: f32,
    ty: f32,
    hw: f32,
    hh: f32,
    inv_half_lx: f32,
    inv_half_ly: f32,
    half_lx: f32,
    half_ly: f32,
    // Texel width in half-light units.
    wx: f32,
    // Occluder rows per chunk (of a receiver's rows in reach).
    rows_per_chunk: u32,
    // The light samples on the light (bitmask): samples, or a disk's.
    counted: u32,
    // 1 under a disk light (ssm clips its micro-patches to it).
    disk: u32,
}

// Which chunk a dispatch adds. Shared with Rust (`ChunkParams` in gather.rs).
struct ChunkParams {
    layer: u32,
    chunk: u32,
    _pad0: u32,
    _pad1: u32,
}

// One occluder row: its nearest 1/depth and occupied columns [first, last).
// Shared with Rust (`RowSpan` in gather.rs).
struct RowSpan {
    w_max: f32,
    first: u32,
    last: u32,
    _pad: u32,
}

@group(0) @binding(0) var<storage, read> maps: array<u32>;
@group(0) @binding(1) var<storage, read_write> rows: array<RowSpan>;
@group(0) @binding(2) var<storage, read_write> layer_w_max: array<atomic<u32>>;
@group(0) @binding(3) var<uniform> gp: GatherParams;
@group(0) @binding(4) var<storage, read> axes: array<f32>;
@group(0) @binding(5) var<storage, read_write> vis: array<f32>;
// Per-receiver accumulators (the method's layout), zeroed before the chunks.
@group(0) @binding(7) var<storage, read_write> acc: array<u32>;
@group(0) @binding(8) var<uniform> chunk: ChunkParams;

// 1/depth of a map texel, 0 where empty (+inf, or 0 bits: a farthest layer
// never written), as gather.rs's Layer::new.
fn inv_depth(bits: u32) -> f32 {
    let z = bitcast<f32>(bits);
    if z > 0.0 && z < bitcast<f32>(0x7f800000u) {
        return 1.0 / z;
    }
    return 0.0;
}

fn row_coord(y: f32) -> f32 {
    return (1.0 - y / gp.ty) * 0.5 * f32(gp.occ_h) - 0.5;
}

fn col_coord(x: f32) -> f32 {
    return (x / gp.tx + 1.0) * 0.5 * f32(gp.occ_w) - 0.5;
}

// floor/ceil of a texel coordinate clamped to [lo, hi] before the conversion
// (an unbounded float does not convert to i32 portably).
fn clamp_index(c: f32, lo: i32, hi: i32) -> i32 {
    return i32(clamp(c, f32(lo), f32(hi)));
}

// Per occluder row: nearest 1/depth (the method's texel_reach) and occupied
// columns; per layer, the nearest 1/depth of all (atomicMax on the bits of a
// positive float).
@compute @workgroup_size(64)
fn row_stats(@builtin(global_invocation_id) gid: vec3<u32>) {
    let n = gid.x;
    if n >= gp.n_layers * gp.occ_h {
        return;
    }
    let layer = n / gp.occ_h;
    let j = n % gp.occ_h;
    let base = gp.layer0_offset + layer * gp.layer_stride + j * gp.occ_w;
    var span = RowSpan(0.0, 0u, 0u, 0u);
    var found = false;
    for (var i = 0u; i < gp.occ_w; i++) {
        let w = inv_depth(maps[base + i]);
        if w > 0.0 {
            if !found {
                span.first = i;
                found = true;
            }
            span.last = i + 1u;
            span.w_max = max(span.w_max, texel_reach(base + i, w));
        }
    }
    rows[n] = span;
    atomicMax(&layer_w_max[layer], bitcast<u32>(span.w_max));
}

// A receiver texel: its index, tangent position, 1/depth; ok = false where
// there is no receiver.
struct Receiver {
    ok: bool,
    idx: u32,
    xr: f32,
    yr: f32,
    wr: f32,
}

fn receiver(gid: vec3<u32>) -> Receiver {
    var r = Receiver(false, 0u, 0.0, 0.0, 0.0);
    if gid.x >= gp.rec_w || gid.y >= gp.rec_h {
        return r;
    }
    r.idx = gid.y * gp.rec_w + gid.x;
    let zr = bitcast<f32>(maps[r.idx]);
    if !(zr > 0.0 && zr < bitcast<f32>(0x7f800000u)) {
        return r;
    }
    r.ok = true;
    r.wr = 1.0 / zr;
    r.xr = axes[gp.ax_rec_x + gid.x];
    r.yr = axes[gp.ax_rec_y + gid.y];
    return r;
}

// What one occluder row offers a receiver: the columns in reach and the row's
// y-interval relative to the receiver in half-light units, [-nay0, ay1].
struct RowReach {
    ok: bool,
    i_lo: u32,
    i_hi: u32,
    nay0: f32,
    ay1: f32,
}

fn row_reach(layer: u32, j: u32, xr: f32, yr: f32, wr: f32) -> RowReach {
    var r = RowReach(false, 0u, 0u, 0.0, 0.0);
    let span = rows[layer * gp.occ_h + j];
    if span.first >= span.last || span.w_max <= wr {
        return r;
    }
    let dw = span.w_max - wr;
    let yc = axes[gp.ax_row_y + j];
    let dy = max(max(yr - yc, yc - yr), 0.0);
    if dy >= gp.hh + gp.half_ly * dw {
        return r;
    }
    let reach_x = gp.hw + gp.half_lx * dw;
    let w_i = i32(gp.occ_w);
    let i_lo = max(clamp_index(floor(col_coord(xr - reach_x)), -1, w_i), i32(span.first));
    let i_hi = min(clamp_index(ceil(col_coord(xr + reach_x)), -1, w_i) + 1, i32(span.last));
    if i_lo >= i_hi {
        return r;
    }
    r.ok = true;
    r.i_lo = u32(i_lo);
    r.i_hi = u32(i_hi);
    r.nay0 = (yr - (yc - gp.hh)) * gp.inv_half_ly;
    r.ay1 = (yc + gp.hh - yr) * gp.inv_half_ly;
    return r;
}

// The occluder rows of this dispatch's chunk that a receiver at (yr, wr) can
// see in this dispatch's layer: [x, y], empty when x > y. The rows in reach
// are those of gather.rs's add_layer, the chunk a slice of rows_per_chunk.
fn chunk_rows(yr: f32, wr: f32) -> vec2<i32> {
    let w_max = bitcast<f32>(atomicLoad(&layer_w_max[chunk.layer]));
    if w_max <= wr {
        return vec2<i32>(1, 0);
    }
    let reach_y = gp.hh + gp.half_ly * (w_max - wr);
    let last = i32(gp.occ_h) - 1;
    let j_lo = clamp_index(floor(row_coord(yr + reach_y)), 0, last);
    let j_hi = clamp_index(ceil(row_coord(yr - reach_y)), 0, last);
    let start = j_lo + i32(chunk.chunk * gp.rows_per_chunk);
    return vec2<i32>(start, min(j_hi, start + i32(gp.rows_per_chunk) - 1));
}

fn layer_offset(layer: u32) -> u32 {
    return gp.layer0_offset + layer * gp.layer_stride;
}

// Visits, in row order, every texel of this dispatch's chunk of its layer
// that can reach receiver `rc`, and hands each to the method's add_texel
// (defined in the method's file, which adds to its own per-invocation
// state): the twin of gather.rs's add_row loop, whose methods are its
// Accumulators.
fn gather_chunk(rc: Receiver) {
    let xr_s = rc.xr * gp.inv_half_lx;
    let js = chunk_rows(rc.yr, rc.wr);
    let base = layer_offset(chunk.layer);
    for (var j = js.x; j <= js.y; j++) {
        let r = row_reach(chunk.layer, u32(j), rc.xr, rc.yr, rc.wr);
        if !r.ok {
            continue;
        }
        let row = base + u32(j) * gp.occ_w;
        for (var i = r.i_lo; i < r.i_hi; i++) {
            let w = inv_depth(maps[row + i]);
            if w <= rc.wr {
                continue;
            }
            let x0 = axes[gp.ax_col_x0s + i];
            add_texel(row + i, w, x0, x0 + gp.wx, xr_s, r, rc);
        }
    }
}

// ---------------------------------------------------------------------------
// Points mode.

// Shared with Rust (`PointsParams` in gather.rs).
struct PointsParams {
    // Points, a multiple of POINTS_GROUP (the last group padded with inactive lanes).
    n_points: u32,
    // Outward steps (two occluder rows each) of a group's window per chunk,
    // and the chunks per layer (sized on the CPU from a bound on the windows).
    steps_per_chunk: u32,
    chunks: u32,
    // 1 where the points are weighed for the shaded image (`weigh_points`
    // holds one per point), 0 where not (it holds one unread entry).
    weigh: u32,
}

// One lane: tangent (x, y) and 1/depth; live = 0 where there is no receiver.
// Shared with Rust (`GpuPoint` in gather.rs).
struct GatherPoint {
    x: f32,
    y: f32,
    wr: f32,
    live: u32,
}

// A group's bounds over its live lanes (a receiver in front of the light) (gather/group.rs's Group).
// Shared with Rust (`GpuGroup` in gather.rs).
struct GroupBounds {
    x_lo: f32,
    x_hi: f32,
    y_lo: f32,
    y_hi: f32,
    wr_min: f32,
    live: u32,
    _pad0: u32,
    _pad1: u32,
}

const POINTS_GROUP: u32 = 64u;

@group(0) @binding(9) var<uniform> pp: PointsParams;
@group(0) @binding(10) var<storage, read> points: array<GatherPoint>;
@group(0) @binding(11) var<storage, read> point_groups: array<GroupBounds>;
// Raised when a group's window outlasts the last chunk (the CPU's bound was
// too small): an error, never a silently partial sum.
@group(0) @binding(12) var<storage, read_write> points_status: array<atomic<u32>>;

// The weighted visibility's receivers (`WeighPoint`, irradiance_weight.wgsl),
// one per sorted point.
@group(0) @binding(14) var<storage, read> weigh_points: array<WeighPoint>;

fn point_index(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.x + gid.y * groups.x * POINTS_GROUP;
}

fn point_receiver(idx: u32) -> Receiver {
    var r = Receiver(false, idx, 0.0, 0.0, 0.0);
    if idx >= pp.n_points {
        return r;
    }
    let p = points[idx];
    r.ok = p.live != 0u;
    r.xr = p.x;
    r.yr = p.y;
    r.wr = p.wr;
    return r;
}

// f32::round: half-way cases away from zero (WGSL's round goes to even).
fn round_away(x: f32) -> f32 {
    let t = trunc(x);
    if abs(x - t) >= 0.5 {
        return t + sign(x);
    }
    return t;
}

// A group's rows in this dispatch's layer (add_layer): [j_lo, j_hi] and
// the central row j_c the visit starts from; ok = false when none reaches.
struct GroupRows {
    ok: bool,
    j_lo: i32,
    j_hi: i32,
    j_c: i32,
}

fn group_rows(b: GroupBounds) -> GroupRows {
    var r = GroupRows(false, 0, 0, 0);
    let w_max = bitcast<f32>(atomicLoad(&layer_w_max[chunk.layer]));
    if b.live == 0u || w_max <= b.wr_min {
        return r;
    }
    let reach_y = gp.hh + gp.half_ly * (w_max - b.wr_min);
    let last = i32(gp.occ_h) - 1;
    r.ok = true;
    r.j_lo = clamp_index(floor(row_coord(b.y_hi + reach_y)), 0, last);
    r.j_hi = clamp_index(ceil(row_coord(b.y_lo - reach_y)), 0, last);
    r.j_c = clamp_index(round_away(row_coord(0.5 * (b.y_lo + b.y_hi))), r.j_lo, r.j_hi);
    return r;
}

// Occluder row j as the group sees it (add_row): the columns [i_lo, i_hi)
// in reach of the group's bounds and the row's centre yc.
struct GroupRow {
    ok: bool,
    i_lo: u32,
    i_hi: u32,
    yc: f32,
}

fn group_row(j: u32, b: GroupBounds) -> GroupRow {
    var r = GroupRow(false, 0u, 0u, 0.0);
    let span = rows[chunk.layer * gp.occ_h + j];
    if span.first >= span.last || span.w_max <= b.wr_min {
        return r;
    }
    let dw = span.w_max - b.wr_min;
    let yc = axes[gp.ax_row_y + j];
    let dy = max(max(b.y_lo - yc, yc - b.y_hi), 0.0);
    if dy >= gp.hh + gp.half_ly * dw {
        return r;
    }
    let reach_x = gp.hw + gp.half_lx * dw;
    let w_i = i32(gp.occ_w);
    let i_lo = max(clamp_index(floor(col_coord(b.x_lo - reach_x)), -1, w_i), i32(span.first));
    let i_hi = min(clamp_index(ceil(col_coord(b.x_hi + reach_x)), -1, w_i) + 1, i32(span.last));
    if i_lo >= i_hi {
        return r;
    }
    r.ok = true;
    r.i_lo = u32(i_lo);
    r.i_hi = u32(i_hi);
    r.yc = yc;
    return r;
}

// Adds occluder row j of this dispatch's layer to lane `rc` of group `b`.
fn points_row(j: i32, b: GroupBounds, rc: Receiver, xr_s: f32) {
    let g = group_row(u32(j), b);
    if !g.ok {
        return;
    }
    // The lane's own y-interval of the row, in half-light units (RowLanes).
    let r = RowReach(
        true,
        g.i_lo,
        g.i_hi,
        (rc.yr - (g.yc - gp.hh)) * gp.inv_half_ly,
        (g.yc + gp.hh - rc.yr) * gp.inv_half_ly,
    );
    let row = layer_offset(chunk.layer) + u32(j) * gp.occ_w;
    points_begin_row();
    for (var i = g.i_lo; i < g.i_hi; i++) {
        let w = inv_depth(maps[row + i]);
        // Empty, or behind every lane's receiver.
        if w <= b.wr_min {
            continue;
        }
        let x0 = axes[gp.ax_col_x0s + i];
        add_texel(row + i, w, x0, x0 + gp.wx, xr_s, r, rc);
    }
    points_end_row();
}

// Adds this dispatch's chunk of outward steps of the group's window to lane
// `rc`: steps m of [chunk * steps_per_chunk, ...), rows j_c - m then j_c + 1 + m.
fn gather_points_chunk(rc: Receiver) {
    let b = point_groups[rc.idx / POINTS_GROUP];
    let gr = group_rows(b);
    if !gr.ok {
        return;
    }
    let xr_s = rc.xr * gp.inv_half_lx;
    let steps = max(gr.j_c - gr.j_lo + 1, gr.j_hi - gr.j_c);
    let m0 = i32(chunk.chunk * pp.steps_per_chunk);
    let m1 = min(m0 + i32(pp.steps_per_chunk), steps);
    if chunk.chunk + 1u == pp.chunks && m1 < steps {
        atomicOr(&points_status[0], 1u);
    }
    for (var m = m0; m < m1; m++) {
        let up = gr.j_c - m;
        if up >= gr.j_lo {
            points_row(up, b, rc, xr_s);
        }
        let down = gr.j_c + 1 + m;
        if down <= gr.j_hi {
            points_row(down, b, rc, xr_s);
        }
    }
}
