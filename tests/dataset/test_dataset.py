"""The dataset command: determinism, resume after SIGKILL, Dask, the record, the examples.

Items are small (64x48 eye view, 64² light-view maps) so the file runs in
seconds. Faults (failing items, full disks, damaged folders, hostile specs,
killed workers) are in test_dataset_faults.py.
"""

from __future__ import annotations

import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import softshadow as ss
from softshadow import io
from softshadow.dataset import SpecError, check_output, load_spec, run
from softshadow.dataset.build import build_camera, build_light, build_scene
from softshadow.dataset.item import item_files
from softshadow.dataset.manifest import read_manifest

ROOT = Path(__file__).resolve().parents[2]

SMALL = """
seed = 3
count = 5

[[objects]]
kind = "box"
count = [1, 2]
scale = [0.4, 0.8]
stretch = [1.0, [0.5, 2.0], 1.0]
x = [-1.0, 1.0]
z = [-1.0, 1.0]

[[objects]]
kind = "sphere"
placement = "floating"
height = [0.3, 0.8]
scale = 0.5
albedo = [[0.2, 0.9], 0.5, [0.1, 0.3]]

[[lights]]
kind = "rect"
size = [0.5, 1.5]

[[lights]]
kind = "sun"
angular_size = [0.5, 3.0]

[camera]
resolution = [64, 48]

[method]
name = "ssm"
map_resolution = 64

[outputs]
light_maps = true
previews = true
"""


def write_spec(folder: Path, text: str = SMALL, name: str = "spec.toml") -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    p = folder / name
    p.write_text(text)
    return p


