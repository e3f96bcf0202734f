"""The dynamics of a model with coupled joints, in its independent coordinates.

A model with couplings (:mod:`eomgen.model.coupling`) is derived on its whole tree: the
derivation's joint coordinates are ``q_full = T q + c``, its velocities ``T q̇`` and its
accelerations ``T q̈`` (:func:`coupled_inputs`), so every algorithm runs unchanged in the full
coordinates. Each output then goes through :func:`project`, the one place that turns a
full-coordinate result into the independent coordinates, by what its rows and columns are
(:data:`PROJECTIONS`):

* rows that are joint efforts (τ, g, C q̇ + g, M's rows, Y's rows) are multiplied by ``Tᵀ``
  (virtual work: ``δqᵀ_full τ = δqᵀ Tᵀ τ``);
* columns that multiply joint velocities (M's, C's columns, Jacobians) by ``T``.

So ``M_r = Tᵀ M T``, ``C_r = Tᵀ C(T q + c, T q̇) T`` (exactly the Christoffel C of the reduced
Lagrangian: the symbols ``c_ijk`` are multilinear in the directions, and ``T`` is constant),
``g_r = Tᵀ g``, ``τ_r = Tᵀ τ(T q + c, T q̇, T q̈)``, ``Y_r = Tᵀ Y``, ``J_r = J T``. Outputs
absent from the table are refused under couplings (:func:`refused`): the ABA solves the
unconstrained tree, the base regressor's columns are those of the uncoupled tree, the flexible
joints' motor states are per joint. (Y_SL: its ``q̇_r``, ``q̈_r`` enter as ``T q̇_r``,
``T q̈_r``, :meth:`~eomgen.symbolic.derivation.Derivation.tangent`.)

The derivatives of the dynamics (:mod:`eomgen.symbolic.derivatives`) are built in the
independent coordinates already, so they pass unprojected: ``τ_r``'s program is differentiated
in forward mode along the independent ``q``, ``q̇`` (a follower's entry ``Σ k q_leader + c``
carries its gains, so ``∂τ_r/∂q_r = Tᵀ ∂τ/∂q T`` exactly), and ``M_r⁻¹`` (no ABA) comes from
the straight-line LDLᵀ factors of ``M_r = Tᵀ M T`` (:func:`independent` gives the tangent
directions of the independent coordinates).
"""

from __future__ import annotations

import sympy as sp

from ..model.coupling import coupling_map, full_configuration, uncoupled
from ..outputs import BY_SYMBOL, splits
from .charts import independent_view

#: Per output symbol: ``(rows, columns)``, whether its rows are joint efforts (× Tᵀ) and its
#: columns joint velocities (× T). Outputs not listed are refused under couplings.
PROJECTIONS: dict[str, tuple[bool, bool]] = {
    "M": (True, True), "C": (True, True), "g": (True, False), "P": (False, False),
    "tau": (True, False), "h": (True, False),
    "M_a": (True, True), "tau_f": (True, False), "tau_f_smooth": (True, False),
    "tau_a": (True, False), "tau_p": (True, False), "tau_act": (True, False),
    "Y": (True, False), "Y_SL": (True, False), "pi": (False, False), "Y_K": (False, False), "Y_P": (False, False),
    "p_f": (False, False), "R_f": (False, False), "J_f": (False, True),
    "Jb_f": (False, True), "dJqd_f": (False, False), "dJbqd_f": (False, False),
    "J_c": (False, True), "dJqd_c": (False, False), "tau_c": (True, False),
    "Phi_l": (False, False), "J_l": (False, True), "dJqd_l": (False, False),
    "cone_c": (False, False), "pyramid_c": (False, False),
    "c_G": (False, False), "J_G": (False, True), "A_G": (False, True), "dAGv": (False, False),
    "I_G": (False, False),
    # the derivatives, built in the independent coordinates (eomgen.symbolic.derivatives)
    "dtau_dq": (False, False), "dtau_dqd": (False, False), "dg_dq": (False, False),
    "dqdd_dq": (False, False), "dqdd_dqd": (False, False), "Minv": (False, False),
    "A_lin": (False, False), "B_lin": (False, False), "dtau_a_dqd": (False, False),
    "dqdd_a_dq": (False, False), "dqdd_a_dqd": (False, False), "Minv_a": (False, False),
    # the controls' forward dynamics, built in the independent coordinates too
    # (eomgen.symbolic.controls: M_a⁻¹ Tᵀ (τ_act + τ_p − h) from the LDLᵀ factors)
    "qdd_ctrl": (False, False), "dqdd_dctrl": (False, False), "dqdd_ctrl_dq": (False, False),
    "dqdd_ctrl_dqd": (False, False), "xd_act": (False, False), "dxd_act": (False, False),
    "A_act": (False, False), "B_act": (False, False),
}

