"""The builder of the generated Slotine–Li regressor functions (registered in
:mod:`eomgen.outputs`): ``slotine_li_regressor`` (Y_SL, n × p, the columns of the joint torque
regressor) and ``slotine_li_base_regressor`` (its base columns, n × b).

Y_SL π depends on π only through the base parameters β: M, and with it the Christoffel C, and g
are determined by τ = Y π (M's columns are τ(q, 0, e_i) − g, g = τ(q, 0, 0)), so every π with
Y π ≡ 0 has Y_SL π ≡ 0 too, and the grouping that gives Y π = Y_base β gives Y_SL π =
Y_SL[:, base] β with the same columns and the same β (docs/control.md).
"""

from __future__ import annotations

import sympy as sp

from ..symbolic.slotine_li import slotine_li_program
from .generated import declared_actuator_terms, generated_base


def build_slotine_li(derivation, wanted) -> dict:
    """``Y_SL`` (n × p) and ``Y_SL_base`` (n × b), those in ``wanted``, built by
    :func:`eomgen.symbolic.slotine_li.slotine_li_program` into the derivation's program with
    the actuator columns the model declares (:func:`declared_actuator_terms`)."""
    model = derivation.model
    Y = slotine_li_program(derivation.tree, derivation.q, derivation.qd,
                           derivation.tangent(derivation.inputs["qd_r"]),
                           derivation.tangent(derivation.inputs["qdd_r"]), model.gravity,
                           derivation.builder, declared_actuator_terms(model))
    out: dict[str, sp.Matrix] = {}
    if "Y_SL" in wanted:
        out["Y_SL"] = Y
    if "Y_SL_base" in wanted:
        out["Y_SL_base"] = Y.extract(list(range(Y.rows)), list(generated_base(model).columns))
    return out


__all__ = ["build_slotine_li"]
