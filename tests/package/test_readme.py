"""The README's usage example runs as written (the README stays true)."""

import re
from pathlib import Path

import numpy as np
import pytest

README = Path(__file__).resolve().parents[2] / "README.md"


def test_usage_example_runs():
    pytest.importorskip("trimesh")
    text = README.read_text()
    block = re.search(r"```python\n(import numpy as np, trimesh, softshadow as ss.*?)```", text, re.S)
    assert block, "the usage example is missing from the README"
    env: dict = {}
    exec(compile(block.group(1), "README.md", "exec"), env)
    sm, fast, accurate = env["sm"], env["fast"], env["accurate"]
    assert sm.visibility.shape == (256, 256) and sm.visibility.min() < 0.05
    v = sm.sample(env["points"])
    assert v[0] < 0.2 and v[1] == 1.0  # under the bunny; far outside its shadow
    assert np.abs(fast.visibility - sm.visibility).mean() < 0.01
    ss = env["ss"]
    assert sm.method == ss.Ssm(passes=2, occluder_resolution=256, hierarchy=False, precision="f32")
    assert fast.method == env["auto"].method == ss.Ssm(passes=2, occluder_resolution=64, hierarchy=False)
    assert (
        accurate.method
        == env["same"].method
        == ss.Bitmask(samples=256, passes=2, occluder_resolution=256, hierarchy=True)
    )
    np.testing.assert_array_equal(accurate.visibility, env["same"].visibility)
    assert env["reference"].occluder_depth is None and env["reference"].method == ss.Exact(samples=1024, engine="masks")
    assert env["one_core"].threads == 1
    np.testing.assert_array_equal(env["one_core"].visibility, sm.visibility)
    np.testing.assert_array_equal(env["sm2"].visibility, ss_one_pass(env))


def ss_one_pass(env):
    ss = env["ss"]
    return ss.soft_shadow_map(env["scene"], env["light"], resolution=256, passes=1).visibility


def test_eye_view_example_runs():
    text = README.read_text()
    block = re.search(r"```python\n(import softshadow as ss\nfrom softshadow import scenes\n.*?)```", text, re.S)
    assert block, "the eye-view example is missing from the README"
    env: dict = {}
    exec(compile(block.group(1), "README.md", "exec"), env)
    img = env["img"]
    # The last image is the three lights' (a disk, a sphere and the sun).
    assert img.visibility.shape == (3, 240, 320) and img.mask.mean() > 0.3
    assert img.albedo.shape == (240, 320, 3) and len(img.parts) == 3
    # The bunny shadows the floor and itself: some pixels it sees are dark
    # under each light.
    for v in img.visibility:
        assert (v[img.mask] < 0.05).mean() > 0.02
