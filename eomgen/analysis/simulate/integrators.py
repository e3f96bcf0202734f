"""The integrators of ``eomgen simulate`` (objects; pass them to
:func:`~eomgen.analysis.simulate.study.simulate`), and their names on the command line.

* :class:`ExplicitEuler` — first order, energy grows.
* :class:`SemiImplicitEuler` — ``q̇ₖ₊₁ = q̇ₖ + h q̈ₖ``, ``qₖ₊₁ = qₖ + h q̇ₖ₊₁``; symplectic
  when M is constant, first order.
* :class:`RK4` — classical fourth order.
* :class:`ImplicitMidpoint` — the implicit midpoint rule in canonical coordinates
  ``(q, p = M(q) q̇)``, with ``q̇ = M⁻¹p`` and ``ṗ = C(q, q̇)ᵀ q̇ − g(q) + τ`` (which is
  ``∂L/∂q + τ``, since ``Cᵀq̇ = ½ q̇ᵀ ∂M/∂q q̇`` for the Christoffel C); symplectic and
  symmetric, second order, energy error bounded. Solved by fixed-point iteration to
  :attr:`ImplicitMidpoint.tolerance`.
* :class:`Adaptive` — :func:`scipy.integrate.solve_ivp` (``RK45`` or ``DOP853``) with a
  relative tolerance (``atol = rtol``).

Each has ``run(system, q0, qd0, times) -> (states, step)``; the system is a
:class:`~eomgen.analysis.simulate.system.System` or one with its methods (the flexible-joint,
contact and loop systems).

**Configurations that are not vectors.** For a system whose ``quaternion`` is true (a free
flyer, ball or planar joints: ``q`` holds unit quaternions or ``(cos θ, sin θ)``, NQ ≠ NV) the
fixed-step methods move ``q`` by the joints' exponentials, ``system.integrate(q, v, h) = q ⊕ h
v`` (:func:`~eomgen.analysis.simulate.system.advance`), and add velocities as vectors, so every
quaternion stays unit, and every ``(cos θ, sin θ)`` on its circle, up to round-off whatever the
step:

* explicit Euler ``qₖ₊₁ = qₖ ⊕ h vₖ``; semi-implicit Euler ``qₖ₊₁ = qₖ ⊕ h vₖ₊₁``;
* RK4 the commutator-free Lie group method of order 4 of Celledoni, Marthinsen and Owren
  (2003), whose velocities and stage velocities are the classical RK4's:
  ``Q₂ = q ⊕ ½h V₁``, ``Q₃ = q ⊕ ½h V₂``, ``Q₄ = Q₂ ⊕ h (V₃ − ½V₁)``, ``qₖ₊₁ = (q ⊕
  h (3V₁ + 2V₂ + 2V₃ − V₄)/12) ⊕ h (−V₁ + 2V₂ + 2V₃ + 3V₄)/12``. The "frozen" scheme
  ``q ⊕ h Σ bᵢ Vᵢ`` with RK4's weights is only of order 2 when the angular velocity turns
  (it leaves out the commutator ``h³/12 [ω, ω̇]`` of each step);
* the implicit midpoint rule ``ξ = h M⁻¹(Q) (p₀ + p₁)/2``, ``Q = q ⊕ ξ/2``, ``qₖ₊₁ = q ⊕ ξ``
  (symmetric, order 2), iterated on ``(ξ, p₁)``;
* the adaptive methods (SciPy's steps cannot be group steps) integrate the embedded form
  ``q̇ = configuration_rate(q, v)``, a quaternion as a vector (its norm drifts by about the
  tolerance), and put each output after the start back on its manifold, ``q ⊕ 0``
  (normalised): their outputs are unit, their error shows in the trajectory error.
  (Restarting from each projected output instead would cap their steps at the output
  spacing.)

A system without such joints (or without ``quaternion``) is integrated as a vector,
``q + h q̇``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Protocol, Sequence

import numpy as np

from .system import Diverged, System


def _on_manifold(system) -> bool:
    """True when the system's configuration is stepped by ``system.integrate`` (module
    docstring)."""
    return bool(getattr(system, "quaternion", False))


def _rate(system, q, qd):
    """``q̇`` for the integrators: :meth:`System.configuration_rate` where the system has one
    (a free flyer's quaternion), else the velocities themselves (the flexible-joint and contact
    systems, whose q and q̇ have one size)."""
    rate = getattr(system, "configuration_rate", None)
    return qd if rate is None else rate(q, qd)


class Integrator(Protocol):
    name: str

    def label(self) -> str: ...


@dataclass(frozen=True)
class FixedStep:
    """Base of the fixed-step integrators: ``step(system, q, qd, h) -> (q, qd)``."""

    dt: float
    name = "fixed step"

    def label(self) -> str:
        return f"dt = {self.dt:g} s"

    def run(self, system: System, q0, qd0, times: np.ndarray):
        """Integrate onto ``times`` (equally spaced) with the largest step ≤ ``dt`` that divides
        their spacing (a ``dt`` above the spacing is reduced to it); returns the states at
        ``times`` and the step used."""
        steps_per_output = max(1, math.ceil((times[1] - times[0]) / self.dt - 1e-9))
        h = (times[1] - times[0]) / steps_per_output
        state = self.start(system, np.array(q0, float), np.array(qd0, float))
        out = [self.output(system, state)]
        for _ in range(len(times) - 1):
            for _ in range(steps_per_output):
                state = self.step(system, state, h)
            q, qd = self.output(system, state)
            if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
                raise Diverged("the state is no longer finite")
            out.append((q, qd))
        return out, h

    def start(self, system, q, qd):
        return q, qd

    def output(self, system, state):
        return state

    def step(self, system, state, h):  # pragma: no cover - abstract
        raise NotImplementedError


@dataclass(frozen=True)
class ExplicitEuler(FixedStep):
    name = "explicit Euler"

    def step(self, system, state, h):
        q, qd = state
        if _on_manifold(system):
            return system.integrate(q, qd, h), qd + h * system.forward_dynamics(q, qd)
        return q + h * _rate(system, q, qd), qd + h * system.forward_dynamics(q, qd)


@dataclass(frozen=True)
class SemiImplicitEuler(FixedStep):
    name = "semi-implicit Euler"

    def step(self, system, state, h):
        q, qd = state
        qd = qd + h * system.forward_dynamics(q, qd)
        if _on_manifold(system):
            return system.integrate(q, qd, h), qd
        return q + h * _rate(system, q, qd), qd


@dataclass(frozen=True)
class RK4(FixedStep):
    name = "RK4"

    def step(self, system, state, h):
        if _on_manifold(system):
            return self.lie_step(system, state, h)
        q, qd = state
        f = system.forward_dynamics

        def rate(q, v):
            return _rate(system, q, v)

        k1q, k1v = rate(q, qd), f(q, qd)
        q2, v2 = q + h / 2 * k1q, qd + h / 2 * k1v
        k2q, k2v = rate(q2, v2), f(q2, v2)
        q3, v3 = q + h / 2 * k2q, qd + h / 2 * k2v
        k3q, k3v = rate(q3, v3), f(q3, v3)
        q4, v4 = q + h * k3q, qd + h * k3v
        k4q, k4v = rate(q4, v4), f(q4, v4)
        return (q + h / 6 * (k1q + 2 * k2q + 2 * k3q + k4q),
                qd + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v))

    @staticmethod
    def lie_step(system, state, h):
        """One step of the commutator-free method of order 4 (module docstring): the stage
        velocities ``Vᵢ`` and the new velocity are RK4's, the configurations move by
        ``system.integrate``."""
        q, v1 = state
        f, move = system.forward_dynamics, system.integrate
        a1 = f(q, v1)
        q2, v2 = move(q, v1, h / 2), v1 + h / 2 * a1
        a2 = f(q2, v2)
        q3, v3 = move(q, v2, h / 2), v1 + h / 2 * a2
        a3 = f(q3, v3)
        q4, v4 = move(q2, v3 - v1 / 2, h), v1 + h * a3
        a4 = f(q4, v4)
        half = move(q, (3 * v1 + 2 * v2 + 2 * v3 - v4) / 12, h)
        return (move(half, (-v1 + 2 * v2 + 2 * v3 + 3 * v4) / 12, h),
                v1 + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4))


@dataclass(frozen=True)
class ImplicitMidpoint(FixedStep):
    """Implicit midpoint rule on ``(q, p = M q̇)`` (symplectic), fixed-point iterations.

    Each step solves ``z₁ = z₀ + h F((z₀ + z₁)/2)`` for ``z = (q, p)`` by iterating from the
    explicit Euler guess until the update is below ``tolerance`` (relative to ``1 + |z|``),
    at most ``max_iterations`` times; it raises :class:`Diverged` otherwise (a step too large
    for the iteration to contract, ``h·‖∂F/∂z‖ ≥ 1``).
    """

    tolerance: float = 1e-13
    max_iterations: int = 100
    name = "implicit midpoint"

    def start(self, system, q, qd):
        return q, system.M(q) @ qd

    def output(self, system, state):
        q, p = state
        return q, system.velocity(q, p)

    def step(self, system, state, h):
        if _on_manifold(system):
            return self.lie_step(system, state, h)
        q0, p0 = state
        qd, pdot = system.velocity_and_momentum_rate(q0, p0)
        q1, p1 = q0 + h * _rate(system, q0, qd), p0 + h * pdot
        for _ in range(self.max_iterations):
            middle = (q0 + q1) / 2
            qd, pdot = system.velocity_and_momentum_rate(middle, (p0 + p1) / 2)
            q_next, p_next = q0 + h * _rate(system, middle, qd), p0 + h * pdot
            change = max(np.max(np.abs(q_next - q1)), np.max(np.abs(p_next - p1)))
            scale = 1 + max(np.max(np.abs(q_next)), np.max(np.abs(p_next)))
            q1, p1 = q_next, p_next
            if change <= self.tolerance * scale:
                return q1, p1
            if not np.isfinite(change):
                break
        raise Diverged(f"the implicit midpoint iteration did not converge (h = {h:g} s)")

    def lie_step(self, system, state, h):
        """The midpoint rule on the manifold (module docstring): iterate ``ξ = h q̇(Q, p̄)``,
        ``Q = q₀ ⊕ ξ/2``, ``p₁ = p₀ + h ṗ(Q, p̄)``, ``p̄ = (p₀ + p₁)/2`` from the explicit Euler
        guess, to the same tolerance; then ``q₁ = q₀ ⊕ ξ``."""
        q0, p0 = state
        qd, pdot = system.velocity_and_momentum_rate(q0, p0)
        xi, p1 = h * qd, p0 + h * pdot
        scale_q = np.max(np.abs(q0))
        for _ in range(self.max_iterations):
            middle = system.integrate(q0, xi, 0.5)
            qd, pdot = system.velocity_and_momentum_rate(middle, (p0 + p1) / 2)
            xi_next, p_next = h * qd, p0 + h * pdot
            change = max(np.max(np.abs(xi_next - xi)), np.max(np.abs(p_next - p1)))
            scale = 1 + max(scale_q, np.max(np.abs(p_next)))
            xi, p1 = xi_next, p_next
            if change <= self.tolerance * scale:
                return system.integrate(q0, xi, 1.0), p1
            if not np.isfinite(change):
                break
        raise Diverged(f"the implicit midpoint iteration did not converge (h = {h:g} s)")


@dataclass(frozen=True)
class Adaptive:
    """:func:`scipy.integrate.solve_ivp` with ``method`` (``"RK45"``, ``"DOP853"``), relative
    tolerance ``rtol`` and ``atol = rtol``."""

    method: str = "DOP853"
    rtol: float = 1e-8

    @property
    def name(self) -> str:
        return f"{self.method} (adaptive)"

    def label(self) -> str:
        return f"rtol = {self.rtol:g}"

    def run(self, system: System, q0, qd0, times: np.ndarray):
        from scipy.integrate import solve_ivp  # optional dependency (the analysis extra)

        n = getattr(system, "nq", system.n)

        def rhs(t, z):
            return np.concatenate([_rate(system, z[:n], z[n:]),
                                   system.forward_dynamics(z[:n], z[n:])])

        z0 = np.concatenate([np.asarray(q0, float), np.asarray(qd0, float)])
        solution = solve_ivp(rhs, (times[0], times[-1]), z0, method=self.method, t_eval=times,
                             rtol=self.rtol, atol=self.rtol)
        if solution.status != 0 or solution.y.shape[1] != len(times):
            raise Diverged(f"solve_ivp ({self.method}) failed: {solution.message}")
        if _on_manifold(system):  # each output after the start put back on the manifold
            zero = np.zeros(len(z0) - n)
            return [(z0[:n], z0[n:])] + [
                (system.integrate(solution.y[:n, k], zero, 0.0), solution.y[n:, k])
                for k in range(1, len(times))], None
        return [(solution.y[:n, k], solution.y[n:, k]) for k in range(len(times))], None


def default_integrators(dts: Sequence[float] = (1e-2, 3e-3, 1e-3),
                        rtols: Sequence[float] = (1e-4, 1e-6, 1e-8)) -> list:
    """Every integrator at every step in ``dts`` and every tolerance in ``rtols``."""
    fixed = [kind(dt) for kind in (ExplicitEuler, SemiImplicitEuler, RK4, ImplicitMidpoint)
             for dt in dts]
    return fixed + [Adaptive(method, rtol) for method in ("RK45", "DOP853") for rtol in rtols]


#: Integrator families by command-line name.
INTEGRATORS = {"euler": ExplicitEuler, "semi-implicit-euler": SemiImplicitEuler, "rk4": RK4,
               "implicit-midpoint": ImplicitMidpoint, "rk45": "RK45", "dop853": "DOP853",
               "radau": "Radau", "bdf": "BDF"}
#: The implicit solvers for stiff systems (SciPy's Radau IIA and BDF, finite-difference
#: Jacobians): in ``all`` only for stiff systems (flexible joints).
STIFF = ("radau", "bdf")


def integrators_named(names: Sequence[str], dts: Sequence[float], rtols: Sequence[float],
                      stiff: bool = False) -> list:
    """The integrators of :data:`INTEGRATORS` named in ``names`` (or ``all``: every one, the
    :data:`STIFF` ones only when ``stiff``), at every step / tolerance; raises ValueError for
    an unknown name."""
    names = ([k for k in INTEGRATORS if stiff or k not in STIFF] if list(names) == ["all"]
             else list(names))
    unknown = [n for n in names if n not in INTEGRATORS]
    if unknown:
        raise ValueError(f"unknown integrator {', '.join(unknown)}; choose from "
                         f"{', '.join(INTEGRATORS)} or all")
    out = []
    for name in names:
        kind = INTEGRATORS[name]
        if isinstance(kind, str):
            out += [Adaptive(kind, r) for r in rtols]
        else:
            out += [kind(d) for d in dts]
    return out


__all__ = ["INTEGRATORS", "STIFF", "Adaptive", "ExplicitEuler", "FixedStep", "ImplicitMidpoint",
           "Integrator", "RK4", "SemiImplicitEuler", "default_integrators", "integrators_named"]
