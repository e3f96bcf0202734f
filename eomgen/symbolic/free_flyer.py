"""The free flyer's symbolic pieces: the root pose from ``q[0:7]`` and the chart corrections.

A free-flyer model (:mod:`eomgen.free_flyer`) has six virtual joints under its root
(translations along, then rotations about, the root frame's x, y, z axes). The derivation holds
them at zero and puts the root pose ``(R(quaternion), p)`` above them (:func:`root_placement`):
at the current configuration they are then a chart of SE(3) whose velocities ``ξ̇`` equal the
root twist ``v[0:6]`` (root frame, linear then angular), so that every body-frame algorithm
(CRBA, Newton–Euler, ABA, the frame kinematics) runs unchanged and M, g and the Jacobians are
the free flyer's.

The chart's second-order terms differ from the free flyer's: with ``Sᵢ`` the six unit motions
in chain order, the chart's root acceleration is ``v̇ + n(v)`` less than what the algorithms
see, ``n(v) = Σ_{i<j} (Sᵢ vᵢ) × (Sⱼ vⱼ) = (v_lin × ω, (ω_y ω_z, −ω_x ω_z, ω_x ω_y))``
(:func:`chart_offset`), so

* inverse dynamics take the chart accelerations ``ξ̈ = v̇ − n(v)`` (:func:`chart_accelerations`);
* forward dynamics give ``v̇ = ξ̈ + n(v)``;
* the Coriolis matrix: the Christoffel C of the chart (what the recursion of
  :func:`eomgen.symbolic.composite.coriolis_program` gives) plus ``M[:, 0:6] K(v)``, with column
  ``i < 6`` of K the motion ``(Σ_{j>i} Sⱼ vⱼ) × Sᵢ`` (:func:`coriolis_correction`), is the
  matrix of Pinocchio's ``computeCoriolisMatrix`` (Echeandia and Wensing's factorisation with
  each body's own velocity in J̇): ``C v = h − g`` and ``Ṁ − 2C`` is skew-symmetric.
"""

from __future__ import annotations

import sympy as sp

from ..model import Transform

_ZERO = sp.S.Zero


def quaternion_rotation(x, y, z, w, s=None) -> tuple:
    """The rotation matrix of quaternion ``(x, y, z, w)`` divided by its squared norm: the
    rotation of the normalised quaternion (:mod:`eomgen.free_flyer`, non-unit quaternions).
    ``s`` is ``1 / (x² + y² + z² + w²)`` when the caller has it named already."""
    s = 1 / (x * x + y * y + z * z + w * w) if s is None else s
    return ((s * (w * w + x * x - y * y - z * z), 2 * s * (x * y - z * w), 2 * s * (x * z + y * w)),
            (2 * s * (x * y + z * w), s * (w * w - x * x + y * y - z * z), 2 * s * (y * z - x * w)),
            (2 * s * (x * z - y * w), 2 * s * (y * z + x * w), s * (w * w - x * x - y * y + z * z)))


def root_placement(q, b) -> Transform:
    """The pose of the root link in the world from ``q[0:7]`` (position, quaternion x, y, z,
    w), its rotation's entries named ``Rb11 … Rb33`` in the program builder ``b``."""
    x, y, z, w = q[3:7]
    s = b.define(1 / (x * x + y * y + z * z + w * w), "qn", ("qn",))
    R = quaternion_rotation(x, y, z, w, s)
    R = tuple(tuple(b.define(R[i][j], f"Rb{i + 1}{j + 1}", ("Rb", i + 1, j + 1))
                    for j in range(3)) for i in range(3))
    return Transform(R, tuple(q[:3]))


def _cross(a, c):
    return (a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2], a[0] * c[1] - a[1] * c[0])


def _motion_cross(m1, m2):
    """``m1 × m2`` for motions ``(linear, angular)`` (6-tuples, linear first)."""
    v1, w1, v2, w2 = m1[:3], m1[3:], m2[:3], m2[3:]
    lin = tuple(a + c for a, c in zip(_cross(w1, v2), _cross(v1, w2)))
    return lin + _cross(w1, w2)


def _unit(i):
    return tuple(sp.Integer(1) if k == i else _ZERO for k in range(6))


def chart_offset(v) -> tuple:
    """``n(v)`` (module docstring) for the root twist ``v[0:6]``: 6 entries, linear first."""
    total = [_ZERO] * 6
    for i in range(6):
        for j in range(i + 1, 6):
            term = _motion_cross(tuple(e * v[i] for e in _unit(i)),
                                 tuple(e * v[j] for e in _unit(j)))
            total = [a + c for a, c in zip(total, term)]
    return tuple(sp.expand(t) for t in total)


def chart_accelerations(qd, qdd) -> tuple:
    """The chart accelerations of true accelerations ``qdd`` at velocity ``qd``: ``qdd`` with
    ``n(v)`` subtracted from its first six entries."""
    n = chart_offset(qd)
    return tuple(qdd[k] - n[k] for k in range(6)) + tuple(qdd[6:])


def true_accelerations(qd, chart) -> tuple:
    """The inverse of :func:`chart_accelerations`: ``n(v)`` added to the first six entries."""
    n = chart_offset(qd)
    return tuple(chart[k] + n[k] for k in range(6)) + tuple(chart[6:])


def coriolis_correction(qd) -> sp.Matrix:
    """K(v) (6×6, module docstring): column ``i`` is ``(Σ_{j>i} Sⱼ vⱼ) × Sᵢ``."""
    K = sp.zeros(6, 6)
    for i in range(6):
        later = tuple(sp.Add(*[_unit(j)[k] * qd[j] for j in range(i + 1, 6)]) for k in range(6))
        column = _motion_cross(later, _unit(i))
        for k in range(6):
            K[k, i] = column[k]
    return K


def corrected_coriolis(C: sp.Matrix, M: sp.Matrix, qd) -> sp.Matrix:
    """The free flyer's C from the chart's: ``C + M[:, 0:6] K(v)`` in the base columns."""
    K = coriolis_correction(qd)
    n = C.shape[0]
    out = sp.Matrix(C)
    for r in range(n):
        for i in range(6):
            extra = sp.Add(*[M[r, k] * K[k, i] for k in range(6) if K[k, i] != 0])
            out[r, i] = C[r, i] + extra
    return out


__all__ = ["chart_accelerations", "chart_offset", "coriolis_correction", "corrected_coriolis",
           "quaternion_rotation", "root_placement", "true_accelerations"]
