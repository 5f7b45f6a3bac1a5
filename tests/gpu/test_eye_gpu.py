"""The eye view on the GPU: ``ss.render(..., backend="gpu")`` against the CPU.

The GPU twin (src/gpu/eye.rs) casts the first hits, the shadow rays, the
occluder layers and the gather at the pixels' points on the device, and
shares the framing (light space, focused grid, biases) with the CPU: the two
images must agree on the pixels where both see the same surface, and the
pixels may differ only where a centre grazes an edge. The configs are the
ones the GPU resolves (no hierarchy, f32 sums), given explicitly so that the
CPU runs the same kernels. Needs an adapter (lavapipe in CI); skipped
without one unless SOFTSHADOW_REQUIRE_GPU=1. Images stay small: lavapipe
renders on the CPU.
"""

from __future__ import annotations

import numpy as np
import pytest

import softshadow as ss

RESOLUTION = (96, 72)

METHODS = {
    "exact": dict(method="exact", samples=64),
    "ssm": dict(method="ssm", hierarchy=False),
    "bitmask": dict(method="bitmask", samples=64, hierarchy=False),
    "bitmask-open": dict(method=ss.Bitmask(samples=64, gaps="open", hierarchy=False)),
    "bitmask-1024": dict(method=ss.Bitmask(samples=1024, hierarchy=False)),
    "bitmask-1024-open-1pass": dict(method=ss.Bitmask(samples=1024, passes=1, gaps="open", hierarchy=False)),
}

LIGHTS = {
    "rect": ss.RectLight(center=(0.3, 4.0, 0.2), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), size=(1.0, 0.6)),
    "sun": ss.DirectionalLight(direction=(0.8, -0.7, -0.3), up=(0.0, 0.0, 1.0), angular_size=(2.0, 2.0)),
}


@pytest.fixture(scope="module")
def scene():
    """A sphere on a floor, and a box beside it."""
    creation = pytest.importorskip("trimesh").creation
    sphere = creation.icosphere(subdivisions=3, radius=0.5)
    sphere.apply_translation((0.1, 0.5, -0.2))
    floor = creation.box(extents=(8.0, 0.2, 8.0))
    floor.apply_translation((0.0, -0.1, 0.0))
    box = creation.box(extents=(0.7, 0.7, 0.6))
    box.apply_translation((-1.1, 0.35, 0.5))
    return ss.Scene(meshes=[sphere, floor, box])


@pytest.fixture(scope="module")
def camera():
    return ss.Camera.look_at(
        eye=(0.9, 2.4, 3.6), target=(-0.2, 0.3, 0.0), up=(0.0, 1.0, 0.0), fov_y=45.0, resolution=RESOLUTION
    )


@pytest.mark.parametrize("light_name", sorted(LIGHTS))
@pytest.mark.parametrize("method_name", sorted(METHODS))
def test_gpu_render_is_the_cpu_render(gpu, scene, camera, light_name, method_name):
    light, options = LIGHTS[light_name], METHODS[method_name]
    cpu = ss.render(scene, light, camera, backend="cpu", **options)
    img = ss.render(scene, light, camera, backend="gpu", **options)
    assert img.backend == "gpu" and cpu.backend == "cpu"
    assert img.visibility.shape == (RESOLUTION[1], RESOLUTION[0]) and img.visibility.dtype == np.float32
    assert np.isfinite(img.visibility).all()
    # The same surfaces on all but the pixels whose centre grazes an edge
    # (the CPU rasterizes its first hits, the GPU casts them).
    same = img.mesh_id == cpu.mesh_id
    assert same.mean() >= 0.995, f"{(~same).sum()} pixels see another mesh"
    # Matching pixels: the same surface point (mesh and f64 position).
    hit = same & cpu.mask & (img.position == cpu.position).all(axis=-1)
    assert hit.sum() >= 0.995 * (same & cpu.mask).sum()
    assert hit.sum() > 0.5 * hit.size
    # The scene has shadows and penumbrae to compare.
    v = cpu.visibility[hit]
    assert (v < 0.5).sum() > 50 and ((v > 0.02) & (v < 0.98)).sum() > 20
    dv = np.abs(img.visibility[hit].astype(np.float64) - cpu.visibility[hit])
    assert dv.mean() <= 1e-4, f"mean |dV| {dv.mean():.2e}, max {dv.max():.2e}"
    # Pixels that see nothing are lit, on both.
    assert (img.visibility[~img.mask] == 1.0).all()
    # The same maps and the same config.
    assert img.map_extent == cpu.map_extent
    passes = getattr(options["method"], "passes", None) or 2
    assert len(img.shadow_maps) == len(cpu.shadow_maps) == (0 if method_name == "exact" else passes)
    for a, b in zip(img.shadow_maps, cpu.shadow_maps, strict=True):
        assert a.shape == b.shape
        assert (a.view(np.uint32) != b.view(np.uint32)).mean() <= 0.005
    if method_name.startswith("bitmask") and all(
        (a.view(np.uint32) == b.view(np.uint32)).all() for a, b in zip(img.shadow_maps, cpu.shadow_maps, strict=True)
    ):
        # Masks OR: on the same maps (lavapipe), the same bits at every
        # pixel that sees the same surface point.
        differ = img.visibility[hit].view(np.uint32) != cpu.visibility[hit].view(np.uint32)
        assert not differ.any(), f"{differ.sum()} pixels differ"
        assert ("corners" in img.timings) == (getattr(img.method, "gaps", "closed") == "closed")
    assert repr(img.method) == repr(cpu.method)
    assert any(k.startswith("gpu") for k in img.timings)


