"""The typed method configs and the core's table of them.

Python holds no copy of the method table: every option, default and limit
here is read from ``ss.capabilities()`` / ``ss.limits()``, and each is
checked against what the core accepts and refuses.
"""

from __future__ import annotations

import copy
import inspect
import pickle
from pathlib import Path

import numpy as np
import pytest

import softshadow as ss
from softshadow import scenes

CAPS = ss.capabilities()


def _accepted(opt: ss.OptionInfo) -> list:
    """Values the option's row says are accepted."""
    if opt.kind == "int":
        return [opt.min, opt.max, (opt.min + opt.max) // 2]
    if opt.kind in ("one_of", "choice", "bool"):
        return list(opt.choices)
    if opt.kind == "resolution":
        return [1, (3, 5), 64]
    if opt.kind in ("float", "config"):
        # Their limits are in the option's doc and the part's own class.
        return []
    raise AssertionError(opt.kind)


def _refused(opt: ss.OptionInfo) -> list:
    """Values just past the row's limits."""
    if opt.kind == "int":
        return [opt.min - 1, opt.max + 1]
    if opt.kind == "one_of":
        return [min(opt.choices) - 1, max(opt.choices) + 1, 0]
    if opt.kind == "choice":
        return ["f8", "F32", ""]
    if opt.kind == "resolution":
        return [0, (0, 4), (4, -1), (opt.max + 1, 1)]
    return []


def test_every_method_has_a_config_class_exported_by_the_package():
    # The core's table holds these (and any method added since, which needs
    # no edit here).
    assert {"ssm", "bitmask", "exact", "pcss", "smoothies", "shadow_mapping", "auto"} <= set(CAPS)
    for name, info in CAPS.items():
        assert info.config is getattr(ss, info.config.__name__)
        assert info.config().name == name
        reads = {"occluder_layers", "occluder_triangles", "scene_triangles", "camera"}
        assert set(info.reads) <= reads and info.reads
        assert "cpu" in info.backends
        assert info.summary


@pytest.mark.parametrize("name", [n for n in CAPS if CAPS[n].options])
def test_every_documented_option_is_accepted_and_every_limit_refused(name):
    info = CAPS[name]
    for opt in info.options.values():
        default = getattr(info.config(), opt.name)
        if opt.kind == "config" and isinstance(opt.default, str):
            assert type(default).__name__ == opt.default, (name, opt.name)
        elif opt.kind == "resolution" and isinstance(opt.default, int):
            assert default == (opt.default, opt.default), (name, opt.name)
        else:
            assert default == opt.default, (name, opt.name)
        for v in _accepted(opt):
            c = info.config(**{opt.name: v})
            got = getattr(c, opt.name)
            assert got == ((v, v) if opt.kind == "resolution" and isinstance(v, int) else v), (name, opt.name, v)
        for v in _refused(opt):
            with pytest.raises((ValueError, ss.TooLargeError), match=f"^{opt.name}: "):
                info.config(**{opt.name: v})


def test_options_beyond_a_methods_own_are_refused_by_name():
    for info in CAPS.values():
        every = {o for i in CAPS.values() for o in i.options}
        for other in sorted(every - set(info.options)):
            with pytest.raises(TypeError, match=other):
                info.config(**{other: None})


def test_the_shorthand_and_the_config_give_the_same_bits_and_the_same_resolved_config():
    scene, light = scenes.two_spheres()
    for by_name, typed in [
        (dict(method="bitmask", samples=64, passes=3), ss.Bitmask(samples=64, passes=3)),
        (dict(method="ssm", occluder_resolution=24, precision="f64"), ss.Ssm(occluder_resolution=24, precision="f64")),
        (dict(method="exact", samples=16), ss.Exact(samples=16)),
        (dict(method="auto"), ss.Auto()),
    ]:
        a = ss.soft_shadow_map(scene, light, resolution=48, **by_name)
        b = ss.soft_shadow_map(scene, light, resolution=48, method=typed)
        assert a.method == b.method
        np.testing.assert_array_equal(a.visibility, b.visibility)


def test_loose_options_beside_a_config_or_on_the_wrong_method_are_refused():
    scene, light = scenes.square_plate()
    with pytest.raises(ValueError, match="^samples: give it inside the method config"):
        ss.soft_shadow_map(scene, light, resolution=16, method=ss.Bitmask(), samples=64)
    with pytest.raises(ValueError, match="^samples: applies to the sampling methods"):
        ss.soft_shadow_map(scene, light, resolution=16, method="ssm", samples=64)
    with pytest.raises(ValueError, match="^precision: applies to"):
        ss.soft_shadow_map(scene, light, resolution=16, method="bitmask", precision="f64")
    with pytest.raises(ValueError, match="^method: unknown method"):
        ss.soft_shadow_map(scene, light, resolution=16, method="vsm")
    with pytest.raises(TypeError, match="^method: "):
        ss.soft_shadow_map(scene, light, resolution=16, method=3)


def test_the_gpu_restrictions_of_the_table_are_the_ones_the_core_applies():
    scene, light = scenes.square_plate()
    for info in CAPS.values():
        for opt in info.options.values():
            for backend, allowed in opt.restricted_on.items():
                assert backend in info.backends
                for v in _accepted(opt):
                    cfg = info.config(**{opt.name: v})
                    if v in allowed:
                        continue
                    if not ss.gpu_available():
                        continue
                    with pytest.raises(ValueError, match=f"^{opt.name}: the GPU backend"):
                        ss.soft_shadow_map(scene, light, resolution=16, method=cfg, backend=backend)


def test_configs_are_frozen_keyword_only_comparable_and_picklable():
    for c in [ss.Ssm(passes=3, occluder_resolution=(32, 16), hierarchy=True, precision="f16"), ss.Bitmask(samples=16)]:
        assert pickle.loads(pickle.dumps(c)) == c and hash(pickle.loads(pickle.dumps(c))) == hash(c)
        assert copy.deepcopy(c) == c
        assert eval(repr(c), {c.__class__.__name__: c.__class__}) == c
        assert type(c)(**c.to_dict()) == c
        with pytest.raises(AttributeError):
            c.passes = 1  # type: ignore[misc]
    assert ss.Exact(samples=4) != ss.Exact(samples=5) and ss.Exact() == ss.Exact(samples=256)
    assert ss.Ssm() != ss.Bitmask() and pickle.loads(pickle.dumps(ss.Auto())) == ss.Auto()
    with pytest.raises(TypeError):
        ss.Bitmask(64)  # type: ignore[misc]
    with pytest.raises(TypeError, match="^samples: must be an int"):
        ss.Exact(samples=2.5)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="^hierarchy: must be a bool"):
        ss.Ssm(hierarchy=1)  # type: ignore[arg-type]


