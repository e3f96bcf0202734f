"""The kinematic tree of a compiled MuJoCo model: bodies → links, hinge/slide joints → joints,
the free joint → the quaternion free flyer (conventions in :mod:`eomgen.parsers.mjcf`).

MuJoCo places a body at ``X(q) = X_pb · J_1(q_1) ⋯ J_k(q_k)``: its pose as written in its
parent (``body_pos``, ``body_quat``) followed by its joints in order, each in the body's local
axes, ``J = Tr(p) · Rot(a, q − ref) · Tr(−p)`` for a hinge at anchor ``p`` and
``J = Tr(a (q − ref))`` for a slide. eomgen's joints rotate about their frame's origin, so each
joint gets the frame ``Tr(p) · Rot(a, −ref)`` after what precedes it, and the offset ``Tr(−p)``
moves on to the next joint (or to the body, through the fixed joint ``<body>_anchor``).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ...errors import KinematicTreeError, UnsupportedError
from ...model.floating import add_free_flyer, quaternion_matrix
from ...model import (
    Actuator,
    BallSpring,
    Spring,
    Notice,
    NoticeKind,
    Inertial,
    Joint,
    JointType,
    Link,
    RobotModel,
    Transform,
    build_model,
    check_tree,
    scalar,
    snap,
    vec3,
)

#: MuJoCo's joint types (``mjtJoint``, stable since MuJoCo 2).
FREE, BALL, SLIDE, HINGE = 0, 1, 2, 3
#: The world body's link (MuJoCo's body 0, always named ``world``).
WORLD = "world"
#: MuJoCo's wrap type of a joint in a fixed tendon (``mjWRAP_JOINT``).
_WRAP_JOINT = 1


def disabled(m, flag: str) -> bool:
    """Whether ``<option><flag NAME="disable">`` is set: ``flag`` is the ``mjDSBL_`` suffix
    (``"GRAVITY"``, ``"DAMPER"``); the bit is looked up in MuJoCo (it moved between
    versions)."""
    import mujoco  # an optional dependency, present whenever a compiled model is

    return bool(m.opt.disableflags & int(getattr(mujoco.mjtDisableBit, f"mjDSBL_{flag}")))


def body_names(m) -> list[str]:
    """MuJoCo's body names; an unnamed body ``i`` is ``body<i>`` (made unique)."""
    return _names([m.body(i).name for i in range(m.nbody)], "body")


def joint_names(m) -> list[str]:
    """MuJoCo's joint names; an unnamed joint ``i`` is ``joint<i>`` (made unique)."""
    return _names([m.joint(i).name for i in range(m.njnt)], "joint")


def _names(given: list[str], prefix: str) -> list[str]:
    taken = {name for name in given if name}
    out = []
    for i, name in enumerate(given):
        if not name:
            name = _unique(f"{prefix}{i}", taken)
            taken.add(name)
        out.append(name)
    return out


def _unique(name: str, taken: set[str]) -> str:
    """``name``, or ``name_2``, ``name_3``, … the first not in ``taken``."""
    if name not in taken:
        return name
    k = 2
    while f"{name}_{k}" in taken:
        k += 1
    return f"{name}_{k}"


def rotation_of_quaternion(wxyz) -> np.ndarray:
    """The rotation matrix of MuJoCo's quaternion ``(w, x, y, z)`` (normalised first)."""
    w, x, y, z = np.asarray(wxyz, dtype=float)
    return quaternion_matrix((x, y, z, w))


