"""Parsers for eomgen's YAML robot format and DH tables, and the bundled example robots.

Kinematics are checked against forward kinematics computed here in NumPy straight from the
textbook formulas (the DH products, the planar arm's closed form); dynamics of the bundled
robots against Pinocchio on a model built from ours, and against published reference values.
"""

from __future__ import annotations

import dataclasses
import re
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import eomgen
from support import ROOT
from eomgen.errors import (
    DescriptionError,
    EomgenError,
    PhysicalConsistencyWarning,
    UnsupportedError,
)
from eomgen.model import JointType, RobotModel, parameter_symbol
from eomgen.parsers import _yaml, dh, yaml_format
from eomgen.robots import DEFAULT, EXAMPLES, example_path
from support.extras import need

DOCS = ROOT / "docs" / "formats.md"

# ----------------------------------------------------------------------------------------------
# Helpers: homogeneous transforms and forward kinematics, in NumPy
# ----------------------------------------------------------------------------------------------


def rot_x(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def rot_z(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def trans(x=0.0, y=0.0, z=0.0):
    out = np.eye(4)
    out[:3, 3] = (x, y, z)
    return out


def dh_standard(a, alpha, d, theta):
    """Textbook standard DH: Rz(theta) Tz(d) Tx(a) Rx(alpha)."""
    return rot_z(theta) @ trans(z=d) @ trans(x=a) @ rot_x(alpha)


def dh_modified(a, alpha, d, theta):
    """Craig's modified DH: Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)."""
    return rot_x(alpha) @ trans(x=a) @ rot_z(theta) @ trans(z=d)


def homogeneous(transform) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = np.array(transform.rotation, dtype=float)
    out[:3, 3] = np.array(transform.translation, dtype=float)
    return out


def motion(joint, q: float) -> np.ndarray:
    axis = np.array(joint.axis, dtype=float)
    out = np.eye(4)
    if joint.type.is_revolute:
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        out[:3, :3] = np.eye(3) + np.sin(q) * K + (1 - np.cos(q)) * K @ K
    elif joint.type is JointType.PRISMATIC:
        out[:3, 3] = q * axis
    return out


def forward_kinematics(model: RobotModel, q) -> dict[str, np.ndarray]:
    """World pose (4×4) of every link frame; ``q`` in ``model.joint_names`` order."""
    assert not model.free_symbols, "use with_numeric_parameters() first"
    qmap = dict(zip(model.joint_names, q))
    poses = {model.root: np.eye(4)}

    def pose(link):
        if link not in poses:
            joint = model.parent_joint[link]
            poses[link] = (pose(joint.parent) @ homogeneous(joint.origin)
                           @ motion(joint, qmap.get(joint.name, 0.0)))
        return poses[link]

    for link in model.links:
        pose(link.name)
    return poses


def world_com_and_inertia(model: RobotModel, q) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    poses = forward_kinematics(model, q)
    out = {}
    for link in model.links:
        if link.inertial is None:
            continue
        T = poses[link.name]
        com = T[:3, :3] @ np.array(link.inertial.com, dtype=float) + T[:3, 3]
        R = T[:3, :3]
        out[link.name] = (com, R @ np.array(link.inertial.inertia, dtype=float) @ R.T)
    return out


def write(tmp_path: Path, text: str, name: str = "robot.yaml") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def num(x: float) -> str:
    return repr(float(x))


# ----------------------------------------------------------------------------------------------
# Pinocchio reference built from a numeric RobotModel (revolute/prismatic/fixed joints)
# ----------------------------------------------------------------------------------------------


def pinocchio_model(model: RobotModel):
    pin = need("pinocchio")
    model = model.with_numeric_parameters() if model.free_symbols else model
    pm = pin.Model()
    pm.gravity.linear = np.array(model.gravity, dtype=float)
    # link → (pinocchio joint id, placement of the link frame in that joint's frame)
    where = {model.root: (0, pin.SE3.Identity())}
    for joint in model.topological_joints:
        parent_id, parent_placement = where[joint.parent]
        R = np.array(joint.origin.rotation, dtype=float)
        placement = parent_placement * pin.SE3(R, np.array(joint.origin.translation, dtype=float))
        axis = np.array(joint.axis, dtype=float)
        if joint.type is JointType.FIXED:
            where[joint.child] = (parent_id, placement)
        else:
            jm = (pin.JointModelRevoluteUnaligned(axis) if joint.type.is_revolute
                  else pin.JointModelPrismaticUnaligned(axis))
            jid = pm.addJoint(parent_id, jm, placement, joint.name)
            where[joint.child] = (jid, pin.SE3.Identity())
        inertial = model.link_by_name[joint.child].inertial
        if inertial is not None:
            jid, link_placement = where[joint.child]
            pm.appendBodyToJoint(
                jid,
                pin.Inertia(float(inertial.mass), np.array(inertial.com, dtype=float),
                            np.array(inertial.inertia, dtype=float)),
                link_placement)
    # Pinocchio orders q by joint creation; ours follows the description: map by name.
    order = [pm.getJointId(name) - 1 for name in model.joint_names]
    assert sorted(order) == list(range(model.dof))
    return pin, pm, order


def pin_M_g(model: RobotModel, q):
    pin, pm, order = pinocchio_model(model)
    data = pm.createData()
    qp = np.zeros(model.dof)
    qp[order] = q
    g = pin.rnea(pm, data, qp, np.zeros(model.dof), np.zeros(model.dof))[order]
    M = pin.crba(pm, data, qp)
    M = np.triu(M) + np.triu(M, 1).T
    return M[np.ix_(order, order)], g


# ----------------------------------------------------------------------------------------------
# The bundled planar two-link arm
# ----------------------------------------------------------------------------------------------


def test_examples_are_package_data():
    assert DEFAULT == "planar_2link" and set(EXAMPLES) == {
        "planar_2link", "puma560_dh", "elbow_rrr", "scara_rrp", "stanford_rrp",
        "cylindrical_rpp", "puma560_arm3"}
    package_dir = Path(eomgen.__file__).resolve().parent
    for name, path in EXAMPLES.items():
        assert example_path(name) == path and path.is_file()
        assert path.parent == package_dir / "robots"
    assert example_path() == EXAMPLES["planar_2link"]
    with pytest.raises(EomgenError, match="unknown example robot 'ur5'.*planar_2link"):
        example_path("ur5")


def test_planar_2link_structure_and_parameters():
    model = eomgen.load(example_path("planar_2link"))
    assert model.name == "planar_2link"
    assert model.joint_names == ("joint1", "joint2")
    assert [j.type for j in model.joints] == [JointType.REVOLUTE, JointType.REVOLUTE,
                                              JointType.FIXED]
    assert [link.name for link in model.links] == ["base", "link1", "link2", "tip"]
    assert model.root == "base"
    values = {p.name: p.value for p in model.parameters}
    assert values == pytest.approx({"m1": 1.0, "m2": 1.0, "l1": 1.0, "l2": 1.0, "lc1": 0.5,
                                    "lc2": 0.5, "I1": 1 / 12, "I2": 1 / 12, "g": 9.81})
    assert [p.name for p in model.parameters] == ["m1", "m2", "l1", "l2", "lc1", "lc2", "I1",
                                                  "I2", "g"]
    assert all(p.description for p in model.parameters)
    g, m1, I1, lc1 = (parameter_symbol(n) for n in ("g", "m1", "I1", "lc1"))
    assert model.gravity == (0, -g, 0)
    link1 = model.link_by_name["link1"].inertial
    assert link1.mass == m1 and link1.com == (lc1, 0, 0)
    assert link1.inertia == ((0, 0, 0), (0, 0, 0), (0, 0, I1))
    assert model.link_by_name["tip"].inertial is None
    assert dict(model.info)["description"].startswith("Planar two-link arm")


def test_planar_2link_forward_kinematics_closed_form():
    symbolic = eomgen.load(example_path("planar_2link"))
    values = {"l1": 0.7, "l2": 0.45, "lc1": 0.31, "lc2": 0.18}
    model = symbolic.with_numeric_parameters({parameter_symbol(k): v for k, v in values.items()})
    l1, l2, lc1, lc2 = (values[k] for k in ("l1", "l2", "lc1", "lc2"))
    rng = np.random.default_rng(1)
    for q1, q2 in rng.uniform(-np.pi, np.pi, size=(5, 2)):
        c1, s1, c12, s12 = np.cos(q1), np.sin(q1), np.cos(q1 + q2), np.sin(q1 + q2)
        coms = world_com_and_inertia(model, [q1, q2])
        np.testing.assert_allclose(coms["link1"][0], [lc1 * c1, lc1 * s1, 0], atol=1e-12)
        np.testing.assert_allclose(coms["link2"][0],
                                   [l1 * c1 + lc2 * c12, l1 * s1 + lc2 * s12, 0], atol=1e-12)
        tip = forward_kinematics(model, [q1, q2])["tip"]
        np.testing.assert_allclose(tip[:3, 3], [l1 * c1 + l2 * c12, l1 * s1 + l2 * s12, 0],
                                   atol=1e-12)
        np.testing.assert_allclose(tip[:3, :3], rot_z(q1 + q2)[:3, :3], atol=1e-12)


def test_planar_2link_dynamics_are_the_textbook_ones():
    symbolic = eomgen.load(example_path("planar_2link"))
    rng = np.random.default_rng(2)
    names = ("m1", "m2", "l1", "l2", "lc1", "lc2", "I1", "I2", "g")
    for _ in range(3):
        p = dict(zip(names, rng.uniform(0.2, 2.0, size=len(names))))
        model = symbolic.with_numeric_parameters({parameter_symbol(k): v for k, v in p.items()})
        q1, q2 = rng.uniform(-np.pi, np.pi, size=2)
        M, g = pin_M_g(model, [q1, q2])
        c2 = np.cos(q2)
        M11 = (p["m1"] * p["lc1"] ** 2 + p["m2"] * (p["l1"] ** 2 + p["lc2"] ** 2
               + 2 * p["l1"] * p["lc2"] * c2) + p["I1"] + p["I2"])
        M12 = p["m2"] * (p["lc2"] ** 2 + p["l1"] * p["lc2"] * c2) + p["I2"]
        M22 = p["m2"] * p["lc2"] ** 2 + p["I2"]
        np.testing.assert_allclose(M, [[M11, M12], [M12, M22]], rtol=1e-12, atol=1e-12)
        g1 = ((p["m1"] * p["lc1"] + p["m2"] * p["l1"]) * p["g"] * np.cos(q1)
              + p["m2"] * p["lc2"] * p["g"] * np.cos(q1 + q2))
        g2 = p["m2"] * p["lc2"] * p["g"] * np.cos(q1 + q2)
        np.testing.assert_allclose(g, [g1, g2], rtol=1e-12, atol=1e-12)


# ----------------------------------------------------------------------------------------------
# DH tables: random tables against the textbook products
# ----------------------------------------------------------------------------------------------


def random_table(rng, n):
    rows = []
    for _ in range(n):
        rows.append({
            "type": str(rng.choice(["revolute", "prismatic"])),
            "a": rng.uniform(-1, 1), "alpha": rng.uniform(-np.pi, np.pi),
            "d": rng.uniform(-1, 1), "theta": rng.uniform(-np.pi, np.pi),
            "mass": rng.uniform(0.5, 3), "com": rng.uniform(-0.5, 0.5, size=3),
            "inertia": random_inertia(rng),
        })
    return rows


def random_inertia(rng):
    """A physical inertia: R diag(principal moments satisfying the triangle inequality) Rᵀ."""
    a, b = rng.uniform(0.1, 1.0, size=2)
    c = rng.uniform(abs(a - b) + 0.01, a + b - 0.01)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    return Q @ np.diag([a, b, c]) @ Q.T


def table_yaml(rows, convention, name="random") -> str:
    lines = [f"name: {name}", f"convention: {convention}", "dh:"]
    for i, r in enumerate(rows, start=1):
        I = r["inertia"]
        lines += [
            f"  - name: j{i}",
            f"    type: {r['type']}",
            *(f"    {k}: {num(r[k])}" for k in ("a", "alpha", "d", "theta")),
            f"    mass: {num(r['mass'])}",
            f"    com: [{', '.join(num(c) for c in r['com'])}]",
            f"    inertia: {{ixx: {num(I[0, 0])}, iyy: {num(I[1, 1])}, izz: {num(I[2, 2])}, "
            f"ixy: {num(I[0, 1])}, ixz: {num(I[0, 2])}, iyz: {num(I[1, 2])}}}",
        ]
    return "\n".join(lines) + "\n"


def dh_frames(rows, q, product):
    """World poses of DH frames 1..n: T_0i = Π A_k, with the joint variable added."""
    T, out = np.eye(4), []
    for r, qi in zip(rows, q):
        theta = r["theta"] + (qi if r["type"] == "revolute" else 0.0)
        d = r["d"] + (qi if r["type"] == "prismatic" else 0.0)
        T = T @ product(r["a"], r["alpha"], d, theta)
        out.append(T)
    return out


@pytest.mark.parametrize("convention, product", [("standard", dh_standard),
                                                 ("modified", dh_modified)])
@pytest.mark.parametrize("seed", range(6))
def test_random_dh_table_matches_textbook_product(tmp_path, convention, product, seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 7))
    rows = random_table(rng, n)
    model = eomgen.load(write(tmp_path, table_yaml(rows, convention)))
    assert model.joint_names == tuple(f"j{i}" for i in range(1, n + 1))
    assert [j.type.value for j in model.movable_joints] == [r["type"] for r in rows]
    for _ in range(3):
        q = rng.uniform(-np.pi, np.pi, size=n)
        frames = dh_frames(rows, q, product)
        poses = forward_kinematics(model, q)
        bodies = world_com_and_inertia(model, q)
        for i, (T0i, r) in enumerate(zip(frames, rows), start=1):
            link = poses[f"link{i}"]
            if convention == "modified":
                np.testing.assert_allclose(link, T0i, atol=1e-12)  # link frame = DH frame
            else:  # documented: DH frame i = link frame i · Tx(a_i) Rx(alpha_i)
                np.testing.assert_allclose(link @ trans(x=r["a"]) @ rot_x(r["alpha"]), T0i,
                                           atol=1e-12)
            # a body given in DH frame i sits where T_0i puts it
            com, inertia = bodies[f"link{i}"]
            np.testing.assert_allclose(com, T0i[:3, :3] @ r["com"] + T0i[:3, 3], atol=1e-12)
            R = T0i[:3, :3]
            np.testing.assert_allclose(inertia, R @ r["inertia"] @ R.T, atol=1e-12)
        if convention == "standard":
            np.testing.assert_allclose(poses[f"frame{n}"], frames[-1], atol=1e-12)
        else:
            assert f"frame{n}" not in model.link_by_name


def test_dh_joint_motion_is_about_local_z(tmp_path):
    rows = random_table(np.random.default_rng(11), 4)
    for convention in ("standard", "modified"):
        model = eomgen.load(write(tmp_path, table_yaml(rows, convention)))
        assert all(j.axis == (0, 0, 1) for j in model.movable_joints)


@pytest.mark.parametrize("seed", range(4))
def test_standard_and_modified_tables_of_one_robot_agree(tmp_path, seed):
    """Rewrite a standard table as Craig's table (row i takes a_{i-1}, alpha_{i-1}; the COM
    moves from DH frame i to the frame on joint axis i) and compare the bodies in the world."""
    rng = np.random.default_rng(100 + seed)
    n = int(rng.integers(2, 6))
    standard = random_table(rng, n)
    modified = []
    for i, r in enumerate(standard):
        D = trans(x=r["a"]) @ rot_x(r["alpha"])  # standard frame i in the proximal frame i
        previous = standard[i - 1] if i else {"a": 0.0, "alpha": 0.0}
        modified.append(dict(r, a=previous["a"], alpha=previous["alpha"],
                             com=D[:3, :3] @ r["com"] + D[:3, 3],
                             inertia=D[:3, :3] @ r["inertia"] @ D[:3, :3].T))
    m_std = eomgen.load(write(tmp_path, table_yaml(standard, "standard"), "std.yaml"))
    m_mod = eomgen.load(write(tmp_path, table_yaml(modified, "modified"), "mod.yaml"))
    for _ in range(3):
        q = rng.uniform(-np.pi, np.pi, size=n)
        a, b = world_com_and_inertia(m_std, q), world_com_and_inertia(m_mod, q)
        assert a.keys() == b.keys() == {f"link{i}" for i in range(1, n + 1)}
        for link in a:
            np.testing.assert_allclose(a[link][0], b[link][0], atol=1e-12)
            np.testing.assert_allclose(a[link][1], b[link][1], atol=1e-12)


def test_dh_symbolic_lengths_stay_exact(tmp_path):
    path = write(tmp_path, """\
convention: standard
gravity: [0, -g, 0]
parameters: {a1: 1.0, a2: 0.5, g: 9.81, al2: {value: 0.3}, unused: 2.0}
dh:
  - {a: a1, alpha: 0, mass: 1, com: [-a1/2, 0, 0]}
  - {a: a2, alpha: al2, theta: pi/2}
""")
    model = eomgen.load(path)
    a1, a2, al2, g = (parameter_symbol(n) for n in ("a1", "a2", "al2", "g"))
    assert model.name == "robot"
    assert [p.name for p in model.parameters] == ["a1", "a2", "g", "al2"]  # unused dropped
    j1, j2, end = model.joints
    assert j1.origin.translation == (0, 0, 0) and j1.origin.rotation == ((1, 0, 0), (0, 1, 0),
                                                                          (0, 0, 1))
    assert j2.origin.translation == (a1, 0, 0)
    # theta = pi/2: exact Rz(pi/2)
    assert j2.origin.rotation == ((0, -1, 0), (1, 0, 0), (0, 0, 1))
    assert all(type(v) is sp.Integer or v in (sp.S.One, sp.S.NegativeOne, sp.S.Zero)
               for row in j2.origin.rotation for v in row)
    assert end.type is JointType.FIXED and end.child == "frame2"
    assert end.origin.translation == (a2, 0, 0)
    assert sp.simplify(sp.Matrix(end.origin.rotation)
                       - sp.Matrix([[1, 0, 0], [0, sp.cos(al2), -sp.sin(al2)],
                                    [0, sp.sin(al2), sp.cos(al2)]])) == sp.zeros(3)
    # the COM given in DH frame 1 (-a1/2) is at +a1/2 in the link frame on joint axis 1
    assert sp.simplify(model.link_by_name["link1"].inertial.com[0] - a1 / 2) == 0
    assert model.gravity == (0, -g, 0)
    info = dict(model.info)
    assert info["convention"] == "standard"
    assert info["dh_columns"] == ("joint", "type", "a", "alpha", "d", "theta")
    assert info["dh"] == (("joint1", "revolute", a1, 0, 0, 0),
                          ("joint2", "revolute", a2, al2, 0, sp.pi / 2))


def test_dh_numeric_twists_written_pi_over_2_are_exact():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PhysicalConsistencyWarning)
        model = eomgen.load(example_path("puma560_dh"))
    for joint in model.joints:
        for row in joint.origin.rotation:
            for v in row:
                assert v in (0, 1, -1) and v.is_Integer, (joint.name, v)


