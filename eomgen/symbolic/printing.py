"""Printing numbers and straight-line programs as code, and running printed Python: one place.

Two things every printer of eomgen shares:

* :class:`FloatLiteralMixin`: how a number of the derivation becomes a literal. A SymPy
  ``Float`` is printed as the shortest decimal that reads back as the same double
  (``repr(float(x))``, 17 significant digits at most), and an exact ``Rational`` ``p/q`` as
  the literal of the double nearest to ``p/q``: the value Python's ``p/q`` computes (integer
  true division is correctly rounded), so no generated code spends a division on a constant.
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
from sympy.printing.numpy import NumPyPrinter

from .program import Program


class FloatLiteralMixin:
    """Number literals for a SymPy code printer (put it before the printer class).

    ``Float`` → ``repr(float(x))``; non-integer ``Rational`` ``p/q`` → the literal of the
    double ``p/q`` (correctly rounded), printed without parentheses when positive (a positive
    literal is an atom in Python and C). Integers keep the printer's own form.
    """

    def _literal(self, value: float) -> str:
        """The literal of one double; ``repr`` (round-trips exactly)."""
        return repr(value)

    def _print_Float(self, expr):
        return self._literal(float(expr))

    def _print_Rational(self, expr):
        return self._literal(int(expr.p) / int(expr.q))

    def _as_ordered_terms(self, expr, order=None):
        """SymPy's order of a sum's terms, but a term without a minus sign first when there
        is one: ``y - 2*x`` rather than ``-2*x + y``, which spends a negation."""
        terms = super()._as_ordered_terms(expr, order=order)
        if terms and terms[0].could_extract_minus_sign():
            for k, term in enumerate(terms):
                if not term.could_extract_minus_sign():
                    return [term] + terms[:k] + terms[k + 1:]
        return terms

    def parenthesize(self, item, level, strict=False):
        if isinstance(item, sp.Rational) and not item.is_Integer and item.is_positive:
            return self._print(item)
        return super().parenthesize(item, level, strict)


class NumPyModulePrinter(FloatLiteralMixin, NumPyPrinter):
    """NumPy code with ``np.`` as the module prefix and exact float literals
    (:class:`FloatLiteralMixin`): the printer of the NumPy backend
    (:mod:`eomgen.codegen.backends.numpy_backend`)."""

    def _module_format(self, fqn, register=True):
        text = super()._module_format(fqn, register)
        return "np." + text[len("numpy."):] if text.startswith("numpy.") else text


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
