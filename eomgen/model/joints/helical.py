"""Helical (screw) joints: a rotation by ``q`` [rad] about the unit ``axis`` together with a
translation of ``pitch · q`` [m] along it (``pitch`` in m/rad; a right-handed screw for a
positive pitch); NQ = NV = 1, ``S = (pitch · axis, axis)`` (Pinocchio's
``JointModelHelicalUnaligned(axis, pitch)``).

A helical joint is a joint of the kinematic tree in its own right, one coordinate like a
revolute or prismatic one: the algorithms turn its child by ``q`` about the axis (it
:attr:`~Helical.rotates`) and move it ``pitch · q`` along the axis (its
:meth:`~Helical.lead` is the pitch), so every output of revolute and prismatic joints is
derived for it.
"""

from __future__ import annotations

import math

import numpy as np

from ...errors import InvalidNumberError
from .base import JointKind
from .lie import rotation_about


class Helical(JointKind):
    name = "helical"
    pinocchio = "JointModelHelicalUnaligned"
    rotates = translates = True

    def lead(self, pitch=0):
        return pitch

    def check(self, source: str, joint) -> None:
        try:
            pitch = float(joint.pitch)
        except TypeError:  # a symbolic pitch: a parameter, checked where it has a value
            return
        if not math.isfinite(pitch):
            raise InvalidNumberError(source, f"joint '{joint.name}' pitch",
                                     "the pitch is not finite")

    def transform(self, axis, q, pitch: float = 0.0):
        axis, angle = np.asarray(axis, dtype=float), float(np.ravel(q)[0])
        return rotation_about(axis, angle), axis * (pitch * angle)

    def motion_subspace(self, axis, q=None, pitch: float = 0.0) -> np.ndarray:
        axis = np.asarray(axis, dtype=float)
        return np.concatenate([pitch * axis, axis]).reshape(6, 1)


HELICAL = Helical()

__all__ = ["HELICAL", "Helical"]
