"""Excitation trajectories: a finite Fourier series per joint (:class:`FourierTrajectory`,
Swevers et al. 1997) whose coefficients minimise the condition number of the base regressor
within motion bounds (:func:`excitation_trajectory`, :func:`motion_bounds`), and measurements
simulated along it (:func:`simulate_measurements`).

A model with quaternion joints (a free flyer, ball joints) is excited through a chart: the
series gives NV chart coordinates (a quaternion joint's three angles, and the free flyer's
position), mapped to q (NQ), v and v̇ by :func:`eomgen.identification.charts.chart_states`;
the bounds then apply to those coordinates (angles [rad], position [m])."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Iterable, Mapping, Sequence

import numpy as np

from ..errors import IdentificationError, one_line
from ..model import joint_actuators
from ..numeric import numeric_model, rnea
from ..regressor.derive import by_symbol, derive_regressor
from ..regressor.generated import DECLARED_TERMS, declared_actuator_terms, description_values
from ..regressor.least_squares import normalised_condition
from .charts import trajectory_states
from .measurements import Measurements


@dataclass(frozen=True)
class FourierTrajectory:
    """A finite Fourier series per joint (Swevers et al. 1997), period T = 2π / ω_f::

        q_j(t) = q0_j + Σ_{l=1..L} [ a_jl / (ω_f l) sin(ω_f l t) − b_jl / (ω_f l) cos(ω_f l t) ]

    so that q̇_j = Σ a_jl cos(ω_f l t) + b_jl sin(ω_f l t) and the motion is periodic (every
    period starts in the same state; averaging periods reduces noise).

    Attributes
    ----------
    q0 : (n,) array [rad or m]
    a, b : (n, L) arrays [rad/s or m/s]
    omega : float
        Fundamental angular frequency ω_f [rad/s].
    """

    q0: np.ndarray
    a: np.ndarray
    b: np.ndarray
    omega: float

    def states(self, t) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(q, qd, qdd) at the times ``t`` (N,), each (N, n)."""
        t = np.asarray(t, dtype=float)[:, None, None]
        L = self.a.shape[1]
        w = self.omega * np.arange(1, L + 1)  # (L,)
        s, c = np.sin(w * t), np.cos(w * t)  # (N, 1, L)
        a, b = self.a[None], self.b[None]
        q = self.q0 + np.sum(a / w * s - b / w * c, axis=2)
        qd = np.sum(a * c + b * s, axis=2)
        qdd = np.sum(-a * w * s + b * w * c, axis=2)
        return q, qd, qdd

    def bound(self) -> np.ndarray:
        """The largest possible |q_j(t)| per joint, |q0_j| + Σ_l (|a_jl| + |b_jl|) / (ω_f l)."""
        return np.abs(self.q0) + self._sums(-1)

    def velocity_bound(self) -> np.ndarray:
        """The largest possible |q̇_j(t)| per joint, Σ_l (|a_jl| + |b_jl|)."""
        return self._sums(0)

    def acceleration_bound(self) -> np.ndarray:
        """The largest possible |q̈_j(t)| per joint, Σ_l (|a_jl| + |b_jl|) ω_f l."""
        return self._sums(1)

    def _sums(self, power: int) -> np.ndarray:
        w = self.omega * np.arange(1, self.a.shape[1] + 1)
        return np.sum((np.abs(self.a) + np.abs(self.b)) * w ** power, axis=1)


@dataclass(frozen=True)
class MotionBounds:
    """What an excitation trajectory must respect, per joint (JOINT_NAMES order).

    Attributes
    ----------
    lower, upper : (n,) arrays
        Position range [rad or m]: lower ≤ q_j(t) ≤ upper.
    velocity, acceleration : (n,) arrays
        |q̇_j(t)| ≤ velocity [rad/s or m/s], |q̈_j(t)| ≤ acceleration [rad/s² or m/s²];
        ``inf`` for no bound.
    """

    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


