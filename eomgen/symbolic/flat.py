"""Builders of the flat inverse dynamics of Spong's flexible-joint model (issue 17) as generated
functions: the motor angles, rates and torques that make the links follow a trajectory ``q(t)``,
from ``q`` and its time derivatives up to order 4.

With ``τ_L = M(q) q̈ + C(q, q̇) q̇ + g(q)`` the rigid-body inverse dynamics (the Newton–Euler
program of the generated τ), on every flexible joint ``j`` (stiffness ``K_j``, motor inertia
``B_j``, motor friction ``d_j θ̇_j + f_j sign(θ̇_j)``)::

    θ_j  = q_j  + τ_L,j / K_j
    θ̇_j  = q̇_j  + τ̇_L,j / K_j
    θ̈_j  = q̈_j  + τ̈_L,j / K_j
    τ_m,j = B_j θ̈_j + K_j (θ_j − q_j) + d_j θ̇_j + f_j sign(θ̇_j)

and on every rigid joint ``i`` (armature ``a_i``) the joint torque of the rigid model,
``τ_i = τ_L,i + a_i q̈_i + d_i q̇_i + f_i sign(q̇_i)``, with ``θ_i = q_i``, ``θ̇_i = q̇_i`` (a
rigid joint's motor turns with its link). The ``_smooth`` output uses ``f tanh(v / w)`` in place
of ``f sign(v)``, the law of ``motor_forward_dynamics`` and of
:func:`eomgen.analysis.actuators.flexible_forward_dynamics` (``smooth=True``), so that a simulation fed
with it follows ``q(t)``. Conventions (frames, units, signs) are those of :mod:`eomgen.analysis.actuators`:
motor angles on the link side of the gear [rad], torques along the joint axes [N m; N for a
prismatic joint], one torque vector ``tau`` (joint torque of a rigid joint, motor torque of a
flexible one) in ``JOINT_NAMES`` order.

``τ̇_L`` and ``τ̈_L`` are formed in forward mode over the program builder's intermediates
(:func:`define_time_derivatives`): every intermediate ``x = f(s₁, …)`` of ``τ_L`` gets
``ẋ = Σ ∂f/∂s_k ṡ_k`` and ``ẍ = d/dt ẋ``, each defined as a new intermediate, so the program
stays linear in the size of the Newton–Euler program (nothing is expanded).

On a model with quaternion joints (a free flyer, ball joints: :mod:`eomgen.model.quaternion`)
the trajectory is ``q(t)`` in the configuration space (NQ entries) with velocity ``v(t)``
(NV): ``q̇``, ``q̈``, ``q⁽³⁾``, ``q⁽⁴⁾`` above read ``v``, ``v̇``, ``v̈``, ``v⁽³⁾``, and the
configuration moves at ``q̇ = configuration_rate(q, v)`` (:func:`configuration_rates`), not
at ``v``. The flexible joints are real one-DOF joints; in the outputs a quaternion joint's
entries are those of a rigid joint without a drive: ``θ`` holds 0 there (the chart's
coordinate: a quaternion joint has no angle), ``θ̇`` its velocity ``v``, ``τ`` its entries of
``τ_L`` (the root wrench of a free flyer).
"""

from __future__ import annotations

from typing import Mapping, Sequence

import sympy as sp

from ..model import flexible_indices, joint_actuators
from .builders import builds
from .drives import friction_torque_expr, require_flexible
from .program import ProgramBuilder
from .transforms import time_derivative

#: The symbols :func:`build_flat` makes (all need flexible joints).
FLAT = frozenset({"theta_flat", "thetad_flat", "tau_flat", "tau_flat_smooth"})


