"""The URDF reader: real robots against Pinocchio, hand-written cases, and bad input.

Frames are checked independently of eomgen's own kinematics: a small NumPy forward kinematics
below composes ``origin · motion(axis, q)`` from the parsed numbers and is compared with
Pinocchio's ``oMf`` of the frame of the same name. Pinocchio merges bodies joined by fixed
joints, so masses and inertias are compared as sums over the whole robot (total mass, first
moment and rotational inertia about the world origin, at random configurations).
"""

from __future__ import annotations

import math
import time
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import eomgen
from support.robots import INERTIA, joint, legged, link, robot
from support import ROOT
from eomgen.errors import (
    DescriptionError,
    PhysicalConsistencyWarning,
    UnsupportedError,
    UnsupportedFeatureWarning,
)
from eomgen.model import JointType, Notice, NoticeKind, RobotModel, Transform, emit_notices
from eomgen.parsers.legged import LEG_REACH
from eomgen.parsers.urdf import load_urdf, parse_urdf_string, rotate_inertia
from eomgen.reduction import load_for_scene
from eomgen.scene import Scene
from support.extras import need

#: Arms of example-robot-data (paths below its robots/ folder) and whether they use <mimic>.
ARMS = [
    ("ur_description/urdf/ur3_robot.urdf", False),
    ("ur_description/urdf/ur5_robot.urdf", False),
    ("ur_description/urdf/ur10_robot.urdf", False),
    ("panda_description/urdf/panda.urdf", True),
    ("kinova_description/robots/kinova.urdf", False),
    ("xarm_description/urdf/xarm7.urdf", False),
    ("so_arm_description/urdf/so100.urdf", False),
    ("z1_description/urdf/z1.urdf", False),
    ("double_pendulum_description/urdf/double_pendulum.urdf", False),
    ("double_pendulum_description/urdf/double_pendulum_continuous.urdf", False),
    ("double_pendulum_description/urdf/double_pendulum_simple.urdf", False),
]
#: Branched robots (no floating joint in the file; the root link is the fixed base).
TREES = [
    ("talos_data/robots/talos_reduced.urdf", False),  # <mimic> on fixed joints only
    ("talos_data/robots/talos_full_v2.urdf", True),
    ("simple_humanoid_description/urdf/simple_humanoid.urdf", False),
]
TOL = 1e-10


@pytest.fixture(scope="module")
def pin():
    return need("pinocchio")


# ----------------------------------------------------------------------------------------------
# Independent numeric kinematics and mass sums from a RobotModel
# ----------------------------------------------------------------------------------------------

def homogeneous(transform: Transform) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = [[float(x) for x in row] for row in transform.rotation]
    T[:3, 3] = [float(x) for x in transform.translation]
    return T


def motion(joint_type: JointType, axis: np.ndarray, q: float) -> np.ndarray:
    """Child frame in the joint frame: rotation by q about axis (Rodrigues) or translation."""
    T = np.eye(4)
    if joint_type.is_revolute:
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        T[:3, :3] = np.eye(3) + math.sin(q) * K + (1 - math.cos(q)) * K @ K
    elif joint_type is JointType.PRISMATIC:
        T[:3, 3] = q * axis
    return T


def link_poses(model: RobotModel, q: dict[str, float]) -> dict[str, np.ndarray]:
    """World (root link) pose of every link frame; ``q`` maps movable joint names to values."""
    poses = {model.root: np.eye(4)}
    pending = list(model.joints)
    while pending:  # any order in which a parent's pose is known first
        ready = [j for j in pending if j.parent in poses]
        assert ready, "joints do not form a tree below the root"
        for joint in ready:
            axis = np.array([float(a) for a in joint.axis])
            poses[joint.child] = (poses[joint.parent] @ homogeneous(joint.origin)
                                  @ motion(joint.type, axis, q.get(joint.name, 0.0)))
            pending.remove(joint)
    return poses


def mass_sums(bodies) -> tuple[float, np.ndarray, np.ndarray]:
    """Total mass, first moment Σ m c and rotational inertia about the world origin of
    bodies given as (mass, world COM, inertia about the COM in world axes)."""
    mass, first, second = 0.0, np.zeros(3), np.zeros((3, 3))
    for m, c, I_c in bodies:
        mass += m
        first += m * c
        second += I_c + m * (c @ c * np.eye(3) - np.outer(c, c))
    return mass, first, second


def our_bodies(model: RobotModel, poses: dict[str, np.ndarray]):
    for link in model.links:
        if link.inertial is None:
            continue
        R, p = poses[link.name][:3, :3], poses[link.name][:3, 3]
        c = R @ np.array([float(x) for x in link.inertial.com]) + p
        I_c = np.array([[float(x) for x in row] for row in link.inertial.inertia])
        yield float(link.inertial.mass), c, R @ I_c @ R.T


def pin_bodies(pmodel, pdata):
    for i in range(pmodel.njoints):
        Y = pdata.oMi[i].act(pmodel.inertias[i])
        yield Y.mass, np.array(Y.lever), np.array(Y.inertia)


def pin_configuration(pin, pmodel, q: dict[str, float]) -> np.ndarray:
    """Pinocchio's q for joint values by name (continuous joints are stored as cos, sin)."""
    x = pin.neutral(pmodel)
    for name, value in q.items():
        joint = pmodel.joints[pmodel.getJointId(name)]
        if joint.nq == 2:
            x[joint.idx_q:joint.idx_q + 2] = (math.cos(value), math.sin(value))
        else:
            x[joint.idx_q] = value
    return x


