"""The handout's section on loop closures: the constraint ``Φ(q) = 0``, its Jacobian ``J_l``,
the Lagrange multipliers ``λ`` (the loop forces) in ``M q̈ + C q̇ + g = τ + J_lᵀ λ``,
``J_l q̈ + J̇_l q̇ = 0`` and the KKT system; for small models ``Φ``, ``J_l``, ``J̇_l q̇`` and the
joint torques written out (:func:`loop_equations`, printed by :func:`loop_section`).
"""

from __future__ import annotations

import sympy as sp

from ..dynamics import Dynamics, derive
from ..present import notation as nt
from ..present import readability as rd
from ..symbolic.textbook import TextbookDerivation
from ..symbolic.trigonometry import simplify_trig
from .document import Equation, Equations, Paragraph, Section, code, prose
from .writer import Writer, compact_terms


def loop_forces(model) -> list[sp.Symbol]:
    """The multipliers ``λ``, one per loop row (``eomgen_lambda_<k>``, k 1-based)."""
    rows = [r for loop in model.loops for r in loop.rows]
    return [sp.Symbol(f"eomgen_lambda_{k}", real=True) for k in range(1, len(rows) + 1)]


def loop_symbol_names(model) -> dict[sp.Symbol, str]:
    """LaTeX of :func:`loop_forces`: ``λ_{k}``."""
    return {s: rf"\lambda_{{{s.name.rsplit('_', 1)[1]}}}" for s in loop_forces(model)}


def loop_equations(dyn: Dynamics, book: TextbookDerivation | None, coriolis):
    """``Φ`` (m×1), ``J_l`` (m×n), ``J̇_l q̇`` (m×1) of the model's loops
    (:mod:`eomgen.symbolic.loops`) in the joint variables, the multipliers ``λ`` and the rows
    ``τ_i = (M q̈ + C q̇ + g)_i − (J_lᵀ λ)_i`` as ``(lhs, terms)``."""
    model = dyn.model
    rows = derive(model, outputs=("Phi_l", "J_l", "dJqd_l"), simplify=False)
    full = rows.program.expanded()
    Phi, J, bias = (rows.program.expand(rows.program.output(s), full).applyfunc(
        lambda e: simplify_trig(e, rows.q)) for s in ("Phi_l", "J_l", "dJqd_l"))
    lam = loop_forces(model)
    equations = []
    for i in range(model.dof):
        entry, velocity, gi = compact_terms(dyn, book, coriolis, i)
        force = [-(lam[r] * J[r, i]) for r in range(len(lam)) if J[r, i] != 0]
        equations.append((sp.Symbol(f"tau{i + 1}", real=True), entry + velocity + gi + force))
    return Phi, J, bias, lam, equations


def loop_section(dyn: Dynamics, book: TextbookDerivation | None, coriolis, w: Writer) -> Section:
    model = dyn.model
    described = []
    for k, loop in enumerate(model.loops):
        described += ([", "] if k else []) + [code(loop.name), f" (a {loop.kind}"
                                              + (", planar" if loop.plane is not None else "")
                                              + ": frame b on link ", code(loop.b.link),
                                              " held on frame a on link ", code(loop.a.link), ")"]
    blocks: list = [
        Paragraph(prose(
            "The tree of joints is cut at one joint of each closed loop; the scene closes "
            "them again: ", *described, ". Each loop is a constraint on the joint "
            "variables, $\\Phi(q) = 0$ (the position of frame b less that of frame a, in the "
            "directions the cut joint held), so the joint variables are no longer independent. "
            "Lagrange's method with multipliers adds $\\lambda^{T} \\Phi(q)$ to the Lagrangian; "
            "with $J_{l} = \\partial \\Phi / \\partial q$ the equations of motion gain the "
            "force $J_{l}^{T} \\lambda$, and differentiating $\\Phi(q(t)) = 0$ twice gives the "
            "constraint on the accelerations:")),
        Equations((
            Equation(r"M(q)\, \ddot{q} + C(q, \dot{q})\, \dot{q} + g(q)",
                     (r"\tau + J_{l}^{T} \lambda,",)),
            Equation(r"J_{l}(q)\, \ddot{q} + \dot{J}_{l}\, \dot{q}", (r"0.",)))),
        Paragraph(prose(
            "The multipliers $\\lambda$ are the forces the cut joint carries (on frame b's "
            "link; its opposite on frame a's). Given $\\tau$, the accelerations and the loop "
            "forces solve one linear system (KKT):")),
        Equations((Equation(
            r"\begin{bmatrix} M & -J_{l}^{T} \\ J_{l} & 0 \end{bmatrix}"
            r"\begin{bmatrix} \ddot{q} \\ \lambda \end{bmatrix}",
            (r"\begin{bmatrix} \tau - C \dot{q} - g \\ -\dot{J}_{l} \dot{q} \end{bmatrix}.",)),)),
    ]
    if book is None:
        blocks.append(Paragraph(prose(
            "For a robot of this size $\\Phi$, $J_{l}$ and $\\dot{J}_{l} \\dot{q}$ are not "
            "written out here; eomgen derives them as a program of named subexpressions "
            "(eomgen.symbolic.loops) and evaluates them numerically (eomgen.numeric.loops).")))
        return Section("Loop closures", tuple(blocks))
    Phi, J, bias, lam, equations = loop_equations(dyn, book, coriolis)
    angles = list(dyn.q)
    blocks.append(Paragraph(prose(
        "Here $\\lambda = " + nt.vector(w.p, lam) + "$ and the loop constraint is")))
    blocks.append(Equations(tuple(
        w.terms(rf"\Phi_{{{r + 1}}}", rd.by_trig(Phi[r], angles)) for r in range(len(lam)))))
    blocks.append(Paragraph(prose(
        "Its Jacobian (rows: the loop's directions; columns: the joints) and $\\dot{J}_{l} "
        "\\dot{q}$, the relative acceleration at $\\ddot{q} = 0$:")))
    blocks.append(Equations(w.matrix("J_{l}", J)))
    blocks.append(Equations(tuple(
        w.terms(rf"(\dot{{J}}_{{l}} \dot{{q}})_{{{r + 1}}}", rd.by_trig(bias[r], angles))
        for r in range(len(lam)))))
    actuated = set(model.actuated or model.joint_names)
    passive = [k + 1 for k, name in enumerate(model.joint_names) if name not in actuated]
    blocks.append(Paragraph(prose(
        "Joint by joint, the torques that produce a motion $q(t)$ that keeps the loops closed, "
        "with the loop forces $\\lambda$, are $\\tau = M \\ddot{q} + C \\dot{q} + g - "
        "J_{l}^{T} \\lambda$:")))
    blocks.append(Equations(tuple(w.terms(w.tex(lhs), terms) for lhs, terms in equations)))
    if passive:
        blocks.append(Paragraph(prose(
            "The passive joints (" + ", ".join(f"$q_{{{k}}}$" for k in passive) + ") carry "
            "no torque: setting their $\\tau_i = 0$ gives as many equations as loop rows, "
            "which fix $\\lambda$ for a desired motion; the actuated joints' rows then give "
            "their torques (the inverse dynamics of a parallel robot).")))
    return Section("Loop closures", tuple(blocks))
