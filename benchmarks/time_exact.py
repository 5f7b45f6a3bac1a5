"""Times `exact` on every light-view test scene (256², 256 samples, best of 2)
and every eye-view scene (320×240, 64 samples, one run), with a hash of each
result: for comparing builds of the ray-casting kernel (the hashes must not
change when only its speed does).

    python benchmarks/time_exact.py
"""

from __future__ import annotations

import hashlib
import time

import numpy as np

import softshadow as ss
from softshadow import scenes


def digest(a: np.ndarray) -> str:
    return hashlib.sha1(np.ascontiguousarray(a).tobytes()).hexdigest()[:12]


def main() -> None:
    for name, make in scenes.SCENES.items():
        scene, light = make()
        ts, v = [], None
        for _ in range(2):
            t = time.perf_counter()
            v = ss.soft_shadow_map(scene, light, resolution=256, method=ss.Exact(samples=256)).visibility
            ts.append(time.perf_counter() - t)
        assert v is not None
        print(f"{name:18s} {min(ts) * 1e3:7.0f} ms {digest(v)}")
    for name, make_eye in scenes.eye_view.EYE_SCENES.items():
        scene, light, cam = make_eye((320, 240))
        t = time.perf_counter()
        img = ss.render(scene, light, cam, method=ss.Exact(samples=64))
        dt = time.perf_counter() - t
        print(f"eye {name:14s} {dt * 1e3:7.0f} ms {digest(np.asarray(img.visibility))}")


if __name__ == "__main__":
    main()
