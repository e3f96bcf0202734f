"""The builder of the passive forces ``tau_p`` (:mod:`eomgen.outputs`): the joint springs, the
drives' viscous damping and the fixed tendons (:mod:`eomgen.model.passive`), what MuJoCo
calls ``qfrc_passive`` (without fluid forces and gravity compensation)::

    τ_p,i = −k_i (q_i − q_ref,i) − d_i q̇_i + Σ_t c_t,i f_t,
    f_t = −k_t (L_t − clamp(L_t, L_lo, L_hi)) − b_t L̇_t,   L_t = Σ_i c_t,i q_i

in ``JOINT_NAMES`` order (NV entries): the generalised force the springs and dampers put on
the joints, to be *added* to the joint efforts (``M q̈ + C q̇ + g = τ + τ_p``). Coulomb
friction (``frictionloss``) is not in it: it is :data:`tau_f`'s. A quaternion joint's entries
hold their drives' damping only (their springs are not modelled).
"""

from __future__ import annotations

import sympy as sp

from ..model import joint_actuators, tendon_force
from .builders import builds


@builds("tau_p")
def build_passive(derivation, wanted) -> dict:
    """The builder of ``tau_p`` (see the module docstring)."""
    return {"tau_p": passive_forces(derivation)}


def passive_forces(derivation) -> sp.Matrix:
    """``τ_p`` (NV × 1) of the module docstring: what the springs and dampers add to the
    joint efforts; the forward dynamics of the controls adds it too
    (:mod:`eomgen.symbolic.controls`), as MuJoCo's ``qacc_smooth`` does."""
    model = derivation.model
    q, qd = derivation.q, derivation.qd
    out = [sp.Integer(0)] * len(qd)
    for k, (joint, drive) in enumerate(zip(model.movable_joints, joint_actuators(model))):
        if joint.spring is not None and joint.spring.stiffness != 0:
            out[k] -= joint.spring.stiffness * (q[k] - joint.spring.reference)
        if drive.damping != 0:
            out[k] -= drive.damping * qd[k]
    index = {name: k for k, name in enumerate(model.joint_names)}
    for tendon in model.tendons:
        if not tendon.coefficients:  # every joint locked
            continue
        length = sum(c * q[index[name]] for name, c in tendon.coefficients)
        rate = sum(c * qd[index[name]] for name, c in tendon.coefficients)
        force = tendon_force(tendon, length, rate)
        for name, c in tendon.coefficients:
            out[index[name]] += c * force
    return sp.Matrix(out)
