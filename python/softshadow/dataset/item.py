"""One dataset item: sample, build, render, write (what a worker runs).

Item k's files, under ``outputs.folder`` in subfolders of 1000 items
(``items/00000/00000042.*``):

* ``.exr``: the requested channels, float32, as :meth:`softshadow.Image.channels`
  names them (``V``, ``shaded.*``, ``unshadowed.*``, ``depth``, ``normal.x/y/z``,
  ``position.x/y/z``, ``mesh_id``, ``mask``, ``albedo.*``); with several
  lights per item (``lights_per_item``) the visibility is ``V.0``, ``V.1``, ...
  one per light, and the shading sums the lights;
* ``.maps.exr`` on request: the light-view occluder layers (``layer0`` front,
  ``layer1`` back), planar depth from the light or the sun's orthographic depth;
  with several lights ``layer0.j``, ``layer1.j`` for light j;
* ``.png`` (visibility; with several lights their mean) and ``.shaded.png``
  on request: 8-bit previews;
* ``.json``: the record: every sampled parameter, the seed, k, the spec's
  hash, the resolved method and the versions. Nothing in it depends on the
  machine or the time, so the files are the same bit for bit wherever and
  whenever item k is made; the time it took goes to the manifest.
"""

from __future__ import annotations

import functools
import importlib.metadata
import json
import os
import time
from typing import Any

import numpy as np

from .. import io as ssio
from ..scene import Scene
from . import limits as L
from .build import build_camera, build_light, build_lights, build_scene, record_lights, render_albedo
from .files import write_item_files
from .sampling import item_seed, sample_item, scene_item
from .spec import REFERENCE, Spec, shading_available


def item_base(folder: str, k: int) -> str:
    """The relative path of item k's files without extension."""
    return f"{folder}/{k // L.SHARD:05d}/{k:0{L.ITEM_DIGITS}d}"


def item_files(spec: Spec, k: int) -> dict[str, str]:
    """Item k's files by role (``exr``, ``json``, ``maps``, ``preview``, ``shaded_preview``), relative to --out."""
    base = item_base(spec.outputs.folder, k)
    files = {"exr": base + ".exr", "json": base + ".json"}
    if spec.outputs.light_maps:
        files["maps"] = base + ".maps.exr"
    if spec.outputs.previews:
        files["preview"] = base + ".png"
        if "shaded" in spec.outputs.channels:
            files["shaded_preview"] = base + ".shaded.png"
    return files


def versions(spec: Spec) -> dict[str, str | None]:
    """The versions that made the item (mitsuba only for the reference)."""
    return dict(_versions(spec.method.name == REFERENCE))


