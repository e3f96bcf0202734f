"""Prismatic joints: a translation by ``q`` [m] along the unit ``axis`` (joint frame); NQ =
NV = 1, ``S = (axis, 0)`` (Pinocchio's ``JointModelPrismaticUnaligned``)."""

from __future__ import annotations

import numpy as np

from .base import JointKind


class Prismatic(JointKind):
    name = "prismatic"
    pinocchio = "JointModelPrismaticUnaligned"
    translates = True

    def lead(self, pitch=0):
        return 1

    def transform(self, axis, q, pitch: float = 0.0):
        return np.eye(3), np.asarray(axis, dtype=float) * float(np.ravel(q)[0])

    def motion_subspace(self, axis, q=None, pitch: float = 0.0) -> np.ndarray:
        return np.concatenate([np.asarray(axis, dtype=float), np.zeros(3)]).reshape(6, 1)


PRISMATIC = Prismatic()

__all__ = ["PRISMATIC", "Prismatic"]
