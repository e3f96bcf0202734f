"""A straight-line program multiplied out: :func:`expand_program`.

The named results of :func:`eomgen.derive` (:class:`eomgen.symbolic.named.ProgramMatrix`) are
written out as ordinary SymPy expressions on request. Substituting the program's intermediates
into each other and calling SymPy's ``expand`` takes minutes beyond teaching size; instead
:func:`expand_program` multiplies sparse polynomials in ``sin q_i``, ``cos q_i``, the
velocities and the parameters (:class:`Polynomials`), reducing with
``sin² q_i + cos² q_i = 1`` after every product (so they stay small), and counts the work as
it goes, stopping past a limit (:class:`ExpansionTooLargeError`).
"""

from __future__ import annotations

import functools
import operator
from typing import Sequence

import sympy as sp
from sympy.core.basic import _args_sortkey
# Exact rational coefficients: gmpy2's mpq when it is installed, else SymPy's pure-Python
# rational, both several times faster than fractions.Fraction for the same exact values.
from sympy.external.gmpy import MPQ

#: In an expansion with floating-point numbers, terms whose coefficient is below this fraction
#: of the largest coefficient of the result are rounding noise (``1e-17*sin(q1)``), dropped.
NOISE_RTOL = 1e-12

#: The work of building one term of a result as a SymPy expression, in term operations.
#: Measured (one core, SymPy 1.14): a polynomial term operation takes 0.4–1.3 µs, building a
#: term 95–280 µs (more for terms with more factors), so 150. At 300 the 4,212-term M of the
#: PUMA 560 with symbolic inertias (0.05·10⁶ polynomial operations, written out in 0.49 s) and
#: the 5,549-term M of the Panda (0.63 s) were estimated at 1.3 and 1.7 s and left named.
TERM_COST = 150


class ExpansionTooLargeError(ValueError):
    """An expansion passed its ``max_terms`` or ``max_work`` (:func:`expand_program`)."""


def _polynomial_node(expr: sp.Expr) -> bool:
    return expr.is_Add or expr.is_Mul or (
        expr.is_Pow and expr.exp.is_Integer and expr.exp > 0)


