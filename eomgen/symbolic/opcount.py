"""Operation counts of generated code, read from the Python syntax tree of the printed NumPy code.

SymPy's ``count_ops`` counts a SymPy expression (``x - y`` as ``x + (-1)·y``, a rational as one
division); what a generated function executes is what its printed source says. This module
counts the printed source: every arithmetic binary operator (``+ - * / **``), every unary minus
and every call of an elementwise NumPy math function (``np.sin``, ``np.cos``, ``np.sqrt``, …) is
one operation; calls that only move data (``np.zeros``, ``np.asarray``, the input checks) and the
arguments inside them are not counted. ``x**2`` is one operation, as is ``-x``.

This is the counter of the complexity benchmark (``benchmarks/complexity.py``) and of the
operation-count targets of the generated programs.
"""

from __future__ import annotations

import ast
from typing import Iterable

from .printing import NumPyModulePrinter

#: NumPy functions counted as one arithmetic operation each.
MATH_FUNCTIONS = frozenset({"sin", "cos", "tan", "sqrt", "exp", "log", "arctan2", "abs",
                            "sinh", "cosh", "tanh", "arcsin", "arccos", "arctan", "sign"})


def count_node(node: ast.AST) -> int:
    """Arithmetic operations in the syntax tree ``node`` (see the module docstring)."""
    if isinstance(node, ast.Call):
        name = ast.unparse(node.func)
        if not (name.startswith("np.") and name[3:] in MATH_FUNCTIONS):
            return 0  # data movement (np.zeros, _states, …): its arguments are not arithmetic
        own = 1
    elif isinstance(node, ast.BinOp):
        own = 1
    elif isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
        own = 1
    else:
        own = 0
    return own + sum(count_node(child) for child in ast.iter_child_nodes(node))


def module_operation_counts(source: str) -> dict[str, int]:
    """Operations of every public top-level function of a Python module's ``source``."""
    tree = ast.parse(source)
    return {fn.name: count_node(fn) for fn in tree.body
            if isinstance(fn, ast.FunctionDef) and not fn.name.startswith("_")}


def program_operation_count(program, names: Iterable[str] | None = None) -> int:
    """Operations of ``program`` (a :class:`~eomgen.symbolic.program.Program`) printed as the
    NumPy backend prints it: its assignments needed for the named outputs (all by default) and
    their non-zero output entries. Equals :func:`module_operation_counts` of a generated NumPy
    module for the function computing those outputs."""
    printer = NumPyModulePrinter({"fully_qualified_modules": True, "standard": "python3"})
    program = program if names is None else program.pruned(names)
    total = 0
    for _, expr in program.assignments:
        total += count_node(ast.parse(printer.doprint(expr), mode="eval"))
    for _, matrix in program.outputs:
        for entry in matrix:
            if entry != 0:
                total += count_node(ast.parse(printer.doprint(entry), mode="eval"))
    return total
