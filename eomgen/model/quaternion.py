"""Quaternion joints: the free flyer and ball (spherical) joints, whose configuration holds a
unit quaternion, so that ``q`` has more entries (NQ) than the velocity ``v`` (NV).

Both are Pinocchio's joints, laid out as Pinocchio lays them out (each joint's entries where
the joint comes in the joint order):

================  ============================================  ==========================================
 joint             configuration (q entries)                     velocity (v entries, joint names)
================  ============================================  ==========================================
 free flyer        ``base_x, base_y, base_z`` root origin in      ``base_vx … base_vz`` root linear velocity,
 (first, 7 / 6)    the world [m], ``base_qx … base_qw``           ``base_wx … base_wz`` angular velocity, both
                   quaternion (x, y, z, w) of the root's R        in the root frame [m/s, rad/s]
                   (``JointModelFreeFlyer``)
 ball ``<name>``   ``<name>_qx … <name>_qw`` quaternion of the    ``<name>_wx … <name>_wz`` angular velocity of
 (4 / 3)           rotation from the joint frame (the joint's     the child link relative to the parent, in
                   origin) to the child link frame                the child frame [rad/s]
                   (``JointModelSpherical``)
================  ============================================  ==========================================

Within a model a quaternion joint is a chain of virtual one-axis joints (six for the free
flyer, three rotations about the child frame's x, y, z axes for a ball joint) between massless
links: the model's joints are its velocity coordinates. :attr:`RobotModel.free_flyer
<eomgen.model.RobotModel.free_flyer>` and :attr:`RobotModel.ball_joints
<eomgen.model.RobotModel.ball_joints>` say which joints they are, and
:func:`quaternion_layout` lists them with their positions in ``q`` and ``v``; the derivation
(:mod:`eomgen.symbolic.quaternion_joints`) holds the virtual joints at zero and places the
rotation of the quaternion before them.

A parser writes a ball joint as a :class:`~eomgen.model.Joint` of type
:attr:`JointType.SPHERICAL <eomgen.model.JointType.SPHERICAL>` (its origin the joint frame,
its axis unused); :func:`~eomgen.model.build_model` calls :func:`expand_ball_joints`, which
replaces it by the chain.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from ..errors import KinematicTreeError, UnsupportedError
from .parts import Joint, JointType, Link
from .scalars import vec3
from .transforms import Transform

#: A free flyer's configuration entries (q[0:7]): the root link origin in the world [m], then
#: the unit quaternion (x, y, z, w) of its orientation (Pinocchio's ``JointModelFreeFlyer``).
FREE_FLYER_CONFIGURATION = ("base_x", "base_y", "base_z", "base_qx", "base_qy", "base_qz",
                            "base_qw")
#: A free flyer's velocity entries (v[0:6], its joints' names): the twist of the root link in
#: its own frame, linear [m/s] then angular [rad/s].
FREE_FLYER_VELOCITY = ("base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz")

#: Suffixes of a ball joint's velocity entries (its virtual joints ``<name>_wx …``) and of its
#: configuration entries (``<name>_qx … <name>_qw``).
BALL_VELOCITY = ("wx", "wy", "wz")
BALL_CONFIGURATION = ("qx", "qy", "qz", "qw")

FREE_FLYER = "free_flyer"
SPHERICAL = "spherical"


@dataclass(frozen=True)
class QuaternionJoint:
    """One quaternion joint of a model: ``kind`` (:data:`FREE_FLYER` or :data:`SPHERICAL`), its
    name (``base`` for the free flyer), the index of its first velocity entry in ``v``
    (``v_index``) and of its first configuration entry in ``q`` (``q_index``)."""

    kind: str
    name: str
    v_index: int
    q_index: int

    @property
    def nv(self) -> int:
        return 6 if self.kind == FREE_FLYER else 3

    @property
    def nq(self) -> int:
        return self.nv + 1

    @property
    def quaternion(self) -> int:
        """The index in ``q`` of the quaternion's x (then y, z, w)."""
        return self.q_index + self.nv - 3

    @property
    def motions(self) -> tuple[int, ...]:
        """The chart's unit motions in chain order, as indices into a spatial motion vector
        (linear then angular): the free flyer's six, a ball joint's three rotations."""
        return tuple(range(6)) if self.kind == FREE_FLYER else (3, 4, 5)

    @property
    def virtual(self) -> range:
        """The velocity indices whose bodies are the chain's massless links (all its joints but
        the last, whose body is the real child): their inertial parameters are zero."""
        return range(self.v_index, self.v_index + self.nv - 1)

    @property
    def velocity_names(self) -> tuple[str, ...]:
        if self.kind == FREE_FLYER:
            return FREE_FLYER_VELOCITY
        return ball_velocity_names(self.name)

    @property
    def configuration_names(self) -> tuple[str, ...]:
        if self.kind == FREE_FLYER:
            return FREE_FLYER_CONFIGURATION
        return tuple(f"{self.name}_{s}" for s in BALL_CONFIGURATION)