@pytest.mark.parametrize("light_name", sorted(LIGHTS))
@pytest.mark.parametrize(
    "config", [ss.Smoothies(), ss.Smoothies(width=2.0, falloff="sine")], ids=["default", "wide-sine"]
)
def test_gpu_smoothies_render_is_the_cpu_render(gpu, scene, camera, light_name, config):
    light = LIGHTS[light_name]
    cpu = ss.render(scene, light, camera, method=config, backend="cpu")
    img = ss.render(scene, light, camera, method=config, backend="gpu")
    assert img.backend == "gpu" and cpu.backend == "cpu"
    assert np.isfinite(img.visibility).all()
    same = img.mesh_id == cpu.mesh_id
    assert same.mean() >= 0.995, f"{(~same).sum()} pixels see another mesh"
    hit = same & cpu.mask & (img.position == cpu.position).all(axis=-1)
    assert hit.sum() >= 0.995 * (same & cpu.mask).sum()
    v = cpu.visibility[hit]
    assert (v < 0.5).sum() > 50 and ((v > 0.02) & (v < 0.98)).sum() > 20
    dv = np.abs(img.visibility[hit].astype(np.float64) - cpu.visibility[hit])
    assert dv.mean() <= 1e-4, f"mean |dV| {dv.mean():.2e}, max {dv.max():.2e}"
    assert (img.visibility[~img.mask] == 1.0).all()
    # The shadow map: the front layer of every mesh.
    assert img.map_extent == cpu.map_extent
    assert len(img.shadow_maps) == len(cpu.shadow_maps) == 1
    a, b = img.shadow_maps[0], cpu.shadow_maps[0]
    assert a.shape == b.shape and (a.view(np.uint32) != b.view(np.uint32)).mean() <= 0.005
    assert repr(img.method) == repr(cpu.method)
    assert "gpu_smoothie_buffer" in img.timings or "gpu" in img.timings


def test_hard_lights_run_exact_and_refuse_the_map_methods(gpu, scene, camera):
    point = ss.RectLight(center=(0.3, 4.0, 0.2), normal=(0.0, -1.0, 0.0), up=(0.0, 0.0, 1.0), size=(0.0, 0.0))
    cpu = ss.render(scene, point, camera, method="exact", samples=4, backend="cpu")
    img = ss.render(scene, point, camera, method="exact", samples=4, backend="gpu")
    assert img.backend == "gpu"
    assert (img.visibility != cpu.visibility).mean() <= 0.005
    with pytest.raises(ValueError, match="size"):
        ss.render(scene, point, camera, method="ssm", backend="gpu")
    # "auto" keeps a hard light (and a software adapter) on the CPU.
    assert ss.render(scene, point, camera, method="ssm", backend="auto").backend == "cpu"


def test_gpu_refuses_what_it_cannot_run(gpu, scene, camera):
    light = LIGHTS["rect"]
    with pytest.raises(ValueError, match="hierarchy"):
        ss.render(scene, light, camera, method="ssm", hierarchy=True, backend="gpu")
    with pytest.raises(ValueError, match="precision"):
        ss.render(scene, light, camera, method="ssm", precision="f64", backend="gpu")


