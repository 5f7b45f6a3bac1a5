// The light's shape on the device: the twin of src/geom/light_shape/,
// prepended to every module that samples the light (exact.wgsl and the
// eye view's rays). The light is the rectangle [-sx/2, sx/2] x [-sy/2, sy/2]
// at Z = 0; the sample of stratum (sa, sb) of na x nb, jittered by (ja, jb)
// in [0, 1)^2, is (((sa + ja)/na - 1/2) sx, ((sb + jb)/nb - 1/2) sy), in
// the same f32 operations as the CPU's `LightSamples::point` (the same bits).
// A new shape replaces this function and the uniform below (and the Rust
// side's `LightSamples` and `GpuLightSamples`, gpu/light.rs).

// The sample pattern, one uniform member of the ray casters' parameters
// (`GpuLightSamples` in gpu/light.rs; a test there compares layouts).
struct LightSamples {
    // The stratification na x nb (`LightShape::sample_grid`).
    na: u32,
    nb: u32,
    // The rectangle's full width and height.
    size_x: f32,
    size_y: f32,
}

fn light_sample(sa: u32, sb: u32, ja: f32, jb: f32, l: LightSamples) -> vec2<f32> {
    let x = ((f32(sa) + ja) / f32(l.na) - 0.5) * l.size_x;
    let y = ((f32(sb) + jb) / f32(l.nb) - 0.5) * l.size_y;
    return vec2<f32>(x, y);
}
