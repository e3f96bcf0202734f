"""Scenes that lock a ball or planar joint (a compound joint: a chart of virtual joints in the
tree, :mod:`eomgen.model.joints`) at a configuration, and models whose ball joint lies outside
the moving part.

The reduced model's inverse dynamics must equal the whole robot's with the compound joint held
at that configuration (its velocity and acceleration zero): the float Newton–Euler reference
(:mod:`eomgen.numeric`) on both models, the whole one walking its chart, at random states.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.errors import SceneError
from eomgen.numeric import numeric_model, rnea
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene

ROBOT = """\
name: slider
links:
  - name: base
  - name: puck
    mass: 1.3
    com: [0.1, -0.05, 0.02]
    inertia: {ixx: 0.02, iyy: 0.03, izz: 0.04, ixy: 0.001}
  - name: arm
    mass: 0.7
    com: [0.2, 0, 0.1]
    inertia: {ixx: 0.01, iyy: 0.02, izz: 0.02}
joints:
  - name: hip
    type: KIND
    parent: base
    child: puck
    origin: {xyz: [0, 0, 0.1], rpy: [0.3, 0.2, 0.1]}
  - name: elbow
    type: revolute
    parent: puck
    child: arm
    origin: {xyz: [0.3, 0, 0]}
    axis: [0, 1, 0]
"""
#: A configuration of each kind, deliberately not normalised (the kind normalises it).
LOCKED = {"spherical": [0.1, 0.2, 0.3, 0.9], "planar": [0.2, -0.1, 0.6, 0.8]}


def robot(tmp_path, kind):
    path = tmp_path / f"{kind}.yaml"
    path.write_text(ROBOT.replace("KIND", kind))
    return eomgen.load(path)


def scene(tmp_path, text):
    path = tmp_path / "scene.yaml"
    path.write_text("version: 1\n" + text)
    return load_scene(path)


@pytest.mark.parametrize("kind", ["spherical", "planar"])
def test_a_locked_compound_joint_holds_its_configuration(tmp_path, kind):
    whole = robot(tmp_path, kind)
    values = LOCKED[kind]
    reduced = apply_scene(whole, scene(tmp_path, f"locked:\n  hip: {values}\n"))
    assert reduced.model.joint_names == ("elbow",) and reduced.model.nq == 1
    assert reduced.model.compound_joints == ()
    assert [(j.name, j.position, j.listed) for j in reduced.report.locked] == [
        ("hip", tuple(values), True)]
    assert "`hip` at (" in reduced.report.markdown()
    full, small = numeric_model(whole), numeric_model(reduced.model)
    rng = np.random.default_rng(3)
    chart = whole.quaternion_joints[0]
    for _ in range(3):
        x, xd, xdd = rng.normal(size=3)
        q = np.concatenate([values, [x]])
        expected = rnea(full, q, np.r_[np.zeros(chart.nv), xd], np.r_[np.zeros(chart.nv), xdd])
        got = rnea(small, [x], [xd], [xdd])
        assert abs(got[0] - expected[-1]) <= 1e-12 * max(1.0, abs(expected[-1]))
        # and the held joint's rows are not trivially zero: the lock carries real load
        assert np.linalg.norm(expected[:chart.nv]) > 1e-3


def test_a_ball_joint_outside_the_moving_part_is_held_at_its_neutral_configuration(tmp_path):
    whole = robot(tmp_path, "spherical")
    reduced = apply_scene(whole, scene(tmp_path, "base: puck\n"))
    assert reduced.model.joint_names == ("elbow",)
    assert [(j.name, j.position, j.listed) for j in reduced.report.locked] == [
        ("hip", (0.0, 0.0, 0.0, 1.0), False)]
    full, small = numeric_model(whole), numeric_model(reduced.model)
    q = np.array([0.0, 0.0, 0.0, 1.0, 0.7])
    expected = rnea(full, q, np.r_[0, 0, 0, 0.4], np.r_[0, 0, 0, -0.2])
    got = rnea(small, [0.7], [0.4], [-0.2])  # rooted at the puck, gravity in its frame
    assert reduced.model.compound_joints == ()
    assert abs(got[0] - expected[-1]) <= 1e-12 * max(1.0, abs(expected[-1]))


@pytest.mark.parametrize("text, element, problem", [
    ("locked:\n  hip_wy: 0.2\n", "locked 'hip_wy'",
     "a virtual joint of ball joint 'hip': lock 'hip' at its configuration [hip_qx, hip_qy, "
     "hip_qz, hip_qw]"),
    ("locked:\n  hip: 0.2\n", "locked 'hip'",
     "a ball joint is locked at its 4 configuration entries: [hip_qx, hip_qy, hip_qz, hip_qw]"),
    ("locked:\n  hip: [0, 0, 1]\n", "locked 'hip'", "4 configuration entries"),
    ("locked:\n  elbow: [0, 1]\n", "locked 'elbow'", "expected a number [rad or m]"),
])
def test_bad_locks_of_a_ball_joint_are_one_line_errors(tmp_path, text, element, problem):
    whole = robot(tmp_path, "spherical")
    with pytest.raises(SceneError) as error:
        apply_scene(whole, scene(tmp_path, text))
    message = str(error.value)
    assert "\n" not in message and element in message and problem in message


def test_a_locked_free_flyer_bolts_the_robot_at_its_pose(tmp_path):
    """``locked: {base: [x, y, z, qx, qy, qz, qw]}`` on a robot with Pinocchio's free flyer:
    the robot is held at that pose of its root. Its inverse dynamics equal the floating
    robot's rows of the other joints with the free flyer at rest at that pose, and the base
    rows carry the load (gravity turned by the pose: it is not the fixed robot's)."""
    from eomgen.model.floating import add_free_flyer

    whole = add_free_flyer(robot(tmp_path, "spherical"))
    values = [0.3, -0.2, 0.5, 0.2, -0.1, 0.4, 0.9]
    reduced = apply_scene(whole, scene(tmp_path, f"locked:\n  base: {values}\n"))
    model = reduced.model
    assert not model.free_flyer and model.joint_names == ("hip_wx", "hip_wy", "hip_wz", "elbow")
    assert model.compound_joints == (("spherical", "hip"),)
    full, small = numeric_model(whole), numeric_model(model)
    upright = numeric_model(robot(tmp_path, "spherical"))  # bolted at the identity
    rng = np.random.default_rng(5)
    for _ in range(3):
        hip = rng.normal(size=4)
        hip /= np.linalg.norm(hip)
        x, v, a = np.r_[hip, rng.normal()], rng.normal(size=4), rng.normal(size=4)
        q = np.concatenate([values, x])
        expected = rnea(full, q, np.r_[np.zeros(6), v], np.r_[np.zeros(6), a])
        got = rnea(small, x, v, a)
        assert np.allclose(got, expected[6:], rtol=1e-12, atol=1e-12)
        assert np.linalg.norm(expected[:6]) > 1e-3
        assert not np.allclose(got, rnea(upright, x, v, a), atol=1e-6)  # the pose matters


def test_a_virtual_joint_of_the_free_flyer_is_not_locked_alone(tmp_path):
    from eomgen.model.floating import add_free_flyer

    whole = add_free_flyer(robot(tmp_path, "planar"))
    with pytest.raises(SceneError, match="locked 'base_wz': a virtual joint of free flyer "
                                         "joint 'base': lock 'base' at its configuration"):
        apply_scene(whole, scene(tmp_path, "locked:\n  base_wz: 0.1\n"))
