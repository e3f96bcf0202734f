"""Generated code (NumPy module, CasADi module, C through CasADi) run for real.

Every example is generated once per module (:func:`example`), then its modules are imported
from the written files and its shared library is loaded with ``casadi.external``:

* identities with the numeric recursive Newton–Euler algorithm (:func:`eomgen.numeric.rnea`):
  ``tau = RNEA(q, q̇, q̈)``, column i of ``M`` = ``RNEA(q, 0, eᵢ) − RNEA(q, 0, 0)``,
  ``g = RNEA(q, 0, 0)``, ``C(q, q̇) q̇ = RNEA(q, q̇, 0) − RNEA(q, 0, 0)``;
* NumPy, CasADi and compiled C agree on all five functions; batches equal single calls;
  ``forward_dynamics`` inverts ``inverse_dynamics``;
* the interface: JOINT_NAMES, NQ, PARAMETERS and keyword parameters, CasADi's named inputs and
  outputs, shape errors, a singular mass matrix, imports and public names;
* hostile robot, link, joint and parameter names (code injection through generated sources);
* byte-identical output across runs and hash seeds, all-or-nothing writes, ``eomgen generate``.

Numeric comparisons are relative: ``max|a − b| ≤ 1e-10 · max(1, max|b|)``.
"""

from __future__ import annotations

import ast
import builtins
import ctypes
import io
import keyword
import os
import re
import shutil
import subprocess
import sys
import tokenize
from dataclasses import dataclass
from pathlib import Path
from types import ModuleType

import casadi as ca
import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.codegen import BACKENDS, Backend, GeneratedFile, available_backends
from eomgen.codegen.backends.casadi_backend import FUNCTION_NAMES, c_compiler, library_name
from eomgen.codegen.generate import generate, keep_symbolic, render_files, write_atomically
from eomgen.model import (Inertial, Joint, JointType, Link, Parameter, RobotModel, Transform,
                          build_model, vec3)
from eomgen.numeric import NumericModel, numeric_model, rnea
from support.robots import DOCSTRING_BREAKER, HOSTILE, hostile_star, ur5
from support import (
    TESTS, assert_close, erd_robots_dir, load_module, load_quietly, random_states,
    render_text_files,
)
from support.reference import random_robot

RTOL = 1e-10

#: What every generated Python module exports.
PUBLIC = ("JOINT_NAMES", "CONFIGURATION_NAMES", "NQ", "NV", "PARAMETERS", "mass_matrix", "coriolis_matrix", "gravity_vector",
          "inverse_dynamics", "forward_dynamics")
#: The NumPy module also exports the category of forward_dynamics' ill-conditioning warning.
PUBLIC_EXTRA = {"numpy": ("IllConditionedWarning",), "casadi": ()}
#: Standard-library imports besides the numeric library (aliased to stay out of the namespace).
STDLIB_IMPORTS = {"numpy": [("warnings", "_warnings")], "casadi": []}
#: Function → (vector inputs, output name) as documented in eomgen.codegen.functions.
SIGNATURES = {
    "mass_matrix": (("q",), "M"),
    "coriolis_matrix": (("q", "qd"), "C"),
    "gravity_vector": (("q",), "g"),
    "inverse_dynamics": (("q", "qd", "qdd"), "tau"),
    "forward_dynamics": (("q", "qd", "tau"), "qdd"),
}
MATRIX_OUTPUTS = {"mass_matrix", "coriolis_matrix"}



# ----------------------------------------------------------------------------------------------
# Helpers
# ----------------------------------------------------------------------------------------------

def ca_call(f, parameters: dict, *vectors) -> np.ndarray:
    """Evaluate a casadi.Function of the generated interface at one state; parameters by name."""
    args = [ca.DM(np.asarray(v, dtype=float)) for v in vectors]
    args += [parameters[name] for name in f.name_in()[len(vectors):]]
    out = np.array(f(*args).full())
    return out if f.name() in MATRIX_OUTPUTS else out[:, 0]


def numpy_call(module: ModuleType, function: str, *vectors, **parameters) -> np.ndarray:
    return getattr(module, function)(*vectors, **parameters)


def rnea_reference(nm: NumericModel, function: str, q, qd, third) -> np.ndarray:
    """What ``function`` must return, from RNEA alone (``third`` is qdd or tau)."""
    n = nm.n
    zero = np.zeros(n)
    g = rnea(nm, q, zero, zero)
    if function == "gravity_vector":
        return g
    if function == "inverse_dynamics":
        return rnea(nm, q, qd, third)
    M = np.column_stack([rnea(nm, q, zero, e) - g for e in np.eye(n)])
    if function == "mass_matrix":
        return M
    if function == "forward_dynamics":
        return np.linalg.solve(M, third - rnea(nm, q, qd, zero))
    raise ValueError(function)  # coriolis_matrix is only known through C qd


#: Example name → the model. The random robots cover a chain and a tree, prismatic and fixed
#: joints, massless links and q order ≠ tree order (see test_random_robots_cover_...).
EXAMPLES = {
    "planar_2link": lambda: load_quietly(eomgen.example_path("planar_2link")),
    "puma560": lambda: load_quietly(eomgen.example_path("puma560_dh")),
    "ur5": ur5,
    "random_chain": lambda: random_robot(np.random.default_rng(8), 4),
    "random_tree": lambda: random_robot(np.random.default_rng(1), 5, tree=True),
}


@dataclass
class Example:
    name: str
    stem: str  # file-name stem of the generated files
    model: RobotModel
    nm: NumericModel
    paths: dict[str, Path]
    numpy: ModuleType
    casadi: ModuleType
    compiled: dict | None  # function name → casadi.external, None without a C compiler

    @property
    def n(self) -> int:
        return self.model.dof


def build_example(name: str, model: RobotModel, outdir: Path, backends="numpy,casadi,c"
                  ) -> Example:
    paths = generate(model, outdir, backends)
    by_name = {p.name: p for p in paths}
    stem = next(p.name[:-len("_numpy.py")] for p in paths if p.name.endswith("_numpy.py"))
    library = by_name.get(library_name(stem))
    compiled = None
    if library is not None:
        compiled = {f: ca.external(f, str(library)) for f in FUNCTION_NAMES}
    return Example(
        name=name, stem=stem, model=model, nm=numeric_model(model), paths=by_name,
        numpy=load_module(by_name[stem + "_numpy.py"], f"generated_{name}_numpy"),
        casadi=load_module(by_name[stem + "_casadi.py"], f"generated_{name}_casadi"),
        compiled=compiled)


@pytest.fixture(scope="module")
def build(tmp_path_factory):
    """``build(name) -> Example``: each example generated at most once per module."""
    cache: dict[str, Example] = {}

    def get(name: str) -> Example:
        if name not in cache:
            model = EXAMPLES[name]()
            cache[name] = build_example(name, model, tmp_path_factory.mktemp(name))
        return cache[name]

    return get


@pytest.fixture(params=list(EXAMPLES))
def example(request, build) -> Example:
    return build(request.param)


def needs_compiled(ex: Example):
    if ex.compiled is None:
        assert c_compiler() is None, "a C compiler exists but no shared library was built"
        pytest.skip("no C compiler: the C backend writes sources only")
    return ex.compiled


# ----------------------------------------------------------------------------------------------
# The NumPy module against Newton–Euler
# ----------------------------------------------------------------------------------------------

