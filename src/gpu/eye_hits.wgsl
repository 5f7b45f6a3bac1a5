// The eye view's first hits on the GPU: one invocation per pixel casts the
// pixel-centre ray o + t d (o = 0: the eye; d = gbuffer::pixel_ray, uploaded
// in f32) through the camera BVH (gbuffer::camera_bvh, built on the CPU) and
// writes the BVH slot of the nearest triangle crossed with t in (0, best),
// or NONE. The CPU twin is Bvh::nearest in src/trace/bvh.rs, followed
// here operation for operation: the same slab test (glam 0.34's Vec3
// min/max and min/max_element, which pick the second operand unless the
// first compares strictly smaller/larger, then f32::max(0) and
// f32::min(best), which ignore a NaN), the same watertight test (exact.wgsl's
// hit_t) and the same visiting order (children nearer first), so ties go the
// same way. The CPU maps the slot to the input triangle (Bvh::order) and
// builds the G-buffer from it (gbuffer::from_hits, f64).
//
// Appended to u64.wgsl + exact.wgsl (node, vertex, hit_t, fmin, fmax, the
// BVH bindings 1-2 and `status`, binding 7).

// Shared with Rust (`HitsParams` in eye.rs; a test compares layouts).
struct HitsParams {
    // Pixels (rays).
    n: u32,
    // Loop iterations an invocation may run before it gives up and raises
    // `status` (lavapipe stops an invocation after 65535).
    budget: u32,
    _pad0: u32,
    _pad1: u32,
}

const NO_HIT: u32 = 0xffffffffu;
const HITS_GROUP: u32 = 64u;

@group(0) @binding(8) var<uniform> hp: HitsParams;
// Ray directions, 3 floats a pixel.
@group(0) @binding(9) var<storage, read> dirs: array<f32>;
@group(0) @binding(10) var<storage, read_write> hit_slot: array<u32>;

// glam's `if a < b { a } else { b }` and `if a > b { a } else { b }`.
fn sel_min(a: f32, b: f32) -> f32 {
    return select(b, a, a < b);
}

fn sel_max(a: f32, b: f32) -> f32 {
    return select(b, a, a > b);
}

// Bvh::nearest's entry: the ray's entry t into node k, clipped to
// [0, best], or -1 when it misses (an entry is never negative).
fn entry_t(k: u32, o: vec3<f32>, inv: vec3<f32>, best: f32) -> f32 {
    let n = node(k);
    let a = (n.lo - o) * inv;
    let b = (n.hi - o) * inv;
    let mn = vec3<f32>(sel_min(a.x, b.x), sel_min(a.y, b.y), sel_min(a.z, b.z));
    let mx = vec3<f32>(sel_max(a.x, b.x), sel_max(a.y, b.y), sel_max(a.z, b.z));
    let tmin = fmax(sel_max(sel_max(mn.x, mn.y), mn.z), 0.0);
    let tmax = fmin(sel_min(sel_min(mx.x, mx.y), mx.z) * EXIT_SLACK, best);
    if tmin <= tmax {
        return tmin;
    }
    return -1.0;
}

@compute @workgroup_size(64)
fn eye_hits(@builtin(global_invocation_id) gid: vec3<u32>,
            @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = gid.x + gid.y * groups.x * HITS_GROUP;
    if idx >= hp.n {
        return;
    }
    let o = vec3<f32>(0.0, 0.0, 0.0);
    let d = vec3<f32>(dirs[3u * idx], dirs[3u * idx + 1u], dirs[3u * idx + 2u]);
    let inv = vec3<f32>(1.0 / d.x, 1.0 / d.y, 1.0 / d.z);
    let sh = shear_of(d);
    var best = bitcast<f32>(0x7f800000u);
    var hit = NO_HIT;
    var stack: array<u32, 64>;
    var sp = 1u;
    stack[0] = 0u;
    var steps = 0u;
    while sp > 0u {
        steps += 1u;
        if steps > hp.budget {
            atomicOr(&status[0], 1u);
            hit = NO_HIT;
            break;
        }
        sp -= 1u;
        let k = stack[sp];
        if entry_t(k, o, inv, best) < 0.0 {
            continue;
        }
        let n = node(k);
        if n.count > 0u {
            steps += n.count;
            for (var i = 0u; i < n.count; i++) {
                let c = hit_t(n.start + i, o, sh);
                if c.ok && c.t > 0.0 && c.t < best {
                    best = c.t;
                    hit = n.start + i;
                }
            }
        } else {
            let l = n.start;
            let r = n.start + 1u;
            let el = entry_t(l, o, inv, best);
            let er = entry_t(r, o, inv, best);
            // Push the farther child first so the nearer one pops next; on
            // a tie (or one child) the left pops first, as on the CPU.
            if el >= 0.0 && er >= 0.0 && er < el {
                if sp + 2u <= 64u {
                    stack[sp] = l;
                    stack[sp + 1u] = r;
                    sp += 2u;
                }
            } else {
                if er >= 0.0 && sp < 64u {
                    stack[sp] = r;
                    sp += 1u;
                }
                if el >= 0.0 && sp < 64u {
                    stack[sp] = l;
                    sp += 1u;
                }
            }
        }
    }
    hit_slot[idx] = hit;
}
