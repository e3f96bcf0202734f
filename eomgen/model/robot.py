"""The robot model (:class:`RobotModel`): links, joints, gravity, parameters, contacts; and the
queries and operations on a whole model (all its scalars, the joints' actuators, joint motion,
locking joints)."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Iterable, Mapping

import numpy as np
import sympy as sp

from ..common import reprs
from ..errors import KinematicTreeError, ParameterError
from .actuator import Actuator
from .contact import Contact
from .control import Control
from .coupling import Coupling, locked_couplings
from .loop import Loop
from .notices import Notice
from .passive import Tendon
from .joints import KINDS
from .parts import Inertial, Joint, JointType, Link, Parameter
from .quaternion import (QuaternionJoint,
                         quaternion_layout)
from .scalars import IDENTITY3, ZERO3, Scalar, Vec3, scalar, vec3
from .transforms import Transform, rotation_about_axis



def configuration_size(model: "RobotModel") -> int:
    """The length of ``q`` for ``model`` (its NQ; :data:`eomgen.outputs.INPUT_SIZES`)."""
    return model.nq


@dataclass(frozen=True)
class RobotModel:
    """A robot: links, joints (in description order), gravity and parameters.

    The kinematic structure is a tree rooted at ``root``. ``joints`` keeps the order of the
    description; ``movable_joints`` (and hence the joint vector ``q``) follows it.
    ``info`` carries format-specific extras for display (e.g. the DH table) and never changes the
    dynamics. ``notices`` are the parser's findings that warn (or, under ``strict``, refuse):
    see :class:`Notice`; they take no part in comparing models.
    """

    name: str
    links: tuple[Link, ...]
    joints: tuple[Joint, ...]
    root: str
    gravity: Vec3 = vec3([0, 0, -9.81])
    parameters: tuple[Parameter, ...] = ()
    source: str = "<memory>"
    info: tuple[tuple[str, object], ...] = ()
    notices: tuple[Notice, ...] = field(default=(), compare=False, repr=False)
    #: The scene's contacts (:class:`~eomgen.model.Contact`, rows of ``J_c`` in this order)
    #: and the frames it names (``frames:``), carried so that the output builders see them
    #: (:mod:`eomgen.symbolic.frames`); empty for a model without a scene.
    contacts: tuple[Contact, ...] = ()
    frames: tuple[str, ...] = ()
    #: The scene's loop closures (:class:`~eomgen.model.Loop`, rows of ``J_l`` in this order,
    #: after the contacts' in ``J_c``) and its actuated joints (``actuated:``, for the parallel
    #: inverse dynamics; empty: every joint), :mod:`eomgen.symbolic.loops`.
    loops: tuple[Loop, ...] = ()
    actuated: tuple[str, ...] = ()
    #: Pose of the root link's frame in the frame of the description's root link, when a scene
    #: moved the fixed frame (:func:`eomgen.reduction.apply_scene`); None when they coincide.
    #: Frame kinematics are given in the description's frame.
    root_pose: Transform | None = None
    #: ``(kind, name)`` of each joint that is a chain of virtual joints in the tree (a ball
    #: joint: three movable virtual joints ``<name>_wx … <name>_wz`` whose configuration is a
    #: unit quaternion; a planar joint; the free flyer ``("free_flyer", "base")``),
    #: :mod:`eomgen.model.quaternion`, :func:`~eomgen.model.expand_joints`,
    #: :func:`~eomgen.model.floating.add_free_flyer`.
    compound_joints: tuple[tuple[str, str], ...] = ()
    #: Coupled joints (:mod:`eomgen.model.coupling`): each follower's position is an affine
    #: function of its leaders'; followers are no coordinates (``joint_names``, ``dof``).
    couplings: tuple[Coupling, ...] = ()
    #: Fixed tendons (:class:`~eomgen.model.passive.Tendon`): springs and dampers on linear
    #: combinations of joint coordinates, in the passive forces (``tau_p``).
    tendons: tuple[Tendon, ...] = ()
    #: The control inputs (:class:`~eomgen.model.Control`: MuJoCo's actuators on joints and
    #: fixed tendons, YAML's ``controls:``), entries of ``ctrl`` in this order; empty: the input
    #: is the joint effort.
    controls: tuple[Control, ...] = ()
    #: Gravity compensation (MuJoCo's body ``gravcomp``): ``(link, factor)`` pairs, each link
    #: pushed up by ``factor`` times its weight at its centre of mass, a passive force
    #: (``tau_p``, :func:`~eomgen.model.passive.compensated`); empty: none. A scene that merges
    #: links of different factors into one body gives it ``(link, factor, inertial)``: the
    #: weight held up is ``factor`` times that inertial's, not the link's
    #: (:func:`eomgen.reduction.inertia.merged_gravcomp`).
    gravcomp: tuple[tuple[str, Scalar] | tuple[str, Scalar, Inertial], ...] = ()

    @cached_property
    def link_by_name(self) -> dict[str, Link]:
        return {link.name: link for link in self.links}

    @cached_property
    def parent_joint(self) -> dict[str, Joint]:
        """The joint whose child is the given link (absent for the root)."""
        return {joint.child: joint for joint in self.joints}

    @cached_property
    def movable_joints(self) -> tuple[Joint, ...]:
        return tuple(j for j in self.joints if j.type.is_movable)

    @cached_property
    def coordinate_joints(self) -> tuple[Joint, ...]:
        """The movable joints that are coordinates: all but the followers of
        :attr:`couplings`, in description order."""
        followers = {c.follower for c in self.couplings}
        return tuple(j for j in self.movable_joints if j.name not in followers)

    @property
    def joint_names(self) -> tuple[str, ...]:
        """``JOINT_NAMES``: the coordinates' joints (:attr:`coordinate_joints`)."""
        return tuple(j.name for j in self.coordinate_joints)

    @property
    def dof(self) -> int:
        """The number of velocity coordinates (NV): one per movable joint that follows no
        other (:attr:`couplings`)."""
        return len(self.coordinate_joints)

    @property
    def free_flyer(self) -> bool:
        """True when the first six movable joints are a quaternion free flyer's velocity
        coordinates (:mod:`eomgen.model.floating`): the configuration ``q`` then has ``dof + 1``
        entries (root position, unit quaternion), the velocity ``v`` has ``dof``."""
        return any(kind == "free_flyer" for kind, _ in self.compound_joints)

    @property
    def base_kind(self):
        """The kind of the virtual base joint that moves the root in the world (a
        :class:`~eomgen.model.joints.JointKind` whose ``base`` is set: the quaternion free
        flyer), its velocity first in ``v``; None for a fixed root or an Euler chain."""
        for kind, _ in self.compound_joints:
            if KINDS[kind].base:
                return KINDS[kind]
        return None

    @property
    def ball_joints(self) -> tuple[str, ...]:
        """The names of the model's ball (spherical) joints (:attr:`compound_joints`)."""
        return tuple(name for kind, name in self.compound_joints if kind == "spherical")

    @cached_property
    def quaternion_joints(self) -> tuple[QuaternionJoint, ...]:
        """The free flyer and the ball joints, with their places in ``q`` and ``v``
        (:func:`~eomgen.model.quaternion_layout`); empty for a model without them."""
        return quaternion_layout(self)

    @cached_property
    def joint_places(self) -> tuple[QuaternionJoint, ...]:
        """Every joint of the configuration in velocity order, with its kind and the index of
        its first entry in ``v`` and in ``q`` (Pinocchio's joints with their ``idx_v``,
        ``idx_q``): a joint whose configuration is not its coordinates is one place (its
        chain's virtual joints are not places of their own), every other coordinate joint
        one place of its type's kind."""
        charts = {j.v_index: j for j in self.quaternion_joints}
        joints, out, k, iq = self.coordinate_joints, [], 0, 0
        while k < len(joints):
            place = charts.get(k) or QuaternionJoint(joints[k].type.kind, joints[k].name, k, iq)
            out.append(place)
            k, iq = k + place.nv, iq + place.nq
        return tuple(out)

    @property
    def nq(self) -> int:
        """The number of configuration coordinates (NQ): :attr:`dof`, plus one for the
        quaternion of each quaternion joint (a free flyer: seven entries for its six
        velocities; a ball joint: four for three)."""
        return self.dof + sum(j.nq - j.nv for j in self.quaternion_joints)

    @property
    def configuration_names(self) -> tuple[str, ...]:
        """The names of the NQ entries of ``q``: :attr:`joint_names`, except that each
        quaternion joint's velocity coordinates give way to its configuration entries."""
        names = list(self.joint_names)
        for joint in reversed(self.quaternion_joints):
            names[joint.v_index:joint.v_index + joint.nv] = joint.configuration_names
        return tuple(names)

    @cached_property
    def topological_joints(self) -> tuple[Joint, ...]:
        """Joints in depth-first preorder from the root: every joint comes after the joint of
        its parent link, each subtree's joints are contiguous, and siblings keep description
        order."""
        children: dict[str, list[Joint]] = {}
        for joint in self.joints:
            children.setdefault(joint.parent, []).append(joint)
        order: list[Joint] = []
        stack = list(reversed(children.get(self.root, [])))
        while stack:
            joint = stack.pop()
            order.append(joint)
            stack.extend(reversed(children.get(joint.child, [])))
        return tuple(order)

    def __repr__(self) -> str:
        """One line: the name, the sizes, the joints and parameters by name, the source (the
        parts: ``model.links``, ``model.joints``)."""
        params = (f"{len(self.parameters)} parameters ({reprs.names(self.parameter_names)})"
                  if self.parameters else "no parameters")
        sizes = f"nq={self.nq}, nv={self.dof}" + (" (free flyer)" if self.free_flyer else "")
        return (f"<RobotModel {self.name!r}: {sizes}, joints {reprs.names(self.joint_names)}; "
                f"{len(self.links)} links; {params}; from {self.source}>")

    @property
    def parameter_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.parameters)

    def _repr_html_(self) -> str | None:  # rich display in notebooks: registered by eomgen.present.display
        return reprs.render("model", self, "text/html")

    @property
    def parameter_values(self) -> dict[sp.Symbol, float]:
        """Default numeric value of every parameter that has one."""
        return {p.symbol: p.value for p in self.parameters if p.value is not None}

    @property
    def free_symbols(self) -> set[sp.Symbol]:
        """Every symbol appearing anywhere in the model's numbers."""
        found: set[sp.Symbol] = set()
        for value in all_scalars(self):
            found |= value.free_symbols
        return found

    def substitute(self, values: Mapping[sp.Symbol, object]) -> "RobotModel":
        """A copy with the given symbols replaced by numbers or expressions; parameters that
        became numbers are dropped from ``parameters``."""
        subs = {k: scalar(v) if not isinstance(v, sp.Basic) else v for k, v in values.items()}

        def s(x):
            return scalar(x.xreplace(subs)) if isinstance(x, sp.Basic) else x

        def sv(v):
            return tuple(s(x) for x in v)

        links = tuple(
            replace(
                link,
                inertial=None
                if link.inertial is None
                else Inertial(
                    s(link.inertial.mass),
                    sv(link.inertial.com),
                    tuple(sv(r) for r in link.inertial.inertia),
                ),
            )
            for link in self.links
        )
        joints = tuple(
            replace(
                j,
                origin=Transform(
                    tuple(sv(r) for r in j.origin.rotation), sv(j.origin.translation)
                ),
                axis=sv(j.axis),
                pitch=s(j.pitch),
                actuator=None if j.actuator is None else j.actuator.substitute(subs),
            )
            for j in self.joints
        )
        params = tuple(p for p in self.parameters if p.symbol not in subs)
        return replace(self, links=links, joints=joints, gravity=sv(self.gravity),
                       parameters=params)

    def with_numeric_parameters(self, values: Mapping[sp.Symbol, float] | None = None
                                ) -> "RobotModel":
        """A copy with every parameter replaced by a number (``values`` over the defaults).

        Raises
        ------
        ParameterError
            When a parameter has neither a default nor a given value.
        """
        merged = dict(self.parameter_values)
        merged.update(values or {})
        missing = sorted(s.name for s in self.free_symbols if s not in merged)
        if missing:
            raise ParameterError(self.source, "parameters",
                                   "no numeric value for " + ", ".join(missing))
        return self.substitute(merged)


