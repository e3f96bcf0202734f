"""What the dynamics see of a model's masses: joints that move no mass, and inertias that break
the triangle inequality without mattering. The findings a loaded model is left with
(:func:`settled`), one place for the parsers (:func:`eomgen.load`), ``eomgen verify`` and the
scene reports.

**A joint moves no mass** when the bodies after it (everything its motion carries, links fixed
to them included) have no mass and, for a revolute joint, no rotational inertia about its axis:
its row of M(q) is zero, M is singular and forward dynamics fail. With couplings, a coordinate
moves its followers too, and moves no mass when none of them does.

**An inertia that breaks the triangle inequality** (:func:`eomgen.model.check_inertial`) is not a
physical rigid body, but the dynamics may still be those of a physical robot: links fixed to one
another move as one body (their combined inertia is what counts); a body fixed to the world
never moves; and a rotational inertia ``β (E − a aᵀ)`` (no mass) about a revolute joint's axis
``a`` moves across the joint without changing M, C or g (its kinetic energy sees only the
angular velocity across ``a``, which both sides share; a helical joint turns as a revolute one
and a massless inertia does not see its translation; across a prismatic joint, any rotational
inertia moves). In the second moments ``Σ = tr(I)/2 E − I`` (physical ⇔ Σ ⪰ 0) a body takes
``β a aᵀ`` from its parent. Bodies are settled from the leaves up, each taking the least it
needs (taking less never hurts the parent), the world giving whatever is asked: a finding is
kept only for the links of a body that cannot be made physical so. The PUMA 560's published
link 1 (only its moment about joint 1) and link 3 (whose excess link 2 holds) are such bodies.
"""

from __future__ import annotations

import math
from dataclasses import replace

import sympy as sp

from .notices import Notice, NoticeKind
from .parts import Inertial, Joint
from .robot import RobotModel

#: Relative tolerance of "Σ ⪰ 0" and of an axis being parallel to another (as the triangle
#: inequality of :func:`eomgen.model.check_inertial`).
TOLERANCE = 1e-9
#: Relative size below which a moment about an axis is roundoff of zero (a rotated axis).
ROUNDOFF = 1e-12


def _float(x) -> float | None:
    if isinstance(x, sp.Basic) and x.is_number:
        try:
            return float(x)
        except TypeError:
            return None
    return None


def _floats(rows) -> list[list[float]] | None:
    values = [[_float(v) for v in row] for row in rows]
    return None if any(v is None for row in values for v in row) else values


def _children(model: RobotModel) -> dict[str, list[Joint]]:
    children: dict[str, list[Joint]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint)
    return children


def _subtree(children: dict[str, list[Joint]], link: str) -> list[tuple[str, list[Joint]]]:
    """The links from ``link`` down, each with the joints from ``link`` to it."""
    found, stack = [], [(link, [])]
    while stack:
        name, path = stack.pop()
        found.append((name, path))
        stack.extend((j.child, path + [j]) for j in reversed(children.get(name, [])))
    return found


# ----------------------------------------------------------------------------------------------
# Joints that move no mass
# ----------------------------------------------------------------------------------------------