def test_random_robots_cover_prismatic_fixed_and_trees():
    chain, tree = EXAMPLES["random_chain"](), EXAMPLES["random_tree"]()
    for model in (chain, tree):
        kinds = {j.type for j in model.joints}
        assert {JointType.PRISMATIC, JointType.FIXED} <= kinds
        assert any(link.inertial is None for link in model.links)
    parents = [j.parent for j in tree.joints]
    assert len(set(parents)) < len(parents), "the tree has a branching link"
    assert chain.joint_names != tuple(j.name for j in chain.topological_joints
                                      if j.type.is_movable), "q order = tree order"


def test_inverse_dynamics_is_newton_euler(example):
    for q, qd, qdd in random_states(np.random.default_rng(1), example.n):
        assert_close(example.numpy.inverse_dynamics(q, qd, qdd), rnea(example.nm, q, qd, qdd),
                     "tau")


def test_mass_matrix_columns_are_newton_euler_differences(example):
    nm, n = example.nm, example.n
    zero = np.zeros(n)
    for q, _, _ in random_states(np.random.default_rng(2), n):
        M = example.numpy.mass_matrix(q)
        g = rnea(nm, q, zero, zero)
        for i, e in enumerate(np.eye(n)):
            assert_close(M[:, i], rnea(nm, q, zero, e) - g, f"M column {i}")
        assert_close(M, M.T, "M symmetric")


def test_gravity_vector_is_newton_euler_at_rest(example):
    zero = np.zeros(example.n)
    for q, _, _ in random_states(np.random.default_rng(3), example.n):
        assert_close(example.numpy.gravity_vector(q), rnea(example.nm, q, zero, zero), "g")


def test_coriolis_matrix_times_qd_is_newton_euler_difference(example):
    zero = np.zeros(example.n)
    for q, qd, _ in random_states(np.random.default_rng(4), example.n):
        expected = rnea(example.nm, q, qd, zero) - rnea(example.nm, q, zero, zero)
        assert_close(example.numpy.coriolis_matrix(q, qd) @ qd, expected, "C qd")


def test_forward_dynamics_inverts_inverse_dynamics(example):
    module = example.numpy
    for q, qd, qdd in random_states(np.random.default_rng(5), example.n):
        tau = module.inverse_dynamics(q, qd, qdd)
        assert_close(module.forward_dynamics(q, qd, tau), qdd, "FD(ID(qdd))")
        tau = 10.0 * qdd  # now the other way round: an arbitrary effort
        qdd_of_tau = module.forward_dynamics(q, qd, tau)
        assert_close(module.inverse_dynamics(q, qd, qdd_of_tau), tau, "ID(FD(tau))")
        assert_close(qdd_of_tau, rnea_reference(example.nm, "forward_dynamics", q, qd, tau),
                     "FD vs RNEA")


# ----------------------------------------------------------------------------------------------
# NumPy == CasADi == compiled C
# ----------------------------------------------------------------------------------------------

def _arguments(ex: Example, function: str, state) -> tuple:
    q, qd, qdd = state
    third = ex.numpy.inverse_dynamics(q, qd, qdd) if function == "forward_dynamics" else qdd
    return {"q": q, "qd": qd, "qdd": qdd, "tau": third}, SIGNATURES[function][0]


def test_casadi_module_equals_numpy_module(example):
    params = example.numpy.PARAMETERS
    for state in random_states(np.random.default_rng(6), example.n, count=3):
        for function in FUNCTION_NAMES:
            values, inputs = _arguments(example, function, state)
            vectors = [values[a] for a in inputs]
            assert_close(ca_call(getattr(example.casadi, function), params, *vectors),
                         numpy_call(example.numpy, function, *vectors), function)


def test_compiled_c_equals_casadi_module(example):
    compiled = needs_compiled(example)
    params = example.numpy.PARAMETERS
    for state in random_states(np.random.default_rng(7), example.n, count=3):
        for function in FUNCTION_NAMES:
            values, inputs = _arguments(example, function, state)
            vectors = [values[a] for a in inputs]
            expected = numpy_call(example.numpy, function, *vectors)
            assert_close(ca_call(compiled[function], params, *vectors), expected, f"C {function}")
            assert_close(ca_call(getattr(example.casadi, function), params, *vectors), expected,
                         f"CasADi {function}")


def test_casadi_inputs_and_outputs_are_named_as_documented(example):
    parameters = list(example.numpy.PARAMETERS)
    assert list(example.casadi.PARAMETERS.items()) == list(example.numpy.PARAMETERS.items())
    compiled = example.compiled or {}
    for function, (inputs, output) in SIGNATURES.items():
        for f in (getattr(example.casadi, function), compiled.get(function)):
            if f is None:
                continue
            assert f.name() == function
            assert f.name_in() == list(inputs) + parameters
            assert f.name_out() == [output]
            for k in range(len(inputs)):
                assert f.size_in(k) == (example.n, 1)
            n = example.n
            assert f.size_out(0) == ((n, n) if function in MATRIX_OUTPUTS else (n, 1))
    # Calling by name: mass_matrix(q=q, <parameters>)["M"].
    q = np.linspace(-1, 1, example.n)
    by_name = example.casadi.mass_matrix(q=q, **example.casadi.PARAMETERS)["M"]
    assert_close(np.array(by_name.full()), example.numpy.mass_matrix(q), "M by name")


# ----------------------------------------------------------------------------------------------
# Shapes: batches, single states, bad input
# ----------------------------------------------------------------------------------------------

def test_batches_equal_single_calls(example):
    module, n = example.numpy, example.n
    rng = np.random.default_rng(8)
    N = 5
    Q = rng.uniform(-np.pi, np.pi, (N, n))
    QD, QDD = rng.normal(size=(N, n)), rng.normal(size=(N, n))
    TAU = module.inverse_dynamics(Q, QD, QDD)
    inputs = {"q": Q, "qd": QD, "qdd": QDD, "tau": TAU}
    for function, (names, _) in SIGNATURES.items():
        batched = numpy_call(module, function, *(inputs[a] for a in names))
        single_shape = (n, n) if function in MATRIX_OUTPUTS else (n,)
        assert batched.shape == (N,) + single_shape, function
        for k in range(N):
            single = numpy_call(module, function, *(inputs[a][k] for a in names))
            assert single.shape == single_shape, function
            assert_close(batched[k], single, f"{function} state {k}")
        one = numpy_call(module, function, *(inputs[a][:1] for a in names))
        assert one.shape == (1,) + single_shape, f"{function}: a batch of one stays a batch"
        empty = numpy_call(module, function, *(inputs[a][:0] for a in names))
        assert empty.shape == (0,) + single_shape, function


def test_lists_are_accepted(build):
    module = build("planar_2link").numpy
    assert_close(module.gravity_vector([0.1, 0.2]), module.gravity_vector(np.array([0.1, 0.2])))
    assert module.mass_matrix([[0, 0], [1, 1], [2, 2]]).shape == (3, 2, 2)


BAD_SHAPES = [
    ("mass_matrix", [np.zeros(3)]),
    ("mass_matrix", [np.zeros(1)]),
    ("mass_matrix", [np.zeros((4, 3))]),
    ("mass_matrix", [np.zeros((2, 2, 2))]),
    ("mass_matrix", [0.5]),
    ("gravity_vector", [np.zeros((2, 1))]),
    ("coriolis_matrix", [np.zeros(2), np.zeros(3)]),
    ("coriolis_matrix", [np.zeros((3, 2)), np.zeros((4, 2))]),
    ("coriolis_matrix", [np.zeros((3, 2)), np.zeros(2)]),  # a state and a batch of 3
    ("inverse_dynamics", [np.zeros(2), np.zeros(2), np.zeros((2, 2, 1))]),
    ("inverse_dynamics", [np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((3, 2))]),
    ("forward_dynamics", [np.zeros(2), np.zeros(2), np.ones((3, 2))]),  # not silently 1 state
    ("forward_dynamics", [np.zeros((3, 2)), np.zeros((3, 2)), np.ones((1, 2))]),
    ("forward_dynamics", [np.zeros((3, 2)), np.zeros((3, 2)), np.ones((2, 2))]),
    ("forward_dynamics", [np.zeros(2), np.zeros(5), np.ones(2)]),
]