def compare_with_pinocchio(pin, model: RobotModel, pmodel, seed: int = 0) -> None:
    """Joint set, frames of every link and mass sums agree at random configurations."""
    assert sorted(pmodel.names[1:]) == sorted(model.joint_names)
    assert pmodel.nv == model.dof
    pdata = pmodel.createData()
    rng = np.random.default_rng(seed)
    for _ in range(3):
        q = {name: float(rng.uniform(-math.pi, math.pi)) for name in model.joint_names}
        poses = link_poses(model, q)
        pin.framesForwardKinematics(pmodel, pdata, pin_configuration(pin, pmodel, q))
        assert set(poses) == {link.name for link in model.links}
        for name, pose in poses.items():
            frame = pmodel.getFrameId(name, pin.FrameType.BODY)
            assert frame < len(pmodel.frames), f"Pinocchio has no frame {name!r}"
            np.testing.assert_allclose(pose, pdata.oMf[frame].homogeneous, rtol=0, atol=TOL,
                                       err_msg=f"frame of link {name!r}")
        ours, theirs = mass_sums(our_bodies(model, poses)), mass_sums(pin_bodies(pmodel, pdata))
        for a, b in zip(ours, theirs):
            np.testing.assert_allclose(a, b, rtol=1e-12, atol=TOL)


def document_joint_order(path: Path) -> list[str]:
    """Movable joint names in the order the file lists them (read with the standard library)."""
    root = ET.parse(path).getroot()
    return [j.get("name") for j in root.findall("joint") if j.get("type") != "fixed"]


# ----------------------------------------------------------------------------------------------
# example-robot-data against Pinocchio
# ----------------------------------------------------------------------------------------------

def load_expecting_mimic_warnings(path: Path, has_mimic: bool) -> RobotModel:
    """``eomgen.load(path, couplings=False)`` (every joint a coordinate, as Pinocchio's
    default ``buildModelFromUrdf``), checking that mimic warnings come exactly when the file
    has mimics (a humanoid's floating-base warning is tested on its own)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = eomgen.load(path, couplings=False)
    mimics = [w for w in caught if issubclass(w.category, UnsupportedFeatureWarning)
              and "<mimic>" in str(w.message)]
    assert bool(mimics) == has_mimic, [str(w.message) for w in caught]
    return model


@pytest.mark.parametrize("relative, has_mimic", ARMS, ids=[Path(a).stem for a, _ in ARMS])
def test_arm_matches_pinocchio(erd_robots_dir, pin, relative, has_mimic):
    path = erd_robots_dir / relative
    model = load_expecting_mimic_warnings(path, has_mimic)
    pmodel = pin.buildModelFromUrdf(str(path))
    assert list(model.joint_names) == document_joint_order(path)
    assert list(model.joint_names) == list(pmodel.names[1:])  # a chain: same order as Pinocchio
    assert [float(g) for g in model.gravity] == [0.0, 0.0, -9.81]
    compare_with_pinocchio(pin, model, pmodel)


@pytest.mark.parametrize("relative, has_mimic", TREES, ids=[Path(a).stem for a, _ in TREES])
def test_tree_matches_pinocchio(erd_robots_dir, pin, relative, has_mimic):
    path = erd_robots_dir / relative
    model = load_expecting_mimic_warnings(path, has_mimic)
    assert list(model.joint_names) == document_joint_order(path)
    compare_with_pinocchio(pin, model, pin.buildModelFromUrdf(str(path)))


MIMICS = [
    ("panda_description/urdf/panda.urdf", "panda_finger_joint2", "panda_finger_joint1"),
    ("talos_data/robots/talos_full_v2.urdf", "gripper_left_inner_double_joint",
     "gripper_left_joint"),
]


@pytest.mark.parametrize("relative, joint, mimicked", MIMICS, ids=["panda", "talos"])
def test_mimic_joints_are_independent_with_a_warning(erd_robots_dir, pin, relative, joint,
                                                     mimicked):
    """With couplings=False a mimic joint is an ordinary joint (as in Pinocchio's default)
    and each one warns, on one line naming the file and the joint."""
    path = erd_robots_dir / relative
    with pytest.warns(UnsupportedFeatureWarning) as record:
        model = eomgen.load(path, couplings=False)
    messages = [str(w.message) for w in record
                if issubclass(w.category, UnsupportedFeatureWarning)
                and "root link" not in str(w.message)]  # Talos' floating base: tested below
    expected = (f"{path}: joint '{joint}' <mimic>: the coupling to joint '{mimicked}' is not "
                "modelled; read as an independent joint (couplings=False)")
    assert expected in messages
    assert all(len(m.splitlines()) == 1 and m.startswith(f"{path}: joint '") for m in messages)
    mimic_joints = [j.get("name") for j in ET.parse(path).getroot().iter("joint")
                    if j.find("mimic") is not None and j.get("type") != "fixed"]
    assert len(messages) == len(mimic_joints)  # one warning per mimic joint
    assert set(mimic_joints) <= set(model.joint_names)
    assert model.dof == pin.buildModelFromUrdf(str(path)).nv


@pytest.mark.parametrize("relative, joint, mimicked", MIMICS, ids=["panda", "talos"])
def test_mimic_joints_are_honoured_by_default(erd_robots_dir, pin, relative, joint, mimicked):
    """By default (even under strict) a mimic joint follows its leader: no coordinate, no
    warning, the coordinates of Pinocchio's buildModelFromUrdf(path, mimic=True)."""
    path = erd_robots_dir / relative
    fixed = Scene(fixed_base=True)  # Talos' floating base, else refused first, is meant
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnsupportedFeatureWarning)
        model = load_for_scene(path, fixed, strict=True)
    assert joint not in model.joint_names and mimicked in model.joint_names
    followers = [j.get("name") for j in ET.parse(path).getroot().iter("joint")
                 if j.find("mimic") is not None and j.get("type") != "fixed"]
    assert model.dof == pin.buildModelFromUrdf(str(path)).nv - len(followers)
    assert {c.follower for c in model.couplings} == set(followers)