def all_scalars(model: RobotModel) -> Iterable[sp.Expr]:
    """Every number of the model (gravity, inertial data, joint geometry, actuators), in a fixed
    order: the expressions whose symbols are the model's."""
    yield from model.gravity
    for link in model.links:
        if link.inertial is not None:
            yield link.inertial.mass
            yield from link.inertial.com
            for row in link.inertial.inertia:
                yield from row
    for joint in model.joints:
        yield from joint.axis
        yield from joint.origin.translation
        for row in joint.origin.rotation:
            yield from row
        if joint.pitch != 0:  # a helical joint's
            yield joint.pitch
        if joint.actuator is not None:
            yield from joint.actuator.scalars()


def float_constants(model: RobotModel) -> RobotModel:
    """``model`` with its exact irrational constants (√2/2 of an angle snapped to π/4, √3/2 of
    ``pi/6``) as doubles when its numbers hold a float, else ``model`` itself.

    SymPy folds a float with a rational (``0.5 * 1/3`` is one float) but not with an
    irrational number (``0.0075*sqrt(2)`` stays a product), so exact rotations among float
    inertias would cost the generated code an operation per such product; derived in floats
    they cost what the description's floats cost. A model with exact numbers only (symbols,
    integers, rationals, √3) is returned unchanged and derived exactly. The inertial data and
    the joints' geometry are converted (where rotations and inertias meet); gravity and
    actuators are kept.
    """
    if not any(value.has(sp.Float) for value in all_scalars(model)):
        return model

    def floated(x):
        if not isinstance(x, sp.Basic) or x.is_Rational or x.is_Float:
            return x
        return scalar(x.replace(lambda e: e.is_number and not e.is_Rational and not e.is_Float
                                and e.is_real, lambda e: sp.Float(float(e.evalf(30)), 17)))

    def vector(v):
        return tuple(floated(x) for x in v)

    links = tuple(
        replace(link, inertial=Inertial(floated(link.inertial.mass), vector(link.inertial.com),
                                        tuple(vector(r) for r in link.inertial.inertia)))
        if link.inertial is not None else link for link in model.links)
    joints = tuple(
        replace(j, origin=Transform(tuple(vector(r) for r in j.origin.rotation),
                                    vector(j.origin.translation)), axis=vector(j.axis),
                pitch=floated(j.pitch))
        for j in model.joints)
    return replace(model, links=links, joints=joints)