@pytest.mark.parametrize("function, arguments", BAD_SHAPES,
                         ids=[f"{f}-{i}" for i, (f, _) in enumerate(BAD_SHAPES)])
def test_bad_shapes_raise_value_error(build, function, arguments):
    module = build("planar_2link").numpy
    with pytest.raises(ValueError, match="shape|same number of states"):
        getattr(module, function)(*arguments)


def test_a_batch_of_one_with_single_states_is_a_batch(build):
    module = build("planar_2link").numpy
    q = np.array([0.3, -0.2])
    assert module.coriolis_matrix(q[None], q).shape == (1, 2, 2)
    assert module.coriolis_matrix(q, q[None]).shape == (1, 2, 2)
    assert module.forward_dynamics(q, q, q[None]).shape == (1, 2)


def test_singular_mass_matrix_raises_linalg_error(tmp_path):
    """A massless link at the end of a prismatic joint: M has a zero row and column."""
    body = Inertial(2.0, [0.3, 0, 0], [[0.01, 0, 0], [0, 0.02, 0], [0, 0, 0.02]])
    model = build_model(
        "<test>", "singular_slider",
        [Link("base"), Link("arm", body), Link("slider")],
        [Joint("shoulder", JointType.REVOLUTE, "base", "arm", Transform(), vec3([0, 0, 1])),
         Joint("slide", JointType.PRISMATIC, "arm", "slider",
               Transform.from_xyz_rpy([0.5, 0, 0]), vec3([1, 0, 0]))])
    generate(model, tmp_path, "numpy")
    module = load_module(tmp_path / "singular_slider_numpy.py", "singular_slider")
    q = np.array([0.4, 0.1])
    M = module.mass_matrix(q)
    assert M[1, 1] == 0.0 and np.all(M[:, 1] == 0.0)
    assert_close(M, rnea_reference(numeric_model(model), "mass_matrix", q, q, q), "M")
    with pytest.raises(np.linalg.LinAlgError):
        module.forward_dynamics(q, np.zeros(2), np.ones(2))
    with pytest.raises(np.linalg.LinAlgError):
        module.forward_dynamics(np.stack([q, q]), np.zeros((2, 2)), np.ones((2, 2)))


# ----------------------------------------------------------------------------------------------
# Interface: names, parameters, imports
# ----------------------------------------------------------------------------------------------

def test_joint_names_and_nq(example):
    for module in (example.numpy, example.casadi):
        assert module.JOINT_NAMES == example.model.joint_names
        assert module.NQ == example.model.dof == len(module.JOINT_NAMES)
    declared = {p.name: p.value for p in example.model.parameters}
    assert sorted(example.numpy.PARAMETERS.values()) == sorted(declared.values())


def _module_tree(path: Path) -> ast.Module:
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _imports(tree: ast.Module) -> list[tuple[str, str | None]]:
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(a.name, a.asname) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            found += [(f"{node.module}.{a.name}", a.asname) for a in node.names]
    return found


def _top_level_names(tree: ast.Module) -> set[str]:
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.Assign):
            for target in node.targets:
                names |= {n.id for n in ast.walk(target) if isinstance(n, ast.Name)}
        elif isinstance(node, (ast.AnnAssign, ast.AugAssign)):
            names.add(node.target.id)
    return names


def _dunder_all(tree: ast.Module) -> list[str]:
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
                isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets):
            return ast.literal_eval(node.value)
    raise AssertionError("no __all__")


@pytest.mark.parametrize("kind, library, alias", [("numpy", "numpy", "np"),
                                                  ("casadi", "casadi", "ca")])
def test_modules_import_one_library_and_export_the_documented_names(example, kind, library,
                                                                    alias):
    path = example.paths[f"{example.stem}_{kind}.py"]
    tree = _module_tree(path)
    assert _imports(tree) == STDLIB_IMPORTS[kind] + [(library, alias)]
    public = PUBLIC + PUBLIC_EXTRA[kind]
    assert _dunder_all(tree) == list(public)
    defined = _top_level_names(tree) - {"__all__"}
    assert {n for n in defined if not n.startswith("_")} == set(public)
    module = getattr(example, kind)
    assert {n for n in vars(module) if not n.startswith("_")} == set(public) | {alias}
    assert ast.get_docstring(tree) and repr(example.model.name) in ast.get_docstring(tree)


def test_numpy_module_runs_without_casadi_sympy_or_eomgen(build, monkeypatch):
    ex = build("planar_2link")
    for name in ("casadi", "sympy", "eomgen", "jinja2", "scipy"):
        monkeypatch.setitem(sys.modules, name, None)  # any import of these now fails
    module = load_module(Path(ex.numpy.__file__), "planar_numpy_alone")
    assert_close(module.gravity_vector([0.1, 0.2]), ex.numpy.gravity_vector([0.1, 0.2]), "g")


def _parameter_identifiers_are_sound(module: ModuleType) -> None:
    names = list(module.PARAMETERS)
    assert len(set(names)) == len(names)
    module_names = set(vars(module))
    for identifier in names:
        assert identifier.isidentifier() and identifier.isascii(), identifier
        assert not keyword.iskeyword(identifier)
        assert identifier not in dir(builtins), identifier
        assert identifier not in module_names, f"{identifier} shadows a module-level name"


def test_keyword_parameters_equal_substituted_models(build, tmp_path):
    """m2 = 2.5 in the call equals the model with m2 = 2.5: through RNEA and regenerated."""
    ex = build("planar_2link")
    module, model = ex.numpy, ex.model
    assert module.PARAMETERS == {"I1": 1 / 12, "I2": 1 / 12, "g": 9.81, "l1": 1.0, "l2": 1.0,
                                 "lc1": 0.5, "lc2": 0.5, "m1": 1.0, "m2": 1.0}
    _parameter_identifiers_are_sound(module)
    m2 = sp.Symbol("m2", real=True)
    assert m2 in {p.symbol for p in model.parameters}
    generate(model.substitute({m2: 2.5}), tmp_path, "numpy")
    regenerated = load_module(tmp_path / "planar_2link_numpy.py", "planar_m2_fixed")
    assert "m2" not in regenerated.PARAMETERS
    changed = {"m2": 2.5, "g": 3.7, "lc1": 0.8}  # the description's names are the keywords
    nm = numeric_model(model, {"m2": 2.5, "g": 3.7, "lc1": 0.8})
    for q, qd, qdd in random_states(np.random.default_rng(9), 2):
        tau = module.inverse_dynamics(q, qd, qdd, **changed)
        assert_close(tau, rnea(nm, q, qd, qdd), "tau with parameters")
        for function in ("mass_matrix", "gravity_vector", "forward_dynamics"):
            assert_close(numpy_call(module, function, *(q, qd, tau)[:len(SIGNATURES[function][0])],
                                    **changed),
                         rnea_reference(nm, function, q, qd, tau), function)
        zero = np.zeros(2)
        assert_close(module.coriolis_matrix(q, qd, **changed) @ qd,
                     rnea(nm, q, qd, zero) - rnea(nm, q, zero, zero), "C qd")
        # m2 alone against the regenerated module with m2 = 2.5 built in
        for function, (names, _) in SIGNATURES.items():
            args = {"q": q, "qd": qd, "qdd": qdd, "tau": tau}
            vectors = [args[a] for a in names]
            assert_close(numpy_call(module, function, *vectors, m2=2.5),
                         numpy_call(regenerated, function, *vectors), f"{function} m2=2.5")
            assert_close(ca_call(getattr(ex.casadi, function), {**module.PARAMETERS, **changed},
                                 *vectors),
                         numpy_call(module, function, *vectors, **changed), f"CasADi {function}")


