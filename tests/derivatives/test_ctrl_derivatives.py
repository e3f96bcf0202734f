"""∂q̈/∂q and ∂q̈/∂q̇ of forward_dynamics_ctrl (issue 41: MuJoCo's actuators, for MPC).

References: central differences of the generated forward_dynamics_ctrl (along eomgen's
``integrate``, Pinocchio's tangent, for the free flyer) and of MuJoCo's own ``qacc_smooth``
(mj_forward, contacts off) on a model of hinges and a slide: joint springs, damping, armature,
a fixed tendon with a dead band and damping, a position servo, a velocity servo, a motor with
a ctrlrange, a general actuator with an affine gain and a forcerange, and a position servo on
the fixed tendon. The combined function returns the two Jacobians of the single ones; (slow)
every code backend gives the NumPy module's.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedFeatureWarning
from eomgen.model.configuration import integrate
from support.derivatives import results
from support.extras import need
from support.generated import generated

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

OUTPUTS = ["forward_dynamics_ctrl", "forward_dynamics_ctrl_derivative_q",
           "forward_dynamics_ctrl_derivative_qd", "forward_dynamics_ctrl_derivatives"]

ARM = """<mujoco model="servoarm"><option gravity="0.2 -0.1 -9.81"/><worldbody>
  <body name="a"><joint name="j1" axis="0 0 1" stiffness="3" springref="0.2" damping="0.4"/>
    <geom type="capsule" size="0.04" fromto="0 0 0 0.4 0 0" mass="1.2"/>
    <body name="b" pos="0.4 0 0"><joint name="j2" axis="0 1 0.3" armature="0.02"/>
      <geom type="capsule" size="0.03" fromto="0 0 0 0.3 0 0.1" mass="0.7"/>
      <body name="c" pos="0.3 0 0.1"><joint name="j3" type="slide" axis="1 0 0" stiffness="40"
          springref="0.05"/><geom type="box" size="0.03 0.03 0.03" mass="0.3"/>
        <body name="d" pos="0.05 0 0"><joint name="j4" axis="1 0 0" damping="0.1"/>
          <geom type="capsule" size="0.02" fromto="0 0 0 0 0.2 0" mass="0.2"/></body>
      </body></body></body></worldbody>
  <tendon><fixed name="t" stiffness="5" springlength="-0.1 0.1" damping="0.3">
    <joint joint="j1" coef="1"/><joint joint="j2" coef="-0.5"/></fixed></tendon>
  <actuator><position name="p" joint="j2" kp="20" kv="1"/>
    <motor name="m" joint="j3" gear="2" ctrlrange="-1 1" ctrllimited="true"/>
    <velocity name="v" joint="j1" kv="3"/>
    <general name="g" joint="j4" gainprm="2 0.5 0.3" gaintype="affine" biastype="affine"
      biasprm="0.1 -1 -0.2" forcerange="-3 3" forcelimited="true"/>
    <position name="pt" tendon="t" kp="6" kv="0.4" gear="1.5"/></actuator>
</mujoco>"""

FLYER = """<mujoco model="flyer"><worldbody>
  <body name="torso" pos="0 0 1"><freejoint name="root"/>
    <inertial pos="0.01 -0.02 0.03" mass="4" fullinertia="0.2 0.3 0.25 0.01 -0.02 0.015"/>
    <body name="thigh" pos="0.1 0.15 -0.1"><joint name="hip" axis="0 1 0.2" stiffness="2"
        damping="0.3" armature="0.05"/>
      <inertial pos="0 0.01 -0.2" mass="1.2" diaginertia="0.02 0.025 0.01"/>
      <body name="shank" pos="0 0.02 -0.4"><joint name="knee" axis="1 0 0.3"/>
        <inertial pos="0.01 0 -0.2" mass="0.8" diaginertia="0.01 0.012 0.004"/></body></body>
  </body></worldbody>
  <actuator><position name="hip" joint="hip" kp="15" kv="0.5"/>
    <motor name="knee" joint="knee" gear="3"/></actuator>