def joint_actuators(model: RobotModel) -> tuple[Actuator, ...]:
    """The actuator of every movable joint, in ``model.joint_names`` order (a joint without
    one gets ``Actuator()``: no armature, no friction, rigid)."""
    return tuple(j.actuator or Actuator() for j in model.movable_joints)


def flexible_indices(model: RobotModel) -> tuple[int, ...]:
    """Indices (into ``q``) of the flexible joints (those with a stiffness), in joint order."""
    return tuple(k for k, a in enumerate(joint_actuators(model)) if a.flexible)


def joint_motion(joint: Joint, value) -> Transform:
    """The transform a joint applies at position ``value`` (rad or m): child frame in joint
    frame (a helical joint's turns by ``value`` and moves ``pitch · value`` along its axis)."""
    value = scalar(value) if not isinstance(value, sp.Basic) else value
    if not joint.type.is_movable:
        return Transform()
    rotation = rotation_about_axis(joint.axis, value) if joint.rotates else IDENTITY3
    if not joint.type.kind.translates:
        return Transform(rotation, ZERO3)
    move = value if not joint.rotates else joint.lead * value
    return Transform(rotation, tuple(a * move for a in joint.axis))  # type: ignore[arg-type]


def compound_names(model: RobotModel) -> dict[str, tuple[str, tuple[str, ...]]]:
    """``{name: (kind, virtual joints)}`` of the model's :attr:`~RobotModel.compound_joints`
    (a ball joint ``hip``: ``("spherical", ("hip_wx", "hip_wy", "hip_wz"))``)."""
    return {name: (kind, KINDS[kind].velocity_names(name)) for kind, name in model.compound_joints}


