"""Writes the keyword method configs' classes in ``python/softshadow/_core.pyi``
from the core's capabilities table, so the stub cannot drift from what the
core accepts (stubtest then checks the names against the compiled module;
this checks the types and defaults too); and the lists a new method would
otherwise be added to by hand: the module's ``__all__`` and ``_Ran``, the
configs a result says ran.

    python -m softshadow.experiments.method_stubs [--check] [--stub python/softshadow/_core.pyi]

The classes the bindings make from the table (``_KeywordConfig``'s
subclasses: one per method whose config has a keyword form) sit between
``# <keyword-configs:start>`` and ``# <keyword-configs:end>``, in the table's
order. Each option is a keyword-only argument that may be ``None`` (the
default: the core resolves it), and a property of the type the core gives
back: ``None`` only where the table's default is resolved when the config
runs. ``__all__`` (between ``# <all:start>`` and ``# <all:end>``) is the
compiled module's; ``_Ran`` (between ``# <ran:start>`` and ``# <ran:end>``)
every method's config class but ``Auto``'s, which never runs (it resolves
to another), in the table's order. ``--check`` exits 1 when a block differs
from what this would write, and writes nothing.
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

from .. import _core, methods
from .markers import replace_between

START, END = "# <keyword-configs:start>", "# <keyword-configs:end>"
ALL = "# <all:start>", "# <all:end>"
RAN = "# <ran:start>", "# <ran:end>"
# Run from the checkout's root.
STUB = Path("python") / "softshadow" / "_core.pyi"


def _literal(choices: list[object]) -> str:
    return "Literal[" + ", ".join(f'"{c}"' if isinstance(c, str) else repr(c) for c in choices) + "]"


def _types(o: methods.OptionInfo) -> tuple[str, str]:
    """An option's type as an argument and as the property's value (without ``None``)."""
    if o.kind in ("int", "one_of"):
        return "int", "int"
    if o.kind == "float":
        return "float", "float"
    if o.kind == "bool":
        return "bool", "bool"
    if o.kind == "resolution":
        return "_Resolution", "tuple[int, int]"
    if o.kind == "choice":
        assert o.choices is not None
        t = _literal(o.choices)
        return t, t
    raise ValueError(f"option {o.name!r}: kind {o.kind!r} has no keyword form")


def _class(info: methods.MethodInfo) -> str:
    name = info.config.__name__
    summary = info.summary if info.summary.endswith(".") else info.summary + "."
    doc = textwrap.fill(summary, 96, initial_indent='    """', subsequent_indent="    ") + '"""'
    lines = ["@final", f"class {name}(_KeywordConfig):", doc, "", "    def __new__(", "        cls,"]
    if info.options:
        lines.append("        *,")
    props = []
    for o in info.options.values():
        arg, value = _types(o)
        lines.append(f"        {o.name}: {arg} | None = None,")
        props += ["    @property", f"    def {o.name}(self) -> {value}{' | None' if o.default is None else ''}: ..."]
    lines.append(f"    ) -> {name}: ...")
    return "\n".join(lines + props)


def _keyword_config(cls: type) -> bool:
    # The base the bindings make these classes on is not a module attribute.
    return any(b.__name__ == "_KeywordConfig" and b.__module__ == _core.__name__ for b in cls.__mro__[1:])


def block() -> str:
    """The stub's classes of every keyword config, in the table's order."""
    infos = [i for i in methods.capabilities().values() if _keyword_config(i.config)]
    return "\n\n".join(_class(i) for i in infos)


def all_names() -> str:
    """The stub's ``__all__``: the compiled module's."""
    return "__all__ = [\n" + "".join(f'    "{n}",\n' for n in _core.__all__) + "]"


def ran() -> str:
    """The stub's ``_Ran``: every method's config class but ``Auto``'s."""
    names = [i.config.__name__ for i in methods.capabilities().values() if i.config is not methods.Auto]
    return "_Ran = " + " | ".join(names)


def render(stub: str) -> str:
    """``stub`` with its generated blocks replaced by the current ones."""
    note = "# Written by python -m softshadow.experiments.method_stubs: do not edit."
    stub = replace_between(stub, START, END, f"{note}\n\n{block()}\n", str(STUB))
    stub = replace_between(stub, *ALL, all_names(), str(STUB))
    return replace_between(stub, *RAN, ran(), str(STUB))


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--stub", type=Path, default=STUB)
    p.add_argument("--check", action="store_true", help="report a stale stub, write nothing")
    a = p.parse_args(argv)
    old = a.stub.read_text()
    new = render(old)
    if new == old:
        return 0
    if a.check:
        print(f"stale method classes in {a.stub}: run python -m softshadow.experiments.method_stubs")
        return 1
    a.stub.write_text(new)
    return 0


if __name__ == "__main__":
    sys.exit(main())
