"""Quaternion joints in the derivation: the rotation placed from ``q`` and the chart corrections.

A quaternion joint (the free flyer, a ball joint: :mod:`eomgen.model.quaternion`) is a chain of
virtual one-axis joints in the model. The derivation holds them at zero and places the joint's
pose from ``q`` before them (:func:`placements`: ``(R(quaternion), p)`` for the free flyer,
``(R(quaternion), 0)`` for a ball joint): at the current configuration the chain is then a chart
whose velocities ``ξ̇`` equal the joint's velocity (the root twist, or the ball's angular
velocity in the child frame), so that every body-frame algorithm (CRBA, Newton–Euler, ABA, the
frame kinematics) runs unchanged and M, g and the Jacobians are the quaternion joint's.

The chart's second-order terms differ: with ``Sᵢ`` the chain's unit motions in chain order,
the chart's child acceleration exceeds the joint's by ``n(v) = Σ_{i<j} (Sᵢ vᵢ) × (Sⱼ vⱼ)``
whatever the parent does (the parent's velocity enters both as ``(X v_parent) × S v``): for
the free flyer ``n = (v_lin × ω, (ω_y ω_z, −ω_x ω_z, ω_x ω_y))``, for a ball joint the angular
part. In the joint's velocity coordinates (``Sᵢ`` are unit vectors) :func:`chart_offset`
gives it, NV entries, zero outside the quaternion joints; then

* inverse dynamics take the chart accelerations ``ξ̈ = v̇ − n(v)`` (:func:`chart_accelerations`);
* forward dynamics give ``v̇ = ξ̈ + n(v)`` (:func:`true_accelerations`);
* a Jacobian's bias: ``J̇ v = (J̇ v)_chart − J n(v)``;
* the Coriolis matrix: the chart's (the recursion of
  :func:`eomgen.symbolic.composite.coriolis_program`, each body's own velocity in J̇) plus
  ``M[:, cols] K(v)``, column ``i`` of K the motion ``(Σ_{j>i} Sⱼ vⱼ) × Sᵢ``
  (:func:`corrected_coriolis`): the J̇ of the joint's bodies differ from the chart's by exactly
  those columns (in the span of the ``Sᵢ``, as the cross product of two rotations is a
  rotation), which gives the matrix of Pinocchio's ``computeCoriolisMatrix`` (``C v = h − g``
  and ``Ṁ − 2C`` skew-symmetric).
"""

from __future__ import annotations

import sympy as sp

from ..model import QuaternionJoint, Transform
from ..model.joints.lie import quaternion_rotation_symbolic as quaternion_rotation

_ZERO = sp.S.Zero


def placement(joint: QuaternionJoint, q, b, number: int = 0) -> Transform:
    """The pose the joint ``joint`` puts before its chain, from ``q`` (NQ entries): its kind's
    :meth:`~eomgen.model.joints.ChartKind.placement`, the rotation's entries named in the
    program builder ``b`` (``Rb11 … Rb33`` for the free flyer with its origin ``q[0:3]``,
    ``Rs<number>_11 …`` for the ball joint numbered ``number``, ``Rp<number>_11 …`` for a
    planar joint)."""
    R, origin = joint.kind.placement(tuple(q[joint.q_slice]), b, number)
    return Transform(R, origin)


def placements(joints, q, b) -> dict[int, Transform]:
    """:func:`placement` of each of ``joints`` (the joints of each kind numbered from 1 in
    velocity order), by the index of its first velocity (the ``q_index`` of the body whose
    joint starts its chain)."""
    out, numbers = {}, {}
    for joint in joints:
        numbers[joint.kind.name] = numbers.get(joint.kind.name, 0) + 1
        out[joint.v_index] = placement(joint, q, b, numbers[joint.kind.name])
    return out


