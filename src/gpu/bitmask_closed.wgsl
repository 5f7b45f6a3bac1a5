// bitmask, gaps="closed" (appended after bitmask.wgsl): connected
// micro-quads (MaskKernel<_, true> in src/methods/bitmask.rs). The corners
// are made on the CPU by the CPU kernel's own function
// (methods/gather/corners.rs, gather.rs's layer_corners) and uploaded: 4
// 1/depths per texel of every occluder layer, laid out as the layers are in
// `maps` without the receiver map in front.

// Corner 1/depths of texel t of `maps`: corners[t - layer0_offset]
// (top-left, top-right, bottom-left, bottom-right).
@group(0) @binding(13) var<storage, read> corners: array<vec4<f32>>;

fn quad_corners(t: u32) -> vec4<f32> {
    return corners[t - gp.layer0_offset];
}

// A quad reaches as far as its nearest corner (Layer::connect's fold: the
// centre, then the corners in order).
fn texel_reach(t: u32, w: f32) -> f32 {
    let c = quad_corners(t);
    return max(max(max(max(w, c.x), c.y), c.z), c.w);
}

fn add_texel(t: u32, w: f32, x0: f32, x1: f32, xr_s: f32, r: RowReach, rc: Receiver) {
    add_quad(quad_corners(t), w, x0, x1, xr_s, r, rc);
}
