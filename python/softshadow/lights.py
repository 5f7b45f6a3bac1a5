"""The lights: a rectangular area light and the sun (:class:`RectLight`,
:class:`DirectionalLight`), with their emission.

A light's emission is RGB (a number is grey): a rectangle's ``radiance``
(emitted uniformly, Lambertian, on its ``n`` side only) and the sun's
``irradiance`` (on a surface facing it). Only :func:`softshadow.render`'s
shaded images read it (docs/shading.md); visibility never does. The core
checks the values (``_core.light_emission``) and computes the unshadowed
irradiance (:meth:`RectLight.irradiance_at`, src/eye/shading.rs).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _core
from . import _validate as check


class _Frame:
    """The light frame (u, v, n) the core computed, as fresh arrays."""

    _frame: tuple[Any, Any, Any]

    def _core_args(self) -> tuple[Any, ...]:
        raise NotImplementedError

    def _emission(self) -> tuple[float, float, float]:
        raise NotImplementedError

    def irradiance_at(self, points: Any, normals: Any) -> np.ndarray:
        """The unshadowed irradiance (N, 3) float64, RGB, emission included, at
        world ``points`` (N, 3) on surfaces with ``normals`` (N, 3; any
        length, not zero), in closed form: Lambert's polygon formula after
        clipping the rectangle to each point's upper hemisphere (0 at or
        behind its plane), or the sun's ``irradiance * max(0, n . s)``. No
        shadows: :func:`softshadow.render` multiplies by the visibility.
        See docs/shading.md."""
        p = _rows3("points", points)
        n = _rows3("normals", normals)
        result: np.ndarray = _core.irradiance(self._core_args(), p, n, self._emission())
        return result

    @property
    def u(self) -> np.ndarray:
        """Unit vector along the light's width or first angle (map columns grow along it)."""
        return self._frame[0].copy()

    @property
    def v(self) -> np.ndarray:
        """Unit vector along the light's height or second angle (map rows grow against it)."""
        return self._frame[1].copy()

    @property
    def n(self) -> np.ndarray:
        """Unit normal from a rectangle into the scene; the direction a sun's light travels."""
        return self._frame[2].copy()


@dataclass(frozen=True, init=False)
class RectLight(_Frame):
    """A rectangular area light that emits uniformly over its whole rectangle.

    Frame: ``n = normalize(normal)`` points from the light into the scene,
    ``v = normalize(up - (up . n) n)`` and ``u = n x v``. ``size`` is the full
    width along ``u`` and the full height along ``v``.

    ``radiance`` (keyword-only) is the radiance it emits, uniform and
    Lambertian, on its ``n`` side only: a number (grey) or an RGB triple, each
    finite and >= 0; ``None`` takes the core's default, 1.0. Stored as an RGB
    triple. Only the eye view's shaded images read it (docs/shading.md).

    Raises ValueError for a non-finite center, a zero-length ``normal`` or
    ``up``, an ``up`` within 1e-6 rad of parallel to ``normal``, a size that
    is neither finite and > 0 nor (0, 0), or a negative or non-finite
    ``radiance``. Size (0, 0) is a point light: every method then gives the
    hard shadow map, the limit they converge to as the size shrinks (it has
    no area, so it lights no shaded image).
    """

    center: tuple[float, float, float]
    normal: tuple[float, float, float]
    up: tuple[float, float, float]
    size: tuple[float, float]
    radiance: tuple[float, float, float]
    _frame: tuple[Any, Any, Any] = field(repr=False, compare=False)

    def __init__(
        self,
        center: Any,
        normal: Any,
        up: Any,
        size: Any = (1.0, 1.0),
        *,
        radiance: Any = None,
    ) -> None:
        c = check.vector3("center", center)
        n = check.vector3("normal", normal)
        u = check.vector3("up", up)
        s = check.pair("size", size)
        frame = _core.light_frame((c, n, u, s))
        emitted = _core.light_emission("radiance", _color(radiance))
        object.__setattr__(self, "center", c)
        object.__setattr__(self, "normal", n)
        object.__setattr__(self, "up", u)
        object.__setattr__(self, "size", s)
        object.__setattr__(self, "radiance", tuple(emitted))
        object.__setattr__(self, "_frame", tuple(np.array(a) for a in frame))

    @classmethod
    def canonical(cls, size: Any) -> RectLight:
        """The light that depth-map input is expressed in: center at the origin,
        ``n = +z``, ``v = +y`` (so ``u = -x``)."""
        return cls(center=(0.0, 0.0, 0.0), normal=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0), size=size)

    @property
    def area(self) -> float:
        return self.size[0] * self.size[1]

    def corners(self) -> np.ndarray:
        """The four corners (4, 3): (-u,-v), (+u,-v), (+u,+v), (-u,+v)."""
        c = np.asarray(self.center)
        hu = 0.5 * self.size[0] * self._frame[0]
        hv = 0.5 * self.size[1] * self._frame[1]
        return np.array([c - hu - hv, c + hu - hv, c + hu + hv, c - hu + hv])

    def _core_args(self) -> tuple[Any, ...]:
        return (self.center, self.normal, self.up, self.size)

    def _emission(self) -> tuple[float, float, float]:
        return self.radiance


