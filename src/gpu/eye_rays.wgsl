// `exact` in the eye view on the GPU: stratified shadow rays from every
// visible surface point, through the BVH of every triangle in kernel light
// space (built on the CPU). The CPU twin is src/eye/rays.rs (`visibility`,
// through methods/exact.rs's `stratified`): for light sample (x, y, 0) of
// point k (the jitter is exact.rs's hash of the sample, one pattern every
// point shares, as exact.wgsl computes it for map texels), the segment starts at
// the origin on the side of the surface the light point lies on,
//     o = above  if a0 + x au + y av >= 0,  else below
// (the point moved off its surface along the normal by Mitsuba's
// spawn_ray_to offset, computed in f64 on the CPU: rays::ray_starts),
// and runs o + t (light point - o), t in (0, 1 - RAY_EPS) (ExactParams t0 = 0,
// t1). A chunk of samples per dispatch counts the clear ones into `seen`,
// and sums their weights and every sample's into `weights` (the light
// point's share of the irradiance, cos θ cos θ' / r² up to a factor:
// irradiance_weight.wgsl, rays.rs's `RayStart::weight`); the resolve divides the count by the
// sample count into vis[k] and the weights into vis[n + k] (the weighted
// visibility; V where no sample weighs anything), 0 for a start that is
// not valid (a point at or behind a rectangle's plane).
//
// Appended to u64.wgsl + exact.wgsl (hash, unit, occluded and its bindings;
// ExactParams' rec_w is the number of ray starts here) and
// irradiance_weight.wgsl (the weights).

// Shared with Rust (`GpuRayStart` in eye.rs; a test compares layouts).
struct RayStart {
    // Origin above the surface (the normal's side), kernel light space.
    ax: f32,
    ay: f32,
    az: f32,
    // 1: shade this point; 0: visibility 0.
    valid: u32,
    // Origin below the surface.
    bx: f32,
    by: f32,
    bz: f32,
    // side(x, y) = a0 + x au + y av: which side light point (x, y) lies on.
    a0: f32,
    au: f32,
    av: f32,
    _pad0: u32,
    _pad1: u32,
}

const RAYS_GROUP: u32 = 64u;

@group(0) @binding(8) var<storage, read> starts: array<RayStart>;
// Per start: the clear samples' summed weight, then every sample's.
@group(0) @binding(9) var<storage, read_write> weights: array<f32>;

// Adds this dispatch's chunk of samples to each point's count.
@compute @workgroup_size(64)
fn eye_exact(@builtin(global_invocation_id) gid: vec3<u32>,
             @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = gid.x + gid.y * groups.x * RAYS_GROUP;
    if idx >= ep.rec_w || ep.has_tris == 0u {
        return;
    }
    let s = starts[idx];
    if s.valid == 0u {
        return;
    }
    let above = vec3<f32>(s.ax, s.ay, s.az);
    let below = vec3<f32>(s.bx, s.by, s.bz);
    // The surface point (the starts' midpoint) as the weights read it.
    let wp = WeighPoint(0.5 * (above + below), 1u, vec3<f32>(s.a0, s.au, s.av), 0u);
    var count = 0u;
    var w_seen = 0.0;
    var w_all = 0.0;
    for (var k = ep.chunk_start; k < ep.chunk_start + ep.chunk_len; k++) {
        let sa = k % ep.light.na;
        let sb = k / ep.light.na;
        // One pattern every point shares (shadow_rays.rs's Jitter::Shared).
        let j = multi_jitter(sa, sb, ep.light.na, ep.light.nb, k);
        let l = light_sample(sa, sb, j.x, j.y, ep.light);
        let x = l.x;
        let y = l.y;
        let side = s.a0 + x * s.au + y * s.av;
        var o = below;
        if side >= 0.0 {
            o = above;
        }
        let w = irradiance_weight(wp, x, y);
        w_all += w;
        let d = vec3<f32>(x, y, 0.0) - o;
        if !occluded(o, d) {
            count += 1u;
            w_seen += w;
        }
    }
    seen[idx] += count;
    weights[2u * idx] += w_seen;
    weights[2u * idx + 1u] += w_all;
}

@compute @workgroup_size(64)
fn eye_exact_resolve(@builtin(global_invocation_id) gid: vec3<u32>,
                     @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = gid.x + gid.y * groups.x * RAYS_GROUP;
    if idx >= ep.rec_w {
        return;
    }
    let n = ep.rec_w;
    if starts[idx].valid == 0u {
        vis[idx] = 0.0;
        vis[n + idx] = 0.0;
        return;
    }
    if ep.has_tris == 0u {
        vis[idx] = 1.0;
        vis[n + idx] = 1.0;
        return;
    }
    let v = f32(seen[idx]) / f32(ep.light.na * ep.light.nb);
    vis[idx] = v;
    let w_all = weights[2u * idx + 1u];
    vis[n + idx] = select(v, weights[2u * idx] / w_all, w_all > 0.0);
}
