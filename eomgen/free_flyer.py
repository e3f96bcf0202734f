"""The quaternion floating base (free flyer): Pinocchio's ``JointModelFreeFlyer`` as a joint of
eomgen's model.

:func:`add_free_flyer` lets the root link of a robot fly: the configuration and the velocity
then have different sizes, NQ = NV + 1, laid out as Pinocchio lays out a model built with
``pinocchio.buildModelFromUrdf(path, pinocchio.JointModelFreeFlyer())``:

==========  =====================================  =========  ===============================
 q index     configuration (NQ entries)             v index    velocity (NV entries)
==========  =====================================  =========  ===============================
 0, 1, 2     root origin ``p`` in the world [m]     0, 1, 2    root linear velocity, root
                                                               frame [m/s] (``Rᵀ ṗ``)
 3 … 6       quaternion (x, y, z, w) of ``R``       3, 4, 5    root angular velocity ω, root
                                                               frame [rad/s]
 7 …         the robot's joints                     6 …        the robot's joints
==========  =====================================  =========  ===============================

The robot's joints come in depth-first order from the root, the joints below one link sorted by
name: the order of Pinocchio's URDF reader (:func:`pinocchio_order`); a fixed-base model keeps the description's order instead. ``R`` rotates
root-frame vectors into the world frame. The dynamics are ``M(q) v̇ + C(q, v) v + g(q) = τ``
in these velocities, τ[0:6] being the wrench on the root (force then moment, root frame); C is
the matrix Pinocchio's ``computeCoriolisMatrix`` gives (Ṁ − 2C skew-symmetric).

**Non-unit quaternions.** Every generated function uses the *normalised* quaternion: R is
computed as ``(quadratic form of (x, y, z, w)) / (x² + y² + z² + w²)``, so any nonzero multiple
of a unit quaternion gives the same result (for a unit quaternion, Pinocchio's); a zero
quaternion has no orientation (the results are not finite). :func:`integrate` returns a unit
quaternion.

**How it is derived.** Within the model the free flyer is six virtual joints under the root
(translations along, then rotations about, the root frame's x, y, z axes), held at zero: at the
current configuration they are a chart whose velocities are the root twist. The derivation
(:mod:`eomgen.symbolic.free_flyer`) puts the root pose from ``q[0:7]`` above them and corrects
the chart's second-order terms, so that τ, M, C, g, h and q̈ are the free flyer's.

Examples
--------
>>> import numpy as np
>>> q = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0])
>>> q1 = integrate(q, np.array([0.1, 0, 0, 0, 0, np.pi / 2]), 1.0)
>>> bool(np.allclose(difference(q, q1), [0.1, 0, 0, 0, 0, np.pi / 2]))
True
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .floating import WORLD, virtual_chain
from .numeric.floating_base import matrix_quaternion, quaternion_matrix
from .model import (FREE_FLYER_CONFIGURATION, FREE_FLYER_VELOCITY, Joint, JointType, Link,
                    NoticeKind, RobotModel, Transform, vec3)

CONFIGURATION_NAMES = FREE_FLYER_CONFIGURATION
VELOCITY_NAMES = FREE_FLYER_VELOCITY

_AXES = ((1, 0, 0), (0, 1, 0), (0, 0, 1)) * 2
_TYPES = (JointType.PRISMATIC,) * 3 + (JointType.CONTINUOUS,) * 3


def add_free_flyer(model: RobotModel, origin: Transform | None = None) -> RobotModel:
    """``model`` with a quaternion free flyer between a fixed ``world`` link and its root link
    (module docstring): six virtual joints (massless links between them) come first, the
    robot's joints follow in depth-first order. The floating-base notice of the description is
    dropped (the root is now free). ``origin`` places the free flyer in the world (the origin
    of a URDF ``floating`` joint): the root's pose is then ``origin · (R(quaternion), p)``.

    Raises
    ------
    KinematicTreeError
        A root named ``world``, or a link or joint name the free flyer takes.
    InvalidInertiaError
        The robot's total spatial inertia is singular (see
        :func:`eomgen.floating.add_floating_base`).
    """
    chain = virtual_chain(model, VELOCITY_NAMES, "the free flyer's virtual joints")
    virtual = tuple(Joint(name, kind, chain[k], chain[k + 1],
                          (origin or Transform()) if k == 0 else Transform(), vec3(axis))
                    for k, (name, kind, axis) in enumerate(zip(VELOCITY_NAMES, _TYPES, _AXES)))
    return replace(
        model,
        links=(*(Link(name) for name in chain[:-1]), *model.links),
        joints=virtual + pinocchio_order(model),
        root=WORLD, free_flyer=True,
        notices=tuple(n for n in model.notices if n.kind is not NoticeKind.FLOATING_BASE))


def pinocchio_order(model: RobotModel) -> tuple[Joint, ...]:
    """The joints of ``model`` in the order Pinocchio's URDF reader gives them: depth-first from
    the root, the joints below one link in the byte order of their names (urdfdom keeps a
    link's children sorted by joint name)."""
    children: dict[str, list[Joint]] = {}
    for joint in model.joints:
        children.setdefault(joint.parent, []).append(joint)
    order: list[Joint] = []
    stack = sorted(children.get(model.root, []), key=lambda j: j.name.encode(), reverse=True)
    while stack:
        joint = stack.pop()
        order.append(joint)
        stack.extend(sorted(children.get(joint.child, []), key=lambda j: j.name.encode(),
                            reverse=True))
    return tuple(order)


# ---------------------------------------------------------------------------------------------
# Numeric Lie-group operations on q (Pinocchio's integrate / difference), NumPy, one state.

def _skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def _so3_exp(w):
    theta = np.linalg.norm(w)
    K = _skew(w)
    if theta < 1e-8:
        return np.eye(3) + K + K @ K / 2
    return np.eye(3) + np.sin(theta) / theta * K + (1 - np.cos(theta)) / theta ** 2 * K @ K


def _left_jacobian(w):
    """V(ω) with exp([ν, ω]) = (exp(ω), V ν): the SE(3) exponential's translation part."""
    theta = np.linalg.norm(w)
    K = _skew(w)
    if theta < 1e-6:
        return np.eye(3) + K / 2 + K @ K / 6
    return (np.eye(3) + (1 - np.cos(theta)) / theta ** 2 * K
            + (theta - np.sin(theta)) / theta ** 3 * K @ K)


def _so3_log(R):
    cos = np.clip((np.trace(R) - 1) / 2, -1.0, 1.0)
    theta = np.arccos(cos)
    vee = np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])
    if theta < 1e-8:
        return vee / 2
    if np.pi - theta < 1e-6:  # near π: the axis from the symmetric part
        axis = np.sqrt(np.maximum((np.diag(R) + 1) / 2, 0.0))
        k = int(np.argmax(axis))
        axis = (R[k] + np.eye(3)[k]) / (2 * axis[k]) if axis[k] > 0 else axis
        axis /= np.linalg.norm(axis)
        return theta * axis * (1.0 if axis @ vee >= 0 else -1.0)
    return theta / (2 * np.sin(theta)) * vee


