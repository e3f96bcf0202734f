"""The trigonometric algebra of the textbook forms: sums of sines and cosines of joint angles
written as a textbook writes them.

* :func:`fourier_form`: the unique sum of harmonics ``A_0 + Σ_k A_k cos(k·q) + B_k sin(k·q)``
  (products become sums of angles), and :func:`simplify_trig`, that form with float noise
  dropped and common factors pulled out;
* :class:`TrigAlgebra`: one sparse polynomial ring over ``sin q_i``, ``cos q_i``, the
  parameters and the velocities, reduced with ``sin² + cos² = 1``, whose results are written
  as products of sines and cosines of the joint angles or of the absolute angles
  ``q_2 + q_3`` along chains of parallel revolute axes (whichever has fewer terms), with
  ``cos²`` or ``sin²`` chosen per parameter group (``I_x2 sin² q_2 + I_y2 cos² q_2``);
* the floats: rounding noise dropped (:func:`drop_float_noise`), computed floats written with
  15 significant digits (:func:`round_floats`).

The textbook derivation (:mod:`eomgen.symbolic.textbook`) computes in :class:`TrigAlgebra`;
the regressor's forms and the handout's sections print through :func:`simplify_trig` and
:func:`fourier_form`.
"""

from __future__ import annotations

import functools
from fractions import Fraction

import sympy as sp

#: In a sum with floating-point coefficients, terms whose coefficient is smaller than this
#: fraction of the largest coefficient are rounding noise of the description's numbers (e.g.
#: ``2e-19*cos(2*q3)`` next to ``2.5``) and are dropped before simplifying.
FLOAT_NOISE_RTOL = 1e-12


def largest_coefficient(exprs) -> float:
    """The largest magnitude of the numeric coefficients of the terms of ``exprs`` (sums)."""
    return max((abs(float(term.as_coeff_Mul()[0])) for expr in exprs
                for term in sp.Add.make_args(sp.sympify(expr))), default=0.0)


def drop_float_noise(expr: sp.Expr, rtol: float = FLOAT_NOISE_RTOL,
                     reference: float = 0.0) -> sp.Expr:
    """``expr`` (a sum) without the terms whose Float coefficient is below ``rtol`` times the
    largest numeric coefficient of the sum, or of ``reference`` when that is larger (for a sum
    that is all noise, e.g. a Christoffel symbol of a matrix whose entries are of order
    ``reference``). Exact (integer, rational) terms are always kept.

    >>> x, y = sp.symbols("x y")
    >>> drop_float_noise(2.5*x + 1e-19*y + sp.Rational(1, 3)*y**2)
    2.5*x + y**2/3
    """
    if not expr.is_Add and reference == 0:
        return expr
    terms = sp.Add.make_args(expr)
    coefficients = [term.as_coeff_Mul()[0] for term in terms]
    largest = max([reference] + [abs(float(c)) for c in coefficients])
    kept = [term for term, c in zip(terms, coefficients)
            if not (c.is_Float and abs(float(c)) < rtol * largest)]
    return sp.Add(*kept) if len(kept) < len(terms) else expr


Spectrum = dict  # frequency vector (tuple of ints) → complex rational (re, im) of e^{i k·q}


def _integer_combination(arg: sp.Expr, index: dict) -> tuple[int, ...] | None:
    """``k`` when ``arg`` is ``Σ k_j q_j`` with integer ``k_j`` over the given angles."""
    k = [0] * len(index)
    for term in sp.Add.make_args(arg):
        factor, angle = term.as_coeff_Mul()
        if angle not in index or not factor.is_Integer:
            return None
        k[index[angle]] += int(factor)
    return tuple(k)


def _multiply(a: Spectrum, b: Spectrum) -> Spectrum:
    out: Spectrum = {}
    for ka, (ra, ia) in a.items():
        for kb, (rb, ib) in b.items():
            k = tuple(x + y for x, y in zip(ka, kb))
            r, i = out.get(k, (Fraction(0), Fraction(0)))
            out[k] = (r + ra * rb - ia * ib, i + ra * ib + ia * rb)
    return {k: v for k, v in out.items() if v != (0, 0)}


@functools.lru_cache(maxsize=4096)
def _product_spectrum(trig: tuple, n: int) -> Spectrum:
    """The spectrum of a product of ``(sin|cos, k)`` factors (sorted), built on the spectrum of
    the product without its last factor (cached, so shared prefixes are computed once)."""
    if not trig:
        return {(0,) * n: (Fraction(1), Fraction(0))}
    name, k = trig[-1]
    return _multiply(_product_spectrum(trig[:-1], n), _spectrum(getattr(sp, name), k))


