"""Scalars of the symbolic engine: products, sums and negations of SymPy expressions made as
SymPy makes them, the commonest ones directly.

The recursions multiply and add mostly *monomials* (a non-zero number, a symbol, or a number
times distinct symbols) and numbers times sums of them. SymPy's general arithmetic makes each
such product or sum through its flattening, which builds new numbers and then asks each,
through the assumption engine, whether it is zero or negative: most of a derivation's time.
:func:`mul`, :func:`total`, :func:`negated` and :func:`difference` make those directly, the
same expressions argument for argument (``x * y``, ``sp.Add(*terms)``, ``-x``, ``x - y``), and
leave everything else to SymPy. :func:`leads_with_negative_number` is SymPy's
``could_extract_minus_sign`` of a product read off its leading number.

Used by :mod:`eomgen.symbolic.program` (naming, its negation check), :mod:`eomgen.symbolic.
spatial` (the vector algebra) and the printers (:mod:`eomgen.symbolic.printing`).
"""

from __future__ import annotations

from functools import cmp_to_key

import sympy as sp

_ZERO = sp.S.Zero


def _symbolic(x) -> bool:
    return isinstance(x, sp.Expr) and not x.is_Number


def monomial(x):
    """``(coefficient, symbols)`` of a non-zero SymPy number (no symbols), a symbol (coefficient
    None), or a product of one optional number and distinct symbols; None for anything else."""
    t = type(x)
    if t is sp.Symbol:
        return (None, (x,)) if x.is_commutative else None
    if t is sp.Mul:
        if not x.is_commutative:
            return None
        args = x.args
        if args[0].is_Number:
            coefficient, args = args[0], args[1:]
            if not (coefficient.is_Float or coefficient.is_Rational):
                return None
        else:
            coefficient = None
        return (coefficient, args) if all(type(a) is sp.Symbol for a in args) else None
    if (x.is_Float or x.is_Rational) and x:  # a SymPy number: nan, oo and zoo are neither
        return x, ()
    return None


_SORT_KEY = cmp_to_key(sp.Basic.compare)


def mul(x, y):
    """``x y``; when one factor is an exact 0 or 1 (a Python or SymPy integer) and the other a
    SymPy expression that is not a number, the result SymPy's product would give (0, or the
    other factor) without building the product: structural zeros and ones (identity
    rotations, axes along a coordinate axis) are most of the factors of the recursions.

    The commonest other products of the recursions, of two *monomials* (a non-zero number, a
    symbol, or a number times distinct symbols) with no symbol in common, are made directly as
    the product SymPy makes: the product of the numbers first (none when it is 1), then the
    symbols sorted as SymPy sorts factors. SymPy's general flattening would build the same
    product, and a new float for each float coefficient whose assumptions it then works out
    (a third of such a product's cost)."""
    if (type(x) is int or isinstance(x, sp.Integer)) and (x == 0 or x == 1) and _symbolic(y):
        return _ZERO if x == 0 else y
    if (type(y) is int or isinstance(y, sp.Integer)) and (y == 0 or y == 1) and _symbolic(x):
        return _ZERO if y == 0 else x
    if isinstance(x, sp.Basic) and isinstance(y, sp.Basic):
        number, other = (x, y) if x.is_Number else (y, x)
        if (other.is_Add and other.is_commutative and (number.is_Float or number.is_Rational)
                and number and number is not sp.S.One):
            # SymPy distributes a number over a sum: the sum of the scaled terms
            return total([mul(number, term) for term in other.args])
        a, b = monomial(x), monomial(y)
        if a is not None and b is not None and (a[1] or b[1]):
            symbols = a[1] + b[1]
            if len(set(symbols)) == len(symbols):
                if a[0] is None:
                    coefficient = b[0]
                elif b[0] is None:
                    coefficient = a[0]
                else:
                    coefficient = a[0] * b[0]
                if coefficient is None or coefficient is sp.S.One:
                    if len(symbols) > 1:
                        return sp.Mul._from_args(tuple(sorted(symbols, key=_SORT_KEY)), True)
                elif (coefficient.is_Float or coefficient.is_Rational) and coefficient:
                    return sp.Mul._from_args(
                        (coefficient,) + tuple(sorted(symbols, key=_SORT_KEY)), True)
    return x * y


def negated(x):
    """``-x``. A monomial (see :func:`mul`) is negated directly, as SymPy negates it: its
    number's negative (dropped when it is 1) before the same symbols, or −1 before them; a sum
    of monomials as the sum of its negated terms (:func:`total`), which is what SymPy makes of
    −(a + b). SymPy builds each through its general product, whose new float it then asks
    whether it is zero."""
    if isinstance(x, sp.Basic):
        if x.is_Add:
            terms = [negated(t) for t in x.args]
            if all(t is not None and not (isinstance(t, sp.Basic) and t.is_Add) for t in terms):
                return total(terms)
            return -x
        m = monomial(x)
        if m is not None and m[1]:
            coefficient, symbols = m
            if coefficient is None:
                return sp.Mul._from_args((sp.S.NegativeOne,) + symbols, True)
            c = -coefficient
            if c is sp.S.One:
                return symbols[0] if len(symbols) == 1 else sp.Mul._from_args(symbols, True)
            return sp.Mul._from_args((c,) + symbols, True)
    return -x


def difference(x, y):
    """``x - y`` (:func:`total` of ``x`` and :func:`negated` ``y`` when both are SymPy
    expressions)."""
    if not (isinstance(x, sp.Basic) and isinstance(y, sp.Basic)):
        return x - y
    return total([x, negated(y)])


def total(terms) -> sp.Expr:
    """``sp.Add(*terms)``. A sum of monomials (see :func:`mul`) that no two share their symbols
    (so that none combine), zeros aside, and at most one non-zero number, is made directly as
    the sum SymPy makes: the number first, then the terms sorted as SymPy sorts them."""
    kept = [t for t in terms if not (t is _ZERO or (type(t) is int and t == 0))]
    numbers = [t for t in kept if isinstance(t, (sp.Float, sp.Rational))]
    if len(numbers) == 1 and numbers[0]:
        kept = [t for t in kept if t is not numbers[0]]
    elif numbers:
        return sp.Add(*terms)
    if len(kept) + len(numbers) > 1 and all(type(t) in (sp.Symbol, sp.Mul) for t in kept):
        monomials = [monomial(t) for t in kept]
        if all(m is not None for m in monomials) and \
                len({m[1] for m in monomials}) == len(monomials):
            return sp.Add._from_args(tuple(numbers) + tuple(sorted(kept, key=_SORT_KEY)), True)
    return sp.Add(*terms)


def leads_with_negative_number(product: sp.Expr) -> bool:
    """``product.could_extract_minus_sign()`` of a finite product, without building
    ``-product`` as SymPy does to rule out ``zoo``: its leading factor is a negative number."""
    c = product.args[0]
    return c.is_Number and c.is_finite is not False and bool(c.is_extended_negative)


def leads_with_minus(expr: sp.Expr) -> bool:
    """``expr.could_extract_minus_sign()``, a product's read off its leading number
    (:func:`leads_with_negative_number`)."""
    return leads_with_negative_number(expr) if expr.is_Mul else expr.could_extract_minus_sign()


__all__ = ["difference", "leads_with_minus", "leads_with_negative_number", "monomial", "mul",
           "negated", "total"]
