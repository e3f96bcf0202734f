"""The parts of a robot: joint types, links with their inertial data, joints, parameters."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

import sympy as sp

from ..common import reprs
from .actuator import Actuator
from .joints import KINDS, JointKind
from .passive import BallSpring, Spring  # noqa: F401 (the annotation of Joint.spring)
from .scalars import ZERO3, Mat3, Scalar, Vec3, mat3, scalar, vec3
from .transforms import Transform

class _JointTypes(enum.Enum):
    """What every :class:`JointType` member answers (the members are made from the kinds)."""

    @property
    def kind(self) -> JointKind:
        """The joint kind of this type (:data:`eomgen.model.joints.KINDS`)."""
        return KINDS[self.value]

    @property
    def is_movable(self) -> bool:
        return self.kind.nv > 0

    @property
    def is_revolute(self) -> bool:
        return self.value in ("revolute", "continuous")


#: The joint types a description writes, one member per kind of :mod:`eomgen.model.joints`
#: that a description writes (``JointType.REVOLUTE``, ``PLANAR``, …: the table of
#: :mod:`eomgen.model.joints`), each naming its kind (:attr:`kind`, which answers every
#: question about it). A URDF ``<mimic>`` joint is a movable joint that a coupling makes follow
#: another (:mod:`eomgen.model.coupling`). A joint of a kind of several coordinates
#: (``SPHERICAL``: a ball joint, ``PLANAR``, …: a :class:`~eomgen.model.joints.ChainKind`) is
#: what a parser writes; :func:`~eomgen.model.build_model` turns each into its chain of
#: one-axis joints (:func:`eomgen.model.expand_joints`), so no model holds one. ``HELICAL`` is
#: a one-axis joint of the tree like ``REVOLUTE`` and ``PRISMATIC`` (:attr:`Joint.rotates`,
#: :attr:`Joint.lead`).
JointType = _JointTypes("JointType", [(kind.name.upper(), kind.name)
                                      for kind in KINDS.values() if kind.described],
                        module=__name__, qualname="JointType")


@dataclass(frozen=True)
class Inertial:
    """Mass [kg], centre of mass [m] in the link frame, inertia [kg m²] about the centre of mass
    in the link frame axes."""

    __repr__ = reprs.field_repr  # its numbers as short as they read back

    mass: Scalar
    com: Vec3 = ZERO3
    inertia: Mat3 = field(default_factory=lambda: mat3([[0, 0, 0], [0, 0, 0], [0, 0, 0]]))

    def __post_init__(self):  # accept plain numbers from Python callers
        object.__setattr__(self, "mass", scalar(self.mass))
        object.__setattr__(self, "com", vec3(self.com))
        object.__setattr__(self, "inertia", mat3(self.inertia))


@dataclass(frozen=True)
class Link:
    """A rigid body. ``inertial`` is None for a massless link (valid: frames, sensors)."""

    __repr__ = reprs.field_repr  # its numbers as short as they read back

    name: str
    inertial: Inertial | None = None


@dataclass(frozen=True)
class Joint:
    """A joint from ``parent`` link to ``child`` link; see the module docstring for frames."""

    __repr__ = reprs.field_repr  # its numbers as short as they read back

    name: str
    type: JointType
    parent: str
    child: str
    origin: Transform = Transform()
    axis: Vec3 = vec3([0, 0, 1])
    #: The drive of a movable joint (armature, friction, elasticity); None for none.
    actuator: "Actuator | None" = None
    #: A helical joint's pitch [m/rad]: its translation along ``axis`` per radian turned.
    pitch: Scalar = 0
    #: A spring pulling the joint back to its reference (:class:`~eomgen.model.passive.Spring`,
    #: MuJoCo's ``stiffness`` and ``springref``; on a ball joint a
    #: :class:`~eomgen.model.passive.BallSpring`, which its expansion gives to its first virtual
    #: joint ``<name>_wx``); None for none.
    spring: "Spring | BallSpring | None" = None

    def __post_init__(self):  # accept plain numbers from Python callers
        object.__setattr__(self, "axis", vec3(self.axis))
        object.__setattr__(self, "pitch", scalar(self.pitch))

    @property
    def rotates(self) -> bool:
        """True when the joint turns its child by its coordinate about ``axis`` (revolute,
        continuous, helical)."""
        return self.type.kind.rotates

    @property
    def lead(self) -> Scalar:
        """The child's translation along ``axis`` per unit of the coordinate: 1 (prismatic),
        the pitch [m/rad] (helical), 0 (a joint that does not translate)."""
        return self.type.kind.lead(self.pitch)


@dataclass(frozen=True)
class Parameter:
    """A symbol the model keeps symbolic, with the numeric value used where numbers are needed
    (verification, defaults of generated keyword arguments). ``value`` is None when unknown."""

    __repr__ = reprs.field_repr  # its numbers as short as they read back

    symbol: sp.Symbol
    value: float | None = None
    description: str = ""

    @property
    def name(self) -> str:
        return self.symbol.name