def _spectrum(function, k: tuple[int, ...]) -> Spectrum:
    """``cos(k·q) = (e^{ik·q} + e^{-ik·q})/2``, ``sin(k·q) = (e^{ik·q} − e^{-ik·q})/(2i)``."""
    minus = tuple(-x for x in k)  # k ≠ 0: SymPy evaluates sin(0) and cos(0)
    half = Fraction(1, 2)
    if function is sp.cos:
        return {k: (half, Fraction(0)), minus: (half, Fraction(0))}
    return {k: (Fraction(0), -half), minus: (Fraction(0), half)}


def fourier_form(expr: sp.Expr, angles) -> sp.Expr:
    """``expr`` (a polynomial in sines and cosines of integer combinations of ``angles``) as the
    sum of harmonics ``A_0 + Σ_k A_k cos(k·q) + B_k sin(k·q)``, fully expanded.

    Products become sums of angles (``c1 c2 − s1 s2`` → ``cos(q1 + q2)``, ``s2²`` →
    ``1/2 − cos(2 q2)/2``); the form is unique, so whatever cancels does cancel. The expansion
    runs in SymPy's sparse polynomial rings (``sring``), with every other factor (parameters,
    ``sin`` of anything else, ``1/m``) a further generator: exact, and fast where SymPy's
    ``trigsimp`` takes minutes (a 2-joint arm with general axes).

    >>> q1, q2 = sp.symbols("q1 q2")
    >>> fourier_form(sp.cos(q1)*sp.cos(q2) - sp.sin(q1)*sp.sin(q2) + 2*sp.sin(q2)**2, (q1, q2))
    -cos(2*q2) + cos(q1 + q2) + 1
    """
    expr = sp.sympify(expr)
    if not expr.has(sp.sin, sp.cos):
        return sp.expand(expr)
    _, poly = sp.sring(expr)
    return harmonics(poly, angles)


def harmonics(poly, angles) -> sp.Expr:
    """The element ``poly`` of a SymPy polynomial ring (generators: sines and cosines of integer
    combinations of ``angles``, and anything else) in the form of :func:`fourier_form`."""
    ring = poly.ring
    domain = ring.domain if ring.domain.is_Field else ring.domain.get_field()
    index = {angle: j for j, angle in enumerate(angles)}
    zero = (0,) * len(index)
    waves: list[tuple[str, tuple[int, ...]] | None] = []  # per generator: (sin|cos, k) or None
    for generator in ring.symbols:
        k = (_integer_combination(generator.args[0], index)
             if generator.func in (sp.sin, sp.cos) else None)
        waves.append(None if k is None else (generator.func.__name__, k))
    scales: dict[Fraction, object] = {}
    found: dict[tuple[str, tuple[int, ...]], dict[tuple[int, ...], object]] = {}
    for monomial, coefficient in poly.terms():
        coefficient = domain.convert_from(coefficient, ring.domain)
        trig = tuple(wave for wave, e in zip(waves, monomial) if wave is not None for _ in range(e))
        rest = tuple(0 if wave is not None else e for wave, e in zip(waves, monomial))
        for k, (re, im) in _product_spectrum(trig, len(zero)).items():
            if k != zero and next(x for x in k if x != 0) < 0:
                continue  # paired with -k: c e^{ikq} + conj(c) e^{-ikq} = 2 Re c cos − 2 Im c sin
            scale = 1 if k == zero else 2
            for name, value in (("cos", scale * re), ("sin", -scale * im)):
                if value:
                    if value not in scales:
                        scales[value] = domain.from_sympy(
                            sp.Rational(value.numerator, value.denominator))
                    terms = found.setdefault((name, k), {})
                    terms[rest] = terms.get(rest, domain.zero) + scales[value] * coefficient
    out = []
    powers: dict[tuple[int, ...], list[sp.Expr]] = {}
    for (name, k), terms in found.items():
        wave = sp.Integer(1) if k == zero else getattr(sp, name)(
            sp.Add(*[x * angle for x, angle in zip(k, angles)]))
        for rest, value in terms.items():
            if value:
                if rest not in powers:
                    powers[rest] = [g ** e for g, e in zip(ring.symbols, rest) if e]
                out.append(sp.Mul(domain.to_sympy(value), wave, *powers[rest]))
    return sp.Add(*out)


