"""The rule for every number read from a description or a scene: finite, and of magnitude at
most :data:`MAX_MAGNITUDE`.

One rule for every format (URDF, MJCF, eomgen YAML, DH tables, scenes) and every quantity
(lengths, masses, inertias, gravity, joint drives, gears, coupling gains, loop frames):

* **finite**: ``nan`` and ``inf`` describe no robot, and a NaN reaching the generated code
  makes M, C and g NaN without a word;
* **|x| ≤ 1e12** in SI units: no robot has a length of 10¹² m (7 astronomical units), a
  mass of 10¹² kg or an inertia of 10¹² kg m² (a 300 m ship has about 10¹¹), a gravity,
  damping, gear ratio or stiffness that large; and the derivation multiplies a handful of
  numbers (a coupling gain squared, a mass, a length squared: 10⁶⁰ at most), far from the
  double range (1.8·10³⁰⁸), where 10¹⁰⁰ or 10³⁰⁰ gave ``inf`` constants in the generated code
  (modules that do not import, C that does not compile).

Numbers eomgen reads but does not use in the equations of motion are not held to it: a joint
limit of ``1e16`` or ``inf`` means "no limit" in URDF files and is read as such
(:func:`eomgen.parsers.urdf.joint_limits` refuses only ``nan`` there); MJCF joint ranges are not
read at all.

Parsers call :func:`check_number` where they read a number (naming the element and
attribute); :func:`check_model_numbers` checks every number of an assembled model (at the
parameters' default values for expressions), which :func:`eomgen.model.build_model` applies to
every model, so that numbers made by composition (a MuJoCo-compiled inertia, an expression
``l**3``) are held to the same rule.
"""

from __future__ import annotations

import math
from typing import Iterable, Iterator, Mapping

import sympy as sp

from ..errors import InvalidNumberError

#: Numbers of larger magnitude are refused (see the module docstring): no robot needs them in
#: SI units, and products of up to 25 of them stay within double precision.
MAX_MAGNITUDE = 1e12


def number_problem(value) -> str | None:
    """Why ``value`` (an int, float or SymPy number) breaks the rule, or None when it keeps
    it: ``"is not a finite number"`` or ``"is out of range (magnitude above 1e+12)"``."""
    try:
        magnitude = abs(float(value))
    except OverflowError:  # an integer beyond the float range
        magnitude = math.inf
    except TypeError:  # a complex SymPy number
        return "is not a finite real number"
    if math.isnan(magnitude):
        return "is not a finite number"
    if math.isinf(magnitude) and not _finite_beyond_doubles(value):
        return "is not a finite number"
    if not magnitude <= MAX_MAGNITUDE:
        return f"is out of range (magnitude above {MAX_MAGNITUDE:g})"
    return None


def _finite_beyond_doubles(value) -> bool:
    """Whether ``value`` is finite though beyond the float range (a long integer, a SymPy
    ``Float('1e400')``)."""
    return (isinstance(value, int) and not isinstance(value, bool)) or (
        isinstance(value, sp.Basic) and bool(value.is_finite))


def check_number(value, source: str, where: str, label: str = "", shown: str | None = None
                 ) -> float:
    """``float(value)`` if it keeps the rule, else an
    :class:`~eomgen.errors.InvalidNumberError` naming ``source`` and ``where``:
    ``"<label> <shown> is not a finite number"`` (``shown`` defaults to the value)."""
    problem = number_problem(value)
    if problem is not None:
        text = shown if shown is not None else _show(value)
        raise InvalidNumberError(source, where, " ".join(p for p in (label, text, problem) if p))
    return float(value)


def check_numbers(values: Iterable, source: str, where: str, label: str = "") -> tuple:
    """:func:`check_number` on each of ``values`` (a vector: the label says which entry)."""
    return tuple(check_number(v, source, where, label) for v in values)


def _show(value) -> str:
    try:
        return f"{float(value):g}"
    except (TypeError, OverflowError):
        text = str(value)
        return text if len(text) <= 24 else text[:24] + "..."


def model_numbers(links, joints, gravity) -> Iterator[tuple[str, str, object]]:
    """``(element, label, value)`` for every number of a model's parts: gravity, each link's
    mass, centre of mass and inertia, each joint's origin, axis, pitch and drive."""
    for k, g in enumerate(gravity):
        yield "gravity", f"entry {k}", g
    for link in links:
        if link.inertial is None:
            continue
        where = f"link '{link.name}' inertial"
        yield where, "mass", link.inertial.mass
        for v in link.inertial.com:
            yield where, "centre of mass entry", v
        for row in link.inertial.inertia:
            for v in row:
                yield where, "inertia entry", v
    for joint in joints:
        where = f"joint '{joint.name}'"
        for v in joint.origin.translation:
            yield where, "origin translation entry", v
        for row in joint.origin.rotation:
            for v in row:
                yield where, "origin rotation entry", v
        for v in joint.axis:
            yield where, "axis entry", v
        yield where, "pitch", joint.pitch
        actuator = joint.actuator
        if actuator is not None:
            for name in ("armature", "damping", "friction", "friction_width", "stiffness",
                         "rotor_inertia", "gear_ratio"):
                value = getattr(actuator, name)
                if value is not None:
                    yield f"{where} actuator", name, value


def check_model_numbers(source: str, links, joints, gravity,
                        defaults: Mapping[sp.Symbol, object] | None = None) -> None:
    """Every number of a model's parts (:func:`model_numbers`) keeps the rule; an expression
    in parameters is checked at their ``defaults`` (skipped when a symbol has none).

    Raises
    ------
    InvalidNumberError
        Naming ``source``, the element and the value.
    """
    for where, label, value in model_numbers(links, joints, gravity):
        if isinstance(value, sp.Basic) and not value.is_number:
            if not defaults:
                continue
            value = value.xreplace(defaults)
            if not value.is_number:
                continue
            label = f"{label} (at the parameters' default values)"
        check_number(value, source, where, label)


__all__ = ["MAX_MAGNITUDE", "check_model_numbers", "check_number", "check_numbers",
           "model_numbers", "number_problem"]