def test_dh_prismatic_offsets_d(tmp_path):
    model = eomgen.load(write(tmp_path, """\
convention: modified
dh:
  - {type: prismatic, d: 0.25, theta: pi/2}
"""))
    (joint,) = model.joints
    assert joint.type is JointType.PRISMATIC
    pose = forward_kinematics(model, [0.5])["link1"]
    np.testing.assert_allclose(pose[:3, 3], [0, 0, 0.75], atol=1e-15)
    np.testing.assert_allclose(pose[:3, :3], rot_z(np.pi / 2)[:3, :3], atol=1e-15)


# ----------------------------------------------------------------------------------------------
# PUMA 560
# ----------------------------------------------------------------------------------------------

# Published standard DH table of the PUMA 560 (Corke, mdl_puma560), typed in independently of
# the bundled file: (a, alpha, d)
PUMA_DH = [(0, np.pi / 2, 0), (0.4318, 0, 0), (0.0203, -np.pi / 2, 0.15005),
           (0, np.pi / 2, 0.4318), (0, -np.pi / 2, 0), (0, 0, 0)]


def load_puma(strict=False):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        model = eomgen.load(example_path("puma560_dh"), strict=strict)
    return model, [w for w in caught if issubclass(w.category, PhysicalConsistencyWarning)]


