"""Simulation of flexible joints (Spong's reduced model): a stiff system.

``eomgen simulate`` on a description (or scene) whose actuators give a ``stiffness``
integrates the 2(n + m)-dimensional state ``(q, θ, q̇, θ̇)`` of the reduced model
(:mod:`eomgen.analysis.actuators`, docs/actuators.md)::

    M_a(q) q̈ + C(q, q̇) q̇ + g(q) = S_R τ + E K (θ − Eᵀ q)
    B θ̈ + K (θ − Eᵀ q) = Eᵀ τ

with zero input and **no friction** (the actuators' damping and Coulomb friction are left out,
so that the energy is conserved)::

    E = ½ q̇ᵀ M_a q̇ + ½ θ̇ᵀ B θ̇ + P(q) + ½ (θ − Eᵀ q)ᵀ K (θ − Eᵀ q)

computed from :mod:`eomgen.numeric`'s kinetic and potential energy of the links plus the
motors and springs (not from the derived program). The start is at rest at ``q0`` with the
springs wound to hold gravity, ``θ0 = q0_F + K⁻¹ g_F(q0)`` (:func:`flexible_start`); with no
input the motors are not held, so links and motors swing.

:class:`FlexibleSystem` has the interface of :class:`eomgen.analysis.simulate.System` over the
generalised coordinates ``Q = (q, θ)``, so every integrator of that module runs on it,
the implicit midpoint rule included (canonical momenta ``(M_a q̇, B θ̇)``), and the study of
:func:`~eomgen.analysis.simulate.run_study` (energy drift, error against a DOP853 reference at
rtol = 1e-12) applies unchanged. The springs make the system stiff: its highest frequency
``ω_max`` (:meth:`FlexibleSystem.highest_frequency`) bounds the explicit methods' steps (RK4 is
stable for ``ω h ≲ 2.8``, explicit Euler never conserves energy); SciPy's implicit ``Radau``
and ``BDF`` are offered for it.

:func:`step_response` integrates a step in one motor torque from rest and
:func:`plot_step` draws link against motor angle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model import flexible_indices, joint_actuators
from ..model import RobotModel
from .report import pyplot
from .simulate import Adaptive, System


class FlexibleSystem(System):
    """Spong's reduced model of ``model`` (its joints with a ``stiffness``), over
    ``Q = (q, θ)`` (n + m,), q in joint order, θ the motor angles of the flexible joints in
    joint order (link side of the gear), with constant inputs ``tau`` (n,): joint torques of
    rigid joints, motor torques of flexible ones (default zero). Damping and friction are
    left out (module docstring).

    Attributes
    ----------
    links:
        n, the number of joints.
    flexible, rigid:
        Index arrays of the flexible and rigid joints.
    K, B:
        (m,) stiffnesses [N m/rad] and motor inertias [kg m²] of the flexible joints.
    """

    def __init__(self, model: RobotModel, tau=None):
        super().__init__(model)
        actuators = joint_actuators(self.model)
        self.links = nl = self.n
        self.flexible = np.array(flexible_indices(self.model), dtype=int)
        self.rigid = np.array([k for k in range(nl) if k not in set(self.flexible.tolist())],
                              dtype=int)
        armature = np.array([float(a.armature) for a in actuators])
        self.a_links = np.where(np.isin(np.arange(nl), self.flexible), 0.0, armature)
        self.B = armature[self.flexible]
        self.K = np.array([float(actuators[k].stiffness) for k in self.flexible])
        self.n = nl + len(self.flexible)
        self.tau = np.zeros(nl) if tau is None else np.asarray(tau, dtype=float)

    def _links_M(self, q) -> list:
        M = list(self._M(*q.tolist())[0])
        nl = self.links
        for k in range(nl):
            M[k * nl + k] += self.a_links[k]
        return M

    def _spring(self, Q) -> np.ndarray:
        return self.K * (Q[self.links:] - Q[self.flexible])

    def _link_input(self, spring) -> np.ndarray:
        u = np.zeros(self.links)
        u[self.rigid] = self.tau[self.rigid]
        u[self.flexible] = spring
        return u

    def forward_dynamics(self, Q, Qd) -> np.ndarray:
        """``(q̈, θ̈)`` (n + m,)."""
        self.evaluations += 1
        nl = self.links
        q, qd = Q[:nl], Qd[:nl]
        spring = self._spring(Q)
        bias = self._bias(*q.tolist(), *qd.tolist())[0]
        qdd = self._solve(self._links_M(q), (self._link_input(spring) - bias).tolist())
        thdd = (self.tau[self.flexible] - spring) / self.B
        return np.concatenate([qdd, thdd])

    def M(self, Q) -> np.ndarray:
        """``diag(M_a(q), B)`` (n + m, n + m)."""
        nl = self.links
        M = np.zeros((self.n, self.n))
        M[:nl, :nl] = np.reshape(self._links_M(Q[:nl]), (nl, nl))
        M[nl:, nl:] = np.diag(self.B)
        return M

    def velocity(self, Q, P) -> np.ndarray:
        nl = self.links
        return np.concatenate([self._solve(self._links_M(Q[:nl]), P[:nl].tolist()),
                               P[nl:] / self.B])

    def velocity_and_momentum_rate(self, Q, P):
        """``(Q̇, Ṗ)``: ``ṗ_q = Cᵀ q̇ − g + S_R τ + E K (θ − Eᵀ q)``, ``ṗ_θ = −K (θ − Eᵀ q) + Eᵀ τ``."""
        self.evaluations += 1
        nl = self.links
        Qd = self.velocity(Q, P)
        C, g = self._Cg(*Q[:nl].tolist(), *Qd[:nl].tolist())
        v = Qd[:nl].tolist()
        spring = self._spring(Q)
        pq = [sum(C[i * nl + k] * v[i] for i in range(nl)) - g[k] for k in range(nl)]
        return Qd, np.concatenate([np.array(pq) + self._link_input(spring),
                                   self.tau[self.flexible] - spring])

    def energy(self, Q, Qd) -> tuple[float, float]:
        """``(kinetic, potential)`` [J]: links (:mod:`eomgen.numeric`) with the rigid joints'
        armature and the motors; gravity and springs."""
        kinetic, potential = super().energy(Q[:self.links], Qd[:self.links])
        kinetic += 0.5 * float(self.a_links @ Qd[:self.links] ** 2) \
            + 0.5 * float(self.B @ Qd[self.links:] ** 2)
        e = Q[self.links:] - Q[self.flexible]
        return kinetic, potential + 0.5 * float(self.K @ e ** 2)

    def gravity(self, q) -> np.ndarray:
        """``g(q)`` (n,) of the links."""
        q = np.asarray(q, float)
        return np.asarray(self._bias(*q.tolist(), *([0.0] * self.links))[0])

    def highest_frequency(self, q) -> float:
        """``max_j sqrt(K_j (1/B_j + 1/M_a,jj(q)))`` [rad/s]: the frequency of joint j's spring
        between its motor and its link alone, an estimate of the system's stiffest mode."""
        M = np.reshape(self._links_M(np.asarray(q, float)), (self.links, self.links))
        d = np.diag(M)[self.flexible]
        return float(np.max(np.sqrt(self.K * (1 / self.B + 1 / d)))) if len(d) else 0.0


