"""Validation shared by every parser, one place for each rule, and :func:`build_model`, where
every parser ends."""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Iterable, Mapping

import sympy as sp

from ..errors import (
    InvalidActuatorError,
    InvalidAxisError,
    InvalidInertiaError,
    KinematicTreeError,
    ParameterError,
    TooLargeError,
)
from .moving_mass import settled
from .notices import Notice, NoticeKind, emit_notices
from .numbers import check_model_numbers
from .parts import Inertial, Joint, Link, Parameter
from .quaternion import expand_joints
from .robot import RobotModel
from .scalars import Vec3, scalar, vec3
from .snapping import snap

#: At most this many joints (and one more link) in a model: beyond, a symbolic derivation is
#: out of reach anyway, and the checks stay linear in practice.
MAX_JOINTS = 500


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
    if _clearly_fine(values, at_defaults):
        return ()
    # Near a threshold, or a finding to report: NumPy's eigenvalues decide and are quoted.
    import numpy as np  # here: `import eomgen` does not load NumPy (start-up time)

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


#: How far (times the sum of the entries' magnitudes) the closed-form principal moments of
#: :func:`_principal_moments` must keep from a threshold of :func:`check_inertial` to decide
#: without NumPy: their error was at most 4.8e-9 of that sum over 200,000 random symmetric
#: matrices, near-degenerate ones included; NumPy's ``eigvalsh`` errs by about 1e-16 of it
#: (and both give a diagonal matrix's entries exactly: no margin there).
_EIGEN_MARGIN = 1e-6


def _principal_moments(I) -> list[float]:
    """The eigenvalues of the symmetric 3×3 ``I`` (rows of floats), ascending, by the closed
    form of Smith (1961): plain floats, so loading a description does not import NumPy. Exact
    for a diagonal ``I``; else accurate to a few 1e-9 of the entries' magnitudes."""
    a00, a01, a02 = I[0]
    a11, a12, a22 = I[1][1], I[1][2], I[2][2]
    p1 = a01 * a01 + a02 * a02 + a12 * a12
    if p1 == 0:
        return sorted((a00, a11, a22))
    q = (a00 + a11 + a22) / 3
    p = math.sqrt(((a00 - q) ** 2 + (a11 - q) ** 2 + (a22 - q) ** 2 + 2 * p1) / 6)
    b00, b11, b22, b01, b02, b12 = (a00 - q) / p, (a11 - q) / p, (a22 - q) / p, a01 / p, \
        a02 / p, a12 / p
    r = (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02)
         + b02 * (b01 * b12 - b11 * b02)) / 2
    phi = math.acos(min(1.0, max(-1.0, r))) / 3
    largest = q + 2 * p * math.cos(phi)
    smallest = q + 2 * p * math.cos(phi + 2 * math.pi / 3)
    return [smallest, 3 * q - largest - smallest, largest]


def _clearly_fine(values, at_defaults: bool) -> bool:
    """Whether the finite numeric inertia ``values`` (rows) passes every check of
    :func:`check_inertial` by a margin (:data:`_EIGEN_MARGIN`) no rounding of the eigenvalues
    can cross: then NumPy's check, which this stands in for, passes too."""
    if not all(math.isfinite(v) for row in values for v in row):
        return False
    size = sum(abs(v) for row in values for v in row)
    atol = 1e-12 * max(1.0, max(abs(v) for row in values for v in row))
    if any(abs(values[r][c] - values[c][r]) > atol for r in range(3) for c in range(3)):
        return False
    diagonal = all(values[r][c] == 0 for r in range(3) for c in range(3) if r != c)
    margin = 0.0 if diagonal else _EIGEN_MARGIN * size  # a diagonal's are exact in both
    a, b, c = _principal_moments(values)
    scale = max(1.0, abs(a), abs(c))
    if a < -1e-12 * scale + margin:
        return False
    return at_defaults or a + b >= c - 1e-9 * scale + margin


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
    return vec3([snap(v / norm, f"joint '{joint}' axis") for v in values])


def check_kind(source: str, joint: Joint) -> None:
    """Refuse what a joint's kind cannot be (its kind's
    :meth:`~eomgen.model.joints.JointKind.check`: a planar joint whose axis is not the joint
    frame's z axis, a helical joint whose pitch is not a finite number)."""
    joint.type.kind.check(source, joint)


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
    :class:`~eomgen.errors.InvalidNumberError` (a number that is not finite or of magnitude
    above 1e12: :mod:`eomgen.model.numbers`) or
    :class:`~eomgen.errors.ParameterError` (duplicate parameters).
    """
    links = tuple(links)
    joints = tuple(joints)
    check_size(source, len(links), len(joints))
    params = tuple(parameters)
    defaults = {p.symbol: scalar(p.value) for p in params if p.value is not None}
    gravity = vec3(gravity)
    # every number finite and of magnitude at most 1e12, expressions at the defaults
    check_model_numbers(source, links, joints, gravity, defaults)
    joints = tuple(replace(j, axis=check_axis(source, j.name, j.axis)) for j in joints)
    for joint in joints:
        check_kind(source, joint)
    root = check_tree(source, (l.name for l in links), joints)
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
    names = [p.name for p in params]
    for p in params:
        if names.count(p.name) > 1:
            raise ParameterError(source, f"parameter '{p.name}'", "duplicate parameter")
    model = RobotModel(name=name, links=links, joints=joints, root=root, gravity=gravity,
                       parameters=params, source=str(source),
                       info=tuple((info or {}).items()), notices=tuple(notices))
    model = expand_joints(model)  # a parser's ball and planar joints: their chains
    undeclared = sorted((s for s in model.free_symbols if s.name not in names), key=str)
    if undeclared:
        model = replace(model, parameters=params + tuple(Parameter(s) for s in undeclared))
    if not defer_notices:
        model = settled(model)
        emit_notices(model.notices, strict)
    return model
