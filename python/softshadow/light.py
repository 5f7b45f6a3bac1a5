"""The rectangular area light."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from . import _core
from . import _validate as check


class _Frame:
    """The light frame (u, v, n) the core computed, as fresh arrays."""

    _frame: tuple[Any, Any, Any]

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

    Raises ValueError for a non-finite center, a zero-length ``normal`` or
    ``up``, an ``up`` within 1e-6 rad of parallel to ``normal``, or a size that
    is neither finite and > 0 nor (0, 0). Size (0, 0) is a point light: every
    method then gives the hard shadow map, the limit they converge to as the
    size shrinks.
    """

    center: tuple[float, float, float]
    normal: tuple[float, float, float]
    up: tuple[float, float, float]
    size: tuple[float, float]
    _frame: tuple[Any, Any, Any] = field(repr=False, compare=False)

    def __init__(
        self,
        center: Any,
        normal: Any,
        up: Any,
        size: Any = (1.0, 1.0),
    ) -> None:
        c = check.vector3("center", center)
        n = check.vector3("normal", normal)
        u = check.vector3("up", up)
        s = check.pair("size", size)
        frame = _core.light_frame((c, n, u, s))
        object.__setattr__(self, "center", c)
        object.__setattr__(self, "normal", n)
        object.__setattr__(self, "up", u)
        object.__setattr__(self, "size", s)
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

    Raises ValueError for a non-finite or zero ``direction`` or ``up``, an
    ``up`` parallel to ``direction``, or an angle that is negative, NaN, or
    beyond 179 degrees (and one zero angle beside a non-zero one).
    """

    direction: tuple[float, float, float]
    up: tuple[float, float, float]
    angular_size: tuple[float, float]
    _frame: tuple[Any, Any, Any] = field(repr=False, compare=False)

    def __init__(self, direction: Any, up: Any, angular_size: Any = (0.53, 0.53)) -> None:
        d = check.vector3("direction", direction)
        u = check.vector3("up", up)
        a = check.pair("angular_size", angular_size)
        frame = _core.light_frame((d, u, a))
        object.__setattr__(self, "direction", d)
        object.__setattr__(self, "up", u)
        object.__setattr__(self, "angular_size", a)
        object.__setattr__(self, "_frame", tuple(np.array(x) for x in frame))

    def _core_args(self) -> tuple[Any, ...]:
        return (self.direction, self.up, self.angular_size)
