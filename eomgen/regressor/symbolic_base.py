"""Base parameters by the closed-form grouping rules (:mod:`eomgen.symbolic.grouping`), exact in
the geometry symbols, checked numerically over random states (:func:`symbolic_base_parameters`,
:class:`SymbolicBase`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping, Sequence

import numpy as np
import sympy as sp

from ..errors import UnsupportedError
from ..symbolic.grouping import group_parameters
from .derive import Regressor, by_symbol
from .notation import by_coefficient, parameter_latex
from .numeric_base import RANK_TOLERANCE, ZERO_COLUMN, independent_columns, sample_regressor


@dataclass(frozen=True)
class SymbolicBase:
    """Base parameters from the closed-form grouping rules (:mod:`eomgen.symbolic.grouping`).

    Attributes
    ----------
    names:
        Name of each base parameter: the column's name, with ``R`` appended when other
        parameters were grouped into it (``XX2R``).
    base:
        Their column indices in Y (``Y_base = Y[:, base]``), increasing.
    expressions:
        β as SymPy expressions of the standard parameter symbols (:attr:`Regressor.
        parameter_symbols`) and of the model's geometry symbols (kept symbolic).
    unidentifiable:
        Columns the rules kept that are zero at every sampled state (gravity along the first
        axis, bodies that cannot rotate about some axis, …): their parameters have no effect.
    residual:
        Columns the rules kept that were still found dependent numerically (special cases the
        rules do not cover); they are regrouped into the base ones with numeric coefficients
        (least squares at the sampled geometry values), or, when the expanded regressor was
        given, with coefficients solved exactly in the geometry symbols. Empty when the
        grouping alone is complete, and then β is exact in the geometry symbols.
    numeric:
        The residual columns regrouped with numeric coefficients (none solved exactly):
        β is exact in the geometry symbols when this is empty.
    """

    names: tuple[str, ...]
    base: tuple[int, ...]
    expressions: tuple[sp.Expr, ...]
    unidentifiable: tuple[int, ...]
    residual: tuple[int, ...]
    parameter_symbols: tuple[sp.Symbol, ...]
    geometry: tuple[tuple[sp.Symbol, float], ...] = ()
    numeric: tuple[int, ...] = ()

    @property
    def count(self) -> int:
        return len(self.base)

    def beta(self, pi, values: Mapping | None = None) -> np.ndarray:
        """β(π) as floats; geometry symbols at the model's defaults (``values`` overriding)."""
        subs = {**dict(self.geometry), **by_symbol(values)}
        subs.update(zip(self.parameter_symbols, (float(x) for x in pi)))
        return np.array([float(e.xreplace(subs)) for e in self.expressions], dtype=float)

    def latex(self, digits: int = 6) -> str:
        """``\\begin{aligned} name &= expression \\\\ … \\end{aligned}``, numbers rounded to
        ``digits`` significant digits."""
        lines = []
        for name, expr in zip(self.names, self.expressions):
            expr = sp.expand(expr)
            expr = by_coefficient(expr.xreplace({f: sp.Float(f, digits)
                                                  for f in expr.atoms(sp.Float)}),
                                   self.parameter_symbols)
            tex = sp.latex(expr, symbol_names={s: parameter_latex(s.name)
                                               for s in expr.free_symbols
                                               if s in self.parameter_symbols})
            lines.append(f"{parameter_latex(name)} &= {tex}")
        return "\\begin{aligned}\n" + " \\\\\n".join(lines) + "\n\\end{aligned}"


def exact_regrouping(Y: sp.Matrix, dependent: int, support: Sequence[int], state: Sequence,
                     estimate: Sequence[float], at: Mapping) -> list[sp.Expr] | None:
    """The coefficients ``c`` with ``Y[:, dependent] = Σ c_k Y[:, support[k]]`` identically in
    the ``state`` symbols (joint positions, velocities, accelerations), solved exactly: each
    ``c_k`` an expression of the geometry symbols (``2 a_2``), where least squares gives a
    float that is its roundoff (0.49999999999999994). ``Y`` must be in a form where distinct
    functions of the state are distinct terms (sines and cosines in
    :func:`~eomgen.symbolic.trigonometry.fourier_form`). None when there is no unique exact
    solution or it differs from the numeric ``estimate`` at the geometry values ``at``.

    >>> a, q, x, y = sp.symbols("a q x y")
    >>> Y = sp.Matrix([[2*a*sp.cos(q) + x, sp.cos(q), x], [y, 0, y]])
    >>> exact_regrouping(Y, 0, [1, 2], [q, x, y], [0.49999999999999994, 1.0], {a: 0.25})
    [2*a, 1]
    """
    unknowns = sp.symbols(f"eomgen_c0:{len(support)}")
    state = set(state)
    equations = []
    for i in range(Y.rows):
        residue = sp.expand(Y[i, dependent] - sum((c * Y[i, k] for c, k in zip(unknowns, support)),
                                                  sp.Integer(0)))
        by_state: dict = {}
        for term in sp.Add.make_args(residue):
            factors = sp.Mul.make_args(term)
            key = sp.Mul(*[f for f in factors if f.free_symbols & state])
            by_state[key] = by_state.get(key, sp.Integer(0)) + term / key
        equations += [e for e in by_state.values() if e != 0]
    solutions = sp.linsolve(equations, unknowns) if equations else sp.EmptySet
    if not isinstance(solutions, sp.FiniteSet) or len(solutions) != 1:
        return None
    coefficients = [sp.factor_terms(c) for c in next(iter(solutions))]
    if any(c.free_symbols & set(unknowns) for c in coefficients):
        return None  # not unique
    for c, value in zip(coefficients, estimate):
        try:
            exact = float(c.xreplace(at))
        except TypeError:  # a symbol without a value
            return None
        if abs(exact - value) > 1e-6 * max(1.0, abs(value)):
            return None
    return coefficients