def test_every_config_class_takes_its_table_s_options_by_keyword_and_reads_them_back():
    # Most classes are made from the core's table when the module is
    # imported (a new method adds none here): each must behave as the
    # classes written by hand do.
    for name, info in CAPS.items():
        cls = info.config
        params = inspect.signature(cls).parameters
        assert list(params) == list(info.options), name
        assert all(p.kind is inspect.Parameter.KEYWORD_ONLY and p.default is None for p in params.values()), name
        c = cls()
        assert c.to_dict().keys() == info.options.keys(), name
        for opt in info.options:
            assert getattr(c, opt) == c.to_dict()[opt], (name, opt)
        back = pickle.loads(pickle.dumps(c))
        assert back == c and type(back) is cls and hash(back) == hash(c) and repr(back) == repr(c), name
        assert repr(c).startswith(f"{cls.__name__}("), name
        with pytest.raises(TypeError, match="unexpected keyword argument 'not_an_option'"):
            cls(not_an_option=1)
        with pytest.raises(TypeError, match="positional"):
            cls(1)
        with pytest.raises(TypeError):
            type("Derived", (cls,), {})
        with pytest.raises(AttributeError):
            c.anything = 1  # type: ignore[attr-defined]


def test_the_limits_are_the_cores():
    lim = ss.limits()
    scene, light = scenes.square_plate()
    with pytest.raises(ValueError, match="^extent: "):
        ss.soft_shadow_map(scene, light, resolution=8, extent=lim["max_extent"] * 2)
    with pytest.raises(ss.TooLargeError, match="^resolution: "):
        ss.soft_shadow_map(scene, light, resolution=(lim["max_texels"] + 1, 1))
    with pytest.raises(ValueError, match="^threads: "):
        ss.soft_shadow_map(scene, light, resolution=8, threads=lim["max_threads"] + 1)
    with pytest.raises(ValueError, match="^threads: "):
        ss.soft_shadow_map(scene, light, resolution=8, threads=0)


def test_threads_cap_the_call_and_change_no_bit(monkeypatch):
    scene, light = scenes.two_spheres()
    one = ss.soft_shadow_map(scene, light, resolution=48, method="bitmask", samples=64, threads=1)
    two = ss.soft_shadow_map(scene, light, resolution=48, method="bitmask", samples=64, threads=2)
    assert (one.threads, two.threads) == (1, 2)
    np.testing.assert_array_equal(one.visibility, two.visibility)
    monkeypatch.setenv("SOFTSHADOW_THREADS", "1")
    assert ss.soft_shadow_map(scene, light, resolution=16).threads == 1
    assert ss.soft_shadow_map(scene, light, resolution=16, threads=2).threads == 2
    monkeypatch.setenv("SOFTSHADOW_THREADS", "lots")
    with pytest.raises(ValueError, match="^SOFTSHADOW_THREADS: "):
        ss.soft_shadow_map(scene, light, resolution=16)


def test_the_docs_option_tables_are_the_cores():
    from softshadow.experiments import method_docs

    docs = Path(__file__).resolve().parents[2] / "docs" / "methods"
    assert method_docs.main(["--check", "--docs", str(docs)]) == 0, "run python -m softshadow.experiments.method_docs"


def test_the_stubs_method_classes_are_the_cores():
    from softshadow.experiments import method_stubs

    stub = Path(__file__).resolve().parents[2] / "python" / "softshadow" / "_core.pyi"
    assert method_stubs.main(["--check", "--stub", str(stub)]) == 0, "run python -m softshadow.experiments.method_stubs"
    # Each option's property says None exactly where the core resolves it
    # later; a config built with no arguments gives the table's defaults.
    for info in ss.methods.capabilities().values():
        if not method_stubs._keyword_config(info.config):
            continue
        made = info.config()
        for o in info.options.values():
            assert getattr(made, o.name) == o.default, (info.name, o.name)
            line = next(x for x in method_stubs._class(info).splitlines() if f"def {o.name}(self)" in x)
            assert line.endswith("| None: ...") == (o.default is None), line


def test_numpy_scalars_are_accepted_where_python_ones_are():
    assert ss.Ssm(hierarchy=np.True_, passes=np.int32(3)) == ss.Ssm(hierarchy=True, passes=3)
    assert ss.Bitmask(samples=np.uint16(64), occluder_resolution=(np.int64(8), 4)).occluder_resolution == (8, 4)
    with pytest.raises(TypeError, match="^samples: must be an int, got bool"):
        ss.Exact(samples=np.True_)
    with pytest.raises(ValueError, match="^samples: .* beyond"):
        ss.Exact(samples=2**70)
