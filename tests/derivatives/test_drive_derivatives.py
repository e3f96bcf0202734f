"""Derivatives of the dynamics with drives (issue 25 with issue 17's armature and friction):
``drive_inverse_dynamics_derivatives`` and ``drive_forward_dynamics_derivatives``.

References: Pinocchio 4 with ``model.armature`` set (its ``aba``, ``crba`` and
``computeABADerivatives`` take the armature; they know no friction), the friction's derivative
added by hand from its formula, d + f/w (1 − tanh²(q̇/w)); and central differences of the
generated NumPy ``drive_inverse_dynamics``. PUMA 560 with a drive on every joint.
"""

from __future__ import annotations

import dataclasses

from dataclasses import replace

import numpy as np
import pytest

from eomgen.model import Actuator
from support import robots
from support.generated import generated
from support.reference import pin_q_order, to_pinocchio
from support.extras import need

FUNCTIONS = ["drive_inverse_dynamics_derivatives", "drive_forward_dynamics_derivatives",
             "drive_inverse_dynamics"]


@pytest.fixture(scope="module")
def driven(tmp_path_factory):
    """The PUMA 560 with armature, viscous and Coulomb friction on every joint, its NumPy
    module, the drive values and Pinocchio's model with the same armature."""
    need("pinocchio")
    model = robots.puma()
    n = model.dof
    a, d = 0.1 + 0.1 * np.arange(n), 0.2 + 0.05 * np.arange(n)
    f, w = 0.3 + 0.1 * np.arange(n), 0.4
    drives = iter(Actuator(armature=float(a[k]), damping=float(d[k]), friction=float(f[k]),
                           friction_width=w) for k in range(n))
    joints = tuple(replace(j, actuator=next(drives)) if j.type.is_movable else j
                   for j in model.joints)
    model = replace(model, joints=joints)
    _, modules = generated(model, FUNCTIONS, tmp_path_factory.mktemp("driven"),
                           backends=("numpy",))
    pm = to_pinocchio(model)
    perm = pin_q_order(model, pm)
    pm.armature = a[perm]
    return model, modules["numpy"], (a, d, f, w), pm, perm


def test_drive_forward_dynamics_derivatives_agree_with_pinocchio(driven):
    import pinocchio as pin

    model, module, (a, d, f, w), pm, perm = driven
    data, inv, n = pm.createData(), np.argsort(perm), model.dof
    rng = np.random.default_rng(3)
    for _ in range(3):
        q, qd, tau = (rng.uniform(-1.5, 1.5, n) for _ in range(3))
        effort = tau - d * qd - f * np.tanh(qd / w)        # what the rigid bodies receive
        pin.computeABADerivatives(pm, data, q[perm], qd[perm], effort[perm])
        Minv = np.triu(data.Minv) + np.triu(data.Minv, 1).T
        Minv, dq, dqd = (x[np.ix_(inv, inv)] for x in (Minv, data.ddq_dq, data.ddq_dv))
        slope = d + f / w * (1 - np.tanh(qd / w) ** 2)
        expected = (dq, dqd - Minv * slope, Minv)          # Minv @ diag(slope)
        got = module["drive_forward_dynamics_derivatives"](q, qd, tau)
        M_a = pin.crba(pm, data, q[perm])
        M_a = (np.triu(M_a) + np.triu(M_a, 1).T)[np.ix_(inv, inv)]
        np.testing.assert_allclose(got[2] @ M_a, np.eye(n), atol=1e-10)  # M + diag(a)
        for ours, theirs in zip(got, expected):
            assert np.abs(ours - theirs).max() <= 1e-10 * np.abs(theirs).max()


def test_drive_inverse_dynamics_derivatives_agree_with_pinocchio_and_differences(driven):
    import pinocchio as pin

    model, module, (a, d, f, w), pm, perm = driven
    data, inv, n = pm.createData(), np.argsort(perm), model.dof
    rng = np.random.default_rng(5)
    q, qd, qdd = (rng.uniform(-1.5, 1.5, n) for _ in range(3))
    pin.computeRNEADerivatives(pm, data, q[perm], qd[perm], qdd[perm])
    expected = (data.dtau_dq[np.ix_(inv, inv)], data.dtau_dv[np.ix_(inv, inv)] + np.diag(d))
    got = module["drive_inverse_dynamics_derivatives"](q, qd, qdd)
    for ours, theirs in zip(got, expected):
        assert np.abs(ours - theirs).max() <= 1e-10 * np.abs(theirs).max()
    tau_a, h = module["drive_inverse_dynamics"], 1e-6  # exact-sign Coulomb: qd away from 0
    columns = [(tau_a(q, qd + h * e, qdd) - tau_a(q, qd - h * e, qdd)) / (2 * h)
               for e in np.eye(n)]
    np.testing.assert_allclose(got[1], np.stack(columns, axis=1), rtol=1e-6, atol=1e-6)


def test_forward_dynamics_derivatives_of_a_lone_floating_body(tmp_path):
    """The spinning top floating free (one body, the 6-joint virtual chain of the Euler chart):
    some of its ABA accelerations are τ_k / m, no named intermediate; the forward-dynamics
    derivatives (plain and with drives, here none) are the central differences of the
    generated ``forward_dynamics_aba``."""
    import eomgen
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene

    root = robots.ROOT
    scene = load_scene(root / "examples/contacts/top_on_a_point.yaml")  # its Euler chart
    model = apply_scene(eomgen.load(root / "examples/robots/spinning_top.yaml"),
                        dataclasses.replace(scene, floating_base="euler"))[0]
    _, modules = generated(model, ["forward_dynamics_derivatives", "forward_dynamics_aba",
                                   "drive_forward_dynamics_derivatives"], tmp_path,
                           backends=("numpy",))
    module, n, h = modules["numpy"], model.dof, 1e-6
    rng = np.random.default_rng(11)
    q, qd, tau = (rng.uniform(-1.0, 1.0, n) for _ in range(3))
    aba = module["forward_dynamics_aba"]
    expected = (
        np.stack([(aba(q + h * e, qd, tau) - aba(q - h * e, qd, tau)) / (2 * h)
                  for e in np.eye(n)], axis=1),
        np.stack([(aba(q, qd + h * e, tau) - aba(q, qd - h * e, tau)) / (2 * h)
                  for e in np.eye(n)], axis=1),
        np.stack([(aba(q, qd, tau + h * e) - aba(q, qd, tau - h * e)) / (2 * h)
                  for e in np.eye(n)], axis=1))
    for function in ("forward_dynamics_derivatives", "drive_forward_dynamics_derivatives"):
        for ours, theirs in zip(module[function](q, qd, tau), expected):
            np.testing.assert_allclose(ours, theirs, rtol=1e-6, atol=1e-6, err_msg=function)
