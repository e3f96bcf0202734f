"""The robot model: plain, frozen data shared by every stage of eomgen.

Conventions (URDF's, whatever the input format):

* Every link has a frame. A joint connects a parent link to a child link; its ``origin`` is the
  pose of the joint frame in the parent link frame, and the child link frame *is* the joint
  frame moved by the joint variable: ``T_parent_child(q) = origin · motion(axis, q)``.
* ``axis`` is a unit vector in the joint (= child link) frame. A revolute joint rotates by ``q``
  radians about it (right hand rule); a prismatic joint translates by ``q`` metres along it.
* A link's inertial data: mass [kg], centre of mass [m] in the link frame, and the 3×3
  rotational inertia [kg m²] about the centre of mass, expressed in the link frame axes (a
  URDF ``<inertial><origin rpy>`` is already applied by the parser).
* ``gravity`` is the gravitational acceleration [m/s²] in the root link frame, e.g.
  ``(0, 0, -9.81)`` for URDF input.
* A movable joint may carry an :class:`Actuator` (armature, friction, stiffness): the rigid
  bodies' ``M``, ``C``, ``g`` do not use it; :mod:`eomgen.actuators` does (docs/actuators.md).

Every geometric and inertial quantity is a SymPy expression: a number (exact integers are kept
exact so that structural zeros stay zeros) or an expression in the model's parameter symbols.
``RobotModel.parameters`` lists those symbols with their default numeric values.
"""

from __future__ import annotations

import enum
from contextlib import contextmanager
from contextvars import ContextVar
import math
import warnings
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Iterable, Mapping

import sympy as sp

from . import reprs

from .errors import (
    DescriptionError,
    InvalidActuatorError,
    InvalidAxisError,
    InvalidInertiaError,
    InvalidNumberError,
    KinematicTreeError,
    ParameterError,
    PhysicalConsistencyWarning,
    TooLargeError,
    UnsupportedError,
    UnsupportedFeatureWarning,
    one_line,
)

Scalar = sp.Expr
Vec3 = tuple[sp.Expr, sp.Expr, sp.Expr]
Mat3 = tuple[Vec3, Vec3, Vec3]

#: Rotation entries read from floats that lie within this distance of 0 or ±1 are made exact,
#: so that ``rpy="1.57079632679 0 0"`` keeps its structural zeros. The change to the model is
#: below the precision such descriptions are written with, but not below float64's: a model
#: snapped this way differs from tools that keep the floats by up to this much (relative 1e-10
#: in τ of the UR5). ``eomgen.load(path, snap=False)`` (``--no-snap``) keeps the floats; the
#: entries that were snapped are listed in ``model.info`` under ``"snapped"`` (:class:`Snap`).
SNAP_TOLERANCE = 1e-11


@dataclass(frozen=True)
class Snap:
    """One entry made exact by snapping: ``what`` it is (``cos(1.5707963268)``, a joint's axis
    component), the float ``value`` computed from the description and the ``target`` 0 or ±1
    used instead."""

    what: str
    value: float
    target: int

    @property
    def change(self) -> float:
        return abs(self.value - self.target)


_SNAP_ENABLED: ContextVar[bool] = ContextVar("eomgen_snap_enabled", default=True)
_SNAP_RECORDS: ContextVar[list | None] = ContextVar("eomgen_snap_records", default=None)


@contextmanager
def snapping(enabled: bool = True):
    """Within this block, rotation and axis entries are snapped (``enabled``) or kept exactly
    as computed from the description's floats; yields the list of :class:`Snap` records made
    inside the block."""
    records: list[Snap] = []
    enabled_token = _SNAP_ENABLED.set(enabled)
    records_token = _SNAP_RECORDS.set(records)
    try:
        yield records
    finally:
        _SNAP_RECORDS.reset(records_token)
        _SNAP_ENABLED.reset(enabled_token)


