"""Writes each method's option table in docs/methods/ from the core's
capabilities table, so the docs cannot drift from what the core accepts.

    python -m softshadow.experiments.method_docs [--check] [--docs docs/methods]

Each page holds its table between ``<!-- options:start -->`` and
``<!-- options:end -->``; ``--check`` exits 1 (naming the pages) when a page's
table differs from what this would write, and writes nothing.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .. import methods
from .markers import replace_between

START, END = "<!-- options:start -->", "<!-- options:end -->"
# Run from the checkout's root.
DOCS = Path("docs") / "methods"


def _values(o: methods.OptionInfo) -> str:
    if o.kind == "int":
        return f"{o.min} to {o.max}"
    if o.kind == "resolution":
        return f"int or `(W, H)`, at least 1, at most {o.max} texels"
    if o.kind == "bool":
        return "`True` / `False`"
    if o.kind == "float":
        return "a number (limits in its description)"
    if o.kind == "config":
        assert o.choices is not None
        return " or ".join(f"`ss.{c}(...)`" for c in o.choices) + " or `None`"
    assert o.choices is not None
    return ", ".join(f"`{c!r}`" if isinstance(c, str) else str(c) for c in o.choices)


def _restricted(o: methods.OptionInfo) -> str:
    return "; ".join(f"{backend}: only {', '.join(repr(v) for v in vals)}" for backend, vals in o.restricted_on.items())


def table(name: str) -> str:
    """The markdown table of method ``name``'s options."""
    info = methods.capabilities()[name]
    fields = ", ".join(f"{o}=None" for o in info.options)
    signature = f"ss.{info.config.__name__}(*, {fields})" if fields else f"ss.{info.config.__name__}()"
    lines = [f"`{signature}`: reads {', '.join(info.reads)}; backends {', '.join(info.backends)}."]
    if not info.options:
        return lines[0] + " No options."
    lines += [
        "",
        "| option | what it does | values | default (`None`: see this column) | backends that restrict it |",
        "|---|---|---|---|---|",
    ]
    for o in info.options.values():
        lines.append(f"| `{o.name}` | {o.doc} | {_values(o)} | {o.default_doc} | {_restricted(o)} |")
    return "\n".join(lines)


def render(page: str, name: str) -> str:
    """``page`` with its options block replaced by the current table."""
    return replace_between(page, START, END, table(name), f"docs/methods/{name}.md")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--docs", type=Path, default=DOCS)
    p.add_argument("--check", action="store_true", help="report stale pages, write nothing")
    a = p.parse_args(argv)
    stale = []
    for name in methods.capabilities():
        path = a.docs / f"{name}.md"
        page = path.read_text()
        new = render(page, name)
        if new != page:
            stale.append(path.name)
            if not a.check:
                path.write_text(new)
    if a.check and stale:
        print(f"stale option tables in {', '.join(stale)}: run python -m softshadow.experiments.method_docs")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