@dataclass(frozen=True, init=False)
class DirectionalLight(_Frame):
    """A directional light (the sun): a rectangle of directions at infinity.

    Frame: ``n = normalize(direction)`` is the direction the light travels,
    ``v = normalize(up - (up . n) n)``, ``u = n x v``. The light is the set of
    travel directions ``n + x u + y v`` with ``|x| <= tan(a_u / 2)`` and
    ``|y| <= tan(a_v / 2)``, uniform in (x, y); ``angular_size = (a_u, a_v)``
    are full angles in degrees (the sun is about 0.53). ``(0, 0)`` is a hard
    directional light. Its light-view maps are orthographic (see
    docs/conventions.md).

    ``irradiance`` (keyword-only) is the irradiance on a surface facing the
    sun: a number (grey) or an RGB triple, each finite and >= 0; ``None``
    takes the core's default, 1.0. Stored as an RGB triple. The shaded
    images take the cosine toward the sun's centre and ignore its angular
    size there (a relative error below ``a**2 / 4`` for a disc of angular
    radius ``a`` above the horizon; docs/shading.md).

    Raises ValueError for a non-finite or zero ``direction`` or ``up``, an
    ``up`` parallel to ``direction``, an angle that is negative, NaN, or
    beyond 179 degrees (and one zero angle beside a non-zero one), or a
    negative or non-finite ``irradiance``.
    """

    direction: tuple[float, float, float]
    up: tuple[float, float, float]
    angular_size: tuple[float, float]
    irradiance: tuple[float, float, float]
    _frame: tuple[Any, Any, Any] = field(repr=False, compare=False)

    def __init__(self, direction: Any, up: Any, angular_size: Any = (0.53, 0.53), *, irradiance: Any = None) -> None:
        d = check.vector3("direction", direction)
        u = check.vector3("up", up)
        a = check.pair("angular_size", angular_size)
        frame = _core.light_frame((d, u, a))
        emitted = _core.light_emission("irradiance", _color(irradiance))
        object.__setattr__(self, "direction", d)
        object.__setattr__(self, "up", u)
        object.__setattr__(self, "angular_size", a)
        object.__setattr__(self, "irradiance", tuple(emitted))
        object.__setattr__(self, "_frame", tuple(np.array(x) for x in frame))

    def _core_args(self) -> tuple[Any, ...]:
        return (self.direction, self.up, self.angular_size)

    def _emission(self) -> tuple[float, float, float]:
        return self.irradiance


def _rows3(name: str, value: Any) -> np.ndarray:
    """An (N, 3) array of reals as C-contiguous float64 (the core checks the values)."""
    a = np.asarray(value)
    if a.dtype.kind not in "fiu":
        raise TypeError(f"{name}: must be real numbers, got dtype {a.dtype}")
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{name}: must have shape (N, 3), got {a.shape}")
    return np.ascontiguousarray(a, dtype=np.float64)


def _color(value: Any) -> Any:
    """NumPy arrays and scalars, at any depth of lists and tuples, as plain
    Python numbers and lists (what the core's conversion reads); anything
    else unchanged (the core names its type)."""
    if isinstance(value, (np.ndarray, np.generic)):
        return value.tolist()
    if isinstance(value, (list, tuple)):
        return [_color(v) for v in value]
    return value
