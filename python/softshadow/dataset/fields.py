"""Reading one TOML table of a spec, field by field, naming each field.

:class:`Table` wraps a parsed table and its dotted path (``objects[1]``).
Every getter takes a field's name, checks its type and range, and raises
:class:`SpecError` naming ``path.field``, the allowed values and what it
got; :meth:`Table.done` refuses the fields nobody asked for (unknown fields,
typos). A *range* is a number (fixed) or ``[low, high]`` (uniform between);
integer ranges sample uniformly among the integers from low to high.
"""

from __future__ import annotations

import math
from typing import Any

Range = tuple[float, float]
IntRange = tuple[int, int]


class SpecError(ValueError):
    """A spec that cannot be used; the message names the field (dotted path)."""


def _is_number(v: Any) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _show(v: Any) -> str:
    s = repr(v)
    return s if len(s) <= 80 else s[:77] + "..."


class Table:
    """A TOML table being read; ``path`` is its dotted name ('' at the top)."""

    def __init__(self, value: Any, path: str) -> None:
        if not isinstance(value, dict):
            raise SpecError(f"{path or 'spec'}: must be a table, got {_show(value)}")
        self.value = value
        self.path = path
        self.read: set[str] = set()

    def name(self, key: str) -> str:
        return f"{self.path}.{key}" if self.path else key

    def has(self, key: str) -> bool:
        return key in self.value

    def raw(self, key: str, default: Any = None) -> Any:
        self.read.add(key)
        return self.value.get(key, default)

    def fail(self, key: str, message: str) -> SpecError:
        return SpecError(f"{self.name(key)}: {message}")

    def done(self) -> None:
        """Refuses the fields that were never read."""
        unknown = sorted(set(self.value) - self.read)
        if unknown:
            allowed = ", ".join(sorted(self.read))
            raise SpecError(f"{self.name(unknown[0])}: unknown field; allowed here: {allowed}")

    def table(self, key: str, *, required: bool = False) -> Table:
        if key not in self.value and not required:
            self.read.add(key)
            return Table({}, self.name(key))
        if key not in self.value:
            raise SpecError(f"{self.name(key)}: missing (a table)")
        return Table(self.raw(key), self.name(key))

    def tables(self, key: str, *, most: int, least: int = 0) -> list[Table]:
        v = self.raw(key, [])
        if not isinstance(v, list) or not all(isinstance(t, dict) for t in v):
            raise self.fail(key, f"must be an array of tables ([[{key}]]), got {_show(v)}")
        if not least <= len(v) <= most:
            raise self.fail(key, f"must hold {least} to {most} tables, got {len(v)}")
        return [Table(t, f"{self.name(key)}[{i}]") for i, t in enumerate(v)]

    def boolean(self, key: str, default: bool) -> bool:
        v = self.raw(key, default)
        if not isinstance(v, bool):
            raise self.fail(key, f"must be true or false, got {_show(v)}")
        return v

    def choice(self, key: str, allowed: list[str], default: str | None = None) -> str:
        if key not in self.value and default is None:
            raise self.fail(key, f"missing; one of {allowed}")
        v = self.raw(key, default)
        if not isinstance(v, str) or v not in allowed:
            raise self.fail(key, f"must be one of {allowed}, got {_show(v)}")
        return v

    def string(self, key: str, default: str | None = None) -> str:
        if key not in self.value and default is None:
            raise self.fail(key, "missing (a string)")
        v = self.raw(key, default)
        if not isinstance(v, str):
            raise self.fail(key, f"must be a string, got {_show(v)}")
        return v

    def integer(self, key: str, default: int | None, lo: int, hi: int) -> int:
        if key not in self.value and default is None:
            raise self.fail(key, f"missing; an integer in [{lo}, {hi}]")
        v = self.raw(key, default)
        if not isinstance(v, int) or isinstance(v, bool) or not lo <= v <= hi:
            raise self.fail(key, f"must be an integer in [{lo}, {hi}], got {_show(v)}")
        return v

    def number(self, key: str, default: float | None, lo: float, hi: float, *, open_lo: bool = False) -> float:
        bound = f"{'(' if open_lo else '['}{lo:g}, {hi:g}]"
        if key not in self.value and default is None:
            raise self.fail(key, f"missing; a number in {bound}")
        v = self.raw(key, default)
        if not _is_number(v) or not math.isfinite(v) or v > hi or v < lo or (open_lo and v == lo):
            raise self.fail(key, f"must be a finite number in {bound}, got {_show(v)}")
        return float(v)

    def range(self, key: str, default: Range | float | None, lo: float, hi: float, *, open_lo: bool = False) -> Range:
        """A number or [low, high] with lo <= low <= high <= hi (low > lo when ``open_lo``)."""
        bound = f"{'(' if open_lo else '['}{lo:g}, {hi:g}]"
        if key not in self.value and default is None:
            raise self.fail(key, f"missing; a number or [low, high] within {bound}")
        v = self.raw(key, default)
        return parse_range(self.name(key), v, lo, hi, open_lo=open_lo)

    def int_range(self, key: str, default: IntRange | int, lo: int, hi: int) -> IntRange:
        v = given = self.raw(key, default)
        if isinstance(v, int) and not isinstance(v, bool):
            v = (v, v)
        ok = (
            isinstance(v, (list, tuple))
            and len(v) == 2
            and all(isinstance(x, int) and not isinstance(x, bool) for x in v)
            and lo <= v[0] <= v[1] <= hi
        )
        if not ok:
            raise self.fail(
                key, f"must be an integer or [low, high] integers with {lo} <= low <= high <= {hi}, got {_show(given)}"
            )
        return int(v[0]), int(v[1])

    def ranges(self, key: str, default: Any, n: int, lo: float, hi: float) -> tuple[Range, ...]:
        """``n`` ranges: one range for every component, or a list of ``n`` ranges."""
        v = self.raw(key, default)
        if isinstance(v, (list, tuple)) and len(v) == n and n != 2:
            return tuple(parse_range(f"{self.name(key)}[{i}]", x, lo, hi) for i, x in enumerate(v))
        r = parse_range(self.name(key), v, lo, hi, extra=f", or a list of {n} of them")
        return (r,) * n

    def color(self, key: str, default: float) -> tuple[Range, Range, Range]:
        """A grey level (number or [low, high]) or three ranges (R, G, B), each within [0, 1]."""
        v = self.raw(key, default)
        if isinstance(v, list) and len(v) == 3:
            r, g, b = (parse_range(f"{self.name(key)}[{i}]", x, 0.0, 1.0) for i, x in enumerate(v))
            return r, g, b
        grey = parse_range(self.name(key), v, 0.0, 1.0, extra=", or [R, G, B] of them")
        return grey, grey, grey


def parse_range(name: str, v: Any, lo: float, hi: float, *, open_lo: bool = False, extra: str = "") -> Range:
    bound = f"{'(' if open_lo else '['}{lo:g}, {hi:g}]"
    given = v
    if _is_number(v):
        v = [v, v]
    ok = (
        isinstance(v, (list, tuple))
        and len(v) == 2
        and all(_is_number(x) and math.isfinite(x) for x in v)
        and lo <= v[0] <= v[1] <= hi
        and not (open_lo and v[0] == lo)
    )
    if not ok:
        raise SpecError(
            f"{name}: must be a finite number or [low, high] with low <= high, within {bound}{extra}, "
            f"got {_show(given)}"
        )
    return float(v[0]), float(v[1])
