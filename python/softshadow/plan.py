"""What the planner decided: the result types both entry points share.

``ShadowMap.plan`` (:mod:`.shadow_map`) and ``Image.plan`` (:mod:`.render`)
hold a :class:`Plan` when ``Auto(error=...)`` or ``Auto(time=...)`` ran.
They live here, below both, so that neither entry point imports the other.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from .methods import MethodConfig


@dataclass(frozen=True)
class Decision:
    """One decision of a plan: its name, whether it was taken, and why (the
    number that decided)."""

    name: str
    taken: bool
    why: str


@dataclass(frozen=True)
class Plan:
    """What ``Auto(error=...)`` or ``Auto(time=...)`` decided for a scene, and
    the config that ran. ``print(sm.plan)`` lists the decisions."""

    decisions: tuple[Decision, ...]
    method: MethodConfig

    def __str__(self) -> str:
        lines = [f"[{'x' if d.taken else ' '}] {d.name}: {d.why}" for d in self.decisions]
        return "\n".join([*lines, f"ran: {self.method!r}"])


def plan_from_core(decisions: Iterable[Any] | None, method: MethodConfig) -> Plan | None:
    """The core's plan (``(name, taken, why)`` triples, or None when nothing
    was planned) as a :class:`Plan`."""
    return None if decisions is None else Plan(tuple(Decision(*d) for d in decisions), method)
