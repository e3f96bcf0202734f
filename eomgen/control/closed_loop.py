"""Closed-loop simulation of a control law (:mod:`eomgen.control.laws`) on a generated model:
the plant is the module's ``mass_matrix`` and ``inverse_dynamics`` at the true parameters
(q̈ = M⁻¹ (τ − C q̇ − g)), the law sees only what it
is given (an adaptive law integrates its estimate alongside the state).

Integrated with SciPy's ``solve_ivp`` (DOP853; ``rtol`` and ``atol`` 1e-10 by default), the
state ``[q, q̇, β̂ (adaptive laws), ∫ rate dt (if asked)]`` reported at the times ``t_eval``.
With quaternion joints (read off the module's names, :mod:`eomgen.control.configuration`) q
has NQ entries and moves at ``configuration_rate(q, v)``; the quaternions are integrated as
vectors (their norms drift with the integrator's error; every generated function normalises
them).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from .configuration import module_layout, rate as configuration_rate


@dataclass(frozen=True)
class ClosedLoop:
    """A simulated closed loop, at the reporting times.

    Attributes
    ----------
    t : (N,) [s]
    q, qd : (N, NQ), (N, NV) joint positions and velocities
    beta_hat : (N, b) the adaptive law's estimate (``None`` for a fixed law)
    integral : (N,) ∫ rate dt of ``simulate``'s ``rate`` (``None`` without one)
    steps : the integrator's right-hand-side evaluations
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    beta_hat: np.ndarray | None
    integral: np.ndarray | None
    steps: int


def simulate(law, q0, qd0, t_final: float, t_eval=None, beta0=None,
             plant: Mapping | None = None, rate: Callable | None = None,
             rtol: float = 1e-10, atol: float = 1e-10) -> ClosedLoop:
    """Simulate ``law`` on its module's robot from ``(q0, qd0)`` for ``t_final`` seconds.

    Parameters
    ----------
    law:
        A law with ``torque(t, q, qd)``, or with ``torque_and_adaptation(t, q, qd, beta_hat)``
        (then ``beta0`` is the estimate's start).
    plant:
        The true parameters (keywords of the generated functions; {} = the description's).
    rate:
        ``rate(t, q, qd) -> float`` integrated alongside (e.g. the power dissipated).
    t_eval:
        Reporting times (default: 1001 from 0 to ``t_final``).
    """
    from scipy.integrate import solve_ivp  # an optional dependency (eomgen[identify])

    plant = dict(plant or {})
    q0, qd0 = np.asarray(q0, dtype=float), np.asarray(qd0, dtype=float)
    nq, n = len(q0), len(qd0)
    adaptive = beta0 is not None
    b = len(beta0) if adaptive else 0
    module = law.module
    joints = module_layout(module)
    zero = np.zeros(n)

    def forward(q, qd, tau):
        """q̈ = M⁻¹ (τ − C q̇ − g) at the plant's parameters (a 2 × cheaper call than the
        module's forward_dynamics, which also estimates cond M)."""
        bias = module.inverse_dynamics(q, qd, zero, **plant)
        return np.linalg.solve(module.mass_matrix(q, **plant), tau - bias)

    def rhs(t, y):
        q, qd = y[:nq], y[nq:nq + n]
        if adaptive:
            tau, dbeta = law.torque_and_adaptation(t, q, qd, y[nq + n:nq + n + b])
        else:
            tau, dbeta = law.torque(t, q, qd), np.zeros(0)
        qdd = forward(q, qd, tau)
        extra = [rate(t, q, qd)] if rate is not None else []
        return np.concatenate([configuration_rate(joints, q, qd), qdd, dbeta, extra])

    y0 = np.concatenate([q0, qd0, np.asarray(beta0, dtype=float) if adaptive else [],
                         [0.0] if rate is not None else []])
    if t_eval is None:
        t_eval = np.linspace(0.0, t_final, 1001)
    sol = solve_ivp(rhs, (0.0, t_final), y0, method="DOP853", t_eval=t_eval, rtol=rtol,
                    atol=atol)
    if not sol.success:
        raise RuntimeError(f"closed-loop simulation failed: {sol.message}")
    y = sol.y.T
    return ClosedLoop(sol.t, y[:, :nq], y[:, nq:nq + n],
                      y[:, nq + n:nq + n + b] if adaptive else None,
                      y[:, -1] if rate is not None else None, sol.nfev)


__all__ = ["ClosedLoop", "simulate"]