def test_parameters_may_be_arrays_over_the_batch(build):
    module = build("planar_2link").numpy
    rng = np.random.default_rng(10)
    Q, QD = rng.uniform(-3, 3, (4, 2)), rng.normal(size=(4, 2))
    m2 = np.array([0.5, 1.0, 2.0, 4.0])
    batched = module.coriolis_matrix(Q, QD, m2=m2, g=2.0)
    for k in range(4):
        assert_close(batched[k], module.coriolis_matrix(Q[k], QD[k], m2=m2[k], g=2.0), "C")


def test_symbolic_subset_fixes_the_other_parameters(build, tmp_path):
    ex = build("planar_2link")
    generate(ex.model, tmp_path, "numpy", symbolic=["m2"])
    module = load_module(tmp_path / "planar_2link_numpy.py", "planar_only_m2")
    assert module.PARAMETERS == {"m2": 1.0}
    q, qd, qdd = random_states(np.random.default_rng(11), 2, count=1)[0]
    assert_close(module.inverse_dynamics(q, qd, qdd, m2=3.0),
                 ex.numpy.inverse_dynamics(q, qd, qdd, m2=3.0), "tau")


# ----------------------------------------------------------------------------------------------
# Parameters left out of a call: the description's values in every interface, never zeros
# ----------------------------------------------------------------------------------------------

@dataclass
class Interfaces:
    """One generation's NumPy module, CasADi module and (with a C compiler) the shared library
    loaded with ``casadi.external``; ``nm`` is Newton–Euler on the model with the
    description's values."""

    numpy: ModuleType
    casadi: ModuleType
    compiled: dict | None
    nm: NumericModel
    functions: tuple[str, ...]
    library: Path | None


def load_interfaces(files: list[GeneratedFile], outdir: Path, model: RobotModel,
                    name: str) -> Interfaces:
    paths = {p.name: p for p in write_atomically(files, outdir)}
    stem = next(n[:-len("_numpy.py")] for n in paths if n.endswith("_numpy.py"))
    numpy_module = load_module(paths[stem + "_numpy.py"], f"{name}_numpy")
    functions = tuple(f for f in FUNCTION_NAMES if hasattr(numpy_module, f))
    library = paths.get(library_name(stem))
    if library is None:
        assert c_compiler() is None, "a C compiler exists but no shared library was built"
    compiled = None if library is None else {f: ca.external(f, str(library)) for f in functions}
    return Interfaces(numpy_module, load_module(paths[stem + "_casadi.py"], f"{name}_casadi"),
                      compiled, numeric_model(model), functions, library)


def as_array(x, function: str) -> np.ndarray:
    """A CasADi result as the NumPy module returns it: (n, n) matrices, (n,) vectors."""
    out = np.array(x.full())
    return out if function in MATRIX_OUTPUTS else out[:, 0]


def _changed(value: float) -> float:
    return 1.7 * value + 0.3  # never the value itself, never zero for a positive value


def assert_interfaces_use_description_values(ex: Interfaces, rng: np.random.Generator):
    """Every function of every interface, called in order with all inputs, by name with none,
    one or half of the parameters, and with a dict (``call``), equals the NumPy module with the
    same parameters; left out, they are the description's values (Newton–Euler)."""
    parameters = ex.numpy.PARAMETERS
    names = list(parameters)
    subsets = [[], *([n] for n in names), names[::2]]
    n = ex.numpy.NQ
    routes = {"CasADi": ex.casadi.__dict__, "C": ex.compiled or {}}
    if ex.library is not None:  # the C symbol casadi.external reads the defaults from
        shared = ctypes.CDLL(str(ex.library))
        for function in ex.functions:
            default_in = getattr(shared, function + "_default_in")
            default_in.restype, default_in.argtypes = ctypes.c_double, [ctypes.c_longlong]
            first = len(SIGNATURES[function][0])
            assert [default_in(first + k) for k in range(len(names))] == list(
                parameters.values()), function
    for q, qd, qdd in random_states(rng, n, count=2):
        tau = ex.numpy.inverse_dynamics(q, qd, qdd)
        values = {"q": q, "qd": qd, "qdd": qdd, "tau": tau}
        # The NumPy module without parameters is Newton–Euler with the description's values.
        assert_close(ex.numpy.gravity_vector(q),
                     rnea_reference(ex.nm, "gravity_vector", q, qd, qdd), "NumPy g")
        assert_close(tau, rnea(ex.nm, q, qd, qdd), "NumPy tau")
        for function in ex.functions:
            inputs, output = SIGNATURES[function]
            vectors = {a: values[a] for a in inputs}
            for route, functions in routes.items():
                if function not in functions:
                    continue
                f = functions[function]
                shape = lambda x: as_array(x, function)  # noqa: E731
                what = f"{route} {function}"
                expected = numpy_call(ex.numpy, function, *vectors.values())
                positional = f(*vectors.values(), *parameters.values())
                assert_close(shape(positional), expected, f"{what} in order")
                assert_close(shape(f.call(dict(vectors))[output]), expected,
                             f"{what} call(dict)")
                for subset in subsets:
                    given = {p: _changed(parameters[p]) for p in subset}
                    expected = numpy_call(ex.numpy, function, *vectors.values(), **given)
                    assert_close(shape(f(**vectors, **given)[output]), expected,
                                 f"{what} by name with {sorted(given) or 'no parameters'}")


SYMBOLIC_SUBSETS = [None, ["m2", "g"], ["m2"], []]


@pytest.mark.parametrize("symbolic", SYMBOLIC_SUBSETS, ids=lambda s: "all" if s is None else
                         ",".join(s) or "none")
def test_left_out_parameters_take_the_description_values(build, tmp_path, symbolic):
    """The issue: ``gravity_vector(q=q)["g"]`` of ``--symbolic m2,g`` was [0, 0] (CasADi filled
    the parameters with zeros)."""
    model = build("planar_2link").model
    files = render_files(keep_symbolic(model, symbolic), ["numpy", "casadi", "c"])
    ex = load_interfaces(files, tmp_path, model, "planar_defaults")
    if symbolic is not None:
        assert sorted(ex.casadi.PARAMETERS) == sorted(symbolic)
    q = np.array([0.3, -0.7])
    g = rnea_reference(ex.nm, "gravity_vector", q, None, None)
    assert np.all(np.abs(g) > 1.0)  # so that zeros would show
    assert_close(as_array(ex.casadi.gravity_vector(q=q)["g"], "gravity_vector"), g, "the issue's call")
    assert_interfaces_use_description_values(ex, np.random.default_rng(14))


