"""M⁻¹ from straight-line factors (:func:`eomgen.symbolic.derivatives.symmetric_inverse`, the
inverse mass matrix of the derivative outputs): on a branched tree's mass-matrix pattern it
creates no fill-in (a factor entry only where one joint is an ancestor of the other), and its
program is the inverse (against NumPy's, on a matrix built with that pattern)."""

from __future__ import annotations

import re

import numpy as np
import sympy as sp

from eomgen.symbolic.derivatives import symmetric_inverse
from eomgen.symbolic.program import ProgramBuilder

#: a root joint carrying two branches of two joints each (parents before children)
PARENTS = (None, 0, 1, 0, 3)


def ancestors(j: int) -> set[int]:
    found = set()
    while PARENTS[j] is not None:
        j = PARENTS[j]
        found.add(j)
    return found


def related(i: int, j: int) -> bool:
    return i == j or i in ancestors(j) or j in ancestors(i)


def test_a_branched_trees_factors_have_no_fill_in_and_invert_it():
    n = len(PARENTS)
    M = sp.Matrix(n, n, lambda i, j: sp.Symbol(f"m{min(i, j)}{max(i, j)}") if related(i, j)
                  else 0)
    b = ProgramBuilder()
    Minv = symmetric_inverse(b, M, "Mi")

    factors = [re.fullmatch(r"Mi_L(\d+)_(\d+)", s.name) for s, _ in b.assignments]
    pairs = {(int(f[1]) - 1, int(f[2]) - 1) for f in factors if f}
    expected = {(a, j) for j in range(n) for a in ancestors(j)}
    assert pairs == expected  # root first would also couple the two branches' joints

    # M = Lᵀ D L with L unit, nonzero only below the ancestors: positive definite, tree zeros
    rng = np.random.default_rng(3)
    L = np.eye(n)
    for a, j in expected:
        L[j, a] = rng.uniform(-1, 1)
    numeric = L.T @ np.diag(rng.uniform(0.5, 2.0, n)) @ L
    assert all(numeric[i, j] == 0 for i in range(n) for j in range(n) if not related(i, j))
    values = {M[i, j]: numeric[i, j] for i in range(n) for j in range(i, n) if related(i, j)}
    for symbol, expr in b.assignments:
        values[symbol] = float(expr.subs(values))
    result = np.array(Minv.subs(values), dtype=float)
    np.testing.assert_allclose(result, np.linalg.inv(numeric), rtol=1e-12, atol=1e-12)
