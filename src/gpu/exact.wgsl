// Ray casting on the GPU: the twin of src/methods/exact.rs. One invocation
// per receiver texel casts its chunk of the stratified light samples through
// the BVH built on the CPU (binned SAH, bvh.rs), counting the samples that see the
// light into `seen` (a gather: each invocation owns its receiver's count);
// then a resolve divides by the sample count. The jitter is
// shadow_rays.rs's multi-jittered pattern, one every texel shares (its u64
// hash emulated with u32 pairs); the ray-triangle test is its watertight
// one (bvh.rs's hit_t) written in the same order of operations.

// Shared with Rust (`ExactParams` in exact.rs; a test compares layouts).
struct ExactParams {
    rec_w: u32,
    rec_h: u32,
    // Samples [chunk_start, chunk_start + chunk_len) of na * nb in this dispatch.
    chunk_start: u32,
    chunk_len: u32,
    // The light's sample pattern: strata na x nb (light_shape.wgsl).
    light: LightSamples,
    // Loop iterations an invocation may run before it gives up and raises
    // `status` (lavapipe stops an invocation after 65535).
    budget: u32,
    has_tris: u32,
    t0: f32,
    t1: f32,
    // Offsets in `axes`: receiver column x, receiver row y (tangent).
    ax_rec_x: u32,
    ax_rec_y: u32,
    _pad0: u32,
    _pad1: u32,
}

struct Node {
    lo: vec3<f32>,
    hi: vec3<f32>,
    start: u32,
    count: u32,
}

@group(0) @binding(0) var<storage, read> maps: array<u32>;
@group(0) @binding(1) var<storage, read> nodes: array<u32>;
@group(0) @binding(2) var<storage, read> tris: array<f32>;
@group(0) @binding(3) var<uniform> ep: ExactParams;
@group(0) @binding(4) var<storage, read> axes: array<f32>;
@group(0) @binding(5) var<storage, read_write> vis: array<f32>;
@group(0) @binding(6) var<storage, read_write> seen: array<u32>;
@group(0) @binding(7) var<storage, read_write> status: array<atomic<u32>>;

// u64 as vec2(lo, hi); add64 and mul32 come from u64.wgsl.
// Wrapping u64 product.
fn mul64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let p = mul32(a.x, b.x);
    return vec2<u32>(p.x, p.y + a.x * b.y + a.y * b.x);
}

// u64 >> s for 0 < s < 32.
fn shr64(a: vec2<u32>, s: u32) -> vec2<u32> {
    return vec2<u32>((a.x >> s) | (a.y << (32u - s)), a.y >> s);
}

// exact.rs's hash (splitmix64's finalizer).
fn hash(x0: vec2<u32>) -> vec2<u32> {
    var x = add64(x0, vec2<u32>(0x7F4A7C15u, 0x9E3779B9u));
    x = mul64(x ^ shr64(x, 30u), vec2<u32>(0x1CE4E5B9u, 0xBF58476Du));
    x = mul64(x ^ shr64(x, 27u), vec2<u32>(0x133111EBu, 0x94D049BBu));
    return x ^ shr64(x, 31u);
}

// exact.rs's unit: the top 24 bits in [0, 1).
fn unit(h: vec2<u32>) -> f32 {
    return f32(h.y >> 8u) * (1.0 / 16777216.0);
}

// shadow_rays.rs's `permute`: a permutation of [0, l) keyed by `seed`
// (masked bijections of [0, 2^k), walked while the value is l or more).
fn permute(i0: u32, l: u32, seed: u32) -> u32 {
    // 2^k - 1, with 2^k the power of two at or above l.
    var w = l - 1u;
    w |= w >> 1u;
    w |= w >> 2u;
    w |= w >> 4u;
    w |= w >> 8u;
    w |= w >> 16u;
    var i = i0;
    loop {
        i = (i ^ seed) & w;
        i = (i * 0x9E3779B1u) & w;
        i ^= i >> 1u;
        i = (i + (seed >> 8u)) & w;
        i = (i * 0x85EBCA6Bu) & w;
        i ^= i >> 2u;
        if i < l {
            break;
        }
    }
    return i;
}

// The largest f32 below 1: a jitter stays inside its stratum.
const BELOW_ONE: f32 = 0.99999994;

