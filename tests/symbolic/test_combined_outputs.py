"""Several results from one program (issue 18): ``dynamics(q, qd)`` → (M, C, g) and
``mass_matrix_and_bias(q, qd)`` → (M, h = C q̇ + g), in every code backend.

References: eomgen.numeric's Newton–Euler (M column by column, h = τ(q, q̇, 0), g = τ(q, 0, 0))
and C q̇ = h − g; the module's own separate functions (the results are the same program's
outputs, so they must agree to rounding).
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.numeric import M_rnea, numeric_model, rnea
from eomgen.outputs import DYNAMICS, MASS_AND_BIAS, splits
from support.generated import generated


@pytest.fixture(scope="module", params=["planar_2link", "puma560_arm3"])
def robot(request, tmp_path_factory):
    model = eomgen.load(eomgen.example_path(request.param))
    functions = ["dynamics", "mass_matrix_and_bias", "M", "C", "g", "h"]
    calls, modules = generated(model, functions, tmp_path_factory.mktemp(request.param))
    return model, calls, modules


def test_combined_results_are_newton_euler_and_the_separate_functions(robot):
    model, calls, modules = robot
    n = model.dof
    nm = numeric_model(model)
    rng = np.random.default_rng(1)
    q, qd = rng.uniform(-2, 2, (2, 3, n))
    for backend, call in calls.items():
        module = modules[backend]
        for k in range(3):
            zero = np.zeros(n)
            M_ref = M_rnea(nm, q[k])
            h_ref = rnea(nm, q[k], qd[k], zero)
            g_ref = rnea(nm, q[k], zero, zero)
            if backend == "casadi":
                out = module["dynamics"].call({"q": q[k], "qd": qd[k]})
                M, C, g = (np.array(out[s], dtype=float) for s in ("M", "C", "g"))
                out = module["mass_matrix_and_bias"].call({"q": q[k], "qd": qd[k]})
                M2, h = (np.array(out[s], dtype=float) for s in ("M", "h"))
                g, h = g.ravel(), h.ravel()
            else:
                M, C, g = (np.asarray(x, dtype=float) for x in module["dynamics"](q[k], qd[k]))
                M2, h = (np.asarray(x, dtype=float)
                         for x in module["mass_matrix_and_bias"](q[k], qd[k]))
            assert M.shape == (n, n) and C.shape == (n, n) and g.shape == (n,), backend
            scale = max(1.0, np.abs(M_ref).max())
            np.testing.assert_allclose(M, M_ref, rtol=0, atol=1e-12 * scale, err_msg=backend)
            np.testing.assert_allclose(M2, M_ref, rtol=0, atol=1e-12 * scale, err_msg=backend)
            np.testing.assert_allclose(g, g_ref, rtol=1e-12, atol=1e-12, err_msg=backend)
            np.testing.assert_allclose(C @ qd[k], h_ref - g_ref, rtol=1e-10, atol=1e-11,
                                       err_msg=backend)
            np.testing.assert_allclose(h, h_ref, rtol=1e-12, atol=1e-12, err_msg=backend)
            np.testing.assert_allclose(C, call("coriolis_matrix", q[k], qd[k]), rtol=1e-12,
                                       atol=1e-12, err_msg=backend)


def test_a_batch_gives_the_batch_of_tuples(robot):
    model, calls, modules = robot
    n = model.dof
    rng = np.random.default_rng(2)
    q, qd = rng.uniform(-1, 1, (2, 4, n))
    for backend in sorted(set(modules) - {"casadi"}):  # CasADi: one state per call
        M, C, g = (np.asarray(x, dtype=float) for x in modules[backend]["dynamics"](q, qd))
        assert M.shape == (4, n, n) and C.shape == (4, n, n) and g.shape == (4, n), backend
        for k in range(4):
            one = [np.asarray(x, dtype=float) for x in modules[backend]["dynamics"](q[k], qd[k])]
            for a, b in zip((M[k], C[k], g[k]), one):
                np.testing.assert_allclose(a, b, rtol=1e-13, atol=1e-13, err_msg=backend)


def test_splits_follow_the_results():
    assert splits(DYNAMICS, 3) == (("M", 0, 3), ("C", 3, 6), ("g", 6, None))
    assert splits(MASS_AND_BIAS, 2) == (("M", 0, 2), ("h", 2, None))


def test_one_program_costs_less_than_the_separate_ones():
    """Structural (operation counts, not time): the combined program shares the separate
    programs' work, so it never costs more than their sum."""
    model = eomgen.load(eomgen.example_path("puma560_arm3"))
    d = eomgen.derive(model, outputs=("MCg", "Mh", "M", "C", "g", "h"))
    count = d.program.operation_count
    assert count(["MCg"]) <= count(["M"]) + count(["C"]) + count(["g"])
    assert count(["Mh"]) <= count(["M"]) + count(["h"])
