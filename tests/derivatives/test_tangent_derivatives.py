"""Derivatives of the dynamics of models whose configuration and velocity sizes differ (issue
25): a quaternion free flyer and a ball joint, ∂/∂q in tangent coordinates (NV columns), as
Pinocchio's.

References: Pinocchio's ``computeRNEADerivatives``, ``computeABADerivatives`` and
``computeGeneralizedGravityDerivatives`` on the same MJCF text read by Pinocchio's own MJCF
reader (``JointModelFreeFlyer``, ``JointModelSpherical``); central differences of the generated
τ, q̈ and g along Pinocchio's ``integrate`` with v (the body twist) held fixed; the position rows
of ``linearize``'s A by central differences of ``difference(q0, ·)`` along the motion; and every
backend against the NumPy module.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.model.configuration import integrate
from support.generated import generated
from support.extras import need

pin = need("pinocchio", reason="checked against Pinocchio's derivatives")
need("mujoco", reason="the models are MJCF, read by MuJoCo's compiler")

GRAVITY = np.array([0.3, -0.2, -9.81])
#: a ball shoulder off its body's origin, a hinge elbow about a general axis (NQ 5, NV 4)
BALL_ARM = """<mujoco model="ball_arm"><option gravity="0.3 -0.2 -9.81"/><worldbody>
<body name="upper" pos="0.1 0 0.2" quat="0.9 0.1 0.3 0.2">
<joint name="shoulder" type="ball" pos="0 0 0.05"/>
<inertial pos="0.02 0.01 -0.2" mass="1.2" fullinertia="0.02 0.025 0.01 0.001 0.002 -0.001"/>
<body name="fore" pos="0 0.05 -0.4"><joint name="elbow" type="hinge" axis="0.3 1 0"/>
<inertial pos="0.01 0 -0.2" mass="0.8" diaginertia="0.01 0.012 0.004"/></body></body>
</worldbody></mujoco>"""
#: a free-flying trunk with two legs on hinges, a branched tree (NQ 9, NV 8)
HOPPER = """<mujoco model="hopper"><option gravity="0.3 -0.2 -9.81"/><worldbody>
<body name="torso" pos="0 0 1"><freejoint name="root"/>
<inertial pos="0.01 -0.02 0.03" mass="4" fullinertia="0.2 0.3 0.25 0.01 -0.02 0.015"/>
<body name="leg" pos="0.1 0.15 -0.1" quat="0.9 0.1 0.3 0.2">
<joint name="hip" type="hinge" axis="0 1 0.2"/>
<inertial pos="0 0.01 -0.2" mass="1.2" fullinertia="0.02 0.025 0.01 0.001 0.002 -0.001"/>
</body>
<body name="other_leg" pos="-0.1 -0.12 -0.1"><joint name="other_hip" type="hinge" axis="1 0 0"/>
<inertial pos="0 0 -0.15" mass="0.9" diaginertia="0.015 0.012 0.003"/></body>
</body></worldbody></mujoco>"""
FUNCTIONS = ["inverse_dynamics_derivatives", "forward_dynamics_derivatives",
             "gravity_derivative", "linearize", "inverse_dynamics", "forward_dynamics_aba",
             "gravity_vector"]
ROBOTS = {"ball_arm": BALL_ARM, "hopper": HOPPER}


def _case(name, tmp_path_factory, backends=("numpy",)):
    folder = tmp_path_factory.mktemp(name)
    path = folder / f"{name}.xml"
    path.write_text(ROBOTS[name], encoding="utf-8")
    model = eomgen.load(path)
    pm = pin.buildModelFromMJCF(str(path))
    pm.gravity = pin.Motion(GRAVITY, np.zeros(3))
    calls, modules = generated(model, FUNCTIONS, folder, **({} if backends is None else
                                                             {"backends": backends}))
    return model, pm, calls, modules


@pytest.fixture(scope="module", params=sorted(ROBOTS))
def case(request, tmp_path_factory):
    return _case(request.param, tmp_path_factory)


def states(pm, count=2, seed=0):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        yield q, rng.normal(size=pm.nv), rng.normal(size=pm.nv)


def tangent_difference(f, model, q, h=1e-6):
    """Columns ``(f(q ⊕ h eᵢ) − f(q ⊕ −h eᵢ)) / 2h``, ``⊕`` eomgen's integrate (Pinocchio's,
    tests/dynamics); ``model`` None: plain differences of a vector ``q``."""
    columns = []
    for e in np.eye(len(q) if model is None else model.dof) * h:
        if model is None:
            columns.append((f(q + e) - f(q - e)) / (2 * h))
        else:
            columns.append((f(integrate(q, e, model=model)) - f(integrate(q, -e, model=model)))
                           / (2 * h))
    return np.stack(columns, axis=-1)


def test_the_layouts_are_pinocchios(case):
    model, pm, _, modules = case
    assert (model.nq, model.dof) == (pm.nq, pm.nv) and model.nq > model.dof
    assert modules["numpy"]["NQ"] == pm.nq and modules["numpy"]["NV"] == pm.nv


def test_derivatives_equal_pinocchios(case):
    _, pm, _, modules = case
    m, data = modules["numpy"], pm.createData()
    for q, v, a in states(pm):
        dq, dv = m["inverse_dynamics_derivatives"](q, v, a)
        ref_q, ref_v, _ = pin.computeRNEADerivatives(pm, data, q, v, a)
        assert dq.shape == (pm.nv, pm.nv)
        np.testing.assert_allclose(dq, ref_q, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(dv, ref_v, rtol=1e-9, atol=1e-9)
        np.testing.assert_allclose(m["gravity_derivative"](q),
                                   pin.computeGeneralizedGravityDerivatives(pm, data, q),
                                   rtol=1e-9, atol=1e-9)
        tau = pin.rnea(pm, data, q, v, a)
        ddq_dq, ddq_dv, Minv = m["forward_dynamics_derivatives"](q, v, tau)
        pin.computeABADerivatives(pm, data, q, v, tau)
        ref_Minv = np.triu(data.Minv) + np.triu(data.Minv, 1).T
        np.testing.assert_allclose(ddq_dq, data.ddq_dq, rtol=1e-8, atol=1e-8)
        np.testing.assert_allclose(ddq_dv, data.ddq_dv, rtol=1e-8, atol=1e-8)
        np.testing.assert_allclose(Minv, ref_Minv, rtol=1e-9, atol=1e-9)


def test_derivatives_are_central_differences_along_integrate(case):
    model, pm, _, modules = case
    m = modules["numpy"]
    for q, v, a in states(pm, count=1, seed=1):
        tau = m["inverse_dynamics"](q, v, a)
        dq, dv = m["inverse_dynamics_derivatives"](q, v, a)
        ddq_dq, ddq_dv, _ = m["forward_dynamics_derivatives"](q, v, tau)
        pairs = [(dq, lambda x: m["inverse_dynamics"](x, v, a), model, q),
                 (dv, lambda x: m["inverse_dynamics"](q, x, a), None, v),
                 (m["gravity_derivative"](q), m["gravity_vector"], model, q),
                 (ddq_dq, lambda x: m["forward_dynamics_aba"](x, v, tau), model, q),
                 (ddq_dv, lambda x: m["forward_dynamics_aba"](q, x, tau), None, v)]
        for exact, f, along, x in pairs:
            np.testing.assert_allclose(exact, tangent_difference(f, along, x), rtol=1e-6,
                                       atol=1e-6)


def test_linearize_is_the_state_equation_in_tangent_coordinates(case):
    """A = ∂(δ̇, v̇)/∂(δ, v) at δ = 0 in the chart δ ↦ q0 ⊕ δ: δ̇ = d/dt difference(q0, q(t))
    with q(t) moving at v, by central differences in δ and in t."""
    _, pm, _, modules = case
    m, nv, h = modules["numpy"], pm.nv, 1e-5
    for q0, v, tau in states(pm, count=1, seed=2):
        A, B = m["linearize"](q0, v, tau)
        ddq_dq, ddq_dv, Minv = m["forward_dynamics_derivatives"](q0, v, tau)

        def rate(delta):
            q = pin.integrate(pm, q0, delta)
            return (pin.difference(pm, q0, pin.integrate(pm, q, h * v))
                    - pin.difference(pm, q0, pin.integrate(pm, q, -h * v))) / (2 * h)

        np.testing.assert_allclose(rate(np.zeros(nv)), v, rtol=1e-8, atol=1e-8)
        columns = [(rate(e) - rate(-e)) / 2e-4 for e in np.eye(nv) * 1e-4]
        np.testing.assert_allclose(A[:nv, :nv], np.stack(columns, axis=-1), atol=1e-5)
        assert np.abs(A[:nv, :nv]).max() > 0.05  # the transport of v: not the fixed base's 0
        np.testing.assert_array_equal(A[:nv, nv:], np.eye(nv))
        np.testing.assert_array_equal(A[nv:], np.hstack([ddq_dq, ddq_dv]))
        np.testing.assert_array_equal(B, np.vstack([np.zeros((nv, nv)), Minv]))


#: the single-result functions, which every backend's harness calls alike
SINGLE = ["inverse_dynamics_derivative_q", "inverse_dynamics_derivative_qd",
          "gravity_derivative", "forward_dynamics_derivative_q", "forward_dynamics_derivative_qd",
          "inverse_mass_matrix", "state_matrix", "input_matrix"]


@pytest.mark.slow  # a C compile and three array libraries (~20 s; the free flyer's tangent
# seeds run in every backend in test_constrained_derivatives' partials)
def test_every_backend_gives_the_numpy_modules_derivatives(tmp_path_factory):
    name = "ball_arm"
    folder = tmp_path_factory.mktemp(f"{name}_backends")
    path = folder / f"{name}.xml"
    path.write_text(ROBOTS[name], encoding="utf-8")
    model = eomgen.load(path)
    calls, _ = generated(model, SINGLE, folder)
    pm = pin.buildModelFromMJCF(str(path))
    nv = model.dof
    shapes = {f: (2 * nv, 2 * nv) if f == "state_matrix" else
              (2 * nv, nv) if f == "input_matrix" else (nv, nv) for f in SINGLE}
    for q, v, u in states(pm, count=1, seed=3):
        for function in SINGLE:
            args = (q,) if function in ("gravity_derivative", "inverse_mass_matrix") else (q, v, u)
            expected = calls["numpy"](function, *args)
            assert expected.shape == shapes[function], function
            for backend, call in calls.items():
                np.testing.assert_allclose(call(function, *args).reshape(expected.shape),
                                           expected, rtol=1e-11, atol=1e-11,
                                           err_msg=f"{backend} {function}")
