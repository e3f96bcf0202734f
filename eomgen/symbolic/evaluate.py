"""Numeric evaluation of a straight-line program, for verification and notebooks.

The program is printed once, with SymPy's Python printer, into a plain Python function over
floats or complex numbers (NumPy's scalar functions); no expression is ever expanded. Generated modules for users come
from the code generation backends instead; this evaluator exists so that verification does not
depend on them.
"""

from __future__ import annotations

from typing import Callable, Sequence

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from .printing import FloatLiteralMixin, program_function
from .program import Program


class FloatPrinter(FloatLiteralMixin, PythonCodePrinter):
    """Python code over floats (or complex numbers): ``sin(x)`` unqualified, so that the
    namespace the code runs in chooses ``math``'s or NumPy's functions; exact float literals."""

    def __init__(self, settings=None):
        super().__init__({"fully_qualified_modules": False, "standard": "python3",
                          **(settings or {})})


def compile_program(program: Program, inputs: Sequence[sp.Symbol]) -> Callable[..., dict]:
    """A function ``f(*values) -> {output name: ndarray}`` evaluating ``program``.

    ``inputs`` are the symbols the caller provides values for, in order (joint symbols and any
    parameters kept symbolic).
    """
    import numpy as np  # here: derive imports this module (through frames), not NumPy

    printer = FloatPrinter()
    names = [name for name, _ in program.outputs]
    functions = {f: getattr(np, f) for f in ("sin", "cos", "tan", "sqrt", "pi")}
    raw = program_function(program, inputs, printer, functions)

    def evaluate(*values) -> dict:
        """Values may be floats or complex numbers (complex-step differentiation)."""
        out = raw(*values)
        dtype = complex if any(isinstance(v, complex) for v in values) else float
        return {k: np.array(v, dtype=dtype) for k, v in zip(names, out)}

    return evaluate
