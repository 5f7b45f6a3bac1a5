// The published soft shadow map on the GPU (appended to gather.wgsl): the
// arithmetic of Sum::add_texel in src/methods/ssm.rs, per receiver texel.

// ssm.rs's D2_MIN: keeps 0/0 away where occluder and receiver share a depth.
const D2_MIN: f32 = 1e-36;

@compute @workgroup_size(8, 8)
fn ssm(@builtin(global_invocation_id) gid: vec3<u32>) {
    if gid.x >= gp.rec_w || gid.y >= gp.rec_h {
        return;
    }
    let idx = gid.y * gp.rec_w + gid.x;
    let zr = bitcast<f32>(maps[idx]);
    if !(zr > 0.0 && zr < bitcast<f32>(0x7f800000u)) {
        vis[idx] = 1.0;
        return;
    }
    let wr = 1.0 / zr;
    let xr = axes[gp.ax_rec_x + gid.x];
    let yr = axes[gp.ax_rec_y + gid.y];
    let xr_s = xr * gp.inv_half_lx;
    var occ = 0.0;
    // Each layer its own sum, the layers merged by max (§3.5).
    for (var layer = 0u; layer < gp.n_layers; layer++) {
        let w_max = bitcast<f32>(atomicLoad(&layer_w_max[layer]));
        let js = layer_rows(w_max, yr, wr);
        let base = layer_offset(layer);
        var acc = 0.0;
        for (var j = js.x; j <= js.y && acc < 4.0; j++) {
            let r = row_reach(layer, u32(j), xr, yr, wr);
            if !r.ok {
                continue;
            }
            let row = base + u32(j) * gp.occ_w;
            for (var i = r.i_lo; i < r.i_hi; i++) {
                let w = inv_depth(maps[row + i]);
                if w <= wr {
                    continue;
                }
                let x0 = axes[gp.ax_col_x0s + i];
                let x1 = x0 + gp.wx;
                let d = w - wr;
                let cx = min(x1 - xr_s, d) + min(xr_s - x0, d);
                let cy = min(r.ay1, d) + min(r.nay0, d);
                acc += max(cx, 0.0) * max(cy, 0.0) / fma(d, d, D2_MIN);
            }
        }
        occ = max(occ, min(0.25 * acc, 1.0));
    }
    vis[idx] = 1.0 - occ;
}
