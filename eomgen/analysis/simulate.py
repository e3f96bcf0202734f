"""Simulation without torque or damping: integrators against energy drift and trajectory error.

``eomgen simulate`` integrates ``M(q) q̈ + C(q, q̇) q̇ + g(q) = 0`` from a given state with
several integrators and step sizes, and reports, for each run, the wall time against

* **energy drift**: ``max_t |E(t) − E(0)|`` with ``E = K + P`` from
  :func:`eomgen.numeric.kinetic_energy` and :func:`~eomgen.numeric.potential_energy` (an
  independent computation, not the derived program), in J and relative to the energy scale
  ``max(max_t K_ref(t), |E(0)|)``;
* **trajectory error**: ``max_t ‖q(t) − q_ref(t)‖∞`` [rad or m] against a reference from
  :func:`scipy.integrate.solve_ivp` (DOP853, ``rtol = atol = 1e-12``).

Both are sampled on an output grid of :data:`OUTPUT_POINTS` equally spaced times. For a
chaotic system (the double pendulum) the trajectory error of every method grows like
``e^{λt}``; past a few seconds it measures the horizon of predictability more than the method.

The dynamics
------------
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

Integrators (objects; pass them to :func:`simulate`)
----------------------------------------------------
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
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Protocol, Sequence

import numpy as np

from ..dynamics import derive
from ..model import RobotModel
from ..progress import plural
from ..numeric import kinetic_energy, numeric_model, potential_energy
from .conditioning import (CONDITION_LIMIT, EXACT_FROM, IllConditionedWarning,
                           ill_conditioned_message)
from .report import csv_text, fmt, markdown_table, pyplot
from ..quaternion_joints import configuration_rate, neutral
from .routes import compile_scalar, numeric_only

#: Points of the output grid (both ends included).
OUTPUT_POINTS = 101
#: Tolerances of the reference solution (solve_ivp DOP853).
REFERENCE_TOLERANCE = 1e-12


class Diverged(ArithmeticError):
    """The integration left the finite numbers, or the mass matrix lost positive
    definiteness on the way (a sign of a step far too large)."""


# ----------------------------------------------------------------------------------------------
# The system
# ----------------------------------------------------------------------------------------------

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
        #: True when q holds quaternions (a free flyer, ball joints): NQ ≠ NV.
        self.quaternion = bool(self.model.quaternion_joints)
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
        joints (:mod:`eomgen.quaternion_joints`) a free flyer's root position rate (``R v``),
        each quaternion's rate (``½ quaternion ⊗ (ω, 0)``) and the other joints' rates; so
        every integrator integrates a quaternion as a vector (its norm drifts with the error
        of the method; the dynamics normalise it)."""
        if not self.quaternion:
            return qd
        return configuration_rate(q, qd, self.model)


# ----------------------------------------------------------------------------------------------
# Integrators
# ----------------------------------------------------------------------------------------------

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
        return q + h * _rate(system, q, qd), qd + h * system.forward_dynamics(q, qd)


@dataclass(frozen=True)
class SemiImplicitEuler(FixedStep):
    name = "semi-implicit Euler"

    def step(self, system, state, h):
        q, qd = state
        qd = qd + h * system.forward_dynamics(q, qd)
        return q + h * _rate(system, q, qd), qd


@dataclass(frozen=True)
class RK4(FixedStep):
    name = "RK4"

    def step(self, system, state, h):
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
        return [(solution.y[:n, k], solution.y[n:, k]) for k in range(len(times))], None


# ----------------------------------------------------------------------------------------------
# Runs
# ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Run:
    """One integration: the integrator, its step or tolerance, the measurements."""

    robot: str
    integrator: str
    setting: str                  # "dt = 0.001 s" or "rtol = 1e-08"
    step: float | None            # the step used [s] (fixed-step methods)
    evaluations: int
    seconds: float
    energy_drift: float           # max |E - E0| [J]
    relative_energy_drift: float  # over the energy scale
    trajectory_error: float       # max_t |q - q_ref|_inf
    final_error: float            # |q(T) - q_ref(T)|_inf
    max_condition: float
    status: str = "ok"            # "ok" or why it failed


@dataclass(frozen=True)
class Trajectory:
    times: np.ndarray
    q: np.ndarray   # (points, n)
    qd: np.ndarray  # (points, n)


def simulate(system: System, integrator, q0, qd0, duration: float,
             points: int = OUTPUT_POINTS) -> tuple[Trajectory, dict]:
    """Integrate from ``(q0, qd0)`` over ``[0, duration]`` with ``integrator``.

    Returns
    -------
    trajectory:
        States on ``points`` equally spaced times.
    info:
        ``seconds`` (wall time), ``evaluations`` (dynamics evaluations), ``step`` (the fixed
        step used, None for adaptive methods), ``max_condition``.

    Raises
    ------
    Diverged
        When the state stops being finite or M stops being positive definite.
    """
    times = np.linspace(0.0, float(duration), points)
    system.reset()
    start = time.perf_counter()
    try:
        states, step = integrator.run(system, q0, qd0, times)
    except (OverflowError, ZeroDivisionError, FloatingPointError) as exc:
        raise Diverged(f"the state overflowed ({exc})") from None
    seconds = time.perf_counter() - start
    q = np.array([s[0] for s in states])
    qd = np.array([s[1] for s in states])
    return Trajectory(times, q, qd), {"seconds": seconds, "evaluations": system.evaluations,
                                      "step": step, "max_condition": system.max_condition}


