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
    // The rectangle's full width and height (a disk's diameter, twice).
    size_x: f32,
    size_y: f32,
    // 1: the strata are mapped onto the disk inscribed in the size
    // (Shirley and Chiu's concentric map, `disk_sample`).
    disk: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

fn light_sample(sa: u32, sb: u32, ja: f32, jb: f32, l: LightSamples) -> vec2<f32> {
    if l.disk != 0u {
        return disk_sample(sa, sb, ja, jb, l);
    }
    let x = ((f32(sa) + ja) / f32(l.na) - 0.5) * l.size_x;
    let y = ((f32(sb) + jb) / f32(l.nb) - 0.5) * l.size_y;
    return vec2<f32>(x, y);
}

// The twin of disk.rs's `sample_point`: the square [-1, 1]^2 cut by its
// diagonals into four wedges; in the wedge |a| > |b| the point is at
// radius a and angle (pi/4)(b/a), in the other at radius b and angle
// pi/2 - (pi/4)(a/b). The same operations, but the device's sin and cos
// need not round as the CPU's do: a ray grazing an edge may differ.
fn disk_sample(sa: u32, sb: u32, ja: f32, jb: f32, l: LightSamples) -> vec2<f32> {
    let quarter = 0.78539816;
    let a = 2.0 * (f32(sa) + ja) / f32(l.na) - 1.0;
    let b = 2.0 * (f32(sb) + jb) / f32(l.nb) - 1.0;
    var rad = 0.0;
    var phi = 0.0;
    if abs(a) > abs(b) {
        rad = a;
        phi = quarter * (b / a);
    } else if b != 0.0 {
        rad = b;
        phi = 2.0 * quarter - quarter * (a / b);
    }
    let r = 0.5 * l.size_x;
    return vec2<f32>(r * rad * cos(phi), r * rad * sin(phi));
}
