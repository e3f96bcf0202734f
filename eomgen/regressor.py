"""Linear parameterization τ = Y(q, q̇, q̈) π: the regressor, its parameters and base parameters.

:func:`derive_regressor` builds Y as a straight-line program (see
:mod:`eomgen.symbolic.regressor` for the derivation, frames and parameter order);
:func:`base_parameters` finds the identifiable combinations numerically (QR over random
states), :func:`symbolic_base_parameters` by the closed-form grouping rules
(:mod:`eomgen.symbolic.grouping`), checked numerically; :func:`identify` estimates them from
measured efforts by least squares. See docs/regressor.md.

Parameters π, per moving body in JOINT_NAMES order (body k is the child of joint k, fixed links
merged, frame = joint k's frame after it has moved), Pinocchio's order::

    M, MX, MY, MZ, XX, XY, YY, XZ, YZ, ZZ       (m, m c, inertia about the body origin)

then, if asked, one group of n actuator columns per term: ``IA`` (armature, τ_k += I_a q̈_k),
``FV`` (viscous, f_v q̇_k), ``FC`` (Coulomb, f_c sign q̇_k), ``FO`` (offset, f_o).

>>> import eomgen
>>> from eomgen.regressor import derive_regressor
>>> reg = derive_regressor(eomgen.load(eomgen.example_path("planar_2link")))
>>> reg.PARAMETER_NAMES[:4]
('M1', 'MX1', 'MY1', 'MZ1')
"""

from __future__ import annotations

import functools
import time
from dataclasses import dataclass
from functools import cached_property
from typing import Iterable, Mapping, Sequence

import numpy as np
import sympy as sp

from .bodies import BodyTree
from .errors import ParameterError, UnsupportedError
from .model import RobotModel, parameter_symbol
from .symbolic.evaluate import compile_program
from .symbolic.derivation import new_derivation
from .symbolic.program import Program
from .symbolic.regressor import (ACTUATOR_NAMES, ACTUATOR_TERMS, INERTIAL_NAMES,
                                 regressor_program)


