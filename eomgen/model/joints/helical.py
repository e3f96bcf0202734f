"""Helical (screw) joints: a rotation by ``q`` [rad] about the unit ``axis`` together with a
translation of ``pitch · q`` [m] along it (``pitch`` in m/rad; a right-handed screw for a
positive pitch); NQ = NV = 1, ``S = (pitch · axis, axis)`` (Pinocchio's
``JointModelHelicalUnaligned(axis, pitch)``).

In the kinematic tree a helical joint ``<name>`` is a continuous joint ``<name>`` (the
coordinate, at the helical joint's place) followed, through a massless link
``<child>_<name>_screw``, by a prismatic joint ``<name>_screw`` along the same axis whose
position a coupling holds at ``pitch · q`` (:mod:`eomgen.model.coupling`): the two motions
commute, so the child's pose and velocity are the screw's, and the dynamics in the one
coordinate are exact (``M = Tᵀ M_full T``). :func:`chain` writes them.
"""

from __future__ import annotations

import numpy as np

from .base import JointKind
from .lie import rotation_about

#: The suffix of the virtual prismatic joint and link of a helical joint.
SCREW = "screw"


class Helical(JointKind):
    name = "helical"
    pinocchio = "JointModelHelicalUnaligned"
    rotates = translates = True

    def transform(self, axis, q, pitch: float = 0.0):
        axis, angle = np.asarray(axis, dtype=float), float(np.ravel(q)[0])
        return rotation_about(axis, angle), axis * (pitch * angle)

    def motion_subspace(self, axis, pitch: float = 0.0) -> np.ndarray:
        axis = np.asarray(axis, dtype=float)
        return np.concatenate([pitch * axis, axis]).reshape(6, 1)

    def chain(self, joint: str, child: str) -> tuple[str, str]:
        """``(prismatic joint, massless link)``: the names of the helical joint ``joint``'s
        virtual prismatic joint and of the link between it and the continuous joint."""
        return f"{joint}_{SCREW}", f"{child}_{joint}_{SCREW}"

    def element(self, joint: str) -> str:
        """The element the coupling of helical joint ``joint``'s screw names (its errors')."""
        return f"helical joint '{joint}' pitch"

    def coupled(self, coupling) -> str | None:
        """The helical joint whose screw ``coupling`` couples (a
        :class:`~eomgen.model.coupling.Coupling`), or None for a coupling a description
        wrote."""
        leader = coupling.leaders[0][0] if len(coupling.leaders) == 1 else None
        if leader is not None and (coupling.follower, coupling.element) == (
                self.chain(leader, "")[0], self.element(leader)):
            return leader
        return None


HELICAL = Helical()

__all__ = ["HELICAL", "Helical", "SCREW"]
