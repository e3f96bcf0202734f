"""The regressor written out for teaching: Y and β as a student writes them, for small models
(:func:`regressor_form`, :class:`RegressorForm`)."""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..errors import UnsupportedError
from ..symbolic.trigonometry import drop_float_noise, fourier_form
from .derive import Regressor, derive_regressor
from .notation import by_coefficient, parameter_latex
from .numeric_base import base_parameters
from .symbolic_base import symbolic_base_parameters


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
        Those columns, n × len(columns), each entry as :func:`eomgen.symbolic.trigonometry.
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
        return {s: parameter_latex(s.name) for s in self.regressor.parameter_symbols}

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
    small models (:func:`~eomgen.symbolic.trigonometry.simplify_trig`); β comes from the closed-form
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
    reg = (model_or_regressor if isinstance(model_or_regressor, Regressor)
           else derive_regressor(model_or_regressor))
    # simplify_trig's form, but a sum keeps its signs (no −(…) pulled out)
    Y = reg.Y.applyfunc(lambda e: sp.factor_terms(drop_float_noise(fourier_form(e, reg.q)),
                                                  sign=False))
    columns = tuple(k for k in range(reg.p) if any(Y[i, k] != 0 for i in range(reg.n)))
    zero = tuple(k for k in range(reg.p) if k not in columns)
    try:
        sym = symbolic_base_parameters(reg, Y=Y)  # Y: what residual groupings solve exactly
        base, names, exact = sym.base, sym.names, not sym.numeric
        beta = sym.expressions
    except UnsupportedError:  # an axis the grouping rules do not cover
        num = base_parameters(reg)
        base, exact = num.base, False
        names, beta = zip(*num.expressions(digits=15)) if num.base else ((), ())
    beta = tuple(by_coefficient(_integers(drop_float_noise(sp.expand(b))),
                                 reg.parameter_symbols) for b in beta)
    return RegressorForm(reg, columns, Y.extract(list(range(reg.n)), list(columns)), zero,
                         tuple(base), tuple(names), beta, exact)
