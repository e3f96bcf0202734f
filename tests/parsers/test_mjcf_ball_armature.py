"""Armature on a ball joint and on a free joint (MuJoCo's ``armature`` on their degrees of
freedom) in ``forward_dynamics_ctrl``, ``forward_dynamics_act`` and the derivatives of the
first, at nonzero velocity: the ABA's armature multiplies its chart's acceleration, MuJoCo's
the joint's ``v̇`` (they differ by the chart's velocity product ``n(v)``).

References: MuJoCo's ``qacc_smooth`` (contacts off) at the same state and control; central
differences of eomgen's own q̈ along eomgen's ``integrate`` (the tangent) and along ``q̇``; and,
for the ball model, whose velocity map to MuJoCo is constant, central differences of MuJoCo's
``qacc_smooth``. The models carry ball damping and springs, a free joint's armature and
armature on the later joints too.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.model.configuration import integrate
from support import model_states, relative
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import model_from_mujoco  # noqa: E402
from eomgen.parsers.mjcf.convert import (  # noqa: E402
    layout, mujoco_dynamics, to_mujoco, velocity_map)

BALL = """<mujoco model="ballarm"><option><flag contact="disable"/></option><worldbody>
<body pos="0 0 1"><joint name="b1" type="ball" armature="0.05" damping="0.3" stiffness="2"/>
 <geom type="capsule" size=".05" fromto="0 0 0 .4 0 .1"/>
 <body pos=".4 0 .1"><joint name="h1" axis="0 1 0" armature="0.02" damping="0.1"/>
  <geom type="capsule" size=".05" fromto="0 0 0 .3 0 0"/>
  <body pos=".3 0 0"><joint name="b2" type="ball" armature="0.03"/>
   <geom type="box" size=".1 .05 .02" pos=".1 0 0"/></body></body></body></worldbody>
<actuator>ACTUATORS</actuator></mujoco>"""
SERVO = '<position joint="h1" kp="3" kv="0.2"/>'
FILTER = SERVO + '<general joint="h1" dyntype="filter" dynprm="0.3" gainprm="2"/>'

FLYER = """<mujoco model="armflyer"><option><flag contact="disable"/></option><worldbody>
<body pos="0 0 1"><joint name="root" type="free" armature="0.2" damping="0.1"/>
 <inertial pos="0.01 -0.02 0.03" mass="4" fullinertia="0.2 0.3 0.25 0.01 -0.02 0.015"/>
 <body pos=".1 .15 -.1"><joint name="s" type="ball" armature="0.04" damping="0.2"/>
  <geom type="capsule" size=".04" fromto="0 0 0 0 .02 -.4"/>
  <body pos="0 .02 -.4"><joint name="k" axis="1 0 .3" armature="0.05" stiffness="3"/>
   <geom type="capsule" size=".03" fromto="0 0 0 .01 0 -.3"/></body></body></body></worldbody>