def energies(system: System, trajectory: Trajectory) -> tuple[np.ndarray, np.ndarray]:
    """Kinetic and potential energy [J] at every output time."""
    K, P = zip(*(system.energy(q, qd) for q, qd in zip(trajectory.q, trajectory.qd)))
    return np.array(K), np.array(P)


@dataclass(frozen=True)
class Study:
    """The runs of one robot, with the reference they are measured against."""

    robot: str
    dof: int
    duration: float
    q0: tuple[float, ...]
    qd0: tuple[float, ...]
    energy_scale: float
    reference_seconds: float
    runs: tuple[Run, ...]

    CSV_HEADERS = ("robot", "integrator", "setting", "step_s", "evaluations", "seconds",
                   "energy_drift_J", "relative_energy_drift", "trajectory_error",
                   "final_error", "max_condition", "status")

    def csv_rows(self) -> list[tuple]:
        return [(r.robot, r.integrator, r.setting, "" if r.step is None else f"{r.step:.6g}",
                 r.evaluations, f"{r.seconds:.4g}", f"{r.energy_drift:.3e}",
                 f"{r.relative_energy_drift:.3e}", f"{r.trajectory_error:.3e}",
                 f"{r.final_error:.3e}", f"{r.max_condition:.3g}", r.status) for r in self.runs]

    def markdown_table(self) -> str:
        rows = [(r.integrator, r.setting, r.evaluations, f"{r.seconds:.3g}",
                 fmt(r.energy_drift), fmt(r.relative_energy_drift), fmt(r.trajectory_error),
                 fmt(r.final_error), r.status) for r in self.runs]
        return markdown_table(["integrator", "step", "evaluations", "time [s]",
                               "energy drift [J]", "relative", "max error q", "error q(T)",
                               "status"], rows, "llrrrrrrl")

    def describe(self) -> str:
        return (f"{self.robot} ({plural(self.dof, 'joint')}), {self.duration:g} s from q0 = "
                f"({', '.join(f'{x:g}' for x in self.q0)}), q̇0 = "
                f"({', '.join(f'{x:g}' for x in self.qd0)}), zero torque, no damping; "
                f"energy scale {self.energy_scale:.3g} J; reference DOP853 rtol = atol = "
                f"{REFERENCE_TOLERANCE:g} ({self.reference_seconds:.2g} s).")


def initial_state(q0, qd0, n: int, joint_names) -> tuple[np.ndarray, np.ndarray]:
    """The start of a simulation of ``n`` coordinates (the joints ``joint_names``, then the
    motors of flexible joints, if any): ``q0`` [rad or m] and ``qd0`` [rad/s or m/s] as float
    arrays, 1 rad (or m) and 0 for a value left out (None).

    >>> initial_state(None, None, 2, ("joint1", "joint2"))
    (array([1., 1.]), array([0., 0.]))

    Raises
    ------
    ValueError
        When either has another number of values than ``n`` (the message names the joints).
    """
    q0 = np.full(n, 1.0) if q0 is None else np.asarray(q0, float)
    qd0 = np.zeros(n) if qd0 is None else np.asarray(qd0, float)
    if q0.shape != (n,) or qd0.shape != (n,):
        raise ValueError(f"q0 and qd0 must have {n} values (joints {', '.join(joint_names)})")
    return q0, qd0


def quaternion_start(model: RobotModel, q0=None, qd0=None) -> tuple[np.ndarray, np.ndarray]:
    """The start of a simulation of a model with quaternion joints: ``q0`` its configuration
    (``model.nq`` values, ``CONFIGURATION_NAMES``; default: identity quaternions, a free flyer
    at the origin, 1 rad or m for the other joints) and ``qd0`` its velocity (``model.dof``
    values, default zero), as float arrays.

    Raises
    ------
    ValueError
        When either has another number of values (the message names the entries).
    """
    names = model.configuration_names
    if q0 is None:
        q0 = neutral(model)
        q0[[k for k, name in enumerate(names) if name in model.joint_names]] = 1.0
    if len(q0) != model.nq:
        raise ValueError(f"q0 must have {model.nq} values ({', '.join(names)})")
    return np.asarray(q0, float), initial_state(None, qd0, model.dof, model.joint_names)[1]