def simplify_trig(expr: sp.Expr, angles, reference: float = 0.0) -> sp.Expr:
    """The form eomgen prints for small models: :func:`fourier_form` in the joint ``angles``,
    float rounding noise dropped (:func:`drop_float_noise` with ``reference``), common factors
    pulled out:
    ``l1*cos(q1) + lc2*cos(q1 + q2)`` rather than products of sines and cosines.

    >>> q1, q2, l1, lc2 = sp.symbols("q1 q2 l1 lc2")
    >>> simplify_trig(l1*sp.cos(q1) + lc2*(sp.cos(q1)*sp.cos(q2) - sp.sin(q1)*sp.sin(q2)), (q1, q2))
    l1*cos(q1) + lc2*cos(q1 + q2)
    """
    return sp.factor_terms(drop_float_noise(fourier_form(expr, angles), reference=reference))



class TrigAlgebra:
    """Polynomials in the sines and cosines of the joint positions (and in the joint positions,
    velocities and everything else of the model as further generators), in one SymPy sparse
    polynomial ring over a field: products and derivatives without SymPy's ``expand``.

    ``scalars`` are all the model's expressions the derivation starts from; :meth:`__call__`
    returns the ring element of one of them. A model with floating-point numbers is computed in
    floating point (its rotations are orthonormal only to rounding, so exact arithmetic would
    keep the rounding as terms that never cancel); :meth:`expr` drops the rounding noise.
    """

    def __init__(self, scalars, q, qd):
        trig = [f(x) for x in q for f in (sp.sin, sp.cos)]
        everything = [sp.sympify(x) for x in scalars] + trig + list(q) + list(qd)
        ring, elements = sp.sring(everything)
        if not ring.domain.is_Field:
            field = ring.clone(domain=ring.domain.get_field())
            elements = [e.set_ring(field) for e in elements]
            ring = field
        self.ring = ring
        self.q = q
        self._element = dict(zip(everything, elements))
        n = len(q)
        at = len(scalars)
        self.s = elements[at:at + 2 * n:2]
        self.c = elements[at + 1:at + 2 * n:2]
        self.q_gen = elements[at + 2 * n:at + 3 * n]
        self.qd = elements[at + 3 * n:]
        self._pythagoras = [s * s + c * c - 1 for s, c in zip(self.s, self.c)]
        position = {symbol: k for k, symbol in enumerate(ring.symbols)}
        self._pair_index = [(position[sp.sin(x)], position[sp.cos(x)]) for x in q]
        self._angles = None  # see absolute_angles
        self.written: frozenset[float] = frozenset()  # floats printed with all their digits

    # Matrices of ring elements (lists of rows, any shape), with the ring's own arithmetic: a
    # product skips zero factors and sums from the ring's zero.

    @staticmethod
    def transpose(A):
        return [list(column) for column in zip(*A)]

    @staticmethod
    def product(A, B):
        zero = A[0][0].ring.zero
        return [[sum((A[i][k] * B[k][j] for k in range(len(B)) if A[i][k] and B[k][j]), zero)
                 for j in range(len(B[0]))] for i in range(len(A))]

    @staticmethod
    def plus(A, B):
        return [[a + b for a, b in zip(ra, rb)] for ra, rb in zip(A, B)]

    @staticmethod
    def times(x, A):
        return [[x * a for a in row] for row in A]

    def reduce(self, f):
        """``f`` modulo ``sin² q_k + cos² q_k = 1``: a canonical form of degree at most one in
        one of the two, which keeps products small."""
        return f.rem(self._pythagoras) if self._pythagoras else f

    def __call__(self, expr):
        return self._element[sp.sympify(expr)]

    def derivative(self, f, k: int):
        """``∂f/∂q_k``, with ``∂s_k/∂q_k = c_k`` and ``∂c_k/∂q_k = −s_k``."""
        s, c, x = self.s[k], self.c[k], self.q_gen[k]
        return f.diff(x) + c * f.diff(s) - s * f.diff(c)

    def absolute_angles(self, parent: dict[int, int]) -> None:
        """Declare chains of parallel revolute joints: ``parent[k] = p`` when joint ``k``'s axis
        is parallel to that of joint ``p`` just before it, so that body k turns by the absolute
        angle ``θ_k = θ_p + q_k`` (``θ_p = q_p`` at the start of a chain). :meth:`expr` then
        writes each result in whichever of the relative angles ``q_k`` or the absolute angles
        ``θ_k`` (``c_{23} = cos(q_2 + q_3)``) gives it fewer terms."""
        if not parent:
            return
        theta: dict[int, sp.Expr] = {}

        def angle(k):
            if k not in theta:
                theta[k] = self.q[k] + angle(parent[k]) if k in parent else self.q[k]
            return theta[k]

        extra = [f(angle(k)) for k in sorted(parent) for f in (sp.sin, sp.cos)]
        ring = self.ring.clone(symbols=self.ring.symbols + tuple(extra))
        width = len(self.ring.symbols)
        gens = ring.gens[width:]
        S = {k: g for k, g in zip(sorted(parent), gens[0::2])}
        C = {k: g for k, g in zip(sorted(parent), gens[1::2])}
        s = [self._lift(x, ring) for x in self.s]
        c = [self._lift(x, ring) for x in self.c]

        def absolute(k):  # sin and cos of θ_k in the new ring
            return (S[k], C[k]) if k in parent else (s[k], c[k])

        rewrite = []
        for k, p in parent.items():  # q_k = θ_k − θ_p
            Sk, Ck = absolute(k)
            Sp, Cp = absolute(p)
            rewrite += [(s[k], Sk * Cp - Ck * Sp), (c[k], Ck * Cp + Sk * Sp)]
        pairs = [(S[k], C[k]) for k in sorted(parent)]
        pairs += [(s[k], c[k]) for k in range(len(self.q)) if k not in parent]
        self._angles = (ring, rewrite, [a * a + b * b - 1 for a, b in pairs],
                        [(width + 2 * j, width + 2 * j + 1) for j in range(len(parent))]
                        + [self._pair_index[k] for k in range(len(self.q)) if k not in parent])

    def readable_by_factor(self, f):
        """:meth:`readable` chosen for each product of the other factors (velocities,
        parameters) on its own: ``g c_{12} + l_1 q̇_1 q̇_{r,1} s_2`` where :meth:`readable`
        takes the relative or the absolute angles for the whole of ``f``. Exact: rewriting the
        sines and cosines keeps each product's coefficient apart."""
        if self._angles is None:
            return self.readable(f)
        ring, rewrite, pythagoras, pairs = self._angles
        relative = self._pair_index
        trig_index = {k for pair in relative for k in pair}
        groups: dict[tuple, dict] = {}
        for monomial, coefficient in f.terms():
            rest = tuple(0 if k in trig_index else e for k, e in enumerate(monomial))
            groups.setdefault(rest, {})[monomial] = coefficient
        out = ring.zero
        for terms in groups.values():
            part = self.ring(terms)
            best = self._lift(self._shortest_squares(part, relative), ring)
            other = self._lift(part, ring).compose(rewrite).rem(pythagoras)
            if len(other) < len(best):
                other = self._shortest_squares(other, pairs)
                if len(other) < len(best):
                    best = other
            out += best
        return out

    @staticmethod
    def _lift(f, ring):
        """``f`` in ``ring``, which has the generators of ``f.ring`` first and more after."""
        extra = (0,) * (ring.ngens - f.ring.ngens)
        return ring({monomial + extra: coefficient for monomial, coefficient in f.terms()})

    def readable(self, f):
        """``f`` (reduced) as the ring element to print: relative or absolute angles (see
        :meth:`absolute_angles`), and per product of other factors (parameters, velocities)
        ``c²`` or ``1 − s²``, whichever is shorter (``I_x s_2² + I_y c_2²``)."""
        best = self._shortest_squares(f, [self._pair_index[k] for k in range(len(self.q))])
        if self._angles is not None:
            ring, rewrite, pythagoras, pairs = self._angles
            g = self._lift(f, ring).compose(rewrite).rem(pythagoras)
            if len(g) < len(best):
                g = self._shortest_squares(g, pairs)
                if len(g) < len(best):
                    best = g
        return best

    @staticmethod
    def _shortest_squares(f, pairs):
        """``f`` with, per product of the non-trigonometric generators, ``c²`` written as
        ``1 − s²`` or ``s²`` as ``1 − c²`` (``pairs``: generator indices of ``(s, c)``) where
        that has fewer terms."""
        ring = f.ring
        trig_index = {k for pair in pairs for k in pair}
        if not any(monomial[k] >= 2 for monomial in f.itermonoms() for k in trig_index):
            return f
        groups: dict[tuple, dict] = {}
        for monomial, coefficient in f.terms():
            rest = tuple(0 if k in trig_index else e for k, e in enumerate(monomial))
            trig = tuple(e if k in trig_index else 0 for k, e in enumerate(monomial))
            groups.setdefault(rest, {})[trig] = coefficient
        out = ring.zero
        for rest, terms in groups.items():
            part = ring(terms)
            for s, c in pairs:  # c² → 1 − s² or s² → 1 − c², when that is shorter
                for a, b in ((c, s), (s, c)):
                    if any(monomial[a] >= 2 for monomial in part.itermonoms()):
                        other = _swap_squares(part, a, b)
                        if len(other) < len(part):
                            part = other
            out += part * ring({rest: ring.domain.one})
        return out

    def largest(self, matrix) -> float:
        """The largest magnitude of a numeric coefficient among the entries of ``matrix``
        (0 over exact domains, where there is no rounding noise)."""
        if not self.ring.domain.is_RR:
            return 0.0
        return max((abs(float(v)) for row in matrix for f in row for v in f.coeffs()),
                   default=0.0)

    def expr(self, f, reference: float = 0.0, by_factor: bool = False) -> sp.Expr:
        """``f`` as a SymPy expression in the form of :meth:`readable`: float rounding noise
        dropped (:func:`drop_float_noise`), computed floats written with 15 significant digits
        (:func:`round_floats`: ``0.009``, not ``0.0090000000000000018``) while the description's
        own floats keep all theirs, common factors pulled out."""
        readable = self.readable_by_factor if by_factor else self.readable
        value = readable(self._denoise(self.reduce(f), reference)).as_expr()
        return sp.factor_terms(round_floats(value, keep=self.written))

    def _denoise(self, f, reference: float = 0.0, rtol: float = FLOAT_NOISE_RTOL):
        """``f`` without the terms whose (float) coefficient is below ``rtol`` times the largest
        of ``f`` or ``reference`` (see :func:`drop_float_noise`); exact domains have none."""
        if not self.ring.domain.is_RR or not f:
            return f
        largest = max([reference] + [abs(float(c)) for c in f.itercoeffs()])
        kept = {m: c for m, c in f.iterterms() if abs(float(c)) >= rtol * largest}
        return f if len(kept) == len(f) else self.ring(kept)

    def matrix(self, rows, reference: float | None = None) -> sp.Matrix:
        """A SymPy matrix of ring elements; float noise is judged against the largest
        coefficient of the whole matrix unless ``reference`` is given."""
        reference = self.largest(rows) if reference is None else reference
        return sp.Matrix([[self.expr(f, reference) for f in row] for row in rows])


