"""Printing numbers and straight-line programs as code, and running printed Python: one place.

Two things every printer of eomgen shares:

* :class:`FloatLiteralMixin`: how a number of the derivation becomes a literal. A SymPy
  ``Float`` is printed as the shortest decimal that reads back as the same double
  (``repr(float(x))``, 17 significant digits at most), and an exact ``Rational`` ``p/q`` as
  the literal of the double nearest to ``p/q``: the value Python's ``p/q`` computes (integer
  true division is correctly rounded), so no generated code spends a division on a constant;
  an exact irrational constant such as ``sqrt(3)`` (from an angle of ``pi/6``) is the literal
  of its correctly rounded double too (``torch.sqrt`` takes no number).
  Backends whose literals look different (C needs ``1.0`` rather than ``1``; the float32
  batches wrap each literal in their dtype) override only :meth:`FloatLiteralMixin._literal`.
* :class:`NumPyModulePrinter`: the NumPy backend's printer (SymPy's ``NumPyPrinter`` with
  ``np.`` for the module and these literals), which :mod:`eomgen.symbolic.opcount` also counts
  operations with.
* :func:`print_program` and :func:`program_function`: a :class:`~eomgen.symbolic.program.Program`
  printed once into a Python function ``_program(*inputs)`` (assignments in evaluation order,
  then the outputs), compiled and run with :func:`exec_source` in a namespace holding only the
  functions the printer names (``math``'s, NumPy's or ``mpmath``). The printed text is our own
  program, never user text; nothing is expanded.

Examples
--------
>>> import sympy as sp
>>> from sympy.printing.pycode import PythonCodePrinter
>>> class Printer(FloatLiteralMixin, PythonCodePrinter):
...     pass
>>> x = sp.Symbol("x")
>>> Printer().doprint(sp.Rational(1, 2) * x + sp.Rational(1, 3))
'0.5*x + 0.3333333333333333'
"""

from __future__ import annotations

from typing import Callable, Mapping, Sequence

import sympy as sp
from sympy.core.function import Function
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.precedence import PRECEDENCE, precedence

from .monomials import leads_with_minus, leads_with_negative_number
from .program import Program, substituted

_MUL, _ADD = PRECEDENCE["Mul"], PRECEDENCE["Add"]
#: the precedence of a product whose leading factor is a negative number (``-x`` binds looser
#: than a product, tighter than a power: SymPy's weight for a unary minus)
_NEGATED = 0.5 * (PRECEDENCE["Pow"] + PRECEDENCE["Mul"])


def ordered_terms(expr: sp.Expr) -> list:
    """``expr.as_ordered_terms()`` (SymPy's canonical order of a sum's terms, which the code
    printers print), the same list, read off the terms of a sum of real numbers times products
    of integer powers of functions, symbols and other expressions in symbols, without SymPy's
    detour through complex coefficients; any other sum is ordered by SymPy itself."""
    args = expr.args
    if not expr.is_Add:
        return expr.as_ordered_terms()
    if len(args) == 2:  # SymPy's special case: a positive number, then −k·x
        numbers = sorted(args, key=lambda a: not isinstance(a, (sp.Number, sp.NumberSymbol)))
        if isinstance(numbers[0], (sp.Number, sp.NumberSymbol)) and numbers[1].is_Mul:
            factors = sorted(numbers[1].args, key=lambda a: not isinstance(a, sp.Number))
            if (len(factors) == 2 and isinstance(factors[0], sp.Number)
                    and numbers[0].is_positive and factors[0].is_negative):
                return numbers
    gens, terms = {}, []
    for term in args:
        if term.is_Number:
            coefficient, factors = term, ()
        elif term.is_Mul and term.args[0].is_Number:
            coefficient, factors = term.args[0], term.args[1:]
        elif term.is_Mul:
            coefficient, factors = sp.S.One, term.args
        else:
            coefficient, factors = sp.S.One, (term,)
        if not (coefficient.is_Rational or coefficient.is_Float):
            return expr.as_ordered_terms()
        powers = {}
        for factor in factors:
            base, exponent = (factor.base, factor.exp) if factor.is_Pow else (factor, sp.S.One)
            if (not exponent.is_Integer or isinstance(base, sp.exp) or not base.free_symbols
                    or not factor.is_commutative):
                return expr.as_ordered_terms()
            powers[base] = int(exponent)
            gens[base] = None
        terms.append((term, float(coefficient), powers))
    index = {g: k for k, g in enumerate(sorted(gens, key=sp.default_sort_key))}

    def key(entry):
        monomial = [0] * len(index)
        for base, exponent in entry[2].items():
            monomial[index[base]] = -exponent
        return tuple(monomial), entry[1]

    return [term for term, _, _ in sorted(terms, key=key)]