def test_robot_name_and_massless_links(erd_robots_dir):
    model = eomgen.load(erd_robots_dir / "ur_description/urdf/ur5_robot.urdf")
    assert model.name == "ur5"
    assert model.root == "world"
    assert model.link_by_name["world"].inertial is None
    assert model.link_by_name["base_link"].inertial.mass == sp.Integer(4)
    assert model.source == str(erd_robots_dir / "ur_description/urdf/ur5_robot.urdf")


# ----------------------------------------------------------------------------------------------
# Hand-written URDFs
# ----------------------------------------------------------------------------------------------

#: Joint limits: ignored by eomgen, required by urdfdom (Pinocchio) for revolute and prismatic.
LIMIT = '<limit lower="-3" upper="3" effort="1" velocity="1"/>'
#: A branched robot with every feature Pinocchio must agree on: rotated inertial frames, joint
#: origins with rpy, an unaligned unit axis, prismatic, continuous and fixed joints, a massless
#: link, and a document order that is not the depth-first order.
FEATURES = robot(
    link("base", None),
    link("a", '<inertial><origin xyz="0.1 -0.2 0.3" rpy="0.3 -0.7 1.1"/><mass value="2.5"/>'
              '<inertia ixx="0.4" ixy="0.01" ixz="-0.02" iyy="0.5" iyz="0.03" izz="0.6"/>'
              "</inertial>"),
    link("b", '<inertial><origin xyz="0 0.05 0" rpy="1.5707963267948966 0 0"/>'
              '<mass value="1.5"/>'
              '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.25"/></inertial>'),
    link("c"),
    link("tool", '<inertial><origin xyz="0.01 0.02 0.03" rpy="-0.4 0.2 2.9"/><mass value="0.3"/>'
                 '<inertia ixx="0.003" ixy="0.0001" ixz="0" iyy="0.004" iyz="0" izz="0.005"/>'
                 "</inertial>"),
    link("sensor", None),
    joint("j_side", "base", "c", "prismatic",
          '<origin xyz="0 0.4 0.1" rpy="0 0.5 0"/><axis xyz="0.6 0 0.8"/>' + LIMIT),
    joint("j1", "base", "a", "revolute", '<origin xyz="0 0 0.2" rpy="0.1 0.2 0.3"/>'
                                          '<axis xyz="0 0 1"/>' + LIMIT),
    joint("j2", "a", "b", "continuous", '<origin xyz="0.3 0 0" rpy="0 0 -1.2"/>'),
    joint("mount", "b", "tool", "fixed", '<origin xyz="0 0 0.1" rpy="3.0 0.1 -0.2"/>'),
    joint("j3", "c", "sensor", "revolute", '<origin xyz="0.05 0 0"/><axis xyz="0 -1 0"/>' + LIMIT),
)


def test_features_match_pinocchio(pin):
    model = parse_urdf_string(FEATURES)
    assert model.joint_names == ("j_side", "j1", "j2", "j3")
    assert model.link_by_name["c"].inertial.mass == 1
    compare_with_pinocchio(pin, model, pin.buildModelFromXML(FEATURES), seed=7)


def test_defaults_and_exact_numbers():
    model = parse_urdf_string(FEATURES)
    j2 = next(j for j in model.joints if j.name == "j2")
    assert j2.axis == (1, 0, 0)  # URDF default axis
    assert all(isinstance(v, sp.Integer) for v in j2.axis)
    assert model.link_by_name["base"].inertial is None
    assert model.gravity[:2] == (0, 0) and float(model.gravity[2]) == -9.81
    c = model.link_by_name["c"].inertial
    assert c.mass == 1 and isinstance(c.mass, sp.Integer)
    assert c.inertia == ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    assert c.com == (0, 0, 0)


def test_axis_is_normalised():
    model = parse_urdf_string(robot(link("a"), link("b"),
                                    joint("j", "a", "b", body='<axis xyz="0 0 2"/>')))
    assert model.joints[0].axis == (0, 0, 1)


def test_quarter_turn_inertial_keeps_structural_zeros():
    """rpy = (π/2, 0, 0) swaps y and z: exact zeros stay exact, moments are permuted."""
    b = parse_urdf_string(FEATURES).link_by_name["b"].inertial
    I = b.inertia
    assert [float(I[i][i]) for i in range(3)] == [0.1, 0.25, 0.2]
    for i in range(3):
        for k in range(3):
            if i != k:
                assert I[i][k] == 0 and isinstance(I[i][k], sp.Integer), (i, k, I[i][k])
    assert b.com[0] == b.com[2] == 0 and float(b.com[1]) == 0.05