// shadow_rays.rs's `multi_jitter`: the jitter of stratum (sa, sb) of
// na x nb in the pattern every receiver shares, sample s = sb * na + sa
// (< 2^16), in the same operations.
fn multi_jitter(sa: u32, sb: u32, na: u32, nb: u32, s: u32) -> vec2<f32> {
    let column = permute(sb, nb, hash(vec2<u32>(sa ^ 0x51u, 0u)).x);
    let row = permute(sa, na, hash(vec2<u32>(sb ^ 0xA7u, 0u)).x);
    let h = hash(hash(vec2<u32>(s << 1u, 0u)));
    let ja = (f32(column) + unit(h)) / f32(nb);
    let jb = (f32(row) + unit(hash(h))) / f32(na);
    return vec2<f32>(min(ja, BELOW_ONE), min(jb, BELOW_ONE));
}

fn node(k: u32) -> Node {
    let b = k * 8u;
    return Node(
        vec3<f32>(bitcast<f32>(nodes[b]), bitcast<f32>(nodes[b + 1u]), bitcast<f32>(nodes[b + 2u])),
        vec3<f32>(bitcast<f32>(nodes[b + 3u]), bitcast<f32>(nodes[b + 4u]), bitcast<f32>(nodes[b + 5u])),
        nodes[b + 6u],
        nodes[b + 7u],
    );
}

fn vertex(t: u32, v: u32) -> vec3<f32> {
    let b = t * 9u + v * 3u;
    return vec3<f32>(tris[b], tris[b + 1u], tris[b + 2u]);
}

// glam's Vec3::cross and dot, operation for operation.
fn cross3(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y);
}

fn dot3(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

// bvh.rs's Shear: the ray's largest axis kz (the first of equals), the
// next two kx, ky, and the shear taking d to kz.
struct Shear {
    k: vec3<u32>,
    s: vec3<f32>,
}

fn shear_of(d: vec3<f32>) -> Shear {
    let a = abs(d);
    var kz = 2u;
    if a.x >= a.y && a.x >= a.z {
        kz = 0u;
    } else if a.y >= a.z {
        kz = 1u;
    }
    let kx = (kz + 1u) % 3u;
    let ky = (kz + 2u) % 3u;
    return Shear(vec3<u32>(kx, ky, kz), vec3<f32>(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]));
}

// bvh.rs's hit_t: the watertight test (Woop, Benthin & Wald 2013), where
// the line o + t d crosses triangle t (edges included): ok = false when it
// does not. The same operations in the same order.
struct Crossing {
    ok: bool,
    t: f32,
}

fn hit_t(t: u32, o: vec3<f32>, sh: Shear) -> Crossing {
    let none = Crossing(false, 0.0);
    let kx = sh.k.x;
    let ky = sh.k.y;
    let kz = sh.k.z;
    let ra = vertex(t, 0u) - o;
    let rb = vertex(t, 1u) - o;
    let rc = vertex(t, 2u) - o;
    let ax = ra[kx] - sh.s.x * ra[kz];
    let ay = ra[ky] - sh.s.y * ra[kz];
    let bx = rb[kx] - sh.s.x * rb[kz];
    let by = rb[ky] - sh.s.y * rb[kz];
    let cx = rc[kx] - sh.s.x * rc[kz];
    let cy = rc[ky] - sh.s.y * rc[kz];
    let u = cx * by - cy * bx;
    let v = ax * cy - ay * cx;
    let w = bx * ay - by * ax;
    let neg = u < 0.0 || v < 0.0 || w < 0.0;
    let pos = u > 0.0 || v > 0.0 || w > 0.0;
    if neg && pos {
        return none;
    }
    let det = u + v + w;
    if det == 0.0 || !(abs(det) < bitcast<f32>(0x7f800000u)) {
        return none;
    }
    let az = sh.s.z * ra[kz];
    let bz = sh.s.z * rb[kz];
    let cz = sh.s.z * rc[kz];
    return Crossing(true, (u * az + v * bz + w * cz) / det);
}

// bvh.rs's hits: any crossing with t in (t0, t1).
fn hits(t: u32, o: vec3<f32>, sh: Shear) -> bool {
    let c = hit_t(t, o, sh);
    return c.ok && c.t > ep.t0 && c.t < ep.t1;
}