@dataclass(frozen=True)
class Regressor:
    """The regressor of one model. Immutable.

    Attributes
    ----------
    model:
        The model it was derived from.
    tree:
        Its moving bodies (one 10-column block per body, in JOINT_NAMES order).
    q, qd, qdd:
        Joint symbols in JOINT_NAMES order.
    program:
        Straight-line program with outputs ``"Y"`` (n × p), ``"K"`` and ``"P"`` (1 × p):
        ``τ = Y π``, kinetic energy ``K = Y_K π``, potential energy ``P = Y_P π``.
    actuators:
        The actuator terms with columns (subset of ``ACTUATOR_TERMS``, in column order).
    seconds:
        Time spent building the program.
    """

    model: RobotModel
    tree: BodyTree
    q: tuple
    qd: tuple
    qdd: tuple
    program: Program
    actuators: tuple[str, ...] = ()
    seconds: float = 0.0

    @property
    def n(self) -> int:
        return len(self.q)

    @cached_property
    def PARAMETER_NAMES(self) -> tuple[str, ...]:
        """Name of each column of Y: ``M1, MX1, …, ZZ1, M2, …`` then ``IA1…``, ``FV1…`` etc."""
        names = [f"{name}{k + 1}" for k in range(self.n) for name in INERTIAL_NAMES]
        for term in self.actuators:
            names += [f"{ACTUATOR_NAMES[term]}{k + 1}" for k in range(self.n)]
        return tuple(names)

    @property
    def p(self) -> int:
        """Number of standard parameters (columns of Y)."""
        return len(self.PARAMETER_NAMES)

    @cached_property
    def parameter_symbols(self) -> tuple[sp.Symbol, ...]:
        """π as symbols named after :attr:`PARAMETER_NAMES` (for β(π) expressions)."""
        return tuple(parameter_symbol(name) for name in self.PARAMETER_NAMES)

    def inertial_parameters(self, values: Mapping | None = None, actuator: Mapping | None = None
                            ) -> sp.Matrix:
        """π of the description, p × 1: each body's (m, h, I about its origin), symbolic in the
        model's parameters unless ``values`` (symbol or name → number) are given.

        Actuator entries are not in descriptions: 0 unless ``actuator`` maps their names
        (``"FV2"``) to values.
        """
        pi = []
        bodies = sorted(self.tree.bodies, key=lambda body: body.q_index)
        for body in bodies:
            par = body.inertial
            I = par.inertia
            pi += [par.mass, *par.first_moment, I[0][0], I[0][1], I[1][1], I[0][2], I[1][2],
                   I[2][2]]
        pi += [sp.sympify((actuator or {}).get(name, 0)) for name in self.PARAMETER_NAMES[10 * self.n:]]
        out = sp.Matrix(pi)
        if values is not None:
            subs = {(parameter_symbol(k) if isinstance(k, str) else k): v for k, v in values.items()}
            out = out.xreplace({k: sp.sympify(v) for k, v in subs.items()})
        return out

    def numeric_parameters(self, values: Mapping | None = None) -> np.ndarray:
        """π as floats at the model's default parameter values (``values`` overriding)."""
        merged = dict(self.model.parameter_values)
        merged.update({(parameter_symbol(k) if isinstance(k, str) else k): v
                       for k, v in (values or {}).items()})
        return np.array([float(x) for x in self.inertial_parameters(merged)], dtype=float)

    @cached_property
    def Y(self) -> sp.Matrix:
        """Y(q, q̇, q̈), n × p, expanded to full expressions (small models only)."""
        return self.program.expand(self.program.output("Y"))

    @cached_property
    def Y_K(self) -> sp.Matrix:
        """Kinetic energy row, 1 × p: ``K = Y_K(q, q̇) π`` [J]."""
        return self.program.expand(self.program.output("K"))

    @cached_property
    def Y_P(self) -> sp.Matrix:
        """Potential energy row, 1 × p: ``P = Y_P(q) π`` [J], P = −Σ m g_vec · c."""
        return self.program.expand(self.program.output("P"))

    def base_program(self, columns: Sequence[int]) -> Program:
        """The program computing only ``Y_base = Y[:, columns]`` (n × b), output ``"Y_base"``;
        unused intermediates pruned (what generated ``base_regressor(q, qd, qdd)`` prints)."""
        Y = self.program.output("Y")
        out = Y.extract(list(range(Y.rows)), list(columns))
        return Program(self.program.assignments, (("Y_base", out),)).pruned(["Y_base"])

    def operation_count(self, columns: Sequence[int] | None = None) -> int:
        """Operations (SymPy ``count_ops``) of the program computing Y, or only the given
        columns of Y (the base regressor)."""
        if columns is None:
            return self.program.operation_count(["Y"])
        return self.base_program(columns).operation_count()

    def compiled(self, values: Mapping | None = None, program: Program | None = None):
        """A numeric function ``f(q, qd, qdd) -> {"Y": (n, p), "K": (1, p), "P": (1, p)}``
        (or the outputs of ``program``, e.g. :meth:`base_program`).

        Geometry parameters take their default values (``values`` overriding, symbol or name).
        """
        program = self.program if program is None else program
        merged = dict(self.model.parameter_values)
        merged.update({(parameter_symbol(k) if isinstance(k, str) else k): v
                       for k, v in (values or {}).items()})
        signs = tuple(sp.Symbol(f"sign_{s.name}", real=True) for s in self.qd)
        swap = {sp.sign(s): t for s, t in zip(self.qd, signs)}
        subs = {k: sp.Float(v) for k, v in merged.items()}
        free = {s for s in self.model.free_symbols if s not in subs}
        used = set().union(*(e.free_symbols for _, e in program.assignments),
                           *(m.free_symbols for _, m in program.outputs))
        if free & used:
            raise ParameterError(self.model.source, "parameters", "no numeric value for "
                                 + ", ".join(sorted(s.name for s in free & used)))
        assignments = tuple((s, e.xreplace(subs)) for s, e in program.assignments)
        outputs = tuple((name, m.xreplace(swap).xreplace(subs)) for name, m in program.outputs)
        raw = compile_program(Program(assignments, outputs), self.q + self.qd + self.qdd + signs)

        def evaluate(q, qd, qdd) -> dict:
            q, qd, qdd = (np.asarray(x, dtype=float) for x in (q, qd, qdd))
            return raw(*q, *qd, *qdd, *np.sign(qd))

        return evaluate