def test_puma560_loads_silently_with_the_published_data():
    model, caught = load_puma()
    assert caught == []
    assert model.name == "puma560" and model.dof == 6
    assert model.joint_names == tuple(f"joint{i}" for i in range(1, 7))
    assert [float(v) for v in model.gravity] == [0, 0, -9.81]
    masses = [float(link.inertial.mass) for link in model.links if link.inertial is not None]
    assert sum(masses) == pytest.approx(0 + 17.4 + 4.8 + 0.82 + 0.34 + 0.09)
    moments = {link.name: sorted(np.linalg.eigvalsh(np.array(link.inertial.inertia, float)))
               for link in model.links if link.inertial is not None}  # as published:
    assert moments["link1"] == pytest.approx([0, 0, 0.35])  # breaks the triangle inequality
    assert moments["link3"] == pytest.approx([0.0125, 0.066, 0.086])  # this one too
    assert dict(model.info)["convention"] == "standard"
    eomgen.load(example_path("puma560_dh"), strict=True)  # nothing left to refuse


def test_puma560_dynamics_are_those_of_a_physical_robot(tmp_path):
    """Links 1 and 3 break the triangle inequality, yet M, C, g are a physical robot's: link 1
    completed about its axis y1 (its only motion), link 3 given β (E − y3 y3ᵀ) about joint 3's
    axis (y3 in frame 3, z2 in frame 2) that link 2 gives up. Worked by hand from the DH
    frames: the completed file loads under strict and its Newton–Euler torques are the same."""
    from eomgen.verify import reference_rnea

    beta = 0.00375  # 0.066 + β + 0.0125 + β ≥ 0.086
    text = example_path("puma560_dh").read_text(encoding="utf-8")
    for old, new in [("inertia: {iyy: 0.35}", "inertia: {ixx: 0.175, iyy: 0.35, izz: 0.175}"),
                     ("inertia: {ixx: 0.13, iyy: 0.524, izz: 0.539}",
                      f"inertia: {{ixx: {0.13 - beta}, iyy: {0.524 - beta}, izz: 0.539}}"),
                     ("inertia: {ixx: 0.066, iyy: 0.086, izz: 0.0125}",
                      f"inertia: {{ixx: {0.066 + beta}, iyy: 0.086, izz: {0.0125 + beta}}}")]:
        assert old in text
        text = text.replace(old, new)
    physical = eomgen.load(write(tmp_path, text, "puma_physical.yaml"), strict=True)
    published, _ = load_puma()
    ours, theirs = reference_rnea(published), reference_rnea(physical)
    rng = np.random.default_rng(0)
    for _ in range(5):
        q, qd, qdd = rng.uniform(-np.pi, np.pi, 6), rng.normal(size=6), rng.normal(size=6)
        np.testing.assert_allclose(ours(q, qd, qdd), theirs(q, qd, qdd), rtol=0, atol=1e-12)