def test_rotate_inertia_matches_numpy():
    rng = np.random.default_rng(3)
    A = rng.normal(size=(3, 3))
    I = A @ A.T
    rpy = rng.uniform(-math.pi, math.pi, size=3)
    roll, pitch, yaw = rpy
    Rx = np.array([[1, 0, 0], [0, math.cos(roll), -math.sin(roll)],
                   [0, math.sin(roll), math.cos(roll)]])
    Ry = np.array([[math.cos(pitch), 0, math.sin(pitch)], [0, 1, 0],
                   [-math.sin(pitch), 0, math.cos(pitch)]])
    Rz = np.array([[math.cos(yaw), -math.sin(yaw), 0], [math.sin(yaw), math.cos(yaw), 0],
                   [0, 0, 1]])
    R = Rz @ Ry @ Rx
    rotated = rotate_inertia(I.tolist(), rpy.tolist())
    got = np.array([[float(x) for x in row] for row in rotated])
    np.testing.assert_allclose(got, R @ I @ R.T, rtol=0, atol=1e-14)
    assert all(rotated[i][k] == rotated[k][i] for i in range(3) for k in range(3))


def test_document_order_defines_q():
    text = robot(link("base"), link("left"), link("right"), link("left2"),
                 joint("r", "base", "right"), joint("l2", "left", "left2"),
                 joint("l", "base", "left"))
    assert parse_urdf_string(text).joint_names == ("r", "l2", "l")


MIMIC = robot(link("a"), link("b"), link("c"), joint("j1", "a", "b"),
              joint("j2", "a", "c", body='<axis xyz="0 1 0"/><mimic joint="j1" multiplier="2"/>'))


def test_mimic_joint_is_a_coupling():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = parse_urdf_string(MIMIC, source="m.urdf", strict=True)
    assert model.joint_names == ("j1",)
    (coupling,) = model.couplings
    assert (coupling.follower, coupling.leaders, coupling.offset) == ("j2", (("j1", 2),), 0)
    assert coupling.where == "joint 'j2' <mimic>"
    offset = parse_urdf_string(MIMIC.replace('multiplier="2"', 'offset="-0.25"'))
    assert offset.couplings[0].leaders == (("j1", 1),) and float(offset.couplings[0].offset) == -0.25


def test_mimic_joint_read_as_independent_warns_and_is_refused_under_strict(tmp_path):
    path = tmp_path / "m.urdf"
    path.write_text(MIMIC)
    with pytest.warns(UnsupportedFeatureWarning) as record:
        model = eomgen.load(path, couplings=False)
    assert [str(w.message) for w in record] == [
        f"{path}: joint 'j2' <mimic>: the coupling to joint 'j1' is not modelled; "
        "read as an independent joint (couplings=False)"]
    assert model.joint_names == ("j1", "j2")
    assert model.joints[1].axis == (0, 1, 0)
    plain = parse_urdf_string(MIMIC.replace('<mimic joint="j1" multiplier="2"/>', ""),
                              source=str(path))
    assert model == plain  # the mimic element changes nothing else
    with pytest.raises(UnsupportedError) as caught:
        eomgen.load(path, couplings=False, strict=True)
    assert str(caught.value) == (f"{path}: joint 'j2' <mimic>: the coupling to joint 'j1' is "
                                 "not modelled (refused under --strict)")


def test_mimic_on_a_fixed_joint_is_ignored_silently(erd_robots_dir):
    """Talos' reduced model fixes its gripper joints but keeps their <mimic>: nothing to couple."""
    text = MIMIC.replace('joint name="j2" type="revolute"', 'joint name="j2" type="fixed"')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert parse_urdf_string(text, strict=True).joint_names == ("j1",)
        model = load_for_scene(erd_robots_dir / "talos_data/robots/talos_reduced.urdf",
                               Scene(fixed_base=True), strict=True)  # a humanoid, held still
    assert "gripper_left_inner_double_joint" not in model.joint_names


def test_mimic_warning_only_for_valid_files():
    """A file with an error raises it, without a mimic warning first."""
    broken = MIMIC.replace('<link name="c">', '<link name="c2">')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DescriptionError, match="child link 'c' is not defined"):
            parse_urdf_string(broken)


def test_ignored_elements_do_not_matter():
    decorated = robot(
        '<material name="m"><color rgba="1 0 0 1"/></material>',
        '<link name="a"><visual><origin xyz="9 9 9"/><geometry><mesh filename="x.stl"/>'
        "</geometry></visual><collision><geometry><box size='1 1 1'/></geometry></collision>"
        f'<inertial><mass value="1"/>{INERTIA}</inertial></link>',
        link("b"),
        joint("j", "a", "b", body='<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" '
                                  'velocity="1"/>'),  # <dynamics> is read: test_actuators
        '<transmission name="t"><joint name="j"/></transmission>',
        '<gazebo reference="a"><joint name="ghost" type="floating"/></gazebo>',
    )
    plain = robot(link("a"), link("b"), joint("j", "a", "b"))
    assert parse_urdf_string(decorated) == parse_urdf_string(plain)


@pytest.mark.parametrize("name", ['a"); import os #', r"\input{/etc/passwd}", "{{ x }}",
                                  "ünïcødé ✓", "'; DROP TABLE links; --"])
def test_hostile_names_are_data(name):
    model = parse_urdf_string(robot(link("base"), link(name),
                                    joint(name, "base", name), name=name))
    assert model.name == name
    assert model.joint_names == (name,)
    assert model.link_by_name[name].inertial.mass == 1


@pytest.mark.parametrize("name", ["line&#10;break", "carriage&#13;return", "sep&#8232;arator",
                                  "nel&#133;x"])
def test_error_messages_stay_on_one_line(tmp_path, name):
    path = tmp_path / "names.urdf"
    path.write_text(robot(link("base"), f'<link name="{name}"><inertial><mass value="-1"/>'
                                        f"{INERTIA}</inertial></link>",
                          f'<joint name="j" type="fixed"><parent link="base"/>'
                          f'<child link="{name}"/></joint>'), encoding="utf-8")
    with pytest.raises(DescriptionError) as caught:
        load_urdf(path, False)
    message = str(caught.value)
    assert len(message.splitlines()) == 1
    assert message.startswith(f"{path}: link '") and "mass -1.0 is negative" in message


