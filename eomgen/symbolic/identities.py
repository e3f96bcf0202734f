"""Whether a symbolic identity holds: exactly for exact expressions, to a stated tolerance when
they hold floating-point numbers.

A rotation read from floats (``rpy="0 0 0.5"``) is orthogonal only to rounding, so an identity
such as "Ṁ − 2C is skew-symmetric" leaves terms like ``4.4e-15*l1*lc2*m2*cos(q2)`` after
simplification, and an exact comparison with zero fails. :func:`check_zero` decides the
identity exactly when the expressions hold no :class:`~sympy.core.numbers.Float` (a residual
must simplify to 0), and otherwise compares the largest coefficient of the residual with the
largest coefficient of a scale (the terms the identity is about) against
:data:`FLOAT_TOLERANCE`; its result says which it did, in words a reader of a handout or a
notebook sees:

>>> import sympy as sp
>>> q, l = sp.symbols("q l")
>>> print(check_zero("N + N^T = 0", sp.Matrix([4e-15 * l * sp.cos(q)]),
...                  sp.Matrix([2.0 * l * sp.cos(q)])))
N + N^T = 0 to 1e-12 (the model has floating-point numbers; largest relative residual 2.0e-15)
>>> print(check_zero("N + N^T = 0", sp.Matrix([0]), sp.Matrix([l])))
N + N^T = 0 exactly
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

#: Relative tolerance of a symbolic identity of expressions with floating-point numbers: far
#: above the rounding of double precision (1e-16 per operation, a few hundred operations),
#: far below any real failure (a wrong term has a coefficient of the size of the others).
FLOAT_TOLERANCE = 1e-12


@dataclass(frozen=True)
class ZeroCheck:
    """The outcome of :func:`check_zero`.

    Attributes
    ----------
    statement:
        What was checked, in words (``Mdot - 2C is skew-symmetric``).
    exact:
        The expressions hold no floats: the residual had to be exactly 0.
    residual:
        The largest absolute coefficient of the residual over the largest of the scale (0 when
        the residual is 0).
    tolerance:
        The bound on ``residual`` when not ``exact``.
    """

    statement: str
    exact: bool
    residual: float
    tolerance: float = FLOAT_TOLERANCE

    @property
    def holds(self) -> bool:
        return self.residual == 0 if self.exact else self.residual <= self.tolerance

    def __str__(self) -> str:
        if self.exact:
            return (f"{self.statement} exactly" if self.holds else
                    f"{self.statement}: FAILED, the residual is not 0 (largest relative "
                    f"coefficient {self.residual:.1e})")
        floats = (f"the model has floating-point numbers; largest relative residual "
                  f"{self.residual:.1e}")
        return (f"{self.statement} to {self.tolerance:g} ({floats})" if self.holds else
                f"{self.statement}: FAILED, not even to {self.tolerance:g} ({floats})")


def largest_coefficient(matrix) -> float:
    """The largest absolute numeric coefficient of the expanded terms of ``matrix``'s entries
    (0 for a zero matrix): ``3*x*cos(q) - 1e-15*y`` gives 3."""
    largest = 0.0
    for entry in sp.Matrix(matrix):
        for term in sp.Add.make_args(sp.expand(entry)):
            if term == 0:
                continue
            coefficient, _ = term.as_independent(*term.free_symbols, as_Add=False)
            largest = max(largest, abs(float(coefficient)))
    return largest


def check_zero(statement: str, residual, scale, tolerance: float = FLOAT_TOLERANCE
               ) -> ZeroCheck:
    """Whether ``residual`` (a matrix, simplified as far as the caller can: trigonometric
    identities applied) is zero: exactly when neither it nor ``scale`` holds a float, else to
    ``tolerance`` relative to :func:`largest_coefficient` of ``scale`` (the terms the identity
    is about; 1 when that is zero)."""
    residual, scale = sp.Matrix(residual), sp.Matrix(scale)
    exact = not (residual.has(sp.Float) or scale.has(sp.Float))
    size = largest_coefficient(residual)
    return ZeroCheck(statement, exact, size / (largest_coefficient(scale) or 1.0), tolerance)


__all__ = ["FLOAT_TOLERANCE", "ZeroCheck", "check_zero", "largest_coefficient"]
