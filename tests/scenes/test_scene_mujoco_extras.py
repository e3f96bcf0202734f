"""A scene on an MJCF model keeps what moves it besides the joints: gravity compensation
(``gravcomp``), fixed tendons and the controls, when it locks joints and merges bodies
(:func:`eomgen.reduction.apply_scene`). Merged links of different ``gravcomp`` factors, and a
payload the compensation does not hold up, are kept exactly (the compensation is linear in
each part's weight and first moment: :func:`eomgen.reduction.inertia.merged_gravcomp`).

Reference: MuJoCo on the same robot written with the locked joint removed (its child body
turned by the lock's angle), the tendon's spring length shortened by the locked joint's share
and the payload a body of its own without ``gravcomp``: ``qfrc_passive`` and ``qacc_smooth``
(contacts off) at random states and controls.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import eomgen
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import model_states, relative
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import model_from_mujoco  # noqa: E402
from eomgen.parsers.mjcf.convert import layout, to_mujoco  # noqa: E402

LOCK = 0.4  # rad, j2's position in the scene

ROBOT = """<mujoco model="held"><compiler angle="radian"/><option><flag contact="disable"/>
</option><worldbody>
<body name="a" gravcomp="1"><joint name="j1" axis="0 1 0.2" damping="0.1"/>
 <geom type="capsule" size=".04" fromto="0 0 0 .4 0 0" mass="1"/>
 <body name="w" pos=".4 0 0" gravcomp="0.5"><geom type="box" size=".05 .05 .05" pos=".05 0 .1"
   mass=".4"/></body>
 <body name="b" pos=".4 0 0" gravcomp="0.8" B_POSE>J2
  <geom type="capsule" size=".03" fromto="0 0 0 .3 0 .1" mass=".6"/>
  <body name="c" pos=".3 0 .1" gravcomp="1"><joint name="j3" axis="1 0 0" armature="0.01"/>
   <geom type="capsule" size=".02" fromto="0 0 0 0 .2 0" mass=".2"/>PAYLOAD</body></body></body>
</worldbody>
<tendon><fixed name="t" stiffness="3" damping="0.2"><joint joint="j1" coef="1"/>
  <joint joint="j3" coef="-0.5"/></fixed>
 <fixed name="s" stiffness="2" springlength="SPRING">T2</fixed></tendon>
<actuator>MOTOR<position name="p" tendon="t" kp="4" kv="0.3"/>
 <motor name="m3" joint="j3" gear="2"/></actuator></mujoco>"""
WHOLE = {"B_POSE": "", "J2": '<joint name="j2" axis="0 1 0"/>', "PAYLOAD": "",
         "SPRING": "0.1", "T2": '<joint joint="j1" coef="1"/><joint joint="j2" coef="0.7"/>',
         "MOTOR": '<motor name="m2" joint="j2"/>'}
HELD = {"B_POSE": f'axisangle="0 1 0 {LOCK}"', "J2": "",
        "PAYLOAD": '<body name="box"><inertial pos="0.05 0 0.02" mass="0.3" '
                   'diaginertia="0.001 0.002 0.003"/></body>',
        "SPRING": f"{0.1 - 0.7 * LOCK}", "T2": '<joint joint="j1" coef="1"/>', "MOTOR": ""}
SCENE = f"""version: 1
locked: {{j2: {LOCK}}}
payloads:
  - link: c
    name: box
    mass: 0.3
    com: [0.05, 0, 0.02]
    inertia: {{ixx: 0.001, iyy: 0.002, izz: 0.003}}
"""


def mjcf(values: dict) -> str:
    text = ROBOT
    for key, value in values.items():
        text = text.replace(key, value)
    return text


@pytest.fixture(scope="module")
def held(tmp_path_factory):
    """``(reduced model, its module, MuJoCo's model of the held robot)``."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        whole = model_from_mujoco(mujoco.MjModel.from_xml_string(mjcf(WHOLE)), "held.xml")
    scene = load_scene(tmp_path_factory.mktemp("scene") / "held.yaml", text=SCENE)
    reduced = apply_scene(whole, scene).model
    module = eomgen.derive(reduced, outputs=("tau_p", "qdd_ctrl")).lambdify().module
    return reduced, module, mujoco.MjModel.from_xml_string(mjcf(HELD))


def test_the_scene_keeps_the_tendons_controls_and_compensation(held):
    reduced = held[0]
    assert reduced.joint_names == ("j1", "j3")
    assert [t.name for t in reduced.tendons] == ["t", "s"]
    assert [c.name for c in reduced.controls] == ["m2", "p", "m3"]
    factors = {entry[0]: len(entry) for entry in reduced.gravcomp}
    assert factors == {"a": 3, "c": 3}  # both merged of several factors


def test_passive_forces_and_accelerations_are_mujocos(held):
    reduced, module, m = held
    lay, data = layout(m, reduced), mujoco.MjData(m)
    rng = np.random.default_rng(3)
    for q, v in model_states(reduced, count=4, seed=5):
        u = rng.uniform(-2, 2, 3)
        data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
        data.ctrl[:] = u[1:]  # m2 drives the locked j2: no force, not in the held model
        mujoco.mj_forward(m, data)
        assert np.abs(data.qfrc_gravcomp).max() > 0.5
        assert relative(module.passive_forces(q, v).ravel(), data.qfrc_passive) < 1e-12
        assert relative(module.forward_dynamics_ctrl(q, v, u).ravel(), data.qacc_smooth) < 1e-12
