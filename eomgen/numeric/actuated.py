"""Actuated models, numerically: armature, friction and Spong's flexible joints in NumPy.

The equations and conventions are those of :mod:`eomgen.analysis.actuators` (docs/actuators.md).
:func:`actuated_model` compiles a :class:`~eomgen.dynamics.Dynamics` (``M``, ``C``, ``g``,
``P``) with its model's actuators once into an :class:`ActuatedModel`; the evaluators are free
functions of it: the rigid model with actuators (:func:`rigid_M`, :func:`friction_torque`,
:func:`rigid_inverse_dynamics`, :func:`rigid_forward_dynamics`) and Spong's reduced
flexible-joint model (:func:`flexible_forward_dynamics`, :func:`flexible_energy`,
:func:`flexible_inverse_dynamics` by flatness, :func:`flexible_rest_state`). The time
derivatives of ``τ_L = M q̈ + C q̇ + g`` the flat inverse dynamics needs come from the
forward-mode differentiated program (:func:`eomgen.symbolic.transforms.time_derivative_program`),
not from numeric differentiation.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Callable, Mapping

import numpy as np
import sympy as sp

from ..dynamics import Dynamics
from ..errors import ParameterError
from ..model import flexible_indices, joint_actuators, scalar
from ..symbolic.derivation import vector_symbols
from ..symbolic.evaluate import compile_program
from ..symbolic.program import Program
from ..symbolic.transforms import time_derivative_program

__all__ = [
    "ActuatedModel", "actuated_model", "rigid_M", "friction_torque", "rigid_inverse_dynamics",
    "rigid_forward_dynamics", "flexible_forward_dynamics", "flexible_energy",
    "flexible_inverse_dynamics", "flexible_rest_state",
]


@dataclass(frozen=True, eq=False)
class ActuatedModel:
    """A model with actuators, every parameter a number: what the numeric functions read.

    Arrays are (n,) float64 in ``joint_names`` order; ``flexible`` and ``rigid`` are index
    arrays. ``stiffness`` is NaN for rigid joints.
    """

    joint_names: tuple[str, ...]
    flexible: np.ndarray
    rigid: np.ndarray
    armature: np.ndarray
    damping: np.ndarray
    friction: np.ndarray
    friction_width: np.ndarray
    stiffness: np.ndarray
    _program: Callable[..., dict]
    _taylor_source: Program
    _inputs: tuple[sp.Symbol, ...]
    _parameter_values: tuple[float, ...]

    @property
    def n(self) -> int:
        return len(self.joint_names)

    @property
    def m(self) -> int:
        return len(self.flexible)

    def rigid_terms(self, q, qd) -> tuple[np.ndarray, np.ndarray, float]:
        """``M(q)`` (n×n), ``C(q, q̇) q̇ + g(q)`` (n,) and ``P(q)`` [J] of the links alone."""
        out = self._program(*np.concatenate([q, qd]), *self._parameter_values)
        return out["M"], (out["C"] @ np.asarray(qd) + out["g"][:, 0]), float(out["P"][0, 0])

    @cached_property
    def _taylor(self) -> Callable[..., dict]:
        return compile_program(self._taylor_source, self._inputs)

    def link_torque_derivatives(self, q, qd, qdd, qddd, qdddd):
        """``τ_L = M q̈ + C q̇ + g`` and its first and second time derivatives along the
        trajectory (n,) each, from the forward-mode differentiated program."""
        out = self._taylor(*np.concatenate([q, qd, qdd, qddd, qdddd]), *self._parameter_values)
        return out["tauL"][:, 0], out["d_tauL"][:, 0], out["dd_d_tauL"][:, 0]


def _number(x, values: Mapping[sp.Symbol, float], what: str, source: str) -> float:
    x = scalar(x).xreplace(values) if isinstance(x, sp.Basic) else x
    try:
        return float(x)
    except TypeError:
        raise ParameterError(source, what, f"no numeric value for {x}") from None


def actuated_model(dynamics: Dynamics, values: Mapping[str | sp.Symbol, float] | None = None
                   ) -> ActuatedModel:
    """Compile ``dynamics`` (``M``, ``C``, ``g``, ``P``) with its model's actuators for
    numeric use; parameters take ``values`` (by name or symbol) over their defaults.

    Raises
    ------
    ParameterError
        A parameter without a value.
    """
    model = dynamics.model
    given = {(parameter_key.name if isinstance(parameter_key, sp.Symbol) else parameter_key): v
             for parameter_key, v in (values or {}).items()}
    params = [p.symbol for p in model.parameters]
    numbers = {}
    for p in model.parameters:
        value = given.get(p.name, p.value)
        if value is None:
            raise ParameterError(model.source, f"parameter '{p.name}'", "no numeric value")
        numbers[p.symbol] = float(value)
    actuators = joint_actuators(model)

    def column(name):
        return np.array([np.nan if getattr(a, name) is None else
                         _number(getattr(a, name), numbers, f"joint '{j}' actuator {name}",
                                 model.source)
                         for a, j in zip(actuators, model.joint_names)], dtype=float)

    program = dynamics.program
    missing = {"M", "C", "g", "P"} - set(dynamics.outputs)
    if missing:
        raise ValueError(f"dynamics lacks {sorted(missing)}: derive with outputs M, C, g")
    q, qd, qdd = dynamics.q, dynamics.qd, dynamics.qdd
    n = len(q)
    qddd, qdddd = vector_symbols("qddd", n), vector_symbols("qdddd", n)
    tau_L = (program.output("M") * sp.Matrix(qdd) + program.output("C") * sp.Matrix(qd)
             + program.output("g"))
    base = Program(program.assignments, (("tauL", tau_L),)).pruned(["tauL"])
    rates = dict(zip(q, qd)) | dict(zip(qd, qdd)) | dict(zip(qdd, qddd)) \
        | dict(zip(qddd, qdddd))
    once = time_derivative_program(base, rates, ["tauL"], "d_")
    defined = {s.name: s for s, _ in once.assignments}
    known = {s: defined["d_" + s.name] for s, _ in base.assignments if "d_" + s.name in defined}
    twice = time_derivative_program(once, rates | known, ["d_tauL"], "dd_")
    flexible = np.array(flexible_indices(model), dtype=int)
    return ActuatedModel(
        model.joint_names, flexible,
        np.array([k for k in range(n) if k not in set(flexible.tolist())], dtype=int),
        column("armature"), column("damping"), column("friction"), column("friction_width"),
        column("stiffness"),
        compile_program(program.pruned(["M", "C", "g", "P"]), tuple(q) + tuple(qd)
                        + tuple(params)),
        twice.pruned(["tauL", "d_tauL", "dd_d_tauL"]),
        tuple(q) + tuple(qd) + tuple(qdd) + qddd + qdddd + tuple(params),
        tuple(numbers[s] for s in params))


def rigid_M(am: ActuatedModel, q) -> np.ndarray:
    """``M(q) + diag(a)`` (n×n), every joint's armature added (the rigid model)."""
    M, _, _ = am.rigid_terms(np.asarray(q, float), np.zeros(am.n))
    return M + np.diag(am.armature)


