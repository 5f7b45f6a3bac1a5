// The area of a disk's overlap with a rectangle in f32: disk_clip.rs's
// twins, prepended to ssm.wgsl (the SSM's micro-patches clipped to a
// DiskLight) and to pcss.wgsl (PCSS's filter over the ellipse inscribed in
// its box, the twin of methods/pcf_disk.rs).
//
// asin by Abramowitz and Stegun's 4.4.46 (asin_poly: the device's own asin
// may be far looser), the area of the disk of radius r (at the origin) with
// X <= a (left_half_area), with X <= a and Y <= b (corner, corner_below),
// and of the rectangle [x0, x1] x [y0, y1] within it (disk_overlap, the
// twin of rect_overlap_f32).
fn asin_poly(x: f32) -> f32 {
    let t = min(abs(x), 1.0);
    var p = -0.0012624911;
    p = p * t + 0.00667009;
    p = p * t - 0.017088126;
    p = p * t + 0.03089188;
    p = p * t - 0.050174303;
    p = p * t + 0.08897899;
    p = p * t - 0.2145988;
    p = p * t + 0.5 * PI_F32;
    let y = 0.5 * PI_F32 - sqrt(1.0 - t) * p;
    return select(y, -y, x < 0.0);
}

fn left_half_area(r: f32, a0: f32) -> f32 {
    let a = clamp(a0, -r, r);
    let s = clamp(a / r, -1.0, 1.0);
    return 0.5 * (a * sqrt(max(r * r - a * a, 0.0)) + r * r * asin_poly(s)) + 0.25 * PI_F32 * r * r;
}

fn corner_below(r: f32, a0: f32, b0: f32) -> f32 {
    let b = max(b0, -r);
    let xb = sqrt(max(r * r - b * b, 0.0));
    let a = clamp(a0, -xb, xb);
    return max(left_half_area(r, a) - left_half_area(r, -xb) + b * (a + xb), 0.0);
}

fn corner(r: f32, a0: f32, b: f32) -> f32 {
    let a = clamp(a0, -r, r);
    if b >= 0.0 {
        return 2.0 * left_half_area(r, a) - corner_below(r, a, -b);
    }
    return corner_below(r, a, b);
}

fn disk_overlap(r: f32, x0: f32, x1: f32, y0: f32, y1: f32) -> f32 {
    if !(r > 0.0) || !(x1 > x0) || !(y1 > y0) {
        return 0.0;
    }
    let fx = max(abs(x0), abs(x1));
    let fy = max(abs(y0), abs(y1));
    if fx * fx + fy * fy <= r * r {
        return (x1 - x0) * (y1 - y0);
    }
    let nx = clamp(0.0, x0, x1);
    let ny = clamp(0.0, y0, y1);
    if nx * nx + ny * ny >= r * r {
        return 0.0;
    }
    let area = corner(r, x1, y1) - corner(r, x0, y1) - corner(r, x1, y0) + corner(r, x0, y0);
    return clamp(area, 0.0, min((x1 - x0) * (y1 - y0), PI_F32 * r * r));
}

const PI_F32: f32 = 3.1415927;
