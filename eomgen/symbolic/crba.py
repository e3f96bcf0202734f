"""The mass matrix M(q) by the Composite-Rigid-Body Algorithm in body frames, as a straight-line
program.

Featherstone's CRBA (*Rigid Body Dynamics Algorithms*, 2008, Table 6.2): composite inertias
``I^c_i = I_i + Σ_children X_cᵀ I^c_c X_c`` from the leaves to the root, then for each body
``F = I^c_i S_i``, ``M_ii = S_iᵀ F`` and, walking up the ancestors j of i, ``F ← X_jᵀ F``
(force to the parent), ``M_ji = M_ij = S_jᵀ F``. O(n) composite inertias and O(n·depth) force
transforms: O(n²) operations for a chain.

Everything is in body coordinates about the body origin (see :mod:`eomgen.symbolic.aba` for
the spatial conventions), so every vector is link-sized: no quantity is referred to a far-away
root origin. The inertial parameters are the grouped ones of
:func:`~eomgen.symbolic.newton_euler.grouped_inertials`, which give exactly the same M(q).
"""

from __future__ import annotations

import sympy as sp

from ..model.bodies import BodyTree
from ..model import RobotModel
from .derivation import new_derivation
from .newton_euler import grouped_inertials
from .program import Program, ProgramBuilder, name_expr, name_exprs, name_matrix, name_symmetric
from .spatial import JointFrames, dot, joint_subspace, matvec, skew, transpose

_ZERO = sp.Integer(0)


def M_program(tree: BodyTree, q, b: ProgramBuilder, grouped: bool = True) -> sp.Matrix:
    """Build M(q) into ``b`` by the body-frame CRBA; returns the symmetric n×n matrix
    [kg m², kg m, kg] in ``JOINT_NAMES`` order."""
    n = len(tree.bodies)
    frames = JointFrames.named(tree, q, b)
    inertials = grouped_inertials(tree) if grouped else [body.inertial for body in tree.bodies]
    IC = []
    for par in inertials:
        h, m = par.first_moment, par.mass
        IC.append([par.inertia, skew(h), tuple(tuple(m if r == c else _ZERO for c in range(3))
                                          for r in range(3))])

    def subspace(i):
        return joint_subspace(tree.bodies[i].joint)

    M = sp.zeros(n, n)
    for i in reversed(range(n)):
        body = tree.bodies[i]
        tag = body.q_index + 1
        A = name_symmetric(b, IC[i][0], f"Ic{tag}_A", ("Icb", tag, 0))
        B = name_matrix(b, IC[i][1], f"Ic{tag}_B", ("Icb", tag, 1))
        C = name_symmetric(b, IC[i][2], f"Ic{tag}_C", ("Icb", tag, 2))
        S_ang, S_lin = subspace(i)
        Bt = transpose(B)
        F_n = name_exprs(b, tuple(x + y for x, y in zip(matvec(A, S_ang), matvec(B, S_lin))),
                        f"F{tag}_{tag}n", ("Fbody", tag, tag, 0))
        F_f = name_exprs(b, tuple(x + y for x, y in zip(matvec(Bt, S_ang), matvec(C, S_lin))),
                        f"F{tag}_{tag}f", ("Fbody", tag, tag, 1))
        M[body.q_index, body.q_index] = name_expr(b, dot(S_ang, F_n) + dot(S_lin, F_f),
                                              f"M{tag}_{tag}", ("M", tag, tag))
        j = i
        while tree.bodies[j].parent >= 0:
            F_n, F_f = frames.force_to_parent(j, F_n, F_f)
            j = tree.bodies[j].parent
            other = tree.bodies[j].q_index
            F_n = name_exprs(b, F_n, f"F{other + 1}_{tag}n", ("Fbody", other + 1, tag, 0))
            F_f = name_exprs(b, F_f, f"F{other + 1}_{tag}f", ("Fbody", other + 1, tag, 1))
            S_ang, S_lin = subspace(j)
            value = name_expr(b, dot(S_ang, F_n) + dot(S_lin, F_f), f"M{other + 1}_{tag}",
                          ("M", other + 1, tag))
            M[other, body.q_index] = M[body.q_index, other] = value
        if body.parent >= 0:
            A_p, B_p, C_p = frames.inertia_to_parent(i, A, B, C, b, tag)
            p = body.parent
            IC[p] = [tuple(tuple(x + y for x, y in zip(r1, r2)) for r1, r2 in zip(IC[p][0], A_p)),
                     tuple(tuple(x + y for x, y in zip(r1, r2)) for r1, r2 in zip(IC[p][1], B_p)),
                     tuple(tuple(x + y for x, y in zip(r1, r2)) for r1, r2 in zip(IC[p][2], C_p))]
    return M


def crba_program(model: RobotModel) -> tuple[tuple[sp.Symbol, ...], Program]:
    """M(q) of ``model`` by the body-frame CRBA: ``(q symbols, program with output "M")``.

    Examples
    --------
    >>> import eomgen
    >>> from eomgen.symbolic.crba import crba_program
    >>> q, program = crba_program(eomgen.load(eomgen.example_path("planar_2link")))
    >>> program.output("M").shape
    (2, 2)
    """
    d = new_derivation(model, ("q",))
    return d.q, d.program([("M", M_program(d.tree, d.q, d.builder))])

