"""Builders of the control outputs (issue 41): MuJoCo's actuators on joints and fixed tendons
as generated functions of ``(q, q̇, ctrl)`` (:class:`~eomgen.model.Control`, docs/formats.md).

* ``tau_act`` (``actuator_forces``): ``τ_act = Σ_i J_iᵀ clamp(gain_i · clamp(ctrl_i) +
  bias_i)`` with ``gain = g0 + g1 l + g2 v``, ``bias = b0 + b1 l + b2 v`` on the actuator's
  length ``l = gear · L`` and velocity ``v = gear · L̇``, ``L = Σ c_j q_j + L_0`` its
  transmission (the joint itself, or a fixed tendon's coefficients), ``J_i = gear · ∂L/∂q``
  (MuJoCo's ``qfrc_actuator`` of a joint or tendon transmission: ``force = gain · ctrl +
  bias``, the control clamped to ``ctrlrange`` and the force to ``forcerange``, then the
  moment ``Jᵀ force``);
* ``qdd_ctrl`` (``forward_dynamics_ctrl``): ``q̈ = (M + diag(a))⁻¹ (τ_act + τ_p − C q̇ − g)``
  by the Articulated-Body Algorithm with the drives' armature ``a`` (MuJoCo's ``armature``)
  and the passive forces ``τ_p`` of :mod:`eomgen.symbolic.passive` (joint springs, the drives'
  viscous damping, fixed tendons): MuJoCo's ``qacc_smooth``. Coulomb friction (MuJoCo's
  ``frictionloss``, a constraint there) is left out;
* ``dqdd_dctrl``: ``∂q̈/∂ctrl = (M + diag(a))⁻¹ ∂τ_act/∂ctrl`` (nv × nu), zero in the columns
  whose clamp holds;
* ``dqdd_ctrl_dq``, ``dqdd_ctrl_dqd`` (nv × nv; ``dqdd_ctrl_dx`` both side by side):
  ``∂q̈/∂x = −(M + diag(a))⁻¹ (∂τ/∂x − ∂(τ_act + τ_p)/∂x)`` for x = q (along the tangent of a
  quaternion joint, as :mod:`eomgen.symbolic.derivatives`) and x = q̇, the Newton–Euler
  ``∂τ`` taken at q̈ held fixed (the implicit function theorem,
  :func:`~eomgen.symbolic.derivatives.applied_forward_dynamics_jacobians`): what MPC
  linearizes. A clamp that holds contributes 0 to them; a tendon's dead band too.

* ``xd_act`` (``forward_dynamics_act``): for a model whose controls include activation
  dynamics (MuJoCo's ``dyntype`` integrator, filter, filterexact, a DC motor's current, with
  or without ``actearly``; :mod:`eomgen.model.control`),
  ``(q̈, act_dot)`` stacked (nv + na), a function of ``(q, q̇, ctrl, act)``: the forces of
  those controls follow their activations ``act`` (MuJoCo's ``act``, ``ACTIVATION_NAMES``
  order), ``q̈`` is ``qdd_ctrl``'s at those forces (MuJoCo's ``qacc_smooth``) and
  ``act_dot`` is MuJoCo's. The outputs above, without ``act``, refuse such a model.
* ``dxd_act`` (``forward_dynamics_act_derivatives``): its Jacobian, ``(nv + na)`` rows
  (q̈ then act_dot) and the columns ``∂/∂q`` (along the tangent, nv), ``∂/∂q̇`` (nv),
  ``∂/∂ctrl`` (nu), ``∂/∂act`` (na) side by side: q̈'s by
  :func:`~eomgen.symbolic.derivatives.applied_forward_dynamics_jacobians` (the implicit
  function theorem, ``∂q̈/∂u = M_a⁻¹ Tᵀ ∂f/∂u`` for u = ctrl, act), act_dot's by forward
  mode. With ``actearly`` the force follows ``clamp(act + α act_dot, actrange)``, so
  ``∂q̈/∂ctrl`` takes ``α ∂act_dot/∂ctrl`` and ``∂q̈/∂q̇`` a DC motor's back-EMF through it;
* ``A_act``, ``B_act`` (``state_matrix_act``, ``input_matrix_act``): ẋ = f(x, ctrl) of the
  state ``x = (q, q̇, act)`` linearized, ``A = [[T, I, 0], [∂q̈/∂q, ∂q̈/∂q̇, ∂q̈/∂act],
  [∂ȧ/∂q, ∂ȧ/∂q̇, ∂ȧ/∂act]]``, ``B = [[0], [∂q̈/∂ctrl], [∂ȧ/∂ctrl]]``, T the tangent
  chart's velocity transport of :func:`~eomgen.symbolic.derivatives.linearization`.

A clamp is the piecewise-linear ``clamp(x, lo, hi) = (lo + hi + |x − lo| − |x − hi|) / 2``:
exact inside the range (up to rounding of order ``ulp(max(|lo|, |hi|))``), ``lo`` below and
``hi`` above, and its derivative ``(sign(x − lo) − sign(x − hi)) / 2`` is 1 inside, 0 outside
(½ on the bound itself). Every backend prints ``Abs`` and ``sign``.

With coupled joints (:mod:`eomgen.symbolic.couplings`) ``tau_act`` is projected by ``Tᵀ`` and
the other outputs are built in the independent coordinates: ``q̈ = M_a⁻¹ Tᵀ (τ_act + τ_p −
h)``, ``M_a = Tᵀ (M + diag(a)) T``, from its LDLᵀ factors
(:func:`~eomgen.symbolic.derivatives.applied_forward_dynamics`; the ABA solves the
unconstrained tree), ``∂q̈/∂ctrl = M_a⁻¹ Tᵀ ∂τ_act/∂ctrl``.

A control on a joint the model no longer moves (locked by a scene or an equality) gives no
force; its ``ctrl`` entry stays (a tendon's held joints are in its length, :meth:`~eomgen.
model.Control.locked`).
"""

