"""Rigid bodies of a robot: links joined by fixed joints merged into one body per movable joint.

A :class:`BodyTree` is what the dynamics algorithms walk. Each body is the child link of one
movable joint together with every link rigidly attached to it through fixed joints; links
rigidly attached to the root never move and are dropped (they cannot change M, C or g).
:func:`frame_site` says on which body a link sits, and where.

Inertial data are kept as the ten *inertial parameters about the body frame origin*, which are
linear in the link data and add up when bodies are merged (and are the parameters π of the
regressor form): mass ``m`` [kg], first moment ``h = m c`` [kg m] and rotational inertia about
the origin ``I_O = I_c + m (|c|² 1 − c cᵀ)`` [kg m²], all in body-frame coordinates.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Iterable

import sympy as sp

from ..errors import KinematicTreeError
from . import IDENTITY3, Inertial, Joint, Mat3, RobotModel, Transform, Vec3, ZERO3

ZERO33: Mat3 = tuple(tuple(sp.Integer(0) for _ in range(3)) for _ in range(3))  # type: ignore


@dataclass(frozen=True)
class InertialParameters:
    """Mass, first moment ``h = m c`` and inertia about the frame origin, in frame coordinates."""

    mass: sp.Expr = sp.Integer(0)
    first_moment: Vec3 = ZERO3
    inertia: Mat3 = ZERO33

    @staticmethod
    def from_inertial(inertial: Inertial | None) -> "InertialParameters":
        if inertial is None:
            return InertialParameters()
        m, c, Ic = inertial.mass, inertial.com, inertial.inertia
        cc = sum(ci * ci for ci in c)
        I = tuple(
            tuple(Ic[a][b] + m * ((cc if a == b else 0) - c[a] * c[b]) for b in range(3))
            for a in range(3)
        )
        return InertialParameters(m, tuple(m * ci for ci in c), I)  # type: ignore[arg-type]

    def __add__(self, other: "InertialParameters") -> "InertialParameters":
        return InertialParameters(
            self.mass + other.mass,
            tuple(a + b for a, b in zip(self.first_moment, other.first_moment)),  # type: ignore
            tuple(tuple(a + b for a, b in zip(r, s)) for r, s in zip(self.inertia, other.inertia)),  # type: ignore
        )

    def transformed(self, T: Transform) -> "InertialParameters":
        """The same body's parameters in the frame where its frame has pose ``T``."""
        R, t, m = T.rotation, T.translation, self.mass
        Rh = tuple(sum(R[a][k] * self.first_moment[k] for k in range(3)) for a in range(3))
        RI = [[sum(R[a][k] * self.inertia[k][b] for k in range(3)) for b in range(3)] for a in range(3)]
        RIRt = [[sum(RI[a][k] * R[b][k] for k in range(3)) for b in range(3)] for a in range(3)]
        tt = sum(x * x for x in t)
        tRh = sum(t[k] * Rh[k] for k in range(3))
        I = tuple(
            tuple(
                RIRt[a][b] + m * ((tt if a == b else 0) - t[a] * t[b])
                + (2 * tRh if a == b else 0) - t[a] * Rh[b] - Rh[a] * t[b]
                for b in range(3)
            )
            for a in range(3)
        )
        h = tuple(Rh[a] + m * t[a] for a in range(3))
        return InertialParameters(m, h, I)  # type: ignore[arg-type]

    @property
    def is_zero(self) -> bool:
        return self.mass == 0 and all(v == 0 for v in self.first_moment) and all(
            v == 0 for row in self.inertia for v in row)


@dataclass(frozen=True)
class RigidBody:
    """One moving body: the child side of a movable joint, fixed descendants merged.

    Attributes
    ----------
    joint:
        The movable joint; its ``axis`` is in the body frame (= joint frame).
    q_index:
        Position of the joint in the joint vector (``JOINT_NAMES`` order).
    parent:
        Index of the parent body in :attr:`BodyTree.bodies`, or -1 for the fixed base.
    placement:
        Pose of the joint frame (before the joint moves) in the parent body frame; fixed joints in
        between are composed into it.
    inertial:
        Inertial parameters of the merged body about its frame origin, body-frame coordinates.
    links:
        Names of the links merged into the body, the joint's child first.
    """

    joint: Joint
    q_index: int
    parent: int
    placement: Transform
    inertial: InertialParameters
    links: tuple[str, ...]


