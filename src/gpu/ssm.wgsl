// The published soft shadow map on the GPU (appended to gather.wgsl): the
// arithmetic of Sum::add_texel in src/methods/ssm.rs, per receiver texel.
// `acc` holds one f32 sum (as bits) per layer and receiver: layer * W * H + idx
// (points mode: layer * n_points + idx). Points mode sums as the CPU's
// TwoLevel does: each occluder row on its own, then into the total.

// ssm.rs's D2_MIN: keeps 0/0 away where occluder and receiver share a depth.
const D2_MIN: f32 = 1e-36;

// The receiver's sum of this layer while gather_chunk runs.
var<private> sum: f32;

// A flat micro-patch reaches as far as its own 1/depth.
fn texel_reach(t: u32, w: f32) -> f32 {
    return w;
}

// Sum::add_texel's arithmetic for micro-patch [x0, x1] x (row r) at 1/depth w
// (texel t of `maps`, which the sum does not need).
fn add_texel(t: u32, w: f32, x0: f32, x1: f32, xr_s: f32, r: RowReach, rc: Receiver) {
    let d = w - rc.wr;
    let cx = min(x1 - xr_s, d) + min(xr_s - x0, d);
    let cy = min(r.ay1, d) + min(r.nay0, d);
    sum += max(cx, 0.0) * max(cy, 0.0) / fma(d, d, D2_MIN);
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
    gather_points_chunk(rc);
    acc[slot] = bitcast<u32>(sum);
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