def snap_summary(snaps) -> str:
    """One line: how many entries were snapped, the largest change and where."""
    if not snaps:
        return "no rotation or axis entry snapped"
    worst = max(snaps, key=lambda s: s.change)
    kinds = sorted({s.what for s in snaps})
    listed = ", ".join(kinds[:4]) + (f" and {len(kinds) - 4} more" if len(kinds) > 4 else "")
    noun = "entry" if len(snaps) == 1 else "entries"
    return (f"snapped {len(snaps)} rotation/axis {noun} within {SNAP_TOLERANCE:g} of 0 or ±1 "
            f"to exact values (largest change {worst.change:.1e}, {worst.what}; from {listed}); "
            "--no-snap keeps the description's floats")

#: At most this many joints (and one more link) in a model: beyond, a symbolic derivation is
#: out of reach anyway, and the checks stay linear in practice.
MAX_JOINTS = 500


def parameter_symbol(name: str) -> sp.Symbol:
    """The one way eomgen makes a parameter symbol (real-valued), so that equal names give
    equal symbols everywhere."""
    return sp.Symbol(name, real=True)


def scalar(value) -> sp.Expr:
    """Convert a number or SymPy expression to the model's scalar type.

    Integral floats become exact SymPy Integers (``0.0`` → ``0``) so that they propagate as
    structural zeros and ones; other floats become SymPy Floats at double precision.
    """
    if isinstance(value, sp.Basic):
        if value.is_Float and float(value).is_integer():
            return sp.Integer(int(float(value)))
        return value
    if isinstance(value, bool):
        raise TypeError("booleans are not scalars")
    if isinstance(value, int):
        return sp.Integer(value)
    value = float(value)
    if value.is_integer():
        return sp.Integer(int(value))
    return sp.Float(value, 17)


def _snap(value: float, what: str = "") -> sp.Expr:
    if _SNAP_ENABLED.get():
        for target in (0.0, 1.0, -1.0):
            if abs(value - target) <= SNAP_TOLERANCE:
                records = _SNAP_RECORDS.get()
                if records is not None and value != target:
                    records.append(Snap(what, value, int(target)))
                return sp.Integer(int(target))
    return scalar(value)


def vec3(values: Iterable) -> Vec3:
    out = tuple(scalar(v) for v in values)
    if len(out) != 3:
        raise ValueError("a 3-vector needs three components")
    return out  # type: ignore[return-value]


def mat3(rows: Iterable[Iterable]) -> Mat3:
    out = tuple(vec3(r) for r in rows)
    if len(out) != 3:
        raise ValueError("a 3×3 matrix needs three rows")
    return out  # type: ignore[return-value]


IDENTITY3: Mat3 = mat3([[1, 0, 0], [0, 1, 0], [0, 0, 1]])
ZERO3: Vec3 = vec3([0, 0, 0])


def _matmul3(a: Mat3, b: Mat3) -> Mat3:
    return tuple(
        tuple(sp.Add(*[a[i][k] * b[k][j] for k in range(3)]) for j in range(3)) for i in range(3)
    )  # type: ignore[return-value]


def _matvec3(a: Mat3, v: Vec3) -> Vec3:
    return tuple(sp.Add(*[a[i][k] * v[k] for k in range(3)]) for i in range(3))  # type: ignore


def rotation_about_axis(axis: Vec3, angle) -> Mat3:
    """Rotation matrix of ``angle`` (rad, right hand rule) about the unit vector ``axis``."""
    if isinstance(angle, sp.Basic) and not angle.is_number:
        c, s = sp.cos(angle), sp.sin(angle)
    else:
        c = _snap(math.cos(float(angle)), f"cos({float(angle)!r})")
        s = _snap(math.sin(float(angle)), f"sin({float(angle)!r})")
    x, y, z = axis
    t = 1 - c
    return mat3(
        [
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ]
    )


def rotation_from_rpy(rpy: Vec3) -> Mat3:
    """URDF fixed-axis roll-pitch-yaw: ``R = Rz(yaw) · Ry(pitch) · Rx(roll)``."""
    roll, pitch, yaw = rpy
    rx = rotation_about_axis(vec3([1, 0, 0]), roll)
    ry = rotation_about_axis(vec3([0, 1, 0]), pitch)
    rz = rotation_about_axis(vec3([0, 0, 1]), yaw)
    return _matmul3(rz, _matmul3(ry, rx))


