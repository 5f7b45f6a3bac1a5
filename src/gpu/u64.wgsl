// 64-bit integers as vec2(lo, hi) of u32 (WGSL has no 64-bit types),
// shared by raster.wgsl and shadow_mapping.wgsl (exact edge functions,
// signed, two's complement) and exact.wgsl (exact.rs's u64 hash). Each of
// those modules is this file followed by its own (see SOURCE in raster.rs,
// shadow_mapping.rs and exact.rs).

// Wrapping sum.
fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    return vec2<u32>(lo, a.y + b.y + select(0u, 1u, lo < a.x));
}

// Two's complement negation.
fn neg64(a: vec2<u32>) -> vec2<u32> {
    return add64(~a, vec2<u32>(1u, 0u));
}

// The full 64-bit product of two u32 (schoolbook on 16-bit halves).
fn mul32(a: u32, b: u32) -> vec2<u32> {
    let a0 = a & 0xffffu;
    let a1 = a >> 16u;
    let b0 = b & 0xffffu;
    let b1 = b >> 16u;
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let p11 = a1 * b1;
    let mid = p01 + p10;
    let mid_carry = select(0u, 0x10000u, mid < p01);
    let lo = p00 + (mid << 16u);
    let hi = p11 + (mid >> 16u) + mid_carry + select(0u, 1u, lo < p00);
    return vec2<u32>(lo, hi);
}

// The exact product of two i32 as a signed 64-bit integer.
fn imul64(a: i32, b: i32) -> vec2<u32> {
    let r = mul32(u32(abs(a)), u32(abs(b)));
    if (a < 0) != (b < 0) {
        return neg64(r);
    }
    return r;
}
