"""Control laws over generated dynamics: computed torque, PD plus gravity compensation and the
adaptive passivity-based controller of Slotine and Li (docs/control.md).

Each law is a small frozen object with ``torque(t, q, qd, ...)``; the dynamics it uses are the
functions of a generated NumPy module (:meth:`eomgen.Dynamics.lambdify`'s ``module``, or the
module itself), so a law evaluated on a model with wrong parameters is simply a law given other
keyword values. Vectors are (n,) in JOINT_NAMES order [rad, rad/s, rad/s², N m].

Desired motions are callables ``desired(t) -> (q_d, qd_d, qdd_d)``, e.g.
:func:`fourier_reference` of an excitation trajectory of ``eomgen excite``.

Models with quaternion joints (a free flyer, ball joints; read off the module's
``CONFIGURATION_NAMES``, :mod:`eomgen.control.configuration`): ``q`` and ``q_d`` have NQ
entries, every other vector NV (``q̇`` is the velocity v: the root twist, a ball's angular
velocity in its child frame), and the position error is ``e = difference(q_d, q)`` (NV, the
velocity that moves ``q_d`` to ``q`` in unit time) with ``ė`` taken as ``v − v_d``. That is
the error's rate to first order in ``e``, so the statements below (exact error dynamics,
energy and Lyapunov balances) hold to first order in ``e`` there: the laws converge from
errors that are not too large (tests/control/test_quaternion_control.py).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from ..identification.charts import chart_states
from .configuration import module_layout, position_error

Desired = Callable[[float], tuple]


def fourier_reference(trajectory, model=None) -> Desired:
    """``desired(t) = (q_d, qd_d, qdd_d)`` of a :class:`~eomgen.identification.excitation.
    FourierTrajectory` (the excitation trajectories of ``eomgen excite``); for a ``model`` with
    quaternion joints (or a generated module of one) the trajectory is in the chart of
    :mod:`eomgen.identification.charts` and ``q_d`` has NQ entries."""
    joints = () if model is None else module_layout(model)

    def desired(t):
        q, qd, qdd = chart_states(joints, *trajectory.states(np.array([float(t)])))
        return q[0], qd[0], qdd[0]

    return desired


def _error(module, q, q_d) -> np.ndarray:
    return position_error(module_layout(module), q, q_d)


@dataclass(frozen=True)
class ComputedTorque:
    """τ = M(q) (q̈_d − K_d ė − K_p e) + C(q, q̇) q̇ + g(q), e = q − q_d: with the model's
    own parameters the error obeys ë + K_d ė + K_p e = 0 exactly.

    ``module``: a generated NumPy module with ``mass_matrix`` and ``inverse_dynamics``;
    ``parameters``: keyword values the law uses (the caller's estimate; {} = the description's).
    """

    module: object
    desired: Desired
    Kp: np.ndarray
    Kd: np.ndarray
    parameters: Mapping = field(default_factory=dict)

    def torque(self, t, q, qd):
        q_d, qd_d, qdd_d = self.desired(t)
        e, de = _error(self.module, q, q_d), qd - qd_d
        v = qdd_d - self.Kd @ de - self.Kp @ e
        m = self.module
        bias = m.inverse_dynamics(q, qd, np.zeros_like(qd), **self.parameters)
        return m.mass_matrix(q, **self.parameters) @ v + bias


@dataclass(frozen=True)
class PDGravity:
    """τ = −K_p (q − q_d) − K_d q̇ + g(q) for a set point q_d: with the model's own g the energy
    E = ½ q̇ᵀ M q̇ + ½ eᵀ K_p e decreases as dE/dt = −q̇ᵀ K_d q̇ (Ṁ − 2C skew)."""

    module: object
    q_d: np.ndarray
    Kp: np.ndarray
    Kd: np.ndarray
    parameters: Mapping = field(default_factory=dict)

    def torque(self, t, q, qd):
        g = self.module.gravity_vector(q, **self.parameters)
        return -self.Kp @ _error(self.module, q, self.q_d) - self.Kd @ qd + g

    def energy(self, q, qd, **true_parameters) -> float:
        """E = ½ q̇ᵀ M(q) q̇ + ½ (q − q_d)ᵀ K_p (q − q_d), M at ``true_parameters``."""
        e = _error(self.module, q, self.q_d)
        M = self.module.mass_matrix(q, **true_parameters)
        return 0.5 * qd @ M @ qd + 0.5 * e @ self.Kp @ e


@dataclass(frozen=True)
class SlotineLi:
    """The adaptive passivity-based controller of Slotine and Li (1987)::

        e = q − q_d,  q̇_r = q̇_d − Λ e,  q̈_r = q̈_d − Λ ė,  s = q̇ − q̇_r = ė + Λ e
        τ   = Y_SL(q, q̇, q̇_r, q̈_r) β̂ − K_D s
        dβ̂/dt = −Γ Y_SLᵀ s

    with Y_SL the base Slotine–Li regressor (``slotine_li_base_regressor`` of ``module``; β̂
    estimates its base parameters β, ``base_parameters``). Closed loop: M ṡ + (C + K_D) s =
    Y_SL β̃ (β̃ = β̂ − β); with V = ½ sᵀ M s + ½ β̃ᵀ Γ⁻¹ β̃, dV/dt = −sᵀ K_D s ≤ 0, because
    sᵀ (Ṁ − 2C) s = 0 for the Christoffel C the regressor is built on.
    """

    module: object
    desired: Desired
    Lambda: np.ndarray
    KD: np.ndarray
    Gamma: np.ndarray

    def reference(self, t, q, qd):
        """(q̇_r, q̈_r, s) at time ``t``."""
        q_d, qd_d, qdd_d = self.desired(t)
        e, de = _error(self.module, q, q_d), qd - qd_d
        qd_r = qd_d - self.Lambda @ e
        qdd_r = qdd_d - self.Lambda @ de
        return qd_r, qdd_r, qd - qd_r

    def torque_and_adaptation(self, t, q, qd, beta_hat):
        """(τ, dβ̂/dt)."""
        qd_r, qdd_r, s = self.reference(t, q, qd)
        Y = self.module.slotine_li_base_regressor(q, qd, qd_r, qdd_r)
        return Y @ beta_hat - self.KD @ s, -self.Gamma @ (Y.T @ s)

    @classmethod
    def tuned(cls, module, desired: Desired, beta_hat, period: float, Lambda: float = 5.0,
              damping: float = 10.0, adaptation: float = 2.0, regularization: float = 1e-10,
              samples: int = 100) -> "SlotineLi":
        """The law with gains that scale with the robot (what a 6-joint arm whose wrist is
        10⁵ times lighter than its shoulder needs; one K_D and one Γ for every joint would
        make its closed loop stiff):

        * Λ = ``Lambda`` · I [1/s];
        * K_D = ``damping`` · M̂(q_d(0)), M̂ from the estimate ``beta_hat``
          (:func:`estimated_mass_matrix`), so that s decays at about ``damping`` [1/s] on
          every joint;
        * Γ = ``adaptation`` · (A + ε λ_max(A) I)⁻¹, A = ⟨Y_SLᵀ K_D⁻¹ Y_SL⟩ averaged over
          ``samples`` points of one ``period`` of the desired motion (on it, q̇_r = q̇_d):
          with s ≈ K_D⁻¹ Y_SL β̃, the estimate's error then decays at about ``adaptation``
          [1/s] in every direction the motion excites; ε = ``regularization`` bounds the
          gain of directions it barely excites.

        ``desired`` should be persistently exciting (A positive definite), e.g. an
        excitation trajectory of ``eomgen excite`` through :func:`fourier_reference`."""
        beta_hat = np.asarray(beta_hat, dtype=float)
        q0 = np.asarray(desired(0.0)[0], dtype=float)
        n = len(desired(0.0)[1])  # NV
        KD = damping * estimated_mass_matrix(module, q0, beta_hat)
        KD_inv = np.linalg.inv(KD)
        A = np.zeros((len(beta_hat), len(beta_hat)))
        for t in np.linspace(0.0, period, samples, endpoint=False):
            q, qd, qdd = desired(t)
            Y = module.slotine_li_base_regressor(q, qd, qd, qdd)
            A += Y.T @ KD_inv @ Y / samples
        A = (A + A.T) / 2
        Gamma = adaptation * np.linalg.inv(
            A + regularization * np.linalg.eigvalsh(A)[-1] * np.eye(len(A)))
        return cls(module, desired, Lambda * np.eye(n), KD, (Gamma + Gamma.T) / 2)

    def lyapunov(self, t, q, qd, beta_hat, beta, **true_parameters) -> float:
        """V = ½ sᵀ M(q) s + ½ β̃ᵀ Γ⁻¹ β̃, M at ``true_parameters`` (the plant's)."""
        s = self.reference(t, q, qd)[2]
        M = self.module.mass_matrix(q, **true_parameters)
        err = beta_hat - beta
        return 0.5 * s @ M @ s + 0.5 * err @ np.linalg.solve(self.Gamma, err)


def estimated_mass_matrix(module, q, beta_hat) -> np.ndarray:
    """M̂(q) (NV, NV) of the base-parameter estimate ``beta_hat``, from the Slotine–Li regressor
    alone: column j is Y_SL(q, 0, 0, e_j) β̂ − Y_SL(q, 0, 0, 0) β̂ (the law knows no more of
    the robot than β̂)."""
    q = np.asarray(q, dtype=float)
    n = len(getattr(module, "JOINT_NAMES", q))  # NV
    zero = np.zeros(n)
    Y = module.slotine_li_base_regressor
    g = Y(q, zero, zero, zero) @ beta_hat
    M = np.column_stack([Y(q, zero, zero, e) @ beta_hat - g for e in np.eye(n)])
    return (M + M.T) / 2


__all__ = ["Desired", "fourier_reference", "ComputedTorque", "PDGravity", "SlotineLi",
           "estimated_mass_matrix"]