def friction_torque(am: ActuatedModel, qd, smooth: bool = False, joints=None) -> np.ndarray:
    """``d q̇ + f sign(q̇)`` (``smooth``: ``f tanh(q̇/w)``) for the joints ``joints`` (indices,
    default all; ``qd`` of matching length)."""
    k = np.arange(am.n) if joints is None else np.asarray(joints, int)
    qd = np.asarray(qd, float)
    coulomb = np.tanh(qd / am.friction_width[k]) if smooth else np.sign(qd)
    return am.damping[k] * qd + am.friction[k] * coulomb


def rigid_inverse_dynamics(am: ActuatedModel, q, qd, qdd, smooth: bool = False) -> np.ndarray:
    """``(M + diag(a)) q̈ + C q̇ + g + τ_f(q̇)`` (n,), every joint rigid."""
    M, h, _ = am.rigid_terms(np.asarray(q, float), np.asarray(qd, float))
    return (M + np.diag(am.armature)) @ qdd + h + friction_torque(am, qd, smooth)


def rigid_forward_dynamics(am: ActuatedModel, q, qd, tau, smooth: bool = True) -> np.ndarray:
    """``q̈`` (n,) of the rigid model with actuators under joint torques ``tau``."""
    M, h, _ = am.rigid_terms(np.asarray(q, float), np.asarray(qd, float))
    rhs = np.asarray(tau, float) - h - friction_torque(am, qd, smooth)
    return np.linalg.solve(M + np.diag(am.armature), rhs)


