"""The builder of the passive forces ``tau_p`` (:mod:`eomgen.outputs`): the joint springs, the
drives' viscous damping and the fixed tendons (:mod:`eomgen.model.passive`), what MuJoCo
calls ``qfrc_passive`` (without fluid forces)::

    τ_p,i = −k_i (q_i − q_ref,i) − d_i q̇_i + Σ_t c_t,i f_t,
    f_t = −k_t (L_t − clamp(L_t, L_lo, L_hi)) − b_t L̇_t,   L_t = Σ_i c_t,i q_i

and gravity compensation (MuJoCo's body ``gravcomp``, :attr:`~eomgen.model.RobotModel.gravcomp`:
``qfrc_gravcomp``), the weight of each compensated link times its factor ``γ_b`` pushed back
up at its centre of mass::

    τ_gc = Σ_b γ_b J_b(q)ᵀ (−m_b g),

the gravity vector of the tree whose links weigh ``γ_b m_b`` (Newton–Euler at ``q̇ = q̈ = 0``),

in ``JOINT_NAMES`` order (NV entries): the generalised force the springs and dampers put on
the joints, to be *added* to the joint efforts (``M q̈ + C q̇ + g = τ + τ_p``). Coulomb
friction (``frictionloss``) is not in it: it is :data:`tau_f`'s. A ball joint's spring
(:class:`~eomgen.model.BallSpring`) puts MuJoCo's ``−k · subQuat(q, q_ref)`` on its three
entries (:func:`~eomgen.model.ball_spring_torque`); a free joint has no spring.
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from ..model import (BallSpring, Inertial, Spring, ball_spring_torque, float_constants,
                     joint_actuators, quaternion_layout, tendon_force)
from ..model.bodies import body_tree
from .builders import builds
from .newton_euler import inverse_dynamics_program


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
        spring = joint.spring  # a ball's (on its first virtual joint) is added below
        if isinstance(spring, Spring) and spring.stiffness != 0:
            out[k] -= spring.stiffness * (q[k] - spring.reference)
        if drive.damping != 0:
            out[k] -= drive.damping * qd[k]
    for ball in quaternion_layout(model):
        spring = model.movable_joints[ball.v_index].spring
        if isinstance(spring, BallSpring) and spring.stiffness != 0:
            quaternion = derivation.configuration[ball.q_index:ball.q_index + 4]
            for axis, torque in enumerate(ball_spring_torque(spring, quaternion)):
                out[ball.v_index + axis] += torque
    index = {name: k for k, name in enumerate(model.joint_names)}
    for tendon in model.tendons:
        if not tendon.coefficients:  # every joint locked
            continue
        length = sum(c * q[index[name]] for name, c in tendon.coefficients)
        rate = sum(c * qd[index[name]] for name, c in tendon.coefficients)
        force = tendon_force(tendon, length, rate)
        for name, c in tendon.coefficients:
            out[index[name]] += c * force
    if model.gravcomp:
        out = [a + b for a, b in zip(out, gravity_compensation(derivation))]
    return sp.Matrix(out)


def gravity_compensation(derivation) -> list:
    """``τ_gc`` (NV) of the module docstring: Newton–Euler at ``q̇ = q̈ = 0`` on the
    derivation's tree with each link's inertial scaled by its ``gravcomp`` factor (the links
    without one massless), so that fixed links merged into a body keep their own factors; an
    entry ``(link, factor, inertial)`` (a scene's merged body of several factors,
    :func:`eomgen.reduction.inertia.merged_gravcomp`) scales its own inertial instead."""
    model = derivation.model
    held = {entry[0]: (entry[1], entry[2] if len(entry) > 2 else None)
            for entry in model.gravcomp}

    def weight(link):  # what the compensation holds up of the link: None for nothing
        factor, inertial = held.get(link.name, (0, None))
        inertial = inertial or link.inertial
        if factor == 0 or inertial is None:
            return None
        return Inertial(factor * inertial.mass, inertial.com,
                        [[factor * x for x in row] for row in inertial.inertia])

    links = tuple(replace(link, inertial=weight(link)) for link in model.links)
    scaled = body_tree(float_constants(replace(model, links=links)))
    tree = replace(derivation.tree, bodies=tuple(
        replace(body, inertial=light.inertial)
        for body, light in zip(derivation.tree.bodies, scaled.bodies)))
    zero = [sp.Integer(0)] * len(derivation.qd)
    return list(inverse_dynamics_program(tree, derivation.q, zero, zero, model.gravity,
                                         derivation.builder, hint="tau_gc"))
