"""How the handout writes equations: :class:`Writer` prints them with the document's printer
(:func:`eomgen.present.notation.printing`), and :func:`compact_terms` writes a row of
``M q̈ + C q̇ + g`` in the names of the entries (``M_{i,j}``, ``C_{i,j}``, ``g_{i}``, step 6's
named factors; :func:`abbreviation_values` says what they stand for), which the equations of
motion, the drives and the contacts sections all end with.
"""

from __future__ import annotations

import sympy as sp

from ..dynamics import Dynamics
from ..present import notation as nt
from ..present import readability as rd
from ..symbolic.textbook import TextbookDerivation
from .document import Equation, Span, code, math


class Writer:
    """Builds equations with the document's printer."""

    def __init__(self, p: nt.Printing):
        self.p = p

    def tex(self, expr) -> str:
        return self.p.tex(expr)

    def eq(self, lhs: str, expr) -> Equation:
        return self.convert([self.p.equation(lhs, expr)])[0]

    def terms(self, lhs: str, terms: list) -> Equation:
        """``lhs =`` the sum of ``terms`` in the given order."""
        lines = self.p.printer.print_sum_lines(terms or [sp.Integer(0)], self.p.width)
        return Equation(lhs, tuple(lines))

    def matrix(self, lhs: str, matrix: sp.Matrix) -> tuple[Equation, ...]:
        return self.convert(nt.matrix_equations(self.p, lhs, matrix))

    @staticmethod
    def convert(equations) -> tuple[Equation, ...]:
        """The LaTeX backend's equations as the handout's."""
        return tuple(Equation(e.lhs, tuple(e.lines)) for e in equations)


def vector_span(w: Writer, values) -> Span:
    """``values`` as a LaTeX vector ``(a, b, c)`` in the handout's notation."""
    return math(nt.vector(w.p, values))


def code_names(names) -> list:
    """``names`` as code spans separated by commas, for :func:`~eomgen.teach.document.prose`."""
    out: list = []
    for k, name in enumerate(names):
        out += ([", "] if k else []) + [code(name)]
    return out




def compact_terms(dyn: Dynamics, book: TextbookDerivation | None, coriolis, i: int):
    """Row ``i`` of ``M q̈ + C q̇ + g`` as a student writes it with the entries' names: the
    terms ``M_{i,j} q̈_j``, the velocity terms and ``g_i`` (three lists). With the textbook
    derivation (``book`` and ``coriolis``) the velocity terms are those of step 6, grouped by
    its named factors and zero entries are left out; without it (large models) they are
    ``C_{i,j} q̇_j``. The names are the symbols ``M<i>_<j>`` (``i ≤ j``), ``C<i>_<j>``,
    ``g<i>`` (see :func:`abbreviation_values`)."""
    n = dyn.model.dof
    qd, qdd = dyn.qd, dyn.qdd
    M = book.M if book is not None else None
    entry = [sp.Symbol(f"M{min(i, j) + 1}_{max(i, j) + 1}") * qdd[j]
             for j in range(n) if M is None or M[i, j] != 0]
    if book is None:
        velocity = [sp.Symbol(f"C{i + 1}_{j + 1}") * qd[j] for j in range(n)]
        return entry, velocity, [sp.Symbol(f"g{i + 1}")]
    names, _, C = coriolis
    symbols = [nf.symbol for nf in names]
    Cqd = sp.expand(sum((C[i, j] * qd[j] for j in range(n)), sp.Integer(0)))
    velocity = rd.group_by_factor(Cqd, lambda t: next((h for h in symbols if t.has(h)), None))
    return entry, velocity, ([sp.Symbol(f"g{i + 1}")] if book.g[i] != 0 else [])


def abbreviation_values(dyn: Dynamics, coriolis=None) -> dict[sp.Symbol, sp.Expr]:
    """What the names of :func:`compact_terms` stand for: ``M<i>_<j>``, ``C<i>_<j>``,
    ``g<i>`` of ``dyn`` and the named Christoffel factors of ``coriolis`` (for checks:
    ``expr.subs(values)`` is in joint variables and parameters only)."""
    n = dyn.model.dof
    values: dict[sp.Symbol, sp.Expr] = {}
    for i in range(n):
        values[sp.Symbol(f"g{i + 1}")] = dyn.g[i]
        for j in range(n):
            values[sp.Symbol(f"C{i + 1}_{j + 1}")] = dyn.C[i, j]
            if i <= j:
                values[sp.Symbol(f"M{i + 1}_{j + 1}")] = dyn.M[i, j]
    if coriolis is not None:
        values.update({nf.symbol: nf.value for nf in coriolis[0]})
    return values
