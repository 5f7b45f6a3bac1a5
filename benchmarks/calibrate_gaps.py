"""The planner's gaps decision against the full maps (docs/methods/auto.md, "gaps").

For each of the study's scenes and the hard surfaces at 256² and 512²:
`ss.Auto(error=0.01)`'s coarse measure of what closing the gaps changes (the
plan's `gaps` decision), beside what it changes on the planned maps (the
planned config run with gaps closed and open, `layer_change` of the two:
mean |difference| over texels shadowed in either). `GAP_SCALE` in
`src/methods/plan.rs` is the largest ratio, rounded up. Prints a markdown
table; no timing.

    python benchmarks/calibrate_gaps.py
"""

from __future__ import annotations

import re

import numpy as np

import softshadow as ss
from softshadow import scenes


def change(a: np.ndarray, b: np.ndarray) -> float:
    shadowed = (a < 1) | (b < 1)
    return float(np.abs(a - b)[shadowed].mean()) if shadowed.any() else 0.0


def main() -> None:
    print("| scene (`Auto(error=0.01)`) | 256²: coarse change | full maps' change | 512²: coarse | full | gaps |")
    print("|---|---|---|---|---|---|")
    for name, make in {**scenes.SCENES, **scenes.HARD_SURFACES}.items():
        scene, light = make()
        cells: list[str] = []
        taken = ""
        for res in (256, 512):
            sm = ss.soft_shadow_map(scene, light, resolution=res, method=ss.Auto(error=0.01))
            assert sm.plan is not None
            gaps = [d for d in sm.plan.decisions if d.name == "gaps"]
            if not gaps:
                break  # one plane: the sum, no gaps to open
            m = re.search(r"coarse shadow by ([0-9.]+)", gaps[0].why)
            assert m, gaps[0].why
            cfg = sm.method.to_dict()
            closed, opened = (
                ss.soft_shadow_map(
                    scene, light, resolution=res, extent=sm.extent, method=ss.Bitmask(**{**cfg, "gaps": g})
                ).visibility
                for g in ("closed", "open")
            )
            cells += [m.group(1), f"{change(closed, opened):.4f}"]
            taken = "open" if gaps[0].taken else "closed"
        if cells:
            print(f"| {name} | {' | '.join(cells)} | {taken} |")


if __name__ == "__main__":
    main()
