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
integrator's error).

With quaternion joints (a free flyer, ball joints: NQ ≠ NV) ``q0`` is the configuration (NQ
values, identity quaternions by default: :func:`~eomgen.analysis.simulate.quaternion_start`),
``q̇0`` the velocity (NV), Newton's closure and every step move ``q`` along the joints'
exponentials (``q ⊕ h v``, :func:`~eomgen.analysis.simulate.advance`), as the simulation without
loops does, so each quaternion stays unit.

With the scene's **contacts** as well (loops and contacts together), the KKT system holds the
contact rows then the loop rows (``CONTACT_ROWS``), every contact held still where it is at the
closed ``q0`` (its anchor, as :mod:`eomgen.analysis.simulate_contacts` does), ``q̇0`` projected
onto the null space of all the rows; with Baumgarte each contact gets ``γ = kd J q̇ + kp e``
(the ``--baumgarte`` gains, else its own, else :data:`DEFAULT_GAINS`; ``e`` as in
:mod:`eomgen.numeric.contacts`). The report adds the contacts' position drift ``max_t max_c
‖p_c − p*_c‖`` [m], orientation drift (surface contacts) [rad] and velocity drift ``max_t ‖J_c
q̇‖∞`` over the contact rows. Rows dependent at ``q0`` (a planar mechanism's point contact: its
out-of-plane row is zero; redundant loops) are solved by the damped KKT system with ``ε =``
:data:`~eomgen.analysis.simulate_contacts.DEPENDENT_DAMPING`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..model import POINT, RobotModel
from ..numeric import kinetic_energy, numeric_model, potential_energy
from ..numeric.contacts import ContactDynamics
from ..numeric.loops import RANK_TOLERANCE, LoopDynamics
from ..numeric.so3 import so3_log
from ..symbolic.frames import derive_frames
from ..common.progress import plural
from ..model.configuration import configuration_rate
from .report import csv_text, fmt, markdown_table
from .routes import numeric_only
from .simulate import (OUTPUT_POINTS, Diverged, ImplicitMidpoint, advance, initial_state,
                       quaternion_start, simulate)
from .simulate_contacts import DEPENDENT_DAMPING

#: ``(kp [1/s²], kd [1/s])`` by default: ``Φ̈ + kd Φ̇ + kp Φ = 0`` critically damped at 10 rad/s.
DEFAULT_GAINS = (100.0, 20.0)


class HeldContacts:
    """The model's contacts held still at their poses at ``q0`` (their anchors), with
    Baumgarte gains: the stabilisation term and the drift of the contact rows.

    ``baumgarte`` False: no stabilisation; True: ``gains`` for every contact when given, else a
    contact's own gains, else :data:`DEFAULT_GAINS`. ``frames``: a
    :func:`~eomgen.symbolic.frames.derive_frames` of the contact frames to share."""

    def __init__(self, model: RobotModel, q0, baumgarte: bool, gains=None, frames=None):
        self.frames = frames or derive_frames(model, sorted({c.frame for c in model.contacts}))
        kin = self.frames.evaluate(np.asarray(q0, dtype=float))
        self.gains = tuple((0.0, 0.0) if not baumgarte else tuple(map(float, gains))
                           if gains is not None else (c.kp, c.kd) if c.kp or c.kd
                           else DEFAULT_GAINS for c in model.contacts)
        self.contacts = model.contacts
        # anchors p* and orientations R* at q0; surface_error gives a surface contact's e
        self.held = ContactDynamics(model, model.contacts,
                                    {c.frame: kin[c.frame]["p"].copy() for c in model.contacts},
                                    {c.frame: kin[c.frame]["R"].copy() for c in model.contacts
                                     if c.kind != POINT})

    @property
    def size(self) -> int:
        """The contact rows (3 per point contact, 6 per surface contact)."""
        return sum(c.size for c in self.contacts)

    def gamma(self, q, qd, J) -> np.ndarray:
        """``γ = kd J q̇ + kp e`` (m_c,) of each contact's rows ``J`` (m_c, n) at ``(q, qd)``."""
        kin = self.frames.evaluate(np.asarray(q, dtype=float))
        out, k = [], 0
        for c, (kp, kd) in zip(self.contacts, self.gains):
            rows = J[k:k + c.size] @ qd
            k += c.size
            if not (kp or kd):
                out.append(np.zeros(c.size))
                continue
            f = kin[c.frame]
            e = (f["p"] - self.held.anchors[c.frame] if c.kind == POINT
                 else self.held.surface_error(c.frame, f))
            out.append(kd * rows + kp * e)
        return np.concatenate(out) if out else np.zeros(0)

    def drift(self, q) -> tuple[float, float]:
        """``(max_c ‖p − p*‖ [m], max_c ‖log(R*ᵀ R)‖ [rad])`` at ``q`` (surface contacts for
        the second; 0 without)."""
        kin = self.frames.evaluate(np.asarray(q, dtype=float))
        position = orientation = 0.0
        for c in self.contacts:
            f = kin[c.frame]
            position = max(position, float(np.linalg.norm(f["p"] - self.held.anchors[c.frame])))
            if c.kind != POINT:
                R = self.held.orientations[c.frame].T @ f["R"]
                orientation = max(orientation, float(np.linalg.norm(so3_log(R))))
        return position, orientation