def compound_of(model: RobotModel) -> dict[str, str]:
    """``{virtual joint: compound joint}`` for the virtual joints of the model's
    :attr:`~RobotModel.compound_joints` (``hip_wy`` → ``hip``)."""
    return {v: name for name, (_, virtual) in compound_names(model).items() for v in virtual}


def _lock_compound(model: RobotModel, name: str, configuration) -> dict[str, Transform]:
    """The fixed origins of compound joint ``name``'s virtual joints locked at its
    ``configuration`` (the kind's NQ entries): the first one's origin moved by the kind's pose
    (:meth:`~eomgen.model.joints.ChartKind.pose`), the others at their own; at the kind's
    neutral configuration the origins stay exact."""
    kind_name, virtual = compound_names(model)[name]
    kind = KINDS[kind_name]
    values = np.asarray(configuration, dtype=float)
    joints = {j.name: j for j in model.joints}
    origins = {v: joints[v].origin for v in virtual}
    if not np.array_equal(values, kind.neutral()):
        R, p = kind.pose(values)
        pose = Transform(tuple(tuple(scalar(float(x)) for x in row) for row in R),
                         tuple(scalar(float(x)) for x in p))
        origins[virtual[0]] = origins[virtual[0]] @ pose
    return origins


def lock_joints(model: RobotModel, positions: Mapping[str, object]) -> RobotModel:
    """A copy of ``model`` with the named movable joints made fixed at the given positions.
    A compound joint (:attr:`RobotModel.compound_joints`: a ball or planar joint) is locked by
    its name at its configuration (the kind's NQ entries, e.g. a ball joint's quaternion
    ``(x, y, z, w)``, normalised): its virtual joints become fixed, the pose at the first.

    A follower of a coupling (:attr:`RobotModel.couplings`) whose leaders are all locked is
    locked where its coupling puts it; locked leaders of a coupling that keeps others move its
    offset (:func:`eomgen.model.coupling.locked_couplings`).

    Raises
    ------
    KinematicTreeError
        When a name is not a movable joint of the model, or a coupled joint is locked against
        its coupling.
    """
    movable = {j.name for j in model.movable_joints}
    compound = compound_names(model)
    fixed_origins: dict[str, Transform] = {}
    for name, value in positions.items():
        if name in compound:
            kind = KINDS[compound[name][0]]
            if len(np.atleast_1d(np.asarray(value, dtype=object))) != kind.nq:
                raise KinematicTreeError(model.source, f"joint '{name}'", f"cannot lock: a "
                                         f"{kind.describe()[0]} joint is locked at its {kind.nq} "
                                         f"configuration entries ({', '.join(kind.configuration_names(name))})")
            fixed_origins.update(_lock_compound(model, name, value))
        elif name not in movable:
            raise KinematicTreeError(model.source, f"joint '{name}'",
                                   "cannot lock: not a movable joint of this model")
    positions = {k: v for k, v in positions.items() if k not in compound}
    positions, couplings = locked_couplings(model, positions)
    joints = tuple(
        replace(j, type=JointType.FIXED, origin=j.origin @ joint_motion(j, positions[j.name]),
                spring=None)
        if j.name in positions else
        replace(j, type=JointType.FIXED, origin=fixed_origins[j.name])
        if j.name in fixed_origins else j
        for j in model.joints
    )
    locked = {name for name in compound if any(v in fixed_origins for v in compound[name][1])}
    return replace(model, joints=joints, couplings=couplings,
                   tendons=tuple(t.locked(positions) for t in model.tendons),
                   controls=tuple(c.locked(positions) for c in model.controls),
                   compound_joints=tuple((k, n) for k, n in model.compound_joints
                                         if n not in locked))
