"""Ball-joint springs (MuJoCo's ``stiffness`` on a ball joint, :class:`eomgen.model.BallSpring`):
``passive_forces`` against MuJoCo's ``qfrc_passive`` and the forward dynamics ``M_a⁻¹ (τ_p − h)``
against ``qacc_smooth`` at random quaternions (both signs of the difference's ``w``: MuJoCo's
angle wraps into ``(−π, π]``), with the reference MuJoCo's ``qpos0`` and, set in the compiled
model, a random ``qpos_spring`` far from it; at the reference itself the torque is 0, not NaN.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.model import BallSpring
from support import model_states, relative
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import model_from_mujoco  # noqa: E402
from eomgen.parsers.mjcf.convert import layout, to_mujoco, velocity_map  # noqa: E402

BALLS = """<mujoco model="balls"><option><flag contact="disable"/></option><worldbody>
<body pos="0 0 1"><joint name="b1" type="ball" stiffness="2.5" damping="0.3" armature="0.01"/>
 <geom type="capsule" size=".05" fromto="0 0 0 .4 0 .1"/>
 <body pos=".4 0 .1"><joint name="h1" axis="0 1 0" stiffness="1.5" springref="10"/>
  <geom type="capsule" size=".05" fromto="0 0 0 .3 0 0"/>
  <body pos=".3 0 0"><joint name="b2" type="ball" stiffness="4" pos=".02 0 0"/>
   <geom type="box" size=".1 .05 .02" pos=".1 0 0"/></body></body></body></worldbody></mujoco>"""


@pytest.fixture(scope="module")
def balls():
    """``{reference: (model, m, module)}``: MuJoCo's own reference (qpos0), and b2's moved to a
    random quaternion in the compiled model."""
    out = {}
    for name in ("qpos0", "moved"):
        m = mujoco.MjModel.from_xml_string(BALLS)
        if name == "moved":
            quat = np.random.default_rng(5).normal(size=4)
            adr = int(m.jnt_qposadr[m.joint("b2").id])
            m.qpos_spring[adr:adr + 4] = quat / np.linalg.norm(quat)
        model = model_from_mujoco(m, "balls.xml")
        module = eomgen.derive(model, outputs=("tau_p", "M_a", "h")).lambdify().module
        out[name] = (model, m, module)
    return out


def test_the_springs_are_read(balls):
    model, m, _ = balls["moved"]
    springs = {j.name: j.spring for j in model.joints if isinstance(j.spring, BallSpring)}
    assert set(springs) == {"b1_wx", "b2_wx"}
    assert float(springs["b1_wx"].stiffness) == 2.5
    w, x, y, z = m.qpos_spring[-4:]
    assert [float(v) for v in springs["b2_wx"].reference] == [x, y, z, w]


def states(model, m, count):
    """Random states, and whether the difference to b1's reference (the identity) has w < 0:
    eomgen's q holds b1's quaternion (x, y, z, w) first."""
    found = model_states(model, count=count, seed=3)
    return found, {bool(q[3] < 0) for q, _ in found}


@pytest.mark.parametrize("reference", ["qpos0", "moved"])
def test_passive_forces_are_mujocos(balls, reference):
    model, m, module = balls[reference]
    lay = layout(m, model)
    data = mujoco.MjData(m)
    found, signs = states(model, m, 8)
    assert signs == {True, False}
    for q, v in found:
        data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
        mujoco.mj_forward(m, data)
        assert np.abs(data.qfrc_spring[:3]).max() > 0.5
        T = velocity_map(lay, data.qpos)
        assert relative(module.passive_forces(q, v).ravel(), T.T @ data.qfrc_passive) < 1e-12
        qdd = np.linalg.solve(module.drive_mass_matrix(q), module.passive_forces(q, v).ravel()
                              - module.nonlinear_effects(q, v).ravel())
        assert relative(T @ qdd, data.qacc_smooth) < 1e-12


def test_at_the_reference_the_torque_is_zero(balls):
    model, m, module = balls["moved"]
    q = np.zeros(model.nq)
    q[3] = 1.0  # b1 at the identity, its reference
    w, x, y, z = m.qpos_spring[-4:]
    q[5:9] = -np.array([x, y, z, w])  # b2 at its reference (the same rotation, negated)
    q[4] = m.qpos_spring[4]  # h1 at its springref
    tau = module.passive_forces(q, np.zeros(model.dof)).ravel()
    assert np.all(np.isfinite(tau)) and np.abs(tau).max() < 1e-14


@pytest.mark.slow
def test_the_state_derivative_holds_the_springs():
    """∂q̈/∂q of forward_dynamics_ctrl (a position servo on h1) against central differences
    along eomgen's integrate, at rest (the springs are what depend on q there besides
    gravity), and finite at the springs' reference."""
    from eomgen.model.configuration import integrate

    m = mujoco.MjModel.from_xml_string(BALLS.replace(
        "</worldbody>", '</worldbody><actuator><position joint="h1" kp="3"/></actuator>'))
    model = model_from_mujoco(m, "balls.xml")
    module = eomgen.derive(model, outputs=("qdd_ctrl", "dqdd_ctrl_dq")).lambdify().module
    ctrl, rest, h = np.array([0.3]), np.zeros(model.dof), 1e-5
    for q, _ in model_states(model, count=2, seed=1):
        numeric = np.column_stack([
            (module.forward_dynamics_ctrl(integrate(q, step, model=model), rest, ctrl)
             - module.forward_dynamics_ctrl(integrate(q, -step, model=model), rest, ctrl)
             ).ravel() / (2 * h) for step in h * np.eye(model.dof)])
        assert relative(module.forward_dynamics_ctrl_derivative_q(q, rest, ctrl),
                        numeric) < 1e-8
    q = np.zeros(model.nq)
    q[[3, 8]] = 1.0
    assert np.all(np.isfinite(module.forward_dynamics_ctrl_derivative_q(q, rest, ctrl)))


@pytest.mark.slow
def test_every_code_backend_gives_mujocos_spring_torques(balls, tmp_path):
    from support.generated import generated

    model, m, _ = balls["moved"]
    calls, _ = generated(model, ["passive_forces"], tmp_path)
    lay = layout(m, model)
    data = mujoco.MjData(m)
    q, v = next(iter(model_states(model, count=1, seed=9)))
    data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
    mujoco.mj_forward(m, data)
    expected = velocity_map(lay, data.qpos).T @ data.qfrc_passive
    for name, call in calls.items():
        assert relative(np.asarray(call("passive_forces", q, v)).ravel(), expected) < 1e-12, name