def derive_regressor(model: RobotModel, actuators: Iterable[str] = ()) -> Regressor:
    """Derive the joint torque regressor of ``model`` (see the module docstring).

    Parameters
    ----------
    model:
        A robot model; geometry may stay symbolic (DH lengths as parameters).
    actuators:
        Actuator terms to add columns for, from ``("armature", "viscous", "coulomb",
        "offset")``; their groups follow the inertial columns in the order given.

    Raises
    ------
    ValueError
        For an unknown or repeated actuator term.
    """
    actuators = tuple(actuators)
    bad = [t for t in actuators if t not in ACTUATOR_TERMS]
    if bad or len(set(actuators)) != len(actuators):
        raise ValueError(f"actuator terms must be distinct ones of {ACTUATOR_TERMS}, got {actuators}")
    start = time.perf_counter()
    d = new_derivation(model, ("q", "qd", "qdd"))
    out = regressor_program(d.tree, d.q, d.qd, d.qdd, model.gravity, d.builder, actuators)
    program = d.program((k, out[k]) for k in ("Y", "K", "P"))
    return Regressor(model, d.tree, d.q, d.qd, d.qdd, program, actuators,
                     time.perf_counter() - start)


# ----------------------------------------------------------------------------------------------
# Base parameters, numerically
# ----------------------------------------------------------------------------------------------

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
            out.append((name, _by_coefficient(expr, syms)))
        return out

    def latex(self, digits: int = 6) -> str:
        """The base parameters as a LaTeX ``aligned`` block, one ``name = expression`` a line."""
        lines = []
        for name, expr in self.expressions(digits):
            lines.append(f"{_latex_name(name)} &= {sp.latex(expr, symbol_names=_tex_symbols(expr))}")
        return "\\begin{aligned}\n" + " \\\\\n".join(lines) + "\n\\end{aligned}"


def parameter_latex(name: str) -> str:
    """LaTeX of a standard or base parameter name: ``MX2`` → ``\\mathrm{MX}_{2}``,
    ``ZZ1R`` → ``\\mathrm{ZZ}_{1}^{R}``."""
    return _latex_name(name)


def _latex_name(name: str) -> str:
    head = name.rstrip("0123456789R")
    rest = name[len(head):]
    index = rest.rstrip("R")
    return f"\\mathrm{{{head}}}_{{{index}}}" + ("^{R}" if rest.endswith("R") else "")


def _tex_symbols(expr: sp.Expr) -> dict:
    return {s: _latex_name(s.name) for s in expr.free_symbols}