def symbolic_base_parameters(reg: Regressor, samples: int | None = None, seed: int = 0,
                             values: Mapping | None = None, tolerance: float = RANK_TOLERANCE,
                             Y: sp.Matrix | None = None) -> SymbolicBase:
    """Base parameters by the closed-form grouping rules, then checked over random states.

    The grouping (:func:`eomgen.symbolic.grouping.group_parameters`) gives β as expressions of
    π and of the geometry symbols. Numerically, at the geometry's default values (``values``
    overriding): the identity ``Y π = Y[:, kept] β(π)`` is checked for a random π (a wrong rule
    raises), kept columns that are zero are reported as unidentifiable, and kept columns still
    dependent on earlier ones (special cases the rules do not cover) are reported as
    ``residual`` and regrouped into the others with numeric coefficients. Actuator columns are kept when not zero or dependent.
    Given ``Y``, the expanded regressor (n × p) in the form of
    :func:`~eomgen.symbolic.trigonometry.fourier_form` (what :func:`~eomgen.regressor.
    regressor_form` prints), the residual coefficients are solved exactly in the geometry
    symbols instead (:func:`exact_regrouping`; numeric where that finds no exact solution).

    Raises
    ------
    UnsupportedError
        For a revolute axis not along ±x, ±y, ±z of its joint frame (use
        :func:`base_parameters`).
    RuntimeError
        When the grouped regressor does not reproduce Y π (a defect).
    """
    if reg.p == 0:  # nothing moves
        return SymbolicBase((), (), (), (), (), ())
    try:
        grouping = group_parameters(reg.tree, reg.parameter_symbols)
    except ValueError as exc:
        raise UnsupportedError(reg.model.source, "symbolic base parameters", str(exc)) from None
    kept = list(grouping.kept) + list(range(10 * reg.n, reg.p))
    expressions = list(grouping.expressions) + [reg.parameter_symbols[k]
                                                for k in range(10 * reg.n, reg.p)]
    geometry = reg.parameter_values(values)
    W = sample_regressor(reg, samples, seed, values)
    rng = np.random.default_rng(seed + 1)
    pi = rng.uniform(0.5, 1.5, reg.p)
    subs = {**{k: sp.Float(v) for k, v in geometry.items()}, **dict(zip(reg.parameter_symbols, pi))}
    beta = np.array([float(e.xreplace(subs)) for e in expressions])
    Wk = W[:, kept]
    error = np.abs(Wk @ beta - W @ pi).max()
    if error > 1e-9 * max(1.0, np.abs(W @ pi).max()):
        raise RuntimeError(f"grouped regressor misses Y π by {error:.3g} (a grouping defect)")
    norms = np.linalg.norm(Wk, axis=0)
    nonzero = norms > ZERO_COLUMN * np.linalg.norm(W, axis=0).max()
    Wn = np.where(nonzero, Wk / np.where(nonzero, norms, 1.0), 0.0)
    independent, _ = independent_columns(Wn, nonzero, tolerance)
    unidentifiable = tuple(kept[c] for c in range(len(kept)) if not nonzero[c])
    residual = tuple(kept[c] for c in range(len(kept)) if nonzero[c] and c not in independent)
    # residual dependencies: regrouped with numeric coefficients (at the sampled geometry)
    dependent = [c for c in range(len(kept)) if nonzero[c] and c not in independent]
    regroup = np.zeros((len(independent), 0))
    if dependent:
        regroup, *_ = np.linalg.lstsq(Wk[:, independent], Wk[:, dependent], rcond=None)
        regroup[np.abs(regroup) < 1e-10 * max(1.0, np.abs(regroup).max())] = 0.0
    coefficient = {(r, e): sp.Float(regroup[r, e]) for r in range(len(independent))
                   for e in range(len(dependent)) if regroup[r, e] != 0}
    numeric = []
    for e, d in enumerate(dependent):
        support = [r for r in range(len(independent)) if (r, e) in coefficient]
        exact = None if Y is None else exact_regrouping(
            Y, kept[d], [kept[independent[r]] for r in support], reg.q + reg.qd + reg.qdd,
            [regroup[r, e] for r in support], subs)
        if exact is None:
            numeric.append(kept[d])
            continue
        for r, value in zip(support, exact):
            coefficient[r, e] = value
    names, cols, exprs = [], [], []
    for r, c in enumerate(independent):
        k, expr = kept[c], expressions[c]
        expr = expr + sp.Add(*[coefficient[r, e] * expressions[d]
                               for e, d in enumerate(dependent) if (r, e) in coefficient])
        cols.append(k)
        exprs.append(by_coefficient(expr, reg.parameter_symbols))
        names.append(reg.PARAMETER_NAMES[k] + ("R" if expr != reg.parameter_symbols[k] else ""))
    return SymbolicBase(tuple(names), tuple(cols), tuple(exprs), unidentifiable, residual,
                        reg.parameter_symbols, tuple((k, float(v)) for k, v in geometry.items()),
                        tuple(numeric))