@pytest.mark.slow
def test_scene_payload_is_in_the_defaults(tmp_path):
    """examples/scenes/ur5_payload.yaml keeps the payload mass m_load symbolic (2 kg): called
    without it, every interface carries the payload, which moves g(q) from the bare arm's."""
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    from eomgen.codegen.scene_generate import render_scene_files
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene

    scene = load_scene(TESTS.parent / "examples" / "scenes" / "ur5_payload.yaml")
    model = load_quietly(robots / "ur_description" / "urdf" / "ur5_robot.urdf")
    produced = render_scene_files(model, scene, ["numpy", "casadi", "c"])
    reduced = apply_scene(model, scene).model
    ex = load_interfaces(produced.files, tmp_path, reduced, "ur5_payload")
    assert ex.casadi.PARAMETERS == {"m_load": 2.0}
    q = np.linspace(-1.0, 1.0, ex.numpy.NQ)
    loaded = rnea_reference(ex.nm, "gravity_vector", q, None, None)
    bare = rnea_reference(numeric_model(reduced, {"m_load": 0.0}), "gravity_vector", q, None,
                          None)
    assert np.max(np.abs(loaded - bare)) > 1.0  # the payload shows in g
    assert_close(as_array(ex.casadi.gravity_vector(q=q)["g"], "gravity_vector"), loaded, "CasADi g")
    assert_interfaces_use_description_values(ex, np.random.default_rng(15))


def test_parameters_without_a_value_are_required(tmp_path):
    """m2 declared without a value: NumPy and CasADi calls that leave it out raise TypeError;
    the C code, which cannot refuse, gives NaN."""
    text = eomgen.example_path("planar_2link").read_text(encoding="utf-8")
    declared = re.search(r"\n  m2: .*", text)
    path = tmp_path / "planar_2link.yaml"
    path.write_text(text.replace(declared.group(), "\n  m2: null"), encoding="utf-8")
    model = load_quietly(path)
    files = render_files(model, ["numpy", "casadi", "c"])
    source = next(f.content for f in files if f.name.endswith("_casadi.py"))
    assert_safe_python(source, "ca", CASADI_CALLS | {"_Function", "isinstance", "TypeError"},
                       CASADI_LOCAL_OBJECTS | {"self"})
    with_m2 = model.substitute({sp.Symbol("m2", real=True): 2.5})  # for Newton–Euler
    ex = load_interfaces(files, tmp_path / "out", with_m2, "no_m2")
    assert ex.casadi.PARAMETERS["m2"] is None and ex.numpy.PARAMETERS["m2"] is None
    q, qd, qdd = random_states(np.random.default_rng(16), 2, count=1)[0]
    tau = rnea(ex.nm, q, qd, qdd)  # with m2 = 2.5
    others = {k: v for k, v in ex.casadi.PARAMETERS.items() if v is not None}
    with pytest.raises(TypeError, match="m2"):
        ex.numpy.inverse_dynamics(q, qd, qdd)
    assert_close(ex.numpy.inverse_dynamics(q, qd, qdd, m2=2.5), tau, "NumPy tau")
    for function in ex.functions:
        inputs, output = SIGNATURES[function]
        vectors = {"q": q, "qd": qd, "qdd": qdd, "tau": tau}
        vectors = {a: vectors[a] for a in inputs}
        expected = numpy_call(ex.numpy, function, *vectors.values(), m2=2.5)
        f = getattr(ex.casadi, function)
        for call in (lambda: f(**vectors), lambda: f(**vectors, **others),
                     lambda: f.call(dict(vectors))):
            with pytest.raises(TypeError, match=f"^{function}: parameter m2 has no value"):
                call()
        shape = lambda x: as_array(x, function)  # noqa: E731
        assert_close(shape(f(**vectors, m2=2.5)[output]), expected, f"CasADi {function}")
        assert_close(shape(f(*vectors.values(), *{**ex.casadi.PARAMETERS, "m2": 2.5}.values())),
                     expected, f"CasADi {function} in order")
        if ex.compiled is not None:  # NaN where the result depends on m2, else the value
            c = ex.compiled[function]
            depends = expected != numpy_call(ex.numpy, function, *vectors.values(), m2=3.5)
            assert depends.any()
            left_out = shape(c(**vectors)[output])
            assert np.all(np.isnan(left_out[depends])), f"C {function} without m2: {left_out}"
            assert_close(left_out[~depends], expected[~depends], f"C {function} without m2")
            assert_close(shape(c(**vectors, m2=2.5)[output]), expected, f"C {function}")


def test_no_c_compiler_is_one_warning_line(tmp_path):
    """Without a C compiler the C backend writes the .c and .h and says, in one line on
    stderr, that the .so is missing: also when the run is answered from the cache."""
    empty = tmp_path / "bin"
    empty.mkdir()
    env = {k: v for k, v in os.environ.items() if k != "CC"}
    env["PATH"] = str(empty)
    command = [sys.executable, "-m", "eomgen.cli", "generate", "--backend", "numpy,c",
               "--cache-dir", str(tmp_path / "cache"), "-o", str(tmp_path / "out")]
    expected = ("eomgen: warning: no C compiler found ($CC, cc, gcc, clang): wrote "
                "planar_2link_casadi.c/.h without libplanar_2link_casadi.so")
    for run in ("derived", "cached"):
        result = subprocess.run(command + ["--quiet"], env=env, capture_output=True, text=True,
                                timeout=120)
        assert result.returncode == 0, result.stderr
        assert result.stderr.splitlines() == [expected], f"{run}: {result.stderr}"
        assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
            "planar_2link_casadi.c", "planar_2link_casadi.h", "planar_2link_numpy.py"]


def test_no_c_compiler_warns_library_callers(build, tmp_path, monkeypatch):
    from eomgen.cache import CachedNotice
    from eomgen.codegen.backends.casadi_backend import NoCompilerWarning

    monkeypatch.delenv("CC", raising=False)
    monkeypatch.setenv("PATH", str(tmp_path))
    assert c_compiler() is None
    model = build("planar_2link").model
    match = r"^no C compiler found .*: wrote planar_2link_casadi\.c/\.h without libplanar_2link_casadi\.so$"
    with pytest.warns(NoCompilerWarning, match=match):
        paths = generate(model, tmp_path / "a", "c", cache_dir=tmp_path / "cache")
    assert [p.name for p in paths] == ["planar_2link_casadi.c", "planar_2link_casadi.h"]
    with pytest.warns(CachedNotice, match=match):  # answered from the cache: said again
        generate(model, tmp_path / "b", "c", cache_dir=tmp_path / "cache")


# ----------------------------------------------------------------------------------------------
# Hostile names
# ----------------------------------------------------------------------------------------------

NUMPY_CALLS = {"_batch", "_states", "mass_matrix", "inverse_dynamics", "ValueError", "len", "range",
               "reversed", "zip", "all", "int", "_at", "_not_positive_definite",
               "FloatingPointError",
               # the wrapper naming a renamed parameter's keyword (templates/common/renamed.py.jinja)
               "_renamed_keywords", "function", "TypeError",
               # the Cholesky runtime (eomgen/runtime/cholesky.py), included verbatim
               "_cholesky_solve", "_condition_number", "_condition_estimate",
               "_ill_conditioned_message",
               # the checks of the values (docs/backends.md, "Values a function refuses")
               "_real", "_caller", "_parameters", "float", "type", "RuntimeError"}
NUMPY_LOCAL_OBJECTS = {"arrays", "singles", "_warnings", "x", "values", "error", "frame"}
CASADI_LOCAL_OBJECTS = {"PARAMETERS"}  # the module's dict literal: PARAMETERS.values()
CASADI_CALLS = {"_build", "_function", "_cholesky_solve", "sum", "range", "reversed", "len",
                "float", "_Function", "TypeError", "isinstance"} | {
    f"_{f}_expression" for f in FUNCTION_NAMES}
