"""The model's numbers: SymPy scalars, 3-vectors and 3×3 matrices, and parameter symbols.

Integral floats become exact SymPy Integers so that structural zeros and ones propagate; other
floats become SymPy Floats at double precision.
"""

from __future__ import annotations

from typing import Iterable

import sympy as sp

Scalar = sp.Expr
Vec3 = tuple[sp.Expr, sp.Expr, sp.Expr]
Mat3 = tuple[Vec3, Vec3, Vec3]


def parameter_symbol(name: str) -> sp.Symbol:
    """The one way eomgen makes a parameter symbol (real-valued), so that equal names give
    equal symbols everywhere."""
    return sp.Symbol(name, real=True)


def scalar(value) -> sp.Expr:
    """Convert a number or SymPy expression to the model's scalar type.

    Integral floats become exact SymPy Integers (``0.0`` → ``0``) so that they propagate as
    structural zeros and ones; other floats become SymPy Floats at double precision.
    """
    if isinstance(value, sp.Basic):
        if value.is_Float and float(value).is_integer():
            return sp.Integer(int(float(value)))
        return value
    if isinstance(value, bool):
        raise TypeError("booleans are not scalars")
    if isinstance(value, int):
        return sp.Integer(value)
    value = float(value)
    if value.is_integer():
        return sp.Integer(int(value))
    return sp.Float(value, 17)


def vec3(values: Iterable) -> Vec3:
    out = tuple(scalar(v) for v in values)
    if len(out) != 3:
        raise ValueError("a 3-vector needs three components")
    return out  # type: ignore[return-value]


def mat3(rows: Iterable[Iterable]) -> Mat3:
    out = tuple(vec3(r) for r in rows)
    if len(out) != 3:
        raise ValueError("a 3×3 matrix needs three rows")
    return out  # type: ignore[return-value]


IDENTITY3: Mat3 = mat3([[1, 0, 0], [0, 1, 0], [0, 0, 1]])
ZERO3: Vec3 = vec3([0, 0, 0])