class LoopSystem:
    """``q̈ = f(q, q̇)`` of ``model`` holding its loops (and its contacts: ``contacts``, a
    :class:`HeldContacts`), zero torque; ``gains`` ``(kp, kd)`` of the loops' Baumgarte term
    (``(0, 0)``: none); ``damping`` ε of the KKT solve (dependent rows). ``dynamics``: a
    :class:`LoopDynamics` of the same model to share its compiled program. The attributes the
    integrators of :mod:`eomgen.analysis.simulate` use: ``n``, ``evaluations``,
    ``max_condition``, ``reset`` and ``forward_dynamics``."""

    def __init__(self, model: RobotModel, gains=(0.0, 0.0), dynamics: LoopDynamics | None = None,
                 contacts: HeldContacts | None = None, damping: float = 0.0):
        self.model = model
        self.n = model.dof
        self.dyn = LoopDynamics(model, tuple(map(float, gains)))
        if dynamics is not None:  # the same program: compile it once
            self.dyn.__dict__["_program"] = dynamics._program
        self.contacts = contacts
        self.damping = damping
        self.tau = np.zeros(self.n)
        #: Whether ``q`` holds quaternions (NQ ≠ NV): the integrators then step it by
        #: :meth:`integrate`.
        self.quaternion = model.nq > model.dof
        self._nm = numeric_model(model)
        self.evaluations = 0
        self.max_condition = float("nan")

    def reset(self) -> None:
        self.evaluations = 0

    def constrained(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """``(q̈, F)`` at one state: F the contact forces then the loop forces."""
        e = self.dyn.evaluate(q, qd)
        gamma = None
        if self.contacts is not None:
            gamma = self.contacts.gamma(q, qd, e["J_c"][:self.contacts.size])
        try:
            return self.dyn.solve(e, qd, self.tau, self.damping, gamma)
        except np.linalg.LinAlgError as exc:
            raise Diverged(f"the loop KKT system became singular ({exc})") from None

    def forward_dynamics(self, q, qd) -> np.ndarray:
        self.evaluations += 1
        return self.constrained(q, qd)[0]

    def configuration_rate(self, q, qd) -> np.ndarray:
        """``q̇`` at velocity ``qd``: ``qd`` itself, or with quaternion joints
        :func:`eomgen.model.configuration.configuration_rate`."""
        return configuration_rate(q, qd, self.model) if self.quaternion else qd

    def integrate(self, q, qd, h: float) -> np.ndarray:
        """``q ⊕ h q̇`` along each joint's manifold (:func:`~eomgen.analysis.simulate.advance`):
        how the integrators step ``q`` with quaternion joints."""
        return advance(self.model, np.asarray(q, float), np.asarray(qd, float), h)

    def energy(self, q, qd) -> float:
        """``K + P`` [J] from :mod:`eomgen.numeric`."""
        return kinetic_energy(self._nm, q, qd) + potential_energy(self._nm, q)

    def drift(self, q, qd) -> tuple[float, ...]:
        """``(|Φ|∞, |J_l q̇|∞)`` at one state, and with contacts ``(contact position [m],
        orientation [rad], |J_c q̇|∞ over the contact rows)``."""
        e = self.dyn.evaluate(q, qd)
        loops = (float(np.abs(e["Phi_l"]).max()), float(np.abs(e["J_l"] @ qd).max()))
        if self.contacts is None:
            return loops
        rows = e["J_c"][:self.contacts.size] @ qd
        return loops + self.contacts.drift(q) + (float(np.abs(rows).max()),)


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
    contact_drift: float = math.nan              # max_t max_c |p - p*| [m]
    contact_orientation_drift: float = math.nan  # max_t max_c |log(R*^T R)| [rad]
    contact_velocity_drift: float = math.nan     # max_t |J_c qd|_inf, contact rows


@dataclass(frozen=True)
class LoopStudy:
    """The runs of one closed chain (with contacts, if any), and its consistent start."""

    robot: str
    dof: int
    loops: tuple[str, ...]
    duration: float
    q0: tuple[float, ...]
    qd0: tuple[float, ...]
    runs: tuple[LoopRun, ...]
    contacts: tuple[str, ...] = ()
    damping: float = 0.0
    initial_force: tuple[float, ...] = ()

    CSV_HEADERS = ("robot", "integrator", "setting", "baumgarte", "evaluations", "seconds",
                   "loop_drift", "final_loop_drift", "velocity_drift", "energy_drift_J",
                   "relative_energy_drift", "status")
    #: Added with contacts.
    CONTACT_HEADERS = ("contact_drift_m", "contact_orientation_drift_rad",
                       "contact_velocity_drift")

    @property
    def headers(self) -> tuple[str, ...]:
        return self.CSV_HEADERS + (self.CONTACT_HEADERS if self.contacts else ())

    def csv_rows(self) -> list[tuple]:
        return [(self.robot, r.integrator, r.setting, r.baumgarte, r.evaluations,
                 f"{r.seconds:.4g}", f"{r.drift:.3e}", f"{r.final_drift:.3e}",
                 f"{r.velocity_drift:.3e}", f"{r.energy_drift:.3e}",
                 f"{r.relative_energy_drift:.3e}", r.status)
                + ((f"{r.contact_drift:.3e}", f"{r.contact_orientation_drift:.3e}",
                    f"{r.contact_velocity_drift:.3e}") if self.contacts else ())
                for r in self.runs]

    def markdown_table(self) -> str:
        contacts = bool(self.contacts)
        rows = [(r.integrator, r.setting, r.baumgarte, r.evaluations, f"{r.seconds:.3g}",
                 fmt(r.drift), fmt(r.final_drift), fmt(r.velocity_drift))
                + ((fmt(r.contact_drift), fmt(r.contact_orientation_drift),
                    fmt(r.contact_velocity_drift)) if contacts else ())
                + (fmt(r.energy_drift), fmt(r.relative_energy_drift), r.status)
                for r in self.runs]
        headers = (["integrator", "step", "Baumgarte", "evaluations", "time [s]", "max ‖Φ‖∞",
                    "‖Φ(T)‖∞", "max ‖J_l q̇‖∞"]
                   + (["max contact drift p [m]", "max drift R [rad]", "max ‖J_c q̇‖∞"]
                      if contacts else [])
                   + ["energy drift [J]", "relative", "status"])
        return markdown_table(headers, rows, "lll" + "r" * (len(headers) - 4) + "l")

    def describe(self) -> str:
        held = f"loops held: {', '.join(self.loops)}"
        if self.contacts:
            held += (f"; contacts held (bilateral) at their poses at q0: "
                     f"{', '.join(self.contacts)}")
        text = (f"{self.robot} ({plural(self.dof, 'joint')}), {held}; {self.duration:g} s "
                f"from the closed q0 = ({', '.join(f'{x:.6g}' for x in self.q0)}), q̇0 = "
                f"({', '.join(f'{x + 0.0:.6g}' for x in self.qd0)}) (projected on the "
                f"{'constraints' if self.contacts else 'loops'}' null space), zero torque.")
        if self.contacts:
            text += (" Forces at t = 0 (CONTACT_ROWS: contacts, then loops): "
                     f"({', '.join(f'{x + 0.0:.6g}' for x in self.initial_force)}).")
        if self.damping:
            why = ("a direction no joint moves a contact or a loop in, or redundant loops"
                   if self.contacts else "a loop row no joint moves, as the out-of-plane rows "
                   "of a spatial loop on a planar mechanism, or redundant loops")
            text += (f" The rows are dependent at q0 ({why}): damped KKT solve, "
                     f"ε = {self.damping:g}.")
        return text


def consistent_start(dyn: LoopDynamics, q0, qd0) -> tuple[np.ndarray, np.ndarray]:
    """``q0`` closed by Newton (actuated joints held) and ``qd0`` projected onto the null
    space of ``J_c(q0)``: the loop rows, and the contact rows when the model has contacts."""
    q = dyn.assemble(q0)
    J = dyn.evaluate(q)["J_c"]
    qd = np.asarray(qd0, dtype=float)
    if J.size:
        qd = qd - np.linalg.pinv(J) @ (J @ qd)
    return q, qd


def dependent(J) -> bool:
    """Whether the rows of ``J`` are dependent (:data:`~eomgen.numeric.loops.RANK_TOLERANCE`)."""
    if not J.size:
        return False
    sv = np.linalg.svd(J, compute_uv=False)
    return len(sv) < J.shape[0] or sv.min() <= RANK_TOLERANCE * sv.max()


def run_loop_study(model: RobotModel, integrators: Sequence, duration: float, q0=None,
                   qd0=None, gains=None, progress: Callable[[str], None] = lambda _: None,
                   points: int = OUTPUT_POINTS) -> LoopStudy:
    """Every fixed-step or adaptive integrator without and with Baumgarte on ``model``'s loops
    and contacts (module docstring); a run that diverges is reported with status
    ``diverged``. ``gains`` ``(kp, kd)``: the Baumgarte gains of every row (default: the
    loops' :data:`DEFAULT_GAINS`, each contact's own)."""
    model = numeric_only(model)
    if model.nq > model.dof:
        q0, qd0 = quaternion_start(model, q0, qd0)
    else:
        q0, qd0 = initial_state(q0, qd0, model.dof, model.joint_names)
    progress(f"deriving M, h and the loops of {model.name}")
    program = LoopDynamics(model)
    q0, qd0 = consistent_start(program, q0, qd0)
    damping = DEPENDENT_DAMPING if dependent(program.evaluate(q0)["J_c"]) else 0.0
    contacts = {False: None, True: None}
    if model.contacts:
        off = HeldContacts(model, q0, False)
        contacts = {False: off, True: HeldContacts(model, q0, True, gains, off.frames)}
    loop_gains = tuple(gains) if gains is not None else DEFAULT_GAINS
    systems = {on: LoopSystem(model, loop_gains if on else (0.0, 0.0), program, contacts[on],
                              damping) for on in (False, True)}
    runs = []
    for integrator in integrators:
        if isinstance(integrator, ImplicitMidpoint):
            continue
        for on in (False, True):
            system = systems[on]
            label = "off" if not on else "; ".join(dict.fromkeys(
                f"kp = {kp:g}, kd = {kd:g}" for kp, kd in
                (loop_gains,) + (contacts[True].gains if model.contacts else ())))
            progress(f"{integrator.name}, {integrator.label()}, Baumgarte {label}")
            try:
                trajectory, info = simulate(system, integrator, q0, qd0, duration, points)
                drift = np.array([system.drift(q, v) for q, v in
                                  zip(trajectory.q, trajectory.qd)])
                if not np.all(np.isfinite(drift)):
                    raise Diverged("the constraint error is no longer finite")
            except Diverged as exc:
                runs.append(LoopRun(integrator.name, integrator.label(), label,
                                    system.evaluations, float("nan"), math.inf, math.inf,
                                    math.inf, math.inf, math.inf, f"diverged: {exc}"))
                continue
            E = np.array([system.energy(q, v) for q, v in zip(trajectory.q, trajectory.qd)])
            K = [kinetic_energy(system._nm, q, v) for q, v in zip(trajectory.q, trajectory.qd)]
            energy_drift = float(np.max(np.abs(E - E[0])))
            scale = max(float(np.max(K)), abs(float(E[0])), 1e-300)
            extra = {}
            if model.contacts:
                extra = dict(contact_drift=float(drift[:, 2].max()),
                             contact_orientation_drift=float(drift[:, 3].max()),
                             contact_velocity_drift=float(drift[:, 4].max()))
            runs.append(LoopRun(integrator.name, integrator.label(), label, info["evaluations"],
                                info["seconds"], float(drift[:, 0].max()), float(drift[-1, 0]),
                                float(drift[:, 1].max()), energy_drift, energy_drift / scale,
                                **extra))
    force = systems[False].constrained(q0, qd0)[1] if model.contacts else ()
    return LoopStudy(model.name, model.dof,
                     tuple(f"{loop.name} ({loop.kind}, {loop.size} rows)" for loop in model.loops),
                     float(duration), tuple(q0.tolist()), tuple(qd0.tolist()), tuple(runs),
                     tuple(f"{c.name or c.frame} ({c.kind})" for c in model.contacts), damping,
                     tuple(float(x) for x in force))


def write_loop_outputs(study: LoopStudy, outdir, stem: str) -> list:
    """``<stem>.md`` and ``<stem>.csv`` in ``outdir``."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    md = outdir / f"{stem}.md"
    md.write_text("\n".join(["# Simulation of a closed chain: constraint drift with and "
                             "without Baumgarte", "", study.describe(), "", study.markdown_table(), ""]),
                  encoding="utf-8")
    csv_path = outdir / f"{stem}.csv"
    csv_path.write_text(csv_text(study.headers, study.csv_rows()), encoding="utf-8")
    return [md, csv_path]


__all__ = ["DEFAULT_GAINS", "HeldContacts", "LoopSystem", "dependent", "LoopRun", "LoopStudy", "consistent_start",
           "run_loop_study", "write_loop_outputs"]
