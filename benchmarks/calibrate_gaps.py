"""The planner's gaps decision against the full maps (docs/methods/auto.md, "gaps").

For each of the study's scenes and the hard surfaces at 256² and 512²:
`ss.Auto(error=0.01)`'s coarse measure of what closing the gaps changes (the
plan's `gaps` decision), beside what it changes on the planned maps (the
planned config run with gaps closed and open, `layer_change` of the two:
mean |difference| over texels shadowed in either) and what opening them
costs in error there (each against the 1024-sample Mitsuba reference, the
paper's §4.2.1 metric, cached in `.cache/references/` like the tests').
`GAP_SCALE` in `src/auto/plan.rs` is the largest ratio of the full maps'
change to the coarse one, rounded up. Beside them, plates tilted against
the light next to a second, smaller plate tilted the other way (so that
the occluders are not one plane and the union runs): the surfaces where open
gaps leak the most. Prints a markdown table; no timing.

    python benchmarks/calibrate_gaps.py
"""

from __future__ import annotations

import re

import numpy as np
from _report import CACHE

import softshadow as ss
from softshadow import metrics, scenes
from softshadow.reference.cache import cached_reference_map


def change(a: np.ndarray, b: np.ndarray) -> float:
    shadowed = (a < 1) | (b < 1)
    return float(np.abs(a - b)[shadowed].mean()) if shadowed.any() else 0.0


def tilted_pair(degrees: float) -> tuple[ss.Scene, ss.RectLight]:
    """`scenes.tilted_plate` and a 0.4 plate tilted the other way beside it."""
    one, light = scenes.tilted_plate(degrees)
    other = scenes.rotated(scenes.quad((1.2, 1.5, 0.0), 0.2), -degrees, "z")
    return ss.Scene(occluders=[*one.occluders, other], receivers=list(one.receivers)), light


PAIRS = {f"tilted_pair_{d}": (lambda d=d: tilted_pair(d)) for d in (15, 30, 45, 60)}


def main() -> None:
    print(
        "| scene (`Auto(error=0.01)`) | res | coarse change | full maps' change | full ÷ coarse "
        "| error closed | error open | gaps |"
    )
    print("|---|---|---|---|---|---|---|---|")
    worst = 0.0
    for name, make in {**scenes.SCENES, **scenes.HARD_SURFACES, **PAIRS}.items():
        scene, light = make()
        for res in (256, 512):
            sm = ss.soft_shadow_map(scene, light, resolution=res, method=ss.Auto(error=0.01))
            assert sm.plan is not None
            gaps = [d for d in sm.plan.decisions if d.name == "gaps"]
            if not gaps:
                break  # one plane: the sum, no gaps to open
            m = re.search(r"coarse shadow by ([0-9.]+)", gaps[0].why)
            assert m, gaps[0].why
            coarse = float(m.group(1))
            base = ss.soft_shadow_map(scene, light, resolution=res)
            ref = cached_reference_map(name, base, list(scene.occluders), samples=1024, cache=CACHE)
            cfg = sm.method.to_dict()
            closed, opened = (
                ss.soft_shadow_map(
                    scene, light, resolution=res, extent=base.extent, method=ss.Bitmask(**{**cfg, "gaps": g})
                ).visibility
                for g in ("closed", "open")
            )
            full = change(closed, opened)
            ratio = full / coarse if coarse > 0 else 0.0
            worst = max(worst, ratio)
            e_closed, e_open = metrics.shadow_error(closed, ref), metrics.shadow_error(opened, ref)
            print(
                f"| {name} | {res}² | {coarse:.4f} | {full:.4f} | {ratio:.2f} | {e_closed:.4f} | {e_open:.4f} "
                f"| {'open' if gaps[0].taken else 'closed'} |"
            )
    print(f"\nlargest full ÷ coarse change: {worst:.2f}")


if __name__ == "__main__":
    main()
