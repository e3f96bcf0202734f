"""Independent references for the tests: Pinocchio models built from a RobotModel, a URDF
writer (so Pinocchio's own URDF reader can check our frame conventions), and random robots.

Import from a test module as ``from support.reference import ...`` (see :mod:`support`).
"""

from __future__ import annotations

import math
from dataclasses import replace
from xml.sax.saxutils import quoteattr

import numpy as np
import sympy as sp

from eomgen.model import (
    Inertial,
    Joint,
    JointType,
    Link,
    RobotModel,
    Transform,
    build_model,
    scalar,
    vec3,
)

# ----------------------------------------------------------------------------------------------
# RobotModel → numbers
# ----------------------------------------------------------------------------------------------


def _numeric(model: RobotModel) -> RobotModel:
    return model.with_numeric_parameters() if model.free_symbols else model


def _vec(v) -> np.ndarray:
    return np.array([float(x) for x in v], dtype=float)


def _mat(m) -> np.ndarray:
    return np.array([[float(x) for x in row] for row in m], dtype=float)


def _transform(t: Transform) -> tuple[np.ndarray, np.ndarray]:
    return _mat(t.rotation), _vec(t.translation)


# ----------------------------------------------------------------------------------------------
# Pinocchio
# ----------------------------------------------------------------------------------------------


def _depth_first(model: RobotModel) -> list[Joint]:
    """Joints in depth-first preorder (siblings in description order). Pinocchio needs this
    numbering: its CRBA assumes every subtree occupies a contiguous range of joint indices."""
    children: dict[str, list[Joint]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint)
    order: list[Joint] = []

    def visit(link: str) -> None:
        for joint in children.get(link, []):
            order.append(joint)
            visit(joint.child)

    visit(model.root)
    return order


def to_pinocchio(model: RobotModel):
    """A ``pinocchio.Model`` built joint by joint from ``model`` (not through URDF text).

    Every movable joint becomes a ``JointModelRevoluteUnaligned`` or
    ``JointModelPrismaticUnaligned`` about its axis, placed at the composite of the fixed
    transforms from its last movable ancestor's frame (or the root) to its origin. Every link's
    inertia is appended to the Pinocchio joint it is rigidly attached to, at the composite
    placement; links attached to the root (universe) are left out. Every non-root link also
    becomes a BODY frame with its own name, for forward-kinematics checks. Gravity is the
    model's (in the root frame). Parameters take their default values.

    Returns
    -------
    pinocchio.Model
        Joints in depth-first preorder of the tree; map ``q`` with :func:`pin_q_order`.
    """
    import pinocchio as pin

    model = _numeric(model)
    pmodel = pin.Model()
    pmodel.name = model.name
    # link name -> (pinocchio joint id it moves with, SE3 of the link in that joint's frame)
    anchor = {model.root: (0, pin.SE3.Identity())}
    frame_of = {model.root: 0}  # the universe frame stands for the root link
    for joint in _depth_first(model):
        parent_id, T_parent = anchor[joint.parent]
        R, p = _transform(joint.origin)
        T = T_parent * pin.SE3(R, p)
        if joint.type.is_movable:
            axis = _vec(joint.axis)
            jm = (pin.JointModelRevoluteUnaligned(axis) if joint.type.is_revolute
                  else pin.JointModelPrismaticUnaligned(axis))
            jid = pmodel.addJoint(parent_id, jm, T, joint.name)
            jframe = pmodel.addJointFrame(jid, frame_of[joint.parent])
            anchor[joint.child] = (jid, pin.SE3.Identity())
            frame_of[joint.child] = pmodel.addBodyFrame(joint.child, jid, pin.SE3.Identity(),
                                                        jframe)
        else:
            anchor[joint.child] = (parent_id, T)
            frame_of[joint.child] = pmodel.addBodyFrame(joint.child, parent_id, T,
                                                        frame_of[joint.parent])
    for link in model.links:
        jid, T = anchor[link.name]
        if link.inertial is None or jid == 0:
            continue
        inertial = link.inertial
        Y = pin.Inertia(float(inertial.mass), _vec(inertial.com), _mat(inertial.inertia))
        pmodel.appendBodyToJoint(jid, Y, T)
    pmodel.gravity = pin.Motion(_vec(model.gravity), np.zeros(3))
    return pmodel