def _axis_rotation(axis, angle: float) -> np.ndarray:
    x, y, z = axis
    c, s = math.cos(angle), math.sin(angle)
    t = 1 - c
    return np.array([[t * x * x + c, t * x * y - s * z, t * x * z + s * y],
                     [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
                     [t * x * z - s * y, t * y * z + s * x, t * z * z + c]])


def _transform(R: np.ndarray, p: np.ndarray, what: str) -> Transform:
    """The model's transform of the float pose ``(R, p)``, rotation entries snapped."""
    rotation = tuple(tuple(snap(float(R[i, k]), f"{what} rotation") for k in range(3))
                     for i in range(3))
    return Transform(rotation, vec3(float(v) for v in p))


def _inertial(m, body: int) -> Inertial | None:
    mass = float(m.body_mass[body])
    moments = np.asarray(m.body_inertia[body], dtype=float)
    if mass == 0 and not moments.any():
        return None
    R = rotation_of_quaternion(m.body_iquat[body])
    if np.array_equal(R, np.eye(3)):
        inertia = np.diag(moments)
    else:
        inertia = R @ np.diag(moments) @ R.T
        inertia = (inertia + inertia.T) / 2
    return Inertial(scalar(mass), vec3(float(v) for v in m.body_ipos[body]),
                    tuple(tuple(scalar(float(v)) for v in row) for row in inertia))


def _actuator(m, joint: int) -> Actuator | None:
    """The drive of a joint from its first dof's armature, damping and frictionloss (a free
    joint's are the same on its six dofs, a ball joint's on its three: eomgen gives the drive
    to each of the ball joint's velocity coordinates), with the
    ``armature`` and ``damping`` of the actuators on it times ``gear²`` (MuJoCo 4's
    ``mj_actuatorArmature``, ``mj_actuatorDamping``)."""
    dof = int(m.jnt_dofadr[joint])
    armature, damping = actuator_inertia(m, joint, (0, 1))
    values = {"armature": float(m.dof_armature[dof]) + armature,
              "damping": 0.0 if disabled(m, "DAMPER") else float(m.dof_damping[dof]) + damping,
              "friction": 0.0 if disabled(m, "FRICTIONLOSS") else float(m.dof_frictionloss[dof])}
    if not any(values.values()):
        return None
    return Actuator(**values)


def actuator_count(m) -> int:
    """The number of actuators of ``m``: MuJoCo 4's ``nactuator`` (its ``nu`` counts the
    controls, several for an actuator with several inputs: a PID's ``pos vel``), ``nu``
    before."""
    return int(getattr(m, "nactuator", m.nu))


def actuator_inertia(m, target: int, transmissions) -> tuple[float, float]:
    """``(Σ gear² armature, Σ gear² damping)`` of the actuators whose transmission is one of
    ``transmissions`` (MuJoCo's ``mjTRN_*`` codes) on ``target`` (a joint or a tendon id):
    what MuJoCo adds to its armature and damping (``actuator_armature``, ``actuator_damping``,
    MuJoCo 4; zero before)."""
    armature = damping = 0.0
    for k in range(actuator_count(m)):
        if int(m.actuator_trntype[k]) in transmissions and int(m.actuator_trnid[k, 0]) == target:
            gear2 = float(m.actuator_gear[k, 0]) ** 2
            armature += gear2 * float(getattr(m, "actuator_armature", np.zeros(actuator_count(m)))[k])
            damping += gear2 * float(getattr(m, "actuator_damping", np.zeros(actuator_count(m)))[k])
    return armature, damping


def _spring(m, joint: int) -> Spring | BallSpring | None:
    """The spring of a hinge or slide joint: ``−stiffness (q − qpos_spring)``; of a ball
    joint, MuJoCo's ``−stiffness · subQuat(q, qpos_spring)`` (:class:`~eomgen.model.
    BallSpring`, the reference in eomgen's ``(x, y, z, w)`` order); none when the ``spring``
    flag is disabled."""
    k = float(m.jnt_stiffness[joint])
    kind = int(m.jnt_type[joint])
    if not k or disabled(m, "SPRING") or kind not in (HINGE, SLIDE, BALL):
        return None
    adr = int(m.jnt_qposadr[joint])
    if kind == BALL:
        w, x, y, z = (float(v) for v in m.qpos_spring[adr:adr + 4])
        return BallSpring(k, (x, y, z, w))
    return Spring(k, float(m.qpos_spring[adr]))


def build_tree(m, source: str) -> RobotModel:
    """The links and joints of the compiled model ``m`` (module docstring), validated by
    :func:`eomgen.model.build_model`, with the free flyer of its free joint if it has one.

    Several free bodies (a robot and a ball): the one with the most joints below it (the
    first of those) flies; the others are dropped with their subtrees, one notice each (a
    free body joined to the rest by nothing but contacts and equalities: the tree's dynamics
    of the rest do not depend on it).

    Raises
    ------
    UnsupportedError
        A free joint with other joints in its body.
    """
    bodies, jnames = body_names(m), joint_names(m)
    kept, dropped = _free_bodies(m)
    taken_links, taken_joints = set(bodies), set(jnames)
    links: list[Link] = [Link(WORLD)]
    joints: list[Joint] = []
    notices = []
    free: tuple[int, int] | None = None  # (body, joint)
    for b in range(1, m.nbody):
        name = bodies[b]
        parent = bodies[int(m.body_parentid[b])]
        R = rotation_of_quaternion(m.body_quat[b])
        p = np.asarray(m.body_pos[b], dtype=float)
        body_joints = list(range(int(m.body_jntadr[b]), int(m.body_jntadr[b])
                                 + int(m.body_jntnum[b])))
        types = [int(m.jnt_type[j]) for j in body_joints]
        if b in dropped:
            if FREE in types:
                notices.append(_dropped_notice(m, source, b, dropped, bodies, jnames, kept))
            continue
        if FREE in types:
            j = body_joints[types.index(FREE)]
            if len(types) > 1:
                raise UnsupportedError(source, f"joint '{jnames[j]}' (free, body '{name}')",
                                       "a free joint with other joints in its body")
            free = (b, j)
            # a placeholder, replaced by the free flyer below
            joints.append(Joint(_unique(f"{name}_free", taken_joints), JointType.FIXED,
                                parent, name))
            links.append(Link(name, _inertial(m, b)))
            continue
        if not body_joints:
            weld = _unique(f"{name}_weld", taken_joints)
            taken_joints.add(weld)
            joints.append(Joint(weld, JointType.FIXED, parent, name,
                                _transform(R, p, f"body '{name}'")))
            links.append(Link(name, _inertial(m, b)))
            continue
        previous = parent
        for k, j in enumerate(body_joints):
            anchor = np.asarray(m.jnt_pos[j], dtype=float)
            axis = np.asarray(m.jnt_axis[j], dtype=float)
            ref = float(m.qpos0[int(m.jnt_qposadr[j])])
            if types[k] == BALL:  # a quaternion joint at its anchor, MuJoCo's axes
                R_j, p_j, kind = R, p + R @ anchor, JointType.SPHERICAL
            elif types[k] == HINGE:
                R_j, p_j = R @ _axis_rotation(axis, -ref), p + R @ anchor
                kind = JointType.CONTINUOUS
            else:
                R_j, p_j = R, p + R @ (anchor - ref * axis)
                kind = JointType.PRISMATIC
            last = k == len(body_joints) - 1
            if last and not anchor.any():
                child = name
            else:
                child = _unique(f"{name}_{jnames[j]}", taken_links)
                taken_links.add(child)
                links.append(Link(child))
            joints.append(Joint(jnames[j], kind, previous, child,
                                _transform(R_j, p_j, f"joint '{jnames[j]}'"),
                                vec3(float(a) for a in axis),
                                _actuator(m, j), spring=_spring(m, j)))
            previous = child
            # what follows is placed from this joint's frame: back from its anchor
            R, p = np.eye(3), -anchor
        if previous != name:
            anchor_joint = _unique(f"{name}_anchor", taken_joints)
            taken_joints.add(anchor_joint)
            joints.append(Joint(anchor_joint, JointType.FIXED, previous, name,
                                _transform(R, p, f"body '{name}'")))
        links.append(Link(name, _inertial(m, b)))
    gravity = [0.0] * 3 if disabled(m, "GRAVITY") else [float(v) for v in m.opt.gravity]
    model = build_model(source, _model_name(m, source), links, joints, gravity=gravity,
                        defer_notices=True)
    if free is not None:
        model = _with_free_flyer(model, m, bodies[free[0]], jnames[free[1]], free[1], source)
    return replace(model, notices=tuple(notices) + tuple(model.notices))


def _free_bodies(m) -> tuple[int | None, set[int]]:
    """``(kept, dropped)``: the free body that flies (the most joints below it, the first of
    those; None without one) and every body in the subtree of another free body."""
    free = [b for b in range(1, m.nbody)
            if FREE in [int(m.jnt_type[j]) for j in range(int(m.body_jntadr[b]),
                                                          int(m.body_jntadr[b])
                                                          + int(m.body_jntnum[b]))]]
    if not free:
        return None, set()
    root_of = {}
    for b in range(1, m.nbody):  # parents come before children in MuJoCo's body order
        parent = int(m.body_parentid[b])
        root_of[b] = b if b in free else root_of.get(parent)
    counts = {f: sum(int(m.body_jntnum[b]) for b in root_of if root_of[b] == f) for f in free}
    kept = max(free, key=lambda f: (counts[f], -f))
    return kept, {b for b, root in root_of.items() if root is not None and root != kept}


def _dropped_notice(m, source, body, dropped, bodies, jnames, kept) -> Notice:
    j = int(m.body_jntadr[body])
    below = [b for b in dropped if b == body or _below(m, b, body)]
    joints = tuple(jnames[k] for b in below for k in range(int(m.body_jntadr[b]),
                                                           int(m.body_jntadr[b])
                                                           + int(m.body_jntnum[b])))
    return Notice(NoticeKind.NOT_MODELLED, source,
                  f"joint '{jnames[j]}' (free, body '{bodies[body]}')",
                  f"a second free body (body '{bodies[kept]}' flies): eomgen models one "
                  "floating base",
                  f"dropped with the {len(below)} bodies and {len(joints)} joints of its "
                  "subtree", links=tuple(bodies[b] for b in below), joints=joints)


def _below(m, b: int, root: int) -> bool:
    while b > 0:
        b = int(m.body_parentid[b])
        if b == root:
            return True
    return False


def _model_name(m, source: str) -> str:
    names = bytes(m.names)
    name = names[:names.index(b"\0")].decode("utf-8", "replace") if b"\0" in names else ""
    return name or source.rsplit("/", 1)[-1].rsplit(".", 1)[0]


def _subtree(model: RobotModel, root: str) -> set[str]:
    """The links at and below ``root``."""
    children: dict[str, list[str]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint.child)
    found, stack = set(), [root]
    while stack:
        link = stack.pop()
        found.add(link)
        stack.extend(children.get(link, []))
    return found


def _with_free_flyer(model: RobotModel, m, body: str, joint: str, index: int,
                     source: str) -> RobotModel:
    """``model`` whose body ``body`` (held by a placeholder fixed joint) flies on the
    quaternion free flyer: its six coordinates first, then the other joints in MuJoCo's
    order."""
    floating = _subtree(model, body)
    placeholder = model.parent_joint[body]
    inside = [j for j in model.joints if j.child in floating and j is not placeholder]
    outside = [j for j in model.joints if j.child not in floating and j is not placeholder]
    sub = replace(model, links=tuple(l for l in model.links if l.name in floating),
                  joints=tuple(inside), root=body)
    try:
        flying = add_free_flyer(sub)
    except KinematicTreeError as exc:
        raise KinematicTreeError(source, f"joint '{joint}' (free, body '{body}')",
                                 exc.problem) from None
    actuator = _actuator(m, index)
    virtual = tuple(replace(j, actuator=actuator) for j in flying.joints[:6])
    links = flying.links + tuple(l for l in model.links
                                 if l.name not in floating and l.name != WORLD)
    joints = virtual + tuple(inside) + tuple(outside)
    check_tree(source, (l.name for l in links), joints)
    return replace(flying, links=links, joints=joints,
                   info=flying.info + (("mujoco_free_joint", joint),))


def element_name(m, kind: str, i: int) -> str:
    """MuJoCo's name of element ``i`` of ``kind`` (``"actuator"``, ``"tendon"``, …), or
    ``<kind><i>`` when it has none."""
    return getattr(m, kind)(i).name or f"{kind}{i}"


def not_modelled(source: str, element: str, problem: str, fallback: str = "",
                 joints: tuple[str, ...] = (), links: tuple[str, ...] = ()) -> Notice:
    """A notice that ``element`` of ``source`` is not modelled: ``problem``, ``fallback``."""
    return Notice(NoticeKind.NOT_MODELLED, source, element, problem, fallback, links, joints)


def tendon_joints(m, t: int) -> tuple[tuple[int, float], ...]:
    """``(joint, coefficient)`` of each joint wrap of tendon ``t``."""
    start, count = int(m.tendon_adr[t]), int(m.tendon_num[t])
    return tuple((int(m.wrap_objid[w]), float(m.wrap_prm[w])) for w in range(start, start + count)
                 if int(m.wrap_type[w]) == _WRAP_JOINT)


def is_fixed(m, t: int) -> bool:
    """Whether tendon ``t`` is a fixed tendon (every wrap a joint)."""
    start, count = int(m.tendon_adr[t]), int(m.tendon_num[t])
    return all(int(m.wrap_type[w]) == _WRAP_JOINT for w in range(start, start + count))