def coordinates(joints, q, nv: int) -> tuple:
    """The joint coordinates the algorithms index (NV entries): ``q``'s entries of the other
    joints, zero for the virtual joints of ``joints``."""
    out, k, iq = [], 0, 0
    starts = {j.v_index: j for j in joints}
    while k < nv:
        joint = starts.get(k)
        if joint is None:
            out.append(q[iq])
            k, iq = k + 1, iq + 1
        else:
            out += [sp.Integer(0)] * joint.nv
            k, iq = k + joint.nv, iq + joint.nq
    return tuple(out)


def _cross(a, c):
    return (a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2], a[0] * c[1] - a[1] * c[0])


def _motion_cross(m1, m2):
    """``m1 × m2`` for motions ``(linear, angular)`` (6-tuples, linear first)."""
    v1, w1, v2, w2 = m1[:3], m1[3:], m2[:3], m2[3:]
    lin = tuple(a + c for a, c in zip(_cross(w1, v2), _cross(v1, w2)))
    return lin + _cross(w1, w2)


def _motion(joint: QuaternionJoint, qd, chain) -> tuple:
    """``Σ Sᵢ vᵢ`` over the chain positions ``chain`` of ``joint``: a 6-tuple motion."""
    out = [_ZERO] * 6
    for i in chain:
        out[joint.motions[i]] += qd[joint.v_index + i]
    return tuple(out)


def chart_offset(joints, qd) -> tuple:
    """``n(v)`` (module docstring) in velocity coordinates: ``len(qd)`` entries."""
    out = [_ZERO] * len(qd)
    for joint in joints:
        total = [_ZERO] * 6
        for i in range(joint.nv):
            term = _motion_cross(_motion(joint, qd, (i,)), _motion(joint, qd, range(i + 1, joint.nv)))
            total = [a + c for a, c in zip(total, term)]
        for i, axis in enumerate(joint.motions):
            out[joint.v_index + i] = sp.expand(total[axis])
    return tuple(out)


def chart_accelerations(joints, qd, qdd) -> tuple:
    """The chart accelerations of the true accelerations ``qdd`` at velocity ``qd``:
    ``qdd − n(v)``."""
    n = chart_offset(joints, qd)
    return tuple(a - o for a, o in zip(qdd, n))


def true_accelerations(joints, qd, chart) -> tuple:
    """The inverse of :func:`chart_accelerations`: ``chart + n(v)``."""
    n = chart_offset(joints, qd)
    return tuple(a + o for a, o in zip(chart, n))


def coriolis_correction(joint: QuaternionJoint, qd) -> sp.Matrix:
    """K(v) of ``joint`` (nv×nv, module docstring): column ``i`` is ``(Σ_{j>i} Sⱼ vⱼ) × Sᵢ``
    in the joint's velocity coordinates."""
    K = sp.zeros(joint.nv, joint.nv)
    for i in range(joint.nv):
        unit = tuple(sp.Integer(1 if k == joint.motions[i] else 0) for k in range(6))
        column = _motion_cross(_motion(joint, qd, range(i + 1, joint.nv)), unit)
        for k, axis in enumerate(joint.motions):
            K[k, i] = column[axis]
    return K


def corrected_coriolis(joints, C: sp.Matrix, M: sp.Matrix, qd) -> sp.Matrix:
    """The quaternion joints' C from the chart's: ``C + M[:, cols] K(v)`` in each joint's
    columns ``cols``."""
    out = sp.Matrix(C)
    for joint in joints:
        K, cols = coriolis_correction(joint, qd), range(joint.v_index, joint.v_index + joint.nv)
        for r in range(C.rows):
            for i, col in enumerate(cols):
                extra = sp.Add(*[M[r, c] * K[k, i] for k, c in enumerate(cols) if K[k, i] != 0])
                out[r, col] = C[r, col] + extra
    return out


__all__ = ["chart_accelerations", "chart_offset", "coordinates", "coriolis_correction",
           "corrected_coriolis", "placement", "placements", "quaternion_rotation",
           "true_accelerations"]
