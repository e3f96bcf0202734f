"""The layers of the package, checked: imports point down the table of docs/architecture.md.

:data:`LAYERS` is the table, bottom up (a module belongs to the longest entry that names it or a
package above it). The edges are every import of an ``eomgen`` module, those inside functions
included, and every ``"eomgen.module:function"`` string (an object imported by name at run
time: an edge that an import scan cannot see is an edge all the same; none is left, the
output builders register themselves).

What stands today against the rule is listed (:data:`UPWARD_TODAY`, :data:`CYCLES_TODAY`,
:data:`LONG_TODAY`): a new upward import, cycle or long module fails, and so does an entry of
those lists that no longer holds, so the lists only shrink.
"""

from __future__ import annotations

import ast
import re
import sys
from collections import defaultdict
from pathlib import Path

import pytest

from support import ROOT

PACKAGE = ROOT / "eomgen"

#: The layer table, bottom up: (layer, entries). An entry is a module or package below eomgen.
LAYERS: tuple[tuple[int, tuple[str, ...]], ...] = (
    (0, ("errors", "moved", "common", "runtime", "robots", "outputs")),
    (1, ("model",)),
    (2, ("parsers", "scene", "reduction",
         # the float kinematics floor, which the loop checks of a scene or an MJCF file use
         "numeric.model", "numeric.newton_euler", "numeric.frames", "numeric.so3",
         "numeric.quaternion_chart", "numeric.loop_checks")),
    (3, ("symbolic.monomials", "symbolic.spatial", "symbolic.program", "symbolic.transforms",
         "symbolic.printing", "symbolic.evaluate", "symbolic.derivation", "symbolic.builders",
         "symbolic.charts", "symbolic.couplings")),
    (4, ("symbolic",)),
    (5, ("dynamics", "regressor")),
    (6, ("numeric", "verify")),
    (7, ("codegen", "cache", "present")),
    (8, ("analysis", "identification", "teach", "control")),
    (9, ("cli",)),
    (10, ("",)),   # eomgen/__init__.py: the public API
)

#: The longest a module may be, in lines.
MAX_LINES = 600

#: Imports that point up the table today: (importer, imported).
UPWARD_TODAY: frozenset[tuple[str, str]] = frozenset({
    ('eomgen.dynamics', 'eomgen.codegen.lambdify'),
})

#: Import cycles today, each as the sorted tuple of its modules.
CYCLES_TODAY: frozenset[tuple[str, ...]] = frozenset()

#: Modules over MAX_LINES lines today.
LONG_TODAY: frozenset[str] = frozenset()

_REFERENCE = re.compile(r"^(eomgen(?:\.\w+)+):\w+$")


def modules() -> dict[str, Path]:
    """Every module of the package by dotted name (``eomgen.symbolic.crba``)."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        if parts[-1] == "__init__":
            parts = parts[:-1]
        found[".".join(parts)] = path
    return found


def layer_of(module: str) -> int:
    inside = module.removeprefix("eomgen").removeprefix(".")
    best, layer = -1, None
    for number, entries in LAYERS:
        for entry in entries:
            if inside == entry or inside.startswith(entry + ".") or entry == "" and inside == "":
                if len(entry) > best:
                    best, layer = len(entry), number
    if layer is None:
        raise LookupError(f"{module} is in no layer of the table")
    return layer


def _owner(name: str, known: dict[str, Path]) -> str | None:
    while name and name not in known:
        name = name.rpartition(".")[0]
    return name or None


def edges() -> dict[str, set[str]]:
    """Importer → the package's modules it imports or names by a ``"module:function"`` string."""
    known = modules()
    out: dict[str, set[str]] = defaultdict(set)
    for module, path in known.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        package = module if path.name == "__init__.py" else module.rpartition(".")[0]
        for node in ast.walk(tree):
            targets = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = package.split(".")
                    anchor = anchor[:len(anchor) - (node.level - 1)]
                    base = ".".join(anchor + ([base] if base else []))
                targets = [f"{base}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Constant) and isinstance(node.value, str):
                found = _REFERENCE.match(node.value)
                targets = [found.group(1)] if found else []
            for target in targets:
                owner = _owner(target, known)
                if owner is not None and owner != module and owner.startswith("eomgen"):
                    out[module].add(owner)
    return out


def upward() -> set[tuple[str, str]]:
    return {(a, b) for a, targets in edges().items() for b in targets
            if layer_of(b) > layer_of(a)
            and not (b.startswith(a + ".") and a != "eomgen")}   # a package's own modules


def cycles() -> set[tuple[str, ...]]:
    """The strongly connected components of more than one module (Tarjan)."""
    graph = edges()
    index, low, stack, on, found = {}, {}, [], set(), set()
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.add(tuple(sorted(component)))

    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 10_000))
    try:
        for v in modules():
            if v not in index:
                visit(v)
    finally:
        sys.setrecursionlimit(limit)
    return found


def long_modules() -> set[str]:
    return {m for m, p in modules().items()
            if p.read_text(encoding="utf-8").count("\n") > MAX_LINES}


def test_every_module_has_a_layer():
    for module in modules():
        layer_of(module)


def test_no_import_points_up_the_table():
    assert upward() - UPWARD_TODAY == set(), "an import up the table (docs/architecture.md)"
    assert UPWARD_TODAY - upward() == set(), "gone: take it off UPWARD_TODAY"


def test_no_import_cycle():
    assert cycles() - CYCLES_TODAY == set()
    assert CYCLES_TODAY - cycles() == set(), "gone: take it off CYCLES_TODAY"


def test_no_long_module():
    assert long_modules() - LONG_TODAY == set(), f"a module over {MAX_LINES} lines"
    assert LONG_TODAY - long_modules() == set(), "shortened: take it off LONG_TODAY"


def test_no_module_names_a_function_by_a_string():
    """No ``"eomgen.module:function"`` string is left in the package: what builds an output,
    sizes an input or gives a module's constants registers itself where it is defined
    (:mod:`eomgen.symbolic.builders`), so the import lines are the whole graph. (:func:`edges`
    would still count such a string as an edge.)"""
    assert _REFERENCE.match("eomgen.symbolic.routes:build_lagrangian")  # the form it had
    found = []
    for module, path in modules().items():
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), filename=str(path))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str) \
                    and _REFERENCE.match(node.value):
                found.append((module, node.value))
    assert found == []


@pytest.mark.parametrize("number, entries", LAYERS[:-1])
def test_the_architecture_page_lists_each_layer(number, entries):
    """docs/architecture.md's table names each entry in the rows of its layer."""
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    block = text.split("## Layers, bottom up", 1)[1].split("```text", 1)[1].split("```", 1)[0]
    rows: dict[int, str] = defaultdict(str)
    current = None
    for line in block.splitlines():
        head = re.match(r"^\s?(\d+)\s", line)
        if head:
            current = int(head.group(1))
        if current is not None:
            rows[current] += line + "\n"
    for entry in entries:
        name = entry.rpartition(".")[2]
        assert re.search(rf"\b{re.escape(name)}(\.py|/)", rows[number]), (number, entry)