class Polynomials:
    """Sparse polynomials in the generators of one expansion, as ``{monomial: coefficient}``
    dicts: a monomial is one integer holding every exponent in a field of :attr:`BITS` bits
    (so multiplying monomials is adding integers), a coefficient a Python float (a model with
    decimal numbers) or an exact int / rational (``MPQ``). After every product, ``sin² q_i`` is replaced
    by ``1 − cos² q_i``, which keeps the degree in ``sin q_i`` at most one.

    ``work`` counts the term operations done; :meth:`spend` stops the expansion past
    ``max_work`` or when a result passes ``max_terms``.
    """

    BITS = 16

    def __init__(self, generators, pairs, exact, max_terms, max_work):
        self.generators = list(generators)
        self.position = {g: k for k, g in enumerate(self.generators)}
        self.exact = exact
        self.pairs = [(self.BITS * self.position[s], self.BITS * self.position[c])
                      for s, c in pairs]
        field = (1 << self.BITS) - 1
        self.max_terms, self.max_work, self.work = max_terms, max_work, 0

    def spend(self, work: int, size: int, what: str) -> None:
        self.work += work
        if self.max_work is not None and self.work > self.max_work:
            raise ExpansionTooLargeError(f"expanding {what} passed the work limit of "
                                         f"{self.max_work} term operations")
        if self.max_terms is not None and size > self.max_terms:
            raise ExpansionTooLargeError(
                f"expanding {what} passed {self.max_terms} terms; use the named form, "
                "or expand(max_terms=None) to force it")

    def number(self, x: sp.Expr) -> dict:
        if x.is_Integer:
            value = int(x)
        elif self.exact:
            value = MPQ(int(x.p), int(x.q))
        else:
            value = float(x)
        return {0: value} if value else {}

    def generator(self, g) -> dict:
        return {1 << (self.BITS * self.position[g]): 1}

    def add_to(self, out: dict, b: dict, what: str) -> None:
        """``out += b``, in place."""
        self.spend(len(b), 0, what)
        for m, c in b.items():
            out[m] = out[m] + c if m in out else c

    def multiply(self, a: dict, b: dict, what: str) -> dict:
        if len(a) < len(b):
            a, b = b, a
        self.spend(len(a) * len(b), 0, what)
        out: dict = {}
        for mb, cb in b.items():
            for ma, ca in a.items():
                m = ma + mb
                out[m] = out[m] + ca * cb if m in out else ca * cb
        out = self.reduce(out)
        self.spend(0, len(out), what)
        return out

    def reduce(self, f: dict) -> dict:
        """``f`` with ``sin² q = 1 − cos² q`` applied until no ``sin q`` has degree two: one
        pass over the terms per angle whose sine appears squared."""
        field = (1 << self.BITS) - 1
        self.work += len(f)
        f = {m: c for m, c in f.items() if c}
        seen = functools.reduce(operator.or_, f, 0)  # a sin exponent ≥ 2 sets a bit above bit 0
        for s, cos in self.pairs:
            square = 2 << s
            mask = (field - 1) << s
            while seen & mask:
                self.work += len(f)
                out: dict = {}
                for m, c in f.items():
                    if m & mask:  # s^e with e ≥ 2: s^(e−2) (1 − c²)
                        rest = m - square
                        out[rest] = out[rest] + c if rest in out else c
                        rest += 2 << cos
                        out[rest] = out[rest] - c if rest in out else -c
                    else:
                        out[m] = out[m] + c if m in out else c
                f = {m: c for m, c in out.items() if c}
                seen = functools.reduce(operator.or_, f, 0)
        return f

    def to_expr(self, f: dict) -> sp.Expr:
        """``f`` as a SymPy sum of products, built as SymPy would (coefficient first, then the
        factors in SymPy's canonical order) without re-deriving it for every term."""
        field = (1 << self.BITS) - 1
        powers: dict = {}
        terms = []
        for m, c in f.items():
            factors = []
            k = 0
            while m:
                e = m & field
                if e:
                    if (k, e) not in powers:
                        powers[k, e] = self.generators[k] ** e
                    factors.append(powers[k, e])
                m >>= self.BITS
                k += 1
            number = (sp.Rational(c.numerator, c.denominator) if isinstance(c, MPQ)
                      else sp.Integer(c) if isinstance(c, int) else sp.Float(c))
            factors.sort(key=_args_sortkey)
            if not factors:
                terms.append(number)
            elif number == 1 and len(factors) == 1:
                terms.append(factors[0])
            else:
                terms.append(sp.Mul._from_args(factors if number == 1 else [number] + factors,
                                               is_commutative=True))
        return sp.Add(*terms)


