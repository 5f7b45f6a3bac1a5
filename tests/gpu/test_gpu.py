"""The GPU backend against the CPU one, and its errors.

GPU tests need an adapter; on a machine without one they are skipped, unless
SOFTSHADOW_REQUIRE_GPU=1 (scripts/test.sh sets it after installing Mesa's
lavapipe) makes a missing adapter a failure. Maps stay small: lavapipe
renders on the CPU.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes

SCENES = ["bunny_floating", "bunny_on_floor", "square_plate", "torus_floating", "two_spheres"]


def silhouette_texels(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Texels on a silhouette edge of either map: covered, with a 4-neighbour
    that is empty or lies across a depth jump (> 1% of the depth)."""
    mask = np.zeros(a.shape, bool)
    for m in (a, b):
        finite = np.isfinite(m)
        p = np.pad(m, 1, constant_values=np.inf)
        for nb in (p[:-2, 1:-1], p[2:, 1:-1], p[1:-1, :-2], p[1:-1, 2:]):
            with np.errstate(invalid="ignore"):
                jump = ~np.isfinite(nb) | (np.abs(nb - m) > 0.01 * np.abs(m))
            mask |= finite & jump
    return mask


def assert_depth_maps_agree(cpu: np.ndarray, gpu: np.ndarray, name: str) -> None:
    """Identical bits except on silhouette edges, where at most 0.5% of the
    texels (and no more than 8) may differ (a real GPU may round 1/w
    differently at a coverage tie; lavapipe gives identical maps)."""
    assert cpu.shape == gpu.shape and gpu.dtype == np.float32, name
    differ = cpu.view(np.uint32) != gpu.view(np.uint32)
    assert differ.sum() <= max(8, differ.size // 200), f"{name}: {differ.sum()} texels differ"
    off_edge = differ & ~silhouette_texels(cpu, gpu)
    assert not off_edge.any(), f"{name}: {off_edge.sum()} differing texels off silhouette edges"


def assert_visibility_agrees(cpu: np.ndarray, gpu: np.ndarray, name: str) -> None:
    dv = np.abs(cpu.astype(np.float64) - gpu)
    assert np.isfinite(gpu).all(), name
    assert dv.mean() <= 1e-4 and dv.max() <= 2e-3, f"{name}: mean {dv.mean():.2e}, max {dv.max():.2e}"


GPU_METHODS = [("ssm", None), ("bitmask", 16), ("bitmask", 256), ("exact", 16)]
MAP_METHODS = GPU_METHODS[:3]


@pytest.mark.parametrize("method, samples", GPU_METHODS)
@pytest.mark.parametrize("passes", [1, 2, 3])
@pytest.mark.parametrize("name", SCENES)
def test_gpu_matches_cpu_on_the_scenes(gpu, name, passes, method, samples):
    scene, light = getattr(scenes, name)()
    kw = dict(resolution=(64, 48), passes=passes, method=method, samples=samples)
    # The GPU has no occluder hierarchy: compare with the CPU's without one.
    c = ss.soft_shadow_map(scene, light, backend="cpu", hierarchy=None if method == "exact" else False, **kw)
    g = ss.soft_shadow_map(scene, light, backend="gpu", **kw)
    assert g.extent == c.extent
    assert_visibility_agrees(c.visibility, g.visibility, name)
    assert_depth_maps_agree(c.receiver_depth, g.receiver_depth, f"{name} receiver")
    if method == "exact":  # traces the triangles: no occluder maps on either backend
        assert g.occluder_depth is None and c.occluder_depth is None
        return
    assert_depth_maps_agree(c.occluder_depth, g.occluder_depth, f"{name} front")
    if passes >= 2:
        assert_depth_maps_agree(c.occluder_depth_back, g.occluder_depth_back, f"{name} back")
    else:
        assert g.occluder_depth_back is None
    assert len(g.occluder_depth_middle) == len(c.occluder_depth_middle) == max(0, passes - 2)
    for k, (a, b) in enumerate(zip(c.occluder_depth_middle, g.occluder_depth_middle, strict=True)):
        assert_depth_maps_agree(a, b, f"{name} middle {k}")


def same_maps(c, g) -> bool:
    """Whether every map of the two results holds the same bits."""
    pairs = [(c.receiver_depth, g.receiver_depth), (c.occluder_depth, g.occluder_depth)]
    if c.occluder_depth_back is not None:
        pairs.append((c.occluder_depth_back, g.occluder_depth_back))
    pairs += list(zip(c.occluder_depth_middle, g.occluder_depth_middle, strict=True))
    return all((a.view(np.uint32) == b.view(np.uint32)).all() for a, b in pairs)


def assert_bitmask_agrees(c, g, name: str) -> None:
    """The bitmask's masks OR, so on the same maps (lavapipe) the GPU's
    visibility is the CPU's bit for bit (hierarchy off); where a real GPU
    rounds a silhouette texel differently, within the usual tolerances."""
    if same_maps(c, g):
        differ = c.visibility.view(np.uint32) != g.visibility.view(np.uint32)
        assert not differ.any(), f"{name}: {differ.sum()} texels differ on the same maps"
    else:
        assert_visibility_agrees(c.visibility, g.visibility, name)


@pytest.mark.parametrize("gaps", ["closed", "open"])
@pytest.mark.parametrize("samples", [16, 1024])
@pytest.mark.parametrize("passes", [1, 2])
@pytest.mark.parametrize("name", SCENES)
def test_gpu_bitmask_is_the_cpus_bit_for_bit(gpu, name, passes, samples, gaps):
    scene, light = getattr(scenes, name)()
    config = ss.Bitmask(samples=samples, passes=passes, gaps=gaps, hierarchy=False)
    c = ss.soft_shadow_map(scene, light, resolution=(64, 48), method=config, backend="cpu")
    g = ss.soft_shadow_map(scene, light, resolution=(64, 48), method=config, backend="gpu")
    assert repr(g.method) == repr(c.method) and g.method.gaps == gaps
    assert_depth_maps_agree(c.occluder_depth, g.occluder_depth, f"{name} front")
    assert_bitmask_agrees(c, g, name)
    # Closed gaps make the quads' corners on the CPU, between two submissions.
    assert ("corners" in g.timings) == (gaps == "closed")


@pytest.mark.parametrize("gaps", ["closed", "open"])
@pytest.mark.parametrize("samples", [64, 1024])
def test_gpu_bitmask_from_depth_maps_is_the_cpus_bit_for_bit(gpu, samples, gaps):
    scene, light = scenes.bunny_floating()
    sm = ss.soft_shadow_map(scene, light, resolution=(48, 40), occluder_resolution=(36, 30), passes=2)
    config = ss.Bitmask(samples=samples, gaps=gaps, hierarchy=False)
    for back in (sm.occluder_depth_back, None):
        kw = dict(light_size=light.size, extent=sm.extent, occluder_depth_back=back, method=config)
        c = ss.soft_shadow_map_from_depth(sm.occluder_depth, sm.receiver_depth, backend="cpu", **kw)
        g = ss.soft_shadow_map_from_depth(sm.occluder_depth, sm.receiver_depth, backend="gpu", **kw)
        assert ((c.visibility > 0.01) & (c.visibility < 0.99)).sum() > 30
        differ = c.visibility.view(np.uint32) != g.visibility.view(np.uint32)
        assert not differ.any(), f"back {back is not None}: {differ.sum()} texels differ"


def test_gpu_bitmask_gaps_change_the_answer(gpu):
    # The quads close the gaps between neighbours: less light in the
    # penumbra than the flat patches let through, on both backends.
    scene, light = scenes.bunny_floating()
    v = {
        gaps: ss.soft_shadow_map(
            scene, light, resolution=48, method=ss.Bitmask(samples=256, gaps=gaps), backend="gpu"
        ).visibility
        for gaps in ("closed", "open")
    }
    assert (v["closed"] != v["open"]).any()
    assert v["closed"].mean() < v["open"].mean()


@pytest.mark.parametrize(
    "config",
    [
        ss.Smoothies(),
        ss.Smoothies(width=2.0, falloff="sine"),
        ss.Smoothies(occluder_resolution=(40, 32)),
    ],
    ids=["default", "wide-sine", "coarser"],
)
@pytest.mark.parametrize("name", SCENES)
def test_gpu_smoothies_match_cpu_on_the_scenes(gpu, name, config):
    # The silhouette and the smoothies are built on the CPU for both; the
    # buffer (f32 on the device, f64 on the CPU) and the lookup run on the GPU.
    scene, light = getattr(scenes, name)()
    c = ss.soft_shadow_map(scene, light, resolution=(64, 48), method=config, backend="cpu")
    g = ss.soft_shadow_map(scene, light, resolution=(64, 48), method=config, backend="gpu")
    assert repr(g.method) == repr(c.method) and g.extent == c.extent
    assert_visibility_agrees(c.visibility, g.visibility, name)
    assert_depth_maps_agree(c.receiver_depth, g.receiver_depth, f"{name} receiver")
    assert_depth_maps_agree(c.occluder_depth, g.occluder_depth, f"{name} front")
    assert g.occluder_depth_back is None and len(g.occluder_depth_middle) == 0
    assert "gpu_smoothie_buffer" in g.timings or "gpu" in g.timings


@pytest.mark.parametrize("method", ["ssm", "bitmask"])
def test_gpu_with_coarser_occluder_maps_and_an_explicit_extent(gpu, method):
    scene, light = scenes.torus_floating()
    kw = dict(resolution=(80, 64), occluder_resolution=32, extent=(0.6, 0.5), passes=2, method=method)
    c = ss.soft_shadow_map(scene, light, backend="cpu", hierarchy=False, **kw)
    g = ss.soft_shadow_map(scene, light, backend="gpu", **kw)
    assert g.occluder_depth.shape == (32, 32)
    assert_visibility_agrees(c.visibility, g.visibility, "torus")
    assert_depth_maps_agree(c.occluder_depth, g.occluder_depth, "torus front")
    assert_depth_maps_agree(c.receiver_depth, g.receiver_depth, "torus receiver")


def test_gpu_reports_device_stage_times(gpu):
    scene, light = scenes.square_plate()
    g = ss.soft_shadow_map(scene, light, resolution=32, backend="gpu")
    stages = set(g.timings)
    assert {"setup", "upload", "device", "readback"} <= stages
    device = {"gpu_raster_receivers", "gpu_raster_occluders", "gpu_row_stats", "gpu_shadow"}
    assert device <= stages or "gpu" in stages
    assert all(t >= 0 for t in g.timings.values())


def test_gpu_info_describes_the_adapter(gpu):
    info = ss.gpu_info()
    assert set(info) == {"name", "backend", "device_type", "driver", "software"}
    assert info["backend"] == "vulkan"
    assert isinstance(info["software"], bool)
    assert info["software"] == (info["device_type"] == "cpu")


def test_auto_takes_the_gpu_only_when_it_is_real(gpu):
    scene, light = scenes.square_plate()
    sm = ss.soft_shadow_map(scene, light, resolution=32, backend="auto")
    on_gpu = any(k.startswith("gpu") for k in sm.timings)
    assert on_gpu == (not gpu["software"])


def test_depth_maps_are_not_traced_on_either_backend():
    z = np.full((8, 8), 2.0, np.float32)
    for backend in ("cpu", "gpu"):
        with pytest.raises(ValueError, match="method: .*traces the occluder triangles"):
            ss.soft_shadow_map_from_depth(z, z * 2, light_size=1.0, extent=0.5, method="exact", backend=backend)


@pytest.mark.parametrize("method, samples", MAP_METHODS)
def test_depth_maps_shaded_on_the_gpu_match_the_cpu(gpu, method, samples):
    scene, light = scenes.bunny_floating()
    sm = ss.soft_shadow_map(scene, light, resolution=(48, 40), occluder_resolution=32, passes=2)
    kw = dict(
        light_size=light.size,
        extent=sm.extent,
        occluder_depth_back=sm.occluder_depth_back,
        method=method,
        samples=samples,
    )
    c = ss.soft_shadow_map_from_depth(sm.occluder_depth, sm.receiver_depth, backend="cpu", hierarchy=False, **kw)
    g = ss.soft_shadow_map_from_depth(sm.occluder_depth, sm.receiver_depth, backend="gpu", **kw)
    assert_visibility_agrees(c.visibility, g.visibility, method)
    assert "gpu_shadow" in g.timings or "gpu" in g.timings
    one = ss.soft_shadow_map_from_depth(
        sm.occluder_depth, sm.receiver_depth, backend="gpu", **{**kw, "occluder_depth_back": None}
    )
    ref = ss.soft_shadow_map_from_depth(
        sm.occluder_depth, sm.receiver_depth, backend="cpu", hierarchy=False, **{**kw, "occluder_depth_back": None}
    )
    assert_visibility_agrees(ref.visibility, one.visibility, f"{method}, one layer")


def test_without_an_adapter_gpu_raises_and_auto_runs_on_the_cpu(monkeypatch):
    # SOFTSHADOW_GPU=off hides every adapter (read on every call).
    monkeypatch.setenv("SOFTSHADOW_GPU", "off")
    scene, light = scenes.square_plate()
    assert ss.gpu_available() is False
    with pytest.raises(ss.GpuUnavailableError, match="SOFTSHADOW_GPU=off"):
        ss.gpu_info()
    with pytest.raises(ss.GpuUnavailableError, match="no GPU available"):
        ss.soft_shadow_map(scene, light, resolution=16, backend="gpu")
    z = np.full((8, 8), 2.0, np.float32)
    with pytest.raises(ss.GpuUnavailableError, match="no GPU available"):
        ss.soft_shadow_map_from_depth(z, z * 2, light_size=1.0, extent=0.5, backend="gpu")
    assert issubclass(ss.GpuUnavailableError, RuntimeError)
    auto = ss.soft_shadow_map(scene, light, resolution=16, backend="auto")
    cpu = ss.soft_shadow_map(scene, light, resolution=16, backend="cpu")
    np.testing.assert_array_equal(auto.visibility, cpu.visibility)


def test_gpu_refuses_what_it_does_not_have_and_defaults_around_it(gpu):
    scene, light = scenes.torus_floating()
    with pytest.raises(ValueError, match="hierarchy: the GPU backend has no occluder hierarchy"):
        ss.soft_shadow_map(scene, light, resolution=32, method="bitmask", hierarchy=True, backend="gpu")
    with pytest.raises(ValueError, match='precision: the GPU backend sums in "f32" only'):
        ss.soft_shadow_map(scene, light, resolution=32, precision="f16", backend="gpu")
    g = ss.soft_shadow_map(scene, light, resolution=32, method="bitmask", samples=16, backend="gpu")
    assert g.method.hierarchy is False
    c = ss.soft_shadow_map(scene, light, resolution=32, method="bitmask", samples=16, backend="cpu")
    assert c.method.hierarchy is True
    # The core refuses them too, whatever the Python layer lets through.
    from softshadow import _core

    occ, rec = g.occluder_depth, g.receiver_depth
    with pytest.raises(ValueError, match="hierarchy"):
        _core.shadow_map_from_depth(
            occ, None, rec, (1.0, 1.0), g.extent, "bitmask", samples=16, hierarchy=True, backend="gpu"
        )
    with pytest.raises(ValueError, match="precision"):
        _core.shadow_map_from_depth(occ, None, rec, (1.0, 1.0), g.extent, "ssm", precision="f64", backend="gpu")


def test_bad_backends_name_the_argument():
    scene, light = scenes.square_plate()
    with pytest.raises(ValueError, match="backend: must be one of"):
        ss.soft_shadow_map(scene, light, resolution=16, backend="cuda")
    with pytest.raises(TypeError, match="backend"):
        ss.soft_shadow_map(scene, light, resolution=16, backend=None)


def test_the_gpu_docs_example_runs(gpu):
    text = (Path(__file__).resolve().parents[2] / "docs" / "gpu.md").read_text()
    block = re.search(r"# GPU backend\n\n```python\n(.*?)```", text, re.S)
    assert block, "the GPU example is missing from docs/gpu.md"
    env: dict = {}
    exec(compile(block.group(1), "docs/gpu.md", "exec"), env)
    assert env["sm"].backend == "gpu"
    assert env["sm"].visibility.shape == (128, 128)
    assert any(k.startswith("gpu") for k in env["sm"].timings)


def assert_pcss_agrees(c, g, name: str) -> None:
    """PCSS on both backends: its depth tests compare the maps' own f32
    depths, so where the maps are bit for bit the same (lavapipe) no test
    flips and |dV| stays within the usual tolerances; where a real GPU rounds
    a silhouette texel differently (assert_depth_maps_agree allows it), a
    box reading that texel may flip a blocker: at most 0.5% of the texels
    (and no more than 8) then exceed 2e-3, and the rest agree as usual."""
    dv = np.abs(c.visibility.astype(np.float64) - g.visibility)
    assert np.isfinite(g.visibility).all(), name
    flips = dv > 2e-3
    same_maps = all(
        (a.view(np.uint32) == b.view(np.uint32)).all()
        for a, b in [(c.receiver_depth, g.receiver_depth), (c.occluder_depth, g.occluder_depth)]
    )
    if same_maps:
        assert not flips.any(), f"{name}: {flips.sum()} texels differ by more than 2e-3 on the same maps"
    assert flips.sum() <= max(8, flips.size // 200), f"{name}: {flips.sum()} flipped texels"
    rest = dv[~flips]
    assert rest.mean() <= 1e-4, f"{name}: mean {rest.mean():.2e}"


@pytest.mark.parametrize("max_taps", [32, 4, 1])
@pytest.mark.parametrize("name", SCENES)
def test_gpu_pcss_matches_cpu_on_the_scenes(gpu, name, max_taps):
    scene, light = getattr(scenes, name)()
    method = ss.PCSS(max_taps=max_taps)
    c = ss.soft_shadow_map(scene, light, resolution=(64, 48), method=method, backend="cpu")
    g = ss.soft_shadow_map(scene, light, resolution=(64, 48), method=method, backend="gpu")
    assert g.backend == "gpu" and repr(g.method) == repr(c.method)
    assert g.extent == c.extent
    assert_depth_maps_agree(c.receiver_depth, g.receiver_depth, f"{name} receiver")
    assert_depth_maps_agree(c.occluder_depth, g.occluder_depth, f"{name} front")
    assert g.occluder_depth_back is None and not g.occluder_depth_middle
    assert_pcss_agrees(c, g, name)
    assert "gpu_shadow" in g.timings or "gpu" in g.timings


def test_gpu_pcss_with_coarser_and_finer_occluder_maps(gpu):
    scene, light = scenes.torus_floating()
    for occ in (32, (160, 128)):
        method = ss.PCSS(max_taps=12, occluder_resolution=occ)
        kw = dict(resolution=(80, 64), extent=(0.6, 0.5), method=method)
        c = ss.soft_shadow_map(scene, light, backend="cpu", **kw)
        g = ss.soft_shadow_map(scene, light, backend="gpu", **kw)
        assert g.occluder_depth.shape == c.occluder_depth.shape
        assert_pcss_agrees(c, g, f"torus {occ}")
        assert ((c.visibility > 0.02) & (c.visibility < 0.98)).sum() > 50


def test_gpu_pcss_from_depth_maps_matches_cpu(gpu):
    scene, light = scenes.bunny_floating()
    sm = ss.soft_shadow_map(scene, light, resolution=(48, 40), occluder_resolution=64, passes=1)
    for method in (ss.PCSS(), ss.PCSS(max_taps=3)):
        kw = dict(light_size=light.size, extent=sm.extent, method=method)
        c = ss.soft_shadow_map_from_depth(sm.occluder_depth, sm.receiver_depth, backend="cpu", **kw)
        g = ss.soft_shadow_map_from_depth(sm.occluder_depth, sm.receiver_depth, backend="gpu", **kw)
        assert_visibility_agrees(c.visibility, g.visibility, repr(method))
        assert (c.visibility < 0.5).sum() > 20


def without_engine(config: object) -> tuple[str, dict]:
    """A config's class and options but `exact`'s engine, which each backend resolves."""
    d = dict(config.to_dict())  # type: ignore[attr-defined]
    d.pop("engine", None)
    return type(config).__name__, d


def test_a_plan_with_measured_layers_and_doubled_maps_runs_the_same_on_the_gpu(gpu):
    """The planner measures the occluders on the CPU whatever the backend;
    the GPU then runs what it planned: one layer, three, and maps at twice
    the output's side, bit for bit the CPU's."""
    from methods.test_auto_plan import setting, side_by_side, stacked

    for make, target, passes in [(side_by_side, 0.01, 1), (stacked, 0.01, 3), (scenes.fence, 0.005, 2)]:
        scene, light = make()
        cpu = ss.soft_shadow_map(scene, light, resolution=64, method=ss.Auto(error=target))
        dev = ss.soft_shadow_map(scene, light, resolution=64, method=ss.Auto(error=target), backend="gpu")
        # Where the estimate (CPU rays either way) sent the call to exact,
        # the planned maps are run again here on both backends.
        # The same plan; the engine is each backend's (the GPU traces rays).
        assert dev.backend == "gpu" and without_engine(dev.method) == without_engine(cpu.method)
        assert setting(dev) == setting(cpu)
        assert setting(cpu).passes == passes
        np.testing.assert_array_equal(dev.visibility, cpu.visibility)
        if cpu.plan is not None and cpu.plan.planned is not None:
            maps = [
                ss.soft_shadow_map(scene, light, resolution=64, extent=cpu.extent, method=setting(cpu), backend=b)
                for b in ("cpu", "gpu")
            ]
            np.testing.assert_array_equal(maps[0].visibility, maps[1].visibility)
    assert setting(cpu).occluder_resolution == (128, 128)