# ----------------------------------------------------------------------------------------------
# Bad input: one-line errors naming file and element
# ----------------------------------------------------------------------------------------------

BILLION_LAUGHS = """<?xml version="1.0"?>
<!DOCTYPE robot [
 <!ENTITY lol "lol">
 <!ENTITY lol1 "&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;&lol;">
 <!ENTITY lol2 "&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;&lol1;">
 <!ENTITY lol3 "&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;&lol2;">
 <!ENTITY lol4 "&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;&lol3;">
 <!ENTITY lol5 "&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;&lol4;">
 <!ENTITY lol6 "&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;&lol5;">
 <!ENTITY lol7 "&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;&lol6;">
 <!ENTITY lol8 "&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;&lol7;">
 <!ENTITY lol9 "&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;&lol8;">
]>
<robot name="&lol9;"><link name="a"/></robot>
"""

EXTERNAL_ENTITY = """<?xml version="1.0"?>
<!DOCTYPE robot [<!ENTITY secret SYSTEM "file:///etc/passwd">]>
<robot name="r"><link name="&secret;"/></robot>
"""

PARAMETER_ENTITY = """<?xml version="1.0"?>
<!DOCTYPE robot [<!ENTITY % remote SYSTEM "file:///etc/passwd"> %remote;]>
<robot name="r"><link name="a"/></robot>
"""


def with_mass(attributes: str, inertia: str = INERTIA) -> str:
    return robot(link("base"), f'<link name="arm"><inertial>{attributes}{inertia}</inertial>'
                               "</link>", joint("j", "base", "arm"))


def chain(body: str, kind: str = "revolute") -> str:
    return robot(link("base"), link("arm"), joint("j2", "base", "arm", kind, body))