#: Tokens holding literal text (Python 3.12 splits f-strings into several tokens).
_LITERAL_TOKENS = {tokenize.STRING, tokenize.COMMENT} | (
    {tokenize.FSTRING_MIDDLE} if hasattr(tokenize, "FSTRING_MIDDLE") else set())
FORBIDDEN_NAMES = {"os", "sys", "subprocess", "__import__", "eval", "exec", "compile", "open",
                   "system", "getattr", "globals", "input"}


def assert_safe_python(source: str, alias: str, calls: set[str], local_objects=frozenset()):
    """Parse ``source`` and check that it can only do what a generated module does."""
    tree = ast.parse(source)
    kind = {"np": "numpy", "ca": "casadi"}[alias]
    assert _imports(tree) == STDLIB_IMPORTS[kind] + [(kind, alias)]
    for node in ast.walk(tree):
        if isinstance(node, ast.Name):
            assert node.id not in FORBIDDEN_NAMES, node.id
        if isinstance(node, ast.Attribute):
            assert node.attr not in {"system", "popen", "__import__"}, node.attr
        if not isinstance(node, ast.Call):
            continue
        f = node.func
        if isinstance(f, ast.Name):
            assert f.id in calls, f"call of {f.id}"
            continue
        assert isinstance(f, ast.Attribute), ast.dump(f)
        root = f
        while isinstance(root, ast.Attribute):
            root = root.value
        if isinstance(root, ast.Constant):
            assert isinstance(root.value, str) and f.attr == "join", ast.dump(f)
        else:
            assert isinstance(root, ast.Name) and root.id in {alias, *local_objects}, ast.dump(f)
    # Outside string literals and comments, nothing of the hostile text remains.
    code = [t.string for t in tokenize.generate_tokens(io.StringIO(source).readline)
            if t.type not in _LITERAL_TOKENS]
    assert "import os" not in " ".join(code) and "system(" not in "".join(code)
    for word in ("os", "system", "pwned", "passwd", "__import__", "input"):
        assert word not in code, word
    return tree


@pytest.fixture(scope="module")
def hostile(tmp_path_factory) -> Example:
    model = hostile_star(DOCSTRING_BREAKER)
    return build_example("hostile", model, tmp_path_factory.mktemp("hostile"))


def test_hostile_names_generate_safe_modules(hostile, capfd):
    ex = hostile
    for kind, alias, calls, local in (("numpy", "np", NUMPY_CALLS, NUMPY_LOCAL_OBJECTS),
                                      ("casadi", "ca", CASADI_CALLS, CASADI_LOCAL_OBJECTS)):
        path = Path(getattr(ex, kind).__file__)
        tree = assert_safe_python(path.read_text(encoding="utf-8"), alias, calls, local)
        assert repr(DOCSTRING_BREAKER) in ast.get_docstring(tree)
    for module in (ex.numpy, ex.casadi):
        assert module.JOINT_NAMES == HOSTILE
        assert module.NQ == len(HOSTILE)
    assert "pwned" not in capfd.readouterr().out
    # Loading again with the output captured: importing runs nothing of the names.
    load_module(Path(ex.numpy.__file__), "hostile_again")
    load_module(Path(ex.casadi.__file__), "hostile_casadi_again")
    captured = capfd.readouterr()
    assert "pwned" not in captured.out + captured.err


def test_hostile_names_compute_the_right_dynamics(hostile):
    ex = hostile
    for q, qd, qdd in random_states(np.random.default_rng(12), ex.n, count=2):
        assert_close(ex.numpy.inverse_dynamics(q, qd, qdd), rnea(ex.nm, q, qd, qdd), "tau")
        assert_close(ca_call(ex.casadi.inverse_dynamics, {}, q, qd, qdd),
                     rnea(ex.nm, q, qd, qdd), "CasADi tau")


def test_hostile_names_compile_to_c(hostile):
    compiled = needs_compiled(hostile)
    c_files = [p for name, p in hostile.paths.items() if name.endswith((".c", ".h"))]
    assert len(c_files) == 2
    q = np.linspace(-1, 1, hostile.n)
    assert_close(ca_call(compiled["mass_matrix"], {}, q), hostile.numpy.mass_matrix(q), "C M")


def test_c_backend_accepts_names_with_repeated_underscores(tmp_path):
    """CasADi refuses "__" in names; the stem of "arm  2" is "arm__2"."""
    body = Inertial(1.0, [0.2, 0, 0], [[0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.01]])
    model = build_model("<test>", "Arm  2", [Link("base"), Link("l1", body)],
                        [Joint("j1", JointType.REVOLUTE, "base", "l1", Transform(),
                               vec3([0, 1, 0]))])
    paths = generate(model, tmp_path, "c")
    assert [p.name for p in paths][:2] == ["arm__2_casadi.c", "arm__2_casadi.h"]
    if c_compiler() is not None:
        f = ca.external("gravity_vector", str(tmp_path / library_name("arm__2")))
        assert_close(ca_call(f, {}, [0.3]), rnea(numeric_model(model), [0.3], [0.0], [0.0]), "g")


@pytest.mark.parametrize("robot_name", HOSTILE + (DOCSTRING_BREAKER, "\\", "a\\", "\r\x0c\u2028"),
                         ids=lambda s: ascii(s))
def test_hostile_robot_names_stay_text(robot_name):
    files = {f.name: f.content for f in render_files(hostile_star(robot_name), ["numpy", "casadi"])}
    assert len(files) == 2
    for name, content in files.items():
        assert name.isascii() and name.endswith(("_numpy.py", "_casadi.py"))
        alias = "np" if name.endswith("_numpy.py") else "ca"
        calls = NUMPY_CALLS if alias == "np" else CASADI_CALLS
        local = NUMPY_LOCAL_OBJECTS if alias == "np" else CASADI_LOCAL_OBJECTS
        tree = assert_safe_python(content, alias, calls, local)
        assert repr(robot_name) in ast.get_docstring(tree)
        joint_names = next(ast.literal_eval(node.value) for node in tree.body
                           if isinstance(node, ast.Assign)
                           and getattr(node.targets[0], "id", "") == "JOINT_NAMES")
        assert joint_names == HOSTILE


def test_hostile_names_through_urdf(tmp_path):
    """A URDF file is the realistic carrier of such names."""
    from support.reference import to_urdf

    path = tmp_path / "hostile.urdf"
    path.write_text(to_urdf(hostile_star(DOCSTRING_BREAKER)), encoding="utf-8")
    model = eomgen.load(path)
    assert model.name == DOCSTRING_BREAKER and model.joint_names == HOSTILE
    for f in render_files(model, ["numpy", "casadi"]):
        alias = "np" if f.name.endswith("_numpy.py") else "ca"
        assert_safe_python(f.content, alias, NUMPY_CALLS if alias == "np" else CASADI_CALLS,
                           NUMPY_LOCAL_OBJECTS if alias == "np" else CASADI_LOCAL_OBJECTS)


def test_parameters_named_like_private_helpers_do_not_shadow_them(tmp_path):
    mass = sp.Symbol("_states", real=True)
    body = Inertial(mass, [0.1, 0, 0], [[0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.01]])
    model = build_model("<test>", "underscored", [Link("base"), Link("l1", body)],
                        [Joint("j1", JointType.REVOLUTE, "base", "l1", Transform(),
                               vec3([0, 1, 0]))],
                        parameters=[Parameter(mass, 1.5)])
    generate(model, tmp_path, "numpy")
    module = load_module(tmp_path / "underscored_numpy.py", "underscored_numpy")
    _parameter_identifiers_are_sound(module)
    assert_close(module.gravity_vector([0.3]), rnea(numeric_model(model), [0.3], [0.0], [0.0]),
                 "g")


