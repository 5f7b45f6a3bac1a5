// Percentage-closer soft shadows on the GPU (Fernando 2005, "Percentage-
// Closer Soft Shadows", SIGGRAPH 2005 Sketches; §1 blocker search, §2
// penumbra estimate, §3 filtering), the twin of src/methods/pcss.rs with its
// box filter from src/methods/pcf.rs. Kernel light space: a receiver at
// continuous pixel coordinates p = (px, py) of the occluder grid and planar
// depth z_r sees the occluders at depth z that hide part of the light in the
// box p ± (L/2)(1/z - 1/z_r) / (texel width), per axis.
//
// 1. z_near, the nearest depth of the front layer (`pcss_near`: a min over
//    the map; the bits of positive floats order as u32, so an atomicMax on
//    INF_BITS - bits keeps it, a cleared 0 meaning no occluder).
// 2. Blocker search over p ± h_s, h_s = (L/2)(1/z_near - 1/z_r): the texels
//    with 0 < d < z_r, each weighted by its overlap with the box; their sum of
//    weights sw and of weight x (d - z_near) (`pcss_search`). No blocker:
//    visibility 1.
// 3. Penumbra: z_avg = z_near + Σ w (d - z_near) / sw; filter box p ± h_f,
//    h_f = (L/2)(1/z_avg - 1/z_r).
// 4. The box filter of the test "not occluded" over it (`pcss_filter`), the
//    box's part outside the map lit (`pcss_resolve` adds it and divides).
//
// Per axis the box is pcf.rs's `Axis`: a half-width below 1/2 texel is raised
// to 1/2; when it overlaps at most m = max_taps texels each is read with its
// exact overlap weight, otherwise its part inside the map is cut into m
// strata, one tap bilinear between its two nearest texels at each centre,
// weight (stratum) / (box width). So an axis has at most m entries, each one
// or two texels.
//
// f32 where the CPU computes in f64; three choices keep the two close:
// * the point's pixel coordinate comes split as an integer texel and an f32
//   fraction (computed in f64 on the CPU), and every box end is relative to
//   that texel: its rounding is relative to the box's half-width, not to the
//   map's size;
// * 1/z_near - 1/z_r is ((z_r - z_near) / z_r) / z_near (no cancellation
//   between two nearly equal reciprocals), and 1/z_avg - 1/z_r likewise with
//   z_r - z_avg = (z_r - z_near) - mean(d - z_near);
// * the depth tests compare the same f32 depths as the CPU (the maps are
//   the CPU's bit for bit; the points' depths are computed on the CPU).
//
// Bounded work: an invocation reads at most rows_per_chunk entries of the
// y axis per dispatch, each with at most m entries along x (m <= 256), so
// rows_per_chunk (m + 2) stays within half of lavapipe's 65535 loop
// iterations per invocation; the y entries beyond one chunk take more
// dispatches, each adding into the point's accumulators in `acc`.
//
// Under a disk light (pp.disk, pcf_disk.rs) both boxes are the ellipses
// inscribed in them: the same cells, each weighted by its overlap with the
// ellipse over the ellipse's area (disk_overlap.wgsl, in the coordinates
// where the ellipse is the unit disk) times the share each of its texels
// reads (1 for a texel's part, 1 - t and t for a tap); the ellipse's part
// outside the map (1 - its overlap with the map) is lit.
//
// Weighted (pp.weigh, points mode under an area light; methods/
// pcss_weighted.rs): the filter also sums, per cell that reads a shadowed
// texel, its weight times the irradiance weight of the light point the
// cell stands for (u Lx/2, -v Ly/2), (u, v) the cell centre's offset from
// the point over the half-widths (irradiance_weight.wgsl); the resolve
// writes vis[n + idx] = 1 - min(H / mean weight, 1), H that sum over the
// filter's weights and part off the map, where 0 < V < 1.
//
// Two modes, one kernel: map mode (mode 0), one invocation per output texel,
// its coordinates from per-column and per-row tables and its depth from the
// receiver map; points mode (mode 1, the eye view), one invocation per
// light-space point uploaded by the CPU.