def test_puma560_link3_alone_would_warn(tmp_path):
    """When links 1 and 2 have no rotational inertia to give (link 2 could take it from link
    1 about joint 2's axis, z1, but link 1 turns about y1 only), link 3's published moments
    warn."""
    text = example_path("puma560_dh").read_text(encoding="utf-8").replace(
        "inertia: {ixx: 0.13, iyy: 0.524, izz: 0.539}", "inertia: {ixx: 0, iyy: 0, izz: 0}"
    ).replace("inertia: {iyy: 0.35}", "inertia: {iyy: 0}")
    with pytest.warns(PhysicalConsistencyWarning, match=r"link 'link3' inertial: principal "
                      r"moments 0\.0125, 0\.066, 0\.086 break the triangle inequality"):
        eomgen.load(write(tmp_path, text, "puma_bare_link2.yaml"))


def test_puma560_zero_pose():
    model, _ = load_puma()
    T = np.eye(4)
    for a, alpha, d in PUMA_DH:
        T = T @ dh_standard(a, alpha, d, 0.0)
    # the well-known zero pose: x = a2 + a3, y = -d3, z = d4, orientation identity
    np.testing.assert_allclose(T[:3, 3], [0.4318 + 0.0203, -0.15005, 0.4318], atol=1e-12)
    np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=1e-12)
    end = forward_kinematics(model, np.zeros(6))["link6"]  # a6 = alpha6 = 0: link6 = frame 6
    np.testing.assert_allclose(end, T, atol=1e-12)
    rng = np.random.default_rng(5)
    q = rng.uniform(-np.pi, np.pi, size=6)
    T = np.eye(4)
    for (a, alpha, d), qi in zip(PUMA_DH, q):
        T = T @ dh_standard(a, alpha, d, qi)
    np.testing.assert_allclose(forward_kinematics(model, q)["link6"], T, atol=1e-12)


