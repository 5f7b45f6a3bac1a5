// A Lambertian receiver's weights over a planar light, for the weighted
// visibility of the map methods that weigh (methods/bitmask/weighted.rs,
// methods/ssm/weighted.rs, methods/pcss_weighted.rs): the light point
// (x, y, 0) (kernel space, the light facing +Z) adds cos θ cos θ' / r² to
// the irradiance of a surface point p, cos θ = side / r (0 behind its
// tangent plane), cos θ' = p_z / r: max(side, 0) p_z / r⁴.

// Per point: its surface point p (kernel space, the midpoint of its ray
// starts) and its tangent plane's side(x, y) = side.x + x side.y +
// y side.z; valid 0 where it has none. Shared with Rust (`GpuWeighPoint`
// in irradiance_weight.rs).
struct WeighPoint {
    p: vec3<f32>,
    valid: u32,
    side: vec3<f32>,
    _pad: u32,
}

// The light point (x, y, 0)'s weight at wp (eye/rays.rs's RayStart::weight).
fn irradiance_weight(wp: WeighPoint, x: f32, y: f32) -> f32 {
    let side = wp.side.x + x * wp.side.y + y * wp.side.z;
    let q = vec3<f32>(x, y, 0.0) - wp.p;
    let r2 = dot(q, q);
    return max(side, 0.0) * wp.p.z / (r2 * r2);
}

// shadow_rays.rs's QUAD: the midpoint rule's side over the whole light.
const QUAD: u32 = 32u;

// shadow_rays.rs's light_weight: 4 times the mean weight at the QUAD²
// midpoints of the light of half-extents `half` (under a disk, those
// inside it): ∫ w over the light in units where its area is 4.
fn light_weight(wp: WeighPoint, half: vec2<f32>, disk: bool) -> f32 {
    let step = 2.0 / f32(QUAD);
    var all = 0.0;
    var count = 0u;
    for (var j = 0u; j < QUAD; j++) {
        let v = -1.0 + (f32(j) + 0.5) * step;
        let y = v * half.y;
        for (var i = 0u; i < QUAD; i++) {
            let u = -1.0 + (f32(i) + 0.5) * step;
            if !disk || u * u + v * v <= 1.0 {
                all += irradiance_weight(wp, u * half.x, y);
                count += 1u;
            }
        }
    }
    return all * 4.0 / f32(count);
}
