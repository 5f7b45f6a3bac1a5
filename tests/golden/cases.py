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
    yield from _more_light_view_cases(backends)
    yield from _eye_view_cases(backends)


# The eye view (`render`): every method family and option group, both
# backends where they run; the G-buffer, the shaded images, the maps and the
# resolved config are hashed with the visibility.
EYE_RES = (48, 36)
EYE_SCENE_NAMES = ("bunny_on_floor", "torus", "contact_boxes", "city")
ALL = ("cpu", "gpu")


def _eye_cases() -> list[tuple[str, Callable[[], object], tuple[str, ...]]]:
    return [
        ("default", lambda: "auto", ALL),
        ("ssm", lambda: "ssm", ALL),
        ("ssm-p3", lambda: ss.Ssm(passes=3), ALL),
        ("bitmask64", lambda: ss.Bitmask(samples=64), ALL),
        ("bitmask-open", lambda: ss.Bitmask(samples=64, gaps="open"), ALL),
        ("exact16", lambda: ss.Exact(samples=16), ALL),
        ("auto-error", lambda: ss.Auto(error=0.02), ALL),
        ("pcss", lambda: ss.PCSS(), ALL),
        ("pcss-taps", lambda: ss.PCSS(max_taps=16, occluder_resolution=32), ALL),
        ("smoothies", lambda: ss.Smoothies(), ALL),
        ("smoothies-linear", lambda: ss.Smoothies(width=0.05, falloff="linear"), ALL),
        ("sm", lambda: ss.ShadowMapping(), ALL),
        ("sm-pcf", lambda: ss.ShadowMapping(filter=ss.PCF(size=3)), ALL),
        ("sm-slope", lambda: ss.ShadowMapping(bias=ss.SlopeScaleBias(constant=1.0, slope=2.0)), ALL),
        ("sm-linear", lambda: ss.ShadowMapping(bias=ss.LinearDepthBias()), ALL),
        ("sm-back", lambda: ss.ShadowMapping(bias=ss.BackFaces()), ALL),
        ("sm-mid", lambda: ss.ShadowMapping(bias=ss.MidpointBias()), ALL),
        ("sm-const", lambda: ss.ShadowMapping(bias=ss.ConstantBias(constant=0.01)), ALL),
        ("sm-lispsm", lambda: ss.ShadowMapping(warp=ss.LiSPSM(), resolution=64), ALL),
        ("sm-lispsm-view", lambda: ss.ShadowMapping(warp=ss.LiSPSM(n=2.0, vector="camera")), ALL),
        ("sm-blur", lambda: ss.ShadowMapping(blur=ss.EyeSpaceBlur(iterations=2, radius=1.5)), ALL),
        ("sm-nofocus", lambda: ss.ShadowMapping(focus=False), ALL),
    ]


# Keyword variants of `render` on one method (biases, map resolution,
# albedo, loose options).
EYE_KW_CASES: list[tuple[str, dict, tuple[str, ...]]] = [
    ("bias", {"method": "bitmask", "samples": 64, "normal_offset": 1.0, "depth_bias": 0.0}, ALL),
    ("mapres", {"method": "ssm", "map_resolution": (40, 24)}, ALL),
    ("albedo", {"method": "ssm", "albedo": [0.2, 0.5, 0.9]}, ALL),
    ("loose", {"method": "bitmask", "samples": 16, "passes": 3, "hierarchy": False}, ALL),
]


