"""The main job: the eye view of the bunny standing on a floor, shadowing
itself, rendered by softshadow beside Mitsuba 3's reference.

    python -m softshadow.experiments.demo [--out DIR] [--resolution W H] [--method M] [--samples K]

The scene is :func:`softshadow.scenes.eye_view.bunny_on_floor` (a 1 x 1 light off
to the bunny's side). softshadow renders it with ``method`` (default
``"auto"``, the library's default); Mitsuba traces the same pixel-centre
rays and K stratified shadow rays per pixel
(:func:`softshadow.reference.render_visibility`). The error is
:func:`softshadow.metrics.compare_images`'s ``shadow_error``: the mean
|V - V_Mitsuba| over the pixels Mitsuba shadows (umbra and penumbra) among
those where both see the same surface point, with the acne (Mitsuba lit,
softshadow darker by > 0.05) and leaks (Mitsuba umbra, softshadow lighter
by > 0.05) beside it; a mean over every pixel would hide the errors behind
the lit ones.

Writes ``DIR/demo.png``, one labelled figure: softshadow's visibility,
Mitsuba's, their signed difference with a colour bar, and the light-view
occluder depth map the method read (``img.shadow_maps[0]``), or, for a
method that reads none (``exact``, the default's), the shaded image
(``img.shaded``: the light's radiance, each visible sample weighted by its
cosine); ``DIR/bunny_on_floor.exr``, every channel of softshadow's image
(``Image.write_exr``: ``V``, ``depth``, ``position.*``, ``normal.*``,
``mesh_id``, ``mask``); and ``DIR/bunny_on_floor_reference.exr``, Mitsuba's
``V`` and ``mask``. Prints the stage timings and the error. ``--samples 0``
skips Mitsuba (the figure then has softshadow's panels only).

Needs the ``reference``, ``io`` and ``plot`` extras (``scripts/demo.sh``
installs them).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from typing import Any

import numpy as np

from ..api import render
from ..lights import RectLight
from ..results import Image
from ..scenes import eye_view

#: The signed difference's colour scale: |V - V_Mitsuba| beyond this saturates.
DIFF_RANGE = 0.25


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m softshadow.experiments.demo", description=__doc__.split("\n")[0])
    p.add_argument("--out", default="out", help="output folder (default: out)")
    p.add_argument("--resolution", type=int, nargs=2, default=(640, 480), metavar=("W", "H"))
    p.add_argument("--method", default="auto", help="softshadow method (default: auto)")
    p.add_argument("--samples", type=int, default=256, help="Mitsuba light samples per pixel (0: skip)")
    a = p.parse_args(argv)
    width, height = a.resolution
    if width < 1 or height < 1:
        p.error(f"--resolution: W and H must be positive, got {width} {height}")
    if a.samples < 0:
        p.error(f"--samples: must be 0 or positive, got {a.samples}")
    try:
        from matplotlib.figure import Figure  # noqa: F401
    except ImportError as e:  # pragma: no cover - depends on the environment
        raise ImportError("the demo's figure needs matplotlib: pip install softshadow[plot]") from e

    scene, light, camera = eye_view.bunny_on_floor((width, height))
    assert isinstance(light, RectLight)  # the scene's light is a rectangle
    print(f"scene: bunny_on_floor, {sum(len(f) for _, f in scene.meshes)} triangles; camera {width}x{height}")
    print(f"light: center {light.center}, normal {light.normal}, size {light.size}")

    render(scene, light, camera, a.method)  # warm-up: the first call pays for pools and caches
    t = time.perf_counter()
    img = render(scene, light, camera, a.method)
    total = time.perf_counter() - t
    maps = f", maps {_shape(img.shadow_maps[0])}" if img.shadow_maps else ""
    print(f"softshadow render, method {a.method!r} -> {img.method!r}{maps}:")
    for stage, sec in img.timings.items():
        print(f"  {stage:<18} {sec * 1e3:8.2f} ms")
    print(f"  {'total (Python)':<18} {total * 1e3:8.2f} ms")

    os.makedirs(a.out, exist_ok=True)
    exr = os.path.join(a.out, "bunny_on_floor.exr")
    img.write_exr(exr)
    written = [exr]

    ref = comparison = None
    ref_time = 0.0
    if a.samples > 0:
        from .. import metrics, reference
        from ..io import write_exr

        t = time.perf_counter()
        ref = reference.render_visibility(scene, light, camera, samples=a.samples)
        ref_time = time.perf_counter() - t
        print(
            f"Mitsuba reference ({reference.variant()}, {ref.samples} samples/pixel): {ref_time:.2f} s "
            f"(first hits {ref.time_first_hits:.2f} s, shadow rays {ref.time_shadow:.2f} s)"
        )
        comparison = metrics.compare_images(img, ref)
        print(
            f"error over shadowed pixels (|V - V_Mitsuba| over the {comparison.shadowed} pixels Mitsuba "
            f"shadows): mean {comparison.shadow_error:.4f}; acne {comparison.acne:.2%}, leaks {comparison.leak:.2%}; "
            f"over all {comparison.matched} matched pixels ({comparison.matched_fraction:.2%} of the hit ones): "
            f"max {comparison.max_abs:.4f}, p99 {comparison.p99_abs:.4f}"
        )
        ref_exr = os.path.join(a.out, "bunny_on_floor_reference.exr")
        write_exr(ref_exr, {"V": ref.visibility, "mask": ref.mask.astype(np.float32)})
        written.append(ref_exr)

    png = os.path.join(a.out, "demo.png")
    figure(img, total, ref, ref_time, comparison, method=a.method).savefig(png, dpi=110)
    written.append(png)
    print("wrote " + ", ".join(written))
    return 0


def figure(
    img: Image,
    seconds: float,
    ref: Any = None,
    ref_seconds: float = 0.0,
    comparison: Any = None,
    *,
    method: str = "auto",
) -> Any:
    """The demo's figure (a matplotlib ``Figure``, no pyplot state): softshadow,
    Mitsuba, their difference and the light-view map, each titled with what
    made it."""
    from matplotlib.figure import Figure

    rows = 2 if ref is not None else 1
    fig = Figure(figsize=(12.0, 4.4 * rows + 0.5), layout="constrained")
    axes = fig.subplots(rows, 2).ravel()
    w, h = img.resolution
    # The background (no surface) in blue-grey, told apart from penumbra.
    grey = _cmap("gray", bad=(0.55, 0.62, 0.75))

    ax = axes[0]
    ax.imshow(np.ma.masked_where(~img.mask, img.visibility), cmap=grey, vmin=0.0, vmax=1.0, interpolation="nearest")
    ax.set_title(f"softshadow, method={method!r} -> {_name(img.method)}\n{w}x{h} px, {seconds * 1e3:.0f} ms")
    ax.set_axis_off()

    if ref is not None and comparison is not None:
        ax = axes[1]
        ax.imshow(np.ma.masked_where(~ref.mask, ref.visibility), cmap=grey, vmin=0.0, vmax=1.0, interpolation="nearest")
        ax.set_title(f"Mitsuba 3 reference\n{w}x{h} px, {ref.samples} shadow rays/px, {ref_seconds:.2f} s")
        ax.set_axis_off()

        ax = axes[2]
        diff = np.ma.masked_where(~comparison.mask, img.visibility.astype(np.float64) - ref.visibility)
        cmap = _cmap("RdBu_r", bad=(0.6, 0.6, 0.6))
        shown = ax.imshow(diff, cmap=cmap, vmin=-DIFF_RANGE, vmax=DIFF_RANGE, interpolation="nearest")
        fig.colorbar(shown, ax=ax, shrink=0.8, extend="both", label="V_softshadow - V_Mitsuba")
        ax.set_title(
            f"difference (grey: not the same surface)\nmean |dV| over shadowed pixels "
            f"{comparison.shadow_error:.4f}, acne {comparison.acne:.1%}, leaks {comparison.leak:.1%}"
        )
        ax.set_axis_off()

    ax = axes[-1]
    if img.shadow_maps:
        depth = img.shadow_maps[0]
        finite = np.isfinite(depth)
        depth_cmap = _cmap("viridis", bad=(0.6, 0.6, 0.6))
        shown = ax.imshow(np.ma.masked_where(~finite, depth), cmap=depth_cmap, interpolation="nearest")
        label = "orthographic depth" if img.depth_origin is not None else "planar depth from the light"
        fig.colorbar(shown, ax=ax, shrink=0.8, label=label)
        ax.set_title(f"light-view occluder map (front layer)\n{_shape(depth)} texels; grey: no occluder")
    else:
        # What the method makes beyond V: the shaded image, each visible
        # light sample weighted by its cosine (tone-mapped to its peak).
        shaded = img.shaded.astype(np.float64)
        peak = float(shaded.max()) if shaded.size else 0.0
        ax.imshow(np.clip(shaded / peak if peak > 0 else shaded, 0.0, 1.0) ** (1 / 2.2), interpolation="nearest")
        ax.set_title(f"shaded image, cosine-weighted\n({_name(img.method)} reads no light-view map)")
    ax.set_axis_off()
    fig.suptitle("bunny_on_floor: visibility of a 1x1 area light seen through the camera (blue-grey: no surface)")
    return fig


def _shape(a: np.ndarray) -> str:
    """'W x H' of an (H, W) array."""
    return f"{a.shape[1]}x{a.shape[0]}"


def _name(method: Any) -> str:
    return str(getattr(method, "name", type(method).__name__))


def _cmap(name: str, *, bad: tuple[float, float, float]) -> Any:
    """Matplotlib's colour map ``name`` with masked values drawn in ``bad``."""
    from matplotlib import colormaps

    return colormaps[name].with_extremes(bad=bad)


if __name__ == "__main__":
    sys.exit(main())
