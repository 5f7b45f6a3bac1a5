"""Writes the inputs of the BVH crate comparison (main.rs) to .cache/bvh_crates/.

    .venv/bin/python benchmarks/bvh_crates/export.py [--resolution 256] [--samples 256]

Per study scene, in a folder of its name:

- ``triangles.f32``: the occluder triangles in light space (x along the
  light's u, y along v, z = depth along n, from the light's centre), 9
  little-endian f32 a triangle; computed in f64 as the core's
  ``RectLight::to_light`` does ((p - c).u, .v, .n, summed x, y, z in that
  order), then rounded to f32 as the pipeline's ``light_space_triangles``;
- ``depth.f32``: the receiver map's planar depth per texel, row-major (H, W),
  inf where there is no receiver. The receiver of texel (i, j) is the texel
  centre at that depth; its key (the jitter seed of its rays) is j * W + i,
  as in the light view's ``exact`` (main.rs derives the points with
  ``MapGrid``, exactly as ``Exact::visibility_map`` does);
- ``exact.f32``: the package's own ``exact`` visibility for the same map,
  a cross-check that main.rs traces the very rays the pipeline traces;
- ``meta.txt``: ``key value...`` lines: resolution, extent (tangent
  half-extents), light size, triangle count, samples (floats as Python's
  repr, which Rust parses back to the same f64).

Every contender in main.rs reads these files, so all trace identical rays.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

import softshadow as ss
from softshadow import scenes

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / ".cache" / "bvh_crates"
STUDY = ["bunny_floating", "bunny_on_floor", "two_spheres", "torus"]


def light_space(v: np.ndarray, light: ss.RectLight) -> np.ndarray:
    """World points (n, 3) -> light space, in f64, with the core's order of
    operations (a dot product summed x + y + z), so the f32 rounding is the
    pipeline's."""
    d = v - np.asarray(light.center, dtype=np.float64)
    cols = []
    for axis in (light.u, light.v, light.n):
        cols.append(d[:, 0] * axis[0] + d[:, 1] * axis[1] + d[:, 2] * axis[2])
    return np.stack(cols, axis=-1)


#: bench_scale.py's single meshes (125 000 and 2 000 000 triangles of a
#: bumpy sphere over a box floor), seen from their light.
SCALE = ["mesh_125k", "mesh_2m"]


def scene_of(name: str) -> tuple[ss.Scene, ss.RectLight]:
    """A study scene, or one of bench_scale.py's single meshes."""
    if name not in SCALE:
        return scenes.SCENES[name]()
    sys.path.insert(0, str(ROOT / "benchmarks"))
    import bench_scale

    scene, light, _ = bench_scale.scenes(1.0)[name]((64, 48))
    return scene, light


def export(name: str, resolution: int, samples: int) -> None:
    scene, light = scene_of(name)
    sm = ss.soft_shadow_map(scene, light, resolution=resolution, method=ss.Exact(samples=samples))
    tris = np.concatenate([light_space(v, light)[f] for v, f in scene.occluders]).astype(np.float32)
    out = OUT / name
    out.mkdir(parents=True, exist_ok=True)
    tris.reshape(-1, 9).astype("<f4").tofile(out / "triangles.f32")
    np.asarray(sm.receiver_depth, dtype="<f4").tofile(out / "depth.f32")
    np.asarray(sm.visibility, dtype="<f4").tofile(out / "exact.f32")
    w, h = sm.resolution
    meta = {
        "resolution": [w, h],
        "extent": [float(e) for e in sm.extent],
        "light_size": [float(s) for s in light.size],
        "triangles": [len(tris)],
        "samples": [samples],
    }
    (out / "meta.txt").write_text("".join(f"{k} {' '.join(map(repr, v))}\n" for k, v in meta.items()))
    receivers = int(np.isfinite(sm.receiver_depth).sum())
    print(f"{name}: {len(tris)} triangles, {receivers} receivers -> {out.relative_to(ROOT)}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--resolution", type=int, default=256)
    p.add_argument("--samples", type=int, default=256)
    p.add_argument("--scenes", nargs="+", default=STUDY)
    a = p.parse_args(argv)
    for name in a.scenes:
        export(name, a.resolution, a.samples)
    return 0


if __name__ == "__main__":
    sys.exit(main())
