// ShadowMapping (Scherzer 2005) on the GPU, the twin of
// src/methods/shadow_mapping/{raster.rs, lookup.rs, blur.rs}; placed after
// u64.wgsl (64-bit integer helpers).
//
// sm_raster (Williams 1978's depth map, Scherzer §4.2's offsets baked into
// the set-up triangles): one invocation per texel, one workgroup per 16x16
// tile, over the triangles binned to that tile on the CPU, a chunk of at
// most `chunk_len` of them per dispatch (lavapipe stops an invocation after
// 65535 loop iterations): the chunks of a tile run in successive
// dispatches, each reading and writing the texel's two layers, so no
// atomics are needed and the second-nearest layer (Woo's midpoint) is kept
// as the CPU keeps it. Coverage: exact 64-bit edge functions of the snapped
// vertices with the CPU's tie rule; depth: the CPU's f32 limb planes in the
// same order (`SetupTri::depth`).
//
// sm_lookup (the depth test, Williams; PCF, Reeves et al. 1987): per point,
// its texel (nearest) or the (size+1)^2 texels of its box, weights
// (1 - f), 1, ..., 1, f per axis, projected on the CPU in f64; each box
// texel tested at the receiver's tangent plane there (receiver plane depth
// bias, lookup.rs).
//
// sm_blur (Scherzer §4.3): one iteration of the depth-dependent 3x3
// [1 2 1]^2 blur per dispatch, ping-pong between two images; the spacing
// and the depth tolerance per pixel come from the CPU (blur.rs's f64
// rounding, and the largest f32 not above its f64 tolerance, so that the
// f32 comparison here decides as the CPU's f64 one).

// Shared with Rust (`SmParams` in shadow_mapping.rs; a test compares layouts).
struct SmParams {
    width: u32,
    height: u32,
    tiles_x: u32,
    linear: u32,
    two_layers: u32,
    _pad0: u32,
    chunk_start: u32,
    chunk_len: u32,
    work_offset: u32,
    work_count: u32,
    midpoint: u32,
    pcf: u32,
    n_points: u32,
    img_w: u32,
    img_h: u32,
    // +inf's bits (not a WGSL constant: naga refuses non-finite ones).
    inf_bits: u32,
}

// Shared with Rust (`GpuSmTri`): `SetupTri` with its three planes as
// (w_ref, gx[3], gy[3]) each, then zh_offset, slope, constant, lw_a, lw_b,
// iw_a, iw_b.
struct SmTri {
    x: array<i32, 3>,
    y: array<i32, 3>,
    i0: u32,
    i1: u32,
    j0: u32,
    j1: u32,
    planes: array<f32, 21>,
    k: array<f32, 7>,
}

// Shared with Rust (`GpuSmPoint`): the pixel to write, the first texel of
// the box (or the nearest texel) and the fractions, the depth tested, and
// for PCF the receiver's depth gradient per texel and the box's first
// texel's offsets from the point (lookup.rs's `TapPlane`).
struct SmPoint {
    pixel: u32,
    i: i32,
    j: i32,
    fx: f32,
    fy: f32,
    depth: f32,
    gx: f32,
    gy: f32,
    ox: f32,
    oy: f32,
}

// Shared with Rust (`GpuBlurPixel`).
struct BlurPixel {
    spacing: i32,
    z: f32,
    tol: f32,
    // 1 where the pixel sees a surface (z finite).
    surface: u32,
}

const TILE: u32 = 16u;
const SUB: i32 = 256;

@group(0) @binding(0) var<storage, read> tris: array<SmTri>;
@group(0) @binding(1) var<storage, read> bin_start: array<u32>;
@group(0) @binding(2) var<storage, read> bin_list: array<u32>;
@group(0) @binding(3) var<storage, read> work: array<u32>;
@group(0) @binding(4) var<storage, read_write> near: array<f32>;
@group(0) @binding(5) var<storage, read_write> second: array<f32>;
@group(0) @binding(6) var<uniform> params: SmParams;
@group(0) @binding(7) var<storage, read> points: array<SmPoint>;
@group(0) @binding(8) var<storage, read_write> img: array<f32>;
@group(0) @binding(9) var<storage, read> blur_src: array<f32>;
@group(0) @binding(10) var<storage, read> pixels: array<BlurPixel>;

