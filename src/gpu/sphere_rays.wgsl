// `exact` under a sphere light on the GPU: the twin of
// src/eye/sphere_rays.rs (`trace_packet`). From a surface point outside the
// sphere (centre c, radius R) the light is the cap of directions within α
// of c − x; the shared pattern's a x b strata, mapped onto the unit disk
// and the disk onto the cap so that they keep equal solid angles, come as a
// table of (u1, cos φ, sin φ) computed on the CPU in f64 (`cap_sample`),
// and each point's cap frame (its axis w toward c, a pair e1, e2 about it,
// 1 − cos α) too (`CapFrame`). Sample k's direction is
//     d = (1 − t) w + sqrt(t (2 − t)) (cos φ e1 + sin φ e2),
//     t = u1 (1 − cos α)
// (cos θ = 1 − t); its ray leaves the surface on the side d goes (the two
// origins of Mitsuba's spawn_ray_to, made on the CPU in f64) and stops at
// the sphere's near surface (`cap_hit`), t in (0, 1 − RAY_EPS) of that
// segment; everything is relative to c (the BVH's triangles too). A
// dispatch adds its chunk of samples to each point's count of clear rays
// and to its weights (each ray's n · d: the cap is sampled uniformly in
// solid angle, so that is its share of the irradiance); the resolve
// divides. A point inside the sphere (valid 0) gets 0 and 0.
//
// Appended to u64.wgsl + light_shape.wgsl + exact.wgsl (the traversal,
// `occluded`, and its bindings; ExactParams' rec_w is the number of points,
// its light's strata the pattern's).

// Shared with Rust (`GpuSphereStart` in sphere_rays.rs; a test compares
// layouts). Relative to the sphere's centre.
struct SphereStart {
    // Origin on the normal's side.
    ax: f32,
    ay: f32,
    az: f32,
    // 1: shade this point; 0: inside the sphere, visibility 0.
    valid: u32,
    // Origin on the other side.
    bx: f32,
    by: f32,
    bz: f32,
    // 1 − cos α.
    omc: f32,
    // The surface normal (facing the camera).
    nx: f32,
    ny: f32,
    nz: f32,
    // The cap's axis toward the centre.
    wx: f32,
    wy: f32,
    wz: f32,
    // The pair about it.
    e1x: f32,
    e1y: f32,
    e1z: f32,
    e2x: f32,
    e2y: f32,
    e2z: f32,
}

// Shared with Rust (`SphereParams`): the sphere's radius.
struct SphereParams {
    radius: f32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

const SPHERE_GROUP: u32 = 64u;

@group(0) @binding(8) var<storage, read> caps: array<SphereStart>;
// Per point: the clear rays' summed weight, then every ray's.
@group(0) @binding(9) var<storage, read_write> cap_weights: array<f32>;
// Per sample of the shared pattern: u1, cos φ, sin φ.
@group(0) @binding(10) var<storage, read> cap_table: array<f32>;
@group(0) @binding(11) var<uniform> sp: SphereParams;

// sphere.rs's cap_hit from an origin o relative to the centre: the
// distance along the unit d to the sphere's near surface; 0 from inside or
// on it, a negative number (no hit) where d leaves it behind.
fn cap_hit(o: vec3<f32>, d: vec3<f32>) -> f32 {
    let q = -o;
    let d2 = dot3(q, q);
    let r2 = sp.radius * sp.radius;
    if !(d2 > r2) {
        return 0.0;
    }
    let b = dot3(q, d);
    if !(b > 0.0) {
        return -1.0;
    }
    let m = q - b * d;
    let disc = max(r2 - dot3(m, m), 0.0);
    return (d2 - r2) / (b + sqrt(disc));
}

// Adds this dispatch's chunk of samples to each point's count and weights.
@compute @workgroup_size(64)
fn eye_sphere(@builtin(global_invocation_id) gid: vec3<u32>,
              @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = gid.x + gid.y * groups.x * SPHERE_GROUP;
    if idx >= ep.rec_w {
        return;
    }
    let s = caps[idx];
    if s.valid == 0u {
        return;
    }
    let above = vec3<f32>(s.ax, s.ay, s.az);
    let below = vec3<f32>(s.bx, s.by, s.bz);
    let n = vec3<f32>(s.nx, s.ny, s.nz);
    let w = vec3<f32>(s.wx, s.wy, s.wz);
    let e1 = vec3<f32>(s.e1x, s.e1y, s.e1z);
    let e2 = vec3<f32>(s.e2x, s.e2y, s.e2z);
    var count = 0u;
    var w_seen = 0.0;
    var w_all = 0.0;
    for (var k = ep.chunk_start; k < ep.chunk_start + ep.chunk_len; k++) {
        let u1 = cap_table[3u * k];
        let cos_phi = cap_table[3u * k + 1u];
        let sin_phi = cap_table[3u * k + 2u];
        let t = u1 * s.omc;
        let sin_t = sqrt(max(t * (2.0 - t), 0.0));
        let d = (1.0 - t) * w + sin_t * (cos_phi * e1 + sin_phi * e2);
        let nd = dot3(n, d);
        let weight = max(nd, 0.0);
        w_all += weight;
        var o = below;
        if nd >= 0.0 {
            o = above;
        }
        let reach = cap_hit(o, d);
        if !(reach > 0.0) {
            continue;
        }
        if ep.has_tris == 0u || !occluded(o, reach * d) {
            count += 1u;
            w_seen += weight;
        }
    }
    seen[idx] += count;
    cap_weights[2u * idx] += w_seen;
    cap_weights[2u * idx + 1u] += w_all;
}

// The counts and weights into vis[k] and vis[n + k]: V, and the weighted V
// (V where no ray weighs anything); 0 and 0 inside the sphere.
@compute @workgroup_size(64)
fn eye_sphere_resolve(@builtin(global_invocation_id) gid: vec3<u32>,
                      @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = gid.x + gid.y * groups.x * SPHERE_GROUP;
    if idx >= ep.rec_w {
        return;
    }
    let n = ep.rec_w;
    if caps[idx].valid == 0u {
        vis[idx] = 0.0;
        vis[n + idx] = 0.0;
        return;
    }
    let v = f32(seen[idx]) / f32(ep.light.na * ep.light.nb);
    vis[idx] = v;
    let w_all = cap_weights[2u * idx + 1u];
    vis[n + idx] = select(v, cap_weights[2u * idx] / w_all, w_all > 0.0);
}