def motion_bounds(joint_names: Sequence[str], amplitude: float = 1.0,
                  limits: Mapping | None = None, max_velocity: float | None = None,
                  max_acceleration: float | None = None, source: str = "<description>"
                  ) -> MotionBounds:
    """The bounds of :func:`excitation_trajectory` for each joint: the tighter of the options
    and the description's limits.

    Positions: within ±``amplitude`` and within the joint's ``lower``/``upper`` limits when
    given. Velocities: ``max_velocity`` and the joint's ``velocity`` limit. Accelerations:
    ``max_acceleration`` (descriptions have none).

    Parameters
    ----------
    joint_names:
        JOINT_NAMES (after any scene).
    limits:
        Joint name → an object with ``lower``, ``upper``, ``velocity`` attributes (None for
        absent), e.g. :func:`eomgen.parsers.urdf.joint_limits`; joints not in it unbounded.
    source:
        The description, named in errors.

    Raises
    ------
    IdentificationError
        When a joint has no room to move: an empty or zero-width position range (its limits
        outside ±amplitude, or lower ≥ upper), or a velocity or acceleration bound that is not
        positive.
    """
    n = len(joint_names)
    for name, value in (("--amplitude", amplitude), ("--max-velocity", max_velocity),
                        ("--max-acceleration", max_acceleration)):
        if value is not None and not (value > 0):
            raise IdentificationError(f"{name} must be positive, got {value}")
    lower, upper = np.full(n, -float(amplitude)), np.full(n, float(amplitude))
    inf = math.inf
    velocity = np.full(n, inf if max_velocity is None else float(max_velocity))
    acceleration = np.full(n, inf if max_acceleration is None else float(max_acceleration))
    for j, name in enumerate(joint_names):
        limit = (limits or {}).get(name)
        if limit is None:
            continue
        if limit.lower is not None:
            lower[j] = max(lower[j], limit.lower)
        if limit.upper is not None:
            upper[j] = min(upper[j], limit.upper)
        if limit.velocity is not None:
            if not limit.velocity > 0:
                raise IdentificationError(f"{source}: joint '{name}': velocity limit "
                                          f"{limit.velocity:g} leaves no motion to excite")
            velocity[j] = min(velocity[j], limit.velocity)
        if not upper[j] > lower[j]:
            raise IdentificationError(one_line(
                f"{source}: joint '{name}': its limits [{_g(limit.lower)}, {_g(limit.upper)}] "
                f"and ±--amplitude {amplitude:g} leave no room to move (raise --amplitude)"))
    return MotionBounds(lower, upper, velocity, acceleration)


def _g(value: float | None) -> str:
    return "none" if value is None else f"{value:g}"


@dataclass(frozen=True)
class Excitation:
    """The result of :func:`excitation_trajectory`: the trajectory and the condition number of
    the column-normalised base regressor over the optimisation samples before and after."""

    trajectory: FourierTrajectory
    initial_condition: float
    condition: float
    evaluations: int


#: The optimiser's iterations at most (:func:`excitation_trajectory`'s ``maxiter``).
EXCITATION_ITERATIONS = 30


