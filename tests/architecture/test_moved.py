"""The old module paths (eomgen.moved): each still imports, warns once with the new path and the
release that drops it, and hands out the very module at the new place; nothing of the
project's own (package, tests, docs, examples, benchmarks, templates) uses an old path."""

from __future__ import annotations

import importlib
import re
import sys
import warnings

import pytest

from eomgen.moved import MOVED, REMOVED_IN
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


def test_the_project_uses_no_old_path():
    pattern = re.compile(r"\b(" + "|".join(re.escape(m) for m in MOVED) + r")(?![\w])")
    found = []
    for folder, suffixes in (("eomgen", ".py"), ("tests", ".py"), ("docs", (".md", ".rst", ".py")),
                             ("examples", (".py", ".yaml", ".md")), ("benchmarks", (".py", ".md")),
                             ("templates", ".jinja")):
        for path in (ROOT / folder).rglob("*"):
            if not path.is_file() or not path.name.endswith(suffixes):
                continue
            if path.name in ("moved.py", "test_moved.py"):
                continue
            for k, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
                if pattern.search(line):
                    found.append(f"{path.relative_to(ROOT)}:{k}: {line.strip()}")
    assert not found, "old module paths in use:\n" + "\n".join(found[:20])