@functools.lru_cache(maxsize=2)
def _versions(mitsuba: bool) -> tuple[tuple[str, str | None], ...]:
    """Read once per process: the package metadata took 4 ms an item."""
    import softshadow

    names = ["trimesh", "OpenEXR"] + (["mitsuba"] if mitsuba else [])
    out: dict[str, str | None] = {"softshadow": softshadow.__version__, "numpy": np.__version__}
    for name in names:
        try:
            out[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            out[name] = None
    return tuple(out.items())


def select_channels(all_channels: dict[str, np.ndarray], groups: tuple[str, ...]) -> dict[str, np.ndarray]:
    """The channels of the requested groups (``visibility`` is ``V``, or
    ``V.0``, ``V.1``, ... with several lights; a group ``g`` is the channel
    ``g`` or the channels ``g.*``: ``albedo`` is ``albedo.R/G/B``), in the
    groups' order."""
    out = {}
    for g in groups:
        name = "V" if g == "visibility" else g
        found = {k: v for k, v in all_channels.items() if k == name or k.startswith(name + ".")}
        if not found:
            raise RuntimeError(f"outputs.channels: the render gave no {g!r} channel (it gave {sorted(all_channels)})")
        out.update(found)
    return out


#: The scenes this process built last, by (spec hash, scene item): the
#: items of one scene (``views``) that a process renders reuse its
#: ``Scene`` and so what it prepared (its triangles; the shadow rays' tree,
#: refitted to each camera and light of the same orientation).
_SCENES: dict[tuple[str, int], tuple[Scene, list[np.ndarray]]] = {}
_KEPT_SCENES = 2


def _scene(spec: Spec, k: int, params: dict[str, Any]) -> tuple[Scene, list[np.ndarray]]:
    """Item k's scene and albedos: built, or the one built for another item
    of its scene (its objects are the same by construction)."""
    if spec.views == 1:
        return build_scene(params, spec.folder)
    key = (spec.hash, scene_item(spec, k))
    if key not in _SCENES:
        while len(_SCENES) >= _KEPT_SCENES:
            del _SCENES[next(iter(_SCENES))]
        _SCENES[key] = build_scene(params, spec.folder)
    return _SCENES[key]


def render_item(
    spec: Spec, k: int, threads: int | None
) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray], dict[str, Any]]:
    """Item k's channels (all of them), light-view maps (by channel name) and
    record (without file names)."""
    params = sample_item(spec, k)
    scene, albedo = _scene(spec, k, params)
    camera = build_camera(params["camera"])
    m = spec.method
    record: dict[str, Any] = {"k": k, "seed": spec.seed, "spec_hash": spec.hash, "versions": versions(spec)}
    record.update(params)
    maps: dict[str, np.ndarray] = {}
    if m.name == REFERENCE:
        from ..reference import render_visibility

        if threads is not None:
            _cap_drjit_threads(threads)
        samples = int(m.options.get("samples", 256))
        lights = record_lights(params)
        seeds = [item_seed(spec.seed, k, j) for j in range(len(lights))]
        refs = [
            render_visibility(scene, build_light(p, shading=False), camera, samples, seed=s)
            for p, s in zip(lights, seeds, strict=True)
        ]
        ref = refs[0]  # the G-buffer: every light's run sees the same first hits
        channels: dict[str, np.ndarray] = (
            {f"V.{j}": r.visibility for j, r in enumerate(refs)} if spec.several_lights else {"V": ref.visibility}
        )
        channels["depth"] = ref.depth
        for i, axis in enumerate("xyz"):
            channels[f"position.{axis}"] = ref.position[..., i]
            channels[f"normal.{axis}"] = ref.normal[..., i]
        channels["mesh_id"] = ref.mesh_id.astype(np.float32)
        channels["mask"] = ref.mask.astype(np.float32)
        jitter: int | list[int] = seeds if spec.several_lights else seeds[0]
        record["method"] = {"name": REFERENCE, "samples": ref.samples, "jitter_seed": jitter}
    else:
        from ..api import render

        shading = shading_available()
        light = build_lights(params, shading=shading)
        extra = render_albedo(scene, albedo) if shading else {}
        config, loose = method_call(spec)
        img = render(
            scene, light, camera, config,
            map_resolution=m.map_resolution, normal_offset=m.normal_offset, depth_bias=m.depth_bias,
            backend=m.backend, threads=threads, **extra, **loose,
        )  # fmt: skip
        channels = img.channels()
        parts = img.parts if spec.several_lights else (img,)
        if spec.several_lights:
            record["method"] = {"name": m.name, "config": [repr(p.method) for p in parts], "backend": img.backend}
        else:
            record["method"] = {"name": m.name, "config": repr(img.method), "backend": img.backend}
        if spec.outputs.light_maps:
            maps = _light_maps(parts, several=spec.several_lights)
            about = [
                {
                    "layers": len(p.shadow_maps),
                    "extent": None if p.map_extent is None else list(p.map_extent),
                    "depth_origin": None if p.depth_origin is None else list(p.depth_origin),
                    "depth_range": p.depth_range,
                }
                for p in parts
            ]
            record["light_maps"] = about if spec.several_lights else about[0]
    record["shading"] = {"albedo": _albedo_note(scene), "applied": m.name != REFERENCE and shading_available()}
    return channels, maps, record


def _albedo_note(scene: Scene) -> str:
    """The record's word on where the albedo came from (build.py)."""
    if any(mat is not None for mat in scene.materials):
        return 'per mesh, scene order; the file\'s own colours for the objects with "colors": "file"'
    return "per mesh, scene order"


