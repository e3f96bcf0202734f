"""Snapping: rotation and axis entries read from floats within :data:`SNAP_TOLERANCE` of 0 or ±1
are made exact, inside a :func:`snapping` block that records each change (:class:`Snap`)."""

from __future__ import annotations

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
