"""Several lights of mixed kinds per item (``lights_per_item``; rect, disk,
sphere, sun), the ``albedo`` channel, and mesh files that keep their own
colours and textures (``colors``); and that specs without them make the
items they made before.

Items are tiny (48x36) so the file runs in seconds.
"""

from __future__ import annotations

import errno
import hashlib
import json
import os
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import softshadow as ss
import softshadow.io
from softshadow import io
from softshadow.dataset import SpecError, StorageError, check_output, load_spec, parse_spec, run
from softshadow.dataset.build import build_camera, build_lights, build_scene, render_albedo
from softshadow.dataset.sampling import item_seed, light_count, sample_item

from .test_dataset import SMALL

trimesh = pytest.importorskip("trimesh")
Image = pytest.importorskip("PIL.Image")
pytest.importorskip("OpenEXR")

TEXTURE = np.array([[[255, 0, 0], [0, 255, 0]], [[0, 0, 255], [255, 255, 0]]], dtype=np.uint8)
"""The asset's 2x2 texture: red, green (top row), blue, yellow; linear 1 or 0 once decoded."""

MIXED = """
seed = 11
count = 8
lights_per_item = [1, 3]

[[objects]]
kind = "box"
scale = 0.5
x = [1.4, 1.8]
z = [-1.0, 1.0]
albedo = [0.2, 0.5, 0.9]

[[objects]]
kind = "mesh"
path = "tex.glb"
placement = "floating"
height = 0.6
scale = 2.0
yaw = 0.0
albedo = 0.3

[[lights]]
kind = "rect"
size = [0.5, 1.0]
radiance = 20.0

[[lights]]
kind = "disk"
radius = [0.2, 0.5]
radiance = 40.0

[[lights]]
kind = "sphere"
radius = [0.1, 0.3]
radiance = 100.0

[[lights]]
kind = "sun"
angular_size = [0.5, 2.0]
irradiance = 2.0

[camera]
elevation = [55.0, 75.0]
distance = [4.5, 5.5]
resolution = [48, 36]

[outputs]
channels = ["visibility", "shaded", "albedo", "depth", "mesh_id", "mask"]
previews = true
"""

KEYS = {
    "rect": {"center", "normal", "up", "size", "radiance", "distance"},
    "disk": {"center", "normal", "radius", "radiance", "distance"},
    "sphere": {"center", "radius", "radiance", "distance"},
    "sun": {"direction", "up", "angular_size", "irradiance"},
}
"""What each kind of light's record holds besides entry, kind, azimuth, elevation."""


def textured_quad(path: Path) -> None:
    """A unit quad in the xz plane, UVs over the whole texture, written as glb."""
    v = np.array([[-0.5, 0.0, -0.5], [0.5, 0.0, -0.5], [0.5, 0.0, 0.5], [-0.5, 0.0, 0.5]])
    f = np.array([[0, 2, 1], [0, 3, 2]])
    uv = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    mesh = trimesh.Trimesh(v, f, process=False)
    material = trimesh.visual.material.PBRMaterial(baseColorTexture=Image.fromarray(TEXTURE))
    mesh.visual = trimesh.visual.TextureVisuals(uv=uv, material=material)
    mesh.export(path)


def write(folder: Path, text: str = MIXED, name: str = "spec.toml") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    if not (folder / "tex.glb").exists():
        textured_quad(folder / "tex.glb")
    p = folder / name
    p.write_text(text)
    return p