def ball_velocity_names(name: str) -> tuple[str, str, str]:
    """The virtual joints of ball joint ``name``: ``<name>_wx``, ``<name>_wy``, ``<name>_wz``."""
    return tuple(f"{name}_{s}" for s in BALL_VELOCITY)  # type: ignore[return-value]


def expand_ball_joints(model: "RobotModel") -> "RobotModel":
    """``model`` with each :attr:`~eomgen.model.JointType.SPHERICAL` joint replaced by its
    chain (module docstring): joints ``<name>_wx``, ``<name>_wy``, ``<name>_wz`` (continuous,
    about the x, y, z axes, the first at the ball joint's origin) through massless links
    ``<child>_<name>_wx`` and ``<child>_<name>_wy``, in the ball joint's place in the joint
    order; the names are recorded in :attr:`~eomgen.model.RobotModel.ball_joints`. The hook a
    parser calls (:func:`~eomgen.model.build_model` does it for every parser).

    Raises
    ------
    KinematicTreeError
        A name the chain needs is taken by a link or joint.
    UnsupportedError
        The ball joint carries an actuator (armature, friction, stiffness): not modelled yet.
    """
    balls = [j for j in model.joints if j.type is JointType.SPHERICAL]
    if not balls:
        return model
    taken = {link.name for link in model.links} | {j.name for j in model.joints}
    chains: dict[str, list[str]] = {}
    joints: list[Joint] = []
    for joint in model.joints:
        if joint.type is not JointType.SPHERICAL:
            joints.append(joint)
            continue
        where = f"ball joint '{joint.name}'"
        if joint.actuator is not None:
            raise UnsupportedError(model.source, where, "a ball joint takes no actuator "
                                   "(armature, friction, stiffness) yet")
        names = ball_velocity_names(joint.name)
        links = [f"{joint.child}_{names[0]}", f"{joint.child}_{names[1]}"]
        for name in (*names, *links):
            if name in taken:
                raise KinematicTreeError(model.source, where, f"the name '{name}' of one of "
                                         "its virtual joints or links is taken")
            taken.add(name)
        chain = [joint.parent, *links, joint.child]
        joints += [Joint(names[k], JointType.CONTINUOUS, chain[k], chain[k + 1],
                         joint.origin if k == 0 else Transform(),
                         vec3([1 if i == k else 0 for i in range(3)])) for k in range(3)]
        chains[joint.child] = links
    links_out: list[Link] = []
    for link in model.links:
        links_out += [Link(name) for name in chains.get(link.name, ())]
        links_out.append(link)
    return replace(model, links=tuple(links_out), joints=tuple(joints),
                   ball_joints=model.ball_joints + tuple(j.name for j in balls))


def quaternion_layout(model: "RobotModel") -> tuple[QuaternionJoint, ...]:
    """The quaternion joints of ``model`` in velocity order, with their places in ``q`` and
    ``v`` (module docstring).

    Raises
    ------
    KinematicTreeError
        A ball joint's three virtual joints are no longer consecutive movable joints, one the
        child of the other (a scene locked or reordered one of them).
    UnsupportedError
        The model holds a :attr:`~eomgen.model.JointType.SPHERICAL` joint that was not
        expanded (:func:`expand_ball_joints`).
    """
    for joint in model.joints:
        if joint.type is JointType.SPHERICAL:
            raise UnsupportedError(model.source, f"joint '{joint.name}'",
                                   "a spherical joint must be expanded first "
                                   "(eomgen.model.expand_ball_joints; build_model does it)")
    movable = model.coordinate_joints  # the followers of couplings are no coordinates
    index = {j.name: k for k, j in enumerate(movable)}
    found = [(0, FREE_FLYER, "base")] if model.free_flyer else []
    for ball in model.ball_joints:
        names = ball_velocity_names(ball)
        k = index.get(names[0], -1)
        chain = movable[k:k + 3] if k >= 0 else ()
        if (tuple(j.name for j in chain) != names
                or any(chain[i + 1].parent != chain[i].child for i in range(2))):
            raise KinematicTreeError(model.source, f"ball joint '{ball}'",
                                     f"its joints {', '.join(names)} are not three consecutive "
                                     "movable joints in a chain (was one locked or removed?)")
        found.append((k, SPHERICAL, ball))
    layout, extra = [], 0
    for k, kind, name in sorted(found):
        layout.append(QuaternionJoint(kind, name, k, k + extra))
        extra += 1
    return tuple(layout)


__all__ = ["BALL_CONFIGURATION", "BALL_VELOCITY", "FREE_FLYER", "FREE_FLYER_CONFIGURATION",
           "FREE_FLYER_VELOCITY", "QuaternionJoint", "SPHERICAL", "ball_velocity_names",
           "expand_ball_joints", "quaternion_layout"]