def sample_regressor(reg: Regressor, samples: int | None = None, seed: int = 0,
                     values: Mapping | None = None) -> np.ndarray:
    """Y stacked over random states, (samples · n, p): q uniform in [−π, π], q̇ and q̈
    standard normal (prismatic joints too)."""
    f = reg.compiled(values)
    n, p = reg.n, reg.p
    samples = samples or max(20, 3 * p // max(n, 1) + 10)
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(samples):
        q = rng.uniform(-np.pi, np.pi, n)
        rows.append(f(q, rng.standard_normal(n), rng.standard_normal(n))["Y"])
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
    import scipy.linalg

    if reg.p == 0:  # nothing moves
        return BaseParameters((), (), (), np.zeros((0, 0)), 0, (np.inf, 0.0))
    W = sample_regressor(reg, samples, seed, values)
    norms = np.linalg.norm(W, axis=0)
    nonzero = norms > ZERO_COLUMN * norms.max()
    Wn = np.where(nonzero, W / np.where(nonzero, norms, 1.0), 0.0)
    R = scipy.linalg.qr(Wn, mode="r", pivoting=True)[0]
    d = np.abs(np.diag(R))
    rank = int(np.sum(d > tolerance * d[0])) if d.size and d[0] > 0 else 0

    kept, gap = _independent_columns(Wn, nonzero, tolerance)
    if len(kept) != rank:
        raise RuntimeError(f"rank by pivoted QR is {rank} but {len(kept)} columns were kept: "
                           f"no clear gap at tolerance {tolerance}")
    dependent = [k for k in range(W.shape[1]) if k not in kept]
    K, *_ = np.linalg.lstsq(W[:, kept], W[:, dependent], rcond=None)
    if K.size:
        K[np.abs(K) < 1e-10 * max(1.0, np.abs(K).max())] = 0.0
    return BaseParameters(reg.PARAMETER_NAMES, tuple(kept), tuple(dependent), K, rank, gap)


def _independent_columns(Wn: np.ndarray, candidates, tolerance: float):
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


# ----------------------------------------------------------------------------------------------
# Base parameters, symbolically (closed-form grouping), checked numerically
# ----------------------------------------------------------------------------------------------


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
        subs = dict(self.geometry)
        subs.update({(parameter_symbol(k) if isinstance(k, str) else k): v
                     for k, v in (values or {}).items()})
        subs.update(zip(self.parameter_symbols, (float(x) for x in pi)))
        return np.array([float(e.xreplace(subs)) for e in self.expressions], dtype=float)

    def latex(self, digits: int = 6) -> str:
        """``\\begin{aligned} name &= expression \\\\ … \\end{aligned}``, numbers rounded to
        ``digits`` significant digits."""
        lines = []
        for name, expr in zip(self.names, self.expressions):
            expr = sp.expand(expr)
            expr = _by_coefficient(expr.xreplace({f: sp.Float(f, digits)
                                                  for f in expr.atoms(sp.Float)}),
                                   self.parameter_symbols)
            tex = sp.latex(expr, symbol_names={s: _latex_name(s.name)
                                               for s in expr.free_symbols
                                               if s in self.parameter_symbols})
            lines.append(f"{_latex_name(name)} &= {tex}")
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
    from .symbolic.grouping import group_parameters

    if reg.p == 0:  # nothing moves
        return SymbolicBase((), (), (), (), (), ())
    try:
        grouping = group_parameters(reg.tree, reg.parameter_symbols)
    except ValueError as exc:
        raise UnsupportedError(reg.model.source, "symbolic base parameters", str(exc)) from None
    kept = list(grouping.kept) + list(range(10 * reg.n, reg.p))
    expressions = list(grouping.expressions) + [reg.parameter_symbols[k]
                                                for k in range(10 * reg.n, reg.p)]
    geometry = dict(reg.model.parameter_values)
    geometry.update({(parameter_symbol(k) if isinstance(k, str) else k): v
                     for k, v in (values or {}).items()})
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
    independent, _ = _independent_columns(Wn, nonzero, tolerance)
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
        exprs.append(_by_coefficient(expr, reg.parameter_symbols))
        names.append(reg.PARAMETER_NAMES[k] + ("R" if expr != reg.parameter_symbols[k] else ""))
    return SymbolicBase(tuple(names), tuple(cols), tuple(exprs), unidentifiable, residual,
                        reg.parameter_symbols, tuple((k, float(v)) for k, v in geometry.items()))


def _by_coefficient(expr: sp.Expr, pi: Sequence[sp.Symbol]) -> sp.Expr:
    """A linear form in ``pi`` written as Σ coefficient · (sum of the parameters sharing it):
    ``a2**2*(M3 + M4 + M5 + M6) + XX2 - YY2``."""
    terms: dict = {}
    order: list = []
    poly = sp.expand(expr)
    used = [s for s in pi if s in poly.free_symbols]
    for s in used:
        coef = poly.coeff(s)
        if coef not in terms:
            terms[coef] = []
            order.append(coef)
        terms[coef].append(s)
    constant = poly.subs({s: 0 for s in used})
    # a number times a sum is distributed by SymPy unless told not to
    return sp.Add(*[sp.Mul(c, sp.Add(*terms[c]), evaluate=False)
                    if len(terms[c]) > 1 and abs(c) != 1 else c * sp.Add(*terms[c])
                    for c in order]) + constant


# ----------------------------------------------------------------------------------------------
# Written out for teaching: Y and β as a student writes them (small models)
# ----------------------------------------------------------------------------------------------

#: What each of a body's ten inertial parameters is, by name prefix (for documents).
PARAMETER_MEANINGS = {
    "M": "mass m_k [kg]",
    "MX": "first moment m_k c_k, x [kg m]", "MY": "first moment m_k c_k, y [kg m]",
    "MZ": "first moment m_k c_k, z [kg m]",
    "XX": "inertia about the body origin, xx [kg m²]", "XY": "inertia, xy [kg m²]",
    "YY": "inertia, yy [kg m²]", "XZ": "inertia, xz [kg m²]", "YZ": "inertia, yz [kg m²]",
    "ZZ": "inertia, zz [kg m²]",
}


@dataclass(frozen=True)
class RegressorForm:
    """τ = Y(q, q̇, q̈) π and τ = Y_base(q, q̇, q̈) β written out: expanded entries in compact
    trigonometric form and the base parameters β as expressions of π (and of the geometry
    symbols), for teaching-sized models (:func:`regressor_form`).

    Attributes
    ----------
    regressor:
        The :class:`Regressor` it was written from.
    columns:
        Indices of the columns of Y that are not identically zero, increasing.
    Y:
        Those columns, n × len(columns), each entry as :func:`eomgen.symbolic.textbook.
        simplify_trig` writes it (``l1*cos(q2)``, ``g*cos(q1 + q2)``) except that a sum is not
        written as −(…).
    zero:
        Indices of the columns of Y that are identically zero: parameters with no effect.
    base:
        Indices of the base columns (``Y_base = Y[:, base]``), increasing.
    base_names:
        Names of the base parameters (``MX1R`` where others are grouped into ``MX1``).
    beta:
        β as expressions of :attr:`Regressor.parameter_symbols` and the geometry symbols.
    exact:
        True when β comes from the closed-form grouping alone (exact in the geometry
        symbols); False when some coefficients are numbers at the description's values (the
        numeric route, or residual dependencies, see :class:`SymbolicBase`).
    """

    regressor: Regressor
    columns: tuple[int, ...]
    Y: sp.Matrix
    zero: tuple[int, ...]
    base: tuple[int, ...]
    base_names: tuple[str, ...]
    beta: tuple[sp.Expr, ...]
    exact: bool

    @property
    def names(self) -> tuple[str, ...]:
        """Names of the non-zero columns (PARAMETER_NAMES of :attr:`columns`)."""
        return tuple(self.regressor.PARAMETER_NAMES[k] for k in self.columns)

    @property
    def pi(self) -> sp.Matrix:
        """The parameters of the non-zero columns, a column of symbols: ``τ = Y π``."""
        return sp.Matrix([self.regressor.parameter_symbols[k] for k in self.columns])

    @property
    def latex_names(self) -> dict:
        """LaTeX of every standard parameter symbol (``MX2`` → ``\\mathrm{MX}_{2}``), for
        printers' ``symbol_names``."""
        return {s: _latex_name(s.name) for s in self.regressor.parameter_symbols}

    @property
    def Y_base(self) -> sp.Matrix:
        """The base columns of :attr:`Y`, n × b: ``τ = Y_base β``."""
        return self.Y.extract(list(range(self.Y.rows)),
                              [self.columns.index(k) for k in self.base])


def _integers(expr: sp.Expr) -> sp.Expr:
    """Floats within 1e-12 of an integer (numeric regrouping coefficients, 1.0000000000000002)
    as that integer."""
    return expr.xreplace({f: sp.Integer(round(f)) for f in expr.atoms(sp.Float)
                          if abs(float(f) - round(f)) <= 1e-12 * max(1.0, abs(float(f)))})


def regressor_form(model_or_regressor) -> RegressorForm:
    """Y and the base parameters of a small model written out (:class:`RegressorForm`).

    Y is expanded (:attr:`Regressor.Y`) and each entry put in the form eomgen prints for
    small models (:func:`~eomgen.symbolic.textbook.simplify_trig`); β comes from the closed-form
    grouping (:func:`symbolic_base_parameters`), or, for axes it does not cover, from the
    numeric route with 15-digit coefficients. Expanding is exponential in the number of
    joints: meant for teaching-sized models (the bound of the textbook derivation,
    :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_DOF` joints and
    :data:`~eomgen.symbolic.textbook.TEXTBOOK_MAX_OPERATIONS`), which callers check.

    >>> import eomgen
    >>> form = regressor_form(eomgen.load(eomgen.example_path("planar_2link")))
    >>> form.names
    ('MX1', 'MY1', 'ZZ1', 'M2', 'MX2', 'MY2', 'ZZ2')
    >>> list(zip(form.base_names, form.beta))[:3]
    [('MX1R', M2*l1 + MX1), ('MY1', MY1), ('ZZ1R', M2*l1**2 + ZZ1)]
    """
    from .symbolic.textbook import drop_float_noise, fourier_form

    reg = (model_or_regressor if isinstance(model_or_regressor, Regressor)
           else derive_regressor(model_or_regressor))
    # simplify_trig's form, but a sum keeps its signs (no −(…) pulled out)
    Y = reg.Y.applyfunc(lambda e: sp.factor_terms(drop_float_noise(fourier_form(e, reg.q)),
                                                  sign=False))
    columns = tuple(k for k in range(reg.p) if any(Y[i, k] != 0 for i in range(reg.n)))
    zero = tuple(k for k in range(reg.p) if k not in columns)
    try:
        sym = symbolic_base_parameters(reg)
        base, names, exact = sym.base, sym.names, not sym.residual
        beta = sym.expressions
    except UnsupportedError:  # an axis the grouping rules do not cover
        num = base_parameters(reg)
        base, exact = num.base, False
        names, beta = zip(*num.expressions(digits=15)) if num.base else ((), ())
    beta = tuple(_by_coefficient(_integers(drop_float_noise(sp.expand(b))),
                                 reg.parameter_symbols) for b in beta)
    return RegressorForm(reg, columns, Y.extract(list(range(reg.n)), list(columns)), zero,
                         tuple(base), tuple(names), beta, exact)


# ----------------------------------------------------------------------------------------------
# Identification: least squares of β from measured joint efforts
# ----------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Identification:
    """Least-squares estimate of the base parameters from measurements.

    Attributes
    ----------
    beta:
        Estimated β, (b,), in the order of the base used.
    std:
        Standard deviations of β from the residual (σ² (WᵀW)⁻¹, σ² = |τ − W β|² / (rows − b)).
    rms:
        Root mean square of the residual τ − W β [N m or N].
    condition:
        Condition number of the column-normalised observation matrix W (a measure of how well
        the trajectory excites the base parameters).
    """

    beta: np.ndarray
    std: np.ndarray
    rms: float
    condition: float


def identify(reg: Regressor, base, q, qd, qdd, tau, values: Mapping | None = None
             ) -> Identification:
    """Estimate β by ordinary least squares, ``min |W β − τ|`` with W the base regressor
    stacked over the samples (:func:`eomgen.identification.observation_matrix`). Gautier's
    weighted least squares, CSV data and the physically consistent fit are in
    :mod:`eomgen.identification`.

    Parameters
    ----------
    reg:
        The regressor.
    base:
        A :class:`BaseParameters` or :class:`SymbolicBase` (its ``base`` columns are used).
    q, qd, qdd, tau:
        (N, n) arrays of joint positions, velocities, accelerations and measured efforts, in
        JOINT_NAMES order (SI units).
    values:
        Geometry parameter values overriding the model's defaults.

    Raises
    ------
    ValueError
        When the arrays are not (N, n) or there are fewer rows N n than base parameters.
    """
    arrays = [np.atleast_2d(np.asarray(x, dtype=float)) for x in (q, qd, qdd, tau)]
    if any(a.shape != arrays[0].shape or a.shape[1] != reg.n for a in arrays):
        raise ValueError(f"q, qd, qdd and tau must all have shape (N, {reg.n})")
    columns = list(base.base)
    if arrays[0].size < len(columns):
        raise ValueError(f"{arrays[0].size} equations for {len(columns)} base parameters")
    from .identification.estimation import normalised_condition, observation_matrix

    W = observation_matrix(reg, columns, *arrays[:3], values=values)
    y = arrays[3].reshape(-1)
    beta, *_ = np.linalg.lstsq(W, y, rcond=None)
    residual = y - W @ beta
    dof = max(W.shape[0] - W.shape[1], 1)
    sigma2 = float(residual @ residual) / dof
    cov = sigma2 * np.linalg.pinv(W.T @ W)
    return Identification(beta, np.sqrt(np.clip(np.diag(cov), 0, None)),
                          float(np.sqrt(np.mean(residual ** 2))), normalised_condition(W))


# ----------------------------------------------------------------------------------------------
# Generated functions (eomgen.outputs): regressor, inertial_parameters, base_regressor, ...
# ----------------------------------------------------------------------------------------------

#: Actuator terms a generated regressor gets columns for when a joint's actuator declares them,
#: with the :class:`~eomgen.model.Actuator` field holding each one's value. Descriptions and
#: scenes have no offset, so generated regressors have no ``FO`` columns.
DECLARED_TERMS = {"armature": "armature", "viscous": "damping", "coulomb": "friction"}


def declared_actuator_terms(model: RobotModel) -> tuple[str, ...]:
    """The actuator terms (:data:`DECLARED_TERMS` order) for which some movable joint of
    ``model`` has an actuator with a value that is not identically zero: the actuator column
    groups of the generated regressor.

    Raises
    ------
    UnsupportedError
        For a flexible joint (an actuator with a stiffness): its motor has an equation of its
        own, which τ = Y π does not describe.
    """
    actuators = [(j.name, j.actuator) for j in model.movable_joints if j.actuator is not None]
    for name, a in actuators:
        if a.flexible:
            raise UnsupportedError(model.source, f"joint '{name}' actuator",
                                   "a flexible joint has no rigid-body regressor (remove its "
                                   "stiffness to identify it as a rigid joint)")
    return tuple(term for term, field in DECLARED_TERMS.items()
                 if any(getattr(a, field) != 0 for _, a in actuators))


def description_parameters(reg: Regressor) -> sp.Matrix:
    """π of the description (p × 1): :meth:`Regressor.inertial_parameters` with the actuator
    columns taken from the joints' actuators (armature, damping, friction; 0 for a joint
    without one), in the model's parameters."""
    values = {}
    for term in reg.actuators:
        for k, joint in enumerate(reg.model.movable_joints):
            actuator = joint.actuator
            values[f"{ACTUATOR_NAMES[term]}{k + 1}"] = (
                0 if actuator is None else getattr(actuator, DECLARED_TERMS[term]))
    return reg.inertial_parameters(actuator=values)


@dataclass(frozen=True)
class GeneratedBase:
    """The base parameters a generated module exports.

    Attributes
    ----------
    names:
        ``BASE_PARAMETER_NAMES``: each base column's name, ``R`` appended when others were
        grouped into it.
    columns:
        Their columns of Y, increasing (``Y_base = Y[:, columns]``).
    beta:
        β as expressions of the model's parameters (the description's π substituted into the
        grouping's β(π)).
    route:
        ``"symbolic"`` (closed-form grouping, checked numerically) or ``"numeric"`` (QR over
        random states, for revolute axes the grouping rules do not cover).
    """

    names: tuple[str, ...]
    columns: tuple[int, ...]
    beta: tuple[sp.Expr, ...]
    route: str


@functools.lru_cache(maxsize=8)
def generated_base(model: RobotModel) -> GeneratedBase:
    """The base parameters of ``model`` as generated modules export them (cached per model:
    the output builder and the module constants ask for the same).

    The closed-form grouping (:func:`symbolic_base_parameters`, exact in geometry symbols when
    it leaves no residual column) is used where its rules apply; otherwise the numeric route
    (:func:`base_parameters`, needs SciPy). Both sample the regressor at the parameters' values.

    Raises
    ------
    ParameterError
        When a parameter the regressor uses has no value (the base is found numerically).
    UnsupportedError
        For a tilted revolute axis without SciPy installed.
    """
    reg = derive_regressor(model, declared_actuator_terms(model))
    pi = description_parameters(reg)
    subs = dict(zip(reg.parameter_symbols, pi))
    try:
        base = symbolic_base_parameters(reg)
        names, columns, route = base.names, base.base, "symbolic"
        exprs = base.expressions
    except UnsupportedError:
        try:
            numeric = base_parameters(reg)
        except ImportError:
            raise UnsupportedError(model.source, "base parameters", "a revolute axis not along "
                                   "x, y or z of its joint frame needs SciPy for the numeric "
                                   "route (pip install scipy)") from None
        named = numeric.expressions(digits=17)
        names, columns, route = tuple(n for n, _ in named), numeric.base, "numeric"
        exprs = tuple(e for _, e in named)
    beta = tuple(sp.expand(e.xreplace(subs)) for e in exprs)
    return GeneratedBase(tuple(names), tuple(columns), beta, route)


def build_outputs(derivation, wanted) -> dict:
    """The builder of the regressor outputs (:mod:`eomgen.outputs`): ``Y`` (n × p),
    ``Y_K`` and ``Y_P`` (p × 1, the energy regressors), ``pi`` (p × 1), ``Y_base`` (n × b) and
    ``beta`` (b × 1), those in ``wanted``.

    Y is built by :func:`eomgen.symbolic.regressor.regressor_program` into the derivation's
    program, with the actuator columns the model declares (:func:`declared_actuator_terms`);
    Y_base is its base columns (:func:`generated_base`); π and β are expressions of the model's
    parameters (functions of the parameters only in the generated modules).
    """
    model = derivation.model
    terms = declared_actuator_terms(model)
    out: dict[str, sp.Matrix] = {}
    if wanted & {"Y", "Y_K", "Y_P", "Y_base"}:
        built = regressor_program(derivation.tree, derivation.q, derivation.qd, derivation.qdd,
                                  model.gravity, derivation.builder, terms)
        Y = built["Y"]
        if "Y" in wanted:
            out["Y"] = Y
        if "Y_K" in wanted:
            out["Y_K"] = built["K"].T
        if "Y_P" in wanted:
            out["Y_P"] = built["P"].T
        if "Y_base" in wanted:
            out["Y_base"] = Y.extract(list(range(Y.rows)), list(generated_base(model).columns))
    if "pi" in wanted:
        tree = derivation.tree
        q, qd, qdd = derivation.q, derivation.qd, derivation.qdd
        out["pi"] = description_parameters(
            Regressor(model, tree, q, qd, qdd, Program((), ()), terms))
    if "beta" in wanted:
        out["beta"] = sp.Matrix(generated_base(model).beta)
    return out


def parameter_names(dynamics) -> dict[str, tuple[str, ...]]:
    """``PARAMETER_NAMES``: the columns of the generated regressor (module constant)."""
    model = dynamics.model
    terms = declared_actuator_terms(model)
    names = [f"{name}{k + 1}" for k in range(model.dof) for name in INERTIAL_NAMES]
    for term in terms:
        names += [f"{ACTUATOR_NAMES[term]}{k + 1}" for k in range(model.dof)]
    return {"PARAMETER_NAMES": tuple(names)}


def base_parameter_names(dynamics) -> dict[str, tuple[str, ...]]:
    """``BASE_PARAMETER_NAMES`` (and ``PARAMETER_NAMES``): the columns of the generated base
    regressor (module constants)."""
    return {**parameter_names(dynamics),
            "BASE_PARAMETER_NAMES": generated_base(dynamics.model).names}