def excitation_trajectory(reg, base, period: float = 10.0, harmonics: int = 3,
                          amplitude: float = 1.0, samples: int | None = None, seed: int = 0,
                          maxiter: int = EXCITATION_ITERATIONS, values: Mapping | None = None,
                          bounds: MotionBounds | None = None,
                          progress: Callable[[str], None] = lambda _: None) -> Excitation:
    """Fourier coefficients minimising cond(W_base) (Swevers et al. 1997) within bounds on
    q, q̇ and q̈.

    Variables: q0 and the coefficients a, b of :class:`FourierTrajectory` (n (2 L + 1) of
    them), in boxes that guarantee every bound at every t, not only at samples. With joint j's
    position range [lo, hi] (mid-point m, half-width h), velocity bound V and acceleration
    bound A (``bounds``; default |q_j| ≤ ``amplitude``, no V or A)::

        |q0_j − m| ≤ h / 2,   |a_jl|, |b_jl| ≤ min(h ω_f l / (4 L), V / (2 L), A / (2 L ω_f l))

    so that Σ_l (|a_jl| + |b_jl|) / (ω_f l) ≤ h / 2 (q within [lo, hi]), Σ_l (|a_jl| + |b_jl|)
    ≤ V and Σ_l (|a_jl| + |b_jl|) ω_f l ≤ A (:meth:`FourierTrajectory.bound` and its
    siblings); the boxes are shrunk by 1e-9 so that rounding cannot reach a bound. The boxes
    split each bound evenly between the harmonics, so after the optimisation each joint's
    a, b are scaled up until the tightest of those sums reaches its bound, kept if that does
    not raise the condition number. Objective:
    log10 of the condition number of the column-normalised base regressor stacked at
    ``samples`` evenly spaced times of one period (default 3 b / n + 10). Start: uniform random
    inside the boxes from ``seed``; minimiser: ``scipy.optimize.minimize(method="L-BFGS-B")``
    with finite-difference gradients, at most ``maxiter`` iterations. Deterministic for a given
    seed.

    Parameters
    ----------
    reg, base:
        The regressor and its base parameters (:func:`eomgen.regressor.base_parameters`).
    period:
        T [s]; ω_f = 2π / T.
    harmonics:
        L, the number of harmonics per joint.
    amplitude:
        Bound on |q_j(t)| [rad or m] when ``bounds`` is None.
    bounds:
        Position ranges and velocity and acceleration bounds (:func:`motion_bounds`).
    progress:
        Called after each iteration of the optimiser with ``"cond c, e
        evaluations"`` (c the best condition number so far); the optimisation takes seconds to
        a minute.
    """
    from scipy.optimize import minimize  # an optional dependency (eomgen[identify])

    n, L, b = reg.n, int(harmonics), len(base.base)
    if n == 0:
        raise IdentificationError(f"{reg.model.source}: no movable joint to excite")
    if bounds is None:
        bounds = motion_bounds(reg.model.joint_names, amplitude, source=reg.model.source)
    omega = 2 * math.pi / period
    samples = samples or 3 * b // max(n, 1) + 10
    t = np.arange(samples) * (period / samples)
    f = reg.compiled(values, program=reg.base_program(list(base.base)))
    ws = omega * np.arange(1, L + 1)
    shrink = 1 - 1e-9
    mid = (bounds.lower + bounds.upper) / 2
    half = (bounds.upper - bounds.lower) / 2
    coef = shrink * np.minimum.reduce([
        half[:, None] * ws[None, :] / (4 * L),
        np.broadcast_to(bounds.velocity[:, None] / (2 * L), (n, L)),
        bounds.acceleration[:, None] / (2 * L * ws[None, :])])
    low = np.concatenate([mid - shrink * half / 2, -coef.ravel(), -coef.ravel()])
    high = np.concatenate([mid + shrink * half / 2, coef.ravel(), coef.ravel()])

    def unpack(x):
        x = np.clip(x, low, high)
        return FourierTrajectory(x[:n], x[n:n + n * L].reshape(n, L),
                                 x[n + n * L:].reshape(n, L), omega)

    count, lowest = [0], [300.0]

    def condition(trajectory):
        count[0] += 1
        q, qd, qdd = trajectory_states(reg.model, trajectory, t)
        W = np.vstack([f(*row)["Y_base"] for row in zip(q, qd, qdd)])
        c = normalised_condition(W)
        value = math.log10(c) if math.isfinite(c) and c < 1e300 else 300.0
        lowest[0] = min(lowest[0], value)
        return value

    def iterated(_x):
        progress(f"cond {10 ** lowest[0]:.4g}, {count[0]} evaluations")

    def objective(x):
        return condition(unpack(x))

    def stretched(trajectory):
        # each joint's oscillation scaled up until its tightest bound is reached (by the same
        # sums that bound it): the boxes split each bound evenly between the harmonics, so
        # the optimum usually leaves room
        tr = trajectory
        room = shrink * half - np.abs(tr.q0 - mid)
        with np.errstate(divide="ignore", invalid="ignore"):
            scale = np.nanmin([room / tr._sums(-1), shrink * bounds.velocity / tr._sums(0),
                               shrink * bounds.acceleration / tr._sums(1)], axis=0)
        scale = np.where(np.isfinite(scale), np.maximum(scale, 1.0), 1.0)[:, None]
        return FourierTrajectory(tr.q0, tr.a * scale, tr.b * scale, omega)

    rng = np.random.default_rng(seed)
    x0 = rng.uniform(low, high)
    initial = 10 ** objective(x0)
    result = minimize(objective, x0, method="L-BFGS-B", bounds=list(zip(low, high)),
                      options={"maxiter": int(maxiter)}, callback=iterated)
    best = unpack(result.x if result.fun <= math.log10(initial) else x0)
    value = condition(best)
    wider = stretched(best)
    wider_value = condition(wider)
    if wider_value <= value:
        best, value = wider, wider_value
    return Excitation(best, initial, 10 ** value, count[0])