def configuration_rate(q, v) -> np.ndarray:
    """``q̇`` (NQ) at velocity ``v`` (NV): the root origin's rate ``R v[0:3]``, the quaternion's
    ``½ (x, y, z, w) ⊗ (ω, 0)`` (ω = v[3:6], root frame), then ``v[6:]``."""
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float)
    u, w, omega = q[3:6], q[6], v[3:6]
    out = np.empty(len(q))
    out[:3] = quaternion_matrix(q[3:7]) @ v[:3]
    out[3:6] = 0.5 * (w * omega + np.cross(u, omega))
    out[6] = -0.5 * (u @ omega)
    out[7:] = v[6:]
    return out


def integrate(q, v, dt: float = 1.0) -> np.ndarray:
    """The configuration reached from ``q`` (NQ) moving with the constant velocity ``v`` (NV)
    for ``dt`` seconds: the free flyer along the SE(3) exponential of its twist ``v[0:6] dt``
    (root frame), the other joints by ``q + v dt`` (Pinocchio's ``integrate``). The quaternion
    of the result is normalised."""
    q, v = np.asarray(q, dtype=float), np.asarray(v, dtype=float) * dt
    R, p = quaternion_matrix(q[3:7]), q[:3]
    dR = _so3_exp(v[3:6])
    out = np.empty(len(q))
    out[:3] = p + R @ (_left_jacobian(v[3:6]) @ v[:3])
    out[3:7] = matrix_quaternion(R @ dR)
    out[7:] = q[7:] + v[6:]
    return out


def difference(q0, q1) -> np.ndarray:
    """The velocity ``v`` (NV) with ``integrate(q0, v, 1) = q1``: the SE(3) logarithm of the
    root's relative pose ``(R0, p0)⁻¹ (R1, p1)`` (root frame of ``q0``) and ``q1 − q0`` for the
    other joints (Pinocchio's ``difference``)."""
    q0, q1 = np.asarray(q0, dtype=float), np.asarray(q1, dtype=float)
    R0, R1 = quaternion_matrix(q0[3:7]), quaternion_matrix(q1[3:7])
    w = _so3_log(R0.T @ R1)
    out = np.empty(len(q0) - 1)
    out[:3] = np.linalg.solve(_left_jacobian(w), R0.T @ (q1[:3] - q0[:3]))
    out[3:6] = w
    out[6:] = q1[7:] - q0[7:]
    return out


def neutral(nq: int) -> np.ndarray:
    """The neutral configuration of a free-flyer model with ``nq`` entries: root at the world
    origin, identity quaternion (0, 0, 0, 1), joints at zero (Pinocchio's ``neutral``)."""
    q = np.zeros(nq)
    q[6] = 1.0
    return q


__all__ = ["CONFIGURATION_NAMES", "VELOCITY_NAMES", "add_free_flyer", "configuration_rate",
           "difference",
           "integrate", "matrix_quaternion", "neutral", "pinocchio_order", "quaternion_matrix"]
