"""The registries: outputs declared once (:mod:`eomgen.outputs`), backends found where they are
defined (:mod:`eomgen.codegen.backends`), one C compiler lookup (:mod:`eomgen.compiler`).

The generated modules are checked against the registry (names, inputs, shapes) and the
registry against what the project documented before it existed (the function table, the
backend order of ``--backend all``), so a registry that drifted from the code fails here.
"""

from __future__ import annotations

import dataclasses
import importlib.util
import inspect
import shutil
from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen import cache, compiler, outputs
from eomgen.codegen import BACKENDS, available_backends, make_job
from eomgen.codegen.backends import BACKEND_MODULES, casadi_backend, fast_backend
from eomgen.codegen.functions import (FUNCTION_ALIASES, RESERVED_IDENTIFIERS, derived_outputs,
                                      reserved_identifiers, safe_identifier, select_functions)
from eomgen.codegen.render import TEMPLATES_DIR
from eomgen.dynamics import ALL_OUTPUTS, derive
from eomgen.outputs import BY_SYMBOL, FORWARD, OUTPUTS, Output, register_output

#: The function table of the generated modules as the README documented it before the registry.
DOCUMENTED = {"mass_matrix": ("M", ("q",)), "coriolis_matrix": ("C", ("q", "qd")),
              "gravity_vector": ("g", ("q",)), "inverse_dynamics": ("tau", ("q", "qd", "qdd")),
              "forward_dynamics": (None, ("q", "qd", "tau"))}


@pytest.fixture(scope="module")
def planar():
    return derive(eomgen.load(eomgen.example_path("planar_2link")), outputs=ALL_OUTPUTS,
                  simplify=False)


def test_registry_holds_the_documented_functions_in_module_order():
    assert {f: (o.symbol, o.inputs) for f, o in OUTPUTS.items()} == DOCUMENTED
    assert list(OUTPUTS) == list(DOCUMENTED)
    assert ALL_OUTPUTS == ("M", "C", "g", "tau")
    assert FUNCTION_ALIASES == {"M": "mass_matrix", "C": "coriolis_matrix",
                                "g": "gravity_vector", "tau": "inverse_dynamics"}
    assert FORWARD.composed and FORWARD.composed_from == ("mass_matrix", "inverse_dynamics")
    assert set(OUTPUTS) | set(BY_SYMBOL) <= RESERVED_IDENTIFIERS


def test_selection_follows_the_registry():
    assert select_functions(["g", "forward_dynamics"]) == (
        "mass_matrix", "gravity_vector", "inverse_dynamics", "forward_dynamics")
    assert derived_outputs(["forward_dynamics"]) == ("M", "tau")
    with pytest.raises(ValueError, match="did you mean 'tau'"):
        select_functions(["taux"])


def test_register_output_refuses_duplicates_and_unknown_parts():
    taken = dataclasses.replace(OUTPUTS["gravity_vector"], symbol="g2")
    with pytest.raises(ValueError, match="already registered"):
        register_output(taken)
    with pytest.raises(ValueError, match="symbol 'M'"):
        register_output(dataclasses.replace(taken, function="other", symbol="M"))
    with pytest.raises(ValueError, match="unregistered"):
        register_output(Output("other", None, "", ("q",), True, "", ("M",),
                               composed_from=("no_such_function",)))
    assert "other" not in OUTPUTS and "g2" not in BY_SYMBOL