def run_study(model: RobotModel, integrators: Sequence, duration: float, q0=None, qd0=None,
              progress: Callable[[str], None] = lambda _: None, system: System | None = None
              ) -> Study:
    """Run every integrator (objects, e.g. ``RK4(dt=1e-3)``) on ``model`` and measure each
    against the reference (see the module docstring). A run that diverges is reported with
    status ``diverged`` and infinite errors, not raised.

    ``q0`` defaults to 1 rad (or m) per joint, ``qd0`` to zero; with quaternion joints ``q0``
    has its NQ entries (``CONFIGURATION_NAMES``; default: a free flyer at the origin, identity
    quaternions, 1 rad or m for the other joints).
    """
    system = system or System(model)
    if getattr(system, "quaternion", False):  # q0: NQ values, quaternions at rest by default
        q0, qd0 = quaternion_start(system.model, q0, qd0)
    else:
        q0, qd0 = initial_state(q0, qd0, system.n, system.model.joint_names)
    progress("reference (DOP853, rtol = atol = 1e-12)")
    reference, info = simulate(system, Adaptive("DOP853", REFERENCE_TOLERANCE), q0, qd0, duration)
    reference_seconds = info["seconds"]
    K_ref, P_ref = energies(system, reference)
    E0 = K_ref[0] + P_ref[0]
    scale = max(float(np.max(K_ref)), abs(E0), 1e-300)
    runs = []
    for integrator in integrators:
        progress(f"{integrator.name}, {integrator.label()}")
        try:
            trajectory, info = simulate(system, integrator, q0, qd0, duration)
        except Diverged as exc:
            runs.append(Run(system.model.name, integrator.name, integrator.label(), None,
                            system.evaluations, float("nan"), math.inf, math.inf, math.inf,
                            math.inf, system.max_condition, f"diverged: {exc}"))
            continue
        K, P = energies(system, trajectory)
        drift = float(np.max(np.abs(K + P - E0)))
        error = np.max(np.abs(trajectory.q - reference.q), axis=1)
        setting = integrator.label()
        step = info["step"]
        if step is not None and abs(step - integrator.dt) > 1e-9 * integrator.dt:
            setting += f" (used {step:.3g} s)"
        runs.append(Run(system.model.name, integrator.name, setting, info["step"],
                        info["evaluations"], info["seconds"], drift, drift / scale,
                        float(np.max(error)), float(error[-1]), info["max_condition"]))
        if info["max_condition"] > CONDITION_LIMIT:
            warnings.warn(ill_conditioned_message(info["max_condition"],
                                                  f" during {integrator.name}"),
                          IllConditionedWarning, stacklevel=2)
    joints = getattr(system, "links", system.n)  # a flexible system has n joints and m motors
    return Study(system.model.name, joints, float(duration), tuple(q0.tolist()),
                 tuple(qd0.tolist()),
                 scale, reference_seconds, tuple(runs))


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


# ----------------------------------------------------------------------------------------------
# Output
# ----------------------------------------------------------------------------------------------

def plot(studies: Sequence[Study], path) -> None:
    """Time against energy drift and against trajectory error, one row per robot (PNG)."""
    plt = pyplot()
    fig, axes = plt.subplots(len(studies), 2, figsize=(11, 3.9 * len(studies)), squeeze=False)
    for row, study in zip(axes, studies):
        families = list(dict.fromkeys(r.integrator for r in study.runs))
        for k, family in enumerate(families):
            runs = [r for r in study.runs if r.integrator == family and r.status == "ok"]
            runs.sort(key=lambda r: r.seconds)
            for ax, value in ((row[0], "relative_energy_drift"), (row[1], "trajectory_error")):
                ys = [max(getattr(r, value), 1e-17) for r in runs]
                ax.plot([r.seconds for r in runs], ys, marker="osD^v<>"[k % 7], color=f"C{k}",
                        label=family, lw=1)
        for ax, title in ((row[0], "energy drift max|E − E0| / energy scale"),
                          (row[1], "trajectory error max‖q − q_ref‖∞ [rad]")):
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel("wall time [s]")
            ax.set_title(f"{study.robot}: {title}", fontsize=10)
            ax.grid(True, lw=0.3)
        row[0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def write_outputs(studies: Sequence[Study], outdir, stem: str = "simulate") -> list:
    """``<stem>.md``, ``<stem>.csv`` and ``<stem>.png`` in ``outdir``; returns their paths."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    png = outdir / f"{stem}.png"
    plot(studies, png)
    lines = ["# Simulation: time against energy drift and trajectory error", ""]
    for study in studies:
        lines += [f"## {study.robot}", "", study.describe(), "", study.markdown_table(), ""]
    lines += [f"![time against error]({png.name})", ""]
    md = outdir / f"{stem}.md"
    md.write_text("\n".join(lines), encoding="utf-8")
    rows = [row for study in studies for row in study.csv_rows()]
    csv_path = outdir / f"{stem}.csv"
    csv_path.write_text(csv_text(Study.CSV_HEADERS, rows), encoding="utf-8")
    return [md, csv_path, png]


__all__ = ["System", "ExplicitEuler", "SemiImplicitEuler", "RK4", "ImplicitMidpoint", "Adaptive",
           "Diverged", "Run", "Study", "Trajectory", "simulate", "run_study", "energies",
           "initial_state", "quaternion_start",
           "default_integrators", "integrators_named", "INTEGRATORS", "STIFF", "plot",
           "write_outputs"]