def test_puma560_dynamics_match_published_reference():
    """Corke's Robotics Toolbox test values at qn = (0, pi/4, pi, 0, pi/4, 0): gravload, and
    the joint-space inertia, whose diagonal there includes the motor inertia Jm G²."""
    model, _ = load_puma()
    qn = np.array([0, np.pi / 4, np.pi, 0, np.pi / 4, 0])
    M, g = pin_M_g(model, qn)
    np.testing.assert_allclose(g, [0, 31.6399, 6.0351, 0, 0.0283, 0], atol=6e-5)
    Jm = np.array([200e-6, 200e-6, 200e-6, 33e-6, 33e-6, 33e-6])
    G = np.array([-62.6111, 107.815, -53.7063, 76.0364, 71.923, 76.686])
    published = np.array([
        [3.6594, -0.4044, 0.1006, -0.0025, 0.0000, -0.0000],
        [-0.4044, 4.4137, 0.3509, 0.0000, 0.0024, 0.0000],
        [0.1006, 0.3509, 0.9378, 0.0000, 0.0015, 0.0000],
        [-0.0025, 0.0000, 0.0000, 0.1925, 0.0000, 0.0000],
        [0.0000, 0.0024, 0.0015, 0.0000, 0.1713, 0.0000],
        [-0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.1941]])
    np.testing.assert_allclose(M + np.diag(Jm * G**2), published, atol=6e-5)