def test_generated_module_exports_the_registry_with_its_shapes(planar, tmp_path):
    job = make_job(planar, count_operations=False)
    (file,) = available_backends()["numpy"].generate(job)
    path = tmp_path / file.name
    path.write_text(file.content, encoding="utf-8")
    spec = importlib.util.spec_from_file_location("registry_planar_numpy", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    n = planar.model.dof
    rng = np.random.default_rng(3)
    values = {"q": rng.normal(size=n), "qd": rng.normal(size=n), "qdd": rng.normal(size=n),
              "tau": rng.normal(size=n)}
    results = {}
    for name, output in OUTPUTS.items():
        function = getattr(module, name)
        params = [p.name for p in inspect.signature(function).parameters.values()
                  if p.kind is p.POSITIONAL_OR_KEYWORD]
        assert tuple(params) == output.inputs, name
        results[name] = function(*(values[a] for a in output.inputs))
        assert np.shape(results[name]) == output.shape(n), name
    # the composed function is built from the functions the registry names
    M = results[FORWARD.composed_from[0]]
    bias = getattr(module, FORWARD.composed_from[1])(values["q"], values["qd"], np.zeros(n))
    np.testing.assert_allclose(M @ results[FORWARD.function], values["tau"] - bias,
                               rtol=1e-10, atol=1e-12)


def test_templates_name_no_printed_output():
    printed = [f for f, o in OUTPUTS.items() if not o.composed]
    for template in TEMPLATES_DIR.rglob("*.jinja"):
        text = template.read_text(encoding="utf-8")
        assert not [f for f in printed if f in text], template


def test_backends_are_found_in_the_documented_order_with_their_configs():
    found = sorted(p.stem for p in Path(casadi_backend.__file__).parent.glob("*_backend.py"))
    assert list(BACKEND_MODULES) == found
    assert list(available_backends()) == ["numpy", "casadi", "c", "fast", "latex", "jax", "torch"]
    for name, backend in available_backends().items():
        assert dataclasses.is_dataclass(backend.config), name
        config = backend.config()
        assert (TEMPLATES_DIR / config.template).is_file(), name
        assert config.suffix, name


def test_a_caller_passes_a_config(planar):
    job = make_job(planar, ["g"], count_operations=False)
    backend = available_backends()["numpy"]
    (default,) = backend.generate(job)
    (renamed,) = backend.generate(job, backend.config(suffix="_np.py"))
    assert default.name == "planar_2link_numpy.py" and renamed.name == "planar_2link_np.py"
    assert renamed.content == default.content


def test_backends_reserve_the_names_their_modules_import(monkeypatch):
    assert {"np", "ca", "casadi", "jnp", "torch"} <= reserved_identifiers()
    assert not {"np", "ca", "jnp", "torch"} & RESERVED_IDENTIFIERS  # each says it itself
    assert safe_identifier("np", set()) == "np_"
    available_backends()
    monkeypatch.setitem(BACKENDS, "other", dataclasses.replace(
        BACKENDS["numpy"], name="other", reserved=("stiffness",)))
    assert safe_identifier("stiffness", set()) == "stiffness_"


def test_replacing_a_backend_keeps_its_place(monkeypatch):
    available_backends()
    order = list(BACKENDS)
    monkeypatch.setitem(BACKENDS, "numpy", dataclasses.replace(BACKENDS["numpy"], order=10**6))
    assert list(available_backends()) == order


def test_one_compiler_lookup(monkeypatch):
    true = shutil.which("true")
    if true is None:
        pytest.skip("no `true` executable to stand in for a compiler")
    monkeypatch.setenv("CC", "true")
    assert compiler.c_compiler() == "true"
    assert compiler.c_compiler_path() == true
    assert cache.toolchain()["cc"] == true
    assert casadi_backend.c_compiler is compiler.c_compiler
    assert fast_backend.c_compiler is compiler.c_compiler
    monkeypatch.setenv("CC", "")
    monkeypatch.setenv("PATH", "")
    assert compiler.c_compiler() is None and cache.toolchain()["cc"] is None
    assert outputs.OUTPUTS  # the registry needs no compiler


def test_cli_help_lists_the_registered_backends(monkeypatch):
    from click.testing import CliRunner

    from eomgen.cli import main

    available_backends()
    monkeypatch.setitem(BACKENDS, "zig", dataclasses.replace(BACKENDS["numpy"], name="zig"))
    result = CliRunner().invoke(main, ["generate", "--help"], terminal_width=200)
    assert result.exit_code == 0, result.output
    assert ("among " + ", ".join(available_backends()) + "; or all") in result.output
    assert "torch, zig" in result.output