fn is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// raster.rs's edge(a, b, q) > 0, or == 0 where the edge owns ties.
fn inside_edge(ax: i32, ay: i32, bx: i32, by: i32, qx: i32, qy: i32) -> bool {
    let e = add64(imul64(bx - ax, qy - ay), neg64(imul64(by - ay, qx - ax)));
    let hi = bitcast<i32>(e.y);
    if hi != 0 {
        return hi > 0;
    }
    if e.x != 0u {
        return true;
    }
    return by > ay || (by == ay && bx > ax);
}

fn covers(n: u32, i: u32, j: u32) -> bool {
    let t = tris[n];
    let qx = i32(i) * SUB + SUB / 2;
    let qy = i32(j) * SUB + SUB / 2;
    return inside_edge(t.x[0], t.y[0], t.x[1], t.y[1], qx, qy)
        && inside_edge(t.x[1], t.y[1], t.x[2], t.y[2], qx, qy)
        && inside_edge(t.x[2], t.y[2], t.x[0], t.y[0], qx, qy);
}

// `plane_at` of raster.rs: plane p (0 z/w, 1 1/w, 2 l/w) of triangle n,
// the same additions in the same order.
fn plane_at(n: u32, p: u32, di: f32, dj: f32) -> f32 {
    let o = 7u * p;
    var w = tris[n].planes[o];
    w = w + tris[n].planes[o + 1u] * di;
    w = w + tris[n].planes[o + 4u] * dj;
    w = w + tris[n].planes[o + 2u] * di;
    w = w + tris[n].planes[o + 5u] * dj;
    w = w + tris[n].planes[o + 3u] * di;
    w = w + tris[n].planes[o + 6u] * dj;
    return w;
}

// `SetupTri::depth`: the offset depth at texel (i, j); +inf's bits where
// the CPU writes nothing.
fn sm_depth(n: u32, i: u32, j: u32) -> f32 {
    let t = tris[n];
    let di = f32(i - t.i0);
    let dj = f32(j - t.j0);
    var z: f32;
    if params.linear == 0u {
        z = plane_at(n, 0u, di, dj) + t.k[0];
    } else {
        let a = plane_at(n, 2u, di, dj);
        let bw = plane_at(n, 1u, di, dj);
        if !(bw > 0.0) {
            return bitcast<f32>(params.inf_bits);
        }
        let d = a / bw;
        let dx = (t.k[3] - d * t.k[5]) / bw;
        let dy = (t.k[4] - d * t.k[6]) / bw;
        let m = max(abs(dx), abs(dy));
        z = d + (t.k[1] * m + t.k[2]);
    }
    if !is_finite(z) {
        return bitcast<f32>(params.inf_bits);
    }
    return z;
}

@compute @workgroup_size(16, 16)
fn sm_raster(@builtin(workgroup_id) wid: vec3<u32>,
             @builtin(num_workgroups) groups: vec3<u32>,
             @builtin(local_invocation_id) lid: vec3<u32>) {
    let w = wid.x + wid.y * groups.x;
    if w >= params.work_count {
        return;
    }
    let tile = work[params.work_offset + w];
    let i = (tile % params.tiles_x) * TILE + lid.x;
    let j = (tile / params.tiles_x) * TILE + lid.y;
    if i >= params.width || j >= params.height {
        return;
    }
    let o = j * params.width + i;
    // sm_clear set both layers to +inf before the first chunk.
    var n1 = near[o];
    var n2 = bitcast<f32>(params.inf_bits);
    if params.two_layers != 0u {
        n2 = second[o];
    }
    let start = bin_start[tile] + params.chunk_start;
    let end = min(bin_start[tile + 1u], start + params.chunk_len);
    for (var n = start; n < end; n++) {
        let tn = bin_list[n];
        let t = tris[tn];
        if i < t.i0 || i > t.i1 || j < t.j0 || j > t.j1 {
            continue;
        }
        if !covers(tn, i, j) {
            continue;
        }
        let z = sm_depth(tn, i, j);
        if !is_finite(z) {
            continue;
        }
        if z < n1 {
            n2 = n1;
            n1 = z;
        } else if z < n2 {
            n2 = z;
        }
    }
    near[o] = n1;
    if params.two_layers != 0u {
        second[o] = n2;
    }
}