</mujoco>"""


def load(tmp_path, text, name):
    path = tmp_path / f"{name}.xml"
    path.write_text(text, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnsupportedFeatureWarning)
        return eomgen.load(path), path


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    folder = tmp_path_factory.mktemp("ctrl_arm")
    model, path = load(folder, ARM, "arm")
    calls, _ = generated(model, OUTPUTS, folder, ("numpy",))
    return model, mujoco.MjModel.from_xml_path(str(path)), calls["numpy"]


def differences(f, x, h=1e-6):
    return np.column_stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(len(x))])


def relative(a, b):
    return np.abs(a - b).max() / np.abs(b).max()


def states(rng, count):
    for _ in range(count):  # some controls beyond ctrlrange, some forces beyond forcerange
        yield rng.uniform(-1, 1, 4), rng.uniform(-2, 2, 4), rng.uniform(-2, 2, 5)


def test_the_derivatives_are_central_differences_of_forward_dynamics_ctrl(arm):
    model, _, call = arm
    worst = 0.0
    for q, qd, u in states(np.random.default_rng(2), 5):
        dq = call("forward_dynamics_ctrl_derivative_q", q, qd, u)
        dqd = call("forward_dynamics_ctrl_derivative_qd", q, qd, u)
        assert dq.shape == dqd.shape == (4, 4)
        worst = max(worst,
                    relative(dq, differences(lambda x: call("forward_dynamics_ctrl", x, qd, u), q)),
                    relative(dqd, differences(lambda x: call("forward_dynamics_ctrl", q, x, u), qd)))
    assert worst <= 1e-6, worst


def test_the_derivatives_are_central_differences_of_mujocos_qacc_smooth(arm):
    model, m, call = arm
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    d = mujoco.MjData(m)

    def qacc(q, qd, u):
        d.qpos[:], d.qvel[:], d.ctrl[:] = q, qd, u
        mujoco.mj_forward(m, d)
        return d.qacc_smooth.copy()

    worst = 0.0
    for q, qd, u in states(np.random.default_rng(5), 4):
        worst = max(worst,
                    relative(call("forward_dynamics_ctrl_derivative_q", q, qd, u),
                             differences(lambda x: qacc(x, qd, u), q)),
                    relative(call("forward_dynamics_ctrl_derivative_qd", q, qd, u),
                             differences(lambda x: qacc(q, x, u), qd)))
    assert worst <= 1e-6, worst


def test_the_combined_function_returns_both(arm):
    _, _, call = arm
    q, qd, u = next(states(np.random.default_rng(9), 1))
    dq, dqd = (call("forward_dynamics_ctrl_derivative_q", q, qd, u),
               call("forward_dynamics_ctrl_derivative_qd", q, qd, u))
    both = call("forward_dynamics_ctrl_derivatives", q, qd, u)
    assert np.array_equal(both[0], dq) and np.array_equal(both[1], dqd)


def test_a_free_flyer_is_differentiated_along_the_tangent(tmp_path):
    model, _ = load(tmp_path, FLYER, "flyer")
    call = generated(model, OUTPUTS[:3], tmp_path, ("numpy",))[0]["numpy"]
    rng = np.random.default_rng(4)
    quaternion = rng.normal(size=4)
    q = np.r_[0.1, -0.2, 0.9, quaternion / np.linalg.norm(quaternion), 0.3, -0.5]
    qd, u = rng.uniform(-1.5, 1.5, 8), np.array([0.4, -0.7])
    h = 1e-6
    along = np.column_stack([
        (call("forward_dynamics_ctrl", integrate(q, h * e, model=model), qd, u)
         - call("forward_dynamics_ctrl", integrate(q, -h * e, model=model), qd, u)) / (2 * h)
        for e in np.eye(8)])
    assert relative(call("forward_dynamics_ctrl_derivative_q", q, qd, u), along) <= 1e-6
    assert relative(call("forward_dynamics_ctrl_derivative_qd", q, qd, u),
                    differences(lambda x: call("forward_dynamics_ctrl", q, x, u), qd)) <= 1e-6


@pytest.mark.slow
def test_every_code_backend_gives_the_numpy_derivatives(tmp_path):
    model, _ = load(tmp_path, ARM, "arm")
    _, modules = generated(model, OUTPUTS[1:], tmp_path)
    q, qd, u = next(states(np.random.default_rng(21), 1))
    reference = {f: results("numpy", modules["numpy"], f, q, qd, u) for f in OUTPUTS[1:]}
    for backend, module in modules.items():
        for f in OUTPUTS[1:]:
            for ours, theirs in zip(results(backend, module, f, q, qd, u), reference[f]):
                assert np.allclose(np.reshape(ours, theirs.shape), theirs, rtol=1e-12,
                                   atol=1e-12), (backend, f)
