"""Gravity compensation (MuJoCo's body ``gravcomp``, :attr:`eomgen.model.RobotModel.gravcomp`)
in the passive forces ``tau_p`` (eomgen.symbolic.passive): against MuJoCo's ``qfrc_passive``
(plus ``qfrc_actuator`` on a joint with ``actuatorgravcomp``, where MuJoCo routes it) and the
forward dynamics ``M_a⁻¹ (τ_p − h)`` against ``qacc_smooth``, at random states.

The model: a free base with fractional factors (0.5, 1, 0.7) on a hinge chain, a welded body
(0.25, merged into its parent's body: its own factor kept) and a ball joint, a body of two
joints without compensation, one joint with ``actuatorgravcomp``, a motor at rest (MuJoCo adds that joint's compensation to
``qfrc_actuator`` only in a model with actuators).
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedFeatureWarning
from support import model_states, relative
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import compile_mjcf  # noqa: E402
from eomgen.parsers.mjcf.convert import layout, to_mujoco, velocity_map  # noqa: E402
from eomgen.parsers.mjcf.tree import rotation_of_quaternion  # noqa: E402

COMPENSATED = """<mujoco model="gravcomp"><option><flag contact="disable"/></option><worldbody>
<body pos="0 0 1"><freejoint name="root"/><geom size=".2" mass="3"/>
 <body pos=".3 0 0" gravcomp="0.5"><joint name="h1" axis="0 0 1" damping=".2"/>
  <geom type="capsule" size=".05" fromto="0 0 0 .4 0 0"/>
  <body pos=".4 0 0" gravcomp="1"><joint name="h2" axis="0 1 0" stiffness="1.5"/>
   <geom type="capsule" size=".05" fromto="0 0 0 .3 0 .1"/>
   <body name="welded" pos=".3 0 .1" gravcomp="0.25"><geom size=".07" pos=".05 0 0"/></body>
  </body></body>
 <body pos="-.3 0 0"><joint name="s1" type="slide" axis="0 0 1"/>
  <joint name="h3" axis="1 0 0" pos="0 .1 0"/><geom size=".1" pos="0 .05 0"/>
  <body pos="0 0 -.2" gravcomp="0.6"><joint name="h4" axis="0 1 0" actuatorgravcomp="true"/>
   <geom type="capsule" size=".04" fromto="0 0 0 .2 0 -.1"/></body></body>
 <body name="ball" pos="0 .3 0" gravcomp="0.7"><joint name="b1" type="ball" damping="0.3"/>
  <geom type="box" size=".1 .05 .02" pos=".1 .02 0"/></body></body></worldbody>
<actuator><motor name="idle" joint="h1"/></actuator></mujoco>"""


@pytest.fixture(scope="module")
def compensated(tmp_path_factory):
    path = tmp_path_factory.mktemp("gravcomp") / "gravcomp.xml"
    path.write_text(COMPENSATED)
    with pytest.warns(UnsupportedFeatureWarning, match="joint 'h4' actuatorgravcomp: its "
                      "gravity compensation is in tau_p"):
        model = eomgen.load(path)
    m = compile_mjcf(path)
    module = eomgen.derive(model, outputs=("tau_p", "M_a", "h")).lambdify().module
    return model, m, module


def test_the_factors_are_read(compensated):
    model = compensated[0]
    assert dict(model.gravcomp) == {"body2": 0.5, "body3": 1.0, "welded": 0.25, "body6": 0.6,
                                    "ball": 0.7}


def mujoco_state(m, lay, q, v):
    data = mujoco.MjData(m)
    data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
    mujoco.mj_forward(m, data)
    return data


def test_passive_forces_are_mujocos(compensated):
    """τ_p = Tᵀ (qfrc_passive + qfrc_actuator): MuJoCo puts h4's compensation in
    qfrc_actuator (the only actuator's control is 0, so that is all it holds; MuJoCo 4.0
    skips it in a model without actuators)."""
    model, m, module = compensated
    lay = layout(m, model)
    for q, v in model_states(model, count=6):
        data = mujoco_state(m, lay, q, v)
        T = velocity_map(lay, data.qpos)
        assert np.abs(data.qfrc_gravcomp).max() > 1
        expected = T.T @ (data.qfrc_passive + data.qfrc_actuator)
        assert relative(module.passive_forces(q, v).ravel(), expected) < 1e-12


def test_forward_dynamics_is_mujocos(compensated):
    """M_a q̈ = τ_p − h is MuJoCo's qacc_smooth (through the free joint's map, qacc = T v̇ +
    Ṫ v)."""
    model, m, module = compensated
    lay = layout(m, model)
    for q, v in model_states(model, count=4):
        data = mujoco_state(m, lay, q, v)
        qdd = np.linalg.solve(module.drive_mass_matrix(q), module.passive_forces(q, v).ravel()
                              - module.nonlinear_effects(q, v).ravel())
        drift = np.zeros(m.nv)
        qa, da = lay.free
        drift[da:da + 3] = rotation_of_quaternion(data.qpos[qa + 3:qa + 7]) @ np.cross(
            v[3:6], v[0:3])
        T = velocity_map(lay, data.qpos)
        assert relative(T @ qdd + drift, data.qacc_smooth) < 1e-12
