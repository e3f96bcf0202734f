"""Number literals and straight-line programs as every printer writes them
(eomgen.symbolic.printing): one mixin for the literals, one print_program for the programs."""

from __future__ import annotations

import math
import random
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from eomgen.analysis.routes import _BatchPrinter, compile_batch, compile_scalar
from eomgen.codegen import available_backends
from eomgen.codegen.backends.fast_backend import FastCPrinter
from eomgen.symbolic.evaluate import FloatPrinter, compile_program
from eomgen.symbolic.printing import FloatLiteralMixin, ordered_terms, print_program, renamed
from eomgen.symbolic.program import Program
from support.expressions import X, Z, random_expressions
from support.extras import need

#: Every code backend's registered printer (the registry: a new backend is tested too), and
#: the printers of the numeric routes.
PRINTERS = [FloatPrinter, _BatchPrinter] + [
    b.printer for b in available_backends().values()
    if b.printer is not None and issubclass(b.printer, FloatLiteralMixin)]


def _rationals(count: int = 2000) -> list[sp.Rational]:
    """Small and large numerators and denominators, both signs; most p/q are not doubles
    (q not a power of two), some have p or q beyond 2**53 (not exact as doubles either)."""
    rng = random.Random(12)
    out = [sp.Rational(1, 2), sp.Rational(1, 3), sp.Rational(2, 3), sp.Rational(-1, 6),
           sp.Rational(1, 10), sp.Rational(2**53 + 2, 3), sp.Rational(1, 2**60 + 1)]
    while len(out) < count:
        bits = rng.choice((4, 20, 53, 60, 120))
        p = rng.randint(1, 2**bits) * rng.choice((1, -1))
        q = rng.randint(2, 2**rng.choice((4, 20, 53, 60, 120)))
        r = sp.Rational(p, q)
        if not r.is_Integer:
            out.append(r)
    return out


def _value(printer, text: str) -> float:
    """The double a printed literal stands for: Python's float() reads a decimal correctly
    rounded, as C's strtod does; the batch printer's _F(x) is x in float64 here."""
    if isinstance(printer, _BatchPrinter):
        assert text.startswith("_F(") and text.endswith(")")
        text = text[3:-1]
    return float(text)


@pytest.mark.parametrize("cls", PRINTERS, ids=lambda c: c.__name__)
def test_a_rational_is_the_literal_of_the_double_python_computes(cls):
    """p/q is printed as one literal (no division left for run time) that reads back as the
    double Python's p/q gives (integer true division, correctly rounded): exactly the value
    the former "(p/q)" produced, for every rational, exact as a double or not."""
    printer = cls({"standard": "python3"}) if cls is not FastCPrinter else cls()
    inexact = 0
    for r in _rationals():
        p, q = int(r.p), int(r.q)
        text = printer.doprint(r)
        assert "/" not in text, text
        assert _value(printer, text) == p / q, (r, text)
        # and p/q is the double nearest to the rational (no double rounding)
        assert Fraction(p / q) == Fraction(p, q) or abs(Fraction(p / q) - Fraction(p, q)) <= \
            abs(Fraction(math.nextafter(p / q, math.inf)) - Fraction(p, q))
        inexact += Fraction(p / q) != Fraction(p, q)
    assert inexact > 1500  # the claim is tested where it matters: p/q not a double


@pytest.mark.parametrize("cls", PRINTERS, ids=lambda c: c.__name__)
def test_positive_literals_stand_bare_and_negative_ones_keep_parentheses(cls):
    printer = cls({"standard": "python3"}) if cls is not FastCPrinter else cls()
    x = sp.Symbol("x")
    half = printer.doprint(sp.Rational(1, 2))
    assert printer.doprint(sp.Rational(1, 2) * x) == f"{half}*x"
    if isinstance(printer, FloatPrinter):  # Python's ** binds tighter than unary minus
        text = printer.doprint(sp.Pow(sp.Rational(-1, 3), x, evaluate=False))
        assert text == "(-0.3333333333333333)**x"
        assert eval(text, {"x": 2}) == (-1 / 3) ** 2  # noqa: S307


def test_python_code_with_rationals_evaluates_as_sympy_does():
    """Printed with the shared literals, an expression full of rationals evaluates (math
    functions) to SymPy's own value of it, to rounding."""
    x, y = sp.symbols("x y")
    expr = (sp.Rational(1, 3) * x**2 - sp.Rational(7, 2) * sp.sin(y) / (1 + sp.Rational(2, 5) * x)
            + sp.Pow(sp.Rational(-1, 3), 3) * y + x**sp.Rational(1, 3))
    printer = FloatPrinter({"standard": "python3"})
    value = eval(printer.doprint(expr), {"sin": math.sin, "x": 1.7, "y": -0.4})  # noqa: S307
    assert value == pytest.approx(float(expr.subs({x: 1.7, y: -0.4})), rel=1e-15)


def test_mixin_is_the_only_number_printing_of_the_printers():
    """Every code printer takes its number literals from the one mixin."""
    for cls in PRINTERS:
        assert issubclass(cls, FloatLiteralMixin)
        owner = next(k for k in cls.__mro__ if "_print_Rational" in vars(k))
        assert owner is FloatLiteralMixin, cls


