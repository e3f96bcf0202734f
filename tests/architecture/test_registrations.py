"""The output registry upside down, checked: the catalogue (:mod:`eomgen.outputs.catalogue`) is data, and
each printed output has exactly one builder, registered by the module that builds it
(:mod:`eomgen.symbolic.builders`), once the place that derives (:mod:`eomgen.dynamics`) is
imported; so are the sizes of the inputs and the module constants the catalogue names.

The check runs in a fresh interpreter that imports only ``eomgen.dynamics``: in this process
other tests may have imported a builder's module already, which would hide a module the place
that derives forgot.
"""

from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from types import SimpleNamespace

import pytest

import eomgen
from eomgen import outputs
from eomgen.outputs import catalogue
from eomgen.symbolic import builders
from support import ROOT

_FRESH = """
import json
import eomgen.dynamics
from eomgen import outputs
from eomgen.symbolic import builders
print(json.dumps({
    "printed": list(outputs.BY_SYMBOL),
    "built": {s: f"{f.__module__}.{f.__qualname__}" for s, f in builders.BUILDERS.items()},
    "sized": sorted(builders.SIZES),
    "constants": [list(k) for k in builders.CONSTANTS],
}))
"""


@pytest.fixture(scope="module")
def fresh():
    done = subprocess.run([sys.executable, "-c", _FRESH], capture_output=True, text=True,
                          timeout=120, cwd=ROOT, env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def test_every_printed_output_has_exactly_one_builder(fresh):
    printed = [o.symbol for o in catalogue.CATALOGUE if o.symbol is not None]
    assert fresh["printed"] == printed
    # a symbol maps to one function; the keys are exactly the printed outputs, no more
    assert sorted(fresh["built"]) == sorted(printed)
    for symbol, where in fresh["built"].items():
        assert where.startswith("eomgen."), (symbol, where)


def test_every_sized_input_and_named_constant_has_its_function(fresh):
    assert fresh["sized"] == sorted(outputs.INPUT_SIZES)
    named = {o.constants for o in catalogue.CATALOGUE if o.constants}
    assert {tuple(k) for k in fresh["constants"]} == named


def test_a_second_builder_for_a_symbol_is_refused():
    import eomgen.dynamics  # noqa: F401  (every builder registered)

    with pytest.raises(ValueError, match="builder of 'M' is already registered"):
        builders.builds("M")(lambda derivation, wanted: {})
    with pytest.raises(ValueError, match="no printed output"):
        builders.builds("P")  # returned by the Lagrangian builder, declared by no output
    with pytest.raises(LookupError, match="no builder registered for output 'nothing'"):
        builders.builder_of("nothing")
    assert builders.builder_of("M") is builders.builder_of("C")  # built in one call


def test_each_constants_provider_gives_the_names_it_is_registered_for():
    """What a provider returns are the names the catalogue declares, in that order (the
    values are the model's: a model without frames, contacts or loops gives empty tuples)."""
    import eomgen.dynamics  # noqa: F401

    model = eomgen.load(eomgen.example_path("planar_2link"))
    for names, provider in builders.CONSTANTS.items():
        got = provider(SimpleNamespace(model=model))
        assert tuple(got) == names, provider


def test_the_input_sizes_come_from_the_registered_functions():
    import eomgen.dynamics  # noqa: F401

    model = eomgen.load(eomgen.example_path("planar_2link"))
    assert builders.input_size("q", model) == model.nq
    assert builders.input_size("F_c", model) == 0  # no contacts, no loops
    assert builders.input_size("qd", model) == model.dof
    with pytest.raises(ValueError, match="unknown input"):
        builders.input_size("nothing", model)


def test_the_catalogue_is_data():
    """It and its record type's module import nothing but the standard library and each other,
    and the catalogue holds no callable but its record type (no builder named, by reference or
    by string)."""
    for name, allowed in (("catalogue", {"__future__", "record"}),
                          ("record", {"__future__", "dataclasses"})):
        tree = ast.parse((ROOT / "eomgen" / "outputs" / f"{name}.py").read_text(encoding="utf-8"))
        imported = [node.module if isinstance(node, ast.ImportFrom) else a.name
                    for node in ast.walk(tree) if isinstance(node, (ast.Import, ast.ImportFrom))
                    for a in node.names]
        assert set(imported) <= allowed, name
    for output in catalogue.CATALOGUE:
        for value in vars(output).values():
            assert not callable(value), (output.function, value)
            assert not (isinstance(value, str) and ":" in value and value.startswith("eomgen.")), \
                (output.function, value)

