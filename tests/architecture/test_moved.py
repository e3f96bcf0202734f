"""The old module paths (eomgen.moved): each still imports, warns once with the new path and the
release that drops it, and hands out the very module at the new place; so does each name that
left a module which stays (MOVED_NAMES); nothing of the project's own (package, tests, docs,
examples, benchmarks, templates) uses an old path or an old name."""

from __future__ import annotations

import ast
import importlib
import re
import sys
import warnings

import pytest

from eomgen.moved import MOVED, MOVED_NAMES, REMOVED_IN
from support import ROOT


@pytest.mark.parametrize("old", sorted(MOVED))
def test_an_old_path_warns_and_gives_the_new_module(old):
    new = importlib.import_module(MOVED[old])
    sys.modules.pop(old, None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        module = importlib.import_module(old)
    assert module is new
    messages = [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)]
    assert messages == [f"{old} moved to {MOVED[old]}; the old path goes in eomgen {REMOVED_IN}"]


OLD_NAMES = sorted((module, name) for module, names in MOVED_NAMES.items() for name in names)


@pytest.mark.parametrize("module, name", OLD_NAMES)
def test_an_old_name_warns_once_and_gives_the_object_at_its_new_place(module, name):
    new = getattr(importlib.import_module(MOVED_NAMES[module][name]), name)
    old = importlib.import_module(module)
    vars(old).pop(name, None)  # bound by an earlier look-up in this process
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert getattr(old, name) is new
        assert getattr(old, name) is new
    messages = [str(w.message) for w in caught if issubclass(w.category, DeprecationWarning)]
    assert messages == [f"{module}.{name} moved to {MOVED_NAMES[module][name]}; the old path "
                        f"goes in eomgen {REMOVED_IN}"]
    assert name not in old.__all__


@pytest.mark.parametrize("module", sorted(MOVED_NAMES))
def test_a_module_that_stays_still_misses_what_it_never_had(module):
    with pytest.raises(AttributeError, match="no_such_name"):
        getattr(importlib.import_module(module), "no_such_name")


def _project_files():
    for folder, suffixes in (("eomgen", ".py"), ("tests", ".py"), ("docs", (".md", ".rst", ".py")),
                             ("examples", (".py", ".yaml", ".md")), ("benchmarks", (".py", ".md")),
                             ("templates", ".jinja")):
        for path in (ROOT / folder).rglob("*"):
            if path.is_file() and path.name.endswith(suffixes) \
                    and path.name not in ("moved.py", "test_moved.py"):
                yield path


def test_the_project_uses_no_old_path():
    pattern = re.compile(r"\b(" + "|".join(re.escape(m) for m in MOVED) + r")(?![\w])")
    found = []
    for path in _project_files():
        for k, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            if pattern.search(line):
                found.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
    assert not found, "old module paths in use:\n" + "\n".join(found[:20])


def test_the_project_uses_no_old_name():
    """Neither ``module.name`` in any text nor ``from module import name`` in Python (an
    import over several lines included)."""
    dotted = re.compile(r"\b(" + "|".join(re.escape(f"{m}.{n}") for m, n in OLD_NAMES)
                        + r")(?![\w])")
    found = []
    for path in _project_files():
        text = path.read_text(encoding="utf-8")
        for k, line in enumerate(text.splitlines(), 1):
            if dotted.search(line):
                found.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
        if path.suffix != ".py":
            continue
        package = ".".join(path.relative_to(ROOT).with_suffix("").parts[:-1])
        for node in ast.walk(ast.parse(text, filename=str(path))):
            if isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:  # relative: resolved from the file's package
                    anchor = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                    base = ".".join(anchor + ([base] if base else []))
                for alias in node.names:
                    if (base, alias.name) in OLD_NAMES:
                        found.append(f"{path.relative_to(ROOT)}:{node.lineno}: "
                                     f"from {base} import {alias.name}")
    assert not found, "old names in use:\n" + "\n".join(found[:20])