def _small_program():
    q1, q2, m = sp.symbols("q1 q2 m")
    s = sp.Symbol("s")
    program = Program(((s, sp.sin(q1) * sp.cos(q2)),),
                      (("A", sp.Matrix([[s + m / 3, q1 * q2], [sp.Rational(1, 7), s**2]])),
                       ("b", sp.Matrix([s * m, q2]))))
    exact = {"A": sp.Matrix([[sp.sin(q1) * sp.cos(q2) + m / 3, q1 * q2],
                             [sp.Rational(1, 7), (sp.sin(q1) * sp.cos(q2))**2]]),
             "b": sp.Matrix([sp.sin(q1) * sp.cos(q2) * m, q2])}
    return program, (q1, q2, m), exact


def test_every_evaluator_of_a_program_agrees_with_sympy():
    """compile_program (NumPy scalars), compile_scalar (math, flat), compile_batch (arrays)
    and the mpmath reference all print the program with print_program; each equals SymPy's
    evaluation of the expanded outputs."""
    mpmath = need("mpmath", reason="the mpmath reference needs mpmath")
    from eomgen.analysis.precision import compile_program_mp

    program, inputs, exact = _small_program()
    values = (0.3, -1.1, 2.5)
    expected = {k: np.array(v.subs(dict(zip(inputs, values))).evalf(30), dtype=float)
                for k, v in exact.items()}
    got = compile_program(program, inputs)(*values)
    flat = compile_scalar(program, inputs, ["A", "b"])(*values)
    batch = compile_batch(program, inputs, ["b", "A"])(*[np.array([v]) for v in values])
    with mpmath.workdps(30):
        mp = compile_program_mp(program, inputs, ["A"])(*values)
    for name in ("A", "b"):
        np.testing.assert_allclose(got[name], expected[name], rtol=1e-15)
    np.testing.assert_allclose(np.reshape(flat[0], (2, 2)), expected["A"], rtol=1e-15)
    np.testing.assert_allclose(flat[1], expected["b"].ravel(), rtol=1e-15)
    np.testing.assert_allclose(batch[1][0], expected["A"], rtol=1e-15)
    np.testing.assert_allclose(batch[0][0], expected["b"], rtol=1e-15)
    np.testing.assert_allclose(np.array(mp["A"], dtype=float), expected["A"], rtol=1e-15)
    assert set(mp) == {"A"}


def test_print_program_prunes_renames_and_fixes():
    program, (q1, q2, m), _ = _small_program()
    text = print_program(program, (q1, q2), FloatPrinter(), ["b"], fixed={m: 2}, flat=True)
    assert text.splitlines()[0] == "def _program(_a0, _a1):"
    assert text.splitlines()[1:] == ["    s = sin(_a0)*cos(_a1)", "    return ([2*s, _a1],)"]


def _sympys_own(cls):
    """``cls`` printing sums and products with SymPy's own methods (StrPrinter._print_Add,
    CodePrinter._print_Mul, StrPrinter.parenthesize and SymPy's term order, then a term
    without a minus sign first) and the mixin's literals: the reference of the mixin's faster
    sums and products."""
    from sympy.printing.codeprinter import CodePrinter
    from sympy.printing.printer import Printer
    from sympy.printing.str import StrPrinter

    def parenthesize(self, item, level, strict=False):
        if isinstance(item, sp.Rational) and not item.is_Integer and item.is_positive:
            return self._print(item)
        return StrPrinter.parenthesize(self, item, level, strict)

    def ordered(self, expr, order=None):
        terms = Printer._as_ordered_terms(self, expr, order=order)
        if terms and terms[0].could_extract_minus_sign():
            for k, term in enumerate(terms):
                if not term.could_extract_minus_sign():
                    return [term] + terms[:k] + terms[k + 1:]
        return terms

    return type("SymPys" + cls.__name__, (cls,), {
        "_print_Add": StrPrinter._print_Add, "_print_Mul": CodePrinter._print_Mul,
        "parenthesize": parenthesize, "_as_ordered_terms": ordered})


@pytest.mark.parametrize("cls", PRINTERS, ids=lambda c: c.__name__)
def test_sums_and_products_print_as_sympys_own_methods_print_them(cls):
    """The mixin's sums and products (signs read off leading numbers, negations listed, not
    built) give SymPy's text, character for character, on random expressions and their
    renamed copies (``renamed``, what the backends print, against ``xreplace``)."""
    make = (lambda c: c({"standard": "python3"})) if cls is not FastCPrinter else (lambda c: c())
    ours, reference = make(cls), make(_sympys_own(cls))
    names = {X: sp.Symbol("t_x", real=True), Z: sp.Symbol("q[2]", real=True)}
    evaluated = 0
    for expr in random_expressions(300, seed=3):
        assert ours.doprint(expr) == reference.doprint(expr), expr
        if expr.xreplace(names).xreplace({v: k for k, v in names.items()}) == expr:
            # an evaluated expression (what a derivation makes; -(x + y) built unevaluated
            # becomes -x - y in xreplace)
            evaluated += 1
            assert ours.doprint(renamed(expr, names)) == reference.doprint(
                expr.xreplace(names)), expr
    assert evaluated > 300


def test_ordered_terms_are_sympys_order():
    sums = [e for e in random_expressions(600, seed=7) if e.is_Add]
    sums += [a for e in sums for a in e.args if a.is_Add]
    assert len(sums) > 200
    for expr in sums:
        assert ordered_terms(expr) == expr.as_ordered_terms(), expr
