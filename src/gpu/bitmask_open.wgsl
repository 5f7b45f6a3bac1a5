// bitmask, gaps="open" (appended after bitmask.wgsl): flat per-texel
// micro-patches, as the SSM has them (MaskKernel<_, false> in
// src/methods/bitmask.rs).

// A flat micro-patch reaches as far as its own 1/depth.
fn texel_reach(t: u32, w: f32) -> f32 {
    return w;
}

fn add_texel(t: u32, w: f32, x0: f32, x1: f32, xr_s: f32, r: RowReach, rc: Receiver) {
    add_patch(w, x0, x1, xr_s, r, rc);
}