@dataclass(frozen=True)
class BodyTree:
    """Moving bodies in topological order (a parent before its children)."""

    bodies: tuple[RigidBody, ...]
    gravity: Vec3
    joint_names: tuple[str, ...]
    fixed_links: tuple[str, ...]

    def ancestors(self, i: int) -> list[int]:
        """Strict ancestors of body ``i``, nearest first."""
        out = []
        p = self.bodies[i].parent
        while p >= 0:
            out.append(p)
            p = self.bodies[p].parent
        return out

    def subtree(self, i: int) -> list[int]:
        """Body ``i`` and all its descendants."""
        members = {i}
        for k in range(i + 1, len(self.bodies)):
            if self.bodies[k].parent in members:
                members.add(k)
        return sorted(members)


@dataclass(frozen=True)
class RigidAttachment:
    """Where the fixed joints put every link: the one walk that merges fixed links, used by
    :func:`body_tree` and by the scene reduction (:mod:`eomgen.reduction`).

    Attributes
    ----------
    movers:
        One entry per movable joint, in topological order (body ``k`` is ``movers[k]``):
        ``(joint, parent body index or -1 for the world, placement)``, the placement being the
        pose of the joint frame (before the joint moves) in the parent body frame, the fixed
        joints in between composed into it.
    site:
        For every link, in topological order (the root first, a body's joint child before the
        links fixed to it): ``(body index or -1 for the world, pose of the link frame in that
        body frame)``.
    """

    movers: tuple[tuple[Joint, int, Transform], ...]
    site: dict[str, tuple[int, Transform]]

    def links_of(self, body: int) -> list[str]:
        """Links rigidly attached to ``body`` (-1: the world), in topological order."""
        return [link for link, (k, _) in self.site.items() if k == body]

    def inertial_parts(self, model: RobotModel) -> list[list[tuple[Inertial, Transform]]]:
        """Per body, the inertial data of its links (``model.links`` order) with their poses
        in the body frame; links attached to the world are left out."""
        parts: list[list[tuple[Inertial, Transform]]] = [[] for _ in self.movers]
        for link in model.links:
            body, pose = self.site[link.name]
            if body >= 0 and link.inertial is not None:
                parts[body].append((link.inertial, pose))
        return parts


def attach_fixed_links(model: RobotModel,
                       tidy: Callable[[Transform], Transform] = lambda T: T) -> RigidAttachment:
    """Walk the joints of ``model`` root to tips, composing the fixed joints: every link's
    moving body and pose in it (see :class:`RigidAttachment`). ``tidy`` is applied to every
    composed pose (the scene reduction snaps roundoff in rotations with it)."""
    site: dict[str, tuple[int, Transform]] = {model.root: (-1, Transform())}
    movers: list[tuple[Joint, int, Transform]] = []
    for joint in model.topological_joints:
        body, pose = site[joint.parent]
        if joint.type.is_movable:
            movers.append((joint, body, tidy(pose @ joint.origin)))
            site[joint.child] = (len(movers) - 1, Transform())
        else:
            site[joint.child] = (body, tidy(pose @ joint.origin))
    return RigidAttachment(tuple(movers), site)


def merged_inertial(parts: Iterable[tuple[Inertial, Transform]]) -> InertialParameters:
    """The inertial parameters, about the body origin, of parts given in frames with the given
    poses in the body frame (summed in the given order)."""
    total = InertialParameters()
    for inertial, pose in parts:
        params = InertialParameters.from_inertial(inertial)
        total = total + (params if pose == Transform() else params.transformed(pose))
    return total


def body_tree(model: RobotModel) -> BodyTree:
    """Group the links of ``model`` into moving rigid bodies (see module docstring)."""
    q_index = {j.name: k for k, j in enumerate(model.movable_joints)}
    rigid = attach_fixed_links(model)
    parts = rigid.inertial_parts(model)
    bodies = tuple(
        RigidBody(joint, q_index[joint.name], parent, placement, merged_inertial(parts[k]),
                  tuple(rigid.links_of(k)))
        for k, (joint, parent, placement) in enumerate(rigid.movers)
    )
    return BodyTree(bodies, model.gravity, model.joint_names, tuple(rigid.links_of(-1)))


def frame_site(model: RobotModel, name: str) -> tuple[str | None, Transform]:
    """Where link ``name`` sits: ``(body link, pose in that link's frame)``.

    The body link is the child link of the nearest movable joint above ``name`` (``name``
    itself when its own joint moves); None when ``name`` is rigidly attached to the root
    (the pose is then in the root frame).

    Raises
    ------
    KinematicTreeError
        When the model has no link ``name``.
    """
    if name not in model.link_by_name:
        raise KinematicTreeError(model.source, f"frame '{name}'",
                                 f"no link '{name}' in robot '{model.name}'")
    pose = Transform(IDENTITY3, ZERO3)
    link = name
    parent = model.parent_joint
    while link in parent and not parent[link].type.is_movable:
        joint = parent[link]
        pose = joint.origin @ pose
        link = joint.parent
    return (link if link in parent else None), pose