#: Several-result outputs (:attr:`eomgen.outputs.Output.returns`) projected block by block.
COMBINED = ("MCg", "Mh", "dtau", "dqdd", "AB", "dtau_a", "dqdd_a", "dqdd_ctrl_dx")


def supported(symbol: str) -> bool:
    """Whether output ``symbol`` is derived under couplings."""
    if symbol in COMBINED:
        return all(s in PROJECTIONS for s in BY_SYMBOL[symbol].returns)
    return symbol in PROJECTIONS


def refused(symbols) -> list[str]:
    """The symbols of ``symbols`` not derived under couplings, sorted."""
    return sorted(s for s in symbols if not supported(s))


def coupled_inputs(model, q, qd):
    """``(full model, T, q_full, qd_full)`` of a model with couplings and the symbols of its
    independent ``q`` (NQ) and ``qd`` (NV): the model the algorithms walk (every movable
    joint a coordinate), the full configuration (the whole tree's NQ entries,
    :func:`eomgen.model.coupling.full_configuration`: a quaternion joint's block copied, a
    follower's entry ``Σ k q_leader + c``) and the full velocities ``T q̇``.

    ``T`` (NV_full × NV) acts on velocities: a quaternion joint's velocity coordinates are
    never coupled, so their rows are unit rows and the map is exact on the joint's tangent
    space as well."""
    T, _ = coupling_map(model)
    q_full = full_configuration(model, tuple(q))
    qd_full = tuple(T * sp.Matrix(qd))
    return uncoupled(model), T, q_full, qd_full


def project(symbol: str, matrix: sp.Matrix, T: sp.Matrix) -> sp.Matrix:
    """Output ``symbol``'s full-coordinate ``matrix`` in the independent coordinates (see the
    module docstring).

    Raises
    ------
    KeyError
        For a symbol not derived under couplings (callers check :func:`supported` first).
    """
    if symbol in COMBINED:
        output = BY_SYMBOL[symbol]
        if not any(any(PROJECTIONS[part]) for part in output.returns):
            return matrix  # built in the independent coordinates (the derivatives)
        blocks = []
        for part, start, end in splits(output, T.rows):
            block = matrix[:, start:start + 1] if end is None else matrix[:, start:end]
            blocks.append(project(part, block, T))
        return sp.Matrix.hstack(*blocks)
    rows, columns = PROJECTIONS[symbol]
    if rows:
        matrix = T.T * matrix
    if columns:
        matrix = matrix * T
    return matrix


def independent(derivation):
    """What :func:`eomgen.symbolic.tangent.tangent_seeds` and
    :func:`~eomgen.symbolic.tangent.velocity_transport` read of ``derivation``, in the
    independent coordinates: ``derivation`` itself without couplings; with couplings a view
    whose joints with a chart are numbered in the independent ``q`` and ``v``
    (:func:`eomgen.symbolic.charts.independent_view`)."""
    return derivation if derivation.coupling is None else independent_view(derivation)


__all__ = ["COMBINED", "PROJECTIONS", "coupled_inputs", "independent", "project", "refused",
           "supported"]