def _image(img: ss.Image) -> dict[str, np.ndarray | None]:
    out: dict[str, np.ndarray | None] = {
        "visibility": img.visibility,
        "shaded": img.shaded,
        "unshadowed": img.unshadowed,
        "albedo": img.albedo,
        "depth": img.depth,
        "position": img.position,
        "normal": img.normal,
        "mesh_id": img.mesh_id,
        "map_extent": None if img.map_extent is None else np.asarray(img.map_extent, np.float64),
        "depth_origin": None if img.depth_origin is None else np.asarray(img.depth_origin, np.float64),
        "depth_range": None if img.depth_range is None else np.asarray([img.depth_range], np.float64),
        "method": np.frombuffer(repr(img.method).encode(), np.uint8),
    }
    for k, m in enumerate(img.shadow_maps):
        out[f"map{k}"] = m
    if img.plan is not None:
        # The error estimate is a timed measurement (how many pixels it
        # traces depends on the call's time), not a result: left out.
        kept = tuple(d for d in img.plan.decisions if d.name != "estimate")
        plan = ss.Plan(kept, img.plan.method)
        out["plan"] = np.frombuffer(str(plan).encode(), np.uint8)
    return out


def _light_view_sun() -> ss.DirectionalLight:
    return ss.DirectionalLight(direction=(0.3, -1.0, 0.2), up=(0.0, 0.0, 1.0), angular_size=(2.0, 2.0))


def _eye_view_cases(backends: list[str]) -> Iterator[tuple[str, Callable[[], dict[str, np.ndarray | None]]]]:
    from softshadow.scenes.eye_view import EYE_SCENES

    for name in EYE_SCENE_NAMES:
        scene, light, cam = EYE_SCENES[name](EYE_RES)
        for label, method, where in _eye_cases():
            if label.startswith("sm-lispsm") and name != "city":
                continue  # LiSPSM warps the sun's maps only
            for b in backends:
                if b in where:
                    yield (
                        f"eye/{name}/{label}/{b}",
                        lambda scene=scene, light=light, cam=cam, method=method, b=b: _image(
                            ss.render(scene, light, cam, method(), backend=b)
                        ),
                    )
        for label, kw, where in EYE_KW_CASES:
            for b in backends:
                if b in where:
                    yield (
                        f"eye/{name}/{label}/{b}",
                        lambda scene=scene, light=light, cam=cam, kw=kw, b=b: _image(
                            ss.render(scene, light, cam, backend=b, **kw)
                        ),
                    )
    # A hard light: exact's one ray, ShadowMapping on either backend.
    scene, light, cam = EYE_SCENES["bunny_on_floor"](EYE_RES)
    point = ss.RectLight(center=light.center, normal=light.normal, up=light.up, size=(0.0, 0.0))
    for label, method, where in (("exact", "exact", ALL), ("ssm", "ssm", ("cpu",)), ("sm", "shadow_mapping", ALL)):
        for b in backends:
            if b in where:
                yield (
                    f"eye-point/bunny_on_floor/{label}/{b}",
                    lambda method=method, b=b: _image(ss.render(scene, point, cam, method, backend=b)),
                )
    # Disks and spheres (issue 31): a disk traced and on the bitmask's
    # samples on it, a sphere traced (CPU), and three lights in one call.
    disk = ss.DiskLight(light.center, light.normal, 0.5, radiance=(1.0, 0.8, 0.6))
    sphere = ss.SphereLight(light.center, 0.4, radiance=2.0)
    shaped = (
        ("disk-exact16", disk, ss.Exact(samples=16), ALL),
        ("disk-bitmask64", disk, ss.Bitmask(samples=64), ALL),
        ("sphere-exact16", sphere, ss.Exact(samples=16), ("cpu",)),
        ("sphere-default", sphere, "auto", ("cpu",)),
        ("three-lights", [light, disk, sphere], "auto", ("cpu",)),
    )
    for label, lt, method, where in shaped:
        for b in backends:
            if b in where:
                yield (
                    f"eye-lights/bunny_on_floor/{label}/{b}",
                    lambda lt=lt, method=method, b=b: _image(ss.render(scene, lt, cam, method, backend=b)),
                )


