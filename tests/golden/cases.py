"""The golden cases: every method, its options, both entry points and
`ShadowMap.sample`, on the test scenes at small resolutions (CI-sized).

Each case returns named arrays; `case_hashes` hashes their bytes. Only the
string forms of the API are used here, so the same file checks every version.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Iterator

import numpy as np

import softshadow as ss
from softshadow import scenes

RES = 48
SCENE_NAMES = ("bunny_floating", "bunny_on_floor", "square_plate", "torus", "two_spheres")

# (label, keyword arguments of soft_shadow_map, backends that run it)
MESH_CASES: list[tuple[str, dict, tuple[str, ...]]] = [
    ("ssm", {}, ("cpu", "gpu")),
    ("ssm-p1", {"passes": 1}, ("cpu", "gpu")),
    ("ssm-p4", {"passes": 4}, ("cpu", "gpu")),
    ("ssm-occ24", {"occluder_resolution": 24}, ("cpu", "gpu")),
    ("ssm-hier", {"hierarchy": True}, ("cpu",)),
    ("ssm-f64", {"precision": "f64"}, ("cpu",)),
    ("ssm-f16", {"precision": "f16"}, ("cpu",)),
    ("ssm-f16b", {"precision": "f16-batched"}, ("cpu",)),
    ("bitmask16", {"method": "bitmask", "samples": 16}, ("cpu", "gpu")),
    ("bitmask64", {"method": "bitmask", "samples": 64}, ("cpu", "gpu")),
    ("bitmask256", {"method": "bitmask"}, ("cpu", "gpu")),
    ("bitmask-nohier", {"method": "bitmask", "hierarchy": False}, ("cpu", "gpu")),
    ("bitmask-p3", {"method": "bitmask", "samples": 64, "passes": 3}, ("cpu", "gpu")),
    ("exact16", {"method": "exact", "samples": 16}, ("cpu", "gpu")),
    ("exact64", {"method": "exact", "samples": 64}, ("cpu", "gpu")),
    ("auto", {"method": "auto"}, ("cpu", "gpu")),
]

# Methods for the depth-map entry: maps from a CPU mesh shadow map.
DEPTH_CASES: list[tuple[str, dict, tuple[str, ...]]] = [
    ("ssm", {}, ("cpu", "gpu")),
    ("ssm-f16b", {"precision": "f16-batched"}, ("cpu",)),
    ("bitmask64", {"method": "bitmask", "samples": 64}, ("cpu", "gpu")),
    ("bitmask-nohier", {"method": "bitmask", "samples": 64, "hierarchy": False}, ("cpu", "gpu")),
]

# ShadowMap.sample on the CPU (the only backend it has).
SAMPLE_CASES: list[tuple[str, dict]] = [
    ("ssm", {}),
    ("ssm-p3", {"passes": 3}),
    ("bitmask64", {"method": "bitmask", "samples": 64}),
    ("exact16", {"method": "exact", "samples": 16}),
]


def digest(arrays: dict[str, np.ndarray | None]) -> str:
    h = hashlib.sha256()
    for k in sorted(arrays):
        a = arrays[k]
        h.update(k.encode())
        if a is None:
            h.update(b"None")
        else:
            a = np.ascontiguousarray(a)
            h.update(str(a.dtype).encode() + str(a.shape).encode() + a.tobytes())
    return h.hexdigest()[:32]


def _maps(sm: ss.ShadowMap) -> dict[str, np.ndarray | None]:
    out = {
        "visibility": sm.visibility,
        "receiver_depth": sm.receiver_depth,
        "occluder_depth": sm.occluder_depth,
        "occluder_depth_back": sm.occluder_depth_back,
        "extent": np.asarray(sm.extent, np.float64),
    }
    for k, m in enumerate(sm.occluder_depth_middle):
        out[f"middle{k}"] = m
    return out


def _points(sm: ss.ShadowMap) -> np.ndarray:
    pts, _ = sm.receiver_points()
    rng = np.random.default_rng(7)
    pick = rng.choice(len(pts), size=min(200, len(pts)), replace=False)
    return pts[np.sort(pick)]


def cases(backends: list[str]) -> Iterator[tuple[str, Callable[[], dict[str, np.ndarray | None]]]]:
    for name in SCENE_NAMES:
        scene, light = scenes.SCENES[name]()
        for label, kw, where in MESH_CASES:
            for b in backends:
                if b in where:
                    yield (
                        f"mesh/{name}/{label}/{b}",
                        lambda scene=scene, light=light, kw=kw, b=b: _maps(
                            ss.soft_shadow_map(scene, light, resolution=RES, backend=b, **kw)
                        ),
                    )
        base = ss.soft_shadow_map(scene, light, resolution=RES, occluder_resolution=RES // 2)
        for label, kw, where in DEPTH_CASES:
            for b in backends:
                if b in where:
                    yield (
                        f"depth/{name}/{label}/{b}",
                        lambda base=base, light=light, kw=kw, b=b: {
                            "visibility": ss.soft_shadow_map_from_depth(
                                base.occluder_depth,
                                base.receiver_depth,
                                occluder_depth_back=base.occluder_depth_back,
                                light_size=light.size,
                                extent=base.extent,
                                backend=b,
                                **kw,
                            ).visibility
                        },
                    )
        for label, kw in SAMPLE_CASES:
            sm = ss.soft_shadow_map(scene, light, resolution=RES, **kw)
            yield (f"sample/{name}/{label}/cpu", lambda sm=sm: {"visibility": sm.sample(_points(sm))})
    # A point light: the hard shadow map the methods converge to.
    scene, light = scenes.SCENES["two_spheres"]()
    point = ss.RectLight(center=light.center, normal=light.normal, up=light.up, size=(0.0, 0.0))
    # (The GPU refuses point lights.)
    for label, kw in (("ssm", {}), ("bitmask64", {"method": "bitmask", "samples": 64})):
        yield (
            f"point/two_spheres/{label}/cpu",
            lambda kw=kw: {"visibility": ss.soft_shadow_map(scene, point, resolution=RES, **kw).visibility},
        )


def all_hashes(backends: list[str]) -> dict[str, str]:
    return {key: digest(run()) for key, run in cases(backends)}


def GPU_ADAPTER_KEY() -> str:  # noqa: N802
    info = ss.gpu_info()
    return f"{info['name']} ({info['driver']})"
