"""The free flyer's symbolic pieces, as they were named before ball joints joined it: the root
pose from ``q[0:7]`` and the chart corrections for a model whose only quaternion joint is a
free flyer at ``v[0:6]``. Every function is :mod:`eomgen.symbolic.charts` (which
holds the mechanism and its derivation, for the free flyer and ball joints alike) with that
layout bound; new code calls that module with the model's
:attr:`~eomgen.model.RobotModel.quaternion_joints`.
"""

from __future__ import annotations

import sympy as sp

from ..model import QuaternionJoint, Transform
from ..model.quaternion import FREE_FLYER
from . import charts as _quaternion
from .charts import quaternion_rotation

#: The free flyer as the first joint of a model (velocity and configuration both at 0).
FREE_FLYER_JOINT = QuaternionJoint(FREE_FLYER, "base", 0, 0)


def root_placement(q, b) -> Transform:
    """The pose of the root link in the world from ``q[0:7]`` (position, quaternion x, y, z,
    w), its rotation's entries named ``Rb11 … Rb33`` in the program builder ``b``."""
    return _quaternion.placement(FREE_FLYER_JOINT, q, b)


def chart_offset(v) -> tuple:
    """``n(v)`` for the root twist ``v[0:6]``: 6 entries, linear first."""
    return _quaternion.chart_offset((FREE_FLYER_JOINT,), tuple(v[:6]))


def chart_accelerations(qd, qdd) -> tuple:
    """The chart accelerations of true accelerations ``qdd`` at velocity ``qd``."""
    return _quaternion.chart_accelerations((FREE_FLYER_JOINT,), qd, qdd)


def true_accelerations(qd, chart) -> tuple:
    """The inverse of :func:`chart_accelerations`."""
    return _quaternion.true_accelerations((FREE_FLYER_JOINT,), qd, chart)


def coriolis_correction(qd) -> sp.Matrix:
    """K(v) (6×6): column ``i`` is ``(Σ_{j>i} Sⱼ vⱼ) × Sᵢ``."""
    return _quaternion.coriolis_correction(FREE_FLYER_JOINT, qd)


def corrected_coriolis(C: sp.Matrix, M: sp.Matrix, qd) -> sp.Matrix:
    """The free flyer's C from the chart's: ``C + M[:, 0:6] K(v)`` in the base columns."""
    return _quaternion.corrected_coriolis((FREE_FLYER_JOINT,), C, M, qd)


__all__ = ["FREE_FLYER_JOINT", "chart_accelerations", "chart_offset", "coriolis_correction",
           "corrected_coriolis", "quaternion_rotation", "root_placement", "true_accelerations"]
