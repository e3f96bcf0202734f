"""The registries: outputs declared once (:mod:`eomgen.outputs`), backends found where they are
defined (:mod:`eomgen.codegen.backends`), one C compiler lookup (:mod:`eomgen.common.compiler`).

The generated modules are checked against the registry (names, inputs, shapes) and the
registry against what the project documented before it existed (the function table, the
backend order of ``--backend all``), so a registry that drifted from the code fails here.
"""

from __future__ import annotations

import dataclasses
import inspect
import shutil
from pathlib import Path

import numpy as np
import sympy as sp
import pytest

import eomgen
from eomgen import cache, outputs
from eomgen.common import compiler
from eomgen.codegen import BACKENDS, available_backends, loadable_backends, make_job
from eomgen.codegen.backends import BACKEND_MODULES, casadi_backend, fast_backend
from eomgen.codegen.functions import (RESERVED_IDENTIFIERS, derived_outputs,
                                      reserved_identifiers, safe_identifier, select_functions)
from eomgen.codegen.render import TEMPLATES_DIR
from eomgen.dynamics import ALL_OUTPUTS, derive
from eomgen.outputs import BY_SYMBOL, FORWARD, OUTPUTS, Output, register_output
from eomgen.symbolic.builders import BUILDERS, CONSTANTS, builds, provides
from support import load_module

#: The function table of the generated modules as the README documented it before the registry.
DOCUMENTED = {"mass_matrix": ("M", ("q",)), "coriolis_matrix": ("C", ("q", "qd")),
              "gravity_vector": ("g", ("q",)), "inverse_dynamics": ("tau", ("q", "qd", "qdd")),
              "forward_dynamics": (None, ("q", "qd", "tau"))}


@pytest.fixture(scope="module")
def planar():
    return derive(eomgen.load(eomgen.example_path("planar_2link")), outputs=ALL_OUTPUTS,
                  simplify=False)


def test_registry_holds_the_documented_functions_in_module_order():
    default = {f: o for f, o in OUTPUTS.items() if o.default}
    assert {f: (o.symbol, o.inputs) for f, o in default.items()} == DOCUMENTED
    assert list(default) == list(DOCUMENTED) == list(select_functions())
    assert ALL_OUTPUTS == ("M", "C", "g", "tau")
    assert {s: o.function for s, o in BY_SYMBOL.items() if o.default} == {
        "M": "mass_matrix", "C": "coriolis_matrix", "g": "gravity_vector",
        "tau": "inverse_dynamics"}
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
    module = load_module(path, "registry_planar_numpy")
    n = planar.model.dof
    rng = np.random.default_rng(3)
    values = {"q": rng.normal(size=n), "qd": rng.normal(size=n), "qdd": rng.normal(size=n),
              "tau": rng.normal(size=n)}
    results = {}
    for name, output in OUTPUTS.items():
        if not output.default:
            assert not hasattr(module, name), name
            continue
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
    """Code templates name no printed output anywhere (their code is the generated module's);
    document templates (LaTeX, handouts, the notebook's cells) none in their Jinja code, where
    prose and the notebook's calls of eomgen's API may say "regressor"."""
    import re

    printed = [f for f, o in OUTPUTS.items() if not o.composed]
    for template in TEMPLATES_DIR.rglob("*.jinja"):
        text = template.read_text(encoding="utf-8")
        if template.parent.name in ("latex", "teach", "notebook"):
            text = " ".join(re.findall(r"\{\{.*?\}\}|\{%.*?%\}", text, flags=re.S))
        assert not [f for f in printed if re.search(rf"\b{f}\b", text)], template


def test_backends_are_found_in_the_documented_order_with_their_configs():
    found = sorted(p.stem for p in Path(casadi_backend.__file__).parent.glob("*_backend.py"))
    assert list(BACKEND_MODULES) == found
    found = available_backends()
    # by order (the reference NumPy first); a backend added later finds its own place
    assert next(iter(found)) == "numpy"
    assert [b.order for b in found.values()] == sorted(b.order for b in found.values())
    assert {"numpy", "casadi", "c", "fast", "latex"} <= set(found)
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
    reserved = {name for backend in available_backends().values() for name in backend.reserved}
    assert {"np", "ca", "casadi"} <= reserved and reserved <= reserved_identifiers()
    assert not reserved & set(RESERVED_IDENTIFIERS)  # each backend says it itself
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
    assert f"{list(available_backends())[-2]}, zig" in result.output


# ----------------------------------------------------------------------------------------------
# An output is one catalogue entry plus one registered builder: three made-up outputs (a 2×3 matrix of q, a
# vector of q, qd and tau, a vector without inputs with module constants) go through every
# backend and are compared with SymPy evaluating what the builders returned.
# ----------------------------------------------------------------------------------------------

def _toy_builder(derivation, wanted):
    q, qd, tau = derivation.q, derivation.qd, derivation.tau
    p = {s.name: s for s in derivation.model.parameter_symbols} if hasattr(
        derivation.model, "parameter_symbols") else {
        par.name: par.symbol for par in derivation.model.parameters}
    shared = derivation.builder.define(sp.cos(q[0]) * p["l1"], "toy_c")
    built = {
        "TOY_A": sp.Matrix([[shared, sp.sin(q[1]), 1], [q[0] * q[1], 0, p["m2"] * shared]]),
        "TOY_B": sp.Matrix([tau[k] - qd[k] * q[k] + shared for k in range(len(q))]),
        "TOY_C": sp.Matrix([p["m1"], 2 * p["m2"] + sp.Rational(1, 3)]),
    }
    return {name: built[name] for name in wanted}


