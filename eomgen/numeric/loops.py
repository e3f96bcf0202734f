"""Closed kinematic chains, numerically: ``M q̈ + C q̇ + g = τ + J_cᵀ F_c`` with the loops'
rows in ``J_c`` (after the contacts'), closure by Newton, parallel inverse dynamics.

:class:`LoopDynamics` evaluates the derived program of a model carrying loops (a scene's
``loops:``, :mod:`eomgen.symbolic.loops` for the rows, axes and signs):

* ``loop_constraint(q)`` ``Φ`` (m_l,), ``loop_jacobian(q)`` ``J_l`` (m_l×n), ``loop_bias(q,
  qd)`` ``J̇_l q̇`` (m_l,);
* ``constrained_forward_dynamics(q, qd, tau)`` → ``(q̈, F)``: the KKT system
  ``[[M, −Jᵀ], [J, 0]] [q̈; F] = [τ − h; −J̇ q̇ − γ]`` over the contact rows then the loop rows
  (``CONTACT_ROWS``), ``γ = kd J_l q̇ + kp Φ`` on the loop rows when Baumgarte gains are given;
  ``damping = ε > 0`` the damped solution (redundant loops, as a planar loop declared spatial);
* ``parallel_inverse_dynamics(q, qd, qdd)`` → ``(τ_a, λ)``: the efforts of the actuated joints
  ``S`` (the scene's ``actuated:``) and the loop forces with ``M q̈ + h = Sᵀ τ_a + J_lᵀ λ``
  (passive joints carry no effort); the square system when ``n_a + m_l = n`` (LU), else least
  squares, whose residual must vanish (a q̈ consistent with the loops);
* ``assemble(q)``: the loops closed by Newton's method on ``Φ`` over the passive coordinates
  (the actuated ones held), :class:`AssemblyError` when it does not converge.

Sizes: ``q`` is the configuration (NQ, ``CONFIGURATION_NAMES``), ``q̇``, ``q̈``, ``τ`` and the
columns of ``J_l`` the velocity coordinates (n = NV, ``JOINT_NAMES``). With quaternion joints (a
free flyer, ball joints: NQ ≠ NV) ``J_l`` is in ``v`` and ``J̇_l q̇`` is ``J̇_l v``, as the
contact rows (:mod:`eomgen.symbolic.frames`), and Newton's steps move ``q`` along the joints'
exponentials (:func:`eomgen.model.configuration.integrate`), so its quaternions stay unit.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..dynamics import derive
from ..errors import AnalysisError
from ..model import RobotModel
from ..model.bodies import frame_site
from ..model.configuration import integrate
from ..symbolic.evaluate import compile_program
from .pinocchio import pinocchio_name

#: The unconstrained KKT solve refuses rows whose smallest singular value is below this
#: fraction of the largest (dependent rows: use damping, or a planar loop).
RANK_TOLERANCE = 1e-10


class AssemblyError(AnalysisError):
    """The loops cannot be closed from the given coordinates (out of reach, or a singular
    configuration): :meth:`LoopDynamics.assemble` did not converge."""


def kkt_solve(M, h, tau, J, bias, damping: float = 0.0, what: str = "constraint"):
    """``(q̈, F)`` of ``M q̈ + h = τ + Jᵀ F``, ``J q̈ + bias = 0``: the KKT system by LU
    (``damping = 0``, refusing dependent rows) or ``F = −(J M⁻¹ Jᵀ + ε 1)⁻¹ (bias + J M⁻¹
    (τ − h))``."""
    n, m = len(h), len(bias)
    if damping > 0:
        Minv_J = np.linalg.solve(M, J.T)
        free = np.linalg.solve(M, tau - h)
        F = -np.linalg.solve(J @ Minv_J + damping * np.eye(m), bias + J @ free)
        return free + Minv_J @ F, F
    if m:
        sv = np.linalg.svd(J, compute_uv=False)
        if len(sv) < m or sv.min() <= RANK_TOLERANCE * sv.max():
            raise np.linalg.LinAlgError(
                f"the {what} Jacobian ({m}×{n}) has dependent rows (smallest singular value "
                f"{sv.min():.3g}): the forces are not unique; use damping > 0 (or a planar loop)")
    K = np.block([[M, -J.T], [J, np.zeros((m, m))]])
    x = np.linalg.solve(K, np.concatenate([tau - h, -bias]))
    return x[:n], x[n:]


@dataclass(frozen=True)
class LoopDynamics:
    """The dynamics of ``model`` (with loops, and contacts if any) at given states.

    Attributes
    ----------
    model:
        A model carrying loops (:func:`eomgen.reduction.apply_scene` with a scene's
        ``loops:``); parameters take their default values.
    baumgarte:
        ``(kp [1/s²], kd [1/s])`` of the loop rows' stabilisation in
        :meth:`constrained_forward_dynamics` (``Φ̈ + kd Φ̇ + kp Φ = 0``); ``(0, 0)``: none.
    """

    model: RobotModel
    baumgarte: tuple[float, float] = (0.0, 0.0)

    @cached_property
    def _program(self):
        outputs = ("M", "h", "Phi_l", "J_l", "dJqd_l", "J_c", "dJqd_c")
        dyn = derive(self.model, outputs=outputs)
        params = tuple(p.symbol for p in self.model.parameters)
        values = tuple(float(self.model.parameter_values[s]) for s in params)
        f = compile_program(dyn.program, dyn.q + dyn.qd + params)
        nq = self.model.nq
        return lambda q, qd: f(*map(float, np.reshape(q, nq)), *map(float, qd), *values)

    def evaluate(self, q, qd=None) -> dict[str, np.ndarray]:
        """``{"M", "h", "Phi_l", "J_l", "dJqd_l", "J_c", "dJqd_c"}`` at one state (``qd``
        default zero); vectors flat."""
        qd = np.zeros(self.model.dof) if qd is None else np.asarray(qd, dtype=float)
        out = dict(self._program(q, qd))
        for key in ("h", "Phi_l", "dJqd_l", "dJqd_c"):
            out[key] = np.asarray(out[key], dtype=float).reshape(-1)
        return out

    def loop_constraint(self, q) -> np.ndarray:
        """``Φ(q)`` (m_l,), zero where every loop is closed."""
        return self.evaluate(q)["Phi_l"]

    def loop_jacobian(self, q) -> np.ndarray:
        """``J_l(q)`` (m_l, n)."""
        return self.evaluate(q)["J_l"]

    def loop_bias(self, q, qd) -> np.ndarray:
        """``J̇_l q̇`` (m_l,)."""
        return self.evaluate(q, qd)["dJqd_l"]

    @property
    def actuated(self) -> np.ndarray:
        """Indices of the actuated joints (the scene's ``actuated:``; all when it names none)."""
        names = self.model.joint_names
        wanted = self.model.actuated or names
        return np.array([names.index(j) for j in wanted], dtype=int)

    @property
    def passive(self) -> np.ndarray:
        """Indices of the passive joints (not :attr:`actuated`)."""
        return np.setdiff1d(np.arange(self.model.dof), self.actuated)

    def constrained_forward_dynamics(self, q, qd, tau, damping: float = 0.0
                                     ) -> tuple[np.ndarray, np.ndarray]:
        """``(q̈, F)`` [(n,), (m,)] (module docstring): ``F`` the contact forces, then the loop
        forces (``CONTACT_ROWS`` order).

        Raises
        ------
        numpy.linalg.LinAlgError
            With ``damping = 0``, when the rows are dependent (redundant loops).
        """
        qd = np.asarray(qd, dtype=float)
        return self.solve(self.evaluate(q, qd), qd, tau, damping)

    def solve(self, e: dict, qd, tau, damping: float = 0.0, contact_gamma=None
              ) -> tuple[np.ndarray, np.ndarray]:
        """``(q̈, F)`` of :meth:`constrained_forward_dynamics` from ``e``, an :meth:`evaluate`
        at the state ``(q, qd)``; ``contact_gamma`` (m_c,): a stabilisation term added to the
        contact rows' ``J̇ q̇`` (a simulation's Baumgarte term on contacts held at an anchor,
        :mod:`eomgen.analysis.simulate_loops`)."""
        qd, tau = (np.asarray(x, dtype=float) for x in (qd, tau))
        bias = e["dJqd_c"].copy()
        kp, kd = self.baumgarte
        m_l = len(e["Phi_l"])
        if kp or kd:
            bias[len(bias) - m_l:] += kd * (e["J_l"] @ qd) + kp * e["Phi_l"]
        if contact_gamma is not None:
            bias[:len(bias) - m_l] += contact_gamma
        return kkt_solve(e["M"], e["h"], tau, e["J_c"], bias, damping)

    def parallel_inverse_dynamics(self, q, qd, qdd, tolerance: float = 1e-8
                                  ) -> tuple[np.ndarray, np.ndarray]:
        """``(τ_a, λ)``: actuated efforts (:attr:`actuated` order) and loop forces
        (``LOOP_ROWS``) with ``M q̈ + h = Sᵀ τ_a + J_lᵀ λ`` (module docstring).

        Raises
        ------
        AnalysisError
            When ``[Sᵀ J_lᵀ]`` is singular (square case), or the least-squares residual exceeds
            ``tolerance`` of ``|M q̈ + h|`` (a q̈ that breaks the loops, or too few actuators).
        """
        e = self.evaluate(q, np.asarray(qd, dtype=float))
        tau = e["M"] @ np.asarray(qdd, dtype=float) + e["h"]
        n, act = self.model.dof, self.actuated
        A = np.hstack([np.eye(n)[:, act], e["J_l"].T])
        if A.shape[0] == A.shape[1]:
            try:
                x = np.linalg.solve(A, tau)
            except np.linalg.LinAlgError:
                raise AnalysisError("parallel inverse dynamics: [S^T J_l^T] is singular at this "
                                    "configuration (a singularity of the parallel robot)") from None
        else:
            x = np.linalg.lstsq(A, tau, rcond=None)[0]
        residual = float(np.linalg.norm(A @ x - tau))
        if residual > tolerance * max(1.0, float(np.linalg.norm(tau))):
            raise AnalysisError(f"parallel inverse dynamics: no actuated efforts and loop forces "
                                f"give M qdd + h (residual {residual:.3g}): qdd breaks the loops "
                                "or the actuated joints cannot drive this motion")
        return x[:len(act)], x[len(act):]

    def assemble(self, q, tolerance: float = 1e-12, iterations: int = 50) -> np.ndarray:
        """``q`` with its passive coordinates moved so that every loop closes (``|Φ|∞ ≤
        tolerance``), the actuated ones held; Newton's method (least-norm steps
        ``Δv_p = −J_l,p⁺ Φ`` on the passive velocity coordinates, ``q ← q ⊕ Δv``) from ``q``
        (NQ,).

        Raises
        ------
        AssemblyError
            One line with the remaining ``|Φ|``, when it does not converge in ``iterations``.
        """
        q = np.array(q, dtype=float)
        passive = self.passive
        error = np.inf
        for _ in range(iterations):
            e = self.evaluate(q)
            error = float(np.max(np.abs(e["Phi_l"]))) if len(e["Phi_l"]) else 0.0
            if error <= tolerance:
                return q
            step = np.zeros(self.model.dof)
            step[passive] = np.linalg.lstsq(e["J_l"][:, passive], -e["Phi_l"], rcond=None)[0]
            q = integrate(q, step, 1.0, self.model) if self.model.nq > self.model.dof else q + step
            if not np.all(np.isfinite(q)):
                break
        raise AssemblyError(f"the loops of '{self.model.name}' do not assemble from this "
                            f"configuration: |Phi| = {error:.3g} after {iterations} Newton "
                            "steps (actuated joints out of reach, or a singular configuration)")


__all__ = ["RANK_TOLERANCE", "AssemblyError", "LoopDynamics", "kkt_solve", "pinocchio_loops"]


def pinocchio_loops(model: RobotModel, pm, reference=None):
    """Pinocchio's ``RigidConstraintModel`` of each loop of ``model`` between the Pinocchio
    joints of its two frames (``pm``: :func:`eomgen.numeric.pinocchio.to_pinocchio` of
    ``model``; a ball joint or the free flyer is one Pinocchio joint): ``CONTACT_3D`` for a point loop (a planar one too: its third row is then
    dependent), ``CONTACT_6D`` for a weld, joint 1 the loop's frame a, joint 2 its frame b,
    placements the frames in the joints' frames, in ``reference`` (default ``LOCAL``: the
    forces in frame a's axes).

    Raises
    ------
    ValueError
        For a hinge loop (Pinocchio has no 5-row constraint).
    """
    import pinocchio as pin  # optional dependency: imported when used


    reference = pin.ReferenceFrame.LOCAL if reference is None else reference
    # a joint of several coordinates is one Pinocchio joint (a free flyer's named root_joint):
    # each of its virtual joints stands for it
    names = {virtual: pinocchio_name(place) for place in model.joint_places
             if place.nq != place.nv
             for virtual in (m.name for m in model.movable_joints[place.v_slice])}
    models = pin.StdVec_RigidConstraintModel()
    for loop in model.loops:
        if loop.kind == "hinge":
            raise ValueError(f"loop '{loop.name}': Pinocchio has no hinge (5-row) constraint")
        ends = []
        for frame in (loop.a, loop.b):
            body, pose = frame_site(model, frame.link)
            T = pose @ frame.pose
            name = model.parent_joint[body].name if body else None
            joint = pm.model.getJointId(names.get(name, name)) if body else 0
            R = np.array([[float(x) for x in row] for row in T.rotation])
            ends += [joint, pin.SE3(R, np.array([float(x) for x in T.translation]))]
        kind = pin.ContactType.CONTACT_3D if loop.kind == "point" else pin.ContactType.CONTACT_6D
        models.append(pin.RigidConstraintModel(kind, pm.model, *ends, reference))
    return models