def pinocchio_free_motion(pm, q0, v0, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """Pinocchio's free motion (τ = 0) of model ``pm`` from ``(q0, v0)``: ``(q, v)`` after
    ``duration`` seconds, by SciPy's DOP853 (rtol = atol = 1e-11) on ``aba``, with q̇ a central
    difference of ``pinocchio.integrate`` (error ~1e-12) and every quaternion (a joint with
    nq = nv + 1) normalised where it is read and at the end."""
    import pinocchio as pin
    from scipy.integrate import solve_ivp

    quaternions = [slice(j.idx_q + j.nq - 4, j.idx_q + j.nq) for j in pm.joints[1:]
                   if j.nq == j.nv + 1]
    data, zero, nq = pm.createData(), np.zeros(pm.nv), pm.nq

    def unit(q):
        q = q.copy()
        for k in quaternions:
            q[k] /= np.linalg.norm(q[k])
        return q

    def rhs(t, z):
        q, v, eps = unit(z[:nq]), z[nq:], 1e-6
        qdot = (pin.integrate(pm, q, eps * v) - pin.integrate(pm, q, -eps * v)) / (2 * eps)
        return np.concatenate([qdot, pin.aba(pm, data, q, v, zero)])

    end = solve_ivp(rhs, (0.0, duration), np.concatenate([q0, v0]), method="DOP853",
                    rtol=1e-11, atol=1e-11).y[:, -1]
    return unit(end[:nq]), end[nq:]


def pin_q_order(model: RobotModel, pmodel) -> np.ndarray:
    """Permutation between our joint order and Pinocchio's, matched by joint name.

    Returns
    -------
    perm : (n,) int array
        ``perm[k]`` is the index in our ``q`` (``model.joint_names`` order) of Pinocchio's
        k-th coordinate: ``q_pin = q[perm]`` and ``tau = np.empty(n); tau[perm] = tau_pin``
        (``M = M_pin[np.ix_(inv, inv)]`` with ``inv = np.argsort(perm)``).

    Raises
    ------
    ValueError
        When a Pinocchio joint has nq != 1 or nv != 1 (e.g. a continuous joint read from
        URDF), or the joint names do not match one to one.
    """
    ours = {name: k for k, name in enumerate(model.joint_names)}
    perm = np.full(pmodel.nv, -1, dtype=int)
    for jid in range(1, pmodel.njoints):
        name = pmodel.names[jid]
        jm = pmodel.joints[jid]
        if jm.nq != 1 or jm.nv != 1:
            raise ValueError(f"pinocchio joint '{name}' has nq={jm.nq}, nv={jm.nv}; expected 1")
        if name not in ours:
            raise ValueError(f"pinocchio joint '{name}' is not a movable joint of the model")
        perm[jm.idx_q] = ours[name]
    if pmodel.nq != len(ours) or sorted(perm) != list(range(len(ours))):
        raise ValueError("joint names of the two models do not match one to one")
    return perm


# ----------------------------------------------------------------------------------------------
# URDF writer (to let Pinocchio's URDF reader interpret our conventions independently)
# ----------------------------------------------------------------------------------------------


def _rpy_from_rotation(R: np.ndarray) -> tuple[float, float, float]:
    """URDF roll-pitch-yaw with ``R = Rz(yaw) Ry(pitch) Rx(roll)``."""
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    if math.hypot(R[0, 0], R[1, 0]) < 1e-12:  # gimbal lock: put everything in roll
        return math.atan2(-R[1, 2], R[1, 1]), pitch, 0.0
    return math.atan2(R[2, 1], R[2, 2]), pitch, math.atan2(R[1, 0], R[0, 0])


def _fmt(values) -> str:
    return " ".join(repr(float(v)) for v in values)


_INERTIA_ENTRIES = (("ixx", (0, 0)), ("ixy", (0, 1)), ("ixz", (0, 2)),
                    ("iyy", (1, 1)), ("iyz", (1, 2)), ("izz", (2, 2)))


def to_urdf(model: RobotModel) -> str:
    """URDF text of ``model`` (numbers at the default parameter values, full precision).

    Continuous joints are written as revolute with wide limits so that Pinocchio gives them one
    coordinate; gravity is not part of URDF and must be set on the result separately.
    """
    model = _numeric(model)
    out = [f"<robot name={quoteattr(model.name)}>"]
    for link in model.links:
        if link.inertial is None:
            out.append(f"  <link name={quoteattr(link.name)}/>")
            continue
        i = link.inertial
        I = _mat(i.inertia)
        out += [
            f"  <link name={quoteattr(link.name)}>",
            "    <inertial>",
            f"      <origin xyz=\"{_fmt(_vec(i.com))}\" rpy=\"0 0 0\"/>",
            f"      <mass value=\"{float(i.mass)!r}\"/>",
            "      <inertia " + " ".join(
                f"{name}=\"{float(I[r, c])!r}\"" for name, (r, c) in _INERTIA_ENTRIES) + "/>",
            "    </inertial>",
            "  </link>",
        ]
    for j in model.joints:
        R, p = _transform(j.origin)
        kind = {JointType.CONTINUOUS: "revolute"}.get(j.type, j.type.value)
        out += [
            f"  <joint name={quoteattr(j.name)} type=\"{kind}\">",
            f"    <parent link={quoteattr(j.parent)}/>",
            f"    <child link={quoteattr(j.child)}/>",
            f"    <origin xyz=\"{_fmt(p)}\" rpy=\"{_fmt(_rpy_from_rotation(R))}\"/>",
        ]
        if j.type.is_movable:
            out += [
                f"    <axis xyz=\"{_fmt(_vec(j.axis))}\"/>",
                "    <limit lower=\"-100\" upper=\"100\" effort=\"1\" velocity=\"1\"/>",
            ]
        out.append("  </joint>")
    out.append("</robot>")
    return "\n".join(out) + "\n"


# ----------------------------------------------------------------------------------------------
# Random robots
# ----------------------------------------------------------------------------------------------


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    """A uniformly distributed rotation matrix (QR of a Gaussian matrix, sign-fixed)."""
    Q, Rr = np.linalg.qr(rng.standard_normal((3, 3)))
    Q = Q * np.sign(np.diag(Rr))
    if np.linalg.det(Q) < 0:
        Q[:, 0] = -Q[:, 0]
    return Q


def random_inertial(rng: np.random.Generator) -> Inertial:
    """A physical rigid body: random mass, centre of mass, and the inertia of a random box
    (principal moments obey the triangle inequality) in random principal axes."""
    m = float(rng.uniform(0.1, 5.0))
    a, b, c = rng.uniform(0.02, 0.6, size=3)
    principal = m / 12.0 * np.array([b * b + c * c, a * a + c * c, a * a + b * b])
    Q = random_rotation(rng)
    I = Q @ np.diag(principal) @ Q.T
    I = 0.5 * (I + I.T)
    com = rng.uniform(-0.3, 0.3, size=3)
    return Inertial(scalar(m), vec3(com.tolist()), tuple(vec3(r) for r in I.tolist()))


def _random_axis(rng: np.random.Generator) -> list[float]:
    if rng.random() < 0.25:  # sometimes exactly a coordinate axis, either sign
        axis = [0.0, 0.0, 0.0]
        axis[int(rng.integers(3))] = float(rng.choice([-1.0, 1.0]))
        return axis
    v = rng.standard_normal(3)
    return (v / np.linalg.norm(v)).tolist()


def _random_origin(rng: np.random.Generator) -> Transform:
    xyz = rng.uniform(-0.5, 0.5, size=3).tolist()
    rpy = rng.uniform(-math.pi, math.pi, size=3).tolist()
    return Transform.from_xyz_rpy(xyz, rpy)


def random_robot(
    rng: np.random.Generator,
    n_joints: int,
    tree: bool = False,
    prismatic: bool = True,
    fixed_links: bool = True,
) -> RobotModel:
    """A random robot with ``n_joints`` movable joints, built with :func:`build_model`.

    Parameters
    ----------
    rng : numpy.random.Generator
    n_joints : int
        Number of movable joints (the dof).
    tree : bool
        Attach each new joint to a random existing link (branches) instead of the last one.
    prismatic : bool
        Make about a third of the joints prismatic.
    fixed_links : bool
        Insert fixed joints: sometimes before a movable joint (an offset link), sometimes as a
        leaf (a tool); fixed links may carry mass.

    Notes
    -----
    Joint axes point in random directions (sometimes exactly ±x/y/z), origins have random
    xyz and rpy, about one link in six is massless, and the joints (and links) are listed in
    shuffled order, so ``q`` order differs from tree order. Gravity is a random vector of
    length 9.81 in the root frame.
    """
    links = [Link("base", random_inertial(rng) if rng.random() < 0.5 else None)]
    joints: list[Joint] = []
    chain_tip = "base"

    def new_link(name: str) -> Link:
        return Link(name, None if rng.random() < 1 / 6 else random_inertial(rng))

    for k in range(n_joints):
        parent = links[int(rng.integers(len(links)))].name if tree else chain_tip
        if fixed_links and rng.random() < 0.3:
            offset = f"offset{k}"
            links.append(new_link(offset))
            joints.append(Joint(f"fixed{k}", JointType.FIXED, parent, offset,
                                _random_origin(rng)))
            parent = offset
        if prismatic and rng.random() < 1 / 3:
            kind = JointType.PRISMATIC
        else:
            kind = JointType.REVOLUTE if rng.random() < 0.5 else JointType.CONTINUOUS
        child = f"link{k}"
        links.append(new_link(child))
        joints.append(Joint(f"joint{k}", kind, parent, child, _random_origin(rng),
                            vec3(_random_axis(rng))))
        chain_tip = child
        if fixed_links and rng.random() < 0.2:
            tool = f"tool{k}"
            links.append(new_link(tool))
            joints.append(Joint(f"tool_fixed{k}", JointType.FIXED, child, tool,
                                _random_origin(rng)))
    order = rng.permutation(len(joints))
    link_order = rng.permutation(len(links))
    g = rng.standard_normal(3)
    g = 9.81 * g / np.linalg.norm(g)
    kind = "tree" if tree else "chain"
    return build_model(
        "<random>", f"random_{kind}_{n_joints}",
        [links[i] for i in link_order],
        [joints[i] for i in order],
        gravity=g.tolist(),
    )


def massive_tree(seed: int, joints: int) -> RobotModel:
    """A random tree (:func:`random_robot` with branches) whose links all carry mass, so that
    M stays positive definite with a floating base above its root."""
    rng = np.random.default_rng(seed)
    fixed = random_robot(rng, joints, tree=True)
    links = tuple(replace(link, inertial=random_inertial(rng)) if link.inertial is None
                  or link.name == fixed.root else link for link in fixed.links)
    return replace(fixed, links=links)


def planar_2link_by_hand():
    """The textbook closed form of the planar two-link arm's regressor, derived by hand
    (Lagrange) with every parameter about its joint's origin, body axes (x along the link),
    gravity γ along −y: body 2's point (x, y) sits at l1 e(q1) + R(q1 + q2) (x, y), so

        τ1 = ZZ1 q̈1 + MX1 γ c1 − MY1 γ s1 + M2 (l1² q̈1 + l1 γ c1) + ZZ2 (q̈1 + q̈2)
             + MX2 (l1 ((2 q̈1 + q̈2) c2 − (2 q̇1 q̇2 + q̇2²) s2) + γ c12)
             − MY2 (l1 ((2 q̈1 + q̈2) s2 + (2 q̇1 q̇2 + q̇2²) c2) + γ s12)
        τ2 = ZZ2 (q̈1 + q̈2) + MX2 (l1 (q̈1 c2 + q̇1² s2) + γ c12)
             + MY2 (l1 (q̇1² c2 − q̈1 s2) − γ s12)

    Returns the non-zero columns {name: (row 1, row 2)} and the symbols used."""
    q1, q2, qd1, qd2, qdd1, qdd2, l1, g = sp.symbols("q1 q2 qd1 qd2 qdd1 qdd2 l1 g", real=True)
    s1, c1, s2, c2 = sp.sin(q1), sp.cos(q1), sp.sin(q2), sp.cos(q2)
    s12, c12 = sp.sin(q1 + q2), sp.cos(q1 + q2)
    a, v = 2 * qdd1 + qdd2, 2 * qd1 * qd2 + qd2 ** 2
    columns = {
        "MX1": (g * c1, 0), "MY1": (-g * s1, 0), "ZZ1": (qdd1, 0),
        "M2": (l1 ** 2 * qdd1 + l1 * g * c1, 0),
        "MX2": (l1 * (a * c2 - v * s2) + g * c12, l1 * (qdd1 * c2 + qd1 ** 2 * s2) + g * c12),
        "MY2": (-l1 * (a * s2 + v * c2) - g * s12, l1 * (qd1 ** 2 * c2 - qdd1 * s2) - g * s12),
        "ZZ2": (qdd1 + qdd2, qdd1 + qdd2),
    }
    return columns, (q1, q2), l1


def pinocchio_contacts(pm, pd, frames, kind: str = "point"):
    """Pinocchio's ``(RigidConstraintModel list, RigidConstraintData list)`` holding each of
    ``frames`` of ``pm``: a point contact (CONTACT_3D, world-aligned axes) or a surface contact
    (CONTACT_6D, the frame's own axes), eomgen's conventions (docs/contact.md); its
    constraint dynamics initialised on ``pd``."""
    import pinocchio as pin

    ctype, reference = ((pin.ContactType.CONTACT_3D, pin.LOCAL_WORLD_ALIGNED) if kind == "point"
                        else (pin.ContactType.CONTACT_6D, pin.LOCAL))
    models = pin.StdVec_RigidConstraintModel()
    for name in frames:
        frame = pm.frames[pm.getFrameId(name)]
        models.append(pin.RigidConstraintModel(ctype, pm, frame.parentJoint, frame.placement,
                                               reference))
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm, pd, models, datas)
    return models, datas
