"""Drives on the real joints of a floating quaternion model (a free flyer with a ball hip, a
flexible knee and a rigid driven arm) against Pinocchio's model built by hand
(``JointModelFreeFlyer``, ``JointModelSpherical``, ``model.armature``), q (NQ) and v (NV)
passed unchanged:

* ``M_a`` and ``tau_a`` are Pinocchio's ``crba`` and ``rnea`` with the armature in
  ``model.armature``, plus the friction law d v + f sign(v) written out here; ``tau_f``,
  ``tau_f_smooth`` that law;
* Spong's flexible knee: ``M_l``, ``tau_K``, ``thetadd_m`` from Pinocchio's M and the
  equations of docs/actuators.md;
* the flat outputs (θ, θ̇, τ that make the links follow q(t)) against finite differences of
  Pinocchio's ``rnea`` along a trajectory whose configuration is integrated with
  q̇ = configuration_rate(q, v(t)) (SciPy's DOP853, tolerance 1e-13), v(t) a cubic.
"""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.model import Actuator
from eomgen.model.configuration import configuration_rate
from support import relative
from support.generated import generated
from support.quaternion import pinocchio_states, quaternion_robot
from support.extras import need

pin = need("pinocchio", reason="quaternion joints are checked against Pinocchio")

SPEC = (("a_hip", "spherical", -1), ("b_knee", "revolute", 0), ("c_arm", "revolute", -1))
KNEE = Actuator(armature=0.05, damping=0.1, friction=0.2, friction_width=0.5, stiffness=50.0)
ARM = Actuator(armature=0.3, damping=0.4, friction=0.3, friction_width=0.2)
FUNCTIONS = ("M_a", "tau_f", "tau_f_smooth", "tau_a", "M_l", "tau_K", "thetadd_m",
             "theta_flat", "thetad_flat", "tau_flat", "tau_flat_smooth")


@pytest.fixture(scope="module")
def case(tmp_path_factory):
    model, pm = quaternion_robot(SPEC, seed=3, free_flyer=True,
                                 actuators={"b_knee": KNEE, "c_arm": ARM})
    calls, _ = generated(model, FUNCTIONS, tmp_path_factory.mktemp("quaternion_drives"),
                         backends=("numpy",))
    index = {name: pm.joints[pm.getJointId(name)].idx_v for name in ("b_knee", "c_arm")}
    index.update({f"q_{name}": pm.joints[pm.getJointId(name)].idx_q for name in index})
    return model, pm, calls["numpy"], index


def drive_vectors(pm, index):
    """Armature, viscous, Coulomb and width per velocity entry (0 off the drives)."""
    a, d, f, w = (np.zeros(pm.nv) for _ in range(4))
    w[:] = 1.0
    for name, drive in (("b_knee", KNEE), ("c_arm", ARM)):
        k = index[name]
        a[k], d[k], f[k], w[k] = drive.armature, drive.damping, drive.friction, \
            drive.friction_width
    return a, d, f, w


def test_rigid_drive_outputs_are_pinocchios_with_armature(case):
    _, pm, call, index = case
    a, d, f, w = drive_vectors(pm, index)
    pm.armature = a  # every joint stiff here: the flexible knee's motor inertia is its armature
    data = pm.createData()
    for q, v, acc in pinocchio_states(pm, count=2, seed=4):
        M = pin.crba(pm, data, q)
        assert relative(call("drive_mass_matrix", q), np.triu(M) + np.triu(M, 1).T) < 1e-12
        friction = d * v + f * np.sign(v)
        assert relative(call("friction_torque", v), friction) < 1e-14
        assert relative(call("friction_torque_smooth", v), d * v + f * np.tanh(v / w)) < 1e-14
        assert relative(call("drive_inverse_dynamics", q, v, acc),
                        pin.rnea(pm, data, q, v, acc) + friction) < 1e-12


