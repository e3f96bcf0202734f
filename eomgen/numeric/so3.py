"""Rotations as numbers: the skew matrix, the exponential and the logarithm of SO(3), once.

The floor of the numeric layer (NumPy only; the symbolic counterparts, over SymPy expressions,
are :mod:`eomgen.symbolic.spatial`'s ``skew`` and ``rotation``):

* :func:`skew` ``[w]×``, the 3×3 matrix with ``[w]× x = w × x``;
* :func:`rotation_about` ``exp(θ [k]×) = 1 + sin θ [k]× + (1 − cos θ) [k]×²`` for a unit axis
  ``k`` (Rodrigues' formula);
* :func:`so3_exp` ``exp([w]×)`` of a rotation vector ``w`` (axis × angle);
* :func:`so3_log` its inverse: the rotation vector ``w``, ``|w| ∈ [0, π]``, of a rotation;
* :func:`left_jacobian` ``V(w)``, the translation part of the SE(3) exponential
  ``exp([ν, w]) = (exp([w]×), V(w) ν)``.

:func:`skew` and :func:`rotation_about` compute in the number type of the recursions
(``numbers``: a :class:`~eomgen.numeric.Numbers` such as float64 or mpmath; None for float64);
the others are float64.

>>> w = np.array([0.3, -0.2, 0.5])
>>> bool(np.allclose(skew(w) @ [1.0, 2.0, 3.0], np.cross(w, [1.0, 2.0, 3.0])))
True
>>> bool(np.allclose(so3_log(so3_exp(w)), w))
True
"""

from __future__ import annotations

import numpy as np

def skew(w, numbers=None) -> np.ndarray:
    """``[w]×`` (3, 3): the matrix of ``x ↦ w × x``. ``numbers``: the entries' type (a
    :class:`~eomgen.numeric.Numbers`; None: float64)."""
    zero, dtype = (0.0, float) if numbers is None else (numbers.value(0), numbers.dtype)
    return np.array([[zero, -w[2], w[1]], [w[2], zero, -w[0]], [-w[1], w[0], zero]], dtype=dtype)


def rotation_about(axis, angle, numbers=None) -> np.ndarray:
    """The rotation (3, 3) by ``angle`` [rad] about the unit vector ``axis`` (right hand rule):
    ``exp(angle [axis]×) = 1 + sin(angle) [axis]× + (1 − cos(angle)) [axis]×²`` (Rodrigues).
    ``numbers``: the number type of ``angle`` and of the result (None: float64)."""
    K = skew(axis, numbers)
    if numbers is None:
        return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)
    return numbers.eye(3) + numbers.sin(angle) * K + (1.0 - numbers.cos(angle)) * (K @ K)


def so3_exp(w) -> np.ndarray:
    """The rotation ``exp([w]×)`` (3, 3) of the rotation vector ``w`` (3,) [rad]: the rotation
    by ``|w|`` about ``w / |w|`` (:func:`rotation_about`); ``1 + [w]× + [w]×² / 2`` below
    1e-8 rad."""
    w = np.asarray(w, dtype=float)
    theta = float(np.linalg.norm(w))
    if theta < 1e-8:
        K = skew(w)
        return np.eye(3) + K + K @ K / 2
    return rotation_about(w / theta, theta)


def so3_log(R) -> np.ndarray:
    """The rotation vector ``θ u`` (3,) [rad] of the rotation matrix ``R``: ``exp([θ u]×) = R``
    with ``θ ∈ [0, π]`` (the logarithm of SO(3)).

    ``θ`` is ``atan2(sin θ, cos θ)`` from the skew part ``(R − Rᵀ)/2 = sin θ [u]×`` and the trace
    ``1 + 2 cos θ``. Up to ``θ = π/2`` the axis is the skew part over ``sin θ`` (a series below
    1e-6 rad); beyond, where ``sin θ`` vanishes towards π, it comes from the
    symmetric part ``(R + Rᵀ)/2 − cos θ 1 = (1 − cos θ) u uᵀ``, its sign from the skew part
    (at ``θ = π`` exactly both signs are logarithms; the one returned is that of the largest
    diagonal entry's row).

    >>> np.round(so3_log(np.array([[0., -1, 0], [1, 0, 0], [0, 0, 1]])), 6)
    array([0.      , 0.      , 1.570796])
    """
    R = np.asarray(R, dtype=float)
    w = 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])  # sin θ u
    c = min(1.0, max(-1.0, 0.5 * (np.trace(R) - 1.0)))
    s = float(np.linalg.norm(w))
    theta = float(np.arctan2(s, c))
    if theta < 1e-6:
        return w * (1.0 + theta * theta / 6.0)  # θ / sin θ to second order
    if c >= 0.0:
        return w * (theta / s)
    B = 0.5 * (R + R.T) - c * np.eye(3)  # (1 − cos θ) u uᵀ
    k = int(np.argmax(np.diag(B)))
    u = B[k] / np.sqrt(B[k, k] * (1.0 - c))
    if u @ w < 0:
        u = -u
    return theta * u


def left_jacobian(w) -> np.ndarray:
    """``V(w)`` (3, 3) with ``exp([ν, w]) = (exp([w]×), V(w) ν)``: the translation part of the
    SE(3) exponential, ``1 + (1 − cos θ)/θ² [w]× + (θ − sin θ)/θ³ [w]×²`` (``θ = |w|``; its
    series below 1e-6)."""
    w = np.asarray(w, dtype=float)
    theta = np.linalg.norm(w)
    K = skew(w)
    if theta < 1e-6:
        return np.eye(3) + K / 2 + K @ K / 6
    return (np.eye(3) + (1 - np.cos(theta)) / theta ** 2 * K
            + (theta - np.sin(theta)) / theta ** 3 * K @ K)


__all__ = ["left_jacobian", "rotation_about", "skew", "so3_exp", "so3_log"]
