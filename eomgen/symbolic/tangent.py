"""Derivatives with respect to the configuration in tangent coordinates (issue 25).

A model's configuration ``q`` has NQ entries, its velocity ``v`` NV: a quaternion free flyer or
ball joint (:mod:`eomgen.model.quaternion`) holds four quaternion entries for three rotational
velocities. A derivative "with respect to q" is then, as in Pinocchio, the derivative along the
tangent: column ``i`` of ∂f/∂q is ``d/dε f(q ⊕ ε eᵢ)`` at ``ε = 0``, with
``q ⊕ δ`` :func:`eomgen.model.configuration.integrate` (the joint's pose times the exponential of
``δ`` in its own frame: ``M exp(δ)``), ``v`` and the other arguments held fixed (``v`` is the
body twist of the free flyer, the child-frame angular velocity of a ball joint).

The derivation's programs are functions of the configuration entries themselves (the chart of
:mod:`eomgen.symbolic.charts` is re-centred at each ``q``), so the tangent
derivative is the chain rule through ``∂(q ⊕ δ)/∂δ`` at ``δ = 0`` (:func:`tangent_seeds`):

* a one-axis joint's entry: 1 along its own direction;
* the free flyer's origin ``p``: ``R`` along the linear directions (``p ⊕ δ = p + R V(ω) v``,
  and ``V = 1`` to first order), 0 along the angular ones;
* a quaternion ``(x, y, z, w)``: ``½ (w eₖ + (x, y, z) × eₖ)`` and ``−½ (x, y, z)ₖ`` along
  the angular direction ``k`` (``q ⊗ (ω/2, 1)`` to first order). These directions are
  tangent to the sphere of the quaternion's norm, so they hold for a quaternion of any norm
  (the rotation is that of the normalised quaternion).

In the same chart ``δ ↦ q ⊕ δ`` the state equation's position rows are
``δ̇ = J_r(δ)⁻¹ v`` (``J_r`` the right Jacobian of the joint's group), whose derivative at
``δ = 0`` is :func:`velocity_transport`: ``−½ ad_v`` for the free flyer (SE(3)),
``−½ [ω]×`` for a ball joint (SO(3)), 0 for one-axis joints. Both walk the joints with a
chart, so they live with the chart's other maps (:mod:`eomgen.symbolic.charts`); this module
names them for the derivatives.
"""

from __future__ import annotations

from .charts import tangent_seeds, velocity_transport

__all__ = ["tangent_seeds", "velocity_transport"]
