"""Mitsuba's whole eye-view shadow job, written as a Mitsuba user writes it:
what softshadow's ``render`` is timed against.

Pixel-centre camera rays from the sensor (:func:`camera_sensor`), one
``ray_intersect``, then per hit pixel ``samples`` shadow rays to the light
(stratified over the rectangle, or over the sun's tangent square, jittered
by Dr.Jit's PCG32, spawned with ``spawn_ray_to`` / ``spawn_ray``) and one
``ray_test``, all in Dr.Jit arrays. The scene and the sensor are loaded
once; :meth:`MitsubaEyeJob.run` is the timed part.

Unlike :func:`render_visibility` (the reference, which returns the first
hits' G-buffer too and rejects the sun's back-facing points per point), this
job returns only the visibility image: it is the competitor's cost, not the
ground truth.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ._mitsuba import _mitsuba, _mitsuba_mesh
from .camera import camera_sensor

#: Rays per Dr.Jit launch: keeps the ray arrays to a few hundred MB.
BATCH_RAYS = 1 << 23


class MitsubaEyeJob:
    """Mitsuba's eye-view job on one scene, its scene and sensor loaded once."""

    def __init__(self, scene: Any, light: Any, camera: Any) -> None:
        from .. import DirectionalLight

        mi, dr = _mitsuba()
        self.mi, self.dr = mi, dr
        d: dict[str, Any] = {"type": "scene"}
        for k, (v, f) in enumerate(scene.meshes):
            d[f"mesh_{k}"] = _mitsuba_mesh(mi, f"mesh_{k}", v.astype(np.float32), f)
        self.scene = mi.load_dict(d)
        self.sensor = mi.load_dict(camera_sensor(camera))
        self.w, self.h = camera.resolution
        self.sun = isinstance(light, DirectionalLight)
        self.n, self.u, self.v = light.n, light.u, light.v
        if self.sun:
            self.size = tuple(2 * math.tan(math.radians(a) / 2) for a in light.angular_size)
            self.center = self.n
        else:
            self.size = light.size
            self.center = np.asarray(light.center)

    def run(self, samples: int) -> np.ndarray:
        """The visibility image (H, W) at ``samples`` per pixel."""
        mi, dr = self.mi, self.dr
        w, h = self.w, self.h
        idx = dr.arange(mi.UInt32, w * h)
        pos = mi.Point2f((mi.Float(idx % w) + 0.5) / w, (mi.Float(idx // w) + 0.5) / h)
        ray, _ = self.sensor.sample_ray(0.0, 0.0, pos, mi.Point2f(0.5, 0.5))
        si = self.scene.ray_intersect(ray)
        hit = np.asarray(si.is_valid().numpy(), dtype=bool)
        p = np.asarray(si.p.numpy(), dtype=np.float32).reshape(3, -1).T[hit]
        n = np.asarray(si.n.numpy(), dtype=np.float32).reshape(3, -1).T[hit]
        if self.sun:
            lit = np.ones(len(p), dtype=bool)
        else:
            lit = (p - self.center) @ self.n > 0
        vis = np.zeros(len(p), dtype=np.float32)
        a, b = self.strata(samples)
        chosen = np.flatnonzero(lit)
        per = max(1, BATCH_RAYS // samples)
        for first in range(0, len(chosen), per):
            sel = chosen[first : first + per]
            vis[sel] = self._shadow(p[sel], n[sel], samples, a, b, first)
        out = np.ones(w * h, dtype=np.float32)
        out[hit] = vis
        return out.reshape(h, w)

    def strata(self, samples: int) -> tuple[int, int]:
        """The a x b stratification of ``samples`` over the light: the
        largest divisor at most its square root across the shorter side."""
        small = int(math.isqrt(samples))
        while samples % small:
            small -= 1
        return (samples // small, small) if self.size[0] >= self.size[1] else (small, samples // small)

    def shadow_rays(self, p: np.ndarray, n: np.ndarray, k: int, a: int, b: int, seed: int) -> Any:
        """The ``k`` shadow rays of each point ``p`` (normal ``n``): one per
        stratum of ``a`` x ``b``, jittered by PCG32 seeded by ``seed``."""
        mi, dr = self.mi, self.dr
        total = len(p) * k
        j = dr.arange(mi.UInt32, total)
        pix = j // k
        s = j % k
        si = mi.SurfaceInteraction3f()
        si.p = dr.gather(mi.Point3f, mi.Point3f(np.ascontiguousarray(p.T)), pix)
        si.n = dr.gather(mi.Normal3f, mi.Normal3f(np.ascontiguousarray(n.T)), pix)
        si.time = dr.zeros(mi.Float, total)
        rng = mi.PCG32(size=total, initstate=mi.UInt64(j) + seed * k)
        x = ((mi.Float(s % a) + rng.next_float32()) / a - 0.5) * self.size[0]
        y = ((mi.Float(s // a) + rng.next_float32()) / b - 0.5) * self.size[1]
        u, v = mi.Vector3f(*self.u.tolist()), mi.Vector3f(*self.v.tolist())
        target = mi.Vector3f(*np.asarray(self.center, dtype=float).tolist()) + x * u + y * v
        return si.spawn_ray(-dr.normalize(target)) if self.sun else si.spawn_ray_to(mi.Point3f(target))

    def _shadow(self, p: np.ndarray, n: np.ndarray, k: int, a: int, b: int, seed: int) -> np.ndarray:
        blocked = self.scene.ray_test(self.shadow_rays(p, n, k, a, b, seed), coherent=False)
        hits = np.asarray(blocked.numpy(), dtype=np.float32).reshape(len(p), k)
        return 1.0 - hits.mean(axis=1)
