"""Step 6 of the handout: the Christoffel symbols and the Coriolis matrix C, written with the
common factors the symbols share (``h₁``, …) and grouped by body mass as M is."""

from __future__ import annotations

import sympy as sp

from ..dynamics import Dynamics
from ..present import readability as rd
from ..present.grouping import body_masses
from ..symbolic.textbook import TextbookDerivation
from .control import handout_check
from .document import Equations, Paragraph, Section, prose
from .writer import Writer


def named_coriolis(dyn: Dynamics, book: TextbookDerivation, check: bool = True):
    """The names of the common factors of the Christoffel symbols (see
    :func:`~eomgen.teach.readability.common_christoffel_factors`; none when a parameter is
    already called ``h``…), the Christoffel symbols written with them, and C written with them
    (checked equal to the derived C unless ``check`` is false: :func:`handout_check`)."""
    n = dyn.model.dof
    taken = {p.name for p in dyn.model.parameters}
    names = [] if taken & {"h", "h1", "h2", "h3", "h4"} else rd.common_christoffel_factors(
        [value for _, value in book.christoffel])
    christoffel = [(key, rd.in_terms_of(value, names)) for key, value in book.christoffel]
    C = sp.zeros(n, n)
    for (i, j, k), value in christoffel:
        C[i, j] += value * dyn.qd[k]
        if j != k:
            C[i, k] += value * dyn.qd[j]
    C = C.applyfunc(sp.factor_terms)
    values = {nf.symbol: nf.value for nf in names}
    if check:
        handout_check(dyn, "C written with named factors equals the derived C",
                      (C.subs(values) - book.C).applyfunc(sp.expand), book.C)
    return names, christoffel, C


def coriolis_section(book: TextbookDerivation, coriolis, w: Writer) -> Section:
    names, christoffel, C = coriolis
    blocks = [Paragraph(prose(
        "The Christoffel symbols of the first kind are "
        "$\\Gamma_{i,j,k} = \\tfrac{1}{2} \\bigl(\\partial M_{i,j} / \\partial q_{k} + "
        "\\partial M_{i,k} / \\partial q_{j} - \\partial M_{j,k} / \\partial q_{i}\\bigr)$, "
        "symmetric in $j, k$ (so each is shown once); those not listed are zero."))]
    if names:
        blocks.append(Paragraph(prose(
            "They are all multiples of " + ("one expression" if len(names) == 1 else
                                              f"{len(names)} expressions") + ", named:")))
        masses = body_masses(book)
        blocks.append(Equations(tuple(w.terms(w.tex(nf.symbol), rd.by_mass(nf.value, masses))
                                      for nf in names)))
    masses = body_masses(book)
    equations = []
    for (i, j, k), value in christoffel:  # grouped by body mass, as M and the names are
        lhs = rf"\Gamma_{{{i + 1},{j + 1},{k + 1}}}"
        if j != k:
            lhs += rf" = \Gamma_{{{i + 1},{k + 1},{j + 1}}}"
        equations.append(w.terms(lhs, rd.by_mass(value, masses)))
    blocks.append(Equations(tuple(equations)) if equations else
                  Paragraph(prose("All Christoffel symbols are zero.")))
    blocks.append(Paragraph(prose(
        "The Coriolis matrix is $C_{i,j} = \\sum_{k} \\Gamma_{i,j,k}\\, \\dot{q}_{k}$ "
        "(with this choice, $\\dot{M} - 2C$ is skew-symmetric):")))
    if names or not equations:
        blocks.append(Equations(w.matrix("C", C)))
    else:  # entry by entry, each Γ as printed above (grouped by mass) times its velocity
        blocks.append(Equations(tuple(
            w.terms(f"C_{{{i + 1},{j + 1}}}", terms)
            for (i, j), terms in coriolis_terms(christoffel, book.qd, masses).items())))
    return Section("Step 6: Christoffel symbols and the Coriolis matrix", tuple(blocks))


def coriolis_terms(christoffel, qd, masses) -> dict[tuple[int, int], list[sp.Expr]]:
    """The non-zero entries of ``C_{i,j} = Σ_k Γ_{i,j,k} q̇_k`` as lists of terms
    ``q̇_k (Γ_{i,j,k} grouped by body mass)``, in the order of ``christoffel`` (``Γ_{i,j,k}``
    with ``j ≤ k``, 0-based), for the handout to print with the Christoffel symbols' form."""
    entries: dict[tuple[int, int], dict[int, sp.Expr]] = {}
    for (i, j, k), value in christoffel:
        for a, b in ((j, k), (k, j)) if j != k else ((j, k),):
            entries.setdefault((i, a), {})[b] = value
    out = {}
    for (i, j) in sorted(entries):
        terms = []
        for k, value in sorted(entries[i, j].items()):
            grouped = rd.mass_grouped(value, masses)
            if grouped.is_Add:  # q̇_k (the sum)
                terms.append(sp.Mul(qd[k], grouped, evaluate=False))
                continue
            negative = grouped.could_extract_minus_sign()  # Γ's product as above, then q̇_k
            term = sp.Mul(-grouped if negative else grouped, qd[k], evaluate=False)
            terms.append(sp.Mul(-1, term, evaluate=False) if negative else term)
        out[i, j] = terms
    return out


__all__ = ["coriolis_section", "coriolis_terms", "named_coriolis"]
