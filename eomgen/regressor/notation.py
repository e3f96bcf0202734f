"""How regressor parameters are written for people: LaTeX names (``MX2`` → ``\\mathrm{MX}_{2}``)
and linear forms in π grouped by coefficient."""

from __future__ import annotations

from typing import Sequence

import sympy as sp


def parameter_latex(name: str) -> str:
    """LaTeX of a standard or base parameter name: ``MX2`` → ``\\mathrm{MX}_{2}``,
    ``ZZ1R`` → ``\\mathrm{ZZ}_{1}^{R}``."""
    head = name.rstrip("0123456789R")
    rest = name[len(head):]
    index = rest.rstrip("R")
    return f"\\mathrm{{{head}}}_{{{index}}}" + ("^{R}" if rest.endswith("R") else "")


def tex_symbols(expr: sp.Expr) -> dict:
    """``symbol_names`` for :func:`sympy.latex`: each free symbol of ``expr`` written by
    :func:`parameter_latex`."""
    return {s: parameter_latex(s.name) for s in expr.free_symbols}


def by_coefficient(expr: sp.Expr, pi: Sequence[sp.Symbol]) -> sp.Expr:
    """A linear form in ``pi`` written as Σ coefficient · (sum of the parameters sharing it):
    ``a2**2*(M3 + M4 + M5 + M6) + XX2 - YY2``."""
    terms: dict = {}
    order: list = []
    poly = sp.expand(expr)
    used = [s for s in pi if s in poly.free_symbols]
    for s in used:
        coef = poly.coeff(s)
        if coef not in terms:
            terms[coef] = []
            order.append(coef)
        terms[coef].append(s)
    constant = poly.subs({s: 0 for s in used})
    # a number times a sum is distributed by SymPy unless told not to
    return sp.Add(*[sp.Mul(c, sp.Add(*terms[c]), evaluate=False)
                    if len(terms[c]) > 1 and abs(c) != 1 else c * sp.Add(*terms[c])
                    for c in order]) + constant