// bvh.rs's EXIT_SLACK: a box's exit t widened by it (1 + 4 ulps).
const EXIT_SLACK: f32 = 1.000000476837158203125;

// f32::min / f32::max: the non-NaN operand wins.
fn fmin(a: f32, b: f32) -> f32 {
    if a != a {
        return b;
    }
    if b != b {
        return a;
    }
    return min(a, b);
}

fn fmax(a: f32, b: f32) -> f32 {
    if a != a {
        return b;
    }
    if b != b {
        return a;
    }
    return max(a, b);
}

// Loop iterations this invocation has run (see ExactParams::budget).
var<private> iterations: u32 = 0u;

// bvh.rs's Bvh::occluded (the one-ray reference): whether o + t d, t in (t0, t1), hits a triangle.
fn occluded(o: vec3<f32>, d: vec3<f32>) -> bool {
    let inv = vec3<f32>(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
    let sh = shear_of(d);
    var stack: array<u32, 64>;
    var sp = 1u;
    stack[0] = 0u;
    while sp > 0u {
        iterations += 1u;
        if iterations > ep.budget {
            atomicOr(&status[0], 1u);
            return false;
        }
        sp -= 1u;
        let n = node(stack[sp]);
        let a = (n.lo - o) * inv;
        let b = (n.hi - o) * inv;
        let mn = vec3<f32>(fmin(a.x, b.x), fmin(a.y, b.y), fmin(a.z, b.z));
        let mx = vec3<f32>(fmax(a.x, b.x), fmax(a.y, b.y), fmax(a.z, b.z));
        let tmin = fmax(fmax(mn.x, fmax(mn.y, mn.z)), ep.t0);
        let tmax = fmin(fmin(mx.x, fmin(mx.y, mx.z)) * EXIT_SLACK, ep.t1);
        if tmin > tmax {
            continue;
        }
        if n.count > 0u {
            iterations += n.count;
            for (var k = 0u; k < n.count; k++) {
                if hits(n.start + k, o, sh) {
                    return true;
                }
            }
        } else if sp + 2u <= 64u {
            stack[sp] = n.start;
            stack[sp + 1u] = n.start + 1u;
            sp += 2u;
        }
    }
    return false;
}

fn receiver_point(gid: vec3<u32>) -> vec4<f32> {
    let idx = gid.y * ep.rec_w + gid.x;
    let z = bitcast<f32>(maps[idx]);
    if !(z > 0.0 && z < bitcast<f32>(0x7f800000u)) {
        return vec4<f32>(0.0, 0.0, 0.0, 0.0);
    }
    let x = axes[ep.ax_rec_x + gid.x];
    let y = axes[ep.ax_rec_y + gid.y];
    return vec4<f32>(x * z, y * z, z, 1.0);
}

// Adds this dispatch's chunk of samples to each receiver's count.
@compute @workgroup_size(8, 8)
fn exact(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= ep.rec_w || gid.y >= ep.rec_h || ep.has_tris == 0u {
        return;
    }
    let pr = receiver_point(gid);
    if pr.w == 0.0 {
        return;
    }
    let p = pr.xyz;
    let idx = gid.y * ep.rec_w + gid.x;
    var count = 0u;
    for (var s = ep.chunk_start; s < ep.chunk_start + ep.chunk_len; s++) {
        let sa = s % ep.light.na;
        let sb = s / ep.light.na;
        // One pattern every texel shares (shadow_rays.rs's Jitter::Shared).
        let j = multi_jitter(sa, sb, ep.light.na, ep.light.nb, s);
        let l = light_sample(sa, sb, j.x, j.y, ep.light);
        let d = vec3<f32>(l.x, l.y, 0.0) - p;
        if !occluded(p, d) {
            count += 1u;
        }
    }
    seen[idx] += count;
}

@compute @workgroup_size(8, 8)
fn exact_resolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= ep.rec_w || gid.y >= ep.rec_h {
        return;
    }
    let idx = gid.y * ep.rec_w + gid.x;
    let pr = receiver_point(gid);
    if pr.w == 0.0 {
        vis[idx] = 1.0;
        return;
    }
    if ep.has_tris == 0u {
        vis[idx] = 1.0;
        return;
    }
    vis[idx] = f32(seen[idx]) / f32(ep.light.na * ep.light.nb);
}
