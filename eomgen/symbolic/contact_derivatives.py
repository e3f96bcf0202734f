"""Derivatives of the contact-constrained dynamics (issue 25): the partials of the KKT system.

``constrained_forward_dynamics(q, q̇, τ)`` solves (docs/contact.md; the contacts push on the
robot with ``F_c``, rows ``CONTACT_ROWS``)::

    [[M, −J_cᵀ], [J_c, 0]] [q̈; F_c] = [τ − (C q̇ + g); −J̇_c q̇]

that is ``r(q, q̇, q̈, F_c) = τ`` with ``r = τ_c = M q̈ + C q̇ + g − J_cᵀ F_c`` (the contact
inverse dynamics) and ``a(q, q̇, q̈) = J_c q̈ + J̇_c q̇ = 0`` (the contact accelerations).
Differentiating both at the solution (implicit function theorem), with
``K = [[M, −J_cᵀ], [J_c, 0]]``::

    K ∂(q̈, F_c)/∂x = −[∂r/∂x; ∂a/∂x]  (x = q, q̇),    K ∂(q̈, F_c)/∂τ = [1; 0]

:func:`constrained_partials` gives ``[[∂r/∂q, ∂r/∂q̇], [∂a/∂q, ∂a/∂q̇]]`` ((NV + m) × 2 NV,
∂/∂q along the tangent for quaternion joints, :mod:`eomgen.symbolic.tangent`) as one program:
the Newton–Euler ``τ``, ``J_c`` and ``J̇_c q̇`` differentiated in forward mode with ``q̈`` and
``F_c`` inputs held fixed. The generated ``constrained_forward_dynamics_derivatives`` solves
with ``K`` at the state's ``(q̈, F_c)`` (the solve is numeric: a template composes it).
This is what Pinocchio's ``computeConstraintDynamicsDerivatives`` returns (``ddq_dq``,
``ddq_dv``, ``ddq_dtau``, ``dlambda_dq``, ``dlambda_dv``, ``dlambda_dtau``) for point contacts
in ``LOCAL_WORLD_ALIGNED`` axes, whose ``λ`` is the force on the robot as ``F_c`` is.
"""

from __future__ import annotations

import sympy as sp

from .builders import builds
from .derivatives import forward_mode
from .tangent import tangent_seeds


def constrained_partials(derivation) -> sp.Matrix:
    """``[[∂r/∂q, ∂r/∂q̇], [∂a/∂q, ∂a/∂q̇]]`` (module docstring), (NV + m) × 2 NV, at the
    derivation's ``qdd`` and ``F_c`` inputs."""
    r = derivation.output("tau_c")
    J, drift = derivation.output("J_c"), derivation.output("dJqd_c")
    a = J * sp.Matrix(derivation.inputs["qdd"]) + drift
    nv = derivation.model.dof
    seeds = {**tangent_seeds(derivation),
             **{s: ("qd", k) for k, s in enumerate(derivation.qd)}}
    rows = forward_mode(derivation.builder, [*r, *a], seeds)
    return sp.Matrix(len(rows), 2 * nv, lambda i, j: rows[i].get(
        ("q", j) if j < nv else ("qd", j - nv), sp.Integer(0)))


@builds("dKKT")
def build_constrained_partials(derivation, wanted) -> dict:
    """The builder of ``dKKT`` in :mod:`eomgen.outputs`: :func:`constrained_partials`."""
    return {"dKKT": constrained_partials(derivation)}


__all__ = ["build_constrained_partials", "constrained_partials"]
