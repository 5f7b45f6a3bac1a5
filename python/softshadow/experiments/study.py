"""The study: what accuracy costs in time, and the paper's experiments.

    python -m softshadow.experiments.study [--out study] [--resolution 256] [--quick]

Against Mitsuba 3 references (1024 stratified light samples per texel), on
2 cores, everything timed in one run:

1. The accuracy-time plane, per scene (bunny floating, bunny on the floor, two
   spheres at different heights, torus): error (the paper's §4.2.1 metric)
   against time for ``ssm`` (1 and 2 passes, occluder maps at the output's
   resolution and coarser), ``bitmask`` (64 and 256 samples, two occluder
   resolutions), ``exact`` (several sample counts), ``pcss`` (Fernando
   2005) and ``smoothies`` (Chan & Durand 2003), and Mitsuba's
   ``ray_test`` (several sample counts). SSM and exact times are end to end
   from meshes; Mitsuba's are ``ray_test`` alone.
2. The paper's §4.2 experiments (bunny floating): error against occluder-map
   resolution, light size, the occluder's vertical position (its gap to the
   floor) and its lateral position, for ``ssm`` (1 and 2 passes),
   ``bitmask`` (256 samples) and ``exact`` (64 samples).
3. The paper's §5 timings: time against polygon count (spheres of 1k to 1M
   triangles), map size and light size.

Writes PNG plots and ``study.md`` (markdown tables) into ``--out``. Needs the
``reference`` and ``study`` extras (Mitsuba, matplotlib).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Callable
from typing import Any

import numpy as np

from .. import PCSS, Auto, Smoothies, metrics, scenes
from ..api import soft_shadow_map
from ..lights import RectLight
from ..results import ShadowMap
from ..scene import Scene
from ..scenes.eye_view import EYE_SCENES
from .eye_plane import eye_plane, markdown_eye_plane, markdown_eye_summary
from .points import Point, median_seconds, mitsuba_seconds_at

PLANE_SCENES = ("bunny_floating", "bunny_on_floor", "two_spheres", "torus")
#: Builds an experiment's scene and light from the value of its parameter.
MakeScene = Callable[[float], tuple[Scene, RectLight]]
#: The same, with the map resolution to time it at.
MakeTimedScene = Callable[[float], tuple[Scene, RectLight, int]]


class Study:
    def __init__(self, resolution: int, repeats: int, reference_samples: int, quick: bool) -> None:
        from .. import reference

        self.reference = reference
        self.res = resolution
        self.repeats = repeats
        self.ref_samples = reference_samples
        self.quick = quick

    def reference_map(self, sm: ShadowMap, scene: Scene) -> np.ndarray:
        return self.reference.reference_map(sm, scene.occluders, samples=self.ref_samples, seed=12345)

    # -- 1. the accuracy-time plane ------------------------------------------------

    def plane(self, name: str) -> list[Point]:
        scene, light = scenes.SCENES[name]()
        res = self.res
        base = soft_shadow_map(scene, light, resolution=res)
        ref = self.reference_map(base, scene)
        points: list[Point] = []

        def measure(label: str, setting: str, **kw: Any) -> None:
            def run() -> ShadowMap:
                return soft_shadow_map(scene, light, resolution=res, extent=base.extent, **kw)

            t = median_seconds(run, self.repeats if label == "ssm" else max(1, self.repeats // 3))
            points.append(Point(name, label, setting, t, metrics.shadow_error(run().visibility, ref)))

        occ_levels = [res, res // 2, res // 4] if not self.quick else [res, res // 4]
        for passes in (1, 2):
            for occ in occ_levels:
                measure(
                    "ssm",
                    f"{passes} pass{'es' if passes > 1 else ''}, occluders {occ}²",
                    passes=passes,
                    occluder_resolution=occ,
                )
        auto_occ = Auto().rule(res).occluder_resolution or (res, res)
        measure("auto", f"ssm, 2 passes, occluders {auto_occ[0]}²", method="auto")
        for k in (64, 256) if not self.quick else (256,):
            for occ in occ_levels:
                measure(
                    "bitmask", f"{k} samples, occluders {occ}²", method="bitmask", samples=k, occluder_resolution=occ
                )
        measure(
            "bitmask",
            f"256 samples, occluders {res}², no hierarchy",
            method="bitmask",
            samples=256,
            hierarchy=False,
        )
        for k in (16, 64, 256) if not self.quick else (16, 64):
            measure("exact", f"{k} samples", method="exact", samples=k)
        # The other two papers' light-view methods (ShadowMapping has no
        # light view: it is focused, warped and blurred for a camera).
        for occ in occ_levels:
            measure("pcss", f"occluders {occ}²", method=PCSS(occluder_resolution=occ))
        for w in (0.5, 1.0) if not self.quick else (0.5,):
            measure("smoothies", f"width {w}, occluders {res}²", method=Smoothies(width=w))
        rscene = self.reference.ReferenceScene(scene.occluders)
        for k in (4, 16, 64, 256) if not self.quick else (4, 16, 64):
            ts, err = [], 0.0
            for rep in range(max(2, self.repeats // 3)):
                v = self.reference.reference_map(base, rscene, samples=k, seed=rep)
                stats = rscene.last_stats
                assert stats is not None  # set by every visibility query
                ts.append(stats.trace_seconds)
                err = metrics.shadow_error(v, ref)
            points.append(Point(name, "mitsuba", f"{k} samples", float(np.median(ts)), err))
        return points

    # -- 2. the paper's §4.2 experiments -----------------------------------------

    def experiment(
        self,
        label: str,
        values: list[float],
        make: MakeScene,
        res: int,
        vary_occluder_res: bool = False,
    ) -> dict[str, list[float]]:
        curves: dict[str, list[float]] = {
            "ssm, 1 pass": [],
            "ssm, 2 passes": [],
            "bitmask, 256 samples": [],
            "exact, 64 samples": [],
        }
        for x in values:
            scene, light = make(x)
            occ = int(x) if vary_occluder_res else None
            base = soft_shadow_map(scene, light, resolution=res)
            ref = self.reference_map(base, scene)
            for passes in (1, 2):
                sm = soft_shadow_map(
                    scene, light, resolution=res, extent=base.extent, passes=passes, occluder_resolution=occ
                )
                curves[f"ssm, {passes} pass{'es' if passes > 1 else ''}"].append(
                    metrics.shadow_error(sm.visibility, ref)
                )
            bm = soft_shadow_map(
                scene, light, resolution=res, extent=base.extent, method="bitmask", samples=256, occluder_resolution=occ
            )
            curves["bitmask, 256 samples"].append(metrics.shadow_error(bm.visibility, ref))
            ex = soft_shadow_map(scene, light, resolution=res, extent=base.extent, method="exact", samples=64)
            curves["exact, 64 samples"].append(metrics.shadow_error(ex.visibility, ref))
        return curves

    # -- 3. the paper's §5 timings ------------------------------------------------

    def timing(self, values: list[float], make: MakeTimedScene) -> dict[str, list[float]]:
        curves: dict[str, list[float]] = {"ssm, 1 pass": [], "ssm, 2 passes": []}
        for x in values:
            scene, light, res = make(x)
            for passes in (1, 2):

                def run(scene=scene, light=light, res=res, passes=passes) -> ShadowMap:
                    return soft_shadow_map(scene, light, resolution=res, passes=passes)

                t = median_seconds(run, max(3, self.repeats // 2))
                curves[f"ssm, {passes} pass{'es' if passes > 1 else ''}"].append(t)
        return curves


def bunny_with_light(size: float) -> tuple[Scene, RectLight]:
    return scenes.bunny_floating(light_size=size)


def bunny_at_gap(gap: float) -> tuple[Scene, RectLight]:
    return scenes.bunny_floating(gap=gap)


def bunny_shifted(dx: float) -> tuple[Scene, RectLight]:
    v, f = scenes.bunny_mesh(1.0, 1.0)
    v = v + np.array([dx, 0.0, 0.0])
    return Scene(occluders=[(v, f)], receivers=[scenes.floor()]), scenes.default_light()


def sphere_scene(segments: float) -> tuple[Scene, RectLight, int]:
    mesh = scenes.sphere((0.0, 1.5, 0.0), 0.5, n=int(segments))
    return Scene(occluders=[mesh], receivers=[scenes.floor()]), scenes.default_light(), 256


def plot_plane(points: list[Point], path: str, title: str, ylabel: str = "over shadow texels") -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.4), dpi=110)
    styles = {
        "ssm": ("o", "tab:blue"),
        "auto": ("*", "tab:orange"),
        "bitmask": ("D", "tab:purple"),
        "exact": ("s", "tab:green"),
        "pcss": ("v", "tab:brown"),
        "smoothies": ("P", "tab:pink"),
        "shadow map": ("x", "tab:olive"),
        "shadow map, PCF": ("X", "tab:cyan"),
        "shadow map, blur": ("h", "tab:gray"),
        "mitsuba": ("^", "tab:red"),
    }
    for method, (marker, color) in styles.items():
        pts = [p for p in points if p.method == method]
        if not pts:
            continue
        ax.scatter(
            [p.seconds * 1e3 for p in pts],
            [p.error for p in pts],
            marker=marker,
            color=color,
            label=method if method != "mitsuba" else "Mitsuba ray_test",
        )
        for p in pts:
            ax.annotate(p.setting, (p.seconds * 1e3, p.error), fontsize=6, xytext=(3, 3), textcoords="offset points")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("time (ms, 2 cores)")
    ax.set_ylabel(f"error (mean |V - V_ref| {ylabel})")
    ax.set_title(title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def plot_curves(
    x: list[float], curves: dict[str, list[float]], path: str, xlabel: str, ylabel: str, title: str, logy: bool = False
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(5.6, 3.8), dpi=110)
    for name, ys in curves.items():
        ax.plot(x, ys, marker="o", label=name)
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    if logy:
        ax.set_yscale("log")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def markdown_plane(points: list[Point]) -> str:
    lines = [
        "| scene | method | setting | time (ms) | error | Mitsuba at equal error (ms) | Mitsuba time / time |",
        "|---|---|---|---|---|---|---|",
    ]
    for p in points:
        cells = ["", ""]
        if p.method != "mitsuba":
            same = [q for q in points if q.scene == p.scene]
            t, outside = mitsuba_seconds_at(p.error, same)
            mark = "*" if outside else ""
            cells = [f"{t * 1e3:.1f}{mark}", f"{t / p.seconds:.2f}{mark}"]
        head = f"| {p.scene} | {p.method} | {p.setting} | {p.seconds * 1e3:.1f} | {p.error:.4f}"
        lines.append(f"{head} | {cells[0]} | {cells[1]} |")
    return "\n".join(lines)


def markdown_summary(points: list[Point]) -> str:
    """Per scene: the largest lead over Mitsuba at equal error, bitmask's
    error with its defaults at the output's resolution, and the largest lead
    among the settings with error <= 0.01."""
    lines = [
        "| scene | fastest against Mitsuba at equal error | error | Mitsuba time / time "
        "| bitmask, defaults: error | Mitsuba time / time "
        "| fastest against Mitsuba with error <= 0.01 | error | Mitsuba time / time |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for scene in dict.fromkeys(p.scene for p in points):
        same = [q for q in points if q.scene == scene]
        ratio = {id(p): mitsuba_seconds_at(p.error, same)[0] / p.seconds for p in same if p.method != "mitsuba"}
        best = max((p for p in same if p.method != "mitsuba"), key=lambda p: ratio[id(p)])
        # The first 256-sample bitmask setting has the occluder maps at the
        # output's resolution and the hierarchy on: the defaults.
        bm = [p for p in same if p.method == "bitmask" and p.setting.startswith("256 ")]
        bm_cells = f"{bm[0].error:.4f} | {ratio[id(bm[0])]:.2f}" if bm else "- | -"
        fine = [p for p in same if p.method != "mitsuba" and p.error <= 0.01]
        fine_best = max(fine, key=lambda p: ratio[id(p)]) if fine else None
        fine_cells = (
            f"{fine_best.method}, {fine_best.setting} | {fine_best.error:.4f} | {ratio[id(fine_best)]:.2f}"
            if fine_best is not None
            else "- | - | -"
        )
        lines.append(
            f"| {scene} | {best.method}, {best.setting} | {best.error:.4f} | {ratio[id(best)]:.2f} "
            f"| {bm_cells} | {fine_cells} |"
        )
    return "\n".join(lines)


def markdown_curves(xlabel: str, x: list[float], curves: dict[str, list[float]], fmt: str) -> str:
    head = f"| {xlabel} | " + " | ".join(curves) + " |"
    sep = "|---" * (len(curves) + 1) + "|"
    rows = [f"| {xv:g} | " + " | ".join(format(c[i], fmt) for c in curves.values()) + " |" for i, xv in enumerate(x)]
    return "\n".join([head, sep, *rows])


README_START, README_END = "<!-- study-summary:start -->", "<!-- study-summary:end -->"


def command(argv: list[str] | None) -> str:
    return " ".join(["python -m softshadow.experiments.study", *(argv if argv is not None else sys.argv[1:])])


def write_readme_block(path: str, lines: list[str]) -> None:
    """Replaces the README's text between the study-summary markers."""
    with open(path) as f:
        text = f.read()
    if README_START not in text or README_END not in text:
        raise SystemExit(f"{path}: no {README_START} ... {README_END} block to write the summary into")
    head, rest = text.split(README_START, 1)
    _, tail = rest.split(README_END, 1)
    with open(path, "w") as f:
        f.write(head + README_START + "\n" + "\n".join(lines) + "\n" + README_END + tail)