# ----------------------------------------------------------------------------------------------
# Format detection
# ----------------------------------------------------------------------------------------------


def test_sniffers():
    assert dh.sniff("name: x\ndh:\n  - {a: 1}\n")
    assert dh.sniff("'dh' : []\n") and dh.sniff('"dh":\n')
    assert not dh.sniff("links:\n  - name: dh\njoints: []\n")
    assert not dh.sniff("name: x\n  dh: 3\n")  # not top level
    assert not dh.sniff("dhx: 1\n")
    assert yaml_format.sniff("links:\n  - name: a\njoints: []\n")
    assert not yaml_format.sniff("links:\n  - name: a\n")
    assert not yaml_format.sniff("dh: []\n")


def test_load_picks_the_format_by_content(tmp_path):
    assert dict(eomgen.load(example_path("puma560_dh")).info)["convention"] == "standard"
    yml = write(tmp_path, "links:\n  - name: a\njoints: []\n", "single.yml")
    model = eomgen.load(yml)
    assert model.dof == 0 and model.root == "a" and model.name == "single"
    with pytest.raises(DescriptionError, match="cannot tell which format"):
        eomgen.load(write(tmp_path, "name: x\n"))


# ----------------------------------------------------------------------------------------------
# Bad input: one line, naming the file and the element
# ----------------------------------------------------------------------------------------------

ARM = """\
name: arm
parameters:
  l1: {value: 1.0}
links:
  - name: base
  - name: link1
    mass: 1.0
    com: [0.5, 0, 0]
    inertia: {ixx: 0.1, iyy: 0.1, izz: 0.1}
joints:
  - name: joint1
    type: revolute
    parent: base
    child: link1
    origin: {xyz: [0, 0, l1]}
"""


def arm(old: str, new: str) -> str:
    assert old in ARM
    return ARM.replace(old, new)


DH = """\
convention: standard
dh:
  - {a: 1, alpha: 0, mass: 1}
  - {a: 1, alpha: pi/2}
"""

BILLION_LAUGHS = "\n".join(
    ['links: [{name: base}]', 'joints: []', 'a: &a ["lol","lol","lol","lol","lol","lol","lol"]']
    + [f"{c}: &{c} [{', '.join(['*' + p] * 9)}]" for p, c in zip("abcdefgh", "bcdefghi")]) + "\n"