def flexible_start(system: FlexibleSystem, q0) -> np.ndarray:
    """``Q0 = (q0, θ0)`` at rest with the springs wound to hold gravity:
    ``θ0 = q0_F + K⁻¹ g_F(q0)``."""
    q0 = np.asarray(q0, float)
    g = system.gravity(q0)
    return np.concatenate([q0, q0[system.flexible] + g[system.flexible] / system.K])


@dataclass(frozen=True)
class StepResponse:
    """Link and motor angle of joint ``joint`` after a step of ``size`` in its motor torque."""

    robot: str
    joint: str
    size: float
    stiffness: float
    motor_inertia: float
    times: np.ndarray
    link: np.ndarray    # q_j(t) [rad]
    motor: np.ndarray   # θ_j(t) [rad]


def step_response(model: RobotModel, q0, size: float, duration: float, joint: int | None = None,
                  points: int = 401, rtol: float = 1e-10) -> StepResponse:
    """Start at rest at ``q0`` held by ``τ = g(q0)`` (springs wound for gravity), add ``size``
    [N m] to the motor torque of flexible joint ``joint`` (index into the joints; default the
    first flexible one) at t = 0 and integrate ``duration`` seconds (DOP853 at ``rtol``)."""
    probe = FlexibleSystem(model)
    if not len(probe.flexible):
        raise ValueError(f"{probe.model.name} has no flexible joint")
    joint = int(probe.flexible[0]) if joint is None else int(joint)
    Q0 = flexible_start(probe, q0)
    tau = probe.gravity(q0)
    tau[joint] += size
    system = FlexibleSystem(model, tau)
    times = np.linspace(0.0, float(duration), points)
    states, _ = Adaptive("DOP853", rtol).run(system, Q0, np.zeros(system.n), times)
    col = int(np.flatnonzero(system.flexible == joint)[0])
    return StepResponse(system.model.name, system.model.joint_names[joint], float(size),
                        float(system.K[col]), float(system.B[col]), times,
                        np.array([s[0][joint] for s in states]),
                        np.array([s[0][system.links + col] for s in states]))


def plot_step(response: StepResponse, path) -> None:
    """Link and motor angle against time, and their difference (the spring's deflection), as a
    PNG whose bytes depend on the data only (no software stamp)."""
    plt = pyplot()
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7, 5), sharex=True)
    top.plot(response.times, response.motor, color="C1", lw=1.2, label="motor θ")
    top.plot(response.times, response.link, color="C0", lw=1.2, label="link q")
    top.set_ylabel("angle [rad]")
    top.legend(fontsize=8)
    top.set_title(f"{response.robot}: step of {response.size:g} N m in the motor torque of "
                  f"{response.joint} (K = {response.stiffness:g} N m/rad, "
                  f"B = {response.motor_inertia:g} kg m²)", fontsize=9)
    bottom.plot(response.times, response.motor - response.link, color="C2", lw=1)
    bottom.set_ylabel("θ − q [rad]")
    bottom.set_xlabel("time [s]")
    for ax in (top, bottom):
        ax.grid(True, lw=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=90, metadata={"Software": None})
    plt.close(fig)


def describe_stiffness(system: FlexibleSystem, q0) -> str:
    """One sentence: the flexible joints, ω_max and the RK4 stability bound it implies."""
    omega = system.highest_frequency(q0)
    names = [system.model.joint_names[k] for k in system.flexible]
    return (f"Flexible joints (Spong's reduced model, no friction, zero input; started at rest "
            f"with the springs wound for gravity): {', '.join(names)}; highest joint frequency "
            f"ω_max ≈ {omega:.4g} rad/s, so explicit RK4 needs dt ≲ 2.8/ω_max = "
            f"{2.8 / omega if omega else math.inf:.3g} s; the state is (q, θ), errors are over "
            "both.")


__all__ = ["FlexibleSystem", "flexible_start", "StepResponse", "step_response", "plot_step",
           "describe_stiffness"]