def item_hashes(out: Path) -> dict[str, str]:
    """sha256 of every item file under out/items."""
    return {
        str(p.relative_to(out)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted((out / "items").rglob("*"))
        if p.is_file()
    }


def test_same_files_from_one_worker_two_workers_and_one_item_alone(tmp_path):
    spec = load_spec(write_spec(tmp_path))
    one = run(spec, tmp_path / "one", workers=1, progress=False)
    two = run(spec, tmp_path / "two", workers=2, progress=False)
    alone = run(spec, tmp_path / "alone", items=[3], progress=False)
    assert (one.done, two.done, alone.done) == (5, 5, 1)
    a, b, c = (item_hashes(tmp_path / n) for n in ("one", "two", "alone"))
    assert len(a) == 5 * len(item_files(spec, 0)) >= 5 * 4  # exr, maps, json, png (and shaded png) per item
    assert a == b
    assert c == {k: v for k, v in a.items() if "/00000003." in k}
    # Items differ from each other (the seed reaches every item).
    exrs = [v for k, v in a.items() if k.endswith(".exr") and not k.endswith(".maps.exr")]
    assert len(set(exrs)) == len(exrs)
    for name in ("one", "two"):
        assert check_output(str(tmp_path / name)).complete == list(range(5))


def test_record_rebuilds_the_item_and_files_hold_the_channels(tmp_path):
    spec = load_spec(write_spec(tmp_path))
    run(spec, tmp_path / "out", count=2, progress=False)
    base = tmp_path / "out" / "items" / "00000" / "00000001"
    record = json.loads(base.with_suffix(".json").read_text())
    assert record["k"] == 1 and record["seed"] == 3 and record["spec_hash"] == spec.hash
    assert {"softshadow", "numpy", "trimesh"} <= set(record["versions"])
    assert record["versions"]["softshadow"] == ss.__version__
    assert record["shape"] == [48, 64]
    channels = io.read_exr(base.with_suffix(".exr"))
    # OpenEXR reads shaded.R/G/B back as one (H, W, 3) channel "shaded".
    assert set(channels) == {n[: -len(".R")] if n[-2:] in (".R", ".G", ".B") else n for n in record["channels"]}
    for name in ("V", "depth", "normal.x", "normal.y", "normal.z", "mesh_id", "mask"):
        assert channels[name].shape == (48, 64) and channels[name].dtype == np.float32
    maps = io.read_exr(Path(str(base) + ".maps.exr"))
    assert sorted(maps) == ["layer0", "layer1"] and maps["layer0"].shape == (64, 64)
    # Every sampled parameter is in the record: the scene rebuilt from it renders the same image.
    scene, albedo = build_scene(record, spec.folder)
    light = build_light(record["light"], shading=True)
    albedo = [tuple(a) for a in albedo]
    img = ss.render(scene, light, build_camera(record["camera"]), "ssm", map_resolution=64, albedo=albedo)
    np.testing.assert_array_equal(img.visibility, channels["V"])
    np.testing.assert_array_equal(img.shaded, channels["shaded"])
    np.testing.assert_array_equal(img.unshadowed, channels["unshadowed"])
    assert channels["shaded"].max() > 0 and record["shading"]["applied"]
    # The sampled albedos reach the image: a sphere's RGB albedo has unequal channels.
    sphere = [i for i, o in enumerate(record["objects"]) if o["kind"] == "sphere"][0]
    on_sphere = (channels["mesh_id"] == sphere) & (channels["unshadowed"][..., 1] > 0)
    assert on_sphere.sum() > 20
    ratio = channels["unshadowed"][on_sphere] / channels["unshadowed"][on_sphere][:, 1:2]
    np.testing.assert_allclose(ratio.mean(axis=0), np.array(record["objects"][sphere]["albedo"]) / 0.5, rtol=1e-4)
    np.testing.assert_array_equal(img.mesh_id.astype(np.float32), channels["mesh_id"])
    # mesh ids: the record's objects in order, then the ground.
    assert int(channels["mesh_id"].max()) == len(record["objects"])


def test_auto_with_light_maps_runs_its_map_rule_and_auto_without_traces(tmp_path):
    # The eye view's default call reads no maps (a probe, then the masks): a spec that writes
    # the light-view maps with name = "auto" runs auto's map rule instead.
    text = SMALL.replace('name = "ssm"\nmap_resolution = 64', 'name = "auto"')
    spec = load_spec(write_spec(tmp_path, text))
    assert run(spec, tmp_path / "maps", count=1, progress=False).done == 1
    base = tmp_path / "maps" / "items" / "00000" / "00000000"
    record = json.loads(base.with_suffix(".json").read_text())
    assert record["method"]["config"].startswith("Ssm(passes=2")
    assert sorted(io.read_exr(Path(str(base) + ".maps.exr"))) == ["layer0", "layer1"]
    spec = load_spec(write_spec(tmp_path / "rays", text.replace("light_maps = true\n", "")))
    assert run(spec, tmp_path / "rays" / "out", count=1, progress=False).done == 1
    record = json.loads((tmp_path / "rays" / "out" / "items" / "00000" / "00000000.json").read_text())
    assert record["method"]["config"] == "Exact(samples=256, probe=16, engine='masks')"


def test_zstd_items_hold_the_zip_items_pixels_and_only_that_spec_hash_changes(tmp_path):
    zip_spec = load_spec(write_spec(tmp_path, name="zip.toml"))
    zstd_spec = load_spec(
        write_spec(tmp_path, SMALL.replace("[outputs]\n", '[outputs]\ncompression = "zstd"\n'), "zstd.toml")
    )
    assert zstd_spec.outputs.compression == "zstd" and zip_spec.outputs.compression == "zip"
    # Different bytes, so another spec; the default leaves the hash it had before the field.
    assert zstd_spec.hash != zip_spec.hash
    assert "compression" not in zip_spec.canonical()["outputs"]
    for name, spec in (("zip", zip_spec), ("zstd", zstd_spec)):
        run(spec, tmp_path / name, count=1, progress=False)
        assert check_output(str(tmp_path / name)).ok
    base = Path("items") / "00000" / "00000000"
    a, b = (io.read_exr(tmp_path / n / base.with_suffix(".exr")) for n in ("zip", "zstd"))
    assert sorted(a) == sorted(b)
    for name in a:
        np.testing.assert_array_equal(a[name], b[name])
    maps = [io.read_exr(tmp_path / n / (str(base) + ".maps.exr")) for n in ("zip", "zstd")]
    np.testing.assert_array_equal(maps[0]["layer0"], maps[1]["layer0"])
    # Each file says the compression it was written with.
    openexr = pytest.importorskip("OpenEXR")
    for name in ("zip", "zstd"):
        for f in (base.with_suffix(".exr"), Path(str(base) + ".maps.exr")):
            with openexr.File(str(tmp_path / name / f)) as exr:
                assert exr.header()["compression"] == io.exr_compression(name), (name, f)


def test_views_share_one_scene_and_its_preparation_and_one_view_keeps_the_old_hash(tmp_path):
    from softshadow.dataset import item as item_module
    from softshadow.dataset.sampling import sample_item

    plain = load_spec(write_spec(tmp_path, name="plain.toml"))
    views = load_spec(write_spec(tmp_path, "views = 3\n" + SMALL.replace('name = "ssm"', 'name = "auto"'), "v.toml"))
    assert views.views == 3 and plain.views == 1
    assert "views" not in plain.canonical()
    one = load_spec(write_spec(tmp_path, "views = 1\n" + SMALL, "one.toml"))
    assert one.hash == plain.hash
    items = [sample_item(views, k) for k in range(6)]
    # Items 0-2 share objects and ground, 3-5 others; lights and cameras are each item's own.
    for k in (1, 2):
        assert (items[k]["objects"], items[k]["ground"]) == (items[0]["objects"], items[0]["ground"])
        assert items[k]["camera"] != items[0]["camera"]
    assert items[3]["objects"] != items[0]["objects"]
    # The first item of a scene draws its objects as without views.
    assert sample_item(plain, 3)["objects"] == items[3]["objects"]
    # One process renders a scene's items through one Scene: later items refit its tree.
    item_module._SCENES.clear()
    scenes = [item_module._scene(views, k, items[k])[0] for k in range(4)]
    assert scenes[0] is scenes[1] is scenes[2] and scenes[3] is not scenes[0]
    out = tmp_path / "out"
    assert run(views, out, count=6, workers=1, progress=False).done == 6
    assert check_output(str(out)).complete == list(range(6))
    held = [s.prepared.held for s in (v[0] for v in item_module._SCENES.values())]
    assert held and all(h[0] for h in held)


def test_spec_is_stored_and_another_spec_is_refused(tmp_path):
    spec = load_spec(write_spec(tmp_path))
    out = tmp_path / "out"
    run(spec, out, count=2, progress=False)
    assert (out / "spec.toml").read_text() == SMALL
    more = run(spec, out, count=4, progress=False)  # a larger count extends the dataset
    assert (more.skipped, more.done) == (2, 2)
    assert json.loads((out / "dataset.json").read_text())["count"] == 4
    other = load_spec(write_spec(tmp_path / "b", SMALL.replace("seed = 3", "seed = 4")))
    before = item_hashes(out)
    with pytest.raises(SpecError, match="another spec"):
        run(other, out, progress=False)
    assert item_hashes(out) == before


def _done_lines(out: Path) -> int:
    try:
        return sum('"status":"done"' in line for line in (out / "manifest.jsonl").read_text().splitlines())
    except FileNotFoundError:
        return 0


@pytest.mark.slow
def test_sigkill_halfway_then_resume_gives_the_same_files(tmp_path):
    count = 120
    spec_path = write_spec(tmp_path, SMALL.replace("count = 5", f"count = {count}"))
    spec = load_spec(spec_path)
    whole = tmp_path / "whole"
    run(spec, whole, progress=False)

    killed = tmp_path / "killed"
    cmd = [sys.executable, "-m", "softshadow.dataset", "run", str(spec_path), "--out", str(killed), "--quiet"]
    proc = subprocess.Popen(cmd, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    while _done_lines(killed) < 5 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.005)
    os.killpg(proc.pid, signal.SIGKILL)  # the run and anything it started
    proc.wait()
    done_at_kill = _done_lines(killed)
    assert 5 <= done_at_kill < count, "the kill must land halfway"
    report = check_output(str(killed))
    assert len(report.complete) == done_at_kill and not report.broken
    assert not report.ok

    resumed = run(spec, killed, progress=False)
    assert resumed.skipped == done_at_kill and resumed.done == count - done_at_kill
    assert item_hashes(killed) == item_hashes(whole)
    final = check_output(str(killed))
    assert final.ok and final.complete == list(range(count)) and not final.temporaries


def test_dask_local_cluster_gives_the_same_files_as_local_processes(tmp_path):
    distributed = pytest.importorskip("distributed")
    spec = load_spec(write_spec(tmp_path))
    run(spec, tmp_path / "local", progress=False)
    with (
        distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False, dashboard_address=":0") as cluster,
        distributed.Client(cluster) as client,
    ):
        summary = run(spec, tmp_path / "dask", dask=client, window=2, progress=False)
    assert summary.done == 5 and not summary.failed
    assert item_hashes(tmp_path / "dask") == item_hashes(tmp_path / "local")
    records = read_manifest(str(tmp_path / "dask"))
    assert sorted(records) == list(range(5)) and all(r["status"] == "done" for r in records.values())