def _carries_nothing(inertial: Inertial | None, joint: Joint, path: list[Joint]) -> bool:
    """Whether a link with ``inertial``, reached from ``joint``'s child through ``path``, adds
    nothing to ``joint``'s row of M: no mass and (revolute) no inertia about the axis, the
    axis being fixed in the link's frame (else: not decided, counted as mass)."""
    if inertial is None:
        return True
    mass = _float(inertial.mass)
    inertia = _floats(inertial.inertia)
    if mass is None or inertia is None or abs(mass) > 0:
        return False
    if not joint.rotates or not any(any(row) for row in inertia):
        return True
    axis = [_float(v) for v in joint.axis]
    for step in path:  # the joint's axis in the frames down to the link
        rotation = _floats(step.origin.rotation)
        if None in axis or rotation is None:
            return False
        axis = [sum(rotation[k][i] * axis[k] for k in range(3)) for i in range(3)]
        if step.rotates:  # turns the frame about its own axis: parallel only
            b = [_float(v) for v in step.axis]
            if None in b or math.dist([0, 0, 0], _cross(axis, b)) > TOLERANCE:
                return False
    if None in axis:
        return False
    scale = max(1.0, max(abs(v) for row in inertia for v in row))
    moment = sum(axis[i] * inertia[i][k] * axis[k] for i in range(3) for k in range(3))
    return abs(moment) <= ROUNDOFF * scale


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def massless_joints(model: RobotModel) -> tuple[tuple[str, tuple[str, ...]], ...]:
    """``(joint, links)`` for each coordinate joint that moves no mass (module docstring), with
    the links its motion carries, in description order."""
    children = _children(model)
    by_name = {j.name: j for j in model.joints}
    links = model.link_by_name
    followers: dict[str, list[str]] = {}
    for coupling in model.couplings:
        for leader, _ in coupling.leaders:
            followers.setdefault(leader, []).append(coupling.follower)
    found = []
    for joint in model.coordinate_joints:
        carried: list[str] = []
        moves_mass = False
        for moved in [joint] + [by_name[f] for f in followers.get(joint.name, [])]:
            for name, path in _subtree(children, moved.child):
                carried.append(name)
                if not _carries_nothing(links[name].inertial, moved, path):
                    moves_mass = True
        if not moves_mass:
            found.append((joint.name, tuple(dict.fromkeys(carried))))
    return tuple(found)


def _named(kind: str, names, most: int = 3) -> str:
    quoted = [f"'{n}'" for n in names]
    more = f" and {len(quoted) - most} more" if len(quoted) > most else ""
    return f"{kind}{'s' if len(quoted) > 1 else ''} " + ", ".join(quoted[:most]) + more


def massless_problem(links: tuple[str, ...]) -> str:
    """What is wrong with a joint that moves no mass, whose motion carries ``links``."""
    carry = "carries" if len(links) == 1 else "carry"
    return (f"moves no mass: {_named('link', links)} after it {carry} no mass (nor inertia "
            "about its axis), so its row of M(q) is zero and forward dynamics fail; give "
            + ("it" if len(links) == 1 else "them") + " an inertial or make the joint fixed")


def massless_notices(model: RobotModel) -> tuple[Notice, ...]:
    """A :attr:`~NoticeKind.NO_MASS` notice for each joint of :func:`massless_joints`."""
    return tuple(Notice(NoticeKind.NO_MASS, model.source, f"joint '{joint}'",
                        massless_problem(links), links=links, joints=(joint,))
                 for joint, links in massless_joints(model))


# ----------------------------------------------------------------------------------------------
# Inertias that break the triangle inequality without mattering
# ----------------------------------------------------------------------------------------------

