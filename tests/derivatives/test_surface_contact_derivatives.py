"""Derivatives of the contact-constrained forward dynamics with surface contacts (issue 25):
``constrained_forward_dynamics_derivatives`` when a frame is held in position and orientation
(6 rows, the wrench in the frame's axes; docs/contact.md).

References: Pinocchio's ``constraintDynamics`` and ``computeConstraintDynamicsDerivatives``
with a ``CONTACT_6D`` ``RigidConstraintModel`` in ``LOCAL`` axes (eomgen's surface-contact
convention, :func:`support.reference.pinocchio_contacts`) on models Pinocchio reads from the
same URDF: the UR5 holding its ``tool0`` (six joints, six rows) and the one-joint leg of
tests/derivatives/test_constrained_derivatives.py on a quaternion free flyer holding its foot;
central differences of the generated ``constrained_forward_dynamics`` along eomgen's
``integrate``; (slow) the CasADi module's composition against the NumPy module's.
"""

from __future__ import annotations

import numpy as np
import pytest

from support import erd_robots_or_skip
from support.held import (constrained_central_differences, held_robot,
                          pinocchio_constrained_derivatives)
from test_constrained_derivatives import DERIVATIVES, leg, states
from support.extras import need

pin = need("pinocchio", reason="checked against Pinocchio's derivatives")

NAMES = ("dqdd_dq", "dqdd_dqd", "dqdd_dtau", "dF_dq", "dF_dqd", "dF_dtau")


@pytest.fixture(scope="module", params=["ur5", "floating_leg"])
def case(request, tmp_path_factory):
    folder = tmp_path_factory.mktemp(request.param)
    if request.param == "ur5":
        path = erd_robots_or_skip() / "ur_description" / "urdf" / "ur5_robot.urdf"
        return held_robot(path, ["tool0"], False, [DERIVATIVES], folder, kind="surface")
    return floating_leg(folder, ("numpy",))


def floating_leg(folder, backends):
    """The one-joint leg on a quaternion free flyer holding its foot (surface contact)."""
    path = folder / "leg.urdf"
    path.write_text(leg(1), encoding="utf-8")
    return held_robot(path, ["foot"], True, [DERIVATIVES], folder, backends, "surface")


def test_surface_contact_derivatives_equal_pinocchios(case):
    model, modules, pm, constraints = case
    m = modules["numpy"]
    for q, v, tau in states(pm, 2, seed=6):
        (ddq, lam), refs = pinocchio_constrained_derivatives(pm, constraints, q, v, tau)
        qdd, F = m["constrained_forward_dynamics"](q, v, tau)
        assert F.shape == (6,)
        # relative to the largest entry (a small entry beside large ones carries their rounding)
        for got, ref in ((qdd, ddq), (F, lam)):
            np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9 * max(1.0, abs(ref).max()))
        for name, got, ref in zip(NAMES, m[DERIVATIVES](q, v, tau), refs):
            assert got.shape == ref.shape, name
            scale = max(1.0, np.abs(ref).max())
            np.testing.assert_allclose(got / scale, ref / scale, rtol=0, atol=1e-9, err_msg=name)


def test_surface_contact_derivatives_are_central_differences(case):
    model, modules, pm, _ = case
    m, h = modules["numpy"], 1e-6
    cfd = m["constrained_forward_dynamics"]
    for q, v, tau in states(pm, 1, seed=7):
        exact = m[DERIVATIVES](q, v, tau)
        differences = constrained_central_differences(model, cfd, q, v, tau, h)
        for name, got, fd in zip(NAMES, exact, differences):
            scale = max(1.0, np.abs(fd).max())
            np.testing.assert_allclose(got / scale, fd / scale, rtol=0, atol=1e-6, err_msg=name)


@pytest.mark.slow  # the leg derived again, with the CasADi module (~4 s)
def test_casadi_composes_the_surface_contact_derivatives(tmp_path):
    need("casadi")
    _, modules, pm, _ = floating_leg(tmp_path, ("numpy", "casadi"))
    function = modules["casadi"][DERIVATIVES]
    for q, v, tau in states(pm, 1, seed=8):
        out = function.call({"q": q, "qd": v, "tau": tau})
        for name, expected in zip(NAMES, modules["numpy"][DERIVATIVES](q, v, tau)):
            np.testing.assert_allclose(np.array(out[name]), expected, rtol=1e-10, atol=1e-10,
                                       err_msg=name)
