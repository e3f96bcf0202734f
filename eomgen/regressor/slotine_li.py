"""The builder of the generated Slotine–Li regressor functions (registered in
:mod:`eomgen.outputs`): ``slotine_li_regressor`` (Y_SL, n × p, the columns of the joint torque
regressor) and ``slotine_li_base_regressor`` (its base columns, n × b).

Y_SL π depends on π only through the base parameters β: M, and with it the Christoffel C, and g
are determined by τ = Y π (M's columns are τ(q, 0, e_i) − g, g = τ(q, 0, 0)), so every π with
Y π ≡ 0 has Y_SL π ≡ 0 too, and the grouping that gives Y π = Y_base β gives Y_SL π =
Y_SL[:, base] β with the same columns and the same β (docs/control.md).

Joints whose configuration is not their coordinates (a free flyer, ball joints:
:mod:`eomgen.model.quaternion`): q̇_r and q̈_r are quasi-velocities like v (the root twist, the
ball's angular velocity in the child frame) and C is the matrix of Pinocchio's
``computeCoriolisMatrix``, the chart's Christoffel matrix plus ``M[:, cols] K(v)`` in each such
joint's columns (:mod:`eomgen.symbolic.charts`). The program walks the chart, so it is given
``q̈_r + K(v) q̇_r`` in place of ``q̈_r``: ``M (q̈_r + K q̇_r) + C_chart q̇_r + g = M q̈_r + C
q̇_r + g``; at ``q̇_r = v`` this is ``q̈ − n(v)``, the chart accelerations of the joint torque
regressor (``K(v) v = −n(v)``).
"""

from __future__ import annotations

import sympy as sp

from ..symbolic.builders import builds
from ..symbolic.charts import chart_reference_accelerations
from ..symbolic.slotine_li import slotine_li_program
from .generated import declared_actuator_terms, generated_base


@builds("Y_SL", "Y_SL_base")
def build_slotine_li(derivation, wanted) -> dict:
    """``Y_SL`` (n × p) and ``Y_SL_base`` (n × b), those in ``wanted``, built by
    :func:`eomgen.symbolic.slotine_li.slotine_li_program` into the derivation's program with
    the actuator columns the model declares (:func:`declared_actuator_terms`)."""
    model = derivation.model
    qd_r = derivation.tangent(derivation.inputs["qd_r"])
    qdd_r = chart_reference_accelerations(model, derivation.qd, qd_r,
                                          derivation.tangent(derivation.inputs["qdd_r"]))
    Y = slotine_li_program(derivation.tree, derivation.q, derivation.qd, qd_r, qdd_r,
                           model.gravity, derivation.builder, declared_actuator_terms(model))
    out: dict[str, sp.Matrix] = {}
    if "Y_SL" in wanted:
        out["Y_SL"] = Y
    if "Y_SL_base" in wanted:
        out["Y_SL_base"] = Y.extract(list(range(Y.rows)), list(generated_base(model).columns))
    return out


__all__ = ["build_slotine_li", "chart_reference_accelerations"]
