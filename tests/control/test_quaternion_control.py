"""The controllers of eomgen.control on a model with a ball joint (a fixed-base chain: a ball
joint, then a revolute joint), q with NQ = 5 entries and v with NV = 4:

* the laws' torques against Pinocchio's model built by hand (``JointModelSpherical``): computed
  torque is ``crba`` · (v̇_d − K_d (v − v_d) − K_p e) + ``nonLinearEffects``, Slotine–Li with
  the true parameters ``crba`` a_r + ``computeCoriolisMatrix`` v_r + g − K_D s, with
  ``e = pinocchio.difference(q_d, q)``;
* closed loops simulated on the configuration space (q̇ = configuration_rate(q, v)): computed
  torque and the adaptive law bring the error down from a finite start, the adaptive law's
  V = ½ sᵀ M s + ½ β̃ᵀ Γ⁻¹ β̃ decreases;
* the quaternion layout read off a module's names (a free flyer, ball joints).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

import eomgen
from eomgen.control import ComputedTorque, SlotineLi, fourier_reference, simulate
from eomgen.control.configuration import module_layout, position_error
from eomgen.identification import FourierTrajectory
from support import relative
from support.quaternion import quaternion_robot
from support.extras import need

pin = need("pinocchio", reason="the laws are checked against Pinocchio")
need("scipy", reason="closed loops are integrated by SciPy")

SPEC = (("ball", "spherical", -1), ("j2", "revolute", 0))  # a ball joint, then a revolute one


@pytest.fixture(scope="module")
def chain():
    model, pm = quaternion_robot(SPEC, seed=2)
    dyn = eomgen.derive(model, outputs=["M", "tau", "g", "Y_SL_base", "beta"])
    return model, pm, dyn.lambdify().module


def desired_motion(model):
    rng = np.random.default_rng(3)
    trajectory = FourierTrajectory(rng.uniform(-0.3, 0.3, 4), rng.uniform(-0.4, 0.4, (4, 2)),
                                   rng.uniform(-0.4, 0.4, (4, 2)), 2 * np.pi / 2.0)
    return fourier_reference(trajectory, model)


def test_layout_is_read_off_the_module_names(chain):
    model, _, module = chain
    assert module_layout(module) == model.quaternion_joints
    names = SimpleNamespace(
        JOINT_NAMES=("base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz", "knee",
                     "hip_wx", "hip_wy", "hip_wz"),
        CONFIGURATION_NAMES=("base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz",
                             "base_qw", "knee", "hip_qx", "hip_qy", "hip_qz", "hip_qw"))
    layout = module_layout(names)
    assert [(j.kind, j.name, j.v_index, j.q_index) for j in layout] == [
        ("free_flyer", "base", 0, 0), ("spherical", "hip", 7, 8)]
    assert module_layout(SimpleNamespace(JOINT_NAMES=("a", "b"))) == ()


def test_law_torques_are_pinocchios(chain):
    model, pm, module = chain
    data = pm.createData()
    desired = desired_motion(model)
    beta = module.base_parameters()
    Kp, Kd = np.diag([25.0, 25.0, 25.0, 16.0]), np.diag([10.0, 10.0, 10.0, 8.0])
    computed = ComputedTorque(module, desired, Kp, Kd)
    adaptive = SlotineLi(module, desired, 3.0 * np.eye(4), 5.0 * np.eye(4), np.eye(len(beta)))
    rng = np.random.default_rng(4)
    for t in (0.1, 0.9):
        q_d, v_d, a_d = desired(t)
        q = pin.integrate(pm, q_d, rng.uniform(-0.3, 0.3, 4))
        v = v_d + rng.normal(scale=0.3, size=4)
        e = pin.difference(pm, q_d, q)
        assert relative(position_error(model.quaternion_joints, q, q_d), e) < 1e-12
        M = pin.crba(pm, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        expected = M @ (a_d - Kd @ (v - v_d) - Kp @ e) + pin.nonLinearEffects(pm, data, q, v)
        assert relative(computed.torque(t, q, v), expected) < 1e-12
        v_r, a_r = v_d - 3.0 * e, a_d - 3.0 * (v - v_d)
        expected = (M @ a_r + pin.computeCoriolisMatrix(pm, data, q, v) @ v_r
                    + pin.computeGeneralizedGravity(pm, data, q) - 5.0 * (v - v_r))
        tau, _ = adaptive.torque_and_adaptation(t, q, v, beta)
        assert relative(tau, expected) < 1e-12


@pytest.mark.slow
def test_closed_loops_bring_the_error_down(chain):
    model, pm, module = chain
    joints = model.quaternion_joints
    desired = desired_motion(model)
    q_d0, v_d0, _ = desired(0.0)
    q0 = pin.integrate(pm, q_d0, np.array([0.3, -0.2, 0.25, 0.3]))
    v0 = v_d0 + 0.2
    start = np.linalg.norm(position_error(joints, q0, q_d0))
    law = ComputedTorque(module, desired, np.diag([25.0] * 4), np.diag([10.0] * 4))
    run = simulate(law, q0, v0, 2.0, t_eval=np.array([0.0, 2.0]), rtol=1e-8, atol=1e-8)
    assert run.q.shape == (2, model.nq) and run.qd.shape == (2, model.dof)
    end = np.linalg.norm(position_error(joints, run.q[-1], desired(2.0)[0]))
    assert end < 1e-2 * start
    assert abs(np.linalg.norm(run.q[-1][:4]) - 1) < 1e-6  # the ball's quaternion stays unit

    beta = module.base_parameters()
    law = SlotineLi.tuned(module, desired, 1.3 * beta, period=2.0, samples=20)
    run = simulate(law, q0, v0, 2.0, t_eval=np.linspace(0, 2.0, 5), beta0=1.3 * beta,
                   rtol=1e-6, atol=1e-6)
    V = [law.lyapunov(t, q, v, b, beta) for t, q, v, b in zip(run.t, run.q, run.qd,
                                                             run.beta_hat)]
    assert V[-1] < 0.2 * V[0] and all(b < a for a, b in zip(V, V[1:]))
    end = np.linalg.norm(position_error(joints, run.q[-1], desired(2.0)[0]))
    assert end < 0.1 * start
