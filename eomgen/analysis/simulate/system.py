"""The system ``eomgen simulate`` integrates: ``M(q) q̈ + C(q, q̇) q̇ + g(q) = 0``, and its energy.

Every integrator calls :class:`System`, built from one :func:`eomgen.derive` (M, C, g, τ) whose
program is printed over Python floats (:func:`eomgen.analysis.routes.compile_scalar`): it is
the fastest single-state float64 route eomgen has from Python (about 3× faster than the CasADi
SX function and 40× faster than the generated NumPy module called per state; see
``eomgen bench``), and bit-for-bit the same arithmetic as the generated code. Forward dynamics
solves ``M q̈ = −(C q̇ + g)`` (the bias from the Newton–Euler program with q̈ = 0) by a Cholesky
factorisation in plain Python (faster than NumPy's per-call overhead for a robot's few joints),
with the rules of :mod:`eomgen.analysis.conditioning` and of the generated
``forward_dynamics``: a matrix that is not positive definite ends the run (reported as
diverged), and an ill-conditioned M is warned about once per run, not at every step.
"""

from __future__ import annotations

import math

import numpy as np

from ...dynamics import derive
from ...model import RobotModel
from ...numeric import kinetic_energy, numeric_model, potential_energy
from ...model.configuration import configuration_rate, integrate, quaternion_indices
from ..conditioning import EXACT_FROM
from ..routes import compile_scalar, numeric_only


def advance(model: RobotModel, q: np.ndarray, v: np.ndarray, h: float) -> np.ndarray:
    """``q ⊕ h v``: each joint moved along its kind's exponential
    (:func:`eomgen.model.configuration.integrate`), so every quaternion is unit and a planar
    joint's ``(cos θ, sin θ)`` on its circle, up to round-off, whatever the step. Each
    quaternion of the result is the one of ``±`` nearest ``q``'s (both are the same rotation):
    a trajectory stepped with it is continuous, as the reference it is compared with."""
    out = integrate(q, v, h, model)
    for start in quaternion_indices(model):
        k = slice(start, start + 4)
        if out[k] @ q[k] < 0.0:
            out[k] = -out[k]
    return out


class Diverged(ArithmeticError):
    """The integration left the finite numbers, or the mass matrix lost positive
    definiteness on the way (a sign of a step far too large)."""


