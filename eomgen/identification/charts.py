"""Trajectories of models with quaternion joints (a free flyer, ball joints:
:mod:`eomgen.model.quaternion`): a curve ``ξ(t)`` in NV chart coordinates, mapped to the
configuration ``q`` (NQ), the velocity ``v`` and its rate ``v̇`` (NV) the generated functions
take (:func:`chart_states`, each joint's kind's map, walked over the model by
:func:`eomgen.model.configuration.chart_states`), so that the Fourier series of
:mod:`eomgen.identification.excitation` excite such a model as they excite an arm.

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

from ..model.configuration import chart_states
from ..model.joints.lie import rotation_rates  # noqa: F401 (importable here)

def trajectory_states(model, trajectory, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(q, v, v̇)`` of ``trajectory`` (a :class:`~eomgen.identification.excitation.
    FourierTrajectory` in chart coordinates, NV per sample) at the times ``t`` (N,) for
    ``model``: ``q`` (N, NQ) in ``CONFIGURATION_NAMES`` order, ``v``, ``v̇`` (N, NV) in
    ``JOINT_NAMES`` order (:func:`chart_states`)."""
    return chart_states(model, *trajectory.states(t))


__all__ = ["chart_states", "rotation_rates", "trajectory_states"]