BAD_INPUT = {
    "malformed yaml": (arm("    com: [0.5, 0, 0]", "    com: [0.5, 0, 0"),
                       r"not valid YAML: .*line \d+"),
    "unknown key": (arm("    mass: 1.0", "    mas: 1.0"),
                    r"links\[1\] 'link1': unknown key 'mas' .*did you mean 'mass'"),
    "unknown top-level key": (ARM + "gravty: [0, 0, -9.81]\n",
                              r"robot: unknown key 'gravty'.*did you mean 'gravity'"),
    "missing child": (arm("    child: link1\n", ""),
                      r"joints\[0\] 'joint1': missing required key 'child'"),
    "negative mass": (arm("mass: 1.0", 'mass: "-1"'), r"link 'link1' inertial: mass .* negative"),
    "python in mass": (arm("mass: 1.0", "mass: \"__import__('os')\""),
                       r"links\[1\] 'link1' mass: unsupported syntax"),
    "function call": (arm("xyz: [0, 0, l1]", "xyz: [0, 0, exp(l1)]"),
                      r"joints\[0\] 'joint1' origin xyz\[2\]: unsupported syntax"),
    "attribute access": (arm("xyz: [0, 0, l1]", "xyz: [0, 0, l1.real]"),
                         r"joints\[0\] 'joint1' origin xyz\[2\]: unsupported syntax"),
    "undeclared symbol": (arm("com: [0.5, 0, 0]", "com: [lc1, 0, 0]"),
                          r"links\[1\] 'link1' com\[0\]: symbol 'lc1' is not declared"),
    "wrong type com": (arm("com: [0.5, 0, 0]", "com: 0.5"),
                       r"links\[1\] 'link1' com: expected a list of 3 values"),
    "com with 2 values": (arm("com: [0.5, 0, 0]", "com: [0.5, 0]"),
                          r"links\[1\] 'link1' com: expected a list of 3 values.*2 entries"),
    "inertia typo": (arm("ixx: 0.1", "ixxx: 0.1"),
                     r"links\[1\] 'link1' inertia: unknown key 'ixxx'.*did you mean 'ixx'"),
    "inertia not psd": (arm("ixx: 0.1", "ixx: -0.5"), r"link 'link1' inertial: .*negative"),
    "bad joint type": (arm("type: revolute", "type: revolut"),
                       r"joints\[0\] 'joint1' type: 'revolut' is not one of"),
    "floating joint": (arm("type: revolute", "type: floating"), r"floating joints are not"),
    "unknown parent": (arm("parent: base", "parent: bse"), r"parent link 'bse' is not defined"),
    "com without mass": (arm("    mass: 1.0\n", ""), r"links\[1\] 'link1': 'com' given without"),
    "name with space": (arm("- name: link1", "- name: link 1"), r"links\[1\] name: name 'link 1'"),
    "duplicate key": (arm("    mass: 1.0\n", "    mass: 1.0\n    mass: 2.0\n"),
                      r"not valid YAML: duplicate key 'mass' at line 8"),
    "imaginary value": (arm("xyz: [0, 0, l1]", 'xyz: ["sqrt(-1)", 0, l1]'),
                        r"joints\[0\] 'joint1' origin xyz\[0\]: 'sqrt\(-1\)' is not a finite real"),
    "infinite value": (arm("xyz: [0, 0, l1]", 'xyz: [0, "tan(pi/2)", l1]'),
                       r"joints\[0\] 'joint1' origin xyz\[1\]: 'tan\(pi/2\)' is not a finite"),
    "complex parameter value": (arm("l1: {value: 1.0}", "l1: {value: (-2)**0.5}"),
                                r"parameters 'l1' value: .* is not a finite real number"),
    "nan value": (arm("mass: 1.0", "mass: .nan"), r"links\[1\] 'link1' mass: .*not a finite"),
    "boolean value": (arm("mass: 1.0", "mass: true"), r"links\[1\] 'link1' mass: True is not"),
    "parameter with symbol value": (arm("l1: {value: 1.0}", "l1: {value: 2*m}"),
                                    r"parameters 'l1' value: expected a number"),
    "reserved parameter": (arm("l1: {value: 1.0}", "q1: {value: 1.0}\n  l1: 1"),
                           r"parameters 'q1': .*reserved for joint variables"),
    "parameter typo": (arm("l1: {value: 1.0}", "l1: {valeu: 1.0}"),
                       r"parameters 'l1': unknown key 'valeu'.*did you mean 'value'"),
    "top level list": ("- links\n- joints\n", r"document must be a mapping"),
    "empty file": ("", r"empty document"),
    "links not list": (arm("links:\n  - name: base\n  - name: link1\n    mass: 1.0\n"
                           "    com: [0.5, 0, 0]\n    inertia: {ixx: 0.1, iyy: 0.1, izz: 0.1}\n",
                           "links: base\n"),
                       r"links: expected a list, got a string"),
    "deep nesting": ("links: " + "[" * 60 + "]" * 60 + "\njoints: []\n",
                     r"nested deeper than 32"),
    "alias bomb": (BILLION_LAUGHS, r"aliases \(\*name\) are not allowed"),
    "wrong convention": (DH.replace("standard", "craig"),
                         r"convention: 'craig' is not one of: standard, modified"),
    "missing convention": (DH.replace("convention: standard\n", ""),
                           r"robot: missing required key 'convention'"),
    "empty dh": ("convention: modified\ndh: []\n", r"dh: the list is empty"),
    "dh not a list": ("convention: modified\ndh: {a: 1}\n", r"dh: expected a list, got a mapping"),
    "dh row not a mapping": ("convention: modified\ndh:\n  - 1\n",
                             r"dh\[0\]: expected a mapping, got a number"),
    "dh row typo": (DH.replace("alpha: pi/2", "alpah: pi/2"),
                    r"dh\[1\] 'joint2': unknown key 'alpah'.*did you mean 'alpha'"),
    "dh bad expression": (DH.replace("alpha: pi/2", "alpha: pi/"),
                          r"dh\[1\] 'joint2' alpha: cannot parse 'pi/'"),
    "dh undeclared": (DH.replace("alpha: pi/2", "alpha: t2"),
                      r"dh\[1\] 'joint2' alpha: symbol 't2' is not declared"),
    "dh bad type": (DH.replace("{a: 1, alpha: 0", "{type: spherical, a: 1, alpha: 0"),
                    r"dh\[0\] 'joint1' type: 'spherical' is not one of: revolute, prismatic"),
    "dh negative mass": (DH.replace("mass: 1", "mass: -1"), r"link 'link1' inertial: mass"),
    "dh inertia without mass": (DH.replace("alpha: pi/2}", "alpha: pi/2, inertia: {izz: 1}}"),
                                r"dh\[1\] 'joint2': 'inertia' given without 'mass'"),
    "dh duplicate joint name": (DH.replace("{a: 1, alpha: 0", "{name: joint2, a: 1, alpha: 0"),
                                r"joint 'joint2'.*duplicate joint name"),
}