# Light-view maps of a scene shadowing itself (CPU only) and under a sun.
SELF_CASES: list[tuple[str, dict, tuple[str, ...]]] = [
    ("ssm", {}, ("cpu",)),
    ("bitmask64", {"method": "bitmask", "samples": 64}, ("cpu",)),
    ("exact16", {"method": "exact", "samples": 16}, ("cpu",)),
    ("bias", {"method": "ssm", "normal_offset": 1.0, "depth_bias": 2.0}, ("cpu",)),
]
SUN_CASES: list[tuple[str, dict, tuple[str, ...]]] = [
    ("ssm", {}, ALL),
    ("bitmask64", {"method": "bitmask", "samples": 64}, ALL),
    ("exact16", {"method": "exact", "samples": 16}, ALL),
    ("extent", {"method": "ssm", "extent": (3.0, 2.0)}, ALL),
]
# Planned light-view maps (an error target: no timing in the decisions).
PLAN_CASES: list[tuple[str, Callable[[], object], tuple[str, ...]]] = [
    ("auto-error01", lambda: ss.Auto(error=0.01), ALL),
    ("auto-error005", lambda: ss.Auto(error=0.005), ALL),
]


def _planned(sm: ss.ShadowMap) -> dict[str, np.ndarray | None]:
    out = _maps(sm)
    out["method"] = np.frombuffer(repr(sm.method).encode(), np.uint8)
    if sm.plan is not None:
        # The estimate decision says how long it took: left out, as the
        # eye view's (its numbers from a fixed draw show in the verdict).
        kept = tuple(d for d in sm.plan.decisions if d.name != "estimate")
        out["plan"] = np.frombuffer(str(ss.Plan(kept, sm.plan.method)).encode(), np.uint8)
    return out


def _more_light_view_cases(backends: list[str]) -> Iterator[tuple[str, Callable[[], dict[str, np.ndarray | None]]]]:
    from softshadow.scenes.eye_view import EYE_SCENES

    for name in ("bunny_on_floor", "contact_boxes"):
        scene, _, _ = EYE_SCENES[name](EYE_RES)
        light = scenes.default_light()
        for label, kw, where in SELF_CASES:
            for b in backends:
                if b in where:
                    yield (
                        f"self/{name}/{label}/{b}",
                        lambda scene=scene, light=light, kw=kw: _maps(
                            ss.soft_shadow_map(scene, light, resolution=RES, **kw)
                        ),
                    )
    for name in ("bunny_on_floor", "two_spheres"):
        scene, _ = scenes.SCENES[name]()
        sun = _light_view_sun()
        for label, kw, where in SUN_CASES:
            for b in backends:
                if b in where:
                    yield (
                        f"sun/{name}/{label}/{b}",
                        lambda scene=scene, sun=sun, kw=kw, b=b: _maps(
                            ss.soft_shadow_map(scene, sun, resolution=RES, backend=b, **kw)
                        ),
                    )
        base = ss.soft_shadow_map(scene, sun, resolution=RES)
        for b in backends:
            yield (
                f"sun-depth/{name}/ssm/{b}",
                lambda base=base, sun=sun, b=b: {
                    "visibility": ss.soft_shadow_map_from_depth(
                        base.occluder_depth,
                        base.receiver_depth,
                        occluder_depth_back=base.occluder_depth_back,
                        angular_size=sun.angular_size,
                        extent=base.extent,
                        backend=b,
                    ).visibility
                },
            )
        yield (f"sun-sample/{name}/ssm/cpu", lambda base=base: {"visibility": base.sample(_points(base))})
    for name in ("bunny_floating", "square_plate"):
        scene, light = scenes.SCENES[name]()
        for label, method, where in PLAN_CASES:
            for b in backends:
                if b in where:
                    yield (
                        f"plan/{name}/{label}/{b}",
                        lambda scene=scene, light=light, method=method, b=b: _planned(
                            ss.soft_shadow_map(scene, light, resolution=64, method=method(), backend=b)
                        ),
                    )


def all_hashes(backends: list[str]) -> dict[str, str]:
    return {key: digest(run()) for key, run in cases(backends)}


def GPU_ADAPTER_KEY() -> str:  # noqa: N802
    info = ss.gpu_info()
    return f"{info['name']} ({info['driver']})"
