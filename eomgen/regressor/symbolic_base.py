"""Base parameters by the closed-form grouping rules (:mod:`eomgen.symbolic.grouping`), exact in
the geometry symbols, checked numerically over random states (:func:`symbolic_base_parameters`,
:class:`SymbolicBase`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

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
        (least squares at the sampled geometry values). Empty when the grouping alone is
        complete, and then β is exact in the geometry symbols.
    """

    names: tuple[str, ...]
    base: tuple[int, ...]
    expressions: tuple[sp.Expr, ...]
    unidentifiable: tuple[int, ...]
    residual: tuple[int, ...]
    parameter_symbols: tuple[sp.Symbol, ...]
    geometry: tuple[tuple[sp.Symbol, float], ...] = ()

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


def symbolic_base_parameters(reg: Regressor, samples: int | None = None, seed: int = 0,
                             values: Mapping | None = None, tolerance: float = RANK_TOLERANCE
                             ) -> SymbolicBase:
    """Base parameters by the closed-form grouping rules, then checked over random states.

    The grouping (:func:`eomgen.symbolic.grouping.group_parameters`) gives β as expressions of
    π and of the geometry symbols. Numerically, at the geometry's default values (``values``
    overriding): the identity ``Y π = Y[:, kept] β(π)`` is checked for a random π (a wrong rule
    raises), kept columns that are zero are reported as unidentifiable, and kept columns still
    dependent on earlier ones (special cases the rules do not cover) are reported as
    ``residual`` and regrouped into the others with numeric coefficients. Actuator columns are kept when not zero or dependent.

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
    names, cols, exprs = [], [], []
    for r, c in enumerate(independent):
        k, expr = kept[c], expressions[c]
        expr = expr + sp.Add(*[sp.Float(regroup[r, e]) * expressions[d]
                               for e, d in enumerate(dependent) if regroup[r, e] != 0])
        cols.append(k)
        exprs.append(by_coefficient(expr, reg.parameter_symbols))
        names.append(reg.PARAMETER_NAMES[k] + ("R" if expr != reg.parameter_symbols[k] else ""))
    return SymbolicBase(tuple(names), tuple(cols), tuple(exprs), unidentifiable, residual,
                        reg.parameter_symbols, tuple((k, float(v)) for k, v in geometry.items()))
