// GPU twin of the CPU rasterizer (src/raster.rs): one invocation per tile
// (at most TILE x TILE texels) of a set-up triangle's bounding box walks that
// tile. Tiles bound the work per invocation: it balances big and small
// triangles, and Mesa's lavapipe stops any invocation after 65535 loop
// iterations in all (llvmpipe's loop limiter), which a whole floor triangle
// exceeds. Coverage uses the same fixed-point edge
// functions and tie rule, evaluated exactly in 64 bits emulated with u32
// pairs (WGSL has no i64; the products reach 2^50). Depth is the f32 plane of
// src/depth_plane.rs, evaluated in the same order. Depth min/max go through
// atomicMin/atomicMax on the u32 bits of the (positive) f32 depths: for
// positive floats the bit patterns order like the values.

// Shared with Rust (`RasterParams` in raster.rs; a test compares layouts).
struct RasterParams {
    tile_count: u32,
    width: u32,
    height: u32,
    // Where the nearest (or peeled) layer goes in `maps`, in texels.
    out_offset: u32,
    // Where the farthest layer goes; NONE for none.
    far_offset: u32,
    // The layer to peel beyond; NONE when not peeling.
    prev_offset: u32,
    // 1 + PEEL_GAP as the CPU rounds it.
    peel_factor: f32,
    _pad: u32,
}

// Shared with Rust (`GpuTri` in raster.rs).
struct Tri {
    x: array<i32, 3>,
    y: array<i32, 3>,
    i0: u32,
    i1: u32,
    j0: u32,
    j1: u32,
    w_ref: f32,
    gx: array<f32, 3>,
    gy: array<f32, 3>,
}

// A piece of a triangle's bounding box: texels [i0, i1] x [j0, j1].
// Shared with Rust (`RasterTile` in raster.rs).
struct Tile {
    tri: u32,
    i0: u32,
    i1: u32,
    j0: u32,
    j1: u32,
}

// Shared with Rust (`FillParams` in raster.rs).
struct FillParams {
    offset: u32,
    len: u32,
    value: u32,
    _pad: u32,
}

const NONE: u32 = 0xffffffffu;
const ONE: i32 = 256;
const GROUP: u32 = 64u;

@group(0) @binding(0) var<storage, read_write> maps: array<atomic<u32>>;
@group(0) @binding(1) var<storage, read> tris: array<Tri>;
@group(0) @binding(2) var<uniform> params: RasterParams;
@group(0) @binding(3) var<uniform> fill_params: FillParams;
@group(0) @binding(4) var<storage, read> tiles: array<Tile>;

// add64, neg64 and imul64 (the exact signed product) come from u64.wgsl.

// e + bias > 0 for bias in {0, 1}: e > 0, or e == 0 when the edge owns ties.
fn inside64(e: vec2<u32>, owns_ties: bool) -> bool {
    let hi = bitcast<i32>(e.y);
    if hi != 0 {
        return hi > 0;
    }
    return e.x > 0u || owns_ties;
}

// The CPU's owns_ties: of an edge and its reverse exactly one owns a center on it.
fn owns_ties(dx: i32, dy: i32) -> bool {
    return dy < 0 || (dy == 0 && dx > 0);
}

// 1/Z at texel (i0 + di, j0 + dj): DepthPlane::depth in src/depth_plane.rs,
// the same additions in the same order (the limb products are exact).
fn inv_depth_at(t: Tri, di: u32, dj: u32) -> f32 {
    let fi = f32(di);
    let fj = f32(dj);
    var w = t.w_ref;
    for (var k = 0u; k < 3u; k++) {
        w = w + t.gx[k] * fi;
        w = w + t.gy[k] * fj;
    }
    return w;
}

fn write_depth(idx: u32, z: f32) {
    if params.prev_offset != NONE {
        let floor = bitcast<f32>(atomicLoad(&maps[params.prev_offset + idx]));
        if !(z > floor * params.peel_factor) {
            return;
        }
    }
    let bits = bitcast<u32>(z);
    atomicMin(&maps[params.out_offset + idx], bits);
    if params.far_offset != NONE {
        atomicMax(&maps[params.far_offset + idx], bits);
    }
}

@compute @workgroup_size(64)
fn raster(@builtin(global_invocation_id) gid: vec3<u32>,
          @builtin(num_workgroups) groups: vec3<u32>) {
    let n = gid.x + gid.y * groups.x * GROUP;
    if n >= params.tile_count {
        return;
    }
    let tile = tiles[n];
    let t = tris[tile.tri];
    // Edge k goes from vertex k+1 to vertex k+2 (as in raster_tri).
    var dx: array<i32, 3>;
    var dy: array<i32, 3>;
    var owns: array<bool, 3>;
    var step: array<vec2<u32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        let s = (k + 1u) % 3u;
        let e = (k + 2u) % 3u;
        dx[k] = t.x[e] - t.x[s];
        dy[k] = t.y[e] - t.y[s];
        owns[k] = owns_ties(dx[k], dy[k]);
        step[k] = imul64(-dy[k], ONE);
    }
    let cx0 = i32(tile.i0) * ONE + ONE / 2;
    for (var j = tile.j0; j <= tile.j1; j++) {
        let cy = i32(j) * ONE + ONE / 2;
        var e: array<vec2<u32>, 3>;
        for (var k = 0u; k < 3u; k++) {
            let s = (k + 1u) % 3u;
            e[k] = add64(imul64(dx[k], cy - t.y[s]), neg64(imul64(dy[k], cx0 - t.x[s])));
        }
        let row = j * params.width;
        for (var i = tile.i0; i <= tile.i1; i++) {
            if inside64(e[0], owns[0]) && inside64(e[1], owns[1]) && inside64(e[2], owns[2]) {
                let w = inv_depth_at(t, i - t.i0, j - t.j0);
                if w > 0.0 {
                    write_depth(row + i, 1.0 / w);
                }
            }
            for (var k = 0u; k < 3u; k++) {
                e[k] = add64(e[k], step[k]);
            }
        }
    }
}

// Sets maps[offset .. offset + len] to `value` (+inf's bits before a min,
// 0 before a max).
@compute @workgroup_size(64)
fn fill(@builtin(global_invocation_id) gid: vec3<u32>,
        @builtin(num_workgroups) groups: vec3<u32>) {
    let n = gid.x + gid.y * groups.x * GROUP;
    if n < fill_params.len {
        atomicStore(&maps[fill_params.offset + n], fill_params.value);
    }
}