from __future__ import annotations

import sympy as sp

from ..errors import GenerationError
from ..model import RobotModel, joint_actuators
from .aba import forward_dynamics_program, true_accelerations
from .builders import builds, provides, sizes
from .charts import chart_offset
from .couplings import independent
from .derivatives import (applied_forward_dynamics, applied_forward_dynamics_jacobians,
                          input_jacobians, symmetric_inverse)
from .passive import passive_forces
from .program import name_expr
from .tangent import velocity_transport


@sizes("ctrl")
def control_count(model: RobotModel) -> int:
    """The length of ``ctrl``: the model's controls."""
    return len(model.controls)


@sizes("act")
def activation_count(model: RobotModel) -> int:
    """The length of ``act``: the controls with activation dynamics."""
    return sum(1 for c in model.controls if c.dynamics is not None)


@provides("ACTUATOR_NAMES")
def actuator_names(dynamics) -> dict[str, tuple[str, ...]]:
    """``ACTUATOR_NAMES``: the controls' names, the entries of ``ctrl`` in order."""
    return {"ACTUATOR_NAMES": tuple(c.name for c in dynamics.model.controls)}


@provides("ACTUATOR_NAMES", "ACTIVATION_NAMES")
def activation_names(dynamics) -> dict[str, tuple[str, ...]]:
    """``ACTUATOR_NAMES`` and ``ACTIVATION_NAMES``: the names of the controls with activation
    dynamics, the entries of ``act`` (MuJoCo's ``act``) in order."""
    controls = dynamics.model.controls
    return {**actuator_names(dynamics),
            "ACTIVATION_NAMES": tuple(c.name for c in controls if c.dynamics is not None)}


def clamp(x, bounds):
    """``x`` clamped to ``bounds = (lo, hi)`` as a piecewise-linear expression (module
    docstring); ``x`` itself when ``bounds`` is None."""
    if bounds is None:
        return x
    lo, hi = bounds
    return (lo + hi + sp.Abs(x - lo) - sp.Abs(x - hi)) / 2