@dataclass(frozen=True)
class Transform:
    """A rigid transform: ``p_parent = rotation · p_child + translation``."""

    rotation: Mat3 = IDENTITY3
    translation: Vec3 = ZERO3

    @staticmethod
    def from_xyz_rpy(xyz: Iterable = (0, 0, 0), rpy: Iterable = (0, 0, 0)) -> "Transform":
        return Transform(rotation_from_rpy(vec3(rpy)), vec3(xyz))

    def __matmul__(self, other: "Transform") -> "Transform":
        rotation = _matmul3(self.rotation, other.rotation)
        moved = _matvec3(self.rotation, other.translation)
        translation = tuple(moved[i] + self.translation[i] for i in range(3))
        return Transform(rotation, translation)  # type: ignore[arg-type]

    def apply(self, point: Vec3) -> Vec3:
        moved = _matvec3(self.rotation, point)
        return tuple(moved[i] + self.translation[i] for i in range(3))  # type: ignore


class JointType(enum.Enum):
    """Joint types eomgen models. Floating and planar joints are refused by the parsers; a URDF
    ``<mimic>`` joint is read as an independent joint (see :mod:`eomgen.parsers.urdf`)."""

    REVOLUTE = "revolute"
    CONTINUOUS = "continuous"
    PRISMATIC = "prismatic"
    FIXED = "fixed"

    @property
    def is_movable(self) -> bool:
        return self is not JointType.FIXED

    @property
    def is_revolute(self) -> bool:
        return self in (JointType.REVOLUTE, JointType.CONTINUOUS)


@dataclass(frozen=True)
class Inertial:
    """Mass [kg], centre of mass [m] in the link frame, inertia [kg m²] about the centre of mass
    in the link frame axes."""

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

    name: str
    inertial: Inertial | None = None


#: Coulomb friction is smoothed as ``friction · tanh(q̇ / friction_width)`` for simulation; this
#: width [rad/s or m/s] is used when a description gives Coulomb friction without a width.
DEFAULT_FRICTION_WIDTH = 0.01


