"""Dataset items per second: softshadow's methods against the Mitsuba reference as a teacher, at equal error.

    python benchmarks/bench_dataset.py [--spec examples/shadows_ground.toml] [--count 40] [--workers 2]
        [--error-items 4] [--reference-samples 1024] [--resolution 640 480] [--map-resolution 0]
        [--light-maps] [--out docs/benchmarks/dataset.md] [--no-write]

The items of an example spec (``--resolution`` eye view, light-view maps of
``--map-resolution``², or by default sized from the pixels' footprint as
``render`` sizes them; with ``--light-maps`` every item of a map method also
holds those maps, the spec's ``light_maps = true``), made by ``softshadow.dataset.run`` as the command
makes them (EXR and JSON written, manifest fsynced), with the default
method (``auto``) and with ``bitmask``, and by the Mitsuba reference
(``method.name = "reference"``, the teacher) at several sample counts; each
on ``--workers`` local processes and on a Dask LocalCluster of as many
worker processes, every item's render capped at cores / workers threads
(Dr.Jit's too). items/s counts the whole run, the pool's or the cluster's
start included.

Equal error: on the first ``--error-items`` items, every setting's error is
the mean |V - V_ref| over the pixels the reference shadows (umbra and
penumbra) among those both renderers see alike
(:func:`softshadow.metrics.compare_images`'s ``shadow_error``; an average
over every pixel would hide the errors behind the lit ones), with the acne
(reference lit, darker by > 0.05) and leaks (reference umbra, lighter by
> 0.05) beside it, against the reference with
``--reference-samples`` samples a pixel (another jitter seed than the
teacher's). The teacher's time per item at a method's error is interpolated
log-log between the two sample counts around it (``*``: extrapolated beyond
the counts measured; ``†``: one sample a pixel already does as well, its
time is used). Prints the tables and writes them to docs/benchmarks/dataset.md.
"""

from __future__ import annotations

import argparse
import re
import tempfile
import time
from pathlib import Path

import numpy as np
from _report import DOCS, ROOT, Report, add_output_arguments, command_line

from softshadow import render
from softshadow.dataset import load_spec, run
from softshadow.dataset.build import build_camera, build_light, build_scene
from softshadow.dataset.item import method_call
from softshadow.dataset.runner import default_threads
from softshadow.dataset.sampling import item_seed, sample_item
from softshadow.dataset.spec import Spec
from softshadow.metrics import compare_images

TEACHER_SAMPLES = (1, 4, 16, 64, 256)
METHODS = {"auto": 'name = "auto"', "bitmask": 'name = "bitmask"'}


def variant(text: str, method_block: str, resolution: tuple[int, int], light_maps: bool = False) -> str:
    """The example's text with another [method] table, the resolution, no
    previews and, with ``light_maps``, the light-view maps in every item."""
    head, sep, rest = text.partition("\n[method]\n")
    if not sep:
        raise SystemExit("spec: the example needs a [method] table")
    rest = rest[rest.find("\n[") + 1 :] if "\n[" in rest else ""
    text = f"{head}\n[method]\n{method_block}\n\n{rest}"
    text = re.sub(r"(?m)^resolution = \[.*\]", f"resolution = [{resolution[0]}, {resolution[1]}]", text)
    text = re.sub(r"(?m)^previews = true", "previews = false", text)
    if light_maps:
        if "\n[outputs]\n" not in text:
            text += "\n[outputs]\n"
        text = text.replace("\n[outputs]\n", "\n[outputs]\nlight_maps = true\n", 1)
    return text


def spec_for(text: str, folder: Path, name: str) -> Spec:
    path = folder / f"{name}.toml"
    path.write_text(text)
    return load_spec(path)


def errors(
    specs: dict[str, Spec], teacher: Spec, items: int, reference_samples: int, threads: int
) -> dict[str, tuple[float, float, float]]:
    """Over the first ``items`` items, every method's and the teacher's (at
    each sample count): the mean error over the pixels the reference shadows
    (``ImageComparison.shadow_error``, umbra and penumbra), and the acne and
    leaks (shares of the reference's lit and umbra pixels off by > 0.05)."""
    from softshadow.reference import render_visibility
    from softshadow.reference._mitsuba import _mitsuba

    _mitsuba()[1].set_thread_count(threads)
    sums: dict[str, list[tuple[float, float, float]]] = {}

    def add(name: str, img: object, ref: object) -> None:
        c = compare_images(img, ref)
        sums.setdefault(name, []).append((c.shadow_error, c.acne, c.leak))

    for k in range(items):
        params = sample_item(teacher, k)
        scene, _ = build_scene(params, teacher.folder)
        light = build_light(params["light"], shading=False)
        camera = build_camera(params["camera"])
        ref = render_visibility(scene, light, camera, reference_samples, seed=item_seed(teacher.seed, k) + 1)
        for name, spec in specs.items():
            m = spec.method
            config, loose = method_call(spec)
            img = render(scene, light, camera, config, map_resolution=m.map_resolution, threads=threads, **loose)
            add(name, img, ref)
        for s in TEACHER_SAMPLES:
            add(f"reference {s}", render_visibility(scene, light, camera, s, seed=item_seed(teacher.seed, k)), ref)
    means = {name: np.mean(v, axis=0) for name, v in sums.items()}
    return {name: (float(m[0]), float(m[1]), float(m[2])) for name, m in means.items()}