<actuator><position joint="k" kp="15" kv="0.5"/></actuator></mujoco>"""

CTRL = ("qdd_ctrl", "dqdd_ctrl_dq", "dqdd_ctrl_dqd")


MODELS = {"ball": (BALL.replace("ACTUATORS", SERVO), CTRL),
          "act": (BALL.replace("ACTUATORS", FILTER), ("xd_act",)),
          "flyer": (FLYER, CTRL)}


@pytest.fixture(scope="module")
def models():
    """``{name: (model, m, module)}`` of the ball arm with a servo, the same with a filter
    actuator (forward_dynamics_act) and the free flyer, each derived when first asked for."""
    class Derived(dict):
        def __missing__(self, name):
            text, outputs = MODELS[name]
            m = mujoco.MjModel.from_xml_string(text)
            model = model_from_mujoco(m, f"{name}.xml")
            self[name] = (model, m, eomgen.derive(model, outputs=outputs).lambdify().module)
            return self[name]
    return Derived()


def mujoco_qacc(m, lay, q, v, ctrl, act=None):
    """MuJoCo's ``qacc_smooth`` at eomgen's state, in eomgen's coordinates: ``T⁻¹ (qacc −
    Ṫ v)``, ``Ṫ v`` the free joint's ``R (ω × v_lin)``; plus, for a free joint's armature
    ``a``, ``M_a⁻¹ a (ω × v_lin)`` on its linear rows (MuJoCo's armature acts on the
    world-frame linear velocity, eomgen's on the body-frame one: the documented difference
    of eomgen.parsers.mjcf.convert, warned by the parser)."""
    data = mujoco.MjData(m)
    data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
    data.ctrl[:] = ctrl
    if act is not None:
        data.act[:] = act
    mujoco.mj_forward(m, data)
    T = velocity_map(lay, data.qpos)
    drift = np.zeros(m.nv)
    out = np.zeros(m.nv)
    if lay.free is not None:
        qa, da = lay.free
        drift[da:da + 3] = T[da:da + 3, 0:3] @ np.cross(v[3:6], v[0:3])
        held = np.zeros(m.nv)
        held[0:3] = m.dof_armature[da] * np.cross(v[3:6], v[0:3])
        out = np.linalg.solve(mujoco_dynamics(m, lay, q, v)["M_a"], held)
    return np.linalg.solve(T, data.qacc_smooth - drift) + out


def tangent_differences(f, model, q, h=1e-6):
    return np.column_stack([(f(integrate(q, h * e, model=model))
                             - f(integrate(q, -h * e, model=model))) / (2 * h)
                            for e in np.eye(model.dof)])


def differences(f, x, h=1e-6):
    return np.column_stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(len(x))])


@pytest.mark.parametrize("name", ["ball", "flyer"])
def test_forward_dynamics_ctrl_is_mujocos_qacc_smooth_in_motion(models, name):
    model, m, module = models[name]
    lay, u = layout(m, model), np.array([0.4])
    for q, v in model_states(model, count=3, seed=2):
        ours = module.forward_dynamics_ctrl(q, 2 * v, u).ravel()
        assert relative(ours, mujoco_qacc(m, lay, q, 2 * v, u)) < 1e-12


def test_forward_dynamics_act_is_mujocos_qacc_smooth_in_motion(models):
    model, m, module = models["act"]
    lay, u, act = layout(m, model), np.array([0.4, -0.8]), np.array([0.7])
    for q, v in model_states(model, count=3, seed=4):
        qdd = module.forward_dynamics_act(q, 2 * v, u, act).ravel()[:model.dof]
        assert relative(qdd, mujoco_qacc(m, lay, q, 2 * v, u, act)) < 1e-12


@pytest.mark.parametrize("name", ["ball", "flyer"])
def test_the_derivatives_are_central_differences_of_forward_dynamics_ctrl(models, name):
    model, _, module = models[name]
    u, worst = np.array([0.4]), 0.0
    for q, v in model_states(model, count=2, seed=5):
        def f(x, y):
            return module.forward_dynamics_ctrl(x, y, u).ravel()
        worst = max(worst,
                    relative(module.forward_dynamics_ctrl_derivative_q(q, v, u),
                             tangent_differences(lambda x: f(x, v), model, q)),
                    relative(module.forward_dynamics_ctrl_derivative_qd(q, v, u),
                             differences(lambda y: f(q, y), v)))
    assert worst < 1e-6, worst


def test_the_derivatives_are_central_differences_of_mujocos_qacc_smooth(models):
    model, m, module = models["ball"]
    lay, u, worst = layout(m, model), np.array([0.4]), 0.0
    for q, v in model_states(model, count=2, seed=6):
        worst = max(worst,
                    relative(module.forward_dynamics_ctrl_derivative_q(q, v, u),
                             tangent_differences(lambda x: mujoco_qacc(m, lay, x, v, u),
                                                 model, q)),
                    relative(module.forward_dynamics_ctrl_derivative_qd(q, v, u),
                             differences(lambda y: mujoco_qacc(m, lay, q, y, u), v)))
    assert worst < 1e-6, worst
