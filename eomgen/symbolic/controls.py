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

A clamp is the piecewise-linear ``clamp(x, lo, hi) = (lo + hi + |x − lo| − |x − hi|) / 2``:
exact inside the range (up to rounding of order ``ulp(max(|lo|, |hi|))``), ``lo`` below and
``hi`` above, and its derivative ``(sign(x − lo) − sign(x − hi)) / 2`` is 1 inside, 0 outside
(½ on the bound itself). Every backend prints ``Abs`` and ``sign``.

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
from .derivatives import applied_forward_dynamics_jacobians, symmetric_inverse
from .passive import passive_forces
from .program import name_expr


@sizes("ctrl")
def control_count(model: RobotModel) -> int:
    """The length of ``ctrl``: the model's controls."""
    return len(model.controls)


@provides("ACTUATOR_NAMES")
def actuator_names(dynamics) -> dict[str, tuple[str, ...]]:
    """``ACTUATOR_NAMES``: the controls' names, the entries of ``ctrl`` in order."""
    return {"ACTUATOR_NAMES": tuple(c.name for c in dynamics.model.controls)}


def clamp(x, bounds):
    """``x`` clamped to ``bounds = (lo, hi)`` as a piecewise-linear expression (module
    docstring); ``x`` itself when ``bounds`` is None."""
    if bounds is None:
        return x
    lo, hi = bounds
    return (lo + hi + sp.Abs(x - lo) - sp.Abs(x - hi)) / 2


def control_forces(derivation) -> list:
    """``(moments, force)`` of each control of the derivation's model, ``moments`` the
    ``(joint index, gear · c_i)`` of its transmission's joints the model moves (``None`` for
    a control on none of them), the force an expression of ``q``, ``q̇`` and ``ctrl``
    (module docstring)."""
    model = derivation.model
    index = {name: k for k, name in enumerate(model.joint_names)}
    q, qd, ctrl = derivation.q, derivation.qd, derivation.inputs["ctrl"]
    out = []
    for i, control in enumerate(model.controls):
        terms = [(index[n], c) for n, c in control.transmission if n in index]
        if not terms:
            out.append(None)
            continue
        length = control.gear * (sp.Add(*[c * q[k] for k, c in terms]) + control.offset)
        velocity = control.gear * sp.Add(*[c * qd[k] for k, c in terms])
        gain = control.gain[0] + control.gain[1] * length + control.gain[2] * velocity
        bias = control.bias[0] + control.bias[1] * length + control.bias[2] * velocity
        force = clamp(gain * clamp(ctrl[i], control.ctrlrange) + bias, control.forcerange)
        out.append(([(k, control.gear * c) for k, c in terms], force))
    return out


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


@builds("tau_act", "qdd_ctrl", "dqdd_dctrl", "dqdd_ctrl_dq", "dqdd_ctrl_dqd", "dqdd_ctrl_dx")
def build_controls(derivation, wanted) -> dict:
    """The builder of ``tau_act``, ``qdd_ctrl``, ``dqdd_dctrl``, ``dqdd_ctrl_dq``,
    ``dqdd_ctrl_dqd`` and ``dqdd_ctrl_dx`` in :mod:`eomgen.outputs` (see the module
    docstring).

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
    forces = control_forces(derivation)
    tau = out["tau_act"] = actuator_forces(derivation, forces)
    armature = [a.armature for a in joint_actuators(derivation.model)]
    if "qdd_ctrl" in wanted:
        effort = tau + passive_forces(derivation)
        qdd = forward_dynamics_program(derivation.tree, derivation.q, derivation.qd,
                                       list(effort), derivation.model.gravity,
                                       derivation.builder, armature=armature)
        out["qdd_ctrl"] = true_accelerations(derivation, qdd)
    Minv = None
    if wanted & {"dqdd_ctrl_dq", "dqdd_ctrl_dqd", "dqdd_ctrl_dx"}:
        Minv, _, dq, dqd = applied_forward_dynamics_jacobians(
            derivation, tau + passive_forces(derivation), armature, "u")
        out.update(dqdd_ctrl_dq=dq, dqdd_ctrl_dqd=dqd, dqdd_ctrl_dx=sp.Matrix.hstack(dq, dqd))
    if "dqdd_dctrl" in wanted:
        b = derivation.builder
        ctrl = derivation.inputs["ctrl"]
        if Minv is None:
            Minv = symmetric_inverse(b, derivation.output("M") + sp.diag(*armature), "Minv_u")
        B = sp.zeros(len(tau), len(ctrl))
        for i, found in enumerate(forces):
            if found is not None:
                moments, force = found
                slope = name_expr(b, sp.diff(force, ctrl[i]), f"dtau_act{i + 1}",
                                  ("dtau_act", i + 1))
                for k, moment in moments:
                    B[k, i] += moment * slope
        out["dqdd_dctrl"] = Minv * B
    return out


__all__ = ["actuator_forces", "actuator_names", "build_controls", "clamp", "control_count",
           "control_forces"]
