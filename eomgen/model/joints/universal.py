"""Universal (Cardan, Hooke) joints: the child turns by ``q1`` about the joint frame's x axis,
then by ``q2`` about the y axis so turned, as Pinocchio's ``JointModelUniversal(x, y)``.

* configuration = velocity (NQ = NV = 2): ``<name>_rx``, the angle ``q1`` [rad] about the
  joint frame's x axis; ``<name>_ry``, the angle ``q2`` [rad] about the turned y axis (right
  hand rule both); their rates [rad/s] are the velocity;
* the pose: ``R = Rx(q1) Ry(q2)``, no translation (the cross's centre is the joint frame's
  origin);
* the motion subspace, in the child frame: ``S = (0, 0; Ry(q2)ᵀ x, y)``, so ``S`` turns with
  ``q2`` (Pinocchio's ``S`` for ``axis1 = x``, ``axis2 = y``).

A description gives the joint frame (its ``origin``) and leaves the ``axis`` at ``0 0 1``:
the shaft, the direction both pivot axes are normal to at ``q = 0``; to pivot about other
axes, turn the joint frame. Pinocchio's axes must be orthogonal unit vectors too (it asserts
so); its ``axis1``, ``axis2`` are this joint frame's x and y.

In the tree: two continuous joints ``<name>_rx`` about x, ``<name>_ry`` about the y of the
massless link between them (the chain, :class:`~.base.ChainKind`); the configuration is their
coordinates, so every output of revolute joints is derived for it, and ``q ⊕ v = q + v``.
"""

from __future__ import annotations

import numpy as np

from ...errors import UnsupportedError
from .base import ChainKind, zeros
from .lie import rotation_about

_X, _Y = np.eye(3)[0], np.eye(3)[1]


class Universal(ChainKind):
    name = "universal"
    nq, nv = 2, 2
    pinocchio = "JointModelUniversal"
    motions = (3, 4)
    velocity_suffixes = ("rx", "ry")

    def check(self, source: str, joint) -> None:
        if tuple(joint.axis) != (0, 0, 1):
            raise UnsupportedError(source, f"joint '{joint.name}' axis", "a universal joint "
                                   "turns about its joint frame's x axis, then the turned y "
                                   "axis (Pinocchio's JointModelUniversal): its axis, the "
                                   "shaft normal to both, must be 0 0 1; turn the joint frame "
                                   "with the joint's origin")

    def pose(self, q, numbers=None):
        q1, q2 = q
        R = rotation_about(_X, q1, numbers) @ rotation_about(_Y, q2, numbers)
        return R, zeros(numbers, 3)

    def motion_subspace(self, axis=None, q=None, pitch: float = 0.0) -> np.ndarray:
        S = np.zeros((6, 2))
        S[3:, 0] = rotation_about(_Y, float(q[1])).T @ _X
        S[3:, 1] = _Y
        return S

    def describe(self) -> tuple[str, str, str]:
        return ("universal",
                "the angle $q_1$ about the joint frame's $x$ axis, then $q_2$ about the turned "
                "$y$ axis (rad)",
                "$\\dot q_1$, $\\dot q_2$ (rad/s)")


UNIVERSAL = Universal()

__all__ = ["UNIVERSAL", "Universal"]
