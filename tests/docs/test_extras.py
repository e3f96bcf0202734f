"""The optional extras: a newcomer's test run (README: only the ``test`` extra) skips, saying
which extra to install, every test that needs another one.

:mod:`support.extras` is the one table of optional modules and the extras that bring them;
these tests hold it to ``pyproject.toml`` and hold the tests to it. ``.ci/run`` proves the rest:
its first stage is the README's test command in a fresh virtual environment with only the
``test`` extra.
"""

from __future__ import annotations

import ast
import re
import tomllib

import pytest

from support import ROOT, TESTS
from support.extras import EXTRAS, install_hint

PYPROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))


def _name(requirement: str) -> str:
    return re.match(r"[A-Za-z0-9_.-]+", requirement).group(0).lower().replace("_", "-")


def installed_by(extra: str) -> set[str]:
    """The distributions an extra (or ``core``: the dependencies) installs, with the extras of
    eomgen it includes (``eomgen[analysis,dask]``), by normalised name."""
    project = PYPROJECT["project"]
    if extra == "core":
        return {_name(r) for r in project["dependencies"]}
    names: set[str] = set()
    for requirement in project["optional-dependencies"][extra]:
        included = re.fullmatch(r"eomgen\[([a-z,]+)\]", requirement.replace(" ", ""))
        if included:
            for sub in included.group(1).split(","):
                names |= installed_by(sub)
        else:
            names.add(_name(requirement))
    return names | installed_by("core")


@pytest.mark.parametrize("module", sorted(EXTRAS))
def test_the_extra_named_for_a_module_installs_it(module):
    distribution, extra = EXTRAS[module]
    if distribution in {"pillow"}:   # brought by matplotlib, a dependency of eomgen
        assert "matplotlib" in installed_by(extra)
    else:
        assert distribution in installed_by(extra), f"{distribution} is not in [{extra}]"
    assert (f"'.[{extra}]'" in install_hint(module)) == (extra != "core")


def test_the_test_extra_leaves_out_the_heavy_extras():
    """What a newcomer's run has and has not: the simulators, JAX, PyTorch, Selenium and the
    docs site stay out of the test extra (its tests skip), the references stay in."""
    test = installed_by("test")
    for module in ("mujoco", "jax", "torch", "selenium"):
        assert EXTRAS[module][0] not in test
    for module in ("pinocchio", "example_robot_data", "scipy", "cvxpy", "nbclient"):
        assert EXTRAS[module][0] in test


def importorskip_calls(path):
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Call):
            f = node.func
            if getattr(f, "attr", getattr(f, "id", None)) == "importorskip":
                yield node.lineno


def test_every_optional_import_in_the_tests_goes_through_need():
    """A test imports an optional module through ``support.extras.need``, whose skip reason
    names the extra; ``pytest.importorskip`` called directly names none."""
    direct = [f"{p.relative_to(ROOT)}:{line}" for p in sorted(TESTS.rglob("*.py"))
              if p != TESTS / "support" / "extras.py" for line in importorskip_calls(p)]
    assert direct == [], "use support.extras.need(module, reason)"


def test_need_skips_naming_the_extra():
    with pytest.raises(pytest.skip.Exception, match=r"pip install -e '\.\[simulators\]'"):
        EXTRAS["eomgen_no_such_module"] = ("mujoco", "simulators")
        try:
            from support.extras import need
            need("eomgen_no_such_module", reason="a reference")
        finally:
            del EXTRAS["eomgen_no_such_module"]