def fast_precedence(item) -> int:
    """SymPy's :func:`~sympy.printing.precedence.precedence`, with a product's sign read off
    its leading number (:func:`leads_with_negative_number`) rather than by negating it: the
    same value, without making and querying a new expression at every product printed."""
    if isinstance(item, sp.Mul) and not hasattr(item, "precedence"):
        if any(isinstance(a, Function) and getattr(a, "precedence", _MUL) < _MUL
               for a in item.args):
            return _MUL
        return _ADD if leads_with_negative_number(item) else _MUL
    return precedence(item)


class FloatLiteralMixin:
    """Number literals for a SymPy code printer (put it before the printer class).

    ``Float`` → ``repr(float(x))``; non-integer ``Rational`` ``p/q`` → the literal of the
    double ``p/q`` (correctly rounded), printed without parentheses when positive (a positive
    literal is an atom in Python and C); a real power of numbers (``sqrt(3)``) → the literal of
    its double, evaluated to 30 digits and rounded. Integers keep the printer's own form.
    """

    def _literal(self, value: float) -> str:
        """The literal of one double; ``repr`` (round-trips exactly)."""
        return repr(value)

    def _print_Float(self, expr):
        return self._literal(float(expr))

    def _print_Rational(self, expr):
        return self._literal(int(expr.p) / int(expr.q))

    def _print_Pow(self, expr, *args, **kwargs):
        if expr.is_number and expr.is_real:  # sqrt(3), from an angle of pi/6
            return self._literal(float(expr.evalf(30)))
        return super()._print_Pow(expr, *args, **kwargs)

    def _as_ordered_terms(self, expr, order=None):
        """SymPy's order of a sum's terms, but a term without a minus sign first when there
        is one: ``y - 2*x`` rather than ``-2*x + y``, which spends a negation."""
        if (order or self.order) is None:
            terms = ordered_terms(expr)
        else:
            terms = super()._as_ordered_terms(expr, order=order)
        if terms and leads_with_minus(terms[0]):
            for k, term in enumerate(terms):
                if not leads_with_minus(term):
                    return [term] + terms[:k] + terms[k + 1:]
        return terms

    def parenthesize(self, item, level, strict=False):
        if isinstance(item, sp.Rational) and not item.is_Integer and item.is_positive:
            return self._print(item)
        level_of_item = fast_precedence(item)
        if level_of_item < level or (not strict and level_of_item <= level):
            return "(%s)" % self._print(item)
        return self._print(item)

    # SymPy's code printers' sums and products (StrPrinter._print_Add, CodePrinter._print_Mul),
    # the same text, but a product's sign read off its leading number and its negation's factors
    # listed rather than built as a new product: SymPy's own versions make and query a new
    # expression for most products they print, half the time of printing a program.

    def _print_Add(self, expr, order=None):
        terms = self._as_ordered_terms(expr, order=order)
        level = fast_precedence(expr)
        parts = []
        for term in terms:
            text = self._print(term)
            if text.startswith("-") and not term.is_Add:
                sign, text = "-", text[1:]
            else:
                sign = "+"
            if term.is_Add or fast_precedence(term) < level:
                text = "(%s)" % text
            parts.extend([sign, text])
        sign = parts.pop(0)
        return ("" if sign == "+" else sign) + " ".join(parts)

    def _print_Mul(self, expr):
        if not expr.is_commutative or self.order in ("old", "none"):
            return super()._print_Mul(expr)
        level = fast_precedence(expr)
        if leads_with_negative_number(expr):
            sign, c = "-", -expr.args[0]
            factors = list(expr.args[1:])
            if any(f.is_Mul for f in factors) or (
                    c is not sp.S.One and len(factors) == 1 and factors[0].is_Add):
                return super()._print_Mul(expr)  # built unevaluated: -1·(x·y), c·(a + b)
            if c is not sp.S.One:
                factors.insert(0, c)
            factors.sort(key=lambda f: f.sort_key(order=self.order))
        else:
            sign, factors = "", expr.as_ordered_factors()
        numerator, denominator, grouped = [], [], []
        for item in factors:
            if item.is_Pow and item.exp.is_Rational and item.exp.is_negative:
                if item.exp != -1:
                    denominator.append(sp.Pow(item.base, -item.exp, evaluate=False))
                else:
                    if len(item.args[0].args) != 1 and isinstance(item.base, sp.Mul):
                        grouped.append(item)
                    denominator.append(sp.Pow(item.base, -item.exp))
            else:
                numerator.append(item)
        numerator = numerator or [sp.S.One]
        if len(numerator) == 1 and sign == "-":
            texts = [self.parenthesize(numerator[0], _NEGATED)]
        else:
            texts = [self.parenthesize(x, level) for x in numerator]
        below = [self.parenthesize(x, level) for x in denominator]
        for item in grouped:
            if item.base in denominator:
                k = denominator.index(item.base)
                below[k] = "(%s)" % below[k]
        if not denominator:
            return sign + "*".join(texts)
        if len(denominator) == 1:
            return sign + "*".join(texts) + "/" + below[0]
        return sign + "*".join(texts) + "/(%s)" % "*".join(below)