def throughput(spec: Spec, count: int, workers: int, executor: str) -> float:
    """items/s of a fresh run of ``count`` items."""
    with tempfile.TemporaryDirectory(prefix="bench_dataset_") as out:
        t0 = time.perf_counter()
        summary = run(
            spec, out, count=count, workers=workers, dask="local" if executor == "dask" else None, progress=False
        )
        seconds = time.perf_counter() - t0
    if summary.failed or summary.done != count:
        raise SystemExit(f"{executor}: {len(summary.failed)} items failed: {summary.failed}")
    return count / seconds


def bracket(error: float, err: dict[str, float]) -> set[int]:
    """The two neighbouring sample counts of the teacher whose errors surround ``error``
    (the first two when one sample already does as well, the last two beyond the last)."""
    c = list(TEACHER_SAMPLES)
    for a, b in zip(c[:-1], c[1:], strict=True):
        if err[f"reference {b}"] <= error:
            return {a, b}
    return {c[-2], c[-1]}


def teacher_at(error: float, err: dict[str, float], rate: dict[int, float]) -> tuple[float, str, str]:
    """The teacher's items/s at ``error``, its mark, and the counts it comes from."""
    counts = sorted(rate)
    e = np.log([err[f"reference {s}"] for s in counts])
    t = np.log([1.0 / rate[s] for s in counts])
    if error >= err[f"reference {counts[0]}"]:
        return rate[counts[0]], "†", f"{counts[0]}"
    i = int(np.clip(np.searchsorted(-e, -np.log(error)) - 1, 0, len(counts) - 2))
    mark = "*" if error < err[f"reference {counts[-1]}"] else ""
    slope = (t[i + 1] - t[i]) / (e[i + 1] - e[i])
    seconds = float(np.exp(t[i] + slope * (np.log(error) - e[i])))
    return 1.0 / seconds, mark, f"{counts[i]}–{counts[i + 1]}"


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--spec", type=Path, default=ROOT / "examples" / "shadows_ground.toml")
    p.add_argument("--count", type=int, default=40, help="items per timed run")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--error-items", type=int, default=4)
    p.add_argument("--reference-samples", type=int, default=1024)
    p.add_argument("--resolution", type=int, nargs=2, default=(640, 480), metavar=("W", "H"))
    p.add_argument(
        "--map-resolution",
        type=int,
        default=0,
        help="the map methods' light-view maps (side); 0: sized from the pixels' footprint, as render does by default",
    )
    p.add_argument(
        "--light-maps",
        action="store_true",
        help="the map methods' items also hold their light-view maps (the teacher makes none)",
    )
    add_output_arguments(p, DOCS / "dataset.md")
    args = p.parse_args()
    res = (args.resolution[0], args.resolution[1])
    threads = default_threads(args.workers)
    report = Report(
        f"Dataset items per second ({res[0]}×{res[1]}, "
        + (f"maps {args.map_resolution}²" if args.map_resolution else "maps sized from the pixels' footprint")
        + (", light-view maps written)" if args.light_maps else ")"),
        command_line(__file__),
    )
    text = args.spec.read_text()
    with tempfile.TemporaryDirectory(prefix="bench_specs_") as tmp:
        folder = Path(tmp)
        maps = f"\nmap_resolution = {args.map_resolution}" if args.map_resolution else ""
        specs = {
            name: spec_for(
                variant(text, block + maps, res, args.light_maps),
                folder,
                name,
            )
            for name, block in METHODS.items()
        }
        teachers = {
            s: spec_for(variant(text, f'name = "reference"\noptions = {{ samples = {s} }}', res), folder, f"ref{s}")
            for s in TEACHER_SAMPLES
        }
        measured = errors(specs, teachers[1], args.error_items, args.reference_samples, threads)
        report.line(f"## Error on the first {args.error_items} items (reference: {args.reference_samples} samples)")
        report.line()
        report.line("| renderer | error over shadowed pixels | acne | leaks |")
        report.line("|---|---|---|---|")
        for name, (e, acne, leak) in measured.items():
            report.line(f"| {name} | {e:.4f} | {acne:.2%} | {leak:.2%} |")
        report.line()
        err = {name: e for name, (e, _, _) in measured.items()}

        # The teacher's sample counts around each method's error.
        needed = set().union(*(bracket(err[name], err) for name in specs))
        rows: list[str] = []
        for executor in ("local", "dask"):
            rate = {s: throughput(teachers[s], args.count, args.workers, executor) for s in sorted(needed)}
            for name, spec in specs.items():
                ips = throughput(spec, args.count, args.workers, executor)
                t_ips, mark, between = teacher_at(err[name], err, rate)
                rows.append(
                    f"| {executor} | {name} | {ips:.2f} | {err[name]:.4f} | {between} | {t_ips:.2f}{mark} | "
                    f"{ips / t_ips:.1f}{mark} |"
                )
            for s in sorted(needed):
                rows.append(
                    f"| {executor} | reference, {s} samples | {rate[s]:.2f} | {err[f'reference {s}']:.4f} | | | |"
                )
    who = f"{args.workers} local processes" if args.workers > 1 else "1 process"
    report.line(
        f"## Items per second ({args.count} items a run; {who} or a LocalCluster of {args.workers}, "
        f"{threads} threads each)"
    )
    report.line()
    report.line(
        "| executor | renderer | items/s | error | teacher's samples | teacher items/s at equal error | speed-up |"
    )
    report.line("|---|---|---|---|---|---|---|")
    for row in rows:
        report.line(row)
    if not args.no_write:
        report.write(args.out, intro=(__doc__ or "").split("\n\n", 2)[2].strip())


if __name__ == "__main__":
    main()
