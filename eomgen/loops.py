"""Closed kinematic chains (a scene's ``loops:``), numerically: :class:`LoopDynamics`
(constrained forward dynamics with loops and contacts, parallel inverse dynamics, closure by
Newton) from :mod:`eomgen.numeric.loops`, whose docstring gives the conventions; the generated
rows are :mod:`eomgen.symbolic.loops`'. docs/loops.md shows them at work."""

from __future__ import annotations

from .numeric.loops import AssemblyError, LoopDynamics, kkt_solve

__all__ = ["AssemblyError", "LoopDynamics", "kkt_solve"]