def control_forces(derivation, act=None) -> list:
    """``(moments, force)`` of each control of the derivation's model, ``moments`` the
    ``(joint index, gear · c_i)`` of its transmission's joints the model moves (``None`` for
    a control on none of them), the force an expression of ``q``, ``q̇``, ``ctrl`` and, for
    the controls with activation dynamics, their activations ``act`` (module docstring).

    Raises
    ------
    GenerationError
        For a control with activation dynamics when ``act`` is None (an output without the
        input ``act``)."""
    model = derivation.model
    ctrl = derivation.inputs["ctrl"]
    rates = None
    out, j = [], 0
    for i, control in enumerate(model.controls):
        driven = clamp(ctrl[i], control.ctrlrange)
        state = None
        if control.dynamics is not None:
            if act is None:
                raise GenerationError(
                    f"{model.source}: actuator '{control.name}' has {control.dynamics} "
                    "activation dynamics: its force follows its activation act, an input of "
                    "forward_dynamics_act only (docs/formats.md)")
            state = act[j]
            if control.early is not None:  # actearly: one step ahead
                rates = activation_rates(derivation) if rates is None else rates
                state = clamp(state + control.early * rates[j], control.actrange)
            if control.integral is None:  # a PID's integral adds to the setpoint's force
                driven = state
            j += 1
        terms, length, velocity = _transmission(derivation, control)
        if not terms:
            out.append(None)
            continue
        gain = control.gain[0] + control.gain[1] * length + control.gain[2] * velocity
        bias = control.bias[0] + control.bias[1] * length + control.bias[2] * velocity
        if control.integral is not None:
            force = clamp(gain * driven + control.integral * state + bias, control.forcerange)
        else:
            force = clamp(gain * driven + bias, control.forcerange)
        if control.cogging is not None:
            amplitude, poles, phase = control.cogging
            force += amplitude * sp.sin(poles * length + phase)
        out.append(([(k, control.gear * c) for k, c in terms], force))
    return out


def _transmission(derivation, control) -> tuple[list, object, object]:
    """``(terms, l, v)`` of ``control``: the ``(joint index, c_i)`` of its transmission's
    joints the model moves, its length ``l = gear · (Σ c_i q_i + L_0)`` and velocity
    ``v = gear · Σ c_i q̇_i`` (zero without terms)."""
    index = {name: k for k, name in enumerate(derivation.model.joint_names)}
    q, qd = derivation.q, derivation.qd
    terms = [(index[n], c) for n, c in control.transmission if n in index]
    length = control.gear * (sp.Add(*[c * q[k] for k, c in terms]) + control.offset)
    velocity = control.gear * sp.Add(*[c * qd[k] for k, c in terms])
    return terms, length, velocity


def actuator_forces(derivation, forces) -> sp.Matrix:
    """τ_act (nv × 1) of :func:`control_forces` ``forces``, each force named ``f_act<i>``."""
    tau = [sp.Integer(0)] * len(derivation.model.joint_names)
    for i, found in enumerate(forces):
        if found is not None:
            moments, force = found
            named = name_expr(derivation.builder, force, f"f_act{i + 1}", ("f_act", i + 1))
            for k, moment in moments:
                tau[k] += moment * named
    return sp.Matrix(tau)


