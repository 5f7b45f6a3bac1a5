"""The package's layering: no import circle among ``softshadow``'s modules, and
no private name exported from the top level.

The import graph is read from the sources (``python/softshadow/**/*.py``)
with :mod:`ast`, never by importing them. The rule:

* Every ``import`` and ``from ... import`` statement in a file counts,
  wherever it stands: at module level, inside a function or a method (a lazy
  import still closes a circle, it only delays it), under
  ``if TYPE_CHECKING:``, in a ``try``. Relative imports are resolved against
  the importing module's package (``__init__.py`` is its own package).
* ``import softshadow.a.b`` and ``from softshadow.a.b import name`` (or
  ``from .a.b import name``) are an edge to ``softshadow.a.b``.
* ``from softshadow.a import x`` is an edge to the module ``softshadow.a.x``
  when the package has one (a file or a subpackage), else to
  ``softshadow.a`` itself (``x`` is a name its ``__init__`` defines).
* Parent packages: importing ``softshadow.a.b`` first runs the
  ``__init__`` of every package above it, so the edge also goes to each
  package that encloses the target but not the importing module
  (``softshadow.dataset.item`` importing ``softshadow.reference._mitsuba``
  depends on ``softshadow.reference``). The importing module's own enclosing
  packages are not implied: they are already being imported when it runs,
  and a package's ``__init__`` re-exporting its submodules (``softshadow``
  importing ``.render``) is a facade, not a circle. An explicit import of an
  enclosing package (``from .. import PCSS``) is an edge like any other.
* Only ``softshadow.*`` modules are nodes; ``softshadow._core`` (the
  compiled extension) is left out, and so are self-imports.

A circle is any strongly connected component of more than one module; the
failure names its modules and one circle through them, each step with the
file and line of the import.
"""

from __future__ import annotations

import ast
from pathlib import Path

import softshadow as ss

PACKAGE_ROOT = Path(__file__).resolve().parents[2] / "python" / "softshadow"
#: Compiled modules: not sources, not nodes.
EXCLUDED = {"softshadow._core"}

Edges = dict[str, dict[str, list[str]]]
"""module -> imported module -> where ("path:line")."""


