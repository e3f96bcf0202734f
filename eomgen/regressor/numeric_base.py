"""Base parameters found numerically: Gautier's QR of the regressor sampled over random states
(:func:`base_parameters`, :class:`BaseParameters`), and the column selection that the closed-form
route checks itself with."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np
import sympy as sp

from ..model import parameter_symbol
from ..model.configuration import chart_indices
from .derive import Regressor
from .notation import by_coefficient, parameter_latex, tex_symbols


#: A column whose component orthogonal to the columns kept before it is below this fraction of
#: its own norm is dependent (and is regrouped); the same relative tolerance on |R_kk| / |R_00|
#: of the pivoted QR of the column-normalised stack gives the rank. Exact dependencies leave
#: residuals near 1e-14; independent columns of the robots tested stay above 1e-4 (see
#: :attr:`BaseParameters.gap`).
RANK_TOLERANCE = 1e-8
#: Columns whose norm over the samples is below this fraction of the largest are zero (rounding
#: leaves ~1e-16 where a structural zero was not seen symbolically).
ZERO_COLUMN = 1e-10


@dataclass(frozen=True)
class BaseParameters:
    """Identifiable combinations β = π_base + K π_dependent of the standard parameters.

    Attributes
    ----------
    names:
        Names of all standard parameters (columns of Y).
    base:
        Indices of the base columns, increasing (``Y_base = Y[:, base]``).
    dependent:
        Indices of the other columns; ``Y[:, dependent] = Y[:, base] @ K``.
    K:
        Regrouping matrix, (b, p − b); entries below 1e-10 of the largest set to 0.
    rank:
        Rank of the sample stack by pivoted QR (equals ``len(base)``).
    gap:
        (smallest relative residual kept, largest dropped): how clear the decision was.
    """

    names: tuple[str, ...]
    base: tuple[int, ...]
    dependent: tuple[int, ...]
    K: np.ndarray
    rank: int
    gap: tuple[float, float]

    @property
    def count(self) -> int:
        return len(self.base)

    def beta(self, pi) -> np.ndarray:
        """β(π): the base parameters of a standard parameter vector ``pi`` (p,)."""
        pi = np.asarray(pi, dtype=float)
        return pi[list(self.base)] + self.K @ pi[list(self.dependent)]

    def expressions(self, digits: int = 6) -> list[tuple[str, sp.Expr]]:
        """β as SymPy expressions in the standard parameter symbols (coefficients rounded to
        ``digits`` significant digits; integers exact)."""
        syms = [parameter_symbol(n) for n in self.names]
        out = []
        for r, k in enumerate(self.base):
            expr = syms[k]
            for c, d in enumerate(self.dependent):
                coef = self.K[r, c]
                if coef != 0:
                    near = round(coef)
                    value = sp.Integer(near) if abs(coef - near) < 1e-9 else sp.Float(coef, digits)
                    expr = expr + value * syms[d]
            name = self.names[k] + "R" if expr != syms[k] else self.names[k]
            out.append((name, by_coefficient(expr, syms)))
        return out

    def latex(self, digits: int = 6) -> str:
        """The base parameters as a LaTeX ``aligned`` block, one ``name = expression`` a line."""
        lines = []
        for name, expr in self.expressions(digits):
            lines.append(f"{parameter_latex(name)} &= {sp.latex(expr, symbol_names=tex_symbols(expr))}")
        return "\\begin{aligned}\n" + " \\\\\n".join(lines) + "\n\\end{aligned}"



def sample_regressor(reg: Regressor, samples: int | None = None, seed: int = 0,
                     values: Mapping | None = None) -> np.ndarray:
    """Y stacked over random states, (samples · n, p): q uniform in [−π, π], q̇ and q̈
    standard normal (prismatic joints too). A quaternion's four entries drawn so are a
    non-unit quaternion, which the program normalises: a random rotation. The columns of the
    massless links inside a quaternion joint's chain (:attr:`QuaternionJoint.virtual
    <eomgen.model.QuaternionJoint.virtual>`, parameters zero by construction) are zero, and so
    are the actuator columns of a quaternion joint's velocity coordinates (a quaternion joint
    takes no drive), so that no base parameter stands for them."""
    f = reg.compiled(values)
    n, p = reg.n, reg.p
    samples = samples or max(20, 3 * p // max(n, 1) + 10)
    rng = np.random.default_rng(seed)
    rows = []
    chain, charted = chart_indices(reg.model)
    virtual = [10 * k + c for k in chain for c in range(10)]
    virtual += [10 * n + g * n + k for g in range(len(reg.actuators)) for k in charted]
    for _ in range(samples):
        q = rng.uniform(-np.pi, np.pi, len(reg.q))
        Y = np.array(f(q, rng.standard_normal(n), rng.standard_normal(n))["Y"], dtype=float)
        Y[:, virtual] = 0.0
        rows.append(Y)
    return np.vstack(rows)


def base_parameters(reg: Regressor, samples: int | None = None, seed: int = 0,
                    values: Mapping | None = None, tolerance: float = RANK_TOLERANCE
                    ) -> BaseParameters:
    """Base parameters by QR of Y over random states (Gautier's numerical method).

    The rank comes from ``scipy.linalg.qr(W, pivoting=True)`` of the column-normalised sample
    stack W: the number of ``|R_kk| > tolerance · |R_00|``. The base columns are then chosen in
    column order (proximal bodies first, within a body Pinocchio's order): a column is kept when
    its residual after projection on the columns kept before it exceeds ``tolerance`` times its
    norm. This keeps what the classical grouping rules keep (XX_j absorbing YY_j as XXR_j, a
    body's mass and first moments pushed into its parent's parameters), and the regrouping
    matrix comes from least squares, ``W_dependent = W_base K``.

    Parameters
    ----------
    reg:
        The regressor.
    samples:
        Number of random states (default: enough for 3 p rows).
    seed:
        Random seed (the result is deterministic for a given seed).
    values:
        Geometry parameter values overriding the model's defaults.
    tolerance:
        Relative rank tolerance, see :data:`RANK_TOLERANCE`.

    Raises
    ------
    RuntimeError
        When the greedy selection and the pivoted QR disagree on the rank (no clear gap).
    """
    import scipy.linalg  # an optional dependency (eomgen[identify]), needed only here

    if reg.p == 0:  # nothing moves
        return BaseParameters((), (), (), np.zeros((0, 0)), 0, (np.inf, 0.0))
    W = sample_regressor(reg, samples, seed, values)
    norms = np.linalg.norm(W, axis=0)
    nonzero = norms > ZERO_COLUMN * norms.max()
    Wn = np.where(nonzero, W / np.where(nonzero, norms, 1.0), 0.0)
    R = scipy.linalg.qr(Wn, mode="r", pivoting=True)[0]
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > tolerance * d[0])) if d.size and d[0] > 0 else 0

    kept, gap = independent_columns(Wn, nonzero, tolerance)
    if len(kept) != rank:
        raise RuntimeError(f"rank by pivoted QR is {rank} but {len(kept)} columns were kept: "
                           f"no clear gap at tolerance {tolerance}")
    dependent = [k for k in range(W.shape[1]) if k not in kept]
    K, *_ = np.linalg.lstsq(W[:, kept], W[:, dependent], rcond=None)
    if K.size:
        K[np.abs(K) < 1e-10 * max(1.0, np.abs(K).max())] = 0.0
    return BaseParameters(reg.PARAMETER_NAMES, tuple(kept), tuple(dependent), K, rank, gap)


def independent_columns(Wn: np.ndarray, candidates, tolerance: float):
    """Greedy selection in column order among ``candidates`` (boolean mask) of the unit-norm
    columns of ``Wn``: a column is kept when its residual after projection on those kept before
    it exceeds ``tolerance``. Returns (kept indices, (smallest kept residual, largest dropped))."""
    kept: list[int] = []
    Q = np.zeros((Wn.shape[0], 0))
    kept_min, dropped_max = np.inf, 0.0
    for k in range(Wn.shape[1]):
        if not candidates[k]:
            continue
        w = Wn[:, k]
        res = w - Q @ (Q.T @ w)
        res = res - Q @ (Q.T @ res)  # twice is enough (Kahan–Parlett)
        rel = float(np.linalg.norm(res))
        if rel > tolerance:
            kept.append(k)
            Q = np.column_stack([Q, res / rel])
            kept_min = min(kept_min, rel)
        else:
            dropped_max = max(dropped_max, rel)
    return kept, (kept_min, dropped_max)
