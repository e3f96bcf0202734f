"""Trajectories of models with quaternion joints (a free flyer, ball joints:
:mod:`eomgen.model.quaternion`): a curve ``ξ(t)`` in NV chart coordinates, mapped to the
configuration ``q`` (NQ), the velocity ``v`` and its rate ``v̇`` (NV) the generated functions
take (:func:`chart_states`), so that the Fourier series of :mod:`eomgen.identification.excitation`
excite such a model as they excite an arm.

Per quaternion joint, its NV entries of ``ξ`` (its velocity coordinates' places):

* a ball joint: three angles ``(a, b, c)`` [rad], ``R = Rx(a) Ry(b) Rz(c)`` the rotation from
  the joint frame to the child frame; ``ω`` (child frame) and ``ω̇`` in closed form: with
  ``A_k`` the product of the factors after factor ``k`` and ``e_k`` its axis,
  ``ω = Σ_k A_kᵀ e_k θ̇_k`` and ``ω̇ = Σ_k [A_kᵀ e_k θ̈_k + (A_kᵀ e_k θ̇_k) × ω_k]``, ``ω_k`` the
  sum's terms after ``k`` (the angular velocity of ``A_k``);
* the free flyer: the root origin ``p`` in the world [m], then three angles as for a ball
  joint (``R`` the root's orientation in the world); ``v_lin = Rᵀ ṗ`` and
  ``v̇_lin = Rᵀ p̈ − ω × v_lin`` (the rate of the root-frame linear velocity).

Other joints: ``q = ξ``, ``v = ξ̇``, ``v̇ = ξ̈``. The angles only parameterise the curve (no
inverse is ever taken), so the parameterisation has no singular state that matters: at
``b = ±π/2`` the curve is still smooth and ``q``, ``v``, ``v̇`` still consistent
(``q̇ = configuration_rate(q, v)``).
"""

from __future__ import annotations

import numpy as np

from ..numeric.floating_base import matrix_quaternion

_AXES = np.eye(3)


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


def chart_states(joints, xi, xid, xidd) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, v, v̇)`` of the chart states ``(ξ, ξ̇, ξ̈)`` (each (N, NV)) for the quaternion
    joints ``joints`` (:attr:`eomgen.model.RobotModel.quaternion_joints`): ``q`` (N, NQ),
    ``v`` and ``v̇`` (N, NV) (module docstring). Without quaternion joints, the inputs."""
    xi, xid, xidd = (np.atleast_2d(np.asarray(x, dtype=float)) for x in (xi, xid, xidd))
    if not joints:
        return xi, xid, xidd
    N, nv = xi.shape
    q = np.empty((N, nv + len(joints)))
    v, vd = xid.copy(), xidd.copy()
    starts = {j.v_index: j for j in joints}
    k = iq = 0
    while k < nv:
        joint = starts.get(k)
        if joint is None:
            q[:, iq] = xi[:, k]
            k, iq = k + 1, iq + 1
            continue
        w = slice(k + joint.nv - 3, k + joint.nv)
        R, v[:, w], vd[:, w] = rotation_rates(xi[:, w], xid[:, w], xidd[:, w])
        q[:, joint.quaternion:joint.quaternion + 4] = [matrix_quaternion(r) for r in R]
        if joint.nv == 6:
            q[:, iq:iq + 3] = xi[:, k:k + 3]
            linear = np.einsum("nji,nj->ni", R, xid[:, k:k + 3])  # Rᵀ ṗ
            v[:, k:k + 3] = linear
            vd[:, k:k + 3] = (np.einsum("nji,nj->ni", R, xidd[:, k:k + 3])
                              - np.cross(v[:, w], linear))
        k, iq = k + joint.nv, iq + joint.nq
    return q, v, vd


def trajectory_states(model, trajectory, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, v, v̇)`` of ``trajectory`` (a :class:`~eomgen.identification.excitation.
    FourierTrajectory` in chart coordinates, NV per sample) at the times ``t`` (N,) for
    ``model``: ``q`` (N, NQ) in ``CONFIGURATION_NAMES`` order, ``v``, ``v̇`` (N, NV) in
    ``JOINT_NAMES`` order (:func:`chart_states`)."""
    return chart_states(model.quaternion_joints, *trajectory.states(t))


__all__ = ["chart_states", "rotation_rates", "trajectory_states"]