#: Parameters named like builtins, NumPy, the modules' own names, intermediates and each other.
#: Every default is distinct, so a keyword is matched to its parameter through PARAMETERS.
COLLIDING = {
    "sum": 1.25, "np": 0.45, "min": 0.3, "M": 2.5, "g": 9.81, "out": 0.4, "x": 0.2, "x_": 0.35,
    "ca": 0.06, "single": 0.11, "batch": 0.07, "s1": 0.15, "mass_matrix": 0.55,
    "PARAMETERS": 0.65, "len": 0.05, "L": 0.9, "tau": 0.12, "q": 0.13,
}
COLLIDING_YAML = """\
name: colliding_parameters
gravity: [0, 0, -g]
parameters:
{parameters}
links:
  - name: base
  - name: link1
    mass: sum
    com: [x, 0, out]
    inertia: {{ixx: min, iyy: min, izz: np}}
  - name: link2
    mass: M
    com: [s1, single, 0]
    inertia: {{ixx: batch, iyy: batch, izz: ca}}
  - name: link3
    mass: PARAMETERS
    com: [len, tau, q]
    inertia: {{ixx: 0.01, iyy: 0.01, izz: 0.01}}
joints:
  - name: joint1
    type: revolute
    parent: base
    child: link1
    axis: [0, 1, 0]
  - name: joint2
    type: prismatic
    parent: link1
    child: link2
    origin: {{xyz: [mass_matrix, 0, x_]}}
    axis: [1, 0, 0]
  - name: joint3
    type: revolute
    parent: link2
    child: link3
    origin: {{xyz: [L, 0, 0]}}
    axis: [0, 0, 1]
"""


@pytest.fixture(scope="module")
def colliding(tmp_path_factory) -> Example:
    folder = tmp_path_factory.mktemp("colliding")
    lines = [f"  {name}: {{value: {value!r}, description: \"{name} \\\"\\\"\\\"\\n import os\"}}"
             for name, value in COLLIDING.items()]
    path = folder / "colliding.yaml"
    path.write_text(COLLIDING_YAML.format(parameters="\n".join(lines)), encoding="utf-8")
    model = load_quietly(path)
    assert {p.name: p.value for p in model.parameters} == COLLIDING
    return build_example("colliding", model, folder / "out")


def test_colliding_parameter_names_become_sound_keywords(colliding):
    for module in (colliding.numpy, colliding.casadi):
        _parameter_identifiers_are_sound(module)
        assert sorted(module.PARAMETERS.values()) == sorted(COLLIDING.values())
    assert list(colliding.numpy.PARAMETERS.items()) == list(colliding.casadi.PARAMETERS.items())
    for kind, alias, calls, local in (("numpy", "np", NUMPY_CALLS, NUMPY_LOCAL_OBJECTS),
                                      ("casadi", "ca", CASADI_CALLS, CASADI_LOCAL_OBJECTS)):
        assert_safe_python(Path(getattr(colliding, kind).__file__).read_text(encoding="utf-8"),
                           alias, calls, local)
    identifiers = set(colliding.numpy.PARAMETERS)
    for f in FUNCTION_NAMES:
        assert getattr(colliding.casadi, f).name_in()[len(SIGNATURES[f][0]):] == list(
            colliding.numpy.PARAMETERS)
        assert identifiers.isdisjoint(SIGNATURES[f][0])


def test_colliding_parameters_change_what_they_name(colliding):
    ex = colliding
    name_of = {identifier: next(n for n, v in COLLIDING.items() if v == default)
               for identifier, default in ex.numpy.PARAMETERS.items()}
    rng = np.random.default_rng(13)
    q, qd, qdd = random_states(rng, ex.n, count=1)[0]
    assert_close(ex.numpy.inverse_dynamics(q, qd, qdd), rnea(ex.nm, q, qd, qdd), "defaults")
    for identifier, name in name_of.items():
        value = COLLIDING[name] * 1.7 + 0.1
        nm = numeric_model(ex.model, {name: value})
        expected = rnea(nm, q, qd, qdd)
        assert_close(ex.numpy.inverse_dynamics(q, qd, qdd, **{identifier: value}), expected,
                     f"{identifier} ({name})")
        params = {**ex.numpy.PARAMETERS, identifier: value}
        assert_close(ca_call(ex.casadi.inverse_dynamics, params, q, qd, qdd), expected,
                     f"CasADi {identifier}")
        if ex.compiled is not None:
            assert_close(ca_call(ex.compiled["inverse_dynamics"], params, q, qd, qdd), expected,
                         f"C {identifier}")
        assert_close(ex.numpy.mass_matrix(q, **{identifier: value}),
                     rnea_reference(nm, "mass_matrix", q, qd, qdd), f"M {identifier}")


# ----------------------------------------------------------------------------------------------
# Determinism
# ----------------------------------------------------------------------------------------------

_DETERMINISM_SCRIPT = """\
import sys, warnings
sys.path.insert(0, sys.argv[1])
import numpy as np
import eomgen
from eomgen.codegen.generate import write_atomically
from support import render_text_files
from support.reference import random_robot
warnings.simplefilter("ignore")
which, outdir = sys.argv[2], sys.argv[3]
if which == "planar":
    model, backends = eomgen.load(eomgen.example_path("planar_2link")), ["numpy", "casadi", "c"]
else:
    model, backends = random_robot(np.random.default_rng(3), 3, tree=True), ["numpy", "casadi"]
write_atomically([f for f in render_text_files(model, backends) if f.golden], outdir)
"""


def _text_files(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.suffix != ".so"}


def _contents(files: list[GeneratedFile]) -> dict[str, bytes]:
    return {f.name: f.content.encode("utf-8") for f in sorted(files, key=lambda f: f.name)
            if f.golden}