#: ShadowMapping's parts, each on the GPU against the CPU (512² maps:
#: lavapipe rasterizes on the CPU).
SHADOW_MAPPING = {
    "uniform": dict(focus=False),
    "focused": dict(),
    "lispsm": dict(warp=ss.LiSPSM()),
    "pcf": dict(filter=ss.PCF(size=3)),
    "blur": dict(blur=ss.EyeSpaceBlur(iterations=3)),
    "midpoint": dict(bias=ss.MidpointBias(), filter=ss.PCF(size=1)),
    "linear_lispsm": dict(bias=ss.LinearDepthBias(), warp=ss.LiSPSM(vector="camera")),
}


@pytest.mark.parametrize("light_name", sorted(LIGHTS))
@pytest.mark.parametrize("part", sorted(SHADOW_MAPPING))
def test_gpu_shadow_mapping_is_the_cpu_shadow_mapping(gpu, scene, camera, light_name, part):
    light, kw = LIGHTS[light_name], SHADOW_MAPPING[part]
    method = ss.ShadowMapping(resolution=512, **kw)
    if "warp" in kw and light_name == "rect":
        # LiSPSM warps directional lights only, on every backend.
        with pytest.raises(ValueError, match="^warp: "):
            ss.render(scene, light, camera, method=method, backend="gpu")
        return
    cpu = ss.render(scene, light, camera, method=method, backend="cpu")
    img = ss.render(scene, light, camera, method=method, backend="gpu")
    assert img.backend == "gpu" and cpu.backend == "cpu"
    assert img.visibility.dtype == np.float32 and np.isfinite(img.visibility).all()
    assert img.visibility.min() >= 0 and img.visibility.max() <= 1
    same = img.mesh_id == cpu.mesh_id
    assert same.mean() >= 0.995
    hit = same & cpu.mask & (img.position == cpu.position).all(axis=-1)
    assert hit.sum() > 0.5 * hit.size
    v = cpu.visibility[hit]
    assert (v < 0.5).sum() > 50
    dv = np.abs(img.visibility[hit].astype(np.float64) - cpu.visibility[hit])
    # The same map, lookups and blur (src/gpu/shadow_mapping.rs); the
    # G-buffers differ where a pixel centre grazes an edge, which the blur
    # spreads a few pixels and which may move LiSPSM's depth range.
    assert dv.mean() <= 1e-3, f"mean |dV| {dv.mean():.2e}, max {dv.max():.2e}"
    if "blur" not in kw and "warp" not in kw:
        assert (dv > 1e-5).mean() <= 0.005
    assert (img.visibility[~img.mask] == 1.0).all()
    assert repr(img.method) == repr(cpu.method)
    assert any(k.startswith("gpu") for k in img.timings)


@pytest.mark.parametrize("light_name", sorted(LIGHTS))
@pytest.mark.parametrize("max_taps", [32, 3])
def test_gpu_pcss_render_is_the_cpu_render(gpu, scene, camera, light_name, max_taps):
    """PCSS at the visible points (pcss.wgsl's points mode): the front
    layer is the CPU's bit for bit and the biased points are the CPU's, so
    the depth tests are the same; a point may differ by more than 2e-3 only
    where f32 rounding moves a box end across a texel edge (at most 0.2% of
    the matching pixels)."""
    light = LIGHTS[light_name]
    method = ss.PCSS(max_taps=max_taps)
    cpu = ss.render(scene, light, camera, method=method, backend="cpu")
    img = ss.render(scene, light, camera, method=method, backend="gpu")
    assert img.backend == "gpu" and cpu.backend == "cpu"
    assert np.isfinite(img.visibility).all()
    same = img.mesh_id == cpu.mesh_id
    assert same.mean() >= 0.995
    hit = same & cpu.mask & (img.position == cpu.position).all(axis=-1)
    assert hit.sum() > 0.5 * hit.size
    v = cpu.visibility[hit]
    assert (v < 0.5).sum() > 50 and ((v > 0.02) & (v < 0.98)).sum() > 20
    dv = np.abs(img.visibility[hit].astype(np.float64) - cpu.visibility[hit])
    flips = dv > 2e-3
    assert flips.sum() <= 0.002 * dv.size, f"{flips.sum()} points differ by more than 2e-3"
    assert dv.mean() <= 1e-4, f"mean |dV| {dv.mean():.2e}, max {dv.max():.2e}"
    assert (img.visibility[~img.mask] == 1.0).all()
    assert img.map_extent == cpu.map_extent
    assert len(img.shadow_maps) == len(cpu.shadow_maps) == 1
    assert (img.shadow_maps[0].view(np.uint32) != cpu.shadow_maps[0].view(np.uint32)).mean() <= 0.005
    assert repr(img.method) == repr(cpu.method)
    assert any(k.startswith("gpu") for k in img.timings)
