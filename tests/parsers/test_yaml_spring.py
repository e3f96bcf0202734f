"""A YAML joint's ``spring: {stiffness, reference}`` (eomgen.model.Spring): read, in
``passive_forces`` as −k (q − q_ref) − d q̇, refused in one line where it makes no sense."""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedError
from support import write
from support.extras import need

ROBOT = """name: two
links:
  - {{name: base}}
  - {{name: l1, mass: 1, com: [0.5, 0, 0], inertia: {{ixx: 0.1, iyy: 0.1, izz: 0.1}}}}
  - {{name: l2, mass: 2, com: [0.2, 0, 0], inertia: {{ixx: 0.1, iyy: 0.1, izz: 0.1}}}}
joints:
  - {{name: j1, type: revolute, parent: base, child: l1, axis: [0, 1, 0], {spring}}}
  - {{name: j2, type: prismatic, parent: l1, child: l2, spring: {{stiffness: 5}},
      actuator: {{damping: 0.5}}}}
"""


def test_the_spring_is_in_the_passive_forces(tmp_path):
    path = write(tmp_path / "two.yaml", ROBOT.format(
        spring="spring: {stiffness: 2, reference: 0.3}"))
    module = eomgen.derive(eomgen.load(path), outputs=("tau_p",)).lambdify().module
    rng = np.random.default_rng(1)
    for _ in range(3):
        q, v = rng.normal(size=2), rng.normal(size=2)
        expected = [-2 * (q[0] - 0.3), -5 * q[1] - 0.5 * v[1]]
        assert np.allclose(module.passive_forces(q, v).ravel(), expected, rtol=1e-14)


@pytest.mark.parametrize("spring, problem", [
    ("spring: {stiffness: -1}", "spring stiffness: a negative stiffness"),
    ("spring: {reference: 1}", "spring"),
    ("spring: {stiffness: 1, ref: 0}", "spring"),
])
def test_a_wrong_spring_is_refused_by_name(tmp_path, spring, problem):
    path = write(tmp_path / "two.yaml", ROBOT.format(spring=spring))
    with pytest.raises((UnsupportedError, eomgen.errors.DescriptionError)) as raised:
        eomgen.load(path)
    message = str(raised.value)
    assert "joints[0] 'j1' spring" in message and problem in message and "\n" not in message


BALL = """name: ball
links:
  - {{name: base}}
  - {{name: l1, mass: 1, com: [0.3, 0, 0], inertia: {{ixx: 0.1, iyy: 0.2, izz: 0.3}}}}
joints:
  - {{name: b, type: spherical, parent: base, child: l1, {spring}}}
"""


REST = np.array([0.3, -0.2, 0.5, 0.8]) / np.linalg.norm([0.3, -0.2, 0.5, 0.8])


@pytest.fixture(scope="module")
def ball_module(tmp_path_factory):
    """The spherical joint's module (``passive_forces``) with ``spring: {stiffness: 2.5,
    reference: [0.3, -0.2, 0.5, 0.8]}``, and four random unit quaternions."""
    path = write(tmp_path_factory.mktemp("ball") / "ball.yaml", BALL.format(
        spring="spring: {stiffness: 2.5, reference: [0.3, -0.2, 0.5, 0.8]}"))
    module = eomgen.derive(eomgen.load(path), outputs=("tau_p",)).lambdify().module
    rng = np.random.default_rng(4)
    return module, [q / np.linalg.norm(q) for q in rng.normal(size=(4, 4))]


def test_a_spherical_joint_spring_is_minus_k_times_the_rotation_vector(ball_module):
    """``spring: {stiffness, reference: [x, y, z, w]}`` on a spherical joint: the torque on its
    angular velocity coordinates is −k log(R_ref⁻¹ R), the rotation vector (child frame) of the
    rotation from the rest pose, here taken by the matrix logarithm (the module takes it from
    the quaternions)."""
    from eomgen.model.joints.lie import quaternion_matrix, so3_log

    module, quaternions = ball_module
    for q in quaternions:
        expected = -2.5 * np.asarray(so3_log(quaternion_matrix(REST).T @ quaternion_matrix(q)),
                                     dtype=float)
        got = module.passive_forces(q, np.zeros(3)).ravel()
        assert np.allclose(got, expected, rtol=1e-12, atol=1e-12)


def test_a_spherical_joint_spring_equals_mujocos(ball_module):
    """The same spring in MuJoCo (a ball joint's ``stiffness``, ``qpos_spring`` the rest
    quaternion in MuJoCo's (w, x, y, z) order): ``qfrc_passive``."""
    mujoco = need("mujoco")
    module, quaternions = ball_module
    m = mujoco.MjModel.from_xml_string(
        '<mujoco><option><flag gravity="disable"/></option><worldbody><body>'
        '<joint type="ball" stiffness="2.5"/><geom size=".1"/></body></worldbody></mujoco>')
    m.qpos_spring[:] = [REST[3], *REST[:3]]
    d = mujoco.MjData(m)
    for q in quaternions:
        d.qpos[:] = [q[3], *q[:3]]
        mujoco.mj_forward(m, d)
        assert np.allclose(module.passive_forces(q, np.zeros(3)).ravel(), d.qfrc_passive,
                           rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("reference, problem", [
    ("[0, 0, 1]", "quaternion [x, y, z, w], got 3 entries"),
    ("[0, 0, 0, 0]", "norm 0"),
])
def test_a_wrong_ball_spring_reference_is_refused_by_name(tmp_path, reference, problem):
    path = write(tmp_path / "ball.yaml", BALL.format(
        spring=f"spring: {{stiffness: 1, reference: {reference}}}"))
    with pytest.raises(UnsupportedError) as raised:
        eomgen.load(path)
    message = str(raised.value)
    assert "joints[0] 'b' spring reference" in message and problem in message
    assert "\n" not in message