def simulate_measurements(model, trajectory: FourierTrajectory, t, noise: float = 0.0,
                          seed: int = 0, values: Mapping | None = None,
                          actuators: Iterable[str] = tuple(DECLARED_TERMS)) -> Measurements:
    """Efforts along ``trajectory`` at times ``t``: eomgen.numeric's recursive Newton–Euler
    (:func:`eomgen.numeric.rnea`) plus the drive terms the joints' actuators declare, plus
    Gaussian noise of standard deviation ``noise`` times each joint's RMS effort
    (``noise=0.01``: 1 %), drawn from ``seed``.

    A model with quaternion joints moves along the chart of :mod:`~eomgen.identification.
    charts` (q with NQ entries, v and v̇ NV) and its efforts are its regressor's ``Y(q, v, v̇)
    π`` with the description's π (drives included; the float recursions of eomgen.numeric
    take one coordinate per joint), which the tests check against Pinocchio's ``rnea``.

    The drive terms are those of the regressor's actuator columns, for the terms in
    ``actuators`` (default all of :data:`~eomgen.regressor.DECLARED_TERMS`)::

        τ_k += I_a q̈_k  ("armature")  + f_v q̇_k  ("viscous", URDF damping)
               + f_c sign q̇_k  ("coulomb", URDF friction)

    Coulomb friction is the regressor's sign(q̇), not the tanh smoothing of forward simulation.

    Raises
    ------
    IdentificationError
        For a flexible joint (a stiffness): its motor has an equation of its own.
    """
    t = np.asarray(t, dtype=float)
    q, qd, qdd = trajectory_states(model, trajectory, t)
    if model.nq > model.dof:  # a chart: the regressor walks it
        tau = _regressor_efforts(model, values, tuple(actuators), q, qd, qdd)
    else:
        nm = numeric_model(model, values)
        tau = np.array([rnea(nm, *s) for s in zip(q, qd, qdd)]).reshape(len(t), model.dof)
        tau = tau + _drive_efforts(model, values, tuple(actuators), qd, qdd)
    if noise:
        rms = np.sqrt(np.mean(tau ** 2, axis=0))
        tau = tau + np.random.default_rng(seed).standard_normal(tau.shape) * (noise * rms)
    return Measurements(tuple(model.joint_names), t, q, qd, qdd, tau, False, "<simulated>",
                        configuration_names=model.configuration_names)


def _regressor_efforts(model, values, terms, q, qd, qdd) -> np.ndarray:
    """``Y(q, v, v̇) π`` (N, NV) of the description's π, with the actuator columns of
    ``terms`` that some joint declares (a flexible joint refused as by :func:`_drive_efforts`)."""
    _drive_efforts(model, values, (), qd, qdd)  # refuses a flexible joint
    declared = declared_actuator_terms(model)
    reg = derive_regressor(model, tuple(term for term in DECLARED_TERMS
                                        if term in terms and term in declared))
    pi = description_values(reg, values)
    f = reg.compiled(values)
    return np.array([f(*s)["Y"] @ pi for s in zip(q, qd, qdd)]).reshape(len(q), model.dof)


def _drive_efforts(model, values, terms, qd, qdd) -> np.ndarray:
    """Σ over ``terms`` of the actuators' armature q̈, damping q̇, friction sign q̇, (N, n)."""
    unknown = [term for term in terms if term not in DECLARED_TERMS]
    if unknown:
        raise ValueError(f"actuator terms must be ones of {tuple(DECLARED_TERMS)}, got {unknown}")
    out = np.zeros_like(qd)
    if not any(j.actuator is not None for j in model.movable_joints):
        return out
    numbers = model.with_numeric_parameters(by_symbol(values))
    actuators = joint_actuators(numbers)
    for joint, actuator in zip(numbers.movable_joints, actuators):
        if actuator.flexible:
            raise IdentificationError(one_line(
                f"{model.source}: joint '{joint.name}' is flexible (its actuator has a "
                "stiffness): its motor has an equation of its own, which the rigid-body "
                "regressor does not describe"))
    signals = {"armature": qdd, "viscous": qd, "coulomb": np.sign(qd)}
    for term in terms:
        coefficients = np.array([float(getattr(a, DECLARED_TERMS[term])) for a in actuators])
        out = out + coefficients * signals[term]
    return out
