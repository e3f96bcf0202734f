"""Quaternion joints in the numeric recursions: the pose placed from ``q`` and the chart offset,
generic over the number type (float64, mpmath).

A quaternion joint (the free flyer, a ball joint: :mod:`eomgen.model.quaternion`) is, in the
model, a chain of virtual one-axis joints between massless links. The recursions of
:mod:`eomgen.numeric.newton_euler` do what the derivation does
(:mod:`eomgen.symbolic.quaternion_joints`, whose module docstring has the argument): they hold
the virtual joints at zero and place the joint's pose from ``q`` before the chain
(:func:`placements`: ``(R(quaternion), p)`` for the free flyer, ``(R(quaternion), 0)`` for a ball
joint, after the joint's origin). At the current configuration the chain is then a chart whose
velocities are the joint's velocity (the root twist in the root frame, the ball's angular velocity
in the child frame), so M, g, the body velocities and the Jacobians are the quaternion joint's;
the accelerations differ by the chart offset (:func:`chart_offset`)

    ``n(v) = Σ_{i<j} (Sᵢ vᵢ) × (Sⱼ vⱼ)``

over the chain's unit motions ``Sᵢ`` (spatial motions, linear then angular), in the joint's
velocity coordinates: inverse dynamics take ``ξ̈ = v̇ − n(v)``, and a Jacobian's bias is
``J̇ v = (J̇ v)_chart − J n(v)``. The layout of ``q`` (NQ entries) and ``v`` (NV) is Pinocchio's.
"""

from __future__ import annotations

import numpy as np


def quaternion_rotation(numbers, x, y, z, w) -> np.ndarray:
    """The rotation matrix (3, 3) of quaternion ``(x, y, z, w)``, normalised first: the quadratic
    form divided by ``x² + y² + z² + w²`` (any nonzero multiple gives the same rotation; a zero
    quaternion gives entries that are not finite). ``numbers``: a
    :class:`~eomgen.numeric.Numbers`."""
    s = numbers.value(1) / (x * x + y * y + z * z + w * w)
    return np.array([
        [s * (w * w + x * x - y * y - z * z), 2 * s * (x * y - z * w), 2 * s * (x * z + y * w)],
        [2 * s * (x * y + z * w), s * (w * w - x * x + y * y - z * z), 2 * s * (y * z - x * w)],
        [2 * s * (x * z - y * w), 2 * s * (y * z + x * w), s * (w * w - x * x - y * y + z * z)],
    ], dtype=numbers.dtype)


def chart_coordinates(joints, q: np.ndarray, nv: int, numbers) -> np.ndarray:
    """The joint coordinates the recursions index (NV entries) from the configuration ``q``
    (NQ): ``q``'s entries for the other joints, zero for the virtual joints of ``joints``."""
    out = numbers.zeros(nv)
    starts = {j.v_index: j for j in joints}
    k = iq = 0
    while k < nv:
        joint = starts.get(k)
        if joint is None:
            out[k] = q[iq]
            k, iq = k + 1, iq + 1
        else:
            k, iq = k + joint.nv, iq + joint.nq
    return out


def placements(joints, q: np.ndarray, numbers) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """``{v_index: (R, p)}``: the pose each quaternion joint puts before its chain, from ``q``
    (NQ): the rotation of its quaternion, and the free flyer's origin ``q[0:3]`` [m] (zero for a
    ball joint), both in the frame of the joint's origin."""
    out = {}
    for joint in joints:
        k = joint.quaternion
        R = quaternion_rotation(numbers, *q[k:k + 4])
        p = (np.array(q[joint.q_index:joint.q_index + 3], dtype=numbers.dtype) if joint.nv == 6
             else numbers.zeros(3))
        out[joint.v_index] = (R, p)
    return out


def _motion_cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a × b`` of two spatial motions (6,), linear then angular."""
    out = np.empty(6, dtype=a.dtype)
    out[:3] = np.cross(a[3:], b[:3]) + np.cross(a[:3], b[3:])
    out[3:] = np.cross(a[3:], b[3:])
    return out


def chart_offset(joints, qd: np.ndarray, numbers) -> np.ndarray:
    """``n(v)`` (module docstring) in velocity coordinates: ``len(qd)`` entries, zero outside
    the quaternion joints."""
    out = numbers.zeros(len(qd))
    for joint in joints:
        motions = []
        for i, axis in enumerate(joint.motions):
            m = numbers.zeros(6)
            m[axis] = qd[joint.v_index + i]
            motions.append(m)
        total = numbers.zeros(6)
        later = numbers.zeros(6)
        for i in reversed(range(joint.nv)):  # Σ_i (Sᵢ vᵢ) × (Σ_{j>i} Sⱼ vⱼ)
            total = total + _motion_cross(motions[i], later)
            later = later + motions[i]
        for i, axis in enumerate(joint.motions):
            out[joint.v_index + i] = total[axis]
    return out


__all__ = ["chart_coordinates", "chart_offset", "placements", "quaternion_rotation"]
