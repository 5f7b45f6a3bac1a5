// Smoothies (Chan & Durand 2003, §3 steps 4-5, §3.1, Fig. 11 passes 2-4) on
// the GPU: the smoothie buffer and the lookup. Twins: src/methods/smoothies/
// buffer.rs (step 4) and lookup.rs (step 5). The silhouette and the smoothies
// themselves (steps 2-3) are built on the CPU in f64 (construct.rs) and
// uploaded as `Smoothie`s in the image plane q = (x / Lu, y / Lv).
//
// Step 4, one invocation per shadow-map texel k (centre q, shadow-map depth
// r = smap[k]) over the smoothies binned to its 8x8 tile (binned on the CPU
// from each smoothie's hull): a smoothie covering q with linear alpha a and
// depth b is kept when 0 < b < r (else it lies behind a blocker: the Cg's
// f = b/r > 1), its alpha remapped to a' = clamp(a / (1 - b/r), 0, 1) (a
// itself where r = inf), at least the smallest normal f32; min blending keeps
// the smallest a' with its depth b, the nearer b on equal a' (buffer.rs's
// rule; a lexicographic minimum, so the order of the smoothies does not
// matter), and a' = 1 writes nothing. lavapipe stops an invocation after
// 65535 loop iterations: a dispatch reads at most `per_chunk` smoothies of a
// tile, and a tile with more takes several dispatches (`chunk`), each
// resuming from the texel's buffer.
//
// Step 5, per receiver (an output texel or an eye-view point): the 2x2 tent
// over v_k = 0 (z > smap[k]: umbra), alpha[k] (z > depth[k]: penumbra), else
// 1, then the falloff. The tent's texels and weights (the map's edge texels
// repeated beyond its border) are computed on the CPU in f64, per column and
// row of the output grid or per point, as lookup.rs computes them.

// Shared with Rust (`SmoothieParams` in smoothies.rs; a test compares layouts).
struct SmoothieParams {
    // The shadow map's grid.
    occ_w: u32,
    occ_h: u32,
    // The output grid (light view), or the number of points (eye view: rec_w).
    rec_w: u32,
    rec_h: u32,
    // The receiver map in `maps` (texels), NONE for none.
    rec_offset: u32,
    // The front occluder layer in `maps`.
    front_offset: u32,
    // 1: the shadow map is the nearer of front and receiver (the same grid).
    merge: u32,
    // 8x8 tiles per row of the shadow map.
    tiles_x: u32,
    // The smoothies' width in q units.
    t: f32,
    // 0 linear, 1 sine (`Falloff`).
    falloff: u32,
    // Smoothies a dispatch reads of one tile.
    per_chunk: u32,
    _pad: u32,
}

