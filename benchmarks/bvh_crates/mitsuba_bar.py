"""Mitsuba's ``ray_test`` (Embree) on the very rays main.rs traces: the bar.

Not named mitsuba.py: run as a script, that would shadow the mitsuba package.

    .venv/bin/python benchmarks/bvh_crates/mitsuba_bar.py SCENE [--repeats 3]

main.rs runs this after tracing SCENE (it reads the scene from
.cache/bvh_crates/SCENE/ and ours.bits, which main.rs writes: one bit a ray,
set where ``Bvh::occluded`` found it blocked). The rays are rebuilt here bit
for bit: ``exact``'s jitter hash and light point (``Sampling::point`` in
src/trace/shadow_rays.rs) replayed in uint64 and float32 numpy, one f32
operation at a time as the Rust does them. Embree takes no t_min, so the
segment t in (T0, T1) of o + t d becomes the ray from o + T0 d along d with
maxt = T1 - T0 (the same segment up to one rounding of the origin).

Times are of ``ray_test`` alone, its Dr.Jit arrays made before (the most
favourable to Mitsuba), in batches of at most MAX_RAYS_PER_BATCH rays as
softshadow.reference traces them, with one Dr.Jit thread and then all;
medians of --repeats, after a warm-up that compiles the kernel. Prints one
line: ``mitsuba <variant> <build ms> <1-thread ms> <all-threads ms> <rays
differing from ours>``.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import softshadow.reference as reference

ROOT = Path(__file__).resolve().parents[2]
T0 = np.float32(1e-5)
T1 = np.float32(1.0) - np.float32(1e-5)
M64 = np.uint64


def mix(x: np.ndarray) -> np.ndarray:
    """shadow_rays.rs ``hash`` (splitmix64's finaliser), wrapping uint64."""
    x = x + M64(0x9E3779B97F4A7C15)
    x = (x ^ (x >> M64(30))) * M64(0xBF58476D1CE4E5B9)
    x = (x ^ (x >> M64(27))) * M64(0x94D049BB133111EB)
    return x ^ (x >> M64(31))


def unit(h: np.ndarray) -> np.ndarray:
    return (h >> M64(40)).astype(np.float32) * np.float32(1.0 / (1 << 24))


def sample_grid(samples: int, size: list[float]) -> tuple[int, int]:
    """light_shape.rs ``LightShape::sample_grid`` for a rectangle."""
    a = int(np.sqrt(samples))
    while a > 1 and samples % a:
        a -= 1
    a = max(a, 1)
    b = samples // a
    return (b, a) if size[0] >= size[1] else (a, b)


def read_meta(d: Path) -> dict[str, list[float]]:
    return {k: [float(x) for x in v] for k, *v in (line.split() for line in (d / "meta.txt").read_text().splitlines())}


def rays(d: Path, meta: dict[str, list[float]]) -> tuple[np.ndarray, np.ndarray]:
    """Origins and directions (3, R) float32 of every receiver's rays, in
    main.rs's order: receivers by texel index, then sb, then sa."""
    w, h = (int(x) for x in meta["resolution"])
    tx, ty = meta["extent"]
    size = [np.float32(s) for s in meta["light_size"]]
    na, nb = sample_grid(int(meta["samples"][0]), meta["light_size"])
    depth = np.fromfile(d / "depth.f32", dtype="<f4")
    keys = np.flatnonzero(np.isfinite(depth) & (depth > 0))
    # MapGrid::x_of / y_of in f64, then f32; the point (x z, y z, z) in f32.
    i, j = keys % w, keys // w
    x = ((-1.0 + 2.0 * (i + 0.5) / w) * tx).astype(np.float32)
    y = ((1.0 - 2.0 * (j + 0.5) / h) * ty).astype(np.float32)
    z = depth[keys]
    o = np.stack([x * z, y * z, z])  # (3, receivers)
    sb, sa = np.divmod(np.arange(na * nb, dtype=np.uint64), M64(na))
    hs = mix((sb * M64(na) + sa) << M64(1))  # (samples,)
    hk = mix(keys.astype(np.uint64)[:, None] ^ hs[None, :])  # (receivers, samples)
    lx = ((sa.astype(np.float32) + unit(hk)) / np.float32(na) - np.float32(0.5)) * size[0]
    ly = ((sb.astype(np.float32) + unit(mix(hk))) / np.float32(nb) - np.float32(0.5)) * size[1]
    del hk
    dirs = np.stack([lx - o[0][:, None], ly - o[1][:, None], np.broadcast_to(-o[2][:, None], lx.shape)])
    dirs = dirs.reshape(3, -1)
    origins = np.repeat(o, na * nb, axis=1) + T0 * dirs
    return origins.astype(np.float32), dirs.astype(np.float32)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("scene")
    p.add_argument("--repeats", type=int, default=3)
    a = p.parse_args(argv)
    d = ROOT / ".cache" / "bvh_crates" / a.scene
    meta = read_meta(d)
    variant = reference.variant()
    if not variant.startswith("llvm"):
        print(f"mitsuba {variant} skipped: only an LLVM variant traces in bulk")
        return 0
    import drjit as dr
    import mitsuba as mi

    tris = np.fromfile(d / "triangles.f32", dtype="<f4").reshape(-1, 3)
    t = time.perf_counter()
    mesh = mi.Mesh("occluders", len(tris), len(tris) // 3, mi.Properties())
    params = mi.traverse(mesh)
    params["vertex_positions"] = type(params["vertex_positions"])(tris.ravel())
    params["faces"] = type(params["faces"])(np.arange(len(tris), dtype=np.uint32))
    params.update()
    scene = mi.load_dict({"type": "scene", "occluders": mesh})
    build = time.perf_counter() - t

    origins, dirs = rays(d, meta)
    n = origins.shape[1]
    step = reference.MAX_RAYS_PER_BATCH
    batches = []
    for s in range(0, n, step):
        ray = mi.Ray3f(
            mi.Point3f(*(mi.Float(r[s : s + step]) for r in origins)),
            mi.Vector3f(*(mi.Float(r[s : s + step]) for r in dirs)),
        )
        ray.maxt = mi.Float(np.full(min(step, n - s), T1 - T0, dtype=np.float32))
        dr.eval(ray)
        batches.append(ray)
    del origins, dirs

    def trace() -> tuple[float, list]:
        t = time.perf_counter()
        hits = [scene.ray_test(r, coherent=False) for r in batches]
        dr.eval(hits)
        dr.sync_thread()
        return time.perf_counter() - t, hits

    threads = dr.thread_count()
    _, hits = trace()  # warm-up: compiles the kernel
    times: dict[int, list[float]] = {1: [], threads: []}
    for _ in range(a.repeats):
        for k in times:
            dr.set_thread_count(k)
            times[k].append(trace()[0])
    dr.set_thread_count(threads)
    blocked = np.concatenate([np.asarray(h.numpy(), dtype=bool) for h in hits])
    ours = np.unpackbits(np.fromfile(d / "ours.bits", dtype="<u8").view(np.uint8), bitorder="little")
    per = int(meta["samples"][0])
    words = -(-per // 64) * 64
    ours = ours.reshape(-1, words)[:, :per].ravel().astype(bool)
    differ = int((ours != blocked).sum())
    ms = [1e3 * float(np.median(times[k])) for k in (1, threads)]
    print(f"mitsuba {variant} {1e3 * build:.1f} {ms[0]:.1f} {ms[1]:.1f} {differ}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
