"""Simulation with contacts held (bilateral): constraint drift with and without Baumgarte.

``eomgen simulate --scene S`` with a scene that has ``contacts`` integrates

    M(q) q̈ + C(q, q̇) q̇ + g(q) = τ + J_c(q)ᵀ F_c,      J_c q̈ + J̇_c q̇ = −γ

at zero torque, ``(q̈, F_c)`` from the KKT system of
:class:`eomgen.numeric.contacts.ContactDynamics` (M and h = C q̇ + g from the derived program,
:func:`~eomgen.numeric.contacts.derived_mass_and_bias`), every contact held still where it is
at ``q0`` (its **anchor**: position ``p*`` and, for a surface contact, orientation ``R*``, from
the frame kinematics at ``q0``). The constraint is imposed on accelerations only, so the
integrator's truncation error lets the contacts drift (the classical index reduction problem);
Baumgarte's ``γ = kd J_c q̇ + kp e`` feeds the error back (``ë + kd ė + kp e = 0``, see
:mod:`eomgen.numeric.contacts` for ``e``).

Each integrator runs twice, **without** Baumgarte (``γ = 0``) and **with** it (the scene's gains
where a contact gives some, else :data:`DEFAULT_GAINS`), and reports, sampled on the output grid:

* **position drift**: ``max_t max_c ‖p_c − p*_c‖`` [m] (and its value at the end);
* **orientation drift** (surface contacts): ``max_t max_c ‖log(R*ᵀ R_c)‖`` [rad];
* **velocity drift**: ``max_t ‖J_c q̇‖∞`` [m/s or rad/s], the contact frames' velocity;
* **energy drift**: ``max_t |E(t) − E(0)|`` [J] with ``E = K + P`` from :mod:`eomgen.numeric`
  (independent of the derived program). With τ = 0 and no Baumgarte the held contacts do no
  work, so E is conserved up to the integrator's error; Baumgarte forces do work while they
  correct an error.

With quaternion joints (a free flyer, ball or planar joints) the state is the configuration
``q`` (NQ entries) and the velocity ``v`` (NV): every fixed-step integrator moves ``q`` along
the joints' exponentials, ``q ⊕ h v`` (:meth:`ContactSystem.integrate`, as
:class:`eomgen.analysis.simulate.System` does; the adaptive ones put their outputs back on the
manifold), and the runs also report the **quaternion norm drift**
``max_t max_j |‖quaternion_j‖ − 1|`` (a planar joint's ``|‖(cos θ, sin θ)‖ − 1|``): round-off,
the check that every configuration stayed on its manifold.

The implicit midpoint rule of :mod:`eomgen.analysis.simulate` works on the unconstrained
canonical form and is not used here. Contacts whose rows are dependent at ``q0`` (a planar
arm's contact cannot be pushed out of its plane: the z row of J_c is zero) are solved by the
damped KKT system with ``ε =`` :data:`DEPENDENT_DAMPING` (its forces along the dependent
directions are zero; the others change by about ε relative).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..model import POINT, Contact, RobotModel
from ..numeric.contacts import ContactDynamics, derived_mass_and_bias
from ..numeric import kinetic_energy, numeric_model, potential_energy
from ..numeric.so3 import so3_log
from ..common.progress import plural
from ..model.configuration import configuration_rate, norm_error
from .report import csv_text, fmt, markdown_table, pyplot
from .routes import numeric_only
from .simulate import (OUTPUT_POINTS, Diverged, ImplicitMidpoint, advance, initial_state,
                       quaternion_start, simulate)

#: ``(kp [1/s²], kd [1/s])`` for contacts whose scene gives no Baumgarte gains: the error
#: equation ``ë + kd ė + kp e = 0`` critically damped at ω = 10 rad/s.
DEFAULT_GAINS = (100.0, 20.0)
#: Damping of the KKT solve when the contact rows are dependent at ``q0``.
DEPENDENT_DAMPING = 1e-12


class ContactSystem:
    """``q̈ = f(q, q̇)`` with ``contacts`` held at their poses at ``q0``, joint torques ``tau``.

    Parameters
    ----------
    model:
        The robot (parameters take their values).
    contacts:
        :class:`~eomgen.model.Contact` s, e.g. a scene report's ``contacts``.
    q0:
        (nq,) the configuration whose contact poses become the anchors (with quaternion joints
        NQ entries, else n).
    baumgarte:
        False: every gain 0. True: each contact's gains, or ``gains`` when given (for every
        contact), or :data:`DEFAULT_GAINS` for a contact without any.
    tau:
        (n,) constant joint torques (default zero).
    mass_and_bias:
        ``(q, qd) -> (M, h)``; default the derived program's. Share one between systems of
        the same model to derive once.

    The attributes ``evaluations``, ``max_condition`` and the methods ``reset`` and
    ``forward_dynamics`` are those the fixed-step integrators of
    :mod:`eomgen.analysis.simulate` use.
    """

    def __init__(self, model: RobotModel, contacts: Sequence[Contact], q0, baumgarte: bool,
                 gains: tuple[float, float] | None = None, tau=None,
                 mass_and_bias: Callable | None = None):
        self.model = numeric_only(model)
        self.n = n = self.model.dof
        #: Entries of the configuration, and whether it holds quaternions (NQ ≠ NV).
        self.nq = self.model.nq
        self.quaternion = self.model.nq > self.model.dof
        q0 = np.asarray(q0, dtype=float)
        self.tau = np.zeros(n) if tau is None else np.asarray(tau, dtype=float)
        held = []
        for c in contacts:
            if not baumgarte:
                kp, kd = 0.0, 0.0
            elif gains is not None:
                kp, kd = gains
            elif c.kp or c.kd:
                kp, kd = c.kp, c.kd
            else:
                kp, kd = DEFAULT_GAINS
            held.append(replace(c, kp=float(kp), kd=float(kd)))
        self.contacts = tuple(held)
        mass_and_bias = mass_and_bias or derived_mass_and_bias(self.model)
        probe = ContactDynamics(self.model, self.contacts, mass_and_bias=mass_and_bias)
        kin = probe._kinematics(q0, np.zeros(n))
        anchors = {c.frame: kin[c.frame]["p"].copy() for c in self.contacts}
        orientations = {c.frame: kin[c.frame]["R"].copy() for c in self.contacts
                        if c.kind != POINT}
        self.cd = ContactDynamics(self.model, self.contacts, anchors, orientations, mass_and_bias)
        self.cd.__dict__["_frames"] = probe._frames  # the same frames: derive them once
        J = self.cd.contact_jacobian(q0)
        sv = np.linalg.svd(J, compute_uv=False) if J.size else np.ones(1)
        self.dependent = len(sv) < self.cd.m or sv.min() <= 1e-10 * sv.max()
        self.damping = DEPENDENT_DAMPING if self.dependent else 0.0
        self._nm = numeric_model(self.model)
        self.evaluations = 0
        self.max_condition = float("nan")

    @property
    def gains(self) -> tuple[tuple[float, float], ...]:
        """``(kp, kd)`` of each contact."""
        return tuple((c.kp, c.kd) for c in self.contacts)

    def reset(self) -> None:
        self.evaluations = 0

    def constrained(self, q, qd) -> tuple[np.ndarray, np.ndarray]:
        """``(q̈, F_c)`` at one state."""
        try:
            return self.cd.constrained_forward_dynamics(q, qd, self.tau, damping=self.damping)
        except np.linalg.LinAlgError as exc:
            raise Diverged(f"the contact KKT system became singular ({exc})") from None

    def forward_dynamics(self, q, qd) -> np.ndarray:
        """``q̈`` holding the contacts."""
        self.evaluations += 1
        return self.constrained(q, qd)[0]

    def configuration_rate(self, q, qd) -> np.ndarray:
        """``q̇`` at velocity ``qd``: ``qd`` itself, or with quaternion joints
        :func:`eomgen.model.configuration.configuration_rate` (module docstring)."""
        return configuration_rate(q, qd, self.model) if self.quaternion else qd

    def integrate(self, q, qd, h: float) -> np.ndarray:
        """``q ⊕ h q̇`` along each joint's manifold
        (:func:`~eomgen.analysis.simulate.advance`): how the integrators step ``q``
        with quaternion joints."""
        return advance(self.model, np.asarray(q, float), np.asarray(qd, float), h)

    def quaternion_norm_error(self, q) -> float:
        """``max_j |‖quaternion_j‖ − 1|`` over the joints with a unit part at ``q`` (0
        without): :func:`eomgen.model.configuration.norm_error`."""
        return norm_error(q, self.model)

    def energy(self, q, qd) -> tuple[float, float]:
        """``(K, P)`` [J] from :mod:`eomgen.numeric`."""
        return kinetic_energy(self._nm, q, qd), potential_energy(self._nm, q)

    def drift(self, q, qd) -> tuple[float, float, float]:
        """``(position [m], orientation [rad], velocity)`` errors of the contacts at one state:
        the largest ``‖p − p*‖``, ``‖log(R*ᵀ R)‖`` (surface contacts; 0 without) and
        ``‖J_c q̇‖∞``."""
        kin = self.cd._kinematics(np.asarray(q, float), np.asarray(qd, float))
        position = orientation = 0.0
        for c in self.contacts:
            f = kin[c.frame]
            position = max(position, float(np.linalg.norm(f["p"] - self.cd.anchors[c.frame])))
            if c.kind != POINT:
                rotation = self.cd.orientations[c.frame].T @ f["R"]
                orientation = max(orientation, float(np.linalg.norm(so3_log(rotation))))
        J = self.cd.contact_jacobian(q)
        velocity = float(np.abs(J @ np.asarray(qd, float)).max()) if J.size else 0.0
        return position, orientation, velocity


@dataclass(frozen=True)
class ContactRun:
    """One integration with contacts held."""

    integrator: str
    setting: str
    baumgarte: str                # "off" or "kp = …, kd = …"
    evaluations: int
    seconds: float
    position_drift: float         # max_t max_c |p - p*| [m]
    final_position_drift: float   # at the end [m]
    orientation_drift: float      # max_t max_c |log(R*^T R)| [rad]
    velocity_drift: float         # max_t |J_c qd|_inf
    energy_drift: float           # max_t |E - E0| [J]
    relative_energy_drift: float
    status: str = "ok"
    quaternion_norm_drift: float = 0.0  # max_t max_j | |quaternion_j| - 1 | (NQ != NV)


@dataclass(frozen=True)
class ContactStudy:
    """The runs of one robot with contacts, and how they were made."""

    robot: str
    dof: int
    contacts: tuple[str, ...]
    duration: float
    q0: tuple[float, ...]
    qd0: tuple[float, ...]
    initial_velocity_error: float
    initial_force: tuple[float, ...]
    dependent: bool
    runs: tuple[ContactRun, ...]
    drift_curves: tuple[tuple[str, np.ndarray, np.ndarray], ...]  # label, times, position drift
    #: True when q holds quaternions: the runs report the quaternion norm drift too.
    quaternion: bool = False

    CSV_HEADERS = ("robot", "integrator", "setting", "baumgarte", "evaluations", "seconds",
                   "position_drift_m", "final_position_drift_m", "orientation_drift_rad",
                   "velocity_drift", "energy_drift_J", "relative_energy_drift", "status")

    @property
    def csv_headers(self) -> tuple[str, ...]:
        """:data:`CSV_HEADERS`, and ``quaternion_norm_drift`` for a quaternion model."""
        return self.CSV_HEADERS + (("quaternion_norm_drift",) if self.quaternion else ())

    def csv_rows(self) -> list[tuple]:
        return [(self.robot, r.integrator, r.setting, r.baumgarte, r.evaluations,
                 f"{r.seconds:.4g}", f"{r.position_drift:.3e}",
                 f"{r.final_position_drift:.3e}", f"{r.orientation_drift:.3e}",
                 f"{r.velocity_drift:.3e}", f"{r.energy_drift:.3e}",
                 f"{r.relative_energy_drift:.3e}", r.status)
                + ((f"{r.quaternion_norm_drift:.3e}",) if self.quaternion else ())
                for r in self.runs]

    def markdown_table(self) -> str:
        extra = ("max |‖quat‖ − 1|",) if self.quaternion else ()
        rows = [(r.integrator, r.setting, r.baumgarte, r.evaluations, f"{r.seconds:.3g}",
                 fmt(r.position_drift), fmt(r.final_position_drift), fmt(r.orientation_drift),
                 fmt(r.velocity_drift), fmt(r.energy_drift), fmt(r.relative_energy_drift))
                + ((fmt(r.quaternion_norm_drift),) if self.quaternion else ()) + (r.status,)
                for r in self.runs]
        return markdown_table(["integrator", "step", "Baumgarte", "evaluations", "time [s]",
                               "max drift p [m]", "drift p(T) [m]", "max drift R [rad]",
                               "max ‖J_c q̇‖", "energy drift [J]", "relative", *extra,
                               "status"], rows, "lllrrrrrrrr" + "r" * len(extra) + "l")

    def describe(self) -> str:
        text = (f"{self.robot} ({plural(self.dof, 'joint')}), contacts held (bilateral) at "
                f"their poses at q0: {', '.join(self.contacts)}; {self.duration:g} s from q0 = "
                f"({', '.join(f'{x:g}' for x in self.q0)}), q̇0 = "
                f"({', '.join(f'{x:g}' for x in self.qd0)}), zero torque; "
                f"‖J_c q̇0‖∞ = {self.initial_velocity_error:.3g}; contact forces at t = 0: "
                f"({', '.join(f'{x + 0.0:.6g}' for x in self.initial_force)}).")
        if self.dependent:
            text += (" The contact rows are dependent (a direction no joint moves a contact "
                     f"in): damped KKT solve, ε = {DEPENDENT_DAMPING:g}.")
        return text


def run_contact_study(model: RobotModel, contacts: Sequence[Contact], integrators: Sequence,
                      duration: float, q0=None, qd0=None, gains=None,
                      progress: Callable[[str], None] = lambda _: None,
                      points: int = OUTPUT_POINTS) -> ContactStudy:
    """Run every integrator without and with Baumgarte on ``model`` holding ``contacts``
    (module docstring). ``q0`` defaults to 1 rad (or m) per joint, ``qd0`` to zero (with
    quaternion joints ``q0`` has NQ entries, identity quaternions by default:
    :func:`~eomgen.analysis.simulate.quaternion_start`); ``gains = (kp, kd)`` overrides every
    contact's Baumgarte gains. A run that diverges is reported with status ``diverged``, not
    raised."""
    model = numeric_only(model)
    n = model.dof
    if model.nq > model.dof:
        q0, qd0 = quaternion_start(model, q0, qd0)
    else:
        q0, qd0 = initial_state(q0, qd0, n, model.joint_names)
    progress(f"deriving M, h and the contact frames of {model.name}")
    mass_and_bias = derived_mass_and_bias(model)
    systems = {on: ContactSystem(model, contacts, q0, on, gains, mass_and_bias=mass_and_bias)
               for on in (False, True)}
    systems[True].cd.__dict__["_frames"] = systems[False].cd._frames
    plain = systems[False]
    _, F0 = plain.constrained(q0, qd0)
    runs, curves = [], []
    for integrator in integrators:
        if isinstance(integrator, ImplicitMidpoint):
            continue
        for on in (False, True):
            system = systems[on]
            label = ("off" if not on else "; ".join(
                dict.fromkeys(f"kp = {kp:g}, kd = {kd:g}" for kp, kd in system.gains)))
            progress(f"{integrator.name}, {integrator.label()}, Baumgarte {label}")
            try:
                trajectory, info = simulate(system, integrator, q0, qd0, duration, points)
                drift = np.array([system.drift(q, v) for q, v in
                                  zip(trajectory.q, trajectory.qd)])
                if not np.all(np.isfinite(drift)):
                    raise Diverged("the contact error is no longer finite")
            except Diverged as exc:
                runs.append(ContactRun(integrator.name, integrator.label(), label,
                                       system.evaluations, float("nan"), math.inf, math.inf,
                                       math.inf, math.inf, math.inf, math.inf,
                                       f"diverged: {exc}"))
                continue
            K, P = zip(*(system.energy(q, v) for q, v in zip(trajectory.q, trajectory.qd)))
            E = np.array(K) + np.array(P)
            energy_drift = float(np.max(np.abs(E - E[0])))
            scale = max(float(np.max(K)), abs(float(E[0])), 1e-300)
            norm = max(system.quaternion_norm_error(q) for q in trajectory.q)
            runs.append(ContactRun(integrator.name, integrator.label(), label,
                                   info["evaluations"], info["seconds"],
                                   float(drift[:, 0].max()), float(drift[-1, 0]),
                                   float(drift[:, 1].max()), float(drift[:, 2].max()),
                                   energy_drift, energy_drift / scale,
                                   quaternion_norm_drift=norm))
            curves.append((f"{integrator.name}, {integrator.label()}, Baumgarte "
                           f"{'on' if on else 'off'}", trajectory.times, drift[:, 0]))
    J0 = plain.cd.contact_jacobian(q0)
    return ContactStudy(model.name, n, tuple(f"{c.name or c.frame} ({c.kind})" for c in contacts),
                        float(duration), tuple(q0.tolist()), tuple(qd0.tolist()),
                        float(np.abs(J0 @ qd0).max()) if J0.size else 0.0,
                        tuple(float(x) for x in F0), plain.dependent, tuple(runs),
                        tuple(curves), plain.quaternion)


def plot_drift(study: ContactStudy, path) -> None:
    """Position drift against time, one line per run (PNG); no wall times, so the bytes
    depend on the trajectories only."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for k, (label, times, drift) in enumerate(study.drift_curves):
        ax.plot(times, np.maximum(drift, 1e-17), color=f"C{k // 2 % 10}",
                ls="-" if label.endswith("off") else "--", lw=1, label=label)
    ax.set_yscale("log")
    ax.set_xlabel("time [s]")
    ax.set_ylabel("max ‖p − p*‖ [m]")
    ax.set_title(f"{study.robot}: contact position drift (solid: no Baumgarte, dashed: with)",
                 fontsize=10)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(path, dpi=90, metadata={"Software": None})
    plt.close(fig)


def write_contact_outputs(study: ContactStudy, outdir, stem: str) -> list:
    """``<stem>.md``, ``<stem>.csv`` and ``<stem>.png`` (drift against time) in ``outdir``."""
    outdir = Path(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    png = outdir / f"{stem}.png"
    plot_drift(study, png)
    md = outdir / f"{stem}.md"
    md.write_text("\n".join(["# Simulation with contacts: constraint drift with and without "
                             "Baumgarte", "", study.describe(), "", study.markdown_table(), "",
                             f"![drift against time]({png.name})", ""]), encoding="utf-8")
    csv_path = outdir / f"{stem}.csv"
    csv_path.write_text(csv_text(study.csv_headers, study.csv_rows()), encoding="utf-8")
    return [md, csv_path, png]


__all__ = ["DEFAULT_GAINS", "DEPENDENT_DAMPING", "ContactSystem", "ContactRun", "ContactStudy",
           "run_contact_study", "plot_drift", "write_contact_outputs"]