def _split(am: ActuatedModel, x):
    x = np.asarray(x, float)
    n, m = am.n, am.m
    if x.shape != (2 * n + 2 * m,):
        raise ValueError(f"the state must have shape ({2 * n + 2 * m},): q, qd ({n} each), "
                         f"theta, thetad ({m} each); got {x.shape}")
    return x[:n], x[n:2 * n], x[2 * n:2 * n + m], x[2 * n + m:]


def flexible_forward_dynamics(am: ActuatedModel, x, tau, smooth: bool = True) -> np.ndarray:
    """``ẋ`` of the reduced Spong model, ``x = (q, q̇, θ, θ̇)`` (2n + 2m,), inputs ``tau`` (n,):
    joint torques of rigid joints, motor torques of flexible ones."""
    q, qd, th, thd = _split(am, x)
    tau = np.asarray(tau, float)
    F, R = am.flexible, am.rigid
    M, h, _ = am.rigid_terms(q, qd)
    a_rigid = np.zeros(am.n)
    a_rigid[R] = am.armature[R]
    spring = am.stiffness[F] * (th - q[F])
    u = np.zeros(am.n)
    u[R] = tau[R] - friction_torque(am, qd[R], smooth, R)
    u[F] = spring
    qdd = np.linalg.solve(M + np.diag(a_rigid), u - h)
    thdd = (tau[F] - spring - friction_torque(am, thd, smooth, F)) / am.armature[F]
    return np.concatenate([qd, qdd, thd, thdd])


def flexible_energy(am: ActuatedModel, x) -> float:
    """Total energy [J] of the reduced Spong model: link and motor kinetic energy, gravity
    and spring potential. Conserved without friction and input."""
    q, qd, th, thd = _split(am, x)
    F, R = am.flexible, am.rigid
    M, _, P = am.rigid_terms(q, qd)
    a_rigid = np.zeros(am.n)
    a_rigid[R] = am.armature[R]
    e = th - q[F]
    return float(0.5 * qd @ (M + np.diag(a_rigid)) @ qd + 0.5 * am.armature[F] @ thd ** 2
                 + P + 0.5 * am.stiffness[F] @ e ** 2)


def flexible_inverse_dynamics(am: ActuatedModel, q, qd, qdd, qddd, qdddd,
                              smooth: bool = False) -> dict[str, np.ndarray]:
    """The motor states and inputs that make the links of the reduced Spong model follow a
    trajectory, from ``q`` and its derivatives up to order 4 (flatness; no numeric
    differentiation: see the module docstring).

    Returns
    -------
    dict
        ``theta``, ``thetad``, ``thetadd`` (m,) and ``tau`` (n,): motor torques for flexible
        joints, joint torques for rigid ones.
    """
    q, qd, qdd = (np.asarray(v, float) for v in (q, qd, qdd))
    F, R = am.flexible, am.rigid
    t0, t1, t2 = am.link_torque_derivatives(q, qd, qdd, np.asarray(qddd, float),
                                            np.asarray(qdddd, float))
    K = am.stiffness[F]
    theta = q[F] + t0[F] / K
    thetad = qd[F] + t1[F] / K
    thetadd = qdd[F] + t2[F] / K
    tau = np.empty(am.n)
    tau[F] = am.armature[F] * thetadd + t0[F] + friction_torque(am, thetad, smooth, F)
    tau[R] = t0[R] + am.armature[R] * qdd[R] + friction_torque(am, qd[R], smooth, R)
    return {"theta": theta, "thetad": thetad, "thetadd": thetadd, "tau": tau}


def flexible_rest_state(am: ActuatedModel, q) -> np.ndarray:
    """The state ``x`` at rest at link angles ``q``: springs wound up to hold gravity,
    ``θ = q_F + K⁻¹ g_F(q)`` (the inputs that hold it: ``tau = g(q)``)."""
    q = np.asarray(q, float)
    F = am.flexible
    _, g, _ = am.rigid_terms(q, np.zeros(am.n))
    return np.concatenate([q, np.zeros(am.n), q[F] + g[F] / am.stiffness[F], np.zeros(am.m)])
