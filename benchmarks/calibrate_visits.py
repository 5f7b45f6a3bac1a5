"""What a gather kernel's counted visit costs, per method: the calibration
of ``visit_cost`` and ``VISITS_PER_RECEIVER`` (src/methods/gather/work.rs).

    python benchmarks/calibrate_visits.py [--no-write]

The kernels (``ssm``, ``bitmask``) count the occluder texels they visit as
they go and are stopped once a call's count, weighted by the method's
``visit_cost``, passes ``visits_per_receiver`` times its receivers (at least
``min_receivers``: ``ss.limits()``). Each call here asks for far more than
that (a camera inside a closed room lit from outside, whose every tile's
light reaches the whole occluder map, with maps set large; a 179° sun over
a table in the light view), so it is stopped at the limit, and the time
until the refusal is what a refused call costs its user. Divided by the
limit's weighted visits it is the time of one weighted visit (an upper
estimate: it includes rasterizing the maps and the groups in flight when
the count passed). With the weights right, every row takes about as long.
Writes ``docs/benchmarks/visits.md``.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import trimesh
from _report import DOCS, Report, add_output_arguments, command_line

import softshadow as ss


def box(size: tuple[float, float, float], center: tuple[float, float, float]) -> trimesh.Trimesh:
    m = trimesh.creation.box(size)
    m.apply_translation(center)
    return m


ROOM = ss.Scene.from_trimesh(trimesh.Scene([box((4, 4, 3), (0, 0, 1.5)), box((0.5, 0.5, 0.5), (0, 0, 0.25))]))
TABLE = ss.Scene.from_trimesh(trimesh.Scene([box((2, 2, 0.2), (0, 0, -0.1)), box((0.5, 0.5, 0.5), (0, 0, 0.25))]))
ROOM_LIGHT = ss.RectLight((0.3, 0.2, 5.0), (0, 0, -1), (0, 1, 0), 1.0)
ROOM_CAMERA = ss.Camera.look_at(eye=(1.5, 1.5, 1.5), target=(0, 0, 0), up=(0, 0, 1), fov_y=60.0, resolution=(160, 120))
SUN = ss.DirectionalLight((0.2, 0.1, -1), (0, 1, 0), 179.0)


def room(method: Any, side: int) -> tuple[str, Any]:
    what = f"inside a closed room, 160×120, {side}² maps"
    return what, lambda: ss.render(ROOM, ROOM_LIGHT, ROOM_CAMERA, method=method, map_resolution=side)


def sun(method: Any, side: int) -> tuple[str, Any]:
    what = f"179° sun over a table, light view {side}²"
    return what, lambda: ss.soft_shadow_map(TABLE, SUN, resolution=side, method=method)


CASES = [
    ("ssm", room(ss.Ssm(), 6000)),
    ("ssm, hierarchy", room(ss.Ssm(hierarchy=True), 6000)),
    ("bitmask, 16 samples", room(ss.Bitmask(samples=16), 5600)),
    ("bitmask, 64 samples", room(ss.Bitmask(samples=64), 5600)),
    ("bitmask, 256 samples", room(ss.Bitmask(), 5600)),
    ("bitmask, 256 samples, open gaps", room(ss.Bitmask(gaps="open"), 5600)),
    ("bitmask, 256 samples, no hierarchy", room(ss.Bitmask(hierarchy=False), 5600)),
    ("bitmask, 1024 samples", room(ss.Bitmask(samples=1024), 1600)),
    ("bitmask, 256 samples", sun(ss.Bitmask(), 512)),
    ("bitmask, 1024 samples", sun(ss.Bitmask(samples=1024), 256)),
]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_output_arguments(p, DOCS / "visits.md")
    args = p.parse_args()
    limits = ss.limits()
    weighted = limits["visits_per_receiver"] * limits["min_receivers"]
    report = Report("What a counted gather visit costs", command_line(__file__), mitsuba=False)
    report.line("| method | call | outcome | seconds | ns per weighted visit |")
    report.line("|---|---|---|---:|---:|")
    for name, (what, call) in CASES:
        t = time.perf_counter()
        try:
            call()
            outcome = "finished under the limit"
        except ValueError as e:
            outcome = f"stopped, naming `{str(e).split(':', 1)[0]}`"
        seconds = time.perf_counter() - t
        per_visit = f"{seconds / weighted * 1e9:.0f}" if outcome.startswith("stopped") else "–"
        report.line(f"| {name} | {what} | {outcome} | {seconds:.1f} | {per_visit} |")
    if not args.no_write:
        intro = (
            f"Each call is stopped once its kernel's visits, weighted by the method's cost "
            f"(`visit_cost`), pass {weighted:.3g} (`visits_per_receiver` × `min_receivers`: "
            f"these calls shade fewer receivers than that floor). *seconds*: from the call to "
            f"its refusal, what a refused call costs; *ns per weighted visit*: seconds over the "
            f"limit, an upper estimate (it includes rasterizing the maps). How the weights and "
            f"the limit were set from these: [robustness](../robustness.md#bounded-cost-and-ctrl-c)."
        )
        report.write(args.out, intro=intro)


if __name__ == "__main__":
    main()