def _accelerations(derivation, tau, armature, hint: str = "u") -> sp.Matrix:
    """``q̈ = (M + diag(a))⁻¹ (τ_act + τ_p − C q̇ − g)`` by the ABA (module docstring); with
    coupled joints ``q̈ = M_a⁻¹ Tᵀ (τ_act + τ_p − h)``, ``M_a = Tᵀ (M + diag(a)) T``, in the
    independent coordinates (the ABA solves the unconstrained tree), from the LDLᵀ factors
    of :func:`~eomgen.symbolic.derivatives.applied_forward_dynamics` (``hint`` names its
    intermediates).

    The ABA's armature multiplies its own accelerations, which on a free flyer or a ball joint
    are the chart's ``ξ̈ = v̇ − n(v)`` (:mod:`eomgen.symbolic.charts`), where MuJoCo's
    armature (and ``M + diag(a)``) multiplies the joint's ``v̇``: the difference ``a n(v)``
    moves to the efforts."""
    effort = tau + passive_forces(derivation)
    if derivation.coupling is not None:
        return applied_forward_dynamics(derivation, effort, armature, hint)[1]
    offset = chart_offset(derivation, derivation.qd)
    effort = effort - sp.Matrix([a * n for a, n in zip(armature, offset)])
    qdd = forward_dynamics_program(derivation.tree, derivation.q, derivation.qd, list(effort),
                                   derivation.model.gravity, derivation.builder,
                                   armature=armature)
    return true_accelerations(derivation, qdd)


def activation_rates(derivation) -> list:
    """``act_dot`` of each control with activation dynamics, in ``act`` order: ``c`` for an
    integrator, ``c − l`` for a PID's integral, ``(c − act) / T`` for a filter, ``clamp(((c − K v) / R − act) / T, ±di_max)``
    for a DC motor's current (:mod:`eomgen.model.control`), ``c`` the control clamped to its
    ``ctrlrange``, ``v`` the actuator's velocity."""
    ctrl, act = derivation.inputs["ctrl"], derivation.inputs["act"]
    out = []
    for i, control in enumerate(derivation.model.controls):
        if control.dynamics is None:
            continue
        driven = clamp(ctrl[i], control.ctrlrange)
        state = act[len(out)]
        if control.dynamics == "integrator":
            out.append(driven)
        elif control.dynamics == "pid":  # the position error's integral
            out.append(driven - _transmission(derivation, control)[1])
        elif control.dynamics == "dcmotor":
            resistance, constant = control.motor
            velocity = _transmission(derivation, control)[2]
            rate = ((driven - constant * velocity) / resistance - state) / control.timeconst
            limit = control.rate_limit
            out.append(rate if limit is None else clamp(rate, (-limit, limit)))
        else:
            out.append((driven - state) / control.timeconst)
    return out


def _activated(derivation) -> sp.Matrix:
    """``xd_act``: ``(q̈, act_dot)`` stacked, the forces at the activations ``act``."""
    armature = [a.armature for a in joint_actuators(derivation.model)]
    tau = actuator_forces(derivation, control_forces(derivation, derivation.inputs["act"]))
    qdd = _accelerations(derivation, tau, armature, "act")
    return sp.Matrix(list(qdd) + activation_rates(derivation))


def _activated_jacobians(derivation) -> dict:
    """``dxd_act``, ``A_act`` and ``B_act``: the Jacobians of ``xd_act`` = (q̈, act_dot) by
    :func:`~eomgen.symbolic.derivatives.applied_forward_dynamics_jacobians` (q̈, the implicit
    function theorem) and :func:`~eomgen.symbolic.derivatives.input_jacobians` (act_dot), the
    forces at the activations ``act`` (one step ahead with ``actearly``, so that ∂q̈/∂ctrl
    takes α ∂act_dot/∂ctrl), and the state-space pair of x = (q, q̇, act), u = ctrl."""
    armature = [a.armature for a in joint_actuators(derivation.model)]
    tau = actuator_forces(derivation, control_forces(derivation, derivation.inputs["act"]))
    _, _, *dqdd = applied_forward_dynamics_jacobians(
        derivation, tau + passive_forces(derivation), armature, "xa", ("ctrl", "act"))
    dq, dqd, dctrl, dact = dqdd
    rates = activation_rates(derivation)
    ddq, ddqd, ddctrl, ddact = input_jacobians(derivation, rates, ("ctrl", "act"))
    n, na = dq.rows, len(rates)
    jacobian = sp.Matrix.vstack(sp.Matrix.hstack(dq, dqd, dctrl, dact),
                                sp.Matrix.hstack(ddq, ddqd, ddctrl, ddact))
    transport = velocity_transport(independent(derivation))
    A = sp.Matrix.vstack(sp.Matrix.hstack(transport, sp.eye(n), sp.zeros(n, na)),
                         sp.Matrix.hstack(dq, dqd, dact), sp.Matrix.hstack(ddq, ddqd, ddact))
    B = sp.Matrix.vstack(sp.zeros(n, dctrl.cols), dctrl, ddctrl)
    return {"dxd_act": jacobian, "A_act": A, "B_act": B}