D, U = DescriptionError, UnsupportedError
BAD = {
    # id: (document, exception type, element named, problem named)
    "malformed": ('<robot name="r">\n<link name="a">\n</robot>\n', D, "line 3", "malformed XML"),
    "empty file": ("", D, "line 1", "malformed XML"),
    "billion laughs": (BILLION_LAUGHS, D, "<!ENTITY lol>", "entity declarations"),
    "external entity": (EXTERNAL_ENTITY, D, "<!ENTITY secret>", "entity declarations"),
    "parameter entity": (PARAMETER_ENTITY, D, "<!ENTITY remote>", "entity declarations"),
    "root not robot": ('<model name="r"><link name="a"/></model>', D, "root element <model>",
                       "expected <robot>"),
    "robot without name": ('<robot><link name="a"/></robot>', D, "<robot>", "'name'"),
    "link without name": (robot("<link/>"), D, "<link> number 1", "'name'"),
    "two inertials": (robot(link("a", 2 * f'<inertial><mass value="1"/>{INERTIA}</inertial>')),
                      D, "link 'a'", "2 <inertial> elements"),
    "inertial without mass": (with_mass(""), D, "link 'arm' <inertial>", "no <mass>"),
    "mass without value": (with_mass("<mass/>"), D, "link 'arm' <inertial><mass>", "'value'"),
    "mass nan": (with_mass('<mass value="nan"/>'), D, "link 'arm' <inertial><mass>",
                 "value 'nan' is not a finite number"),
    "mass inf": (with_mass('<mass value="-inf"/>'), D, "link 'arm' <inertial><mass>",
                 "not a finite number"),
    "mass negative": (with_mass('<mass value="-1"/>'), D, "link 'arm' inertial",
                      "mass -1.0 is negative"),
    "mass abc": (with_mass('<mass value="abc"/>'), D, "link 'arm' <inertial><mass>",
                 "value 'abc' is not a number"),
    "no inertia": (with_mass('<mass value="1"/>', ""), D, "link 'arm' <inertial>",
                   "no <inertia>"),
    "inertia without izz": (with_mass('<mass value="1"/>', '<inertia ixx="1" ixy="0" ixz="0" '
                                      'iyy="1" iyz="0"/>'), D, "link 'arm' <inertial><inertia>",
                            "no 'izz'"),
    "negative eigenvalue": (with_mass('<mass value="1"/>', '<inertia ixx="1" ixy="2" ixz="0" '
                                      'iyy="1" iyz="0" izz="1"/>'), D, "link 'arm' inertial",
                            "negative eigenvalue"),
    "com with 2 numbers": (with_mass('<origin xyz="0 0"/><mass value="1"/>'), D,
                           "link 'arm' <inertial><origin>", "xyz='0 0' has 2 numbers"),
    "zero axis": (chain('<axis xyz="0 0 0"/>'), D, "joint 'j2' axis", "axis is zero"),
    "nan axis": (chain('<axis xyz="0 nan 1"/>'), D, "joint 'j2' <axis>",
                 "xyz component 'nan' is not a finite number"),
    "axis with 4 numbers": (chain('<axis xyz="0 0 1 0"/>'), D, "joint 'j2' <axis>",
                            "has 4 numbers, expected 3"),
    "xyz with 2 numbers": (chain('<origin xyz="0 0"/>'), D, "joint 'j2' <origin>",
                           "xyz='0 0' has 2 numbers, expected 3"),
    "rpy not a number": (chain('<origin rpy="0 0 x"/>'), D, "joint 'j2' <origin>",
                         "rpy component 'x' is not a number"),
    "two origins": (chain("<origin/><origin/>"), D, "joint 'j2'", "2 <origin> elements"),
    "unknown joint type": (chain("", "ball"), D, "joint 'j2'", "unknown joint type 'ball'"),
    "joint without type": (robot(link("a"), link("b"), '<joint name="j"><parent link="a"/>'
                                 '<child link="b"/></joint>'), D, "joint 'j'", "'type'"),
    "floating joint": (chain("", "floating"), U, "joint 'j2'",
                       "a floating joint is read as the robot's free flyer only from a massless "
                       "root link"),
    "planar joint off z": (chain('<axis xyz="0 1 0"/>', "planar"), U, "joint 'j2' axis",
                           "must be 0 0 1"),
    "mimic without joint": (robot(link("a"), link("b"), link("c"), joint("j1", "a", "b"),
                                  joint("j2", "a", "c", body='<mimic multiplier="2"/>')),
                            D, "joint 'j2' <mimic>", "no 'joint' attribute"),
    "mimic of unknown joint": (robot(link("a"), link("b"), link("c"), joint("j1", "a", "b"),
                                     joint("j2", "a", "c", body='<mimic joint="ghost"/>')),
                               D, "joint 'j2' <mimic>", "joint 'ghost' is not defined"),
    "no parent element": (robot(link("a"), '<joint name="j2" type="fixed"><child link="a"/>'
                                "</joint>"), D, "joint 'j2'", "no <parent>"),
    "cycle": (robot(link("a"), link("b"), link("c"), joint("j1", "b", "c"),
                    joint("j2", "c", "b")), D, "link 'b'", "cycle"),
    "duplicate link": (robot(link("a"), link("b"), link("a"), joint("j", "a", "b")), D,
                       "link 'a'", "duplicate link name"),
    "duplicate joint": (robot(link("a"), link("b"), link("c"), joint("j", "a", "b"),
                              joint("j", "b", "c")), D, "joint 'j'", "duplicate joint name"),
    "missing parent link": (robot(link("a"), joint("j2", "ghost", "a")), D, "joint 'j2'",
                            "parent link 'ghost' is not defined"),
    "disconnected link": (robot(link("a"), link("b"), link("island"), joint("j", "a", "b")), D,
                          "link 'island'", "not connected"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_bad_input_is_one_line_error_naming_file_and_element(tmp_path, case):
    document, kind, element, problem = BAD[case]
    path = tmp_path / "bad robot.urdf"
    path.write_text(document, encoding="utf-8")
    started = time.monotonic()
    with pytest.raises(kind) as caught:
        eomgen.load(path)
    assert time.monotonic() - started < 5
    # unsupported features and bad files are told apart (each bad file raises a subclass of
    # DescriptionError naming its kind; tests/test_corpus.py checks which)
    assert isinstance(caught.value, kind)
    assert isinstance(caught.value, UnsupportedError) == (kind is UnsupportedError)
    message = str(caught.value)
    assert message.startswith(f"{path}: {element}"), message
    assert problem in message, message
    assert len(message.splitlines()) == 1, message
    assert "root:" not in message  # nothing of /etc/passwd


def test_external_dtd_is_not_read(tmp_path):
    """A DTD that would define the robot's name is never fetched: the reference stays empty."""
    dtd = tmp_path / "names.dtd"
    dtd.write_text('<!ENTITY injected "INJECTED">', encoding="utf-8")
    document = (f'<!DOCTYPE robot SYSTEM "{dtd.as_uri()}">'
                '<robot name="&injected;"><link name="a"/></robot>')
    with pytest.raises(DescriptionError) as caught:
        parse_urdf_string(document, source="dtd.urdf")
    assert str(caught.value) == "dtd.urdf: <robot>: no 'name' attribute (or it is empty)"


def test_malformed_xml_names_line_and_column():
    with pytest.raises(DescriptionError) as caught:
        parse_urdf_string('<robot name="r">\n  <link name="a"/>\n  <link name=a/>\n</robot>',
                          source="inline.urdf")
    assert str(caught.value).startswith("inline.urdf: line 3, column 14: malformed XML")


def test_unreadable_file_is_a_description_error(tmp_path):
    with pytest.raises(DescriptionError, match=r"cannot read the file"):
        load_urdf(tmp_path, False)  # a directory


#: Principal moments 3, 1, 1 with the excess across the joint's axis (z): no rotational
#: inertia about that axis moved from the world makes the body physical, so it warns.
TRIANGLE = with_mass('<mass value="1"/>',
                     '<inertia ixx="3" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>')


def test_triangle_inequality_warns_by_default(tmp_path):
    path = tmp_path / "triangle.urdf"
    path.write_text(TRIANGLE, encoding="utf-8")
    with pytest.warns(PhysicalConsistencyWarning) as record:
        model = eomgen.load(path)
    assert model.link_by_name["arm"].inertial.inertia[0][0] == 3
    message = str(record[0].message)
    assert message.startswith(f"{path}: link 'arm'") and "triangle inequality" in message


def test_triangle_inequality_raises_under_strict(tmp_path):
    path = tmp_path / "triangle.urdf"
    path.write_text(TRIANGLE, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DescriptionError) as caught:
            eomgen.load(path, strict=True)
    assert str(caught.value).startswith(f"{path}: link 'arm'")
    assert "triangle inequality" in str(caught.value)


# ----------------------------------------------------------------------------------------------
# Floating bases: a root that looks like a legged robot's trunk warns (refused under strict)
# ----------------------------------------------------------------------------------------------

def floating_notices(model: RobotModel) -> list[Notice]:
    return [n for n in model.notices if n.kind is NoticeKind.FLOATING_BASE]


def test_a_quadruped_warns_once_naming_the_file_the_root_and_the_legs():
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = parse_urdf_string(legged(), source="quad.urdf")
    assert [w.category for w in caught] == [UnsupportedFeatureWarning]
    message = str(caught[0].message)
    assert message.startswith("quad.urdf: root link 'trunk': looks like a floating base (4 "
                              "branches reach down from it like legs at q = 0: 'hip0', 'hip1', "
                              "'hip2', 'hip3'), but is read as bolted to the world; M, C and g "
                              "are those of a robot held at 'trunk'")
    assert "floating_base: true" in message and "fixed_base: true" in message
    assert len(message.splitlines()) == 1
    assert model.dof == 8  # read all the same, as legs of a trunk held still


def test_a_floating_base_is_refused_under_strict():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UnsupportedError) as caught:
            parse_urdf_string(legged(), source="quad.urdf", strict=True)
    assert str(caught.value).startswith("quad.urdf: root link 'trunk': looks like a floating base")
    assert str(caught.value).endswith("read as bolted to the world (refused under --strict)")


@pytest.mark.parametrize("case, document, warns", [
    ("quadruped", legged(), True),
    ("biped", legged(legs=2), True),
    ("massless root fixed to the trunk (ANYmal, Go1)", legged(massless_root=True), True),
    ("bolted to a 'world' link", legged(world=True), False),
    ("one chain down (an arm under a ceiling)", legged(legs=1), False),
    ("four chains up (a hand's fingers)", legged(direction=(0, 0, 1)), False),
    ("four chains sideways (legs folded, arms of a torso)", legged(direction=(1, 0, 0)), False),
    ("legs reach down 0.55 of the extent", legged(legs=2, hip=1.0, length=0.6586), True),
    ("legs reach down 0.45 of the extent", legged(legs=2, hip=1.0, length=0.5039), False),
])
def test_which_roots_look_floating(case, document, warns):
    """The rule (docs/formats.md): not rooted at 'world', and two or more movable branches of
    the root body reach below the root origin by at least LEG_REACH of the model's extent."""
    model = parse_urdf_string(document, defer_notices=True)
    assert bool(floating_notices(model)) == warns, case
    assert LEG_REACH == 0.5  # the two threshold cases sit at 0.45 and 0.55 of the extent


def test_deferred_notices_warn_nothing_and_emit_as_loading_would(tmp_path):
    path = tmp_path / "quad.urdf"
    path.write_text(legged(), encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model = eomgen.load(path, defer_notices=True)
    assert [n.kind for n in model.notices] == [NoticeKind.FLOATING_BASE]
    with warnings.catch_warnings(record=True) as emitted:
        warnings.simplefilter("always")
        emit_notices(model.notices)
    with warnings.catch_warnings(record=True) as loaded:
        warnings.simplefilter("always")
        eomgen.load(path)
    assert [str(w.message) for w in emitted] == [str(w.message) for w in loaded]
    assert model == eomgen.load(path, defer_notices=True)  # notices take no part in equality


def test_floating_joint_from_a_massless_root_is_the_free_flyer(tmp_path):
    """A floating joint from a massless root link is read as the quaternion free flyer (as
    Pinocchio reads it; tests/dynamics/test_free_flyer.py checks the dynamics), through the
    command as a user would; elsewhere it is refused in one line that says what to do, and
    doing that works."""
    from support import ERROR, run_in_process

    document = robot(link("world", None), link("trunk"),
                     joint("root_joint", "world", "trunk", "floating", ""))
    model = parse_urdf_string(document, source="f.urdf", defer_notices=True)
    assert model.free_flyer and (model.nq, model.dof) == (7, 6) and not model.notices
    urdf = tmp_path / "f.urdf"
    urdf.write_text(document, encoding="utf-8")
    out = tmp_path / "out"
    flying = run_in_process("generate", urdf, "--backend", "numpy", "-o", out, "--no-cache",
                            "--quiet")
    assert flying.returncode == 0, flying.stderr
    text = next(out.glob("*_numpy.py")).read_text(encoding="utf-8")
    assert "NQ = 7" in text and "NV = 6" in text

    heavy = document.replace('<link name="world"></link>', '<link name="world"><inertial><mass '
                             'value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" '
                             'izz="1"/></inertial></link>')
    assert heavy != document
    urdf.write_text(heavy, encoding="utf-8")
    failed = run_in_process("generate", urdf, "--backend", "numpy", "-o", tmp_path / "no",
                            "--no-cache")
    lines = failed.stderr.strip().splitlines()
    assert failed.returncode == 2 and len(lines) == 1 and not (tmp_path / "no").exists()
    assert lines[0].startswith(f"{ERROR}{urdf}: joint 'root_joint': ")
    assert "'floating_base: quaternion'" in lines[0]

    urdf.write_text(robot(link("trunk")), encoding="utf-8")  # as the message says
    scene = tmp_path / "fly.yaml"
    scene.write_text("version: 1\nfloating_base: quaternion\n", encoding="utf-8")
    out = tmp_path / "scene_out"
    flying = run_in_process("generate", urdf, "--scene", scene, "--backend", "numpy", "-o", out,
                            "--no-cache", "--quiet")
    assert flying.returncode == 0, flying.stderr
    assert "NQ = 7" in next(out.glob("*_numpy.py")).read_text(encoding="utf-8")


#: example-robot-data's own loader (python/example_robot_data/robots_loader.py, version 4.x)
#: adds a free-flyer root joint for these files: the independent label of "floating base".
ERD_FREE_FLYER = {
    "a1_description/urdf/a1.urdf", "anymal_b_simple_description/robots/anymal.urdf",
    "anymal_b_simple_description/robots/anymal-kinova.urdf",
    "anymal_c_simple_description/urdf/anymal.urdf", "b1_description/urdf/b1.urdf",
    "b1_description/urdf/b1-z1.urdf", "bolt_description/robots/bolt.urdf",
    "go1_description/urdf/go1.urdf", "hector_description/robots/quadrotor_base.urdf",
    "hyq_description/robots/hyq_no_sensors.urdf", "icub_description/robots/icub.urdf",
    "icub_description/robots/icub_reduced.urdf", "iris_description/robots/iris_simple.urdf",
    "laikago_description/urdf/laikago.urdf", "romeo_description/urdf/romeo.urdf",
    "simple_humanoid_description/urdf/simple_humanoid.urdf",
    "simple_humanoid_description/urdf/simple_humanoid_classical.urdf",
    "solo_description/robots/solo.urdf", "solo_description/robots/solo12.urdf",
    "talos_data/robots/talos_reduced.urdf", "talos_data/robots/talos_reduced_box.urdf",
    "talos_data/robots/talos_full_v2.urdf", "talos_data/robots/talos_full_v2_box.urdf",
}
#: Free flyers without legs, which the rule misses by design (docs/formats.md).
ERD_FLYING = {"hector_description/robots/quadrotor_base.urdf",
              "iris_description/robots/iris_simple.urdf"}
#: Legged robots the loader does not list (no loader class), which the rule finds too.
ERD_LEGGED_UNLISTED = {
    "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
    "centauro_description/urdf/centauro.urdf", "g1_description/urdf/g1_29dof_rev_1_0.urdf",
    "g1_description/urdf/g1_29dof_with_hand_rev_1_0.urdf", "go2_description/urdf/go2.urdf",
    "quadruped_description/urdf/quadruped.urdf", "romeo_description/urdf/romeo_small.urdf",
    "talos_data/robots/talos_reduced_corrected.urdf",
}


@pytest.mark.slow
def test_floating_base_rule_over_every_example_robot_data_file(erd_robots_dir):
    """The survey docs/formats.md reports: warns for every legged free flyer and the unlisted
    legged robots, for nothing else (arms, hands, Baxter, PR2, Tiago Pro, ...)."""
    warned, silent = set(), set()
    for path in sorted(erd_robots_dir.rglob("*.urdf")):
        relative = path.relative_to(erd_robots_dir).as_posix()
        try:
            model = eomgen.load(path, defer_notices=True)
        except DescriptionError:
            continue  # refused for other reasons (no robot name, a broken tree)
        (warned if floating_notices(model) else silent).add(relative)
    assert warned == (ERD_FREE_FLYER - ERD_FLYING) | ERD_LEGGED_UNLISTED
    assert (len(warned), len(silent)) == (29, 34)
    arms = {relative for relative, _ in ARMS} | {"talos_data/robots/talos_left_arm.urdf",
                                                "allegro_hand_description/urdf/allegro_left_hand.urdf",
                                                "baxter_description/urdf/baxter.urdf"}
    assert arms <= silent


def test_documented_floating_base_warning_is_what_eomgen_prints(erd_robots_dir):
    text = (ROOT / "docs" / "formats.md").read_text("utf-8")
    documented = [line for line in text.splitlines() if line.startswith("solo12.urdf: root")]
    path = erd_robots_dir / "solo_description/robots/solo12.urdf"
    model = parse_urdf_string(path.read_bytes(), source="solo12.urdf", defer_notices=True)
    assert documented == [n.message for n in floating_notices(model)]


# ----------------------------------------------------------------------------------------------
# Inertias that do not matter: the Go1's placeholder root
# ----------------------------------------------------------------------------------------------


def _go1_text(robots) -> str:
    return (robots / "go1_description/urdf/go1.urdf").read_text(encoding="utf-8")


def _inertia_warnings(path) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        eomgen.load(path)
    return [str(w.message) for w in caught if issubclass(w.category, PhysicalConsistencyWarning)]


def test_go1_placeholder_root_inertia_does_not_warn(erd_robots_dir):
    """The Go1's root link 'base' carries a placeholder (1e-6 in every entry: moments 0, 0,
    3e-6) and is fixed to the world with the trunk: it never moves, nothing to warn about."""
    text = _go1_text(erd_robots_dir)
    assert '<inertia ixx="1e-6" ixy="1e-6" ixz="1e-6" iyy="1e-6" iyz="1e-6" izz="1e-6"/>' in text
    assert _inertia_warnings(erd_robots_dir / "go1_description/urdf/go1.urdf") == []


def test_go1_with_a_bad_leg_inertia_still_warns(erd_robots_dir, tmp_path):
    """A thigh whose largest moment lies across its joint axis (y): no inertia moved across the
    joint makes it physical, so it warns, naming the link."""
    text = _go1_text(erd_robots_dir)
    head, tail = text.split('<link name="FR_thigh">', 1)
    start, end = tail.index("<inertia "), tail.index("/>", tail.index("<inertia ")) + 2
    bad = '<inertia ixx="3" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/>'
    path = tmp_path / "go1.urdf"
    path.write_text(head + '<link name="FR_thigh">' + tail[:start] + bad + tail[end:],
                    encoding="utf-8")
    (message,) = _inertia_warnings(path)
    assert message.startswith(f"{path}: link 'FR_thigh' inertial: principal moments 1, 1, 3 "
                              "break the triangle inequality")