def physical_bodies(model: RobotModel) -> set[str] | None:
    """The links whose bodies can be made physical without changing the dynamics (module
    docstring); None when a symbolic inertia or pose anywhere leaves it undecided (then every
    finding stays)."""
    import numpy as np  # here: loading a description without such a finding needs no NumPy

    children = _children(model)
    links = model.link_by_name
    # bodies: a moving link (or the root) and the links fixed to it, with their poses
    body_of: dict[str, str] = {}
    members: dict[str, list[tuple[str, np.ndarray, np.ndarray]]] = {}
    order: list[str] = []  # bodies, parents first
    stack = [(model.root, model.root, np.eye(3), np.zeros(3))]
    while stack:
        name, lead, R, p = stack.pop()
        if name == lead:
            order.append(lead)
        body_of[name] = lead
        members.setdefault(lead, []).append((name, R, p))
        for joint in reversed(children.get(name, [])):
            if joint.type.is_movable:
                stack.append((joint.child, joint.child, np.eye(3), np.zeros(3)))
                continue
            rotation = _floats(joint.origin.rotation)
            translation = [_float(v) for v in joint.origin.translation]
            if rotation is None or None in translation:
                return None
            stack.append((joint.child, lead, R @ np.array(rotation),
                          R @ np.array(translation) + p))
    sigma: dict[str, np.ndarray] = {}
    for lead, parts in members.items():
        mass, first, second = 0.0, np.zeros(3), np.zeros((3, 3))
        for name, R, p in parts:
            inertial = links[name].inertial
            if inertial is None:
                continue
            m = _float(inertial.mass)
            com = [_float(v) for v in inertial.com]
            inertia = _floats(inertial.inertia)
            if m is None or None in com or inertia is None:
                return None
            I = R @ np.array(inertia) @ R.T
            c = R @ np.array(com) + p
            mass += m
            first += m * c
            second += np.trace(I) / 2 * np.eye(3) - I + m * np.outer(c, c)
        if mass > 0:
            second -= np.outer(first, first) / mass  # about the body's centre of mass
        sigma[lead] = second
    parent_joint = model.parent_joint
    ok: dict[str, bool] = {model.root: True}  # physical once it took what it needs
    took: dict[str, bool] = {}
    for lead in reversed(order[1:]):  # leaves first: each body takes the least it needs
        S = sigma[lead]
        joint = parent_joint[lead]
        parent = body_of[joint.parent]
        R = next(R for name, R, _ in members[parent] if name == joint.parent)
        rotation = _floats(joint.origin.rotation)
        axis = [_float(v) for v in joint.axis]
        if rotation is None or None in axis:
            return None
        to_parent = R @ np.array(rotation)
        scale = max(1.0, float(np.abs(S).max()))
        if not joint.rotates:  # prismatic: any rotational inertia crosses
            eig, vec = np.linalg.eigh(S)
            need = -(vec * np.minimum(eig, 0)) @ vec.T
        else:
            a = np.array(axis) / np.linalg.norm(axis)
            beta = _least_beta(S, a)
            if beta is None or np.linalg.eigvalsh(
                    S + beta * np.outer(a, a))[0] < -TOLERANCE * scale:
                ok[lead], took[lead] = False, False
                continue
            need = beta * np.outer(a, a)
        ok[lead] = True
        took[lead] = bool(np.abs(need).max() > TOLERANCE * scale)
        sigma[parent] = sigma[parent] - to_parent @ need @ to_parent.T
    good: dict[str, bool] = {}
    for lead in order:  # parents first: what a body took, its parent must have had to give
        good[lead] = ok[lead] and (lead == model.root or not took[lead]
                                   or good[body_of[parent_joint[lead].parent]])
    return {name for lead in order if good[lead] for name, _, _ in members[lead]}


def _least_beta(S, a) -> float | None:
    """The least ``β ≥ 0`` with ``S + β a aᵀ ⪰ 0`` (Schur complement on ``a``'s orthogonal
    complement); None when no β does."""
    import numpy as np

    scale = max(1.0, float(np.abs(S).max()))
    Q = np.linalg.svd(np.outer(a, a))[0][:, 1:]  # an orthonormal basis of a's complement
    S_perp = Q.T @ S @ Q
    if np.linalg.eigvalsh(S_perp)[0] < -TOLERANCE * scale:
        return None
    u = Q.T @ S @ a
    need = float(u @ np.linalg.pinv(S_perp, rcond=1e-12) @ u) - float(a @ S @ a)
    return max(0.0, need)


def settled(model: RobotModel) -> RobotModel:
    """``model`` with the findings that remain once the whole model is known (free flyer and
    couplings included): triangle-inequality notices about links whose bodies can be made
    physical without changing the dynamics left out, and a notice for each joint that moves
    no mass added. Idempotent."""
    notices = tuple(n for n in model.notices if n.kind is not NoticeKind.NO_MASS)
    if any(n.kind is NoticeKind.TRIANGLE_INEQUALITY for n in notices):
        fine = physical_bodies(model)
        if fine:
            notices = tuple(n for n in notices if not (
                n.kind is NoticeKind.TRIANGLE_INEQUALITY and n.links
                and all(link in fine for link in n.links)))
    return replace(model, notices=notices + massless_notices(model))