@dataclass(frozen=True)
class Actuator:
    """The drive of one movable joint: a motor behind a gear, with friction, and optionally
    an elastic transmission (a flexible joint, Spong's model). See docs/actuators.md.

    Conventions: the gear ratio ``r`` is motor turns per joint turn (``θ_rotor = r θ``), so a
    rotor of inertia ``I_rotor`` [kg m²] about its spin axis adds the *reflected inertia*
    (armature) ``r² I_rotor`` to the joint's diagonal entry of ``M`` (MuJoCo's ``armature``,
    Drake's rotor inertia and gear ratio). Motor angles of flexible joints are on the link side
    of the gear (``θ_m = θ_rotor / r`` [rad]), so the motor inertia of Spong's model is
    ``B = armature``. Torques are joint-side (N m; N for prismatic joints), positive along the
    joint axis; friction opposes the motion (``τ_friction = -damping q̇ - friction sign(q̇)``
    acts on the joint).

    Attributes
    ----------
    armature:
        Reflected rotor inertia [kg m²; kg for a prismatic joint], ``≥ 0``: given directly or
        computed as ``gear_ratio² · rotor_inertia``.
    damping:
        Viscous friction coefficient [N m s/rad], ``≥ 0``.
    friction:
        Coulomb friction torque [N m], ``≥ 0``.
    friction_width:
        Velocity [rad/s] of the ``tanh`` smoothing of Coulomb friction used for simulation
        (inverse dynamics uses the exact sign), ``> 0``.
    stiffness:
        Joint stiffness ``K`` [N m/rad] of a flexible joint, ``> 0``; None for a rigid joint.
    rotor_inertia, gear_ratio:
        The rotor inertia [kg m²] and gear ratio when the description gives them (None
        otherwise); ``armature`` holds their product ``r² I_rotor``.
    """

    armature: Scalar = sp.Integer(0)
    damping: Scalar = sp.Integer(0)
    friction: Scalar = sp.Integer(0)
    friction_width: Scalar = scalar(DEFAULT_FRICTION_WIDTH)
    stiffness: Scalar | None = None
    rotor_inertia: Scalar | None = None
    gear_ratio: Scalar | None = None

    def __post_init__(self):  # accept plain numbers from Python callers
        for name in ("armature", "damping", "friction", "friction_width", "stiffness",
                     "rotor_inertia", "gear_ratio"):
            value = getattr(self, name)
            if value is not None:
                object.__setattr__(self, name, scalar(value))

    @staticmethod
    def from_rotor(rotor_inertia, gear_ratio, **others) -> "Actuator":
        """An actuator whose armature is ``gear_ratio² · rotor_inertia``."""
        I, r = scalar(rotor_inertia), scalar(gear_ratio)
        return Actuator(armature=r ** 2 * I, rotor_inertia=I, gear_ratio=r, **others)

    def updated(self, values: Mapping[str, object]) -> "Actuator":
        """A copy with the given fields replaced (a scene over a description). Giving
        ``rotor_inertia`` or ``gear_ratio`` recomputes ``armature`` from both (a missing gear
        ratio is 1); giving ``armature`` forgets them."""
        fields = {name: getattr(self, name) for name in self.__dataclass_fields__}
        values = {k: scalar(v) for k, v in values.items()}
        if "rotor_inertia" in values or "gear_ratio" in values:
            I = values.pop("rotor_inertia", self.rotor_inertia)
            r = values.pop("gear_ratio", self.gear_ratio)
            r = sp.Integer(1) if r is None else r
            I = sp.Integer(0) if I is None else I
            values.update(armature=r ** 2 * I, rotor_inertia=I, gear_ratio=r)
        elif "armature" in values:
            values.update(rotor_inertia=None, gear_ratio=None)
        fields.update(values)
        return Actuator(**fields)

    @property
    def flexible(self) -> bool:
        """Whether the joint is elastic (has a stiffness): Spong's model gives it a motor."""
        return self.stiffness is not None

    def scalars(self) -> tuple[sp.Expr, ...]:
        """Every value it holds (for symbol bookkeeping)."""
        return tuple(v for v in (self.armature, self.damping, self.friction,
                                 self.friction_width, self.stiffness, self.rotor_inertia,
                                 self.gear_ratio) if v is not None)

    def substitute(self, subs: Mapping[sp.Symbol, sp.Expr]) -> "Actuator":
        """A copy with ``subs`` applied to every value."""
        def s(x):
            return None if x is None else scalar(x.xreplace(subs))
        return Actuator(s(self.armature), s(self.damping), s(self.friction),
                        s(self.friction_width), s(self.stiffness), s(self.rotor_inertia),
                        s(self.gear_ratio))


@dataclass(frozen=True)
class Joint:
    """A joint from ``parent`` link to ``child`` link; see the module docstring for frames."""

    name: str
    type: JointType
    parent: str
    child: str
    origin: Transform = Transform()
    axis: Vec3 = vec3([0, 0, 1])
    #: The drive of a movable joint (armature, friction, elasticity); None for none.
    actuator: "Actuator | None" = None

    def __post_init__(self):  # accept plain numbers from Python callers
        object.__setattr__(self, "axis", vec3(self.axis))


@dataclass(frozen=True)
class Parameter:
    """A symbol the model keeps symbolic, with the numeric value used where numbers are needed
    (verification, defaults of generated keyword arguments). ``value`` is None when unknown."""

    symbol: sp.Symbol
    value: float | None = None
    description: str = ""

    @property
    def name(self) -> str:
        return self.symbol.name


class NoticeKind(enum.Enum):
    """What a :class:`Notice` is about."""

    TRIANGLE_INEQUALITY = "triangle inequality"  # a link inertia that is not physical
    MIMIC = "mimic"                              # a URDF <mimic> coupling read as independent
    FLOATING_BASE = "floating base"              # a root that looks free, read as fixed