class System:
    """``q̈ = f(q, q̇)`` with zero torque, and what the integrators need besides.

    Parameters
    ----------
    model:
        The robot; parameters take their values.

    Attributes
    ----------
    n:
        Degrees of freedom.
    evaluations:
        Dynamics evaluations so far (forward dynamics, or M, C and g for the implicit
        midpoint rule); reset by :func:`simulate`.
    max_condition:
        Largest condition number of M met since the last reset.
    """

    def __init__(self, model: RobotModel):
        self.model = numeric_only(model)
        dyn = derive(self.model, outputs=("M", "C", "g", "tau"), simplify=False)
        self.n = n = len(dyn.qd)
        self._extra = len(dyn.q) - n  # 1 for each quaternion (free flyer, ball joint)
        zero_qdd = {s: 0 for s in dyn.qdd}
        self._M = compile_scalar(dyn.program, dyn.q, ["M"])
        self._bias = compile_scalar(dyn.program, dyn.q + dyn.qd, ["tau"], fixed=zero_qdd)
        self._Cg = compile_scalar(dyn.program, dyn.q + dyn.qd, ["C", "g"])
        #: True when the configuration is not a vector (a free flyer, ball or planar joints:
        #: NQ ≠ NV): the integrators step it along its manifold (:meth:`integrate`).
        self.quaternion = self.model.nq > self.model.dof
        self._nm = numeric_model(self.model)
        self._shape = (n, n)
        self.evaluations = 0
        self._worst: tuple[float, list] = (1.0, [])

    @property
    def nq(self) -> int:
        """Entries of the configuration: :attr:`n`, one more for a free flyer."""
        return self.n + self._extra

    def reset(self) -> None:
        self.evaluations = 0
        self._worst = (1.0, [])

    def _solve(self, M: list, b: list) -> np.ndarray:
        """Solve ``M x = b`` (M flat, row-major) by Cholesky in plain Python: for the few joints
        of a robot this beats NumPy's per-call overhead several times over. Same rules as
        :func:`~eomgen.analysis.conditioning.cholesky_solve`; the worst condition is kept for
        :attr:`max_condition` rather than warned about at every step. The size is ``len(b)``."""
        n = len(b)
        L = [[0.0] * n for _ in range(n)]
        for j in range(n):
            Lj = L[j]
            d = M[j * n + j] - sum(x * x for x in Lj[:j])
            if not d > 0.0:
                if math.isfinite(d):
                    raise Diverged("M(q) is not positive definite")
                raise Diverged("M(q) is not finite")
            Lj[j] = root = math.sqrt(d)
            for i in range(j + 1, n):
                Li = L[i]
                Li[j] = (M[i * n + j] - sum(Li[k] * Lj[k] for k in range(j))) / root
        y = [0.0] * n
        for i in range(n):
            y[i] = (b[i] - sum(L[i][k] * y[k] for k in range(i))) / L[i][i]
        x = [0.0] * n
        for i in reversed(range(n)):
            x[i] = (y[i] - sum(L[k][i] * x[k] for k in range(i + 1, n))) / L[i][i]
        if n:
            diagonal = [L[i][i] for i in range(n)]
            condition = (max(diagonal) / min(diagonal)) ** 2
            if condition > self._worst[0]:
                self._worst = (condition, M)
        return np.array(x)

    @property
    def max_condition(self) -> float:
        """The largest condition number of M met since the last reset: the estimate of
        :func:`~eomgen.analysis.conditioning.condition_estimate`, exact (eigenvalues) when it
        exceeds :data:`~eomgen.analysis.conditioning.EXACT_FROM`."""
        estimate, M = self._worst
        if estimate > EXACT_FROM:
            eigenvalues = np.linalg.eigvalsh(np.reshape(M, self._shape))
            return max(estimate, eigenvalues[-1] / max(eigenvalues[0], np.finfo(float).tiny))
        return estimate

    def M(self, q: np.ndarray) -> np.ndarray:
        """M(q), (n, n)."""
        return np.reshape(self._M(*q.tolist())[0], self._shape)

    def forward_dynamics(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """q̈ at zero torque: solve ``M(q) q̈ = −(C(q, q̇) q̇ + g(q))``."""
        self.evaluations += 1
        bias = self._bias(*q.tolist(), *qd.tolist())[0]
        return self._solve(self._M(*q.tolist())[0], [-x for x in bias])

    def velocity(self, q: np.ndarray, p: np.ndarray) -> np.ndarray:
        """``q̇ = M(q)⁻¹ p``."""
        return self._solve(self._M(*q.tolist())[0], p.tolist())

    def velocity_and_momentum_rate(self, q: np.ndarray, p: np.ndarray):
        """``(q̇, ṗ)`` of the canonical form: ``q̇ = M⁻¹ p``, ``ṗ = Cᵀ q̇ − g`` (zero torque)."""
        self.evaluations += 1
        qd = self.velocity(q, p)
        C, g = self._Cg(*q.tolist(), *qd.tolist())
        n = self.n
        v = qd.tolist()
        pdot = [sum(C[i * n + k] * v[i] for i in range(n)) - g[k] for k in range(n)]
        return qd, np.array(pdot)

    def energy(self, q: np.ndarray, qd: np.ndarray) -> tuple[float, float]:
        """``(K, P)`` [J] from :mod:`eomgen.numeric` (not the derived program; with quaternion
        joints ``q`` is the configuration, ``qd`` the velocity)."""
        return kinetic_energy(self._nm, q, qd), potential_energy(self._nm, q)

    def configuration_rate(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """``q̇`` of the configuration at velocity ``qd``: ``qd`` itself, or with quaternion
        joints (:mod:`eomgen.model.configuration`) a free flyer's root position rate (``R v``),
        each quaternion's rate (``½ quaternion ⊗ (ω, 0)``) and the other joints' rates (the
        embedded form the adaptive methods integrate between output times)."""
        if not self.quaternion:
            return qd
        return configuration_rate(q, qd, self.model)

    def integrate(self, q: np.ndarray, qd: np.ndarray, h: float) -> np.ndarray:
        """``q ⊕ h q̇``: the configuration reached from ``q`` at the constant velocity ``qd``
        after ``h`` seconds, each joint along its own manifold (:func:`advance`); how the
        integrators step a system whose :attr:`quaternion` is true."""
        return advance(self.model, q, qd, h)


__all__ = ["Diverged", "System", "advance"]