def module_files(root: Path, package: str) -> dict[str, Path]:
    """Dotted module name -> source file, for every ``.py`` under ``root``
    (the folder of ``package``)."""
    mods: dict[str, Path] = {}
    for path in sorted(root.rglob("*.py")):
        parts = list(path.relative_to(root).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        mods[".".join([package, *parts])] = path
    return mods


def _resolve(module: str, is_package: bool, level: int, target: str | None) -> str:
    """The absolute name ``from <level dots><target>`` means inside ``module``."""
    if level == 0:
        return target or ""
    base = module.split(".")
    if not is_package:
        base.pop()  # a plain module's package
    if level > 1:
        base = base[: len(base) - (level - 1)]
    return ".".join([*base, target] if target else base)


def imported_names(mod: str, path: Path, modules: set[str]) -> list[tuple[str, int]]:
    """(absolute module name, line) for every import statement of ``mod``,
    inside functions too; ``from pkg import x`` names ``pkg.x`` when that is
    one of ``modules``, else ``pkg``."""
    is_package = path.name == "__init__.py"
    out: list[tuple[str, int]] = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if isinstance(node, ast.Import):
            out += [(alias.name, node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = _resolve(mod, is_package, node.level, node.module)
            for alias in node.names:
                sub = f"{base}.{alias.name}"
                out.append((sub if sub in modules else base, node.lineno))
    return out


def import_graph(root: Path, package: str, excluded: frozenset[str] | set[str] = frozenset()) -> Edges:
    """The import edges among the modules of ``package`` (see the module's
    docstring for the rule)."""
    files = module_files(root, package)
    graph: Edges = {m: {} for m in files if m not in excluded}
    for mod, path in files.items():
        if mod not in graph:
            continue
        parts = mod.split(".")
        enclosing = {".".join(parts[:i]) for i in range(1, len(parts) + 1)}  # mod itself included
        for target, line in imported_names(mod, path, set(files) | set(excluded)):
            if target in excluded or target not in graph or target == mod:
                continue  # compiled, outside the package, or itself
            t = target.split(".")
            # The packages above the target whose __init__ runs first, unless mod is inside them.
            above = [p for p in (".".join(t[:i]) for i in range(1, len(t))) if p not in enclosing]
            for dest in [*above, target]:
                where = f"{path.relative_to(root.parent)}:{line}"
                if where not in graph[mod].setdefault(dest, []):
                    graph[mod][dest].append(where)
    return graph


def strongly_connected(graph: Edges) -> list[list[str]]:
    """Tarjan's components of more than one node, each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    out: list[list[str]] = []
    counter = 0

    def visit(v: str) -> None:
        nonlocal counter
        index[v] = low[v] = counter
        counter += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph.get(v, {})):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def one_circle(graph: Edges, component: list[str]) -> list[str]:
    """A circle through the component's first module, as its modules in order
    (the first repeated at the end): a shortest path back to it."""
    start, members = component[0], set(component)
    previous: dict[str, str] = {}
    frontier = [start]
    while frontier:
        nxt = []
        for v in frontier:
            for w in sorted(graph[v]):
                if w not in members:
                    continue
                if w == start:
                    path = [v]
                    while path[-1] != start:
                        path.append(previous[path[-1]])
                    return [*reversed(path), start]
                if w not in previous:
                    previous[w] = v
                    nxt.append(w)
        frontier = nxt
    raise AssertionError(f"no circle through {start} in {component}")  # unreachable for a component


def describe(graph: Edges, components: list[list[str]]) -> str:
    lines = []
    for comp in components:
        circle = one_circle(graph, comp)
        lines.append(f"import circle among {len(comp)} modules: {', '.join(comp)}")
        lines.append("  for example:")
        for a, b in zip(circle, circle[1:], strict=False):
            lines.append(f"    {a} -> {b}  ({', '.join(graph[a][b])})")
    return "\n".join(lines)


def test_no_import_circle() -> None:
    graph = import_graph(PACKAGE_ROOT, "softshadow", EXCLUDED)
    assert len(graph) > 30, f"found only {len(graph)} modules under {PACKAGE_ROOT}"
    components = strongly_connected(graph)
    assert not components, "\n" + describe(graph, components)


def test_graph_sees_every_kind_of_import(tmp_path: Path) -> None:
    """The rule on a made-up package: lazy, TYPE_CHECKING, ``from . import
    submodule``, absolute and parent-package imports all make edges."""
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    files = {
        "__init__.py": "from .a import f\nfrom . import _core\n",
        "a.py": "def f():\n    from .b import g\n    return g\n",
        "b.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from .c import C\n",
        "c.py": "from . import a\nimport os\n",
        "d.py": "from . import f\nimport pkg.sub.e\nfrom pkg.sub import e as e2\n",
        "sub/__init__.py": "from .e import h\n",
        "sub/e.py": "from .. import c\ndef h():\n    from ..d import x\n",
    }
    for name, text in files.items():
        (pkg / name).write_text(text)
    graph = import_graph(pkg, "pkg", {"pkg._core"})
    assert {m: set(t) for m, t in graph.items()} == {
        "pkg": {"pkg.a"},
        "pkg.a": {"pkg.b"},
        "pkg.b": {"pkg.c"},
        "pkg.c": {"pkg.a"},
        "pkg.d": {"pkg", "pkg.sub", "pkg.sub.e"},
        "pkg.sub": {"pkg.sub.e"},
        "pkg.sub.e": {"pkg.c", "pkg.d"},
    }
    components = strongly_connected(graph)
    assert components == [["pkg.a", "pkg.b", "pkg.c"], ["pkg.d", "pkg.sub", "pkg.sub.e"]]
    text = describe(graph, components)
    assert "pkg.a -> pkg.b  (pkg/a.py:2)" in text
    assert "pkg.b -> pkg.c  (pkg/b.py:3)" in text


def test_top_level_exports_no_private_name() -> None:
    private = [n for n in ss.__all__ if n.startswith("_") and n != "__version__"]
    assert not private, f"softshadow.__all__ exports private names: {private}"
    missing = [n for n in ss.__all__ if not hasattr(ss, n)]
    assert not missing, f"softshadow.__all__ names what softshadow lacks: {missing}"
    assert len(set(ss.__all__)) == len(ss.__all__), "softshadow.__all__ lists a name twice"