@dataclass(frozen=True)
class Notice:
    """A finding about a description that does not stop it from loading: a warning, or an error
    under ``strict`` (``--strict``).

    Parsers record notices on the model (:attr:`RobotModel.notices`) instead of warning at
    once when asked to (``defer_notices=True``), so that a scene can first say which of them
    still matter: a notice is moot when none of the ``joints`` it concerns moves, or every one
    of the ``links`` it concerns is dropped (see :func:`eomgen.reduction.apply_scene`).

    Attributes
    ----------
    kind:
        What it is about.
    source, element, problem:
        The file, the element and the finding, as in :class:`~eomgen.errors.DescriptionError`.
    fallback:
        How eomgen reads the description anyway (e.g. "read as an independent joint"); empty
        for values used as they are (a non-physical inertia).
    links, joints:
        The links and joints the finding concerns.
    """

    kind: NoticeKind
    source: str
    element: str
    problem: str
    fallback: str = ""
    links: tuple[str, ...] = ()
    joints: tuple[str, ...] = ()

    @property
    def category(self) -> type[Warning]:
        """The warning class issued without ``strict``."""
        if self.kind is NoticeKind.TRIANGLE_INEQUALITY:
            return PhysicalConsistencyWarning
        return UnsupportedFeatureWarning

    @property
    def error(self) -> type[DescriptionError]:
        """The error class raised under ``strict``."""
        if self.kind is NoticeKind.TRIANGLE_INEQUALITY:
            return InvalidInertiaError
        return UnsupportedError

    @property
    def message(self) -> str:
        """The warning's text: one line naming the file, the element and the finding."""
        tail = f"; {self.fallback}" if self.fallback else ""
        return one_line(f"{self.source}: {self.element}: {self.problem}{tail}")

    def emit(self, strict: bool = False, stacklevel: int = 2) -> None:
        """Warn (``category``), or under ``strict`` raise ``error`` saying it was refused."""
        if strict:
            raise self.error(self.source, self.element,
                             self.problem + " (refused under --strict)")
        warnings.warn(self.message, self.category, stacklevel=stacklevel + 1)


def emit_notices(notices: Iterable[Notice], strict: bool = False) -> None:
    """Warn about each notice in order, or under ``strict`` raise the first one's error."""
    for notice in notices:
        notice.emit(strict, stacklevel=3)


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
    #: The scene's contacts (:class:`eomgen.contacts.Contact`, rows of ``J_c`` in this order)
    #: and the frames it names (``frames:``), carried so that the output builders see them
    #: (:mod:`eomgen.symbolic.frames`); empty for a model without a scene.
    contacts: tuple = ()
    frames: tuple[str, ...] = ()
    #: Pose of the root link's frame in the frame of the description's root link, when a scene
    #: moved the fixed frame (:func:`eomgen.reduction.apply_scene`); None when they coincide.
    #: Frame kinematics are given in the description's frame.
    root_pose: Transform | None = None

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

    @property
    def joint_names(self) -> tuple[str, ...]:
        return tuple(j.name for j in self.movable_joints)

    @property
    def dof(self) -> int:
        return len(self.movable_joints)

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

    def _repr_html_(self) -> str | None:  # rich display in notebooks: registered by eomgen.display
        return reprs.render("model", self, "text/html")

    @property
    def parameter_values(self) -> dict[sp.Symbol, float]:
        """Default numeric value of every parameter that has one."""
        return {p.symbol: p.value for p in self.parameters if p.value is not None}

    @property
    def free_symbols(self) -> set[sp.Symbol]:
        """Every symbol appearing anywhere in the model's numbers."""
        found: set[sp.Symbol] = set()
        for value in _all_scalars(self):
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
                actuator=None if j.actuator is None else j.actuator.substitute(subs),
            )
            for j in self.joints
        )
        params = tuple(p for p in self.parameters if p.symbol not in subs)
        return replace(self, links=links, joints=joints, gravity=sv(self.gravity),
                       parameters=params)

    def with_numeric_parameters(self, values: Mapping[sp.Symbol, float] | None = None) -> "RobotModel":
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


def _all_scalars(model: RobotModel) -> Iterable[sp.Expr]:
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
        if joint.actuator is not None:
            yield from joint.actuator.scalars()


# ----------------------------------------------------------------------------------------------
# Validation, shared by every parser: one place for each rule.
# ----------------------------------------------------------------------------------------------

def _number(x: sp.Expr) -> float | None:
    """The float value of x when it is a plain number, else None (symbolic)."""
    if isinstance(x, sp.Basic) and x.is_number:
        try:
            return float(x)
        except TypeError:  # complex numbers
            return float("nan")
    return None


