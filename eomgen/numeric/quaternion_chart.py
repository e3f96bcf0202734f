"""Quaternion joints in the numeric recursions: the pose placed from ``q`` and the chart offset,
generic over the number type (float64, mpmath).

A quaternion joint (the free flyer, a ball joint: :mod:`eomgen.model.quaternion`) is, in the
model, a chain of virtual one-axis joints between massless links. The recursions of
:mod:`eomgen.numeric.newton_euler` do what the derivation does
(:mod:`eomgen.symbolic.charts`, whose module docstring has the argument): they hold
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

from ..model.joints.lie import motion_cross, quaternion_rotation  # noqa: F401 (importable here)


def chart_coordinates(nm, q: np.ndarray) -> np.ndarray:
    """The joint coordinates the recursions of the numeric model ``nm`` index (its ``n_tree``
    entries) from the configuration ``q`` (NQ): ``q``'s entries for the joints without a
    chart, zero for the virtual joints of the others (``q`` itself when none has one)."""
    nv, numbers = nm.n_tree, nm.numbers
    out = numbers.zeros(nv)
    starts = {j.v_index: j for j in nm.chart_places}
    k = iq = 0
    while k < nv:
        joint = starts.get(k)
        if joint is None:
            out[k] = q[iq]
            k, iq = k + 1, iq + 1
        else:
            k, iq = k + joint.nv, iq + joint.nq
    return out


def placements(nm, q: np.ndarray) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """``{v_index: (R, p)}``: the pose each joint with a chart of the numeric model ``nm``
    puts before its chain (none when it has none), from
    ``q`` (NQ), in the frame of the joint's origin: its kind's
    :meth:`~eomgen.model.joints.ChartKind.pose` (the rotation of a quaternion, and a free
    flyer's origin ``q[0:3]`` [m]; a planar joint's rotation about z and origin)."""
    return {joint.v_index: joint.kind.pose(q[joint.q_slice], nm.numbers)
            for joint in nm.chart_places}


def chart_offset(nm, qd: np.ndarray) -> np.ndarray:
    """``n(v)`` (module docstring) of the numeric model ``nm`` in velocity coordinates:
    ``len(qd)`` entries, zero outside the joints with a chart (all zero without them)."""
    numbers = nm.numbers
    out = numbers.zeros(len(qd))
    for joint in nm.chart_places:
        motions = []
        for i, axis in enumerate(joint.motions):
            m = numbers.zeros(6)
            m[axis] = qd[joint.v_index + i]
            motions.append(m)
        total = numbers.zeros(6)
        later = numbers.zeros(6)
        for i in reversed(range(joint.nv)):  # Σ_i (Sᵢ vᵢ) × (Σ_{j>i} Sⱼ vⱼ)
            total = total + motion_cross(motions[i], later)
            later = later + motions[i]
        for i, axis in enumerate(joint.motions):
            out[joint.v_index + i] = total[axis]
    return out


__all__ = ["chart_coordinates", "chart_offset", "placements", "quaternion_rotation"]