@builds("tau_act", "qdd_ctrl", "dqdd_dctrl", "dqdd_ctrl_dq", "dqdd_ctrl_dqd", "dqdd_ctrl_dx",
        "xd_act", "dxd_act", "A_act", "B_act")
def build_controls(derivation, wanted) -> dict:
    """The builder of ``tau_act``, ``qdd_ctrl``, ``dqdd_dctrl``, ``dqdd_ctrl_dq``,
    ``dqdd_ctrl_dqd``, ``dqdd_ctrl_dx``, ``xd_act``, ``dxd_act``, ``A_act`` and ``B_act`` in
    :mod:`eomgen.outputs` (see the module docstring).

    Raises
    ------
    GenerationError
        For a model without controls (nothing to generate a function of ``ctrl`` from).
    """
    model = derivation.model
    if not model.controls:
        raise GenerationError(f"{model.source}: {', '.join(sorted(wanted))} need controls "
                              "(MJCF actuators on joints and fixed tendons, YAML controls:), "
                              "but the model has none (docs/formats.md)")
    out = {}
    activated = {"xd_act", "dxd_act", "A_act", "B_act"}
    if "xd_act" in wanted:
        out["xd_act"] = _activated(derivation)
    if wanted & (activated - {"xd_act"}):
        out.update((k, v) for k, v in _activated_jacobians(derivation).items() if k in wanted)
    if not wanted - activated:
        return out
    forces = control_forces(derivation)
    tau = out["tau_act"] = actuator_forces(derivation, forces)
    armature = [a.armature for a in joint_actuators(derivation.model)]
    if "qdd_ctrl" in wanted:
        out["qdd_ctrl"] = _accelerations(derivation, tau, armature)
    Minv = None
    if wanted & {"dqdd_ctrl_dq", "dqdd_ctrl_dqd", "dqdd_ctrl_dx"}:
        Minv, _, dq, dqd = applied_forward_dynamics_jacobians(
            derivation, tau + passive_forces(derivation), armature, "u")
        out.update(dqdd_ctrl_dq=dq, dqdd_ctrl_dqd=dqd, dqdd_ctrl_dx=sp.Matrix.hstack(dq, dqd))
    if "dqdd_dctrl" in wanted:
        b = derivation.builder
        ctrl = derivation.inputs["ctrl"]
        T = derivation.coupling
        if Minv is None and T is not None:
            Minv = applied_forward_dynamics(derivation, tau + passive_forces(derivation),
                                            armature, "u")[0]
        elif Minv is None:
            Minv = symmetric_inverse(b, derivation.output("M") + sp.diag(*armature), "Minv_u")
        B = sp.zeros(len(tau), len(ctrl))
        for i, found in enumerate(forces):
            if found is not None:
                moments, force = found
                slope = name_expr(b, sp.diff(force, ctrl[i]), f"dtau_act{i + 1}",
                                  ("dtau_act", i + 1))
                for k, moment in moments:
                    B[k, i] += moment * slope
        out["dqdd_dctrl"] = Minv * (B if T is None else T.T * B)
    return out


__all__ = ["activation_count", "activation_names", "activation_rates", "actuator_forces",
           "actuator_names", "build_controls", "clamp", "control_count",
           "control_forces"]
