"""Simulation of closed chains: loop drift with and without Baumgarte, energy.

``eomgen simulate --scene S`` with a scene that has ``loops`` integrates

    M(q) q̈ + C(q, q̇) q̇ + g(q) = J_l(q)ᵀ λ,      J_l q̈ + J̇_l q̇ = −γ

at zero torque, ``(q̈, λ)`` from the KKT system of :class:`eomgen.numeric.loops.LoopDynamics`.
The start is made consistent first: ``q0`` closed by Newton on the passive joints
(:meth:`~eomgen.numeric.loops.LoopDynamics.assemble`, the actuated joints held), ``q̇0``
projected onto the null space of ``J_l`` (the nearest velocity that keeps the loops closed).
The loops are held on accelerations only, so the integrator's error lets them open (drift);
Baumgarte's ``γ = kd J_l q̇ + kp Φ`` feeds ``Φ`` back. Each fixed-step integrator (not the
implicit midpoint rule) runs without and with it (``--baumgarte`` or :data:`DEFAULT_GAINS`)
and the report gives, sampled on the output grid: the largest ``|Φ|∞`` (position drift, m or
the sine of an angle), ``|Φ(T)|∞``, the largest ``|J_l q̇|∞`` (velocity drift), and the energy
drift ``max_t |E − E0|`` [J] (E from :mod:`eomgen.numeric`, independent of the derived
program: without Baumgarte the loop forces do no work, so E is conserved up to the
integrator's error). A scene with contacts as well is refused (simulate them apart).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..errors import AnalysisError
from ..model import RobotModel
from ..numeric import kinetic_energy, numeric_model, potential_energy
from ..numeric.loops import LoopDynamics
from ..progress import plural
from .report import csv_text, fmt, markdown_table
from .routes import numeric_only
from .simulate import OUTPUT_POINTS, Diverged, ImplicitMidpoint, initial_state, simulate

#: ``(kp [1/s²], kd [1/s])`` by default: ``Φ̈ + kd Φ̇ + kp Φ = 0`` critically damped at 10 rad/s.
DEFAULT_GAINS = (100.0, 20.0)


class LoopSystem:
    """``q̈ = f(q, q̇)`` of ``model`` holding its loops, zero torque; ``gains`` ``(kp, kd)``
    of the Baumgarte term (``(0, 0)``: none). ``dynamics``: a :class:`LoopDynamics` of the
    same model to share its compiled program. The attributes the integrators of
    :mod:`eomgen.analysis.simulate` use: ``n``, ``evaluations``, ``max_condition``,
    ``reset`` and ``forward_dynamics``."""

    def __init__(self, model: RobotModel, gains=(0.0, 0.0), dynamics: LoopDynamics | None = None):
        self.model = model
        self.n = model.dof
        self.dyn = LoopDynamics(model, tuple(map(float, gains)))
        if dynamics is not None:  # the same program: compile it once
            self.dyn.__dict__["_program"] = dynamics._program
        self.tau = np.zeros(self.n)
        self._nm = numeric_model(model)
        self.evaluations = 0
        self.max_condition = float("nan")

    def reset(self) -> None:
        self.evaluations = 0

    def forward_dynamics(self, q, qd) -> np.ndarray:
        self.evaluations += 1
        try:
            return self.dyn.constrained_forward_dynamics(q, qd, self.tau)[0]
        except np.linalg.LinAlgError as exc:
            raise Diverged(f"the loop KKT system became singular ({exc})") from None

    def energy(self, q, qd) -> float:
        """``K + P`` [J] from :mod:`eomgen.numeric`."""
        return kinetic_energy(self._nm, q, qd) + potential_energy(self._nm, q)

    def drift(self, q, qd) -> tuple[float, float]:
        """``(|Φ|∞, |J_l q̇|∞)`` at one state."""
        e = self.dyn.evaluate(q, qd)
        return float(np.abs(e["Phi_l"]).max()), float(np.abs(e["J_l"] @ qd).max())


@dataclass(frozen=True)
class LoopRun:
    """One integration holding the loops."""

    integrator: str
    setting: str
    baumgarte: str
    evaluations: int
    seconds: float
    drift: float            # max_t |Phi|_inf
    final_drift: float      # |Phi(T)|_inf
    velocity_drift: float   # max_t |J_l qd|_inf
    energy_drift: float     # max_t |E - E0| [J]
    relative_energy_drift: float
    status: str = "ok"


@dataclass(frozen=True)
class LoopStudy:
    """The runs of one closed chain, and its consistent start."""

    robot: str
    dof: int
    loops: tuple[str, ...]
    duration: float
    q0: tuple[float, ...]
    qd0: tuple[float, ...]
    runs: tuple[LoopRun, ...]

    CSV_HEADERS = ("robot", "integrator", "setting", "baumgarte", "evaluations", "seconds",
                   "loop_drift", "final_loop_drift", "velocity_drift", "energy_drift_J",
                   "relative_energy_drift", "status")

    def csv_rows(self) -> list[tuple]:
        return [(self.robot, r.integrator, r.setting, r.baumgarte, r.evaluations,
                 f"{r.seconds:.4g}", f"{r.drift:.3e}", f"{r.final_drift:.3e}",
                 f"{r.velocity_drift:.3e}", f"{r.energy_drift:.3e}",
                 f"{r.relative_energy_drift:.3e}", r.status) for r in self.runs]

    def markdown_table(self) -> str:
        rows = [(r.integrator, r.setting, r.baumgarte, r.evaluations, f"{r.seconds:.3g}",
                 fmt(r.drift), fmt(r.final_drift), fmt(r.velocity_drift), fmt(r.energy_drift),
                 fmt(r.relative_energy_drift), r.status) for r in self.runs]
        return markdown_table(["integrator", "step", "Baumgarte", "evaluations", "time [s]",
                               "max ‖Φ‖∞", "‖Φ(T)‖∞", "max ‖J_l q̇‖∞", "energy drift [J]",
                               "relative", "status"], rows, "lllrrrrrrrl")

    def describe(self) -> str:
        return (f"{self.robot} ({plural(self.dof, 'joint')}), loops held: "
                f"{', '.join(self.loops)}; {self.duration:g} s from the closed q0 = "
                f"({', '.join(f'{x:.6g}' for x in self.q0)}), q̇0 = "
                f"({', '.join(f'{x + 0.0:.6g}' for x in self.qd0)}) (projected on the loops' "
                "null space), zero torque.")


def consistent_start(dyn: LoopDynamics, q0, qd0) -> tuple[np.ndarray, np.ndarray]:
    """``q0`` closed by Newton (actuated joints held) and ``qd0`` projected onto the null
    space of ``J_l(q0)``."""
    q = dyn.assemble(q0)
    J = dyn.loop_jacobian(q)
    qd = np.asarray(qd0, dtype=float)
    if J.size:
        qd = qd - np.linalg.pinv(J) @ (J @ qd)
    return q, qd


def run_loop_study(model: RobotModel, integrators: Sequence, duration: float, q0=None,
                   qd0=None, gains=None, progress: Callable[[str], None] = lambda _: None,
                   points: int = OUTPUT_POINTS) -> LoopStudy:
    """Every fixed-step or adaptive integrator without and with Baumgarte on ``model``'s loops
    (module docstring); a run that diverges is reported with status ``diverged``."""
    model = numeric_only(model)
    if model.contacts:
        raise AnalysisError("simulate: a scene with both contacts and loops is not simulated "
                            "yet; simulate the loops (or the contacts) alone")
    q0, qd0 = initial_state(q0, qd0, model.dof, model.joint_names)
    progress(f"deriving M, h and the loops of {model.name}")
    plain = LoopSystem(model)
    q0, qd0 = consistent_start(plain.dyn, q0, qd0)
    gains = tuple(gains) if gains is not None else DEFAULT_GAINS
    systems = {False: plain, True: LoopSystem(model, gains, plain.dyn)}
    runs = []
    for integrator in integrators:
        if isinstance(integrator, ImplicitMidpoint):
            continue
        for on in (False, True):
            system = systems[on]
            label = f"kp = {gains[0]:g}, kd = {gains[1]:g}" if on else "off"
            progress(f"{integrator.name}, {integrator.label()}, Baumgarte {label}")
            try:
                trajectory, info = simulate(system, integrator, q0, qd0, duration, points)
                drift = np.array([system.drift(q, v) for q, v in
                                  zip(trajectory.q, trajectory.qd)])
                if not np.all(np.isfinite(drift)):
                    raise Diverged("the loop error is no longer finite")
            except Diverged as exc:
                runs.append(LoopRun(integrator.name, integrator.label(), label,
                                    system.evaluations, float("nan"), math.inf, math.inf,
                                    math.inf, math.inf, math.inf, f"diverged: {exc}"))
                continue
            E = np.array([system.energy(q, v) for q, v in zip(trajectory.q, trajectory.qd)])
            K = [kinetic_energy(system._nm, q, v) for q, v in zip(trajectory.q, trajectory.qd)]
            energy_drift = float(np.max(np.abs(E - E[0])))
            scale = max(float(np.max(K)), abs(float(E[0])), 1e-300)
            runs.append(LoopRun(integrator.name, integrator.label(), label, info["evaluations"],
                                info["seconds"], float(drift[:, 0].max()), float(drift[-1, 0]),
                                float(drift[:, 1].max()), energy_drift, energy_drift / scale))
    return LoopStudy(model.name, model.dof,
                     tuple(f"{loop.name} ({loop.kind}, {loop.size} rows)" for loop in model.loops),
                     float(duration), tuple(q0.tolist()), tuple(qd0.tolist()), tuple(runs))


def write_loop_outputs(study: LoopStudy, outdir, stem: str) -> list:
    """``<stem>.md`` and ``<stem>.csv`` in ``outdir``."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    md = outdir / f"{stem}.md"
    md.write_text("\n".join(["# Simulation of a closed chain: loop drift with and without "
                             "Baumgarte", "", study.describe(), "", study.markdown_table(), ""]),
                  encoding="utf-8")
    csv_path = outdir / f"{stem}.csv"
    csv_path.write_text(csv_text(LoopStudy.CSV_HEADERS, study.csv_rows()), encoding="utf-8")
    return [md, csv_path]


__all__ = ["DEFAULT_GAINS", "LoopSystem", "LoopRun", "LoopStudy", "consistent_start",
           "run_loop_study", "write_loop_outputs"]
