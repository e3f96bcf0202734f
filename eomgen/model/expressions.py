"""A restricted parser for the numbers and simple expressions written in descriptions.

User text is never passed to ``eval`` or ``sympify``. This module accepts exactly: decimal
numbers, parameter names (identifiers), the constant ``pi``, the operators ``+ - * / **`` with
parentheses, and the functions ``sin cos tan sqrt``; numbers must be finite and of magnitude
at most :data:`MAX_MAGNITUDE` (:mod:`eomgen.model.numbers`). Anything else is refused with a
:class:`ValueError` whose message says what was not understood; parsers turn it into a
:class:`~eomgen.errors.DescriptionError` naming file and element.
"""

from __future__ import annotations

import ast
import keyword
import math
import re

import sympy as sp

from . import parameter_symbol, scalar
from .numbers import MAX_MAGNITUDE, number_problem  # noqa: F401  (MAX_MAGNITUDE: its home)

MAX_LENGTH = 200
MAX_EXPONENT = 16

_FUNCTIONS = {"sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "sqrt": sp.sqrt}
_CONSTANTS = {"pi": sp.pi}
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
#: Names eomgen uses for its own symbols (joint positions, velocities, accelerations, torques).
RESERVED = re.compile(r"^(q|qd|qdd|tau)[0-9]+$")


def check_parameter_name(name: str) -> str:
    """Return ``name`` if it can be a parameter symbol, else raise ValueError saying why."""
    if not isinstance(name, str) or not _NAME.match(name):
        raise ValueError(
            f"parameter name {name!r} must start with a letter and use only letters, digits, _"
        )
    if keyword.iskeyword(name) or name in _FUNCTIONS or name in _CONSTANTS:
        raise ValueError(f"parameter name {name!r} is a reserved word")
    if _is_number_text(name):  # nan, inf, infinity: a value of that name would read as a number
        raise ValueError(f"parameter name {name!r} reads as a number")
    if RESERVED.match(name):
        raise ValueError(f"parameter name {name!r} is reserved for joint variables")
    if len(name) > 64:
        raise ValueError(f"parameter name {name[:20]!r}... is longer than 64 characters")
    return name


def parse_scalar(text) -> sp.Expr:
    """Parse a number or a simple expression (see module docstring) into a SymPy scalar.

    >>> parse_scalar("l1/2")
    l1/2
    >>> parse_scalar(0.25)
    0.25000000000000000
    """
    if isinstance(text, bool):
        raise ValueError(f"{text!r} is not a number")
    if isinstance(text, (int, float)):
        if isinstance(text, float) and not math.isfinite(text):
            raise ValueError(f"{text!r} is not a finite number")
        _check_magnitude(text, _shorten(repr(text)))
        return scalar(text)
    if not isinstance(text, str):
        raise ValueError(f"expected a number or expression, got {type(text).__name__}")
    text = text.strip()
    if not text:
        raise ValueError("empty value")
    if len(text) > MAX_LENGTH:
        raise ValueError(f"expression longer than {MAX_LENGTH} characters")
    try:
        value = scalar(float(text)) if _is_float(text) else _convert(ast.parse(text, mode="eval").body)
    except (SyntaxError, RecursionError, MemoryError) as exc:
        raise ValueError(f"cannot parse {text!r} as a number or expression") from exc
    if value.has(sp.I, sp.zoo, sp.oo, sp.nan):  # sqrt(-1), 0**-1, ...
        raise ValueError(f"{text!r} is not a finite real number")
    for number in value.atoms(sp.Number) | ({value} if value.is_number else set()):
        _check_magnitude(number, repr(text))
    return value


def _check_magnitude(value, shown: str) -> None:
    """Refuse a number (int, float or SymPy number) that breaks the rule of
    :mod:`eomgen.model.numbers` (finite, magnitude at most :data:`MAX_MAGNITUDE`)."""
    problem = number_problem(value)
    if problem is not None:
        raise ValueError(f"{shown} {problem}")


def _shorten(text: str, length: int = 24) -> str:
    return text if len(text) <= length else text[:length] + "..."


def _is_number_text(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _is_float(text: str) -> bool:
    try:
        value = float(text)
    except ValueError:
        return False
    if not math.isfinite(value):
        raise ValueError(f"{text!r} is not a finite number")
    _check_magnitude(value, repr(text))
    return True


_BINARY = {
    ast.Add: lambda a, b: a + b,
    ast.Sub: lambda a, b: a - b,
    ast.Mult: lambda a, b: a * b,
    ast.Div: lambda a, b: a / b,
}


def _convert(node: ast.AST) -> sp.Expr:
    if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) and not isinstance(
        node.value, bool
    ):
        if isinstance(node.value, float) and not math.isfinite(node.value):
            raise ValueError("number is not finite")
        _check_magnitude(node.value, _shorten(ast.unparse(node)))
        return scalar(node.value)
    if isinstance(node, ast.Name):
        if node.id in _CONSTANTS:
            return _CONSTANTS[node.id]
        return parameter_symbol(check_parameter_name(node.id))
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        value = _convert(node.operand)
        return -value if isinstance(node.op, ast.USub) else value
    if isinstance(node, ast.BinOp):
        if isinstance(node.op, ast.Pow):
            base = _convert(node.left)
            exponent = _convert(node.right)
            if not (exponent.is_number and abs(float(exponent)) <= MAX_EXPONENT):
                raise ValueError(f"exponent must be a number of magnitude ≤ {MAX_EXPONENT}")
            return base**exponent
        op = _BINARY.get(type(node.op))
        if op is not None:
            left, right = _convert(node.left), _convert(node.right)
            if isinstance(node.op, ast.Div) and right == 0:
                raise ValueError("division by zero")
            return op(left, right)
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords:
        function = _FUNCTIONS.get(node.func.id)
        if function is not None and len(node.args) == 1:
            return function(_convert(node.args[0]))
    raise ValueError(f"unsupported syntax {ast.dump(node)[:40]!r}: only numbers, names, "
                     "+ - * / **, parentheses and sin cos tan sqrt are allowed")