// Shared with Rust (`PcssParams` in pcss.rs; a test compares layouts).
struct PcssParams {
    // Invocations: output texels (map mode) or points.
    n: u32,
    mode: u32,
    // Map mode: output texels per row, and the receiver map in `maps`.
    out_w: u32,
    rec_offset: u32,
    // The occluder grid and its front layer in `maps`.
    occ_w: u32,
    occ_h: u32,
    front_offset: u32,
    front_len: u32,
    // Taps per axis, m (clamped to 1..=MAX_TAPS on the CPU).
    taps: u32,
    // y entries per dispatch of the search and of the filter.
    rows_per_chunk: u32,
    // (L/2) per axis divided by the texel's tangent width.
    half_per_w_x: f32,
    half_per_w_y: f32,
    // 1 under a disk light: the boxes' inscribed ellipses.
    disk: u32,
    // 1: the weighted visibility too (points mode; `weigh_points`).
    weigh: u32,
    // The light's half-extents (kernel units), for the weights.
    half_lx: f32,
    half_ly: f32,
}

// Which chunk of y entries a dispatch reads. Shared with Rust (`PcssChunk`).
struct PcssChunk {
    chunk: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// A continuous pixel coordinate as base + frac (base an integer texel).
// Shared with Rust (`Coord`).
struct Coord {
    base: i32,
    frac: f32,
}

// A point of points mode: pixel coordinates on the occluder grid, planar
// depth, whether it is shaded at all (0: lit), and its tangent plane
// (∂(1/z)/∂px, ∂(1/z)/∂py; pcss.rs's `Plane`). Shared with Rust
// (`GpuPcssPoint`).
struct PcssPoint {
    bx: i32,
    fx: f32,
    by: i32,
    fy: f32,
    z: f32,
    live: u32,
    pa: f32,
    pb: f32,
}

@group(0) @binding(0) var<storage, read> maps: array<u32>;
@group(0) @binding(1) var<uniform> pp: PcssParams;
// Map mode: the output columns' x (out_w entries), then the rows' y.
@group(0) @binding(2) var<storage, read> coords: array<Coord>;
@group(0) @binding(3) var<storage, read> points: array<PcssPoint>;
// INF_BITS - bits(z_near), 0 (cleared) when the map holds no occluder.
@group(0) @binding(4) var<storage, read_write> near: array<atomic<u32>>;
// Per point: (sw, Σ w (d - z_near), filter Σ w test, filter Σ w), zeroed;
// weighing, then per point (filter Σ w (1 - test) irradiance weight, 0, 0, 0).
@group(0) @binding(5) var<storage, read_write> acc: array<vec4<f32>>;
// Per point its visibility; weighing, then per point its weighted one.
@group(0) @binding(6) var<storage, read_write> vis: array<f32>;
@group(0) @binding(7) var<uniform> chunk: PcssChunk;
// Weighing: per point its receiver (one unread entry otherwise).
@group(0) @binding(8) var<storage, read> weigh_points: array<WeighPoint>;

const INF_BITS: u32 = 0x7f800000u;
// pcf.rs's MAX_HALF: the largest half-width the weights are computed with.
const MAX_HALF: f32 = 1e30;
// Front texels one invocation of pcss_near reads (NEAR_SPAN in pcss.rs).
const NEAR_SPAN: u32 = 256u;

fn linear(gid: vec3<u32>, groups: vec3<u32>) -> u32 {
    return gid.x + gid.y * groups.x * 64u;
}

var<workgroup> wg_near: atomic<u32>;

// The front layer's nearest occluder depth (pcss.rs's nearest_depth).
@compute @workgroup_size(64)
fn pcss_near(@builtin(global_invocation_id) gid: vec3<u32>,
             @builtin(local_invocation_id) lid: vec3<u32>,
             @builtin(num_workgroups) groups: vec3<u32>) {
    let start = linear(gid, groups) * NEAR_SPAN;
    var best = 0u;
    for (var k = 0u; k < NEAR_SPAN; k++) {
        let t = start + k;
        if t >= pp.front_len {
            break;
        }
        let d = bitcast<f32>(maps[pp.front_offset + t]);
        if d > 0.0 && d < bitcast<f32>(INF_BITS) {
            best = max(best, INF_BITS - bitcast<u32>(d));
        }
    }
    atomicMax(&wg_near, best);
    workgroupBarrier();
    if lid.x == 0u {
        atomicMax(&near[0], atomicLoad(&wg_near));
    }
}

fn nearest() -> f32 {
    return bitcast<f32>(INF_BITS - atomicLoad(&near[0]));
}

// A point to shade: `ok` false where pcss.rs's visibility returns 1 before
// any search (z not in (0, inf), or no occluder nearer than it).
struct Pt {
    ok: bool,
    bx: i32,
    fx: f32,
    by: i32,
    fy: f32,
    z: f32,
    pa: f32,
    pb: f32,
}

fn point(idx: u32, z_near: f32) -> Pt {
    var p: Pt;
    if pp.mode == 0u {
        let cx = coords[idx % pp.out_w];
        let cy = coords[pp.out_w + idx / pp.out_w];
        p = Pt(true, cx.base, cx.frac, cy.base, cy.frac, bitcast<f32>(maps[pp.rec_offset + idx]), 0.0, 0.0);
    } else {
        let q = points[idx];
        p = Pt(q.live != 0u, q.bx, q.fx, q.by, q.fy, q.z, q.pa, q.pb);
    }
    p.ok = p.ok && p.z > 0.0 && p.z < bitcast<f32>(INF_BITS) && z_near < p.z;
    return p;
}

// One axis of the box [p - h, p + h] over n texels (pcf.rs's Axis::new),
// p = base + frac; `a`, `b` (the box clipped to the map) relative to base.
struct Axis {
    base: i32,
    n: i32,
    // The centre (relative to base) and the half-width after the raise.
    frac: f32,
    h: f32,
    a: f32,
    b: f32,
    inv_full: f32,
    // Exact mode: texels i0 .. i0 + count - 1. Stratified: `count` taps.
    i0: i32,
    count: u32,
    stratified: bool,
    step: f32,
    wt: f32,
    // The fraction of the box outside the map.
    outside: f32,
}

fn make_axis(base: i32, frac: f32, h_in: f32, n_texels: u32) -> Axis {
    var h = 0.5;
    if h_in >= 0.5 {
        h = min(h_in, MAX_HALF);
    }
    var ax: Axis;
    ax.base = base;
    ax.n = i32(n_texels);
    ax.frac = frac;
    ax.h = h;
    ax.inv_full = 0.5 / h;
    let lo = frac - h;
    let hi = frac + h;
    // The map's ends relative to base (exact: |base| <= 2^24).
    let lo_edge = f32(-base);
    let hi_edge = f32(ax.n - base);
    let left = clamp(lo_edge - lo, 0.0, 2.0 * h) * ax.inv_full;
    let right = clamp(hi - hi_edge, 0.0, 2.0 * h) * ax.inv_full;
    ax.outside = min(left + right, 1.0);
    ax.a = max(lo, lo_edge);
    ax.b = min(hi, hi_edge);
    ax.count = 0u;
    ax.stratified = false;
    if !(ax.a < ax.b) {
        return ax;
    }
    ax.i0 = min(base + i32(floor(ax.a)), ax.n - 1);
    let i1 = min(max(base + i32(ceil(ax.b)), 1) - 1, ax.n - 1);
    if i1 - ax.i0 >= i32(pp.taps) {
        ax.stratified = true;
        ax.count = pp.taps;
        ax.step = (ax.b - ax.a) / f32(pp.taps);
        ax.wt = ax.step * ax.inv_full;
    } else {
        ax.count = u32(i1 - ax.i0 + 1);
    }
    return ax;
}

// Entry k of an axis: texel i with weight w0 and texel i + 1 with w1 (0
// where the texel is outside the map, or in exact mode), as Axis::for_each;
// its cell [c0, c1] (relative to base). Under a disk the weights are the
// shares the cell's texels read (Axis::cells), the cell's own weight its
// overlap with the ellipse (`cell_weight`).
struct Entry {
    i: i32,
    w0: f32,
    w1: f32,
    c0: f32,
    c1: f32,
}

fn entry(ax: Axis, k: u32) -> Entry {
    let disk = pp.disk != 0u;
    if !ax.stratified {
        let i = ax.i0 + i32(k);
        let x0 = max(f32(i - ax.base), ax.a);
        let x1 = min(f32(i + 1 - ax.base), ax.b);
        let w = select(max((x1 - x0) * ax.inv_full, 0.0), select(0.0, 1.0, x1 > x0), disk);
        return Entry(i, w, 0.0, x0, x1);
    }
    // The tap's one-texel box [q, q + 1] overlaps texels floor(q) and the
    // next by 1 - t and t.
    let c0 = ax.a + f32(k) * ax.step;
    let q = ax.a + (f32(k) + 0.5) * ax.step - 0.5;
    let fi = floor(q);
    let t = q - fi;
    let i = ax.base + i32(fi);
    let wt = select(ax.wt, 1.0, disk);
    var e = Entry(i, wt * (1.0 - t), wt * t, c0, c0 + ax.step);
    if i < 0 || i >= ax.n {
        e.w0 = 0.0;
    }
    if i + 1 < 0 || i + 1 >= ax.n {
        e.w1 = 0.0;
    }
    return e;
}

fn front(i: i32, j: i32) -> f32 {
    return bitcast<f32>(maps[pp.front_offset + u32(j) * pp.occ_w + u32(i)]);
}

// The search box's axes: p ± (L/2)(1/z_near - 1/z_r).
fn search_axes(p: Pt, z_near: f32) -> array<Axis, 2> {
    let d = ((p.z - z_near) / p.z) / z_near;
    return array<Axis, 2>(
        make_axis(p.bx, p.fx, pp.half_per_w_x * d, pp.occ_w),
        make_axis(p.by, p.fy, pp.half_per_w_y * d, pp.occ_h),
    );
}

// The filter box's axes: p ± (L/2)(1/z_avg - 1/z_r), z_avg from the
// search's sums s = (sw, Σ w (d - z_near)).
fn filter_axes(p: Pt, z_near: f32, s: vec4<f32>) -> array<Axis, 2> {
    let dev = s.y / s.x;
    let z_avg = z_near + dev;
    let d = (((p.z - z_near) - dev) / p.z) / z_avg;
    return array<Axis, 2>(
        make_axis(p.bx, p.fx, pp.half_per_w_x * d, pp.occ_w),
        make_axis(p.by, p.fy, pp.half_per_w_y * d, pp.occ_h),
    );
}

// This dispatch's y entries of the box, every x entry, into `sum`:
// blockers (search) or the lit test's weights (filter). Two-level, as f32
// sums of up to 2m x 2m terms need: each y entry's terms in `row`, then the
// row into `sum` (the CPU sums in f64; measured with 256 taps over 640²
// boxes, a one-level f32 sum was 2e-4 off, the two-level one ~1e-6).
// (The filter's third component: the weighted shadowed sum.)
var<private> sum: vec3<f32>;
var<private> row: vec3<f32>;
// The filter's weighing receiver, where pp.weigh.
var<private> weigh_point: WeighPoint;

// pcss.rs's `plane_depth`: the depth of the point's tangent plane at
// texel (i, j), the same f32 operations; z itself for a plane of (0, 0).
fn plane_z(p: Pt, i: i32, j: i32) -> f32 {
    if p.pa == 0.0 && p.pb == 0.0 {
        return p.z;
    }
    let ox = (f32(i - p.bx) + 0.5) - p.fx;
    let oy = (f32(j - p.by) + 0.5) - p.fy;
    let den = 1.0 + p.z * (p.pa * ox + p.pb * oy);
    if den > 0.0 {
        return p.z / den;
    }
    return bitcast<f32>(INF_BITS);
}

// `lw`: the irradiance weight of the cell's light point (0 unweighed).
fn add(i: i32, j: i32, w: f32, lw: f32, p: Pt, z_near: f32, search: bool) {
    let d = front(i, j);
    let occludes = d > 0.0 && d < plane_z(p, i, j);
    if search {
        if occludes {
            row += vec3<f32>(w, w * (d - z_near), 0.0);
        }
    } else {
        row += vec3<f32>(select(w, 0.0, occludes), w, select(0.0, w * lw, occludes));
    }
}

// The irradiance weight of the light point cell (ex, ey) stands for
// (pcss_weighted.rs): 0 in the search or unweighed.
fn light_point_weight(ax: Axis, ay: Axis, ex: Entry, ey: Entry, search: bool) -> f32 {
    if search || pp.weigh == 0u {
        return 0.0;
    }
    let u = (0.5 * (ex.c0 + ex.c1) - ax.frac) / ax.h;
    let v = (0.5 * (ey.c0 + ey.c1) - ay.frac) / ay.h;
    return irradiance_weight(weigh_point, u * pp.half_lx, -v * pp.half_ly);
}

// The cell (ex, ey)'s weight: 1 for the box (its entries' weights are the
// cell's), under a disk its overlap with the ellipse over the ellipse's
// area, the ellipse the unit disk in ((x - frac) / h, (y - frac) / h)
// (pcf_disk.rs's visit).
fn cell_weight(ax: Axis, ay: Axis, ex: Entry, ey: Entry) -> f32 {
    if pp.disk == 0u {
        return 1.0;
    }
    let u0 = (ex.c0 - ax.frac) / ax.h;
    let u1 = (ex.c1 - ax.frac) / ax.h;
    let v0 = (ey.c0 - ay.frac) / ay.h;
    let v1 = (ey.c1 - ay.frac) / ay.h;
    return disk_overlap(1.0, u0, u1, v0, v1) / PI_F32;
}

fn visit(ax: Axis, ay: Axis, p: Pt, z_near: f32, search: bool) {
    let k0 = chunk.chunk * pp.rows_per_chunk;
    let k1 = min(k0 + pp.rows_per_chunk, ay.count);
    for (var ky = k0; ky < k1; ky++) {
        let ey = entry(ay, ky);
        row = vec3<f32>(0.0);
        for (var kx = 0u; kx < ax.count; kx++) {
            let ex = entry(ax, kx);
            let c = cell_weight(ax, ay, ex, ey);
            if !(c > 0.0) {
                continue;
            }
            let lw = light_point_weight(ax, ay, ex, ey, search);
            if ey.w0 > 0.0 {
                if ex.w0 > 0.0 {
                    add(ex.i, ey.i, c * ey.w0 * ex.w0, lw, p, z_near, search);
                }
                if ex.w1 > 0.0 {
                    add(ex.i + 1, ey.i, c * ey.w0 * ex.w1, lw, p, z_near, search);
                }
            }
            if ey.w1 > 0.0 {
                if ex.w0 > 0.0 {
                    add(ex.i, ey.i + 1, c * ey.w1 * ex.w0, lw, p, z_near, search);
                }
                if ex.w1 > 0.0 {
                    add(ex.i + 1, ey.i + 1, c * ey.w1 * ex.w1, lw, p, z_near, search);
                }
            }
        }
        sum += row;
    }
}

// The blocker search, one chunk of the box's rows.
@compute @workgroup_size(64)
fn pcss_search(@builtin(global_invocation_id) gid: vec3<u32>,
               @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = linear(gid, groups);
    if idx >= pp.n {
        return;
    }
    let z_near = nearest();
    let p = point(idx, z_near);
    if !p.ok {
        return;
    }
    let axes = search_axes(p, z_near);
    if chunk.chunk * pp.rows_per_chunk >= axes[1].count || axes[0].count == 0u {
        return;
    }
    var s = acc[idx];
    sum = vec3<f32>(s.xy, 0.0);
    visit(axes[0], axes[1], p, z_near, true);
    s = vec4<f32>(sum.xy, s.zw);
    acc[idx] = s;
}

// The filter, one chunk of the box's rows (after every search chunk).
@compute @workgroup_size(64)
fn pcss_filter(@builtin(global_invocation_id) gid: vec3<u32>,
               @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = linear(gid, groups);
    if idx >= pp.n {
        return;
    }
    let z_near = nearest();
    let p = point(idx, z_near);
    if !p.ok {
        return;
    }
    var s = acc[idx];
    if !(s.x > 0.0) {
        return;
    }
    let axes = filter_axes(p, z_near, s);
    if chunk.chunk * pp.rows_per_chunk >= axes[1].count || axes[0].count == 0u {
        return;
    }
    var hidden = 0.0;
    if pp.weigh != 0u {
        weigh_point = weigh_points[idx];
        hidden = acc[pp.n + idx].x;
    }
    sum = vec3<f32>(s.zw, hidden);
    visit(axes[0], axes[1], p, z_near, false);
    s = vec4<f32>(s.xy, sum.xy);
    acc[idx] = s;
    if pp.weigh != 0u {
        acc[pp.n + idx] = vec4<f32>(sum.z, 0.0, 0.0, 0.0);
    }
}

// The filter's part outside the map: the box's, from its ends per axis;
// under a disk the ellipse's, 1 - its overlap with the map (0 when its box
// is inside, 1 when the box is off the map; pcf_disk.rs's outside).
fn outside(ax: Axis, ay: Axis) -> f32 {
    let ox = ax.outside;
    let oy = ay.outside;
    if pp.disk == 0u {
        return clamp(ox + oy - ox * oy, 0.0, 1.0);
    }
    if ox == 0.0 && oy == 0.0 {
        return 0.0;
    }
    if ox >= 1.0 || oy >= 1.0 {
        return 1.0;
    }
    let u0 = (f32(-ax.base) - ax.frac) / ax.h;
    let u1 = (f32(ax.n - ax.base) - ax.frac) / ax.h;
    let v0 = (f32(-ay.base) - ay.frac) / ay.h;
    let v1 = (f32(ay.n - ay.base) - ay.frac) / ay.h;
    return clamp(1.0 - disk_overlap(1.0, u0, u1, v0, v1) / PI_F32, 0.0, 1.0);
}

// The visibility: 1 without blockers; else the filter's weighted mean with
// the box's part outside the map lit (pcf.rs's box_filter, Constant(1)).
@compute @workgroup_size(64)
fn pcss_resolve(@builtin(global_invocation_id) gid: vec3<u32>,
                @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = linear(gid, groups);
    if idx >= pp.n {
        return;
    }
    let z_near = nearest();
    let p = point(idx, z_near);
    let s = acc[idx];
    var v = 1.0;
    var den = 0.0;
    if p.ok && s.x > 0.0 {
        let axes = filter_axes(p, z_near, s);
        let out = outside(axes[0], axes[1]);
        den = s.w + out;
        if den > 0.0 {
            v = clamp((s.z + out) / den, 0.0, 1.0);
        }
    }
    vis[idx] = v;
    if pp.weigh != 0u {
        vis[pp.n + idx] = weighted(idx, v, den);
    }
}

// pcss_weighted.rs's weighted_visibility from the filter's sums: V where
// it is 0 or 1 or the point has no receiver; 0 where the whole light is
// behind its tangent plane.
fn weighted(idx: u32, v: f32, den: f32) -> f32 {
    let wp = weigh_points[idx];
    if !(v > 0.0 && v < 1.0) || wp.valid == 0u {
        return v;
    }
    let mean = 0.25 * light_weight(wp, vec2<f32>(pp.half_lx, pp.half_ly), pp.disk != 0u);
    if !(mean > 0.0) {
        return 0.0;
    }
    return 1.0 - clamp(acc[pp.n + idx].x / den / mean, 0.0, 1.0);
}