def define_time_derivatives(builder: ProgramBuilder, exprs: Sequence[sp.Expr],
                            rates: Mapping[sp.Symbol, sp.Expr], order: int = 2,
                            hints: Sequence[str] = ("d_", "dd_")) -> list[list[sp.Expr]]:
    """Time derivatives of ``exprs`` up to ``order``, defined in ``builder`` in forward mode.

    Every intermediate of ``builder`` that ``exprs`` depend on, ``x = f(s₁, …)``, gets its
    derivatives ``ẋ = Σ ∂f/∂s_k ṡ_k`` (and ``ẍ = d/dt ẋ``, ...) defined as new intermediates
    named ``hints[k] + x``, in the builder's order, so that each refers only to earlier ones:
    the added program is a fixed multiple of the size of the one differentiated (each
    expression tree is walked once by the product and chain rules, never expanded).

    Parameters
    ----------
    builder:
        The program builder holding the intermediates of ``exprs``.
    exprs:
        Expressions in the builder's intermediates and inputs.
    rates:
        The time derivative of each input that changes (``q → q̇``, ``q̇ → q̈``, ...); the inputs
        not listed (parameters) are constant. Differentiating ``order`` times needs the rates
        of the inputs' derivatives too (``q̈ → q⁽³⁾`` ...).
    order:
        The highest derivative formed (1 … len(hints)).
    hints:
        Name prefixes of the k-th derivatives of the intermediates.

    Returns
    -------
    list
        ``out[k - 1][i]``: the k-th time derivative of ``exprs[i]``.
    """
    if not 1 <= order <= len(hints):
        raise ValueError(f"order must be between 1 and {len(hints)}, got {order}")
    exprs = [sp.sympify(e) for e in exprs]
    value = dict(builder.assignments)
    needed: set[sp.Symbol] = set()
    for e in exprs:
        needed |= e.free_symbols & value.keys()
    for symbol, expr in reversed(builder.assignments):  # what the expressions depend on
        if symbol in needed:
            needed |= expr.free_symbols & value.keys()
    # sin(q_k) and cos(q_k) already named: their derivatives use the names, not new calls
    named = {expr: symbol for symbol, expr in builder.assignments
             if isinstance(expr, (sp.sin, sp.cos)) and expr.args[0] in rates}
    needed |= set(named.values())
    d: dict[sp.Symbol, sp.Expr] = dict(rates)
    intermediates = set(value)

    def rate(expr: sp.Expr) -> sp.Expr:
        unknown = [s for s in expr.free_symbols if s in intermediates and s not in d]
        if unknown:  # would be taken as constant: a wrong derivative, never silently
            raise RuntimeError(f"no time derivative for the intermediates {unknown}")
        return time_derivative(expr, d).xreplace(named)

    def remember(defined: sp.Expr, derivative: sp.Expr) -> None:
        """Record ``derivative`` as the rate of what ``define`` returned: a symbol, or a number
        times the symbol an equal expression was named by (an input keeps its rate)."""
        factor, symbol = sp.Integer(1), defined
        if defined.is_Mul and len(defined.args) == 2 and defined.args[0].is_Number:
            factor, symbol = defined.args
        if symbol.is_Symbol and symbol not in d:
            d[symbol] = derivative / factor

    # one derivative order at a time over the intermediates in program order: the k-th
    # derivative of x needs the k-th of the intermediates before it and, through the rates of
    # the (k-1)-th derivatives' names, the (k-1)-th of any other (sin ↔ cos)
    chain = [symbol for symbol, _ in builder.assignments if symbol in needed]
    source = {symbol: value[symbol] for symbol in chain}
    previous: dict[sp.Symbol, sp.Expr] = {}
    for k in range(order):
        for symbol in chain:
            source[symbol] = rate(source[symbol])
            size = len(builder.assignments)
            defined = builder.define(source[symbol], hints[k] + symbol.name)
            intermediates.update(s for s, _ in builder.assignments[size:])
            if k == 0:
                d[symbol] = defined
            else:
                remember(previous[symbol], defined)
            previous[symbol] = defined
    out = [exprs]
    for _ in range(order):
        out.append([rate(e) for e in out[-1]])
    return out[1:]


