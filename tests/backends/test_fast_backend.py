"""The fast backend: a CPython extension compiled from generated C (``<robot>_fast``).

Checked against the generated NumPy module (same program, other printer and runtime) on single
states and batches, against Pinocchio on the UR5, and for its Python interface: parameter
defaults are the description's values, keyword overrides, shape errors, a singular M, and the
fallback without a compiler.
"""

from __future__ import annotations

import ast
import warnings
from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.codegen import available_backends, make_job
from eomgen.codegen.backends import fast_backend
from eomgen.codegen.backends.fast_backend import c_string_literal, python_headers
from eomgen.codegen.backends.casadi_backend import c_compiler
from eomgen.codegen.generate import render_files
from eomgen.dynamics import derive
from support import load_module
from support.extras import need

FUNCTIONS = {"mass_matrix": ("q",), "coriolis_matrix": ("q", "qd"), "gravity_vector": ("q",),
             "inverse_dynamics": ("q", "qd", "qdd"), "forward_dynamics": ("q", "qd", "tau")}

needs_compiler = pytest.mark.skipif(c_compiler() is None or python_headers() is None,
                                    reason="needs a C compiler and Python's C headers")


def _load(folder: Path, files, stem: str):
    """Write ``files`` into ``folder`` and import the NumPy and the fast module."""
    for f in files:
        path = folder / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    modules = []
    for name, path in ((stem + "_numpy", folder / f"{stem}_numpy.py"),
                       (stem + "_fast", next(folder.glob(f"{stem}_fast.*.so"), None)
                        or next(folder.glob(f"{stem}_fast*.pyd")))):
        module = load_module(path, name)
        modules.append(module)
    return modules


@pytest.fixture(scope="module")
def planar(tmp_path_factory):
    """The planar 2-link arm with all its parameters symbolic: (NumPy module, fast module)."""
    model = eomgen.load(eomgen.example_path("planar_2link"))
    files = render_files(model, ["numpy", "fast"])
    return _load(tmp_path_factory.mktemp("fast_planar"), files, "planar_2link")


def _states(rng, n, batch=None):
    shape = (n,) if batch is None else (batch, n)
    return {name: rng.uniform(-2, 2, shape) for name in ("q", "qd", "qdd", "tau")}


@needs_compiler
def test_fast_module_equals_the_numpy_module_on_states_and_batches(planar):
    numpy_module, fast = planar
    rng = np.random.default_rng(3)
    assert fast.JOINT_NAMES == numpy_module.JOINT_NAMES and fast.NQ == numpy_module.NQ
    assert set(numpy_module.__all__) == set(fast.__all__)
    for batch in (None, 1, 6):
        x = _states(rng, fast.NQ, batch)
        for name, inputs in FUNCTIONS.items():
            ours = getattr(fast, name)(*(x[i] for i in inputs))
            theirs = getattr(numpy_module, name)(*(x[i] for i in inputs))
            assert ours.shape == theirs.shape
            np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-12 * np.abs(theirs).max())


@needs_compiler
def test_parameters_default_to_the_description_and_can_be_overridden(planar):
    numpy_module, fast = planar
    model = eomgen.load(eomgen.example_path("planar_2link"))
    declared = {p.name: p.value for p in model.parameters}
    assert fast.PARAMETERS == numpy_module.PARAMETERS
    assert fast.PARAMETERS == declared  # keyed by the description's names
    q, qd, qdd = np.array([0.3, -0.7]), np.array([1.1, 0.4]), np.array([-0.2, 0.9])
    # defaults are the description's values, never zero: g(q) of a hanging arm is not zero
    assert np.abs(fast.gravity_vector(q)).max() > 1.0
    for kwargs in ({}, {"m2": 3.5, "g": 1.62}, {"l1": 0.4}):
        np.testing.assert_allclose(fast.inverse_dynamics(q, qd, qdd, **kwargs),
                                   numpy_module.inverse_dynamics(q, qd, qdd, **kwargs), rtol=1e-13)
    np.testing.assert_allclose(fast.inverse_dynamics(q=q, qd=qd, qdd=qdd),
                               fast.inverse_dynamics(q, qd, qdd), rtol=0)
    np.testing.assert_allclose(fast.mass_matrix(q.tolist()), fast.mass_matrix(q), rtol=0)


@needs_compiler
def test_bad_calls_raise_like_the_numpy_module(planar):
    _, fast = planar
    with pytest.raises(ValueError, match=r"q must have shape \(2,\) or \(N, 2\), got \(3,\)"):
        fast.mass_matrix(np.zeros(3))
    with pytest.raises(ValueError, match="same number of states"):
        fast.coriolis_matrix(np.zeros((4, 2)), np.zeros((3, 2)))
    with pytest.raises(TypeError, match="unexpected keyword argument 'mass'"):
        fast.mass_matrix(np.zeros(2), mass=1.0)
    with pytest.raises(TypeError, match="missing required argument 'qd'"):
        fast.coriolis_matrix(np.zeros(2))
    with pytest.raises(np.linalg.LinAlgError, match="not positive definite at state 0"):
        fast.forward_dynamics(np.zeros((2, 2)), np.zeros((2, 2)), np.zeros((2, 2)),
                              m2=np.array(0.0), I2=0.0, I1=0.0, m1=0.0)
    with pytest.raises(FloatingPointError, match="not finite"):
        fast.forward_dynamics(np.zeros(2), np.zeros(2), np.array([np.nan, 0.0]))


