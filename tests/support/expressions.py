"""Random SymPy expressions of the shapes a derivation prints and counts: sums and products of
symbols and numbers of both signs (floats, integers, rationals), powers (squares, inverses,
square roots, symbolic exponents), negations, sines, cosines and hyperbolic tangents, nested a
few levels deep; and a few hand-picked edge cases (unevaluated products of a number and a sum,
``exp``, ``Max``, a piecewise)."""

from __future__ import annotations

import random

import sympy as sp

X, Y, Z = sp.symbols("x y z", real=True)

EDGE_CASES = (
    sp.Mul(-1, X + Y, evaluate=False), sp.Mul(2, X + Y, evaluate=False),
    sp.Mul(-2, X + Y, evaluate=False), sp.Mul(-1, X, evaluate=False),
    sp.Mul(-1, sp.sin(X) * Y, evaluate=False), sp.Add(-X, -Y, -Z * X, evaluate=False),
    -X, -2 * X, X - 2.5 * Y, -X - Y, -X + Y, X / Y, -X / Y, X**-2, sp.sqrt(X), sp.exp(X),
    sp.exp(-X), sp.Max(X, Y), sp.sign(X) * sp.tanh(X / Y), sp.Rational(-1, 3), sp.Rational(1, 3) * X,
    -sp.Rational(1, 3) * X, sp.Float(-2.5), sp.S.One, sp.S.NegativeOne, sp.S.Zero,
    -sp.sin(X)**2 + 1, sp.Piecewise((X, X > 0), (Y, True)), sp.pi * X, -sp.pi * X, X**Y, 2**X,
    -X * Y * Z - 2.0 * X, (X + Y)**-1 * Z, -(X * Y)**-1, 1 / (2 * X * Y))


def random_expressions(count: int, seed: int = 0) -> list[sp.Expr]:
    """``count`` random expressions (module docstring), then :data:`EDGE_CASES`."""
    rng = random.Random(seed)
    atoms = [X, Y, Z, sp.Float(2.5), sp.Float(-0.75), sp.Integer(2), sp.Integer(-3),
             sp.Rational(1, 2), sp.Rational(-2, 3)]

    def draw(depth: int) -> sp.Expr:
        if depth == 0:
            return rng.choice(atoms)
        k = rng.random()
        if k < 0.35:
            return sp.Add(*[draw(depth - 1) for _ in range(rng.randint(2, 4))])
        if k < 0.7:
            return sp.Mul(*[draw(depth - 1) for _ in range(rng.randint(2, 3))])
        if k < 0.8:
            return draw(depth - 1)**rng.choice([2, 3, -1, -2, sp.Rational(1, 2), Y])
        if k < 0.9:
            return -draw(depth - 1)
        return rng.choice([sp.sin, sp.cos, sp.tanh])(draw(depth - 1))

    return [draw(rng.randint(1, 4)) for _ in range(count)] + list(EDGE_CASES)