@pytest.mark.parametrize("case", sorted(BAD_INPUT))
def test_bad_input_is_one_line_naming_file_and_element(tmp_path, case):
    text, pattern = BAD_INPUT[case]
    path = write(tmp_path, text)
    loader = dh.load if "dh:" in text else yaml_format.load
    start = time.perf_counter()
    with pytest.raises(DescriptionError) as info:
        loader(path)
    assert time.perf_counter() - start < 2.0
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith(f"{path}: "), message
    assert re.search(pattern, message), message
    if case == "floating joint":
        assert isinstance(info.value, UnsupportedError)


def test_valid_arm_template_loads(tmp_path):
    """The base of the bad-input cases is itself valid (so each case fails for its reason)."""
    model = yaml_format.load(write(tmp_path, ARM))
    assert model.joint_names == ("joint1",)
    assert model.joints[0].origin.translation == (0, 0, parameter_symbol("l1"))
    assert dh.load(write(tmp_path, DH, "dh.yaml")).dof == 2


def test_alias_bomb_through_load_is_refused_quickly(tmp_path):
    path = write(tmp_path, BILLION_LAUGHS)
    start = time.perf_counter()
    with pytest.raises(DescriptionError, match="aliases"):
        eomgen.load(path)
    assert time.perf_counter() - start < 1.0


def test_node_count_is_bounded(tmp_path, monkeypatch):
    monkeypatch.setattr(_yaml, "MAX_NODES", 50)
    text = "links:\n" + "".join(f"  - name: l{i}\n" for i in range(40)) + "joints: []\n"
    with pytest.raises(DescriptionError, match="more than 50 nodes"):
        yaml_format.load(write(tmp_path, text))


def test_large_file_is_refused(tmp_path):
    path = write(tmp_path, "links: []\njoints: []\n# " + "x" * (_yaml.MAX_BYTES + 10) + "\n")
    with pytest.raises(DescriptionError, match="larger than"):
        yaml_format.load(path)


def test_not_utf8(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_bytes(b"links: []\njoints: []\nname: \xff\xfe\n")
    with pytest.raises(DescriptionError, match="not UTF-8"):
        yaml_format.load(path)


# ----------------------------------------------------------------------------------------------
# The documentation's examples load as documented
# ----------------------------------------------------------------------------------------------


def doc_examples() -> list[str]:
    blocks = re.findall(r"```yaml\n(.*?)```", DOCS.read_text(encoding="utf-8"), re.S)
    return [b for b in blocks if dh.sniff(b) or yaml_format.sniff(b)]


def test_docs_examples_load(tmp_path):
    examples = doc_examples()
    assert len(examples) == 3
    models = {}
    for i, text in enumerate(examples):
        model = eomgen.load(write(tmp_path, text, f"doc{i}.yaml"))
        models[model.name] = model
    bundled = eomgen.load(example_path("planar_2link"))
    # the docs show the bundled file
    assert dataclasses.replace(models["planar_2link"], source=bundled.source) == bundled
    # the docs' standard and modified two-link tables describe the same robot
    std, mod = models["two_link_dh"].with_numeric_parameters(), \
        models["two_link_mdh"].with_numeric_parameters()
    for q in np.random.default_rng(3).uniform(-3, 3, size=(3, 2)):
        a, b = world_com_and_inertia(std, q), world_com_and_inertia(mod, q)
        for link in ("link1", "link2"):
            np.testing.assert_allclose(a[link][0], b[link][0], atol=1e-12)


@pytest.mark.parametrize("name", sorted(EXAMPLES))
def test_every_bundled_robot_loads_without_a_warning(name):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        eomgen.load(example_path(name))