def check_inertial(source: str, link: str, inertial: Inertial,
                   at_defaults: bool = False) -> tuple[Notice, ...]:
    """Check a link's inertial data: finite non-negative mass, finite symmetric PSD inertia;
    return a :class:`Notice` (to warn about, or refuse under ``strict``) when the principal
    moments break the triangle inequality.

    ``at_defaults``: ``inertial`` is a symbolic one with the parameters' default values put in;
    the messages say so, and the triangle inequality is not checked (planar models describe
    thin rods, with a moment of inertia about one axis only, on purpose).
    """
    where = f"link '{link}' inertial" + (" at the parameters' default values" if at_defaults
                                         else "")
    m = _number(inertial.mass)
    if m is not None:
        if not math.isfinite(m):
            raise InvalidInertiaError(source, where, f"mass is {m}, not a finite number")
        if m < 0:
            raise InvalidInertiaError(source, where, f"mass {m} is negative")
    for v in inertial.com:
        c = _number(v)
        if c is not None and not math.isfinite(c):
            raise InvalidInertiaError(source, where, "centre of mass is not finite")
    values = [[_number(v) for v in row] for row in inertial.inertia]
    if any(v is None for row in values for v in row):
        return ()  # symbolic inertia: checked at the numeric values by verification
    import numpy as np

    I = np.array(values, dtype=float)
    if not np.all(np.isfinite(I)):
        raise InvalidInertiaError(source, where, "inertia has a non-finite entry")
    if not np.allclose(I, I.T, rtol=0, atol=1e-12 * max(1.0, np.abs(I).max())):
        raise InvalidInertiaError(source, where, "inertia is not symmetric")
    eig = np.linalg.eigvalsh(I)
    scale = max(1.0, float(np.abs(eig).max()))
    if eig.min() < -1e-12 * scale:
        raise InvalidInertiaError(
            source, where, f"inertia has a negative eigenvalue ({eig.min():.6g})"
        )
    a, b, c = sorted(eig)
    if a + b < c - 1e-9 * scale and not at_defaults:
        return (Notice(NoticeKind.TRIANGLE_INEQUALITY, source, where,
                       f"principal moments {a:.6g}, {b:.6g}, {c:.6g} break the triangle "
                       "inequality (not a physical rigid body)", links=(link,)),)
    return ()


def check_tree(source: str, links: Iterable[str], joints: Iterable[Joint]) -> str:
    """Check that links and joints form one tree; return the root link's name.

    Raises :class:`~eomgen.errors.KinematicTreeError` for duplicate link or joint names, a
    joint naming an unknown link, a link with two parents, a cycle, more than one root
    (disconnected links).
    """
    links = list(links)
    joints = list(joints)
    seen: set[str] = set()
    for name in links:
        if name in seen:
            raise KinematicTreeError(source, f"link '{name}'", "duplicate link name")
        seen.add(name)
    joint_names: set[str] = set()
    parent_of: dict[str, str] = {}
    for j in joints:
        if j.name in joint_names:
            raise KinematicTreeError(source, f"joint '{j.name}'", "duplicate joint name")
        joint_names.add(j.name)
        for role, link in (("parent", j.parent), ("child", j.child)):
            if link not in seen:
                raise KinematicTreeError(source, f"joint '{j.name}'",
                                       f"{role} link '{link}' is not defined")
        if j.child in parent_of:
            raise KinematicTreeError(source, f"joint '{j.name}'",
                                   f"link '{j.child}' already has a parent joint")
        if j.parent == j.child:
            raise KinematicTreeError(source, f"joint '{j.name}'", "joint connects a link to itself")
        parent_of[j.child] = j.parent
    for name in links:  # cycle detection by walking up
        visited = {name}
        node = name
        while node in parent_of:
            node = parent_of[node]
            if node in visited:
                raise KinematicTreeError(source, f"link '{name}'", "kinematic loop (cycle)")
            visited.add(node)
    roots = [name for name in links if name not in parent_of]
    if not roots:
        raise KinematicTreeError(source, "robot", "no root link")
    if len(roots) > 1:
        raise KinematicTreeError(
            source, f"link '{roots[1]}'",
            f"not connected to the tree rooted at '{roots[0]}' (no parent joint)")
    return roots[0]