// Shared with Rust (`SmoothieChunk`): which smoothies of each tile this
// dispatch reads.
struct SmoothieChunk {
    chunk: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// One smoothie (construct.rs's `Shape`), shared with Rust (`GpuSmoothie`):
// EDGE: p = p0, a = d, b = n, len, z0/z1 = 1/depth at p0 and p1;
// CORNER: p = v, a = dA, b = dB, z0 = depth; FAN: p = v, a = o, b = m, z0 = depth.
struct Smoothie {
    kind: u32,
    len: f32,
    z0: f32,
    z1: f32,
    px: f32,
    py: f32,
    ax: f32,
    ay: f32,
    bx: f32,
    by: f32,
    _pad0: u32,
    _pad1: u32,
}

// The tent along one axis: the two texels and the weight of the second.
// Shared with Rust (`TentAxis`).
struct TentAxis {
    a: u32,
    b: u32,
    w: f32,
    _pad: u32,
}

// An eye-view point's tent and the receiver's depth at its four taps (on
// the point's tangent plane: lookup.rs's tent_depths); live 0: nothing to
// shade (v = 1). Shared with Rust (`TentPoint`).
struct TentPoint {
    ia: u32,
    ib: u32,
    ja: u32,
    jb: u32,
    wx: f32,
    wy: f32,
    z_aa: f32,
    z_ba: f32,
    z_ab: f32,
    z_bb: f32,
    live: u32,
}

const NONE: u32 = 0xffffffffu;
const EDGE: u32 = 0u;
const CORNER: u32 = 1u;
const TILE: u32 = 8u;
const GROUP: u32 = 64u;
const PI: f32 = 3.14159265358979;

@group(0) @binding(0) var<storage, read> maps: array<f32>;
@group(0) @binding(1) var<storage, read_write> smap: array<f32>;
@group(0) @binding(2) var<uniform> params: SmoothieParams;
@group(0) @binding(3) var<storage, read> smoothies: array<Smoothie>;
// Tile b's smoothies are tile_items[tile_start[b] .. tile_start[b + 1]].
@group(0) @binding(4) var<storage, read> tile_start: array<u32>;
@group(0) @binding(5) var<storage, read> tile_items: array<u32>;
// q of the shadow map's columns (occ_w), then of its rows (occ_h).
@group(0) @binding(6) var<storage, read> q_axes: array<f32>;
@group(0) @binding(7) var<storage, read_write> alpha: array<f32>;
@group(0) @binding(8) var<storage, read_write> depth: array<f32>;
// [0]: smoothie texels rasterized and not discarded (SmoothieStats::texels).
@group(0) @binding(9) var<storage, read_write> counters: array<atomic<u32>>;
@group(0) @binding(10) var<uniform> chunk: SmoothieChunk;
// The tent per output column (rec_w), then per output row (rec_h).
@group(0) @binding(11) var<storage, read> tent_axes: array<TentAxis>;
@group(0) @binding(12) var<storage, read> points: array<TentPoint>;
@group(0) @binding(13) var<storage, read_write> vis: array<f32>;

fn inf() -> f32 {
    return bitcast<f32>(0x7f800000u);
}

fn cross2(a: vec2<f32>, b: vec2<f32>) -> f32 {
    return a.x * b.y - a.y * b.x;
}

// Shape::sample: (linear alpha, depth) of smoothie s at q; alpha -1 outside
// (or where alpha would be 1).
fn sample(s: Smoothie, q: vec2<f32>, t: f32) -> vec2<f32> {
    let outside = vec2<f32>(-1.0, 0.0);
    let p = vec2<f32>(s.px, s.py);
    let a = vec2<f32>(s.ax, s.ay);
    let b = vec2<f32>(s.bx, s.by);
    let w = q - p;
    if s.kind == EDGE {
        let sp = dot(w, a) / s.len;
        let h = dot(w, b);
        if !(sp >= 0.0 && sp <= 1.0 && h > 0.0 && h < t) {
            return outside;
        }
        return vec2<f32>(h / t, 1.0 / ((1.0 - sp) * s.z0 + sp * s.z1));
    }
    if s.kind == CORNER {
        if !(dot(w, a) > 0.0 && dot(w, b) < 0.0) {
            return outside;
        }
        let r = length(w);
        if !(r < t) {
            return outside;
        }
        return vec2<f32>(r / t, s.z0);
    }
    // FAN: the triangle (v, o, m), either orientation.
    let r = length(w);
    if !(r > 0.0 && r < t) {
        return outside;
    }
    let c0 = cross2(a - p, q - p);
    let c1 = cross2(b - a, q - a);
    let c2 = cross2(p - b, q - b);
    let inside = (c0 >= 0.0 && c1 >= 0.0 && c2 >= 0.0) || (c0 <= 0.0 && c1 <= 0.0 && c2 <= 0.0);
    if !inside {
        return outside;
    }
    return vec2<f32>(r / t, s.z0);
}

// Step 1: the paper's shadow map on the shadow map's grid (mod.rs's
// `shadow_map`: the nearer of front and receiver where they share a grid).
@compute @workgroup_size(8, 8)
fn smoothie_map(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.occ_w || gid.y >= params.occ_h {
        return;
    }
    let k = gid.y * params.occ_w + gid.x;
    var f = maps[params.front_offset + k];
    if params.merge != 0u {
        let r = maps[params.rec_offset + k];
        if r < f {
            f = r;
        }
    }
    smap[k] = f;
}

// Step 4: one chunk of the smoothies of each tile into the smoothie buffer.
// One workgroup per tile, one invocation per texel.
@compute @workgroup_size(8, 8)
fn smoothie_buffer(@builtin(global_invocation_id) gid: vec3<u32>,
                   @builtin(workgroup_id) wid: vec3<u32>) {
    let i = gid.x;
    let j = gid.y;
    if i >= params.occ_w || j >= params.occ_h {
        return;
    }
    let k = j * params.occ_w + i;
    var best_a = 1.0;
    var best_b = inf();
    if chunk.chunk > 0u {
        best_a = alpha[k];
        best_b = depth[k];
    }
    let tile = wid.y * params.tiles_x + wid.x;
    let start = tile_start[tile];
    let stop = tile_start[tile + 1u];
    let skip = chunk.chunk * params.per_chunk;
    var first = stop;
    if skip < stop - start {
        first = start + skip;
    }
    let last = first + min(params.per_chunk, stop - first);
    let q = vec2<f32>(q_axes[i], q_axes[params.occ_w + j]);
    let r = smap[k];
    let r_finite = r < inf();
    var texels = 0u;
    for (var e = first; e < last; e++) {
        let ab = sample(smoothies[tile_items[e]], q, params.t);
        let b = ab.y;
        if !(ab.x >= 0.0 && b > 0.0 && b < r) {
            continue; // outside, or behind (or on) a blocker: discarded
        }
        texels += 1u;
        var a = ab.x;
        if r_finite {
            a = a / (1.0 - b / r);
        }
        // > 0 inside a smoothie, so that v = 0 only in the umbra.
        a = max(clamp(a, 0.0, 1.0), 1.17549435e-38);
        if a < 1.0 && (a < best_a || (a == best_a && b < best_b)) {
            best_a = a;
            best_b = b;
        }
    }
    alpha[k] = best_a;
    depth[k] = best_b;
    if texels > 0u {
        atomicAdd(&counters[0], texels);
    }
}

// lookup.rs's tap at shadow-map texel k for a receiver at depth z.
fn tap(k: u32, z: f32) -> f32 {
    if z > smap[k] {
        return 0.0;
    }
    if z > depth[k] {
        return alpha[k];
    }
    return 1.0;
}

// Falloff::apply.
fn falloff(v: f32) -> f32 {
    let c = clamp(v, 0.0, 1.0);
    if params.falloff == 0u || c <= 0.0 || c >= 1.0 {
        return c;
    }
    return (1.0 - cos(PI * c)) * 0.5;
}

// lookup.rs's at_point given its texels, weights and the receiver's depth
// at each tap (z: (a, a), (b, a), (a, b), (b, b)); the point shadable.
fn tent(ia: u32, ib: u32, ja: u32, jb: u32, wx: f32, wy: f32, z: vec4<f32>) -> f32 {
    let ra = ja * params.occ_w;
    let rb = jb * params.occ_w;
    let top = tap(ra + ia, z.x) * (1.0 - wx) + tap(ra + ib, z.y) * wx;
    let bottom = tap(rb + ia, z.z) * (1.0 - wx) + tap(rb + ib, z.w) * wx;
    return falloff(top * (1.0 - wy) + bottom * wy);
}

fn shadable(z: f32) -> bool {
    return z > 0.0 && z < inf();
}

// Step 5 in the light view: one invocation per output texel, its receiver
// depth from the receiver map.
@compute @workgroup_size(8, 8)
fn smoothie_lookup_map(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= params.rec_w || gid.y >= params.rec_h {
        return;
    }
    let k = gid.y * params.rec_w + gid.x;
    let z = maps[params.rec_offset + k];
    var v = 1.0;
    if shadable(z) {
        let cx = tent_axes[gid.x];
        let cy = tent_axes[params.rec_w + gid.y];
        v = tent(cx.a, cx.b, cy.a, cy.b, cx.w, cy.w, vec4<f32>(z));
    }
    vis[k] = v;
}

// Step 5 at points (the eye view): one invocation per point.
@compute @workgroup_size(64)
fn smoothie_lookup_points(@builtin(global_invocation_id) gid: vec3<u32>,
                          @builtin(num_workgroups) groups: vec3<u32>) {
    let n = gid.x + gid.y * groups.x * GROUP;
    if n >= params.rec_w {
        return;
    }
    let p = points[n];
    var v = 1.0;
    // Live points are shadable (point_tents).
    if p.live != 0u {
        v = tent(p.ia, p.ib, p.ja, p.jb, p.wx, p.wy, vec4<f32>(p.z_aa, p.z_ba, p.z_ab, p.z_bb));
    }
    vis[n] = v;
}
