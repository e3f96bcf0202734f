"""``constrained_forward_dynamics_derivatives`` composed by the CasADi module and its C (issue
25): from the printed KKT partials ``constrained_dynamics_partials`` and the same Schur-complement
Cholesky solve as its ``constrained_forward_dynamics`` (no automatic differentiation).

References: the NumPy module's composition (LU of the whole KKT matrix), and Pinocchio's
``computeConstraintDynamicsDerivatives`` with a ``CONTACT_3D`` contact in
``LOCAL_WORLD_ALIGNED`` axes, on the spatial three-joint arm holding its foot and the one-joint
leg on a quaternion free flyer (the robots of tests/derivatives/test_constrained_derivatives.py).
"""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.common.compiler import c_compiler
from support.held import held_robot, pinocchio_constrained_derivatives
from test_constrained_derivatives import DERIVATIVES, leg, states
from support.extras import need

pin = need("pinocchio", reason="checked against Pinocchio's derivatives")
need("casadi", reason="the CasADi backend")

NAMES = ("dqdd_dq", "dqdd_dqd", "dqdd_dtau", "dF_dq", "dF_dqd", "dF_dtau")


# the free flyer with CasADi's C library compiled (~5 s) is slow
@pytest.fixture(scope="module", params=["fixed", pytest.param("floating", marks=pytest.mark.slow)])
def case(request, tmp_path_factory):
    folder = tmp_path_factory.mktemp(request.param)
    floating = request.param == "floating"
    path = folder / "leg.urdf"
    path.write_text(leg(1 if floating else 3), encoding="utf-8")
    # CasADi's C library: compiled for the free flyer only (one compile is enough)
    backends = ("numpy", "casadi") + (("c",) if floating and c_compiler() else ())
    return held_robot(path, ["foot"], floating, [DERIVATIVES], folder, backends)


def casadi_derivatives(function, q, v, tau, damping=0.0):
    """The six results of a ``casadi.Function`` (the module's or ``casadi.external``'s)."""
    out = function.call({"q": q, "qd": v, "tau": tau, "damping": damping})
    return [np.array(out[name], dtype=float) for name in NAMES]


def test_casadi_composes_the_numpy_modules_derivatives(case):
    _, modules, pm, _ = case
    expected_of = modules["numpy"][DERIVATIVES]
    for q, v, tau in states(pm, 2, seed=3):
        for damping in (0.0, 1e-3):
            expected = expected_of(q, v, tau, damping=damping)
            for backend in (b for b in ("casadi", "c") if b in modules):
                got = casadi_derivatives(modules[backend][DERIVATIVES], q, v, tau, damping)
                for name, x, y in zip(NAMES, got, expected):
                    assert x.shape == y.shape, name
                    np.testing.assert_allclose(x, y, rtol=1e-10, atol=1e-10,
                                               err_msg=f"{backend} {name} damping {damping}")


def test_casadi_derivatives_equal_pinocchios(case):
    _, modules, pm, constraints = case
    for q, v, tau in states(pm, 2, seed=4):
        _, refs = pinocchio_constrained_derivatives(pm, constraints, q, v, tau)
        got = casadi_derivatives(modules["casadi"][DERIVATIVES], q, v, tau)
        for name, x, ref in zip(NAMES, got, refs):
            scale = max(1.0, np.abs(ref).max())
            np.testing.assert_allclose(x / scale, ref / scale, rtol=0, atol=1e-8, err_msg=name)
