"""Numeric evaluation of a straight-line program, for verification and notebooks.

The program is printed once, with SymPy's Python printer, into a plain Python function over
floats or complex numbers (NumPy's scalar functions); no expression is ever expanded. Generated modules for users come
from the code generation backends instead; this evaluator exists so that verification does not
depend on them.
"""

from __future__ import annotations

from typing import Callable, Sequence

import numpy as np
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from .program import Program


class _FloatPrinter(PythonCodePrinter):
    """Prints floats with full precision and symbols by name."""

    def _print_Float(self, expr):
        return repr(float(expr))

    def _print_Rational(self, expr):
        return f"({int(expr.p)}/{int(expr.q)})"


def compile_program(program: Program, inputs: Sequence[sp.Symbol]) -> Callable[..., dict]:
    """A function ``f(*values) -> {output name: ndarray}`` evaluating ``program``.

    ``inputs`` are the symbols the caller provides values for, in order (joint symbols and any
    parameters kept symbolic).
    """
    printer = _FloatPrinter({"fully_qualified_modules": False, "standard": "python3"})
    names = [f"a{k}" for k in range(len(inputs))]
    rename = {s: sp.Symbol(n) for s, n in zip(inputs, names)}
    lines = ["def _program(" + ", ".join(names) + "):"]
    for symbol, expr in program.assignments:
        lines.append(f"    {symbol.name} = {printer.doprint(expr.xreplace(rename))}")
    results = []
    for name, matrix in program.outputs:
        rows = [[printer.doprint(e.xreplace(rename)) for e in matrix.row(r)] for r in range(matrix.rows)]
        results.append(f"{name!r}: [" + ", ".join("[" + ", ".join(r) + "]" for r in rows) + "]")
    lines.append("    return {" + ", ".join(results) + "}")
    namespace: dict = {}
    functions = {f: getattr(np, f) for f in ("sin", "cos", "tan", "sqrt", "pi")}
    exec(compile("\n".join(lines), "<eomgen program>", "exec"),  # noqa: S102 - our own printed code
         functions, namespace)
    raw = namespace["_program"]

    def evaluate(*values) -> dict:
        """Values may be floats or complex numbers (complex-step differentiation)."""
        out = raw(*values)
        dtype = complex if any(isinstance(v, complex) for v in values) else float
        return {k: np.array(v, dtype=dtype) for k, v in out.items()}

    return evaluate
