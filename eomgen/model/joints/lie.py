"""Rotations and rigid motions as numbers, once: the skew matrix, SO(3)'s exponential and
logarithm, the SE(3) left Jacobian, quaternions ↔ rotation matrices, SE(2)'s exponential.

The floor under every joint kind (NumPy only). :func:`skew` and :func:`rotation_about` compute
in the number type of the recursions (``numbers``: a :class:`~eomgen.numeric.Numbers` such as
float64 or mpmath; None for float64); the others are float64. Quaternions are ``(x, y, z, w)``
(Pinocchio's order), ``R`` rotates child-frame vectors into the parent frame.

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


def planar_left_jacobian(theta: float) -> np.ndarray:
    """``V(θ)`` (2, 2) with ``exp([vx, vy, θ]) = (Rz(θ), V(θ) (vx, vy))``: the translation part
    of the SE(2) exponential, ``[[sin θ/θ, −(1 − cos θ)/θ], [(1 − cos θ)/θ, sin θ/θ]]``
    (its series below 1e-6 rad)."""
    theta = float(theta)
    if abs(theta) < 1e-6:
        a, b = 1.0 - theta * theta / 6.0, theta / 2.0
    else:
        a, b = np.sin(theta) / theta, (1.0 - np.cos(theta)) / theta
    return np.array([[a, -b], [b, a]])


def matrix_quaternion(R) -> np.ndarray:
    """Unit quaternion (x, y, z, w), w ≥ 0, of a rotation matrix."""
    R = np.asarray(R, dtype=float)
    t = np.trace(R)
    if t > 0:
        s = 2.0 * np.sqrt(1.0 + t)
        q = [(R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s, (R[1, 0] - R[0, 1]) / s, s / 4]
    else:
        i = int(np.argmax(np.diag(R)))
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * np.sqrt(1.0 + R[i, i] - R[j, j] - R[k, k])
        q = [0.0] * 4
        q[i] = s / 4
        q[j] = (R[j, i] + R[i, j]) / s
        q[k] = (R[k, i] + R[i, k]) / s
        q[3] = (R[k, j] - R[j, k]) / s
    q = np.array(q)
    return q if q[3] >= 0 else -q


def quaternion_matrix(xyzw) -> np.ndarray:
    """The rotation matrix of quaternion ``(x, y, z, w)``, normalised first (any nonzero
    multiple gives the same rotation)."""
    x, y, z, w = np.asarray(xyzw, dtype=float) / np.linalg.norm(xyzw)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def quaternion_rotation(numbers, x, y, z, w) -> np.ndarray:
    """The rotation matrix (3, 3) of quaternion ``(x, y, z, w)`` in the number type
    ``numbers`` (a :class:`~eomgen.numeric.Numbers`), normalised first: the quadratic form
    divided by ``x² + y² + z² + w²`` (a zero quaternion gives entries that are not finite)."""
    s = numbers.value(1) / (x * x + y * y + z * z + w * w)
    return np.array([
        [s * (w * w + x * x - y * y - z * z), 2 * s * (x * y - z * w), 2 * s * (x * z + y * w)],
        [2 * s * (x * y + z * w), s * (w * w - x * x + y * y - z * z), 2 * s * (y * z - x * w)],
        [2 * s * (x * z - y * w), 2 * s * (y * z + x * w), s * (w * w - x * x - y * y + z * z)],
    ], dtype=numbers.dtype)


def quaternion_rotation_symbolic(x, y, z, w, s=None) -> tuple:
    """The rotation matrix of quaternion ``(x, y, z, w)`` divided by its squared norm, over
    SymPy expressions (nested tuples). ``s`` is ``1 / (x² + y² + z² + w²)`` when the caller has
    it named already."""
    s = 1 / (x * x + y * y + z * z + w * w) if s is None else s
    return ((s * (w * w + x * x - y * y - z * z), 2 * s * (x * y - z * w), 2 * s * (x * z + y * w)),
            (2 * s * (x * y + z * w), s * (w * w - x * x + y * y - z * z), 2 * s * (y * z - x * w)),
            (2 * s * (x * z - y * w), 2 * s * (y * z + x * w), s * (w * w - x * x - y * y + z * z)))


def quaternion_rate(quaternion, omega) -> np.ndarray:
    """``d(x, y, z, w)/dt`` (4,) of a quaternion turning at angular velocity ``omega`` (3,, in
    the rotated frame): ``½ (x, y, z, w) ⊗ (ω, 0)``."""
    quaternion, omega = np.asarray(quaternion, dtype=float), np.asarray(omega, dtype=float)
    out = np.empty(4)
    out[:3] = 0.5 * (quaternion[3] * omega + np.cross(quaternion[:3], omega))
    out[3] = -0.5 * (quaternion[:3] @ omega)
    return out


def motion_cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``a × b`` of two spatial motions (6,), linear then angular, in their number type."""
    out = np.empty(6, dtype=a.dtype)
    out[:3] = np.cross(a[3:], b[:3]) + np.cross(a[:3], b[3:])
    out[3:] = np.cross(a[3:], b[3:])
    return out


def _rotation(axis: int, angle) -> np.ndarray:
    """``R_axis(angle)`` for each of the angles ``angle`` (N,): (N, 3, 3)."""
    angle = np.asarray(angle, dtype=float)
    c, s = np.cos(angle), np.sin(angle)
    i, j = (axis + 1) % 3, (axis + 2) % 3
    R = np.zeros(angle.shape + (3, 3))
    R[..., axis, axis] = 1.0
    R[..., i, i], R[..., i, j], R[..., j, i], R[..., j, j] = c, -s, s, c
    return R


def rotation_rates(angles, rates, accelerations) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(R, ω, ω̇)`` of ``R = Rx(a) Ry(b) Rz(c)`` for the angles ``(a, b, c)`` [rad] and their
    first and second time derivatives, each (N, 3) (or (3,)): ``ω`` and ``ω̇`` in the rotated
    (body) frame (module docstring); R (N, 3, 3)."""
    angles, rates, accelerations = (np.asarray(x, dtype=float)
                                    for x in (angles, rates, accelerations))
    omega, domega = np.zeros(angles.shape), np.zeros(angles.shape)
    after = np.broadcast_to(np.eye(3), angles.shape[:-1] + (3, 3))  # A_k: factors after k
    for k in (2, 1, 0):
        axis = after[..., k, :]  # A_kᵀ e_k
        term = axis * rates[..., k:k + 1]
        domega = domega + axis * accelerations[..., k:k + 1] + np.cross(term, omega)
        omega = omega + term  # so far: the terms after k
        after = _rotation(k, angles[..., k]) @ after
    return after, omega, domega


__all__ = ["left_jacobian", "matrix_quaternion", "motion_cross", "planar_left_jacobian",
           "quaternion_matrix", "quaternion_rate", "quaternion_rotation",
           "quaternion_rotation_symbolic", "rotation_about", "rotation_rates", "skew", "so3_exp", "so3_log"]
