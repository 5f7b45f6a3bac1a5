// The light's shape on the device: the twin of src/geom/light_shape.rs,
// prepended to every module that samples the light (exact.wgsl and the
// eye view's rays). The light is the rectangle [-sx/2, sx/2] x [-sy/2, sy/2]
// at Z = 0; the sample of stratum (sa, sb) of na x nb, jittered by (ja, jb)
// in [0, 1)^2, is (((sa + ja)/na - 1/2) sx, ((sb + jb)/nb - 1/2) sy), in
// the same f32 operations as the CPU's `LightSamples::point` (the same bits).
// A new shape replaces this function (and the Rust side's `LightSamples`).

fn light_sample(sa: u32, sb: u32, na: u32, nb: u32, ja: f32, jb: f32, size: vec2<f32>) -> vec2<f32> {
    let x = ((f32(sa) + ja) / f32(na) - 0.5) * size.x;
    let y = ((f32(sb) + jb) / f32(nb) - 0.5) * size.y;
    return vec2<f32>(x, y);
}