@needs_compiler
def test_forward_dynamics_solves_and_reports_the_condition(planar):
    numpy_module, fast = planar
    q, qd, tau = np.array([0.3, 2.9]), np.array([0.5, -1.0]), np.array([2.0, -1.0])
    qdd, condition = fast.forward_dynamics(q, qd, tau, return_condition=True)
    M = fast.mass_matrix(q)
    np.testing.assert_allclose(M @ qdd + fast.inverse_dynamics(q, qd, np.zeros(2)), tau,
                               rtol=1e-13)
    eigenvalues = np.linalg.eigvalsh(M)
    assert 1.0 <= condition <= eigenvalues[-1] / eigenvalues[0] * (1 + 1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(fast.IllConditionedWarning, match="ill-conditioned"):
            fast.forward_dynamics(q, qd, tau, I2=1e-13, lc2=0.0, m2=1e-13)


@needs_compiler
def test_ur5_fast_module_agrees_with_pinocchio(erd_robots_dir, tmp_path):
    """Read without snapping (as Pinocchio reads it), the UR5's τ, M, C and g agree with
    Pinocchio to 1e-14 relative, and q̈ inverts τ."""
    pin = need("pinocchio", reason="Pinocchio is the independent reference")
    path = erd_robots_dir / "ur_description/urdf/ur5_robot.urdf"
    files = render_files(eomgen.load(path, snap=False), ["numpy", "fast"])
    _, fast = _load(tmp_path, files, "ur5")
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    assert tuple(model.names[1:]) == fast.JOINT_NAMES
    rng = np.random.default_rng(7)
    x = _states(rng, 6, 4)
    for k in range(4):
        q, qd, qdd = x["q"][k], x["qd"][k], x["qdd"][k]
        tau = pin.rnea(model, data, q, qd, qdd)
        np.testing.assert_allclose(fast.inverse_dynamics(q, qd, qdd), tau,
                                   atol=1e-14 * np.abs(tau).max())
        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        np.testing.assert_allclose(fast.mass_matrix(q), M, atol=1e-14 * np.abs(M).max())
        np.testing.assert_allclose(fast.forward_dynamics(q, qd, tau), qdd, rtol=1e-7, atol=1e-7)
        C = pin.computeCoriolisMatrix(model, data, q, qd)
        np.testing.assert_allclose(fast.coriolis_matrix(q, qd), C, atol=1e-13 * np.abs(C).max())
        g = pin.computeGeneralizedGravity(model, data, q)
        np.testing.assert_allclose(fast.gravity_vector(q), g, atol=1e-14 * np.abs(g).max())
    batch = fast.inverse_dynamics(x["q"], x["qd"], x["qdd"])
    assert batch.shape == (4, 6)
    np.testing.assert_array_equal(batch[2], fast.inverse_dynamics(x["q"][2], x["qd"][2],
                                                                 x["qdd"][2]))


def test_without_a_compiler_only_the_source_is_written_with_a_note(monkeypatch):
    model = eomgen.load(eomgen.example_path("planar_2link")).with_numeric_parameters()
    job = make_job(derive(model, outputs=("g",), simplify=False), ["g"])
    monkeypatch.setattr(fast_backend, "c_compiler", lambda: None)
    with pytest.warns(RuntimeWarning, match="no C compiler found.*planar_2link_fast.c only"):
        files = available_backends()["fast"].generate(job)
    assert [f.name for f in files] == ["planar_2link_fast.c"]
    assert "gravity_vector_one" in files[0].content and "mass_matrix_one" not in files[0].content


def test_c_string_literals_hold_any_name_in_utf8():
    for text in ['joint "1"', "back\\slash??=", "épaule ∠", "*/ end", "\n\t"]:
        literal = c_string_literal(text)
        assert literal.isascii() and "??" not in literal
        assert ast.literal_eval("b" + literal).decode("utf-8") == text


def test_the_powers_of_a_lanes_kernel_print_without_pow():
    """A lanes kernel (SIMD vectors of states) has sin, cos and sqrt lane by lane but no
    ``pow``: every power in_lanes admits prints as products, quotients and sqrt (a planar
    joint's 1/sqrt(cos² + sin²) once printed as pow(·, -0.5), which did not compile)."""
    import sympy as sp
    x, y = sp.symbols("x y", real=True)
    printer = fast_backend.FastCPrinter()
    for exponent in fast_backend.LANES_EXPONENTS:
        text = printer.doprint((x * x + y) ** exponent)
        assert "pow" not in text, (exponent, text)