def expand_program(subexpressions: Sequence[tuple[sp.Symbol, sp.Expr]],
                   exprs: Sequence[sp.Expr], max_terms: int | None = None,
                   max_work: int | None = None) -> list[sp.Expr]:
    """``exprs`` with the ``subexpressions`` substituted and everything multiplied out: sums of
    products of ``sin q_i``, ``cos q_i`` (reduced with ``sin² + cos² = 1``: degree at most one
    in ``sin q_i``), velocities and parameters. Floats (a model with decimal numbers) are
    computed in double precision, and terms below :data:`NOISE_RTOL` of the largest
    coefficient of a result (rounding noise) dropped; exact numbers stay exact.

    Parameters
    ----------
    max_terms:
        Stop when a product or a result passes this many terms (``None``: no limit).
    max_work:
        Stop when the term operations done pass this (``None``: no limit): a bound on the time
        (about a second per 10⁶ on a 2020s laptop core), checked before each product and before
        the result is built as SymPy expressions (:data:`TERM_COST` per term).

    Raises
    ------
    ExpansionTooLargeError
        When a limit is passed.
    NotImplementedError
        When the program is not polynomial in its inputs and ``sin``/``cos`` of them (a
        division by an intermediate, a function of one).
    """
    subexpressions, exprs = _angle_sums(subexpressions, exprs)
    defined = {symbol for symbol, _ in subexpressions}
    leaves: set = set()
    floats = False

    def collect(expr):
        nonlocal floats
        if expr in defined:
            return
        if expr.is_Number:
            floats = floats or expr.is_Float
            if not expr.is_Rational and not expr.is_Float:
                raise NotImplementedError(f"cannot expand the number {expr}")
        elif _polynomial_node(expr):
            for a in expr.args:
                collect(a)
        elif expr.free_symbols & defined:
            raise NotImplementedError(f"cannot expand {expr}: not a polynomial in the program's "
                                      "intermediates")
        else:
            leaves.add(expr)

    for _, expr in subexpressions:
        collect(expr)
    for expr in exprs:
        collect(expr)
    angles = sorted({x.args[0] for x in leaves if isinstance(x, (sp.sin, sp.cos))},
                    key=sp.default_sort_key)
    leaves.update(f(a) for a in angles for f in (sp.sin, sp.cos))
    P = Polynomials(sorted(leaves, key=sp.default_sort_key),
                     [(sp.sin(a), sp.cos(a)) for a in angles], not floats, max_terms, max_work)
    value: dict = {}

    def convert(expr, what):
        found = value.get(expr)
        if found is not None:
            return found
        if expr.is_Number:
            return P.number(expr)
        if expr in P.position:
            return P.generator(expr)
        if expr.is_Add:
            out: dict = {}
            for a in expr.args:
                P.add_to(out, convert(a, what), what)
            out = {m: c for m, c in out.items() if c}
            P.spend(0, len(out), what)
            return out
        if expr.is_Mul:
            out = {0: 1}
            for a in expr.args:
                out = P.multiply(out, convert(a, what), what)
            return out
        base = convert(expr.base, what)
        out = {0: 1}
        for _ in range(int(expr.exp)):
            out = P.multiply(out, base, what)
        return out

    for symbol, expr in subexpressions:
        f = convert(expr, symbol.name)
        if floats and f:
            largest = max(abs(c) for c in f.values())
            f = {m: c for m, c in f.items() if abs(c) >= 1e-3 * NOISE_RTOL * largest}
        value[symbol] = f
    results = [convert(expr, "the result") for expr in exprs]
    if floats:
        largest = max((abs(c) for f in results for c in f.values()), default=0.0)
        results = [{m: c for m, c in f.items() if abs(c) >= NOISE_RTOL * largest}
                   for f in results]
    P.spend(TERM_COST * sum(len(f) for f in results), 0, "the result")  # before building it
    return [P.to_expr(f) for f in results]


def _angle_sums(subexpressions, exprs):
    """``sin``/``cos`` of an intermediate defined as an input plus a constant (a joint angle
    with a phase, ``qp = q + φ``) written by the angle-sum formulas in ``sin q`` and ``cos q``,
    and such intermediates dropped: the expansion stays a polynomial in the joints' sines and
    cosines."""
    defined = {symbol for symbol, _ in subexpressions}
    sums = {}
    for symbol, expr in subexpressions:
        if expr.is_Add and len(expr.args) == 2 and not expr.free_symbols & defined:
            constant, angle = expr.as_coeff_Add()
            if constant.is_Number and angle.is_Symbol:
                c, s = sp.cos(constant), sp.sin(constant)
                sums[sp.sin(symbol)] = sp.sin(angle) * c + sp.cos(angle) * s
                sums[sp.cos(symbol)] = sp.cos(angle) * c - sp.sin(angle) * s
    if not sums:
        return subexpressions, exprs
    phased = {f.args[0] for f in sums}
    kept = [(symbol, expr.xreplace(sums)) for symbol, expr in subexpressions
            if symbol not in phased]
    return kept, [expr.xreplace(sums) for expr in exprs]
