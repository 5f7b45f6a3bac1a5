"""Text between two marker lines, written by a script (the docs' option
tables, the stub's method classes, the README's benchmark tables)."""

from __future__ import annotations


def replace_between(text: str, start: str, end: str, body: str, where: str) -> str:
    """``text`` with what lies between ``start`` and ``end`` replaced by
    ``body`` (on lines of its own); ValueError naming ``where`` when either
    marker is missing."""
    if start not in text or end not in text:
        raise ValueError(f"{where}: no {start} ... {end} block")
    head, rest = text.split(start, 1)
    _, tail = rest.split(end, 1)
    return f"{head}{start}\n{body}\n{end}{tail}"
