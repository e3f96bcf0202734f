"""M(q), C(q, q̇) q̇ and g(q) in one straight-line program, from the O(n) and O(n²) recursions.

One call that wants several quantities shares their common work (sines and cosines, rotations,
the gravity part of the accelerations): M by the body-frame CRBA
(:mod:`eomgen.symbolic.crba`), ``g = τ(q, 0, 0)`` and ``C q̇ + g = τ(q, q̇, 0)`` by the
Newton–Euler program (:mod:`eomgen.symbolic.newton_euler`), so ``C q̇ = τ(q, q̇, 0) − g``.
The Coriolis *matrix* C (Christoffel symbols, Ṁ − 2C skew-symmetric) is not produced here: its
product with q̇ is what forward dynamics and computed-torque control need, and it costs O(n)
instead of the O(n²) of the matrix (:func:`eomgen.symbolic.composite.coriolis_program`).

Outputs: ``"M"`` (n×n), ``"Cqd"`` (n×1, C(q, q̇) q̇), ``"g"`` (n×1), in ``JOINT_NAMES`` order,
SI units (N m or N for the vectors).
"""

from __future__ import annotations

import sympy as sp

from ..model import RobotModel
from ..outputs import BY_SYMBOL
from .builders import builds
from .crba import M_program
from .derivation import new_derivation
from .newton_euler import inverse_dynamics_program
from .program import Program, name_expr


def dynamics_program(model: RobotModel) -> tuple[tuple, tuple, Program]:
    """``(q symbols, q̇ symbols, program)`` with outputs ``M``, ``Cqd`` and ``g`` of ``model``.

    Examples
    --------
    >>> import eomgen
    >>> from eomgen.symbolic.combined import dynamics_program
    >>> q, qd, program = dynamics_program(eomgen.load(eomgen.example_path("planar_2link")))
    >>> [name for name, _ in program.outputs]
    ['M', 'Cqd', 'g']
    """
    d = new_derivation(model, ("q", "qd"))
    n, q, qd, b, tree = model.dof, d.q, d.qd, d.builder, d.tree
    zero = (sp.Integer(0),) * n
    M = M_program(tree, q, b)
    g = inverse_dynamics_program(tree, q, zero, zero, model.gravity, b)
    bias = inverse_dynamics_program(tree, q, qd, d.accelerations(zero), model.gravity, b)
    Cqd = sp.Matrix([[name_expr(b, bias[k, 0] - g[k, 0], f"Cqd{k + 1}", ("Cqd", k + 1))]
                     for k in range(n)])
    outputs = (("M", M), ("Cqd", Cqd), ("g", g))
    return q, qd, d.program(outputs)


@builds("h")
def build_nonlinear_effects(derivation, wanted) -> dict:
    """The builder of ``h`` in :mod:`eomgen.outputs` (``nonlinear_effects(q, qd)``):
    h = C(q, q̇) q̇ + g(q) = τ(q, q̇, 0), one Newton–Euler pass with q̈ = 0 [N m or N] (what
    Pinocchio's ``nonLinearEffects`` returns), without forming C."""
    zero = (sp.Integer(0),) * len(derivation.q)
    return {"h": inverse_dynamics_program(derivation.tree, derivation.q, derivation.qd,
                                          derivation.accelerations(zero),
                                          derivation.model.gravity, derivation.builder)}


@builds("MCg", "Mh")
def build_combined(derivation, wanted) -> dict:
    """The builder of the several-result functions of :mod:`eomgen.outputs` (``returns``):
    ``MCg`` = [M | C | g] (n × (2n + 1)), returned as (M, C, g), and ``Mh`` = [M | h]
    (n × (n + 1)), returned as (M, h): the results side by side from the outputs already in
    the program (``derivation.output``), so that they are the separate functions' own results
    and share every intermediate; the generated module splits them into tuples."""
    result = {}
    for symbol in wanted:
        parts = BY_SYMBOL[symbol].returns
        result[symbol] = sp.Matrix.hstack(*(derivation.output(p) for p in parts))
    return result
