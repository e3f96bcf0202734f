"""Runs of ``eomgen simulate`` and what they measure: a trajectory on an output grid
(:func:`simulate`), and a study (:func:`run_study`) of every integrator against a reference.

Each run is measured against

* **energy drift**: ``max_t |E(t) − E(0)|`` with ``E = K + P`` from
  :func:`eomgen.numeric.kinetic_energy` and :func:`~eomgen.numeric.potential_energy` (an
  independent computation, not the derived program), in J and relative to the energy scale
  ``max(max_t K_ref(t), |E(0)|)``;
* **trajectory error**: ``max_t ‖q(t) − q_ref(t)‖∞`` [rad or m] against a reference from
  :func:`scipy.integrate.solve_ivp` (DOP853, ``rtol = atol =`` :data:`REFERENCE_TOLERANCE`).

Both are sampled on an output grid of :data:`OUTPUT_POINTS` equally spaced times.
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np

from ...model import RobotModel
from ...common.progress import plural
from ...model.configuration import degenerate, neutral
from ..conditioning import CONDITION_LIMIT, IllConditionedWarning, ill_conditioned_message
from ..report import fmt, markdown_table
from .integrators import Adaptive
from .system import Diverged, System

#: Points of the output grid (both ends included).
OUTPUT_POINTS = 101
#: Tolerances of the reference solution (solve_ivp DOP853).
REFERENCE_TOLERANCE = 1e-12


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
    ValueError
        When ``q0`` holds a quaternion or planar ``(cos, sin)`` pair of zero length
        (:func:`eomgen.model.configuration.degenerate`).
    Diverged
        When the state stops being finite or M stops being positive definite.
    """
    problem = degenerate(q0, system.model)
    if problem is not None:
        raise ValueError(f"q0: {problem}")
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


__all__ = ["OUTPUT_POINTS", "REFERENCE_TOLERANCE", "Run", "Study", "Trajectory", "energies",
           "initial_state", "quaternion_start", "run_study", "simulate"]