def test_flexible_knee_outputs(case):
    _, pm, call, index = case
    a, d, f, w = drive_vectors(pm, index)
    k = index["b_knee"]
    rigid = a.copy()
    rigid[k] = 0.0
    pm.armature = np.zeros(pm.nv)
    data = pm.createData()
    rng = np.random.default_rng(5)
    for q, v, _ in pinocchio_states(pm, count=2, seed=6):
        theta, thetad, tau = (rng.normal(size=pm.nv) for _ in range(3))
        M = pin.crba(pm, data, q)
        assert relative(call("link_mass_matrix", q), np.triu(M) + np.triu(M, 1).T
                        + np.diag(rigid)) < 1e-12
        spring = float(KNEE.stiffness) * (theta[k] - q[index["q_b_knee"]])
        expected = np.zeros(pm.nv)
        expected[k] = spring
        assert relative(call("spring_torque", q, theta), expected) < 1e-14
        expected[k] = (tau[k] - spring - d[k] * thetad[k]
                       - f[k] * np.tanh(thetad[k] / w[k])) / a[k]
        assert relative(call("motor_forward_dynamics", q, theta, thetad, tau), expected) < 1e-12


def test_flat_outputs_follow_a_trajectory_on_the_configuration_space(case):
    scipy = need("scipy.integrate", reason="the trajectory is integrated by SciPy")
    model, pm, call, index = case
    a, d, f, w = drive_vectors(pm, index)
    k = index["b_knee"]
    pm.armature = np.zeros(pm.nv)
    data = pm.createData()
    rng = np.random.default_rng(8)
    q0 = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
    c = [rng.normal(size=pm.nv) for _ in range(4)]  # v, v̇, v̈, v⃛ at t = 0

    def v(t):
        return c[0] + c[1] * t + c[2] * t ** 2 / 2 + c[3] * t ** 3 / 6

    def dv(t):
        return c[1] + c[2] * t + c[3] * t ** 2 / 2

    h = 2.5e-3
    paths = [scipy.solve_ivp(lambda t, x: configuration_rate(x, v(t), model), (0, 2.5 * h * s),
                             q0, method="DOP853", rtol=1e-13, atol=1e-13, dense_output=True)
             for s in (1, -1)]
    tau_L = {s: pin.rnea(pm, data, paths[s < 0].sol(s * h), v(s * h), dv(s * h)).copy()
             for s in (-2, -1, 0, 1, 2)}
    rate = (tau_L[-2] - 8 * tau_L[-1] + 8 * tau_L[1] - tau_L[2]) / (12 * h)
    rate2 = (-tau_L[-2] + 16 * tau_L[-1] - 30 * tau_L[0] + 16 * tau_L[1] - tau_L[2]) / (12 * h * h)
    K = float(KNEE.stiffness)
    theta = call("motor_angles", q0, *c[:2])
    thetad = call("motor_velocities", q0, *c[:3])
    expected_theta = np.zeros(pm.nv)
    expected_theta[index["c_arm"]] = q0[index["q_c_arm"]]
    expected_theta[k] = q0[index["q_b_knee"]] + tau_L[0][k] / K
    assert relative(theta, expected_theta) < 1e-12
    expected_thetad = c[0].copy()
    expected_thetad[k] += rate[k] / K
    assert relative(thetad, expected_thetad) < 1e-8
    assert abs(rate[k]) > 1.0  # the knee's load changes along the trajectory
    thetadd_k = c[1][k] + rate2[k] / K
    for name, law in (("flat_motor_torque", np.sign),
                      ("flat_motor_torque_smooth", lambda x: np.tanh(x / w))):
        expected = tau_L[0] + a * c[1] + d * c[0] + f * law(c[0])
        expected[k] = (a[k] * thetadd_k + tau_L[0][k] + d[k] * expected_thetad[k]
                       + f[k] * law(expected_thetad)[k])
        assert relative(call(name, q0, *c), expected) < 1e-8, name
