// The bitmask method on the GPU (appended to gather.wgsl): the arithmetic of
// Bitmask::add_texel in src/methods/bitmask.rs, per receiver texel. A mask of
// up to 256 light samples is 8 u32 words; the layers OR into one mask.

// The sample pattern's rank tables, 8 words per entry: x_ge[k] (the samples
// whose x-rank is >= k, k in 0..=S) at k * 8, then y_ge[k] at (S + 1 + k) * 8.
@group(0) @binding(6) var<storage, read> tables: array<u32>;

const WORDS: u32 = 8u;

fn x_ge(k: u32, q: u32) -> u32 {
    return tables[k * WORDS + q];
}

fn y_ge(k: u32, q: u32) -> u32 {
    return tables[(gp.samples + 1u + k) * WORDS + q];
}

@compute @workgroup_size(8, 8)
fn bitmask(@builtin(global_invocation_id) gid: vec3<u32>) {
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
    let s = f32(gp.samples);
    let half = 0.5 * s;
    var mask: array<u32, 8>;
    var full = false;
    for (var layer = 0u; layer < gp.n_layers && !full; layer++) {
        let w_max = bitcast<f32>(atomicLoad(&layer_w_max[layer]));
        let js = layer_rows(w_max, yr, wr);
        let base = layer_offset(layer);
        for (var j = js.x; j <= js.y && !full; j++) {
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
                let inv = select(0.0, 1.0 / d, d > 0.0);
                // Light coordinate t in [-1, 1] -> sample units; first rank at
                // or above a lower bound, one past the last at or below an
                // upper bound, clamped to [0, S].
                let ka = u32(clamp(ceil((((x0 - xr_s) * inv) + 1.0) * half - 0.5), 0.0, s));
                let kb = u32(clamp(floor((((x1 - xr_s) * inv) + 1.0) * half - 0.5) + 1.0, 0.0, s));
                let kc = u32(clamp(ceil((((-r.nay0) * inv) + 1.0) * half - 0.5), 0.0, s));
                let kd = u32(clamp(floor(((r.ay1 * inv) + 1.0) * half - 0.5) + 1.0, 0.0, s));
                for (var q = 0u; q < WORDS; q++) {
                    mask[q] |= x_ge(ka, q) & ~x_ge(kb, q) & y_ge(kc, q) & ~y_ge(kd, q);
                }
            }
            // Every sample hidden: nothing left to add.
            full = true;
            for (var q = 0u; q < WORDS; q++) {
                full = full && mask[q] == x_ge(0u, q);
            }
        }
    }
    var hidden = 0u;
    for (var q = 0u; q < WORDS; q++) {
        hidden += countOneBits(mask[q]);
    }
    vis[idx] = 1.0 - f32(hidden) / s;
}
