"""Snapping: rotation and axis entries read from floats within :data:`SNAP_TOLERANCE` of 0 or ±1,
and rotation angles read from floats within :data:`ANGLE_SNAP_TOLERANCE` of a multiple of π/12,
are made exact, inside a :func:`snapping` block that records each change (:class:`Snap`).

An angle written exactly (``pi/6`` in eomgen's YAML or a DH table) is not snapped: it is exact
already (:func:`exact_angle`)."""

from __future__ import annotations

import math
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

import sympy as sp

from .scalars import scalar

#: Rotation entries read from floats that lie within this distance of 0 or ±1 are made exact,
#: so that ``rpy="1.57079632679 0 0"`` keeps its structural zeros. The change to the model is
#: below the precision such descriptions are written with, but not below float64's: a model
#: snapped this way differs from tools that keep the floats by up to this much (relative 1e-10
#: in τ of the UR5). ``eomgen.load(path, snap=False)`` (``--no-snap``) keeps the floats; the
#: entries that were snapped are listed in ``model.info`` under ``"snapped"`` (:class:`Snap`).
SNAP_TOLERANCE = 1e-11

#: Rotation angles read from floats within this distance of a multiple of π/12 (15°) that is
#: not one of π/2 (those the entries' snapping makes exact) are made that multiple exactly, so
#: that ``rpy="0 0 0.5235987755982988"`` gives cos = √3/2 and sin = 1/2 rather than floats
#: (and identities of the derived M, C, g hold exactly). Recorded as :class:`Snap` with the
#: exact angle as ``target``; ``snap=False`` (``--no-snap``) keeps the floats.
ANGLE_SNAP_TOLERANCE = 1e-12

#: The multiples of π/12 are the angles snapped to.
ANGLE_STEP = sp.pi / 12


@dataclass(frozen=True)
class Snap:
    """One entry made exact by snapping: ``what`` it is (``cos(1.5707963268)``, a joint's axis
    component, ``angle 0.5235987755982988``), the float ``value`` computed from the description
    and the ``target`` used instead: 0 or ±1 for an entry, a multiple of π/12 (a SymPy number)
    for an angle."""

    what: str
    value: float
    target: int | sp.Expr

    @property
    def is_angle(self) -> bool:
        """Whether an angle was snapped (to a multiple of π/12), rather than an entry."""
        return not isinstance(self.target, int)

    @property
    def change(self) -> float:
        """``|value - target|``, computed to 30 digits for an angle (its target is irrational)."""
        if not self.is_angle:
            return abs(self.value - self.target)
        return abs(float((sp.Float(self.value, 30) - self.target).evalf(30)))


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
    """One line: how many angles and entries were snapped, the largest change and where."""
    if not snaps:
        return "no rotation or axis entry snapped"
    worst = max(snaps, key=lambda s: s.change)
    kinds = sorted({s.what for s in snaps})
    listed = ", ".join(kinds[:4]) + (f" and {len(kinds) - 4} more" if len(kinds) > 4 else "")
    angles = sum(s.is_angle for s in snaps)
    entries = len(snaps) - angles
    parts = []
    if angles:
        noun = "angle" if angles == 1 else "angles"
        parts.append(f"{angles} {noun} within {ANGLE_SNAP_TOLERANCE:g} of a multiple of π/12")
    if entries:
        noun = "entry" if entries == 1 else "entries"
        parts.append(f"{entries} rotation/axis {noun} within {SNAP_TOLERANCE:g} of 0 or ±1")
    return (f"snapped {' and '.join(parts)} to exact values (largest change "
            f"{worst.change:.1e}, {worst.what}; from {listed}); --no-snap keeps the "
            "description's floats")


def snap(value: float, what: str = "") -> sp.Expr:
    """``value`` as an exact 0 or ±1 when it lies within :data:`SNAP_TOLERANCE` of one and
    snapping is on (recording a :class:`Snap` named ``what``), else :func:`scalar` of it."""
    if _SNAP_ENABLED.get():
        for target in (0.0, 1.0, -1.0):
            if abs(value - target) <= SNAP_TOLERANCE:
                records = _SNAP_RECORDS.get()
                if records is not None and value != target:
                    records.append(Snap(what, value, int(target)))
                return sp.Integer(int(target))
    return scalar(value)


def exact_angle(angle) -> sp.Expr | None:
    """``angle`` (rad) as an exact SymPy number, or None when it has none.

    An angle written exactly (a SymPy number without floats: ``pi/6``, ``0``) is itself. An
    angle read from a float within :data:`ANGLE_SNAP_TOLERANCE` of a multiple of π/12 that is
    not a multiple of π/2 is that multiple when snapping is on (recording a :class:`Snap` named
    ``angle <value>``); multiples of π/2 are left to the entries' snapping (:func:`snap`),
    whose records they have always made. Any other angle has no exact value here.
    """
    if isinstance(angle, sp.Basic) and not angle.has(sp.Float):
        return angle
    if not _SNAP_ENABLED.get():
        return None
    value = float(angle)
    k = round(value / math.pi * 12)
    if k % 6 == 0 or abs(value - k * math.pi / 12) > ANGLE_SNAP_TOLERANCE:
        return None
    target = k * ANGLE_STEP
    records = _SNAP_RECORDS.get()
    if records is not None:
        records.append(Snap(f"angle {value!r}", value, target))
    return target