def check_axis(source: str, joint: str, axis: Vec3) -> Vec3:
    """Return the unit axis; refuse zero, NaN or infinite axes."""
    values = [_number(v) for v in axis]
    if any(v is None for v in values):
        return axis  # symbolic axis: the user's responsibility to keep it unit
    if not all(math.isfinite(v) for v in values):
        raise InvalidAxisError(source, f"joint '{joint}' axis", "axis is not finite")
    norm = math.sqrt(sum(v * v for v in values))
    if norm < 1e-12:
        raise InvalidAxisError(source, f"joint '{joint}' axis", "axis is zero")
    if abs(norm - 1.0) < 1e-12:
        return axis
    return vec3([_snap(v / norm, f"joint '{joint}' axis") for v in values])


def _is_symbolic(inertial: Inertial) -> bool:
    return any(isinstance(v, sp.Basic) and v.free_symbols
               for v in (inertial.mass, *inertial.com, *sum(inertial.inertia, ())))


def _substituted(inertial: Inertial, values: Mapping[sp.Symbol, sp.Expr]) -> Inertial:
    return Inertial(inertial.mass.xreplace(values),
                    tuple(v.xreplace(values) for v in inertial.com),
                    tuple(tuple(v.xreplace(values) for v in row) for row in inertial.inertia))


def check_actuator(source: str, joint: Joint, values: Mapping[sp.Symbol, sp.Expr] | None = None,
                   where: str | None = None) -> None:
    """Refuse an actuator that is not physical; values still symbolic after ``values`` (the
    parameters' defaults) are not checked.

    Raises
    ------
    KinematicTreeError
        An actuator on a fixed joint.
    InvalidActuatorError
        Negative armature, rotor inertia, damping or Coulomb friction, a friction width or
        stiffness that is not positive, a gear ratio of 0, or zero motor inertia (armature) on
        a flexible joint: Spong's motor equation ``B θ̈_m + K (θ_m − q) = τ_m`` needs ``B > 0``.
    """
    a = joint.actuator
    if a is None:
        return
    where = where or f"joint '{joint.name}' actuator"
    if not joint.type.is_movable:
        raise KinematicTreeError(source, where, "a fixed joint cannot have an actuator")
    if values:
        a = a.substitute(values)

    def number(name):
        value = getattr(a, name)
        return None if value is None else _number(value)

    for name in ("armature", "rotor_inertia"):
        v = number(name)
        if v is not None and v < 0:
            raise InvalidActuatorError(source, where, f"{name} {v:g} is negative")
    for name in ("damping", "friction"):
        v = number(name)
        if v is not None and v < 0:
            raise InvalidActuatorError(source, where, f"{name} {v:g} is negative")
    v = number("friction_width")
    if v is not None and v <= 0:
        raise InvalidActuatorError(source, where, f"friction_width {v:g} is not positive")
    v = number("gear_ratio")
    if v is not None and v == 0:
        raise InvalidActuatorError(source, where, "gear_ratio is 0 (the motor would not move "
                                 "the joint)")
    v = number("stiffness")
    if v is not None and v <= 0:
        raise InvalidActuatorError(source, where, f"stiffness {v:g} is "
                                 + ("negative" if v < 0 else "zero")
                                 + " (a flexible joint needs K > 0)")
    B = number("armature")
    if a.flexible and B is not None and B == 0:
        raise InvalidActuatorError(source, where, "zero motor inertia on a flexible joint (give "
                                  "armature or rotor_inertia and gear_ratio > 0)")


def check_size(source: str, links: int, joints: int) -> None:
    """Refuse models with more than :data:`MAX_JOINTS` joints (or ``MAX_JOINTS + 1`` links);
    parsers call it as soon as they have counted, before reading the elements."""
    if joints > MAX_JOINTS:
        raise TooLargeError(source, "robot",
                            f"{joints} joints; eomgen handles at most {MAX_JOINTS}")
    if links > MAX_JOINTS + 1:
        raise TooLargeError(source, "robot",
                            f"{links} links; eomgen handles at most {MAX_JOINTS + 1}")


