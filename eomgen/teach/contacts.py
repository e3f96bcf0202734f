"""The handout's section on contacts: ``M q̈ + C q̇ + g = τ + J_cᵀ F_c``, ``J_c q̈ + J̇_c q̇ = 0``
and, for small models, ``J_c``, ``J̇_c q̇`` and the joint torques written out
(:func:`contact_equations`, printed by :func:`contact_section`).
"""

from __future__ import annotations

import sympy as sp

from ..model import POINT
from ..dynamics import Dynamics
from ..present import notation as nt
from ..present import readability as rd
from ..symbolic.frames import derive_frames
from ..symbolic.textbook import TextbookDerivation
from ..symbolic.trigonometry import simplify_trig
from .document import Equation, Equations, Paragraph, Section, code, prose
from .writer import Writer, compact_terms


_FORCE_AXES = ("f_x", "f_y", "f_z", "n_x", "n_y", "n_z")


def contact_forces(contacts) -> list[sp.Symbol]:
    """The symbols of ``F_c``, in the order of the rows of ``J_c``: ``f_x, f_y, f_z`` per
    point contact, ``f_x … n_z`` per surface contact (``eomgen_<axis>_<k>``, k 1-based)."""
    return [sp.Symbol(f"eomgen_{axis}_{k}", real=True)
            for k, c in enumerate(contacts, start=1) for axis in _FORCE_AXES[:c.size]]


def contact_symbol_names(contacts) -> dict[sp.Symbol, str]:
    """LaTeX of :func:`contact_forces`: ``f_{x}`` for one contact, ``f_{2,x}`` for several."""
    names = {}
    for symbol in contact_forces(contacts):
        _, letter, axis, k = symbol.name.split("_")
        names[symbol] = f"{letter}_{{{axis}}}" if len(contacts) == 1 else \
            f"{letter}_{{{k},{axis}}}"
    return names


def contact_equations(dyn: Dynamics, contacts, book: TextbookDerivation | None, coriolis):
    """The contact Jacobian ``J_c`` (m×n), ``J̇_c q̇`` (m×1), the forces ``F_c`` and the rows
    ``τ_i = (M q̈ + C q̇ + g)_i − (J_cᵀ F_c)_i`` as ``(lhs, terms)`` (names of
    :func:`~eomgen.teach.writer.compact_terms`), the contact terms grouped by force component.
    ``J_c`` and ``J̇_c q̇`` are the point contacts' linear rows of the world-aligned frame Jacobian and the
    surface contacts' body Jacobian (:func:`eomgen.symbolic.frames.derive_frames`), written out
    in the joint variables in the textbook form (small models only)."""
    model = dyn.model
    fk = derive_frames(model, list(dict.fromkeys(c.frame for c in contacts)))
    full = fk.program.expanded()
    rows, bias = [], []
    for c in contacts:
        kinds = ("J", "dJqd") if c.kind == POINT else ("Jb", "dJbqd")
        J, b = (fk.program.expand(fk.output(kind, c.frame), full) for kind in kinds)
        rows += [J[r, :] for r in range(c.size)]
        bias += [b[r] for r in range(c.size)]
    # fk's joint symbols are dyn's (same names and assumptions)
    Jc = sp.Matrix.vstack(*rows).applyfunc(lambda e: simplify_trig(e, fk.q))
    dJqd = sp.Matrix(bias).applyfunc(lambda e: simplify_trig(e, fk.q))
    F = contact_forces(contacts)
    equations = []
    for i in range(model.dof):
        entry, velocity, gi = compact_terms(dyn, book, coriolis, i)
        force = [-(F[r] * Jc[r, i]) for r in range(len(F)) if Jc[r, i] != 0]
        equations.append((sp.Symbol(f"tau{i + 1}", real=True), entry + velocity + gi + force))
    return Jc, dJqd, F, equations


def contact_section(dyn: Dynamics, contacts, book: TextbookDerivation | None, coriolis,
                     w: Writer) -> Section:
    described = []
    for k, c in enumerate(contacts):
        described += ([", "] if k else []) + [code(c.frame)]
        if c.kind == POINT:
            normal = nt.vector(w.p, [sp.Float(v, 15) for v in c.normal])
            described.append(" (a point: its origin is held still; force in world axes, N; "
                             f"normal ${normal}$)")
        else:
            described.append(" (a surface: the frame is held still; force and moment in the "
                             "frame's axes, N and N m)")
    blocks: list = [
        Paragraph(prose(
            "The scene holds ", *described, ". The contact force $F_{c}$ acts on the robot "
            "at the contact frame and enters the equations of motion through the contact "
            "Jacobian $J_{c}$ (the rows of the frame's Jacobian that the contact holds, "
            "$\\dot{p} = J_{c} \\dot{q}$ for a point), and the contact adds the constraint "
            "that the frame does not accelerate:")),
        Equations((
            Equation(r"M(q)\, \ddot{q} + C(q, \dot{q})\, \dot{q} + g(q)",
                     (r"\tau + J_{c}^{T} F_{c},",)),
            Equation(r"J_{c}(q)\, \ddot{q} + \dot{J}_{c}\, \dot{q}", (r"0.",)))),
    ]
    if book is None:
        blocks.append(Paragraph(prose(
            "For a robot of this size $J_{c}$ and $\\dot{J}_{c} \\dot{q}$ are not written out "
            "here; eomgen derives them as a program of named subexpressions "
            "(eomgen.symbolic.frames.derive_frames) and evaluates them numerically "
            "(eomgen.numeric.contacts).")))
        return Section("Contact", tuple(blocks))
    Jc, dJqd, F, equations = contact_equations(dyn, contacts, book, coriolis)
    angles = list(dyn.q)
    blocks.append(Paragraph(prose(
        "Here $F_{c} = " + nt.vector(w.p, F) + "$ and, differentiating the position of the "
        "contact frame (rows: the held directions; columns: the joints),")))
    blocks.append(Equations(w.matrix("J_{c}", Jc)))
    blocks.append(Paragraph(prose(
        "$\\dot{J}_{c} \\dot{q}$ is the acceleration of the contact frame at "
        "$\\ddot{q} = 0$:")))
    blocks.append(Equations(tuple(
        w.terms(rf"(\dot{{J}}_{{c}} \dot{{q}})_{{{r + 1}}}", rd.by_trig(dJqd[r], angles))
        for r in range(len(F)))))
    zero = [r for r in range(len(F)) if all(v == 0 for v in Jc[r, :])]
    if zero:
        blocks.append(Paragraph(prose(
            "Row" + ("s " if len(zero) > 1 else " ")
            + ", ".join(str(r + 1) for r in zero) + " of $J_{c}$ "
            + ("are" if len(zero) > 1 else "is") + " zero: no joint moves the frame in that "
            "direction, so the constraint holds by itself there and the force "
            + ", ".join(f"${w.tex(F[r])}$" for r in zero) + " is not determined by the "
            "motion (it does no work).")))
    blocks.append(Paragraph(prose(
        "Joint by joint, the torques that produce a motion $q(t)$ that keeps the contact, "
        "with the force $F_{c}$ the contact exerts, are $\\tau = M \\ddot{q} + C \\dot{q} + g - "
        "J_{c}^{T} F_{c}$ (entries as in step 8):")))
    blocks.append(Equations(tuple(w.terms(w.tex(lhs), terms) for lhs, terms in equations)))
    return Section("Contact", tuple(blocks))
