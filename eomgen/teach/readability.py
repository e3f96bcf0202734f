"""Making small derivations read like a textbook.

* :func:`group_by_factor`: the terms of a sum gathered by the mass of the body they come from
  (``m_1 l_{c1}^2 + m_2 (l_1^2 + l_{c2}^2 + 2 l_1 l_{c2} c_2) + I_1 + I_2``) or by the
  trigonometric function they multiply (``g (m_1 l_{c1} + m_2 l_1) c_1 + g m_2 l_{c2} c_{12}``);
* :func:`common_christoffel_factors`: the Christoffel symbols of a small arm are often
  multiples of a few expressions; naming them (the textbook's
  ``h = m_2 l_1 l_{c2} \\sin q_2`` for the planar two-link arm) makes C readable.

These only regroup: the grouped sum equals the input exactly (tests check it with SymPy).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import sympy as sp


def _mass_key(masses: Sequence[sp.Symbol]) -> Callable[[sp.Expr], sp.Expr | None]:
    def key(term: sp.Expr):
        for m in masses:
            if term.has(m) and sp.degree(term, m) == 1:
                return m
        return None
    return key


def _trig_key(angles: Sequence[sp.Symbol]) -> Callable[[sp.Expr], sp.Expr | None]:
    def key(term: sp.Expr):
        factors = [f for f in sp.Mul.make_args(term)
                   if isinstance(f.base if f.is_Pow else f, (sp.sin, sp.cos))
                   and (f.base if f.is_Pow else f).args[0].free_symbols & set(angles)]
        return sp.Mul(*factors) if factors else None
    return key


def group_by_factor(expr: sp.Expr, key: Callable[[sp.Expr], sp.Expr | None],
                    factor: bool = True) -> list[sp.Expr]:
    """The terms of ``expr`` gathered by ``key(term)`` (a factor of the term, or None), as a list
    of terms to print in this order: groups in order of first appearance of their key, each
    ``key · (sum of the rest)``, then the terms without a key. ``factor`` pulls common factors
    out of each group's sum (``g (l_1 m_2 + l_{c1} m_1)``); without it a group keeps its terms
    (``m_2 (l_1^2 + l_{c2}^2)``) and a one-term group prints with its key first
    (``m_1 l_{c1}^2``, through :class:`sympy.UnevaluatedExpr`: call ``.doit()`` to compute with
    the result).

    >>> m1, m2, l, c, I = sp.symbols("m1 m2 l c I")
    >>> terms = group_by_factor(m1*l**2 + m2*l**2 + m2*c + I, lambda t: m2 if t.has(m2) else None)
    >>> terms
    [m2*(c + l**2), I, l**2*m1]
    >>> sp.expand(sp.Add(*terms) - (m1*l**2 + m2*l**2 + m2*c + I))
    0
    """
    groups: dict = {}
    rest: list[sp.Expr] = []
    for term in sp.Add.make_args(sp.expand(expr)):
        k = key(term)
        if k is None:
            rest.append(term)
        else:
            groups.setdefault(k, []).append(sp.cancel(term / k))
    out = []
    for k, parts in groups.items():
        inner = sp.Add(*parts)
        inner = sp.factor_terms(inner) if factor else perfect_power(inner)
        if inner.is_Number:  # a number goes first, as usual: 8.08 c_1, -2 m_2
            out.append(inner * k)
            continue
        negative = inner.could_extract_minus_sign() and not inner.is_Add
        inner = -inner if negative else inner
        if inner == 1:
            term = k
        elif inner.is_Add or factor:
            term = sp.Mul(k, inner, evaluate=False)
        else:
            term = sp.Mul(k, sp.UnevaluatedExpr(inner), evaluate=False)
        out.append(sp.Mul(-1, term, evaluate=False) if negative else term)
    return out + rest


def perfect_power(expr: sp.Expr) -> sp.Expr:
    """``expr`` written as a power (``a_2^2 c_2^2 + 2 a_2 l_{c3} c_2 c_{23} + l_{c3}^2 c_{23}^2``
    → ``(a_2 c_2 + l_{c3} c_{23})^2``, the textbook's form of a point's squared distance) or a
    product of sums (``(a_2 c_2 + l_{c3} c_{23}) (a_2 s_2 + l_{c3} s_{23})``) when it is a
    number times one, else ``expr`` unchanged.

    >>> a, b, x = sp.symbols("a b x")
    >>> perfect_power(a**2*sp.cos(x)**2 + 2*a*b*sp.cos(x) + b**2)
    (a*cos(x) + b)**2
    >>> perfect_power(a**2 + b**2)
    a**2 + b**2
    """
    if not expr.is_Add or len(expr.args) < 3:
        return expr
    factored = sp.factor(expr)
    coefficient, rest = factored.as_coeff_Mul()
    if rest.is_Pow and rest.exp.is_Integer and rest.exp >= 2 and rest.base.is_Add:
        return factored
    factors = sp.Mul.make_args(rest)  # a product of sums only: (a c_2 + b c_23)(a s_2 + b s_23)
    if len(factors) >= 2 and all(f.is_Add or (f.is_Pow and f.base.is_Add) for f in factors):
        return factored
    return expr


def mass_grouped(expr: sp.Expr, masses: Sequence[sp.Symbol]) -> sp.Expr:
    """``expr`` as one (unevaluated) sum of its terms grouped by mass (:func:`by_mass`), to print
    as one expression (in a product, a matrix entry). ``.doit()`` gives back an ordinary sum."""
    grouped = by_mass(expr, masses)
    return grouped[0] if len(grouped) == 1 else sp.Add(*grouped, evaluate=False)


def trig_grouped(expr: sp.Expr, angles: Sequence[sp.Symbol]) -> sp.Expr:
    """``expr`` as one (unevaluated) sum of its terms grouped by trigonometric factor
    (:func:`by_trig`)."""
    grouped = by_trig(expr, angles)
    return grouped[0] if len(grouped) == 1 else sp.Add(*grouped, evaluate=False)


def by_mass(expr: sp.Expr, masses: Sequence[sp.Symbol]) -> list[sp.Expr]:
    """Terms of ``expr`` grouped by the body mass symbols ``masses`` (in body order)."""
    return _ordered(group_by_factor(expr, _mass_key(masses), factor=False), masses)


def by_trig(expr: sp.Expr, angles: Sequence[sp.Symbol]) -> list[sp.Expr]:
    """Terms of ``expr`` grouped by the sines and cosines of the joint ``angles`` they carry."""
    return group_by_factor(expr, _trig_key(angles))


def _ordered(terms: list[sp.Expr], masses: Sequence[sp.Symbol]) -> list[sp.Expr]:
    """Grouped terms with the mass groups first, in body order."""
    rank = {m: k for k, m in enumerate(masses)}

    def position(term):
        for factor in (term, *(term.args if term.is_Mul else ())):
            if factor in rank:
                return rank[factor]
        return len(rank)
    return sorted(terms, key=position)


@dataclass(frozen=True)
class NamedFactor:
    """A name for a common factor of the Christoffel symbols: ``symbol = value``."""

    symbol: sp.Symbol
    value: sp.Expr


def common_christoffel_factors(values: Sequence[sp.Expr], max_names: int = 4,
                               min_operations: int = 2) -> list[NamedFactor]:
    """Names ``h`` (or ``h_1, h_2, …``) for the expressions of which every value in ``values``
    is a rational multiple, when at most ``max_names`` are needed and each has at least
    ``min_operations`` operations (naming ``l_1`` would not help); else ``[]``.

    The sign of each name is chosen so that its value has no leading minus sign.

    >>> m2, l1, lc2, q2 = sp.symbols("m2 l1 lc2 q2")
    >>> h = m2*l1*lc2*sp.sin(q2)
    >>> common_christoffel_factors([-h, -h, h])
    [NamedFactor(symbol=h, value=l1*lc2*m2*sin(q2))]
    """
    bases: list[sp.Expr] = []
    for value in values:
        if value == 0 or any(sp.cancel(value / b).is_Rational for b in bases):
            continue
        bases.append(-value if value.could_extract_minus_sign() else value)
        if len(bases) > max_names:
            return []
    if not bases or any(sp.count_ops(b) < min_operations for b in bases):
        return []
    if len(bases) == 1:
        return [NamedFactor(sp.Symbol("h", real=True), bases[0])]
    return [NamedFactor(sp.Symbol(f"h{k}", real=True), b) for k, b in enumerate(bases, 1)]


def in_terms_of(value: sp.Expr, names: Sequence[NamedFactor]) -> sp.Expr:
    """``value`` written as a rational multiple of one of ``names``' symbols when it is one."""
    for name in names:
        ratio = sp.cancel(value / name.value)
        if ratio.is_Rational:
            return ratio * name.symbol
    return value
