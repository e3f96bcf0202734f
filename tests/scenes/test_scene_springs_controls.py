"""A scene's ``springs:`` and ``controls:`` (issue 41: springs and actuators described in YAML
and in scenes the same way): the robot with them set by a scene equals the robot whose YAML
description holds them (passive forces, actuator forces, forward dynamics with controls) at
random states; wrong entries are refused in one line naming the scene entry."""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.errors import SceneError
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import relative, write

ROBOT = """name: arm
links:
  - {{name: base}}
  - {{name: l1, mass: 1, com: [0.3, 0, 0], inertia: {{ixx: 0.1, iyy: 0.2, izz: 0.3}}}}
  - {{name: l2, mass: 2, com: [0.2, 0, 0.1], inertia: {{ixx: 0.2, iyy: 0.1, izz: 0.3}}}}
  - {{name: l3, mass: 0.5, com: [0.1, 0, 0], inertia: {{ixx: 0.01, iyy: 0.02, izz: 0.02}}}}
joints:
  - {{name: hip, type: spherical, parent: base, child: l1{hip}}}
  - {{name: knee, type: revolute, parent: l1, child: l2, origin: {{xyz: [0.6, 0, 0]}},
      axis: [0, 1, 0]{knee}}}
  - {{name: slide, type: prismatic, parent: l2, child: l3, origin: {{xyz: [0.4, 0, 0]}},
      axis: [1, 0, 0]}}
{controls}"""

HIP = ", spring: {stiffness: 1.5, reference: [0.1, 0.2, -0.1, 0.9]}"
KNEE = ", spring: {stiffness: 2.0, reference: 0.3}"
CONTROLS = """controls:
  - {name: knee_servo, joint: knee, gain: [10, 0, 0], bias: [0, -10, -1], ctrlrange: [-1, 1]}
  - {name: pull, tendon: {knee: 0.5, slide: -1}, gear: 2}
"""
SCENE = """version: 1
springs:
  hip: {stiffness: 1.5, reference: [0.1, 0.2, -0.1, 0.9]}
  knee: {stiffness: 2.0, reference: 0.3}
""" + CONTROLS

OUTPUTS = ("tau_p", "tau_act", "qdd_ctrl")


@pytest.fixture(scope="module")
def modules(tmp_path_factory):
    """The NumPy modules of the robot described with its springs and controls, and of the bare
    robot with them set by a scene."""
    folder = tmp_path_factory.mktemp("arm")
    described = eomgen.load(write(folder / "described.yaml",
                                  ROBOT.format(hip=HIP, knee=KNEE, controls=CONTROLS)))
    bare = eomgen.load(write(folder / "bare.yaml", ROBOT.format(hip="", knee="", controls="")))
    scened, _ = apply_scene(bare, load_scene(folder / "scene.yaml", text=SCENE))
    return [eomgen.derive(m, outputs=OUTPUTS).lambdify().module for m in (described, scened)]


def test_a_scene_sets_springs_and_controls_as_the_description_would(modules):
    described, scened = modules
    assert scened.ACTUATOR_NAMES == described.ACTUATOR_NAMES == ("knee_servo", "pull")
    rng = np.random.default_rng(3)
    for _ in range(4):
        quaternion = rng.normal(size=4)
        q = np.concatenate([quaternion / np.linalg.norm(quaternion), rng.normal(size=2)])
        v, ctrl = rng.normal(size=5), rng.uniform(-2, 2, size=2)
        for name, args in (("passive_forces", (q, v)), ("actuator_forces", (q, v, ctrl)),
                           ("forward_dynamics_ctrl", (q, v, ctrl))):
            expected = getattr(described, name)(*args)
            assert np.any(expected != 0)
            assert relative(getattr(scened, name)(*args), expected) < 1e-13, name


@pytest.mark.parametrize("entries, where, problem", [
    ("springs: {elbow: {stiffness: 1}}", "springs 'elbow'", "no joint 'elbow'"),
    ("springs: {knee: {stiffness: 1, reference: [0, 0, 0, 1]}}", "springs 'knee'",
     "not a quaternion"),
    ("springs: {hip: {stiffness: 1, reference: 0.2}}", "springs 'hip'", "is a quaternion"),
    ("springs: {knee: {stiffness: k}}\nparameters: {k: 1}", "springs 'knee'",
     "take numbers, not parameters"),
    ("springs: {knee: {stiffness: -1}}", "springs 'knee' stiffness", "negative stiffness"),
    ("springs: {hip_wy: {stiffness: 1}}", "springs 'hip_wy'", "a coordinate of joint 'hip'"),
    ("controls: [{name: c, joint: hip_wx}]", "controls 'c'", "a coordinate of joint 'hip'"),
    ("controls: [{name: c, tendon: {knee: 1, ankle: 1}}]", "controls 'c'", "no joint 'ankle'"),
])
def test_a_wrong_spring_or_control_is_refused_naming_the_entry(tmp_path, entries, where,
                                                                problem):
    bare = eomgen.load(write(tmp_path / "bare.yaml", ROBOT.format(hip="", knee="",
                                                                   controls="")))
    with pytest.raises(SceneError) as raised:
        apply_scene(bare, load_scene(tmp_path / "scene.yaml", text="version: 1\n" + entries))
    message = str(raised.value)
    assert "scene.yaml" in message and where in message and problem in message, message
    assert "\n" not in message


def test_a_control_named_like_the_descriptions_is_refused(tmp_path):
    described = eomgen.load(write(tmp_path / "described.yaml",
                                  ROBOT.format(hip="", knee="", controls=CONTROLS)))
    with pytest.raises(SceneError, match="controls 'pull'.*has a control of this name"):
        apply_scene(described, load_scene(tmp_path / "scene.yaml",
                                          text="version: 1\ncontrols: [{name: pull, joint: knee}]"))