@pytest.mark.parametrize("name", ["shadows_ground", "city_sun", "tabletop", "mixed_lights"])
def test_example_specs_run(tmp_path, name):
    spec = load_spec(ROOT / "examples" / f"{name}.toml")
    summary = run(spec, tmp_path / name, count=2, progress=False)
    assert summary.done == 2 and not summary.failed
    report = check_output(str(tmp_path / name))
    assert report.ok and report.complete == [0, 1]
    for k in (0, 1):
        record = json.loads((tmp_path / name / "items" / "00000" / f"0000000{k}.json").read_text())
        channels = io.read_exr(tmp_path / name / "items" / "00000" / f"0000000{k}.exr")
        mask = channels["mask"] > 0
        assert record["objects"], "an example item has objects"
        # One visibility channel per light (V, or V.0, V.1, ... with several lights per item).
        lights = record.get("lights", [record.get("light")])
        names = ["V"] if "light" in record else [f"V.{j}" for j in range(len(lights))]
        assert sorted(c for c in channels if c == "V" or c.startswith("V.")) == names
        # Shadows are in view: some seen surface is (partly) shadowed, some is lit.
        v = np.stack([channels[n] for n in names])
        assert (v[:, mask] < 0.5).any() and (v[:, mask] > 0.99).any()


def test_mitsuba_reference_as_teacher(tmp_path):
    pytest.importorskip("mitsuba")
    text = SMALL.replace('name = "ssm"\nmap_resolution = 64', 'name = "reference"\noptions = { samples = 16 }')
    spec = load_spec(write_spec(tmp_path, text.replace("light_maps = true\n", "")))
    run(spec, tmp_path / "all", count=3, progress=False)
    run(spec, tmp_path / "one", count=3, items=[1], progress=False)
    a, b = item_hashes(tmp_path / "all"), item_hashes(tmp_path / "one")
    assert b == {k: v for k, v in a.items() if "/00000001." in k}
    record = json.loads((tmp_path / "all" / "items" / "00000" / "00000001.json").read_text())
    assert record["method"]["name"] == "reference" and record["method"]["samples"] == 16
    assert record["versions"]["mitsuba"]
    # The teacher sees the same scene: its first hits are the core's.
    scene, _ = build_scene(record, spec.folder)
    img = ss.render(scene, build_light(record["light"], shading=False), build_camera(record["camera"]), "exact")
    mesh_id = io.read_exr(tmp_path / "all" / "items" / "00000" / "00000001.exr")["mesh_id"]
    assert (mesh_id == img.mesh_id).mean() > 0.98