def eye_part(a: argparse.Namespace, md: list[str]) -> list[str]:
    """4. The accuracy-time plane in eye view (every family, Mitsuba's whole
    job); returns the summary table."""
    res = (int(a.eye_resolution[0]), int(a.eye_resolution[1]))
    names = a.eye_scenes or list(EYE_SCENES)
    md += [
        f"## 4. Accuracy against time in eye view ({res[0]}×{res[1]})",
        "",
        "Every family end to end from the meshes (`softshadow.render`) against Mitsuba's whole eye-view "
        "job (first hits, then stratified shadow rays with `ray_test`); errors are mean |V - V_ref| over "
        f"the pixels both see alike, against {a.eye_reference_samples}-sample references. "
        "Mitsuba's time at a method's error: † where its one sample a pixel already does as well, "
        "* where it extrapolates.",
        "",
    ]
    planes = []
    for name in names:
        plane = eye_plane(name, res, repeats=max(1, a.repeats // 2), reference_samples=a.eye_reference_samples)
        planes.append(plane)
        plot_plane(plane.points(), os.path.join(a.out, f"eye_{name}.png"), f"{name}, {res[0]}×{res[1]}", "over pixels")
        md += [f"### {name} ({plane.light})", "", *markdown_eye_plane(plane), "", f"![{name}](eye_{name}.png)", ""]
        print(f"eye {name}: {len(plane.rows)} calls", flush=True)
    summary = markdown_eye_summary(planes)
    md += ["### Summary", "", *summary, ""]
    return summary


def scherzer_part(a: argparse.Namespace, md: list[str]) -> None:
    """5. Scherzer 2005's experiments and Smoothies' width, as tables and plots."""
    from . import scherzer

    res = (int(a.eye_resolution[0]), int(a.eye_resolution[1]))
    md += [f"## 5. Practical shadow mapping (Scherzer 2005) and smoothies ({res[0]}×{res[1]})", ""]
    bias = scherzer.bias_errors(res)
    names = list(next(iter(bias.values())))
    md += [
        "### Bias methods: acne and peter-panning (2048² maps, against the exact hard shadow)",
        "",
        "| bias | " + " | ".join(f"{n}: acne / peter-panning" for n in names) + " |",
        "|---|" + "---|" * len(names),
        *(
            f"| {label} | " + " | ".join(f"{v[n][0]:.4f} / {v[n][1]:.4f}" for n in names) + " |"
            for label, v in bias.items()
        ),
        "",
    ]
    _plot_bias(bias, os.path.join(a.out, "bias_acne_peter_panning.png"))
    md += ["![](bias_acne_peter_panning.png)", ""]
    rs = [float(r) for r in scherzer.RESOLUTIONS]
    alias = scherzer.aliasing_errors(res, max(1, a.repeats // 2))
    curves = {k: [e for e, _ in v] for k, v in alias.items()}
    plot_curves(
        rs,
        curves,
        os.path.join(a.out, "aliasing_vs_resolution.png"),
        "map side (texels)",
        "misclassified fraction",
        "large_city: aliasing error",
        logy=True,
    )
    md += [
        "### Aliasing: misclassified pixels against map resolution (large_city, the sun, eye near the ground)",
        "",
        markdown_curves("map side", rs, curves, ".4f"),
        "",
        "![](aliasing_vs_resolution.png)",
        "",
    ]
    blur, width = scherzer.soft_curves(res, max(1, a.repeats // 2))
    for label, xs, data, fname in (
        (
            "eye-space blur iterations (2048²)",
            [float(i) for i in scherzer.BLUR_ITERATIONS],
            blur,
            "blur_iterations.png",
        ),
        ("smoothie width", list(scherzer.SMOOTHIE_WIDTHS), width, "smoothie_width.png"),
    ):
        err = {k: [e for e, _ in v] for k, v in data.items()}
        ms = {k: [t * 1e3 for _, t in v] for k, v in data.items()}
        plot_curves(xs, err, os.path.join(a.out, fname), label, "error against 256-sample exact", f"error vs {label}")
        md += [
            f"### Error against {label} (soft light; time in ms below)",
            "",
            markdown_curves(label, xs, err, ".4f"),
            "",
            markdown_curves(label, xs, ms, ".0f"),
            "",
            f"![]({fname})",
            "",
        ]
    print("scherzer: done", flush=True)


def _plot_bias(bias: dict[str, dict[str, tuple[float, float]]], path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    labels = list(bias)
    names = list(next(iter(bias.values())))
    fig, axes = plt.subplots(1, 2, figsize=(9.6, 3.8), dpi=110, sharey=True)
    width = 0.8 / len(names)
    for ax, which, title in ((axes[0], 0, "acne"), (axes[1], 1, "peter-panning")):
        for j, n in enumerate(names):
            ys = [max(bias[lab][n][which], 1e-5) for lab in labels]
            ax.barh([i + j * width for i in range(len(labels))], ys, height=width, label=n)
        ax.set_xscale("log")
        ax.set_title(f"{title} (fraction of pixels; 0 drawn at 1e-5)")
        ax.grid(True, axis="x", alpha=0.3)
    axes[0].set_yticks([i + 0.4 - width / 2 for i in range(len(labels))], [lab.split(" (")[0] for lab in labels])
    axes[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m softshadow.experiments.study", description=__doc__.split("\n")[0])
    p.add_argument("--out", default="study", help="output folder (default: study)")
    p.add_argument("--resolution", type=int, default=256, help="map size for the accuracy-time plane")
    p.add_argument("--repeats", type=int, default=7, help="timing repeats (medians are reported)")
    p.add_argument("--reference-samples", type=int, default=1024)
    p.add_argument("--quick", action="store_true", help="fewer settings, 128² experiments (a few minutes)")
    p.add_argument("--scenes", nargs="+", default=list(PLANE_SCENES), choices=sorted(scenes.SCENES))
    parts = ["plane", "experiments", "timings", "eye", "scherzer"]
    p.add_argument("--parts", nargs="+", default=parts, choices=parts)
    p.add_argument("--eye-resolution", type=int, nargs=2, default=(320, 240), metavar=("W", "H"))
    p.add_argument("--eye-reference-samples", type=int, default=4096)
    p.add_argument("--eye-scenes", nargs="+", default=None, help="eye-view scenes (default: all)")
    p.add_argument("--readme", default=None, help="also write the summary tables into this README's study block")
    a = p.parse_args(argv)
    os.makedirs(a.out, exist_ok=True)
    st = Study(a.resolution, a.repeats, a.reference_samples, a.quick)
    md = [
        "# softshadow study",
        "",
        f"Generated by `{command(argv)}`.",
        "",
    ]

    all_points: list[Point] = []
    if "plane" in a.parts:
        md += ["## 1. Accuracy against time", ""]
        for name in a.scenes:
            pts = st.plane(name)
            all_points += pts
            plot_plane(pts, os.path.join(a.out, f"plane_{name}.png"), f"{name}, {a.resolution}²")
            print(f"plane {name}: {len(pts)} settings", flush=True)
        md += [
            "Mitsuba's time at a method's error is interpolated log-log between its sample counts "
            "(* where it extrapolates).",
            "",
            markdown_plane(all_points),
            "",
            "### Summary",
            "",
            markdown_summary(all_points),
            "",
        ]
        md += [f"![{n}](plane_{n}.png)" for n in a.scenes] + [""]

    exp_res = 128 if a.quick else a.resolution // 2
    if "experiments" in a.parts:
        md += [f"## 2. Error against the paper's parameters (bunny floating, {exp_res}²)", ""]
        experiments: list[tuple[str, list[float], MakeScene, bool]] = [
            (
                "occluder map resolution",
                [32, 64, 128, 256] if not a.quick else [32, 64, 128],
                lambda x: scenes.bunny_floating(),
                True,
            ),
            ("light size", [0.25, 0.5, 1.0, 1.5, 2.0], bunny_with_light, False),
            ("gap to the floor", [0.1, 0.5, 1.0, 1.5, 2.0], bunny_at_gap, False),
            ("lateral offset", [0.0, 0.5, 1.0, 1.5], bunny_shifted, False),
        ]
        for label, values, make, vary in experiments:
            curves = st.experiment(label, values, make, exp_res, vary)
            fname = "error_vs_" + label.replace(" ", "_") + ".png"
            plot_curves(values, curves, os.path.join(a.out, fname), label, "error", f"error vs {label}")
            md += [
                f"### Error against {label}",
                "",
                markdown_curves(label, values, curves, ".4f"),
                "",
                f"![]({fname})",
                "",
            ]
            print(f"experiment {label}: done", flush=True)

    if "timings" in a.parts:
        md += ["## 3. Time against polygon count, map size and light size (ssm)", ""]
        timings: list[tuple[str, list[float], MakeTimedScene]] = [
            (
                "sphere segments (triangles ~ segments²)",
                [24, 64, 180, 500, 1000] if not a.quick else [24, 180, 500],
                sphere_scene,
            ),
            (
                "map size",
                [64, 128, 256, 512] if not a.quick else [64, 128, 256],
                lambda r: (*scenes.bunny_floating(), int(r)),
            ),
            ("light size", [0.25, 0.5, 1.0, 2.0], lambda s: (*scenes.bunny_floating(light_size=s), 256)),
        ]
        for label, values, make_timed in timings:
            curves = st.timing(values, make_timed)
            ms = {k: [v * 1e3 for v in vs] for k, vs in curves.items()}
            fname = "time_vs_" + label.split(" (")[0].replace(" ", "_") + ".png"
            plot_curves(values, ms, os.path.join(a.out, fname), label, "time (ms)", f"time vs {label}", logy=True)
            md += [
                f"### Time (ms) against {label}",
                "",
                markdown_curves(label, values, ms, ".1f"),
                "",
                f"![]({fname})",
                "",
            ]
            print(f"timing {label}: done", flush=True)

    summary: list[str] = []
    if "plane" in a.parts:
        summary += [
            f"Light view ({a.resolution}², against {a.reference_samples}-sample Mitsuba maps):",
            "",
            markdown_summary(all_points),
            "",
        ]
    if "eye" in a.parts:
        lines = eye_part(a, md)
        summary += [
            f"Eye view ({a.eye_resolution[0]}×{a.eye_resolution[1]}, against {a.eye_reference_samples}-sample "
            "Mitsuba images): each family's most accurate setting, its time, and Mitsuba's time at that "
            "error over it († Mitsuba's one sample a pixel already does as well; * extrapolated):",
            "",
            *lines,
            "",
        ]
    if "scherzer" in a.parts:
        scherzer_part(a, md)

    with open(os.path.join(a.out, "study.md"), "w") as f:
        f.write("\n".join(md) + "\n")
    if a.readme and summary:
        write_readme_block(a.readme, [f"From `{command(argv)}`:", "", *summary])
    print(f"wrote {a.out}/study.md and its plots")
    return 0


if __name__ == "__main__":
    sys.exit(main())