def configuration_rates(model, q, v) -> dict:
    """``q̇`` of every configuration symbol ``q`` (NQ) at the velocity ``v`` (NV), by symbol:
    ``v`` for a one-DOF joint; for a quaternion joint (:mod:`eomgen.model.quaternion`) the
    quaternion's ``½ (x, y, z, w) ⊗ (ω, 0)`` and, for the free flyer, the origin's ``R v_lin``
    (R of the normalised quaternion, as the program places it). Along these rates the
    quaternion's norm is constant, so the forward-mode derivatives of the program, which
    normalises it, are exact."""
    rates = {}
    for place in model.joint_places:  # each joint's kind's rate
        rates.update(place.kind.symbolic_rate(tuple(q[place.q_slice]), tuple(v[place.v_slice])))
    return rates


@builds("theta_flat", "thetad_flat", "tau_flat", "tau_flat_smooth")
def build_flat(derivation, wanted) -> dict:
    """The builder of ``theta_flat``, ``thetad_flat``, ``tau_flat`` and ``tau_flat_smooth`` in
    :mod:`eomgen.outputs` (``motor_angles``, ``motor_velocities``, ``flat_motor_torque``,
    ``flat_motor_torque_smooth``; see the module docstring).

    Raises
    ------
    GenerationError
        For a model without a flexible joint (an actuator with a stiffness).
    """
    model = derivation.model
    wanted = set(wanted)
    require_flexible(model, FLAT & wanted)
    actuators = joint_actuators(model)
    flexible = flexible_indices(model)
    inputs = derivation.inputs
    # the true accelerations (a quaternion joint's chart takes others, derivation.qdd)
    q, qd, qdd = derivation.q, derivation.qd, derivation.tangent(inputs["qdd"])
    qddd, qdddd = inputs["qddd"], inputs["qdddd"]
    n, b = len(q), derivation.builder
    tau_L = derivation.output("tau")
    orders = 2 if wanted & {"tau_flat", "tau_flat_smooth"} else 1 if "thetad_flat" in wanted else 0
    rates = (configuration_rates(model, inputs["q"], qd) | dict(zip(qd, qdd))
             | dict(zip(qdd, qddd)) | dict(zip(qddd, qdddd)))
    rows = [tau_L[k, 0] for k in flexible]
    derivatives = define_time_derivatives(b, rows, rates, orders) if orders else []
    # τ_L,F and its derivatives, named per flexible joint
    t = [b.define_all(rows, "tauL_F")] + [
        b.define_all(values, f"{'d' * (k + 1)}_tauL_F") for k, values in enumerate(derivatives)]

    def motor(level: int, base: Sequence[sp.Expr]) -> list[sp.Expr]:
        """θ (level 0), θ̇ (1) or θ̈ (2), n-vector: q-derivative + τ_L-derivative / K on
        flexible joints, the link's own value on rigid ones."""
        out = list(base)
        for col, k in enumerate(flexible):
            out[k] = base[k] + t[level][col] / actuators[k].stiffness
        return out

    out = {}
    if "theta_flat" in wanted:
        out["theta_flat"] = sp.Matrix(motor(0, q))
    if "thetad_flat" in wanted:
        out["thetad_flat"] = sp.Matrix(motor(1, qd))
    if wanted & {"tau_flat", "tau_flat_smooth"}:
        thetad = b.define_all(motor(1, qd), "thetad_F")
        thetadd = motor(2, qdd)
        for symbol, smooth in (("tau_flat", False), ("tau_flat_smooth", True)):
            if symbol not in wanted:
                continue
            friction = friction_torque_expr(actuators, thetad, smooth)  # θ̇ = q̇ when rigid
            tau = []
            for k in range(n):
                a = actuators[k].armature
                if k in flexible:  # B θ̈ + K (θ − q) + τ_f(θ̇), K (θ − q) = τ_L
                    tau.append(a * thetadd[k] + t[0][flexible.index(k)] + friction[k, 0])
                else:
                    tau.append(tau_L[k, 0] + a * qdd[k] + friction[k, 0])
            out[symbol] = sp.Matrix(tau)
    return out