// Sets both layers to +inf where no tile has triangles.
@compute @workgroup_size(64)
fn sm_clear(@builtin(global_invocation_id) gid: vec3<u32>,
            @builtin(num_workgroups) groups: vec3<u32>) {
    let o = gid.x + gid.y * groups.x * 64u;
    if o >= params.width * params.height {
        return;
    }
    near[o] = bitcast<f32>(params.inf_bits);
    if params.two_layers != 0u {
        second[o] = bitcast<f32>(params.inf_bits);
    }
}

// lookup.rs's `pass`: 1 outside the map or where the limit is +inf.
fn depth_test(i: i32, j: i32, d: f32) -> f32 {
    if i < 0 || j < 0 || i >= i32(params.width) || j >= i32(params.height) {
        return 1.0;
    }
    let k = u32(j) * params.width + u32(i);
    let n1 = near[k];
    if params.midpoint != 0u {
        let n2 = second[k];
        if !is_finite(n2) {
            return 1.0;
        }
        return select(0.0, 1.0, d <= 0.5 * (n1 + n2));
    }
    if !is_finite(n1) {
        return 1.0;
    }
    return select(0.0, 1.0, d <= n1);
}

// The weight of the a-th of size + 1 texels of a box starting at fraction f.
fn box_weight(a: u32, size: u32, f: f32) -> f32 {
    if a == 0u {
        return 1.0 - f;
    }
    if a == size {
        return f;
    }
    return 1.0;
}

@compute @workgroup_size(64)
fn sm_lookup(@builtin(global_invocation_id) gid: vec3<u32>,
             @builtin(num_workgroups) groups: vec3<u32>) {
    let n = gid.x + gid.y * groups.x * 64u;
    if n >= params.n_points {
        return;
    }
    let p = points[n];
    var v: f32;
    if params.pcf == 0u {
        v = depth_test(p.i, p.j, p.depth);
    } else {
        let s = params.pcf;
        var num = 0.0;
        var den = 0.0;
        for (var b = 0u; b <= s; b++) {
            let wy = box_weight(b, s, p.fy);
            for (var a = 0u; a <= s; a++) {
                let w = wy * box_weight(a, s, p.fx);
                // The receiver's tangent plane at this texel (`TapPlane::depth`).
                let d = p.depth + p.gx * (p.ox + f32(a)) + p.gy * (p.oy + f32(b));
                num = num + w * depth_test(p.i + i32(a), p.j + i32(b), d);
                den = den + w;
            }
        }
        v = select(1.0, num / den, den > 0.0);
    }
    img[p.pixel] = v;
}

@compute @workgroup_size(64)
fn sm_blur(@builtin(global_invocation_id) gid: vec3<u32>,
           @builtin(num_workgroups) groups: vec3<u32>) {
    let k = gid.x + gid.y * groups.x * 64u;
    let npix = params.img_w * params.img_h;
    if k >= npix {
        return;
    }
    let px = pixels[k];
    let s = px.spacing;
    if s == 0 {
        img[k] = blur_src[k];
        return;
    }
    let i = i32(k % params.img_w);
    let j = i32(k / params.img_w);
    var sum = 0.0;
    var wsum = 0.0;
    // blur.rs's order: rows outer, columns inner, weights [1 2 1].
    for (var b = 0; b < 3; b++) {
        let jj = j + (b - 1) * s;
        if jj < 0 || jj >= i32(params.img_h) {
            continue;
        }
        let wb = select(1.0, 2.0, b == 1);
        for (var a = 0; a < 3; a++) {
            let ii = i + (a - 1) * s;
            if ii < 0 || ii >= i32(params.img_w) {
                continue;
            }
            let wa = select(1.0, 2.0, a == 1);
            let t = u32(jj) * params.img_w + u32(ii);
            let q = pixels[t];
            if q.surface != 0u && abs(q.z - px.z) <= px.tol {
                sum = sum + wa * wb * blur_src[t];
                wsum = wsum + wa * wb;
            }
        }
    }
    img[k] = select(blur_src[k], sum / wsum, wsum > 0.0);
}
