"""Builders of the drive outputs (issue 17): armature, friction and Spong's flexible joints as
generated functions. The equations and conventions are those of :mod:`eomgen.analysis.actuators`
(docs/actuators.md):

* rigid joints with drives: ``(M(q) + diag(a)) q̈ + C q̇ + g + τ_f(q̇) = τ``, with
  ``τ_f,i = d_i q̇_i + f_i sign(q̇_i)`` (exact, for inverse dynamics) or ``f_i tanh(q̇_i / w_i)``
  (smoothed with the width ``w_i``, for simulation); every joint stiff here (a flexible joint's
  motor inertia is its armature: the limit K → ∞);
* flexible joints (Spong's reduced model), motor angles ``θ`` on the link side of the gear, one
  per joint in ``JOINT_NAMES`` order (the entries of rigid joints are ignored)::

      M_l(q) q̈ + C q̇ + g + S_R τ_f(q̇) = S_R τ + τ_K,   τ_K = E K (θ − Eᵀ q)
      B θ̈ + K (θ − Eᵀ q) + τ_f(θ̇) = τ_m

  with ``M_l = M + diag(armature of the rigid joints)``, ``B`` the armature of the flexible
  joints, ``S_R`` selecting the rigid joints and ``τ`` one vector: joint torque of a rigid joint,
  motor torque of a flexible one.

On a model with quaternion joints (a free flyer, ball joints: :mod:`eomgen.model.quaternion`)
every vector is NV long, in ``JOINT_NAMES`` order (velocity coordinates); drives sit on the
real one-DOF joints only (a quaternion joint's entries have no armature, friction or spring:
0 there), and ``q`` of ``τ_K`` is the flexible joint's own angle.

Units: N m (N for prismatic joints), kg m², rad, rad/s. The friction law itself is
:func:`friction_torque_expr`, shared with :mod:`eomgen.analysis.actuators` and :mod:`eomgen.symbolic.flat`.
"""

from __future__ import annotations

import sympy as sp

from typing import Sequence

from ..errors import GenerationError
from ..model import Actuator, flexible_indices, joint_actuators
from .builders import builds

#: The symbols :func:`build_drives` makes that need flexible joints.
FLEXIBLE = frozenset({"tau_K", "thetadd_m"})


def friction_torque_expr(actuators: Sequence[Actuator], qd: Sequence[sp.Expr],
                         smooth: bool = False) -> sp.Matrix:
    """Symbolic friction torques ``τ_f,i = d_i q̇_i + f_i sign(q̇_i)`` (``smooth``: ``tanh(q̇_i /
    w_i)`` in place of the sign), (len(qd), 1); positive along the joint axis when the joint
    turns positively, i.e. the torque the drive spends on friction."""
    out = []
    for a, v in zip(actuators, qd):
        coulomb = sp.tanh(v / a.friction_width) if smooth else sp.sign(v)
        out.append(a.damping * v + (a.friction * coulomb if a.friction != 0 else 0))
    return sp.Matrix(out)


def require_flexible(model, symbols) -> None:
    """Raise the one-line :class:`GenerationError` of flexible-joint outputs ``symbols`` asked
    of ``model`` when it has no flexible joint (nothing to do for an empty ``symbols``)."""
    if symbols and not flexible_indices(model):
        raise GenerationError(
            f"{model.source}: {', '.join(sorted(symbols))} need flexible joints, "
            "but no joint has an actuator with a stiffness (docs/actuators.md)")


@builds("M_a", "tau_f", "tau_f_smooth", "tau_a", "M_l", "tau_K", "thetadd_m")
def build_drives(derivation, wanted) -> dict:
    """The builder of ``M_a``, ``tau_f``, ``tau_f_smooth``, ``tau_a``, ``M_l``, ``tau_K`` and
    ``thetadd_m`` in :mod:`eomgen.outputs` (see the module docstring).

    Raises
    ------
    GenerationError
        For a flexible-joint output of a model without a flexible joint (an actuator with a
        stiffness).
    """
    model = derivation.model
    actuators = joint_actuators(model)
    flexible = flexible_indices(model)
    require_flexible(model, FLEXIBLE & set(wanted))
    q, qd = derivation.q, derivation.qd
    # the true accelerations v̇ (T q̈ with coupled joints): a quaternion joint's chart takes
    # others (derivation.qdd), but no quaternion joint has a drive
    qdd = derivation.tangent(derivation.inputs["qdd"])
    armature = [a.armature for a in actuators]
    out = {}
    if "M_a" in wanted:
        out["M_a"] = derivation.output("M") + sp.diag(*armature)
    if "M_l" in wanted:
        out["M_l"] = derivation.output("M") + sp.diag(
            *[0 if k in flexible else a for k, a in enumerate(armature)])
    if "tau_f" in wanted:
        out["tau_f"] = friction_torque_expr(actuators, qd, smooth=False)
    if "tau_f_smooth" in wanted:
        out["tau_f_smooth"] = friction_torque_expr(actuators, qd, smooth=True)
    if "tau_a" in wanted:
        tau = derivation.output("tau")
        friction = friction_torque_expr(actuators, qd, smooth=False)
        out["tau_a"] = sp.Matrix([tau[k, 0] + armature[k] * qdd[k] + friction[k, 0]
                                  for k in range(len(q))])
    theta_m = derivation.inputs.get("theta_m")
    if "tau_K" in wanted:
        out["tau_K"] = sp.Matrix([actuators[k].stiffness * (theta_m[k] - q[k]) if k in flexible
                                  else 0 for k in range(len(q))])
    if "thetadd_m" in wanted:
        thetad_m, tau = derivation.inputs["thetad_m"], derivation.tau
        motor_friction = friction_torque_expr(actuators, thetad_m, smooth=True)
        out["thetadd_m"] = sp.Matrix([
            (tau[k] - actuators[k].stiffness * (theta_m[k] - q[k]) - motor_friction[k, 0])
            / actuators[k].armature if k in flexible else 0 for k in range(len(q))])
    return out
