"""GPU ``exact`` against CPU ``exact`` on scenes as users build them (issue 28).

Both backends trace the same rays: the same stratified sample pattern per
pixel (eye view) and per texel (light view), keyed by the pixel's or texel's
flat index, against the same BVH with the same ray-triangle test. Before,
the eye view keyed a pixel's jitter by its rank among the visible pixels: a
single pixel that one backend's first hits saw and the other's did not (a
centre grazing an edge: the CPU rasterizes, the GPU casts) gave every later
pixel another pattern, and 1.4-32% of the pixels differed. The bar: mean
|dV| <= 1e-4 and at most 0.1% of the pixels differing, over the pixels both
see on the same mesh (what remains are first hits on another triangle of
the same mesh, at edges). Needs an adapter (lavapipe in CI).
"""

from __future__ import annotations

import numpy as np
import pytest

import softshadow as ss
from softshadow.scenes import as_built

# Each scene at a resolution where the two backends' first hits disagree on
# a pixel early in the image (found on lavapipe), so that a rank-keyed
# pattern would shift most of the image. open_assets: open meshes with ~30%
# of faces flipped, zero-area triangles, the teapot as a triangle soup;
# crowd: 338 787 triangles.
EYE_CASES = {
    "open_assets": ((120, 90), 16),
    "crowd": ((200, 150), 16),
}


def _agreement(a: np.ndarray, b: np.ndarray) -> tuple[float, float, float]:
    d = np.abs(a.astype(np.float64) - b.astype(np.float64))
    return float(d.mean()), float((d > 1e-6).mean()), float(d.max())


@pytest.mark.parametrize("name", sorted(EYE_CASES))
def test_gpu_exact_render_is_the_cpu_exact_render(gpu, name):
    resolution, samples = EYE_CASES[name]
    scene, light, camera = as_built.SCENES[name](resolution)
    method = ss.Exact(samples=samples)
    a = ss.render(scene, light, camera, method=method, backend="cpu")
    b = ss.render(scene, light, camera, method=method, backend="gpu")
    assert b.backend == "gpu"
    same = a.mask & b.mask & (a.mesh_id == b.mesh_id)
    assert same.sum() >= 0.99 * a.mask.sum()
    v = a.visibility[same]
    # Penumbrae to get wrong.
    assert ((v > 0.02) & (v < 0.98)).sum() > 50
    mean, differ, worst = _agreement(a.visibility[same], b.visibility[same])
    assert mean <= 1e-4 and differ <= 1e-3, (mean, differ, worst)


def test_gpu_exact_light_view_is_the_cpu_exact_on_a_large_scene(gpu):
    # crowd's 338 775 occluder triangles over its floor.
    scene, light, _ = as_built.SCENES["crowd"]((16, 12))
    split = ss.Scene(occluders=scene.meshes[1:], receivers=scene.meshes[:1])
    assert sum(len(f) for _, f in split.occluders) >= 100_000
    maps = [
        ss.soft_shadow_map(split, light, resolution=128, method="exact", samples=16, backend=be).visibility
        for be in ("cpu", "gpu")
    ]
    a = maps[0]
    assert ((a > 0.02) & (a < 0.98)).sum() > 50
    mean, differ, worst = _agreement(*maps)
    assert mean <= 1e-4 and differ <= 1e-3, (mean, differ, worst)
