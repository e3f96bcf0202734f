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
        inner = sp.factor_terms(inner) if factor else readable_sum(inner)
        if inner.is_Number:  # a number goes first, as usual: 8.08 c_1, -2 m_2
            out.append(inner * k)
            continue
        negative = inner.could_extract_minus_sign() and not inner.is_Add
        inner = -inner if negative else inner
        if inner == 1:
            term = k
        elif factor and inner.is_Mul and inner.as_coeff_Mul()[0] != 1:
            term = k * inner  # a monomial with a number: 2 a_2 q̇_1 s_2^2, not s_2^2 · 2 a_2 q̇_1
        elif inner.is_Add or factor:
            term = sp.Mul(k, inner, evaluate=False)
        else:
            term = sp.Mul(k, sp.UnevaluatedExpr(inner), evaluate=False)
        out.append(sp.Mul(-1, term, evaluate=False) if negative else term)
    if factor and len(rest) >= 2:  # g m_2 + g m_3 → g (m_2 + m_3)
        common = sp.factor_terms(sp.Add(*rest))
        if common.is_Mul:
            rest = [common]
    return out + rest


def common_monomial(expr: sp.Expr) -> tuple[sp.Expr, sp.Expr]:
    """``(monomial, rest)`` with ``expr = monomial · rest``: the product of the powers of the
    factors every term of the sum ``expr`` has (``m_3 l_{c3}``, ``s_2^2``), with the sign when
    every term is negative and, for exact numbers, their common rational factor. Floats stay
    in ``rest`` (``0.3 (x + 2.0 y)`` would print numbers the description did not write).

    >>> a, b, c = sp.symbols("a b c")
    >>> common_monomial(-2*a*b*c - 4*a**2*b)
    (-2*a*b, 2*a + c)
    >>> common_monomial(a + b)
    (1, a + b)
    """
    terms = sp.Add.make_args(expr)
    if len(terms) < 2:
        return sp.Integer(1), expr
    shared = None
    for term in terms:
        powers = {base: e for base, e in term.as_coeff_Mul()[1].as_powers_dict().items()
                  if e.is_Integer and e > 0 and not base.is_Number}
        shared = powers if shared is None else {
            base: min(e, powers[base]) for base, e in shared.items() if base in powers}
    monomial = sp.Mul(*[base ** e for base, e in shared.items()])
    if not expr.has(sp.Float):
        monomial *= sp.Add(*terms).as_content_primitive()[0]
    if all(term.could_extract_minus_sign() for term in terms):
        monomial = -monomial
    if monomial == 1:
        return monomial, expr
    return monomial, sp.Add(*[term / monomial for term in terms])


def readable_sum(expr: sp.Expr) -> sp.Expr:
    """``expr`` (a sum) in the shape a textbook writes it, with the same value:

    * a monomial times a sum, a power or a product of sums (:func:`common_monomial`, then
      :func:`perfect_power`): ``m_3 (a_2 l_{c3} c_3 + l_{c3}^2)`` → ``m_3 l_{c3} (a_2 c_3 + l_{c3})``;
    * else the terms with sines and cosines, written so, beside the others:
      ``(a_2 c_2 + a_3 c_{23} − l_{c3} s_{23})^2 + d_3^2``,
      ``2 a_2 (a_3 c_3 − l_{c3} s_3) + a_2^2 + a_3^2 + l_{c3}^2``;
    * else ``expr`` unchanged.

    Products are built unevaluated (``.doit()`` gives an ordinary expression).

    >>> a, b, c, x = sp.symbols("a b c x")
    >>> readable_sum(a*b*sp.cos(x) + b**2)
    b*(a*cos(x) + b)
    >>> readable_sum(a**2*sp.cos(x)**2 + 2*a*b*sp.cos(x)*sp.sin(x) + b**2*sp.sin(x)**2 + c**2)
    c**2 + (a*cos(x) + b*sin(x))**2
    """
    if not expr.is_Add:
        return expr
    monomial, rest = common_monomial(expr)
    if monomial.is_Number:  # 2 (a + b) is no easier to read than 2 a + 2 b
        monomial, rest = sp.Integer(1), expr
    shaped = perfect_power(rest)
    if monomial.could_extract_minus_sign():  # − m_3 d_3 (…), not m_3 (−d_3) (…)
        return sp.Mul(-1, sp.Mul(-monomial, shaped, evaluate=False), evaluate=False)
    if monomial != 1:
        return sp.Mul(monomial, shaped, evaluate=False)
    if shaped is not rest:
        return shaped
    trig = [t for t in expr.args if t.has(sp.sin, sp.cos)]
    plain = [t for t in expr.args if not t.has(sp.sin, sp.cos)]
    if not plain or len(trig) < 2:
        return expr
    part = sp.Add(*trig)
    shaped = perfect_power(part)
    if shaped is part:
        monomial, inner = common_monomial(part)
        if monomial.is_Number or monomial.has(sp.sin, sp.cos):
            return expr
        shaped = sp.Mul(monomial, inner, evaluate=False)
    return sp.Add(shaped, *plain, evaluate=False)


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