@pytest.mark.slow
def test_generation_is_deterministic(build, tmp_path):
    """Twice in this process, and in processes with other hash seeds: identical bytes (the
    bundled arm with every backend, a random tree with the Python backends)."""
    here = os.environ.get("PYTHONHASHSEED")
    seeds = [s for s in ("11", "12", "13") if s != here][:2]
    jobs = {}
    for which, seed in zip(("planar", "tree"), seeds):
        env = dict(os.environ, PYTHONHASHSEED=seed)
        jobs[which] = subprocess.Popen(
            [sys.executable, "-c", _DETERMINISM_SCRIPT, str(TESTS), which, str(tmp_path / which)],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        tree = lambda: random_robot(np.random.default_rng(3), 3, tree=True)  # noqa: E731
        first = {"planar": _text_files(Path(build("planar_2link").numpy.__file__).parent),
                 "tree": _contents(render_files(tree(), ["numpy", "casadi"]))}
        again = {"planar": _contents(render_text_files(EXAMPLES["planar_2link"](),
                                                       ["numpy", "casadi", "c"])),
                 "tree": _contents(render_files(tree(), ["numpy", "casadi"]))}
    finally:
        results = {which: job.communicate(timeout=120) for which, job in jobs.items()}
    for which, job in jobs.items():
        assert job.returncode == 0, results[which][1]
    for which in ("planar", "tree"):
        assert len(first[which]) == (4 if which == "planar" else 2)
        assert again[which] == first[which], f"{which}: a second run differs"
        assert _text_files(tmp_path / which) == first[which], f"{which}: another hash seed differs"


# ----------------------------------------------------------------------------------------------
# All or nothing
# ----------------------------------------------------------------------------------------------

def _snapshot(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in folder.iterdir()} if folder.exists() else {}


def _staging_folders(outdir: Path) -> list[Path]:
    """Staging folders left beside ``outdir`` (a new output) or in it (an existing one)."""
    return [*outdir.parent.glob(".eomgen-staging-*"), *outdir.glob(".eomgen-staging-*")]


def test_failing_backend_writes_nothing(build, tmp_path, monkeypatch):
    model = build("planar_2link").model
    outdir = tmp_path / "out"
    outdir.mkdir()
    (outdir / "keep.txt").write_text("unrelated\n")
    (outdir / "planar_2link_numpy.py").write_text("# the previous generation\n")
    before = _snapshot(outdir)

    def explode(job):
        raise RuntimeError("backend exploded")

    available_backends()  # registers the backends before one is replaced
    monkeypatch.setitem(BACKENDS, "casadi", Backend("casadi", "fails", explode))
    lines = []
    with pytest.raises(RuntimeError, match="backend exploded"):
        generate(model, outdir, "numpy,casadi", progress=lines.append)
    assert any(line.startswith("numpy: planar_2link_numpy.py") for line in lines), lines
    assert _snapshot(outdir) == before
    assert _staging_folders(outdir) == []
    fresh = tmp_path / "fresh"
    with pytest.raises(RuntimeError):
        generate(model, fresh, "numpy,casadi")
    assert not fresh.exists() and _staging_folders(fresh) == []


def test_failing_write_writes_nothing(tmp_path):
    outdir = tmp_path / "out"
    outdir.mkdir()
    (outdir / "a.py").write_text("old a\n")
    before = _snapshot(outdir)
    files = [GeneratedFile("a.py", "new a\n"), GeneratedFile("b.py", "new b\n"),
             GeneratedFile("c.py", None)]  # neither text nor bytes: fails in the staging folder
    with pytest.raises(TypeError):
        write_atomically(files, outdir)
    assert _snapshot(outdir) == before
    assert _staging_folders(outdir) == []


def test_successful_generation_replaces_only_its_files(build, tmp_path):
    outdir = tmp_path / "out"
    outdir.mkdir()
    (outdir / "keep.txt").write_text("unrelated\n")
    (outdir / "planar_2link_numpy.py").write_text("# the previous generation\n")
    paths = generate(build("planar_2link").model, outdir, "numpy")
    assert paths == [outdir / "planar_2link_numpy.py"]
    assert (outdir / "keep.txt").read_text() == "unrelated\n"
    assert (outdir / "planar_2link_numpy.py").read_bytes() == \
        build("planar_2link").paths["planar_2link_numpy.py"].read_bytes()
    assert _staging_folders(outdir) == []


# ----------------------------------------------------------------------------------------------
# eomgen generate
# ----------------------------------------------------------------------------------------------

CLI_RUNS = {
    "default": [],
    "numpy": ["--backend", "numpy"],
    "symbolic": ["--backend", "numpy", "--symbolic", "m2", "--quiet"],
    "unknown_backend": ["--backend", "numpy,fortran"],
    "unknown_symbolic": ["--symbolic", "m2,nosuch"],
}


@dataclass
class CliRun:
    outdir: Path
    returncode: int
    stdout: str
    stderr: str


@pytest.fixture(scope="module")
def cli(tmp_path_factory) -> dict[str, CliRun]:
    """Every run of CLI_RUNS, started together (each in a fresh folder as working directory)."""
    command = [shutil.which("eomgen")] if shutil.which("eomgen") else [
        sys.executable, "-m", "eomgen.cli"]
    started = {}
    for name, arguments in CLI_RUNS.items():
        cwd = tmp_path_factory.mktemp(f"cli_{name}")
        started[name] = (cwd / "out", subprocess.Popen(
            command + ["generate", *arguments, "-o", "out"], cwd=cwd, text=True,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE))
    runs = {}
    for name, (outdir, process) in started.items():
        stdout, stderr = process.communicate(timeout=120)
        runs[name] = CliRun(outdir, process.returncode, stdout, stderr)
    return runs


def _expected_default_files() -> set[str]:
    suffixes = {"numpy": ["_numpy.py"], "casadi": ["_casadi.py"],
                "c": ["_casadi.c", "_casadi.h"], "latex": [".tex"]}
    library = {library_name("planar_2link")} if c_compiler() else set()
    return {"planar_2link" + s for b in available_backends() for s in suffixes.get(b, [])} | library


@pytest.mark.slow
def test_cli_default_generates_the_bundled_arm(cli):
    run = cli["default"]
    assert run.returncode == 0, run.stderr
    written = {p.name for p in run.outdir.iterdir()}
    assert _expected_default_files() <= written
    stdout = run.stdout.splitlines()
    assert sorted(Path(line).name for line in stdout) == sorted(written)
    assert all((run.outdir.parent / line).is_file() for line in stdout)
    progress = run.stderr.splitlines()
    assert progress and all(line.startswith("eomgen: ") for line in progress)
    assert any("deriving" in line for line in progress)
    assert not set(stdout) & {line.removeprefix("eomgen: ") for line in progress}
    module = load_module(run.outdir / "planar_2link_numpy.py", "cli_default_numpy")
    assert module.JOINT_NAMES == ("joint1", "joint2")


@pytest.mark.slow
def test_cli_numpy_backend_writes_only_the_numpy_module(cli, build):
    run = cli["numpy"]
    assert run.returncode == 0, run.stderr
    assert [p.name for p in run.outdir.iterdir()] == ["planar_2link_numpy.py"]
    assert run.stdout.splitlines() == [str(Path("out", "planar_2link_numpy.py"))]
    assert (run.outdir / "planar_2link_numpy.py").read_bytes() == \
        build("planar_2link").paths["planar_2link_numpy.py"].read_bytes()


@pytest.mark.slow
def test_cli_symbolic_keeps_the_named_parameters(cli):
    run = cli["symbolic"]
    assert run.returncode == 0 and run.stderr == ""
    module = load_module(run.outdir / "planar_2link_numpy.py", "cli_symbolic_numpy")
    assert module.PARAMETERS == {"m2": 1.0}


@pytest.mark.parametrize("name, mentions", [("unknown_backend", "fortran"),
                                            ("unknown_symbolic", "nosuch")])
@pytest.mark.slow
def test_cli_bad_request_is_one_error_line_and_writes_nothing(cli, name, mentions):
    run = cli[name]
    assert run.returncode == 2
    lines = run.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("eomgen: error:"), run.stderr
    assert mentions in lines[0]
    assert run.stdout == ""
    assert not run.outdir.exists()
    assert [p.name for p in run.outdir.parent.iterdir()] == []


def test_casadi_printer_takes_square_roots_with_casadi():
    """x**(1/2) and x**(-1/2) (a planar joint's 1/sqrt(cos² + sin²)) print through ca.sqrt:
    the printed text evaluates on CasADi symbols with only ``ca`` in scope, to the value."""
    from eomgen.codegen.backends.casadi_backend import CasADiPrinter
    x, y = sp.symbols("x y", real=True)
    printer = CasADiPrinter({"standard": "python3"})
    sx, sy = ca.SX.sym("x"), ca.SX.sym("y")
    for expr in (sp.sqrt(x * x + y), 1 / sp.sqrt(x * x + y), x / sp.sqrt(x * x + y)):
        value = eval(printer.doprint(expr), {"__builtins__": {}, "ca": ca, "x": sx, "y": sy})
        got = float(ca.Function("f", [sx, sy], [value])(0.3, 1.7))
        assert got == pytest.approx(float(expr.subs({x: 0.3, y: 1.7})), rel=1e-15)