def build_model(
    source: str,
    name: str,
    links: Iterable[Link],
    joints: Iterable[Joint],
    gravity: Iterable = (0, 0, -9.81),
    parameters: Iterable[Parameter] = (),
    strict: bool = False,
    info: Mapping[str, object] | None = None,
    defer_notices: bool = False,
) -> RobotModel:
    """Validate parsed parts and assemble a :class:`RobotModel`. Every parser ends here.

    Findings that do not stop the model from loading (inertias that break the triangle
    inequality) are recorded in :attr:`RobotModel.notices` and, unless ``defer_notices``,
    warned about at once (raised under ``strict``) by :func:`emit_notices`.

    Raises a subclass of :class:`~eomgen.errors.DescriptionError` naming ``source`` and the
    element at fault: :class:`~eomgen.errors.TooLargeError` (more than :data:`MAX_JOINTS`
    joints), :class:`~eomgen.errors.InvalidAxisError`,
    :class:`~eomgen.errors.KinematicTreeError`, :class:`~eomgen.errors.InvalidInertiaError`,
    :class:`~eomgen.errors.InvalidNumberError` (gravity) or
    :class:`~eomgen.errors.ParameterError` (duplicate parameters).
    """
    links = tuple(links)
    joints = tuple(joints)
    check_size(source, len(links), len(joints))
    joints = tuple(replace(j, axis=check_axis(source, j.name, j.axis)) for j in joints)
    root = check_tree(source, (l.name for l in links), joints)
    params = tuple(parameters)
    defaults = {p.symbol: scalar(p.value) for p in params if p.value is not None}
    notices: list[Notice] = []
    for link in links:
        if link.inertial is not None:
            notices += check_inertial(source, link.name, link.inertial)
            if defaults and _is_symbolic(link.inertial):
                notices += check_inertial(source, link.name,
                                          _substituted(link.inertial, defaults), at_defaults=True)
    for joint in joints:
        check_actuator(source, joint)
        if defaults and joint.actuator is not None:
            check_actuator(source, joint, defaults, where=f"joint '{joint.name}' actuator at "
                           "the parameters' default values")
    gravity = vec3(gravity)
    for v in gravity:
        g = _number(v)
        if g is not None and not math.isfinite(g):
            raise InvalidNumberError(source, "gravity", "gravity is not finite")
    names = [p.name for p in params]
    for p in params:
        if names.count(p.name) > 1:
            raise ParameterError(source, f"parameter '{p.name}'", "duplicate parameter")
    model = RobotModel(name=name, links=links, joints=joints, root=root, gravity=gravity,
                       parameters=params, source=str(source),
                       info=tuple((info or {}).items()), notices=tuple(notices))
    undeclared = sorted((s for s in model.free_symbols if s.name not in names), key=str)
    if undeclared:
        model = replace(model, parameters=params + tuple(Parameter(s) for s in undeclared))
    if not defer_notices:
        emit_notices(model.notices, strict)
    return model


def joint_motion(joint: Joint, value) -> Transform:
    """The transform a joint applies at position ``value`` (rad or m): child frame in joint frame."""
    value = scalar(value) if not isinstance(value, sp.Basic) else value
    if joint.type.is_revolute:
        return Transform(rotation_about_axis(joint.axis, value), ZERO3)
    if joint.type is JointType.PRISMATIC:
        return Transform(IDENTITY3, tuple(a * value for a in joint.axis))  # type: ignore[arg-type]
    return Transform()


def lock_joints(model: RobotModel, positions: Mapping[str, object]) -> RobotModel:
    """A copy of ``model`` with the named movable joints made fixed at the given positions.

    Raises
    ------
    KinematicTreeError
        When a name is not a movable joint of the model.
    """
    movable = {j.name for j in model.movable_joints}
    for name in positions:
        if name not in movable:
            raise KinematicTreeError(model.source, f"joint '{name}'",
                                   "cannot lock: not a movable joint of this model")
    joints = tuple(
        replace(j, type=JointType.FIXED, origin=j.origin @ joint_motion(j, positions[j.name]))
        if j.name in positions else j
        for j in model.joints
    )
    return replace(model, joints=joints)
