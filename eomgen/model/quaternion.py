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
links: the model's joints are its velocity coordinates. :attr:`RobotModel.base_kind
<eomgen.model.RobotModel.base_kind>` and :attr:`RobotModel.ball_joints
<eomgen.model.RobotModel.ball_joints>` say which joints they are, and
:func:`quaternion_layout` lists them with their positions in ``q`` and ``v``; the derivation
(:mod:`eomgen.symbolic.charts`) holds the virtual joints at zero and places the
rotation of the quaternion before them.

A parser writes a ball joint as a :class:`~eomgen.model.Joint` of type
:attr:`JointType.SPHERICAL <eomgen.model.JointType.SPHERICAL>` (its origin the joint frame,
its axis unused), a planar joint as one of type ``PLANAR``;
:func:`~eomgen.model.build_model` calls :func:`expand_joints`, which replaces each joint of a
:class:`~eomgen.model.joints.ChainKind` by its chain (a ``HELICAL`` joint is one joint of the
tree and stays; a chain whose configuration is its coordinates, not a
:class:`~eomgen.model.joints.ChartKind`, has no place in :func:`quaternion_layout`). Every
question about a joint's kind (sizes, names, configuration space, pose) is a method of its kind
(:mod:`eomgen.model.joints`); this module only lays them out.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from ..errors import KinematicTreeError, UnsupportedError
from .joints import KINDS, SPHERICAL, ChainKind, ChartKind, JointKind
from .parts import Joint, JointType, Link
from .scalars import vec3
from .transforms import Transform

#: Suffixes of a ball joint's velocity entries (its virtual joints ``<name>_wx …``) and of its
#: configuration entries (``<name>_qx … <name>_qw``).
BALL_VELOCITY = SPHERICAL.velocity_suffixes
BALL_CONFIGURATION = SPHERICAL.configuration_suffixes


@dataclass(frozen=True)
class QuaternionJoint:
    """One joint of a model whose configuration is not its coordinates (a free flyer, a ball
    joint, a planar joint: a :class:`~eomgen.model.joints.ChartKind`): its ``kind``, its name
    (``base`` for the free flyer), the index of its first velocity entry in ``v``
    (``v_index``) and of its first configuration entry in ``q`` (``q_index``). A one-coordinate
    joint has a place of this type too (:attr:`~eomgen.model.RobotModel.joint_places`)."""

    kind: ChartKind
    name: str
    v_index: int
    q_index: int

    @property
    def nv(self) -> int:
        return self.kind.nv

    @property
    def nq(self) -> int:
        return self.kind.nq

    @property
    def v_slice(self) -> slice:
        return slice(self.v_index, self.v_index + self.kind.nv)

    @property
    def q_slice(self) -> slice:
        return slice(self.q_index, self.q_index + self.kind.nq)

    @property
    def quaternion(self) -> int | None:
        """The index in ``q`` of the quaternion's x (then y, z, w); None for a kind without
        one (planar)."""
        offset = self.kind.quaternion_offset
        return None if offset is None else self.q_index + offset

    @property
    def motions(self) -> tuple[int, ...]:
        """The chart's unit motions in chain order, as indices into a spatial motion vector
        (linear then angular)."""
        return self.kind.motions

    @property
    def virtual(self) -> range:
        """The velocity indices whose bodies are the chain's massless links (all its joints but
        the last, whose body is the real child): their inertial parameters are zero."""
        return range(self.v_index, self.v_index + self.nv - 1)

    @property
    def velocity_names(self) -> tuple[str, ...]:
        return self.kind.velocity_names(self.name)

    @property
    def configuration_names(self) -> tuple[str, ...]:
        return self.kind.configuration_names(self.name)


def ball_velocity_names(name: str) -> tuple[str, str, str]:
    """The virtual joints of ball joint ``name``: ``<name>_wx``, ``<name>_wy``, ``<name>_wz``."""
    return SPHERICAL.velocity_names(name)  # type: ignore[return-value]


def _chain(model, joint: Joint, kind: ChainKind, taken: set) -> tuple[list, list]:
    """The virtual joints and massless links of ``joint``'s chain (its kind's)."""
    where = f"{kind.describe()[0]} joint '{joint.name}'"
    if joint.actuator is not None and joint.actuator.flexible:
        raise UnsupportedError(model.source, where, f"a {kind.describe()[0]} joint's stiffness "
                               "is not modelled yet (its spring acts on a rotation, not on one "
                               "angle); armature, damping and friction are")
    steps = kind.chain()
    names = [f"{joint.name}_{suffix}" for suffix, _, _ in steps]
    links = [f"{joint.child}_{name}" for name in names[:-1]]
    for name in (*names, *links):
        if name in taken:
            raise KinematicTreeError(model.source, where, f"the name '{name}' of one of "
                                     "its virtual joints or links is taken")
        taken.add(name)
    chain = [joint.parent, *links, joint.child]
    joints = [Joint(names[k], JointType(step[1]), chain[k], chain[k + 1],
                    joint.origin if k == 0 else Transform(), vec3(step[2]), joint.actuator,
                    spring=joint.spring if k == 0 else None)
              for k, step in enumerate(steps)]
    return joints, [Link(name) for name in links]


def expand_joints(model: "RobotModel") -> "RobotModel":
    """``model`` with each joint of a kind that is a chain in the tree (a
    :class:`~eomgen.model.joints.ChainKind`: a ball or a planar joint, …) replaced by its
    chain, in the joint's place in the joint order: the virtual joints ``<name>_<suffix>`` (the
    kind's :meth:`~eomgen.model.joints.ChainKind.chain`, the first at the joint's origin) through
    massless links ``<child>_<name>_<suffix>``, recorded in
    :attr:`~eomgen.model.RobotModel.compound_joints`. The hook a parser calls (:func:`~eomgen.model.build_model` does it for every parser).

    Raises
    ------
    KinematicTreeError
        A name the chain needs is taken by a link or joint.
    UnsupportedError
        A ball or planar joint's actuator has a stiffness (a flexible joint): not modelled
        yet. Its armature, damping and friction act on each of its velocity coordinates (as
        MuJoCo's act on each dof of a ball joint): the actuator is given to every virtual
        joint of the chain; a ball joint's spring (:class:`~eomgen.model.BallSpring`) to
        its first.
    """
    expanded = [j for j in model.joints if isinstance(j.type.kind, ChainKind)]
    if not expanded:
        return model
    taken = {link.name for link in model.links} | {j.name for j in model.joints}
    chains: dict[str, list[Link]] = {}
    joints: list[Joint] = []
    compound = list(model.compound_joints)
    for joint in model.joints:
        kind = joint.type.kind
        if not isinstance(kind, ChainKind):
            joints.append(joint)
            continue
        virtual, links = _chain(model, joint, kind, taken)
        compound.append((kind.name, joint.name))
        joints += virtual
        chains[joint.child] = links
    links_out: list[Link] = []
    for link in model.links:
        links_out += chains.get(link.name, ())
        links_out.append(link)
    expanded_model = replace(model, links=tuple(links_out), joints=tuple(joints),
                             compound_joints=tuple(compound))
    check_entry_names(expanded_model)
    return expanded_model


def check_entry_names(model: "RobotModel") -> None:
    """Every entry of ``q`` and of ``v`` has a name of its own (``CONFIGURATION_NAMES`` and
    ``JOINT_NAMES`` of the generated modules): a joint named like an entry of a compound joint
    (``hip_qx`` beside a ball joint ``hip``; ``base_x`` on a robot with a free flyer, whose
    position entries are ``base_x, base_y, base_z``) is refused, naming both.

    Raises
    ------
    KinematicTreeError
        Naming the joint whose name is taken and the compound joint that takes it.
    """
    owners = {}  # an entry's name → the compound joint (kind, name) it belongs to
    for joint in quaternion_layout(model):
        for name in (*joint.kind.configuration_names(joint.name),
                     *joint.kind.velocity_names(joint.name)):
            owners[name] = joint
    for name in model.joint_names:
        joint = owners.get(name)
        if joint is None or name in joint.kind.velocity_names(joint.name):
            continue  # not a compound joint's entry, or its own virtual joint
        entries = ", ".join(joint.kind.configuration_names(joint.name))
        raise KinematicTreeError(model.source, f"joint '{name}'",
                                 f"'{name}' is also an entry of the configuration of the "
                                 f"{joint.kind.describe()[0]} joint '{joint.name}' ({entries}):"
                                 " rename the joint")


_COUNT = {2: "two", 3: "three", 6: "six"}

#: The name this hook had when ball joints were the only chains.
expand_ball_joints = expand_joints


def quaternion_layout(model: "RobotModel") -> tuple[QuaternionJoint, ...]:
    """The joints of ``model`` whose configuration is not their coordinates (the free flyer and
    :attr:`~eomgen.model.RobotModel.compound_joints`) in velocity order, with their places in
    ``q`` and ``v`` (module docstring).

    Raises
    ------
    KinematicTreeError
        A chart's virtual joints are no longer consecutive movable joints, one the child of the
        other (a scene locked or reordered one of them).
    UnsupportedError
        The model holds a joint of a chain kind that was not expanded (:func:`expand_joints`).
    """
    for joint in model.joints:
        if isinstance(joint.type.kind, ChainKind):
            raise UnsupportedError(model.source, f"joint '{joint.name}'",
                                   f"a {joint.type.value} joint must be expanded first "
                                   "(eomgen.model.expand_joints; build_model does it)")
    movable = model.coordinate_joints  # the followers of couplings are no coordinates
    index = {j.name: k for k, j in enumerate(movable)}
    found = []
    for kind_name, name in model.compound_joints:
        kind = KINDS[kind_name]
        if not isinstance(kind, ChartKind):  # its configuration is its coordinates
            continue
        names = kind.velocity_names(name)
        k = index.get(names[0], -1)
        chain = movable[k:k + kind.nv] if k >= 0 else ()
        if (tuple(j.name for j in chain) != names
                or any(chain[i + 1].parent != chain[i].child for i in range(kind.nv - 1))):
            raise KinematicTreeError(model.source, f"{kind.describe()[0]} joint '{name}'",
                                     f"its joints {', '.join(names)} are not {_COUNT[kind.nv]} "
                                     "consecutive movable joints in a chain (was one locked "
                                     "or removed?)")
        found.append((k, kind, name))
    layout, extra = [], 0
    for k, kind, name in sorted(found, key=lambda item: item[0]):
        layout.append(QuaternionJoint(kind, name, k, k + extra))
        extra += kind.nq - kind.nv
    return tuple(layout)


__all__ = ["BALL_CONFIGURATION", "BALL_VELOCITY", "JointKind", "QuaternionJoint", "SPHERICAL",
           "ball_velocity_names", "expand_ball_joints", "expand_joints", "quaternion_layout"]
