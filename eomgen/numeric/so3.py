"""Rotations as numbers: the skew matrix, the exponential and the logarithm of SO(3), kept
importable here; they live once in :mod:`eomgen.model.joints.lie`, the floor every joint kind
stands on (the symbolic counterparts, over SymPy expressions, are
:mod:`eomgen.symbolic.spatial`'s ``skew`` and ``rotation``).
"""

from __future__ import annotations

from ..model.joints.lie import left_jacobian, rotation_about, skew, so3_exp, so3_log

__all__ = ["left_jacobian", "rotation_about", "skew", "so3_exp", "so3_log"]