def item_hashes(out: Path) -> dict[str, str]:
    return {
        str(p.relative_to(out)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted((out / "items").rglob("*"))
        if p.is_file()
    }


def base(out: Path, k: int) -> Path:
    return out / "items" / "00000" / f"{k:08d}"


def read(out: Path, k: int) -> tuple[dict, dict]:
    b = base(out, k)
    return json.loads(b.with_suffix(".json").read_text()), io.read_exr(b.with_suffix(".exr"))


def test_mixed_lights_and_a_textured_asset_end_to_end(tmp_path):
    spec = load_spec(write(tmp_path))
    assert spec.several_lights and spec.lights_per_item == (1, 3)
    out = tmp_path / "out"
    summary = run(spec, out, progress=False)
    assert summary.done == 8 and not summary.failed
    assert check_output(str(out)).ok
    counts, kinds = [], set()
    seen = []  # the asset's albedo in every item
    for k in range(8):
        record, channels = read(out, k)
        lights = record["lights"]
        assert "light" not in record and 1 <= len(lights) <= 3
        counts.append(len(lights))
        for light in lights:
            kinds.add(light["kind"])
            assert set(light) == {"entry", "kind", "azimuth", "elevation"} | KEYS[light["kind"]]
            assert spec.lights[light["entry"]].kind == light["kind"]
        # One visibility channel per light; the method as it ran per light.
        assert sorted(n for n in channels if n.startswith("V")) == [f"V.{j}" for j in range(len(lights))]
        assert record["channels"][: len(lights)] == [f"V.{j}" for j in range(len(lights))]
        assert len(record["method"]["config"]) == len(lights)
        assert channels["albedo"].shape == (36, 48, 3) and channels["albedo"].dtype == np.float32
        assert base(out, k).with_suffix(".png").exists()
        # The asset keeps its texture; the box and the ground their sampled albedo.
        box, asset = record["objects"]
        assert asset["colors"] == "file" and "colors" not in box
        ids = channels["mesh_id"]
        assert (ids == 1).sum() > 50, "the asset is in view"
        seen.append(channels["albedo"][ids == 1])
        for index, want in ((0, box["albedo"]), (2, record["ground"]["albedo"])):
            got = channels["albedo"][ids == index]
            np.testing.assert_allclose(got, np.broadcast_to(np.float32(want), got.shape), atol=1e-6)
        assert channels["shaded"][channels["mask"] > 0].max() > 0
    assert kinds == {"rect", "disk", "sphere", "sun"}
    assert 1 in counts and max(counts) == 3
    albedo = np.concatenate(seen)
    for texel in ([1, 0, 0], [0, 1, 0], [0, 0, 1], [1, 1, 0]):
        # Bilinear filtering blends the texels; near each texel's centre it is the texel itself.
        assert np.abs(albedo - texel).max(axis=1).min() < 0.1, texel
    assert np.abs(albedo - 0.3).max(axis=1).min() > 0.1  # never the sampled grey

    # The record rebuilds the item: its scene, colours and lights render the same image.
    k = counts.index(3)
    record, channels = read(out, k)
    scene, sampled = build_scene(record, spec.folder)
    assert scene.materials[1].kind == "texture" and scene.materials[0].kind == "constant"
    assert render_albedo(scene, sampled) == {}  # albedo= would override the texture
    lights = build_lights(record, shading=True)
    assert isinstance(lights, list) and len(lights) == 3
    img = ss.render(scene, lights, build_camera(record["camera"]), "auto", **render_albedo(scene, sampled))
    for j in range(3):
        np.testing.assert_array_equal(img.visibility[j], channels[f"V.{j}"])
    np.testing.assert_array_equal(img.albedo, channels["albedo"])
    np.testing.assert_array_equal(img.shaded, channels["shaded"])


def test_an_interrupted_several_light_run_resumes_to_the_same_files_on_any_workers(tmp_path, monkeypatch):
    spec = load_spec(write(tmp_path))
    whole = tmp_path / "whole"
    run(spec, whole, progress=False)
    real = softshadow.io.write_exr
    writes = []

    def failing(path, channels, **kw):
        writes.append(path)
        if len(writes) == 4:  # item 3's EXR: half written, then the disk is full
            Path(path).write_bytes(b"\x76\x2f\x31\x01 half")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        real(path, channels, **kw)

    monkeypatch.setattr(softshadow.io, "write_exr", failing)
    out = tmp_path / "out"
    with pytest.raises(StorageError, match="rerun the same command to resume"):
        run(spec, out, progress=False)
    report = check_output(str(out))
    assert report.complete == [0, 1, 2] and report.missing == [3, 4, 5, 6, 7] and not report.broken
    monkeypatch.setattr(softshadow.io, "write_exr", real)
    resumed = run(spec, out, progress=False)
    assert (resumed.skipped, resumed.done) == (3, 5)
    assert item_hashes(out) == item_hashes(whole)
    # Two worker processes (the spec pickled to them, mesh colours and all) and
    # any item alone give the same files (its lights and their number are item k's own).
    run(spec, tmp_path / "two", workers=2, progress=False)
    assert item_hashes(tmp_path / "two") == item_hashes(whole)
    alone = tmp_path / "alone"
    run(spec, alone, items=[5], progress=False)
    assert item_hashes(alone) == {n: h for n, h in item_hashes(whole).items() if "/00000005." in n}


def test_specs_with_one_light_per_item_keep_their_hash_records_and_channels(tmp_path):
    plain = load_spec(write(tmp_path, SMALL, "plain.toml"))
    # The hash of test_dataset.py's spec before several lights, kinds and colours existed.
    assert plain.hash == "910c2d297f58c6421da59c906d07ebfddd7f8532820cf2676bd5b3eab5cc0a28"
    canonical = plain.canonical()
    assert "lights_per_item" not in canonical and not plain.several_lights
    assert all("radius" not in light for light in canonical["lights"])
    for given in ("1", "[1, 1]"):
        same = load_spec(write(tmp_path, f"lights_per_item = {given}\n" + SMALL, "same.toml"))
        assert same.hash == plain.hash
    params = sample_item(plain, 0)
    assert "light" in params and "lights" not in params
    assert not isinstance(build_lights(params, shading=True), list)  # rendered alone: V, not V.0
    # With several lights per item, the first light of item k is the one-light spec's.
    several = load_spec(write(tmp_path, "lights_per_item = [1, 3]\n" + SMALL, "several.toml"))
    assert several.hash != plain.hash
    counts = [light_count(several, k) for k in range(20)]
    assert set(counts) == {1, 2, 3}
    for k in range(20):
        item = sample_item(several, k)
        assert len(item["lights"]) == counts[k]
        assert item["lights"][0] == sample_item(plain, k)["light"]
        assert (item["objects"], item["camera"]) == (sample_item(plain, k)["objects"], sample_item(plain, k)["camera"])
    assert light_count(load_spec(write(tmp_path, "lights_per_item = 2\n" + SMALL, "two.toml")), 0) == 2
    # A disk's or sphere's radius is part of the spec.
    disk = SMALL.replace('kind = "sun"\nangular_size = [0.5, 3.0]', 'kind = "disk"\nradius = 0.4')
    disk = disk.replace('name = "ssm"\nmap_resolution = 64', 'name = "auto"').replace("light_maps = true\n", "")
    one, other = (load_spec(write(tmp_path, disk.replace("0.4", r), f"d{r}.toml")) for r in ("0.4", "0.3"))
    assert one.canonical()["lights"][1]["radius"] == [0.4, 0.4] and one.hash != other.hash


def _colored_box(path: Path) -> None:
    mesh = trimesh.creation.box()
    mesh.visual.face_colors = [200, 30, 30, 255]
    mesh.export(path)


ONE_MESH = """
seed = 2
count = 2

[[objects]]
kind = "mesh"
path = "MESH"
scale = 1.2
albedo = [0.1, 0.6, 0.3]
COLORS

[[lights]]
kind = "rect"

[camera]
elevation = [40.0, 60.0]
resolution = [48, 36]

[method]
name = "exact"
options = { samples = 16 }

[outputs]
channels = ["visibility", "shaded", "albedo", "mesh_id"]
"""


@pytest.mark.parametrize(
    ("mesh", "colors", "own"),
    [
        ("red.ply", "", True),  # a coloured file keeps its colours by default
        ("red.ply", 'colors = "albedo"', False),  # unless told to use the sampled albedo
        ("plain.glb", "", False),  # a file without colours takes the sampled albedo
    ],
)
def test_a_mesh_file_keeps_its_colours_unless_told_otherwise(tmp_path, mesh, colors, own):
    _colored_box(tmp_path / "red.ply")
    trimesh.creation.box().export(tmp_path / "plain.glb")
    spec = load_spec(write(tmp_path, ONE_MESH.replace("MESH", mesh).replace("COLORS", colors)))
    # Only a file whose own colours are used enters the hash with them: specs
    # from before the field (sampled albedo everywhere) keep their hash.
    assert ("colors" in spec.canonical()["objects"][0]) == own
    run(spec, tmp_path / "out", progress=False)
    record, channels = read(tmp_path / "out", 0)
    assert record["objects"][0].get("colors") == ("file" if own else None)
    on = channels["mesh_id"] == 0
    assert on.sum() > 20
    want = [srgb(200), srgb(30), srgb(30)] if own else record["objects"][0]["albedo"]
    np.testing.assert_allclose(channels["albedo"][on], np.broadcast_to(np.float32(want), (on.sum(), 3)), atol=1e-6)


def srgb(code: int) -> float:
    return float(ss.materials.srgb_to_linear(np.uint8(code)))


def test_several_lights_write_every_lights_maps(tmp_path):
    text = SMALL.replace("seed = 3", "seed = 3\nlights_per_item = [2, 3]")
    spec = load_spec(write(tmp_path, text))
    run(spec, tmp_path / "out", count=2, progress=False)
    assert check_output(str(tmp_path / "out")).ok
    for k in range(2):
        record, channels = read(tmp_path / "out", k)
        n = len(record["lights"])
        maps = io.read_exr(Path(str(base(tmp_path / "out", k)) + ".maps.exr"))
        assert sorted(maps) == sorted(f"layer{i}.{j}" for i in range(2) for j in range(n))
        assert {a.shape for a in maps.values()} == {(64, 64)}
        assert [m["layers"] for m in record["light_maps"]] == [2] * n
        assert sorted(n for n in channels if n.startswith("V")) == [f"V.{j}" for j in range(n)]


def _spec(**top):
    data = {
        "objects": [{"kind": "box"}],
        "lights": [{"kind": "rect"}, {"kind": "disk"}],
        "camera": {"resolution": [8, 8]},
    }
    data.update(top)
    return data


REFUSED = [
    (
        {"lights": [{"kind": "rect"}, {"kind": "sphere"}], "method": {"name": "pcss"}},
        r"method.name: 'pcss' cannot shade lights\[1\], of kind = 'sphere'.*\"exact\"",
    ),
    (
        {"lights": [{"kind": "rect"}, {"kind": "sphere"}], "method": {"name": "bitmask"}},
        r"method.name: 'bitmask' cannot shade lights\[1\], of kind = 'sphere'",
    ),
    (
        {"lights": [{"kind": "sun"}, {"kind": "sphere"}], "method": {"name": "shadow_mapping"}},
        r"method.name: 'shadow_mapping' cannot shade lights\[1\], of kind = 'sphere'",
    ),
    (
        {"lights": [{"kind": "rect"}, {"kind": "sphere"}], "outputs": {"light_maps": True}},
        r"outputs.light_maps: method 'auto' makes no light-view maps for lights\[1\], of kind = 'sphere' \(its",
    ),
    (
        {"lights": [{"kind": "rect"}, {"kind": "sun"}], "lights_per_item": [1, 2], "outputs": {"light_maps": True}},
        "outputs.light_maps: with several lights per item .* set method.map_resolution",
    ),
    ({"lights": [{"kind": "sphere", "radius": 4.0}]}, "lights.0..radius: a sphere's radius must stay below"),
    ({"lights": [{"kind": "rect", "radius": 1.0}]}, r'lights\[0\].radius: only for kind = "disk" or "sphere"'),
    ({"lights": [{"kind": "sun", "target": [0, 0, 0]}]}, r'lights\[0\].target: only for kind = "rect", "disk" or'),
    ({"lights": [{"kind": "disk", "aspect": 2.0}]}, r'lights\[0\].aspect: only for kind = "rect"'),
    ({"lights": [{"kind": "sphere", "angular_size": 2.0}]}, r'lights\[0\].angular_size: only for kind = "sun"'),
    ({"lights": [{"kind": "disk", "radius": 0.0}]}, r"lights\[0\].radius: must be a finite number"),
    ({"lights": [{"kind": "lamp"}]}, r"lights\[0\].kind: must be one of \['rect', 'disk', 'sphere', 'sun'\]"),
    ({"lights_per_item": [0, 2]}, r"lights_per_item: must be an integer or \[low, high\] .* got \[0, 2\]"),
    ({"lights_per_item": 33}, r"lights_per_item: .*<= 32, got 33"),
    ({"lights_per_item": [3, 1]}, "lights_per_item: must be"),
    ({"objects": [{"kind": "box", "colors": "file"}]}, r'objects\[0\].colors: only for kind = "mesh"'),
    (
        {"method": {"name": "reference"}, "outputs": {"channels": ["albedo"]}},
        "outputs.channels: 'albedo' is not available|method.name: 'reference' needs Mitsuba",
    ),
]


@pytest.mark.parametrize(
    ("top", "message"), REFUSED, ids=[f"{m.split(':')[0]}-{i}" for i, (_, m) in enumerate(REFUSED)]
)
def test_specs_the_lights_or_the_method_cannot_make_are_refused(top, message):
    with pytest.raises(SpecError, match=message):
        parse_spec(_spec(**top))


def test_methods_that_shade_every_kind_are_accepted():
    for method in ({"name": "auto"}, {"name": "exact"}, {"name": "auto", "options": {"error": 0.01}}):
        spec = parse_spec(_spec(method=method, lights_per_item=[1, 32]))
        assert spec.lights_per_item == (1, 32)
    # A target under a sphere plans exact and checks its estimate.
    every = [{"kind": "rect"}, {"kind": "disk"}, {"kind": "sphere"}, {"kind": "sun"}]
    parse_spec(_spec(lights=every, method={"name": "auto", "options": {"error": 0.01}}))
    # shadow_mapping traces no disk but maps it; a sphere it refuses (above).
    parse_spec(_spec(method={"name": "shadow_mapping"}))
    with pytest.raises(SpecError, match="colors: must be one of"):
        parse_spec(_spec(objects=[{"kind": "mesh", "path": "x.glb", "colors": "texture"}]))


def test_the_reference_renders_each_light_with_its_own_jitter(tmp_path, monkeypatch):
    """Mitsuba may be missing: a stand-in teacher (exact's image) takes its place."""
    import importlib.util

    import softshadow.reference as reference

    real_find = importlib.util.find_spec

    def find_spec(name, *args):
        return object() if name == "mitsuba" else real_find(name, *args)

    monkeypatch.setattr(importlib.util, "find_spec", find_spec)
    calls = []

    def teacher(scene, light, camera, samples, *, seed):
        calls.append((type(light).__name__, seed))
        img = ss.render(scene, light, camera, "exact", samples=16)
        return SimpleNamespace(
            visibility=img.visibility, depth=img.depth, position=img.position, normal=img.normal,
            mesh_id=img.mesh_id, mask=img.mask, samples=samples,
        )  # fmt: skip

    monkeypatch.setattr(reference, "render_visibility", teacher)
    text = MIXED.replace("[outputs]", '[method]\nname = "reference"\noptions = { samples = 16 }\n\n[outputs]')
    text = text.replace('"shaded", "albedo", ', "")
    spec = load_spec(write(tmp_path, text))
    run(spec, tmp_path / "out", count=3, progress=False)
    for k in range(3):
        record, channels = read(tmp_path / "out", k)
        n = len(record["lights"])
        seeds = [item_seed(spec.seed, k, j) for j in range(n)]
        assert record["method"]["jitter_seed"] == seeds and len(set(seeds)) == n
        assert seeds[0] == item_seed(spec.seed, k)  # the first light's is the one-light item's
        assert sorted(c for c in channels if c.startswith("V")) == [f"V.{j}" for j in range(n)]
    assert len(calls) == sum(len(read(tmp_path / "out", k)[0]["lights"]) for k in range(3))