def _toy_constants(dynamics):
    return {"TOY_NAMES": ("first", "second 'quoted'")}


_TOYS = (
    Output("toy_a", "TOY_A", "A 2x3 matrix of q.", ("q",), False, "1", ("TOY_A",),
           default=False),
    Output("toy_b", "TOY_B", "A vector of q, qd and tau.", ("q", "qd", "tau"), True, "1",
           ("TOY_B",), default=False),
    Output("toy_c", "TOY_C", "A vector of the parameters only.", (), True, "kg", ("TOY_C",),
           default=False, constants=("TOY_NAMES",)),
)


@pytest.fixture
def toys():
    for toy in _TOYS:
        register_output(toy)
    builds("TOY_A", "TOY_B", "TOY_C")(_toy_builder)  # as a module registers its builder
    provides("TOY_NAMES")(_toy_constants)
    try:
        yield _TOYS
    finally:
        for toy in _TOYS:
            OUTPUTS.pop(toy.function, None)
            BY_SYMBOL.pop(toy.symbol, None)
            BUILDERS.pop(toy.symbol, None)
        CONSTANTS.pop(("TOY_NAMES",), None)


def test_a_registered_output_reaches_every_backend(toys, tmp_path):
    from eomgen.codegen.generate import render_files

    model = eomgen.load(eomgen.example_path("planar_2link"))
    assert "toy_a" not in select_functions() and "TOY_A" not in ALL_OUTPUTS
    functions = select_functions(["TOY_A", "toy_b", "TOY_C", "g"])
    assert functions == ("gravity_vector", "toy_a", "toy_b", "toy_c")
    dyn = derive(model, outputs=derived_outputs(functions), simplify=False)
    job = make_job(dyn, functions, count_operations=False)
    assert job.constants == (("TOY_NAMES", ("first", "second 'quoted'")),)

    rng = np.random.default_rng(7)
    q, qd, tau = rng.normal(size=(3, 2))
    values = {p.symbol: p.value for p in model.parameters}
    subs = {**values, **dict(zip(dyn.q, q)), **dict(zip(dyn.qd, qd)), **dict(zip(dyn.efforts, tau))}
    full = dyn.program.expanded()
    expected = {o.function: np.array(dyn.program.expand(dyn.program.output(o.symbol), full)
                                     .subs(subs).evalf(), dtype=float) for o in toys}
    expected = {f: (e.ravel() if OUTPUTS[f].is_vector else e) for f, e in expected.items()}
    args = {"toy_a": (q,), "toy_b": (q, qd, tau), "toy_c": ()}

    have = list(loadable_backends())  # every code backend the registry can load here
    files = {f.name: f for f in render_files(model, have, functions=functions)}
    for f in files.values():
        path = tmp_path / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    loaded = {name: dict(loadable_backends()[name].load(tmp_path, "planar_2link").namespace)
              for name in have}
    for name, module in loaded.items():
        assert tuple(module["TOY_NAMES"]) == ("first", "second 'quoted'"), name
        assert "TOY_NAMES" in module["__all__"] or name == "casadi", name
        for function, result in expected.items():
            if name == "casadi":  # by name: the parameters take their defaults
                call = dict(zip(OUTPUTS[function].inputs, args[function]))
                got = np.array(module[function].call(call)[OUTPUTS[function].symbol], dtype=float)
                got = got.ravel() if OUTPUTS[function].is_vector else got
            else:
                got = module[function](*args[function])
            got = np.asarray(got, dtype=float)
            np.testing.assert_allclose(got, result, rtol=1e-12, atol=1e-14,
                                       err_msg=f"{name} {function}")
    # a batch of states gives a batch of results; a function of the parameters only, one result
    batch = loaded["numpy"]["toy_b"](np.tile(q, (4, 1)), np.tile(qd, (4, 1)), np.tile(tau, (4, 1)))
    np.testing.assert_allclose(batch, np.tile(expected["toy_b"], (4, 1)), rtol=1e-12)
    np.testing.assert_allclose(loaded["numpy"]["toy_c"](m1=3.0), [3.0, 2 * 1.0 + 1 / 3])


def test_cli_outputs_option_selects_and_refuses(tmp_path):
    from click.testing import CliRunner

    from eomgen.cli import main

    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["generate", "--backend", "numpy", "--outputs", "g,taux",
                                       "-o", str(out), "--no-cache"])
    assert result.exit_code == 2, result.output
    assert "--outputs: unknown output 'taux'" in result.output and "did you mean 'tau'" in result.output
    assert not out.exists()
    result = CliRunner().invoke(main, ["generate", "--backend", "numpy", "--outputs", "g",
                                       "-o", str(out), "--no-cache", "--quiet"])
    assert result.exit_code == 0, result.output
    text = (out / "planar_2link_numpy.py").read_text()
    assert "def gravity_vector(" in text and "def mass_matrix(" not in text