def round_floats(expr: sp.Expr, digits: int = 15, keep=frozenset()) -> sp.Expr:
    """``expr`` with every Float rounded to ``digits`` significant digits (the last bits of a
    float sum are rounding noise: ``0.0090000000000000018`` is ``0.009``) except those whose
    value is in ``keep`` (the numbers a description wrote, ``1/3`` with all 16 digits), and a
    Float that is then a whole number replaced by that Integer (``1.0*x`` is ``x``).

    >>> x = sp.Symbol("x")
    >>> round_floats(sp.Float("0.0090000000000000018", 20) * x + sp.Float(1.0) * x**2)
    x**2 + 0.009*x
    >>> round_floats(sp.Float(1 / 3) * x, keep={1 / 3}) == sp.Float(1 / 3) * x
    True
    """
    floats = expr.atoms(sp.Float)
    if not floats:
        return expr
    rounded = {}
    for x in floats:
        value = float(x) if float(x) in keep else float(f"{float(x):.{digits}g}")
        rounded[x] = (sp.Integer(int(value)) if value.is_integer() and abs(value) < 2 ** 53
                      else sp.Float(value))
    return expr.xreplace(rounded)


def _swap_squares(f, k: int, j: int):
    """``f`` with every ``x_k²`` replaced by ``1 − x_j²`` (for a pair ``x_k² + x_j² = 1`` of
    generators)."""
    ring = f.ring
    b = ring.gens[j]
    one_minus = ring.one - b * b
    out = ring.zero
    for monomial, coefficient in f.terms():
        e = monomial[k]
        if e < 2:
            out += ring({monomial: coefficient})
            continue
        base = list(monomial)
        base[k] = e % 2
        out += ring({tuple(base): coefficient}) * one_minus ** (e // 2)
    return out