def _light_maps(parts: tuple[Any, ...], *, several: bool) -> dict[str, np.ndarray]:
    """The light-view layers by channel name: ``layer0``, ``layer1`` (one
    light), or ``layer0.j``, ``layer1.j`` for light j (several; one EXR, so
    one size: the spec fixes the maps' resolution). Empty when the method
    made none."""
    out: dict[str, np.ndarray] = {}
    for j, p in enumerate(parts):
        for i, a in enumerate(p.shadow_maps):
            out[f"layer{i}.{j}" if several else f"layer{i}"] = a
    shapes = {a.shape for a in out.values()}
    if len(shapes) > 1:
        raise RuntimeError(f"outputs.light_maps: the lights' maps have different sizes {sorted(shapes)}")
    return out


def method_call(spec: Spec) -> tuple[Any, dict[str, Any]]:
    """The method an item renders with, and the options given beside it.
    The eye view's default (``name = "auto"`` without a target) traces rays
    and makes no maps: items that write the light-view maps run auto's map
    rule instead (``ssm``'s options given beside ``"auto"`` select it; two
    passes is its own)."""
    from .._core import Auto
    from .spec import make_config

    config = make_config(spec.method)
    if spec.outputs.light_maps and config == Auto():
        return "auto", {"passes": 2}
    return config, {}


def make_item(spec: Spec, out: str, k: int, threads: int | None = None) -> dict[str, Any]:
    """Renders item k and writes its files under ``out`` (all or nothing);
    returns its manifest entry: ``k``, each file's sha256, the seconds taken."""
    t0 = time.perf_counter()
    all_channels, maps, record = render_item(spec, k, threads)
    channels = select_channels(all_channels, spec.outputs.channels)
    files = item_files(spec, k)
    h, w = next(iter(channels.values())).shape
    record["channels"] = list(channels)
    record["shape"] = [h, w]
    record["files"] = {role: os.path.basename(rel) for role, rel in files.items()}
    mode = spec.outputs.compression
    writers: dict[str, Any] = {files["exr"]: lambda p: ssio.write_exr(p, channels, compression=mode)}
    if "maps" in files:
        if not maps:
            raise RuntimeError(f"outputs.light_maps: method {spec.method.name!r} gave no light-view maps")
        writers[files["maps"]] = lambda p: ssio.write_exr(p, maps, compression=mode)
    if "preview" in files:
        writers[files["preview"]] = lambda p: ssio.write_png(p, ssio.to_uint8(_preview_visibility(all_channels)))
    if "shaded_preview" in files:
        shaded = np.stack([channels[n] for n in channels if n.startswith("shaded.")], axis=-1)
        writers[files["shaded_preview"]] = lambda p: ssio.write_png(p, _tone_map(shaded))
    text = json.dumps(record, indent=1, sort_keys=True) + "\n"
    writers[files["json"]] = lambda p: _write_text(p, text)
    hashes = write_item_files(out, writers)
    return {"k": k, "files": hashes, "seconds": round(time.perf_counter() - t0, 6)}


_drjit_threads: int | None = None


def _cap_drjit_threads(threads: int) -> None:
    """Dr.Jit's pool takes every core unless told; ``threads=`` caps it as it caps the core's."""
    global _drjit_threads
    if _drjit_threads != threads:
        from ..reference._mitsuba import _mitsuba

        _, dr = _mitsuba()
        dr.set_thread_count(threads)
        _drjit_threads = threads


def _preview_visibility(channels: dict[str, np.ndarray]) -> np.ndarray:
    """The visibility preview: ``V``, or the mean of ``V.0``, ``V.1``, ... (several lights)."""
    if "V" in channels:
        return channels["V"]
    several = [v for name, v in channels.items() if name.startswith("V.")]
    return np.asarray(np.mean(np.stack(several), axis=0, dtype=np.float64))


def _tone_map(rgb: np.ndarray) -> np.ndarray:
    """Linear RGB to 8-bit with a 2.2 gamma, clipped at 1 (previews only)."""
    x = np.clip(np.nan_to_num(rgb, nan=0.0, posinf=1.0, neginf=0.0), 0.0, 1.0) ** (1.0 / 2.2)
    return ssio.to_uint8(x)


def _write_text(path: str, text: str) -> None:
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)
