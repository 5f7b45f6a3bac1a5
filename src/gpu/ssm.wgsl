// The published soft shadow map on the GPU (appended to gather.wgsl, after
// disk_overlap.wgsl): the arithmetic of Sum::add_texel in
// src/methods/ssm.rs, per receiver texel.
// `acc` holds one f32 sum (as bits) per layer and receiver: layer * W * H + idx
// (points mode: layer * n_points + idx). Points mode sums as the CPU's
// TwoLevel does: each occluder row on its own, then into the total.

// ssm.rs's D2_MIN: keeps 0/0 away where occluder and receiver share a depth.
const D2_MIN: f32 = 1e-36;

// The receiver's sum of this layer while gather_chunk runs.
var<private> sum: f32;

// Points mode, weighed (pp.weigh, a receiver with a tangent plane): the
// point's weights and its sum of this layer's contributions each weighted
// at its clipped back-projection's centre (methods/ssm/weighted.rs).
var<private> weighing: bool;
var<private> weigh_point: WeighPoint;
var<private> wsum: f32;

// A flat micro-patch reaches as far as its own 1/depth.
fn texel_reach(t: u32, w: f32) -> f32 {
    return w;
}

// 4/pi, the f32 of ssm's FOUR_OVER_PI.
const FOUR_OVER_PI: f32 = 1.2732395;

// Sum::add_texel's arithmetic for micro-patch [x0, x1] x (row r) at 1/depth w
// (texel t of `maps`, which the sum does not need); under a disk
// (gp.disk), contribution::<true>'s: the patch clipped to the disk of
// radius d.
fn add_texel(t: u32, w: f32, x0: f32, x1: f32, xr_s: f32, r: RowReach, rc: Receiver) {
    let d = w - rc.wr;
    var c: f32;
    if gp.disk != 0u {
        c = FOUR_OVER_PI * disk_overlap(d, x0 - xr_s, x1 - xr_s, -r.nay0, r.ay1) / fma(d, d, D2_MIN);
    } else {
        let cx = min(x1 - xr_s, d) + min(xr_s - x0, d);
        let cy = min(r.ay1, d) + min(r.nay0, d);
        c = max(cx, 0.0) * max(cy, 0.0) / fma(d, d, D2_MIN);
    }
    sum += c;
    if weighing && c > 0.0 {
        // weighted.rs's centre, in half-light units, then kernel units.
        let h = 0.5 / d;
        let x = (min(x1 - xr_s, d) - min(xr_s - x0, d)) * h;
        let y = (min(r.ay1, d) - min(r.nay0, d)) * h;
        wsum += c * irradiance_weight(weigh_point, x * gp.half_lx, y * gp.half_ly);
    }
}

// Adds this dispatch's chunk of rows of its layer to every receiver's sum.
@compute @workgroup_size(8, 8)
fn ssm(@builtin(global_invocation_id) gid: vec3<u32>) {
    let rc = receiver(gid);
    if !rc.ok {
        return;
    }
    let slot = chunk.layer * gp.rec_w * gp.rec_h + rc.idx;
    sum = bitcast<f32>(acc[slot]);
    // Contributions are >= 0 and the occlusion is clamped: 4 is final.
    if sum >= 4.0 {
        return;
    }
    gather_chunk(rc);
    acc[slot] = bitcast<u32>(sum);
}

// Each layer its own sum, the layers merged by max (§3.5).
@compute @workgroup_size(8, 8)
fn ssm_resolve(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= gp.rec_w || gid.y >= gp.rec_h {
        return;
    }
    let rc = receiver(gid);
    let idx = gid.y * gp.rec_w + gid.x;
    if !rc.ok {
        vis[idx] = 1.0;
        return;
    }
    var occ = 0.0;
    for (var layer = 0u; layer < gp.n_layers; layer++) {
        let sum = bitcast<f32>(acc[layer * gp.rec_w * gp.rec_h + idx]);
        occ = max(occ, min(0.25 * sum, 1.0));
    }
    vis[idx] = 1.0 - occ;
}

// Points mode (gather.wgsl): the row's own sum starts at 0, then joins the
// total (ssm.rs's TwoLevel: open, then close after every row).
var<private> row_done: f32;

fn points_begin_row() {
    row_done = sum;
    sum = 0.0;
}

fn points_end_row() {
    sum = row_done + sum;
}

// Adds this dispatch's chunk of its layer to every point's sum.
@compute @workgroup_size(64)
fn ssm_points(@builtin(global_invocation_id) gid: vec3<u32>,
              @builtin(num_workgroups) groups: vec3<u32>) {
    let rc = point_receiver(point_index(gid, groups));
    if !rc.ok {
        return;
    }
    let slot = chunk.layer * pp.n_points + rc.idx;
    sum = bitcast<f32>(acc[slot]);
    // Contributions are >= 0 and the occlusion is clamped: 4 is final.
    if sum >= 4.0 {
        return;
    }
    // The weighted sums follow the plain ones (gp.n_layers of each).
    let wslot = (gp.n_layers + chunk.layer) * pp.n_points + rc.idx;
    if pp.weigh != 0u {
        weigh_point = weigh_points[rc.idx];
        weighing = weigh_point.valid != 0u;
        wsum = bitcast<f32>(acc[wslot]);
    }
    gather_points_chunk(rc);
    acc[slot] = bitcast<u32>(sum);
    if weighing {
        acc[wslot] = bitcast<u32>(wsum);
    }
}

@compute @workgroup_size(64)
fn ssm_points_resolve(@builtin(global_invocation_id) gid: vec3<u32>,
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
    var occ = 0.0;
    for (var layer = 0u; layer < gp.n_layers; layer++) {
        let sum = bitcast<f32>(acc[layer * pp.n_points + idx]);
        occ = max(occ, min(0.25 * sum, 1.0));
    }
    vis[idx] = 1.0 - occ;
}

// After ssm_points_resolve: vis[n_points + idx], the weighted visibility:
// the weighted sum of the layer whose plain occlusion is the largest (the
// back layer first, a later one only where strictly larger, as the CPU
// merges them) over the weights of the whole light; vis[idx] where it is 0
// or 1, or where the point has no receiver.
@compute @workgroup_size(64)
fn ssm_points_weigh(@builtin(global_invocation_id) gid: vec3<u32>,
                    @builtin(num_workgroups) groups: vec3<u32>) {
    let idx = point_index(gid, groups);
    if idx >= pp.n_points {
        return;
    }
    let out = pp.n_points + idx;
    let v = vis[idx];
    let wp = weigh_points[idx];
    if !point_receiver(idx).ok || wp.valid == 0u || v <= 0.0 || v >= 1.0 {
        vis[out] = v;
        return;
    }
    var best = -1.0;
    var hidden = 0.0;
    for (var k = 0u; k < gp.n_layers; k++) {
        let layer = gp.n_layers - 1u - k;
        let occ = min(0.25 * bitcast<f32>(acc[layer * pp.n_points + idx]), 1.0);
        if occ > best {
            best = occ;
            hidden = bitcast<f32>(acc[(gp.n_layers + layer) * pp.n_points + idx]);
        }
    }
    // ∫ w over the light (irradiance_weight.wgsl's light_weight).
    let all = light_weight(wp, vec2<f32>(gp.half_lx, gp.half_ly), gp.disk != 0u);
    vis[out] = select(0.0, 1.0 - clamp(hidden / all, 0.0, 1.0), all > 0.0);
}
