"""Revolute and continuous joints: a rotation by ``q`` [rad] about the unit ``axis`` (joint
frame, right hand rule); NQ = NV = 1, ``S = (0, axis)``. A revolute joint has limits, a
continuous one none: the dynamics are the same (Pinocchio's ``JointModelRevoluteUnaligned``;
its ``RevoluteUnbounded`` kind stores ``cos q, sin q`` instead, which eomgen does not)."""

from __future__ import annotations

import numpy as np

from .base import JointKind
from .lie import rotation_about


class Revolute(JointKind):
    name = "revolute"
    pinocchio = "JointModelRevoluteUnaligned"
    rotates = True

    def transform(self, axis, q, pitch: float = 0.0):
        return rotation_about(np.asarray(axis, dtype=float), float(np.ravel(q)[0])), np.zeros(3)

    def motion_subspace(self, axis, q=None, pitch: float = 0.0) -> np.ndarray:
        return np.concatenate([np.zeros(3), np.asarray(axis, dtype=float)]).reshape(6, 1)


class Continuous(Revolute):
    name = "continuous"


REVOLUTE = Revolute()
CONTINUOUS = Continuous()

__all__ = ["CONTINUOUS", "Continuous", "REVOLUTE", "Revolute"]