class NumPyModulePrinter(FloatLiteralMixin, NumPyPrinter):
    """NumPy code with ``np.`` as the module prefix and exact float literals
    (:class:`FloatLiteralMixin`): the printer of the NumPy backend
    (:mod:`eomgen.codegen.backends.numpy_backend`)."""

    def _module_format(self, fqn, register=True):
        text = super()._module_format(fqn, register)
        return "np." + text[len("numpy."):] if text.startswith("numpy.") else text


def renamed(expr: sp.Expr, names: Mapping[sp.Symbol, sp.Symbol]) -> sp.Expr:
    """``expr.xreplace(names)`` for a one-to-one renaming of symbols, printed alike when
    ``expr`` is evaluated (as a derivation's expressions are): sums and products are rebuilt
    from their new arguments as they stand (:func:`~eomgen.symbolic.program.substituted`), not
    flattened and sorted again as ``xreplace`` does, since a printer orders the terms and
    factors it prints itself and renamed symbols never merge.

    >>> x, y, t = sp.symbols("x y t_x")
    >>> renamed(2*x*y + sp.sin(x), {x: t})
    2*t_x*y + sin(t_x)
    """
    return substituted(expr, names) if names else expr


def print_program(program: Program, inputs: Sequence[sp.Symbol], printer,
                  outputs: Sequence[str] | None = None, fixed: Mapping | None = None,
                  flat: bool = False) -> str:
    """Python source of ``def _program(_a0, _a1, …)`` evaluating ``program``.

    Parameters
    ----------
    program:
        The straight-line program.
    inputs:
        The symbols the caller gives values for, in argument order (renamed ``_a0``, ``_a1``, …
        so that no input name can shadow a function of the namespace).
    printer:
        A SymPy code printer (its function names must exist in the namespace the source runs in).
    outputs:
        Output names to return, in order; the program is pruned to what they need. None: all of
        the program's outputs, unpruned.
    fixed:
        Symbols replaced by constants before printing (e.g. ``qdd = 0``; shortens the program).
    flat:
        Each output as one row-major list rather than a list of rows.

    Returns
    -------
    str
        The source; the function returns a tuple with one (nested) list per output.
    """
    if outputs is None:
        outputs = [name for name, _ in program.outputs]
    else:
        program = program.pruned(outputs)
    arguments = [f"_a{k}" for k in range(len(inputs))]
    rename = {s: sp.Symbol(a) for s, a in zip(inputs, arguments)}
    if fixed:
        rename.update({s: sp.sympify(v) for s, v in fixed.items()})
    lines = ["def _program(" + ", ".join(arguments) + "):"]
    for symbol, expr in program.assignments:
        lines.append(f"    {symbol.name} = {printer.doprint(expr.xreplace(rename))}")
    parts = []
    for name in outputs:
        matrix = program.output(name).xreplace(rename)
        rows = [[printer.doprint(e) for e in matrix.row(r)] for r in range(matrix.rows)]
        parts.append("[" + ", ".join(e for row in rows for e in row) + "]" if flat else
                     "[" + ", ".join("[" + ", ".join(row) + "]" for row in rows) + "]")
    lines.append("    return (" + ", ".join(parts) + ("," if len(parts) == 1 else "") + ")")
    return "\n".join(lines)


def exec_source(source: str, filename: str, namespace: dict) -> dict:
    """Compile and run ``source`` (eomgen's own printed or generated code, never user text) in
    ``namespace``; returns the namespace, which then holds what the source defined."""
    exec(compile(source, filename, "exec"), namespace)  # noqa: S102 - our own printed code
    return namespace


def program_function(program: Program, inputs: Sequence[sp.Symbol], printer, functions: dict,
                     outputs: Sequence[str] | None = None, fixed: Mapping | None = None,
                     flat: bool = False, filename: str = "<eomgen program>"
                     ) -> Callable[..., tuple]:
    """:func:`print_program` compiled: ``f(*values) -> (output 1, …)`` as (nested) lists.

    ``functions`` is the namespace the printed code runs in (e.g. ``{"sin": math.sin, …}``,
    ``{"np": numpy}`` or ``{"mpmath": mpmath}``), copied: the caller's dict is not changed.
    """
    source = print_program(program, inputs, printer, outputs, fixed, flat)
    return exec_source(source, filename, dict(functions))["_program"]


__all__ = ["FloatLiteralMixin", "print_program", "exec_source", "program_function"]
