"""High-precision reference dynamics: what every float64 and float32 route is measured against.

Two independent evaluations at :data:`DPS` (40) significant digits with mpmath:

* **the derived program**: the straight-line program of :func:`eomgen.derive` (the one the code
  generators print), printed once with SymPy's ``MpmathPrinter`` into a Python function over
  ``mpmath.mpf`` numbers (:func:`compile_program_mp`; our own printed program, never user
  text);
* **a Newton–Euler recursion in mpmath**: :func:`eomgen.numeric.rnea` itself, which is
  generic over the number type, on a model of ``mpf`` numbers (:func:`mp_model`, the
  :data:`MPMATH` numbers: 3-vectors and 3×3 matrices as NumPy object arrays).

:class:`Reference` holds both and checks that they agree (:meth:`Reference.cross_check`; to
about 1e-35 in practice, see ``tests/dynamics/test_hard_cases.py``).

The model the reference uses
----------------------------
A description read from URDF holds its rotations as float64 numbers (``cos(0.3)`` rounded),
which are orthogonal only to about 1e-16, and its axes are unit only to rounding. Two exact
algorithms then disagree by that much: the composite-body mass matrix and Newton–Euler both
assume rigid motions. :func:`high_precision_model` therefore turns the model into the *exact*
description it stands for: every number keeps its value (a float64 value is an exact binary
fraction) but is carried at :data:`MODEL_DPS` digits, every rotation that holds floats is
replaced by the nearest orthogonal matrix (polar decomposition, computed at that precision),
and every float axis is normalised. Exact entries (integers, rationals, ``pi/2``) are left
alone, so an exact description is its own high-precision model. The differences to the float64
model are a few units in the last place of the description's numbers: what any float64 code
must round them to anyway.

Examples
--------
>>> import eomgen
>>> ref = Reference(eomgen.load(eomgen.example_path("planar_2link")))
>>> tau = ref.tau([0.3, -0.2], [1.0, 0.5], [0.0, 0.0])
>>> bool(ref.cross_check([([0.3, -0.2], [1.0, 0.5], [0.0, 0.0])]) < 1e-30)
True
"""

from __future__ import annotations

from dataclasses import replace
from typing import Callable, Iterable, Sequence

import mpmath
import numpy as np
import sympy as sp
from sympy.printing.pycode import MpmathPrinter

from ..dynamics import Dynamics, derive
from ..model import Inertial, RobotModel, Transform, all_scalars
from ..numeric import NumericModel, Numbers, M_rnea, numeric_model, rnea
from ..symbolic.printing import program_function
from ..symbolic.program import Program

#: Significant digits of every reference evaluation.
DPS = 40
#: Digits at which the high-precision model's numbers are carried (more than DPS, so that the
#: model is never the limiting factor).
MODEL_DPS = 60


# ----------------------------------------------------------------------------------------------
# Numbers
# ----------------------------------------------------------------------------------------------

def _has_float(x) -> bool:
    return isinstance(x, sp.Basic) and bool(x.atoms(sp.Float))


def _to_mpf(x, dps: int = MODEL_DPS) -> mpmath.mpf:
    """A SymPy number (or a Python number) as an mpf; floats keep their exact binary value."""
    with mpmath.workdps(dps):
        if isinstance(x, (int, float)):
            return mpmath.mpf(x)
        value = sp.N(x, dps + 5)
        if not value.is_Float:
            value = sp.Float(value, dps + 5)
        return mpmath.mpf(value._mpf_)


def _float_at(x: mpmath.mpf, dps: int) -> sp.Float:
    """An mpf as a SymPy Float carrying ``dps`` digits."""
    return sp.Float(x, dps)


def _orthogonal(R, dps: int):
    """The orthogonal matrix nearest to the (almost orthogonal) 3×3 ``R``, at ``dps`` digits.

    Newton's iteration for the polar factor, ``X ← (X + X⁻ᵀ)/2``, converges quadratically from
    a matrix orthogonal to rounding.
    """
    with mpmath.workdps(dps + 10):
        X = mpmath.matrix([[_to_mpf(x, dps + 10) for x in row] for row in R])
        for _ in range(60):
            Y = (X + mpmath.inverse(X).T) / 2
            done = mpmath.mnorm(Y - X, 1) < mpmath.mpf(10) ** (-(dps + 5))
            X = Y
            if done:
                break
        return tuple(tuple(_float_at(X[r, c], dps) for c in range(3)) for r in range(3))


def _unit(axis, dps: int):
    with mpmath.workdps(dps + 10):
        v = [_to_mpf(a, dps + 10) for a in axis]
        norm = mpmath.sqrt(sum(a * a for a in v))
        return tuple(_float_at(a / norm, dps) for a in v)


def _precise(x, dps: int):
    """``x`` with every Float carried at ``dps`` digits (same value)."""
    if not _has_float(x):
        return x
    return x.xreplace({f: sp.Float(f, dps) for f in x.atoms(sp.Float)})


def high_precision_model(model: RobotModel, values=None, dps: int = MODEL_DPS) -> RobotModel:
    """The exact description ``model`` stands for, with numbers carried at ``dps`` digits.

    Parameters take their values (``values`` over the description's defaults); then every
    float keeps its value at ``dps`` digits, rotations holding floats become the nearest
    orthogonal matrix and float axes are normalised (see the module docstring). A model
    without floats is returned unchanged (apart from the parameters).
    """
    if model.parameters or (values and len(values)):
        model = model.with_numeric_parameters(values)

    def vec(v):
        return tuple(_precise(x, dps) for x in v)

    def mat(m):
        return tuple(vec(r) for r in m)

    links = []
    for link in model.links:
        i = link.inertial
        if i is not None:
            inertial = Inertial(_precise(i.mass, dps), vec(i.com), mat(i.inertia))
            link = replace(link, inertial=inertial)
        links.append(link)
    joints = []
    for j in model.joints:
        R = j.origin.rotation
        R = _orthogonal(R, dps) if any(_has_float(x) for row in R for x in row) else R
        axis = j.axis
        if j.type.is_movable and any(_has_float(a) for a in axis):
            axis = _unit(axis, dps)
        joints.append(replace(j, origin=Transform(R, vec(j.origin.translation)), axis=axis,
                              pitch=_precise(j.pitch, dps)))
    return replace(model, links=tuple(links), joints=tuple(joints), gravity=vec(model.gravity))


# ----------------------------------------------------------------------------------------------
# The derived program in mpmath
# ----------------------------------------------------------------------------------------------

class _Printer(MpmathPrinter):
    """mpmath code; floats as exact ``mpf`` literals (SymPy's own), pi as ``mpmath.pi``."""


def compile_program_mp(program: Program, inputs: Sequence[sp.Symbol],
                       outputs: Iterable[str] | None = None
                       ) -> Callable[..., dict[str, np.ndarray]]:
    """A function ``f(*values) -> {output: object array of mpf}`` evaluating ``program``.

    ``inputs`` are the symbols given values, in order; values are floats or mpf. Evaluation
    runs at the mpmath precision current at call time (use :func:`mpmath.workdps`). The printed
    code is our own program (assignments in evaluation order), executed in a fresh namespace
    that holds only ``mpmath``.
    """
    names = list(outputs) if outputs is not None else [n for n, _ in program.outputs]
    printer = _Printer({"fully_qualified_modules": True, "standard": "python3"})
    raw = program_function(program, inputs, printer, {"mpmath": mpmath}, names,
                           filename="<eomgen mpmath program>")

    def evaluate(*values) -> dict[str, np.ndarray]:
        converted = [v if isinstance(v, mpmath.mpf) else mpmath.mpf(float(v)) for v in values]
        result = {}
        for k, rows in zip(names, raw(*converted)):
            array = np.empty((len(rows), len(rows[0]) if rows else 0), dtype=object)
            for r, row in enumerate(rows):
                for c, e in enumerate(row):
                    array[r, c] = e if isinstance(e, mpmath.mpf) else mpmath.mpf(e)
            result[k] = array
        return result

    return evaluate


# ----------------------------------------------------------------------------------------------
# Newton–Euler in mpmath
# ----------------------------------------------------------------------------------------------

def _mpf_value(v) -> mpmath.mpf:
    """A caller's value as an mpf: an mpf as it is, anything else through its float (exact)."""
    return v if isinstance(v, mpmath.mpf) else mpmath.mpf(float(v))


#: mpmath numbers for the algorithms of :mod:`eomgen.numeric` (object arrays of ``mpf``):
#: the description's numbers carried at :data:`MODEL_DPS` digits, arithmetic at the mpmath
#: precision current at call time (:func:`mpmath.workdps`).
MPMATH = Numbers("mpmath", object, _to_mpf, _mpf_value, mpmath.sin, mpmath.cos, mpmath.isfinite)


def mp_model(model: RobotModel) -> NumericModel:
    """The numbers of ``model`` (parameters at their values) as mpf: the
    :class:`~eomgen.numeric.NumericModel` of :data:`MPMATH` numbers, on which
    :func:`eomgen.numeric.rnea` and ``M_rnea`` compute in mpmath. Use it on
    :func:`high_precision_model`'s result."""
    return numeric_model(model, numbers=MPMATH)


def _obj(values) -> np.ndarray:
    array = np.empty(len(values), dtype=object)
    array[:] = list(values)
    return array


def _mp_values(x, n: int) -> list:
    values = [_mpf_value(v) for v in x]
    if len(values) != n:
        raise ValueError(f"expected {n} values, got {len(values)}")
    return values


#: Inverse dynamics and the mass matrix by Newton–Euler in mpmath: the one implementation of
#: :mod:`eomgen.numeric` (generic over the number type) on an :func:`mp_model`.
mp_rnea = rnea
mp_M = M_rnea


# ----------------------------------------------------------------------------------------------
# Errors measured in mpmath
# ----------------------------------------------------------------------------------------------

def max_abs(a: np.ndarray) -> mpmath.mpf:
    """Largest absolute entry of an object (mpf) or float array, as an mpf (0 when empty)."""
    flat = np.asarray(a, dtype=object).ravel()
    return max((abs(mpmath.mpf(x)) for x in flat), default=mpmath.mpf(0))


def relative_error(value, reference: np.ndarray) -> float:
    """``max|value − reference| / max|reference|`` (normwise, ∞-norm over entries), the
    difference taken exactly in mpmath, so that a correctly rounded float64 value has error
    at most 2⁻⁵³ ≈ 1.1e-16. 0 when both are zero; inf when only the reference is."""
    with mpmath.workdps(DPS):
        v = np.asarray(value)
        diff = np.asarray([mpmath.mpf(float(x)) for x in v.ravel()], dtype=object) - \
            np.asarray(reference, dtype=object).ravel()
        num, den = max_abs(diff), max_abs(reference)
        if den == 0:
            return 0.0 if num == 0 else float("inf")
        return float(num / den)


def to_float(a: np.ndarray) -> np.ndarray:
    """An object array of mpf rounded to float64."""
    a = np.asarray(a, dtype=object)
    return np.array([float(x) for x in a.ravel()], dtype=float).reshape(a.shape)


# ----------------------------------------------------------------------------------------------
# The reference
# ----------------------------------------------------------------------------------------------

class Reference:
    """High-precision M(q), τ(q, q̇, q̈) and q̈(q, q̇, τ) of a model (see the module docstring).

    Parameters
    ----------
    model:
        The robot, as the float64 routes see it; parameters take their values.
    dynamics:
        Dynamics already derived from ``model`` with M and tau; reused when ``model`` is exact
        (no floats: the high-precision model is the model itself), which saves a derivation.
    dps:
        Significant digits of the evaluations (at least 30).

    Values are object arrays of mpf; inputs are float64 (converted exactly) or mpf. With
    quaternion joints ``q`` is the configuration (NQ entries, :attr:`nq`) and the rest have NV
    (:attr:`n`) entries; a quaternion need not be unit (both evaluations normalise it).
    """

    def __init__(self, model: RobotModel, dynamics: Dynamics | None = None, dps: int = DPS):
        if dps < 30:
            raise ValueError("the reference needs at least 30 digits")
        self.dps = dps
        self.model = high_precision_model(model)
        exact = not any(_has_float(x) for x in all_scalars(model.with_numeric_parameters()
                                                             if model.parameters else model))
        if (dynamics is not None and exact and not model.parameters
                and {"M", "tau"} <= set(dynamics.outputs)):
            self.dynamics = dynamics
        else:
            self.dynamics = derive(self.model, outputs=("M", "tau"), simplify=False)
        d = self.dynamics
        self.n, self.nq = len(d.qd), len(d.q)
        self._M = compile_program_mp(d.program, list(d.q), ["M"])
        self._tau = compile_program_mp(d.program, list(d.q + d.qd + d.qdd), ["tau"])
        self.mp_model = mp_model(self.model)

    def M(self, q) -> np.ndarray:
        """Mass matrix (n, n) from the derived program."""
        with mpmath.workdps(self.dps):
            return self._M(*_mp_values(q, self.nq))["M"]

    def tau(self, q, qd, qdd) -> np.ndarray:
        """Inverse dynamics (n,) from the derived (Newton–Euler) program."""
        with mpmath.workdps(self.dps):
            values = _mp_values(q, self.nq) + _mp_values(qd, self.n) + _mp_values(qdd, self.n)
            return self._tau(*values)["tau"][:, 0]

    def M_rnea(self, q) -> np.ndarray:
        """Mass matrix (n, n) from the mpmath Newton–Euler recursion."""
        with mpmath.workdps(self.dps):
            return M_rnea(self.mp_model, q)

    def tau_rnea(self, q, qd, qdd) -> np.ndarray:
        """Inverse dynamics (n,) from the mpmath Newton–Euler recursion."""
        with mpmath.workdps(self.dps):
            return rnea(self.mp_model, q, qd, qdd)

    def forward_dynamics(self, q, qd, tau) -> np.ndarray:
        """q̈ (n,) solving M q̈ = τ − (C q̇ + g) at ``dps`` digits (mpmath Cholesky)."""
        with mpmath.workdps(self.dps):
            M = self.M(q)
            bias = self.tau(q, qd, [0] * self.n)
            rhs = _obj(_mp_values(tau, self.n)) - bias
            x = mpmath.cholesky_solve(mpmath.matrix(M.tolist()), mpmath.matrix(list(rhs)))
            return _obj([x[k] for k in range(self.n)])

    def condition(self, q) -> float:
        """The 2-norm condition number of M(q), from its eigenvalues at ``dps`` digits."""
        with mpmath.workdps(self.dps):
            eig = mpmath.eigsy(mpmath.matrix(self.M(q).tolist()), eigvals_only=True)
            values = sorted(eig[k] for k in range(self.n))
            return float(values[-1] / values[0]) if values[0] > 0 else float("inf")

    def cross_check(self, states) -> float:
        """Largest relative difference between the program and the Newton–Euler recursion
        over ``states`` ((q, qd, qdd) triples): τ and M. About 1e-35 when all is well."""
        worst = mpmath.mpf(0)
        with mpmath.workdps(self.dps):
            for q, qd, qdd in states:
                for a, b in ((self.tau(q, qd, qdd), self.tau_rnea(q, qd, qdd)),
                             (self.M(q), self.M_rnea(q))):
                    scale = max(max_abs(b), mpmath.mpf(10) ** -300)
                    worst = max(worst, max_abs(a - b) / scale)
        return float(worst)


__all__ = ["DPS", "MODEL_DPS", "Reference", "high_precision_model", "compile_program_mp",
           "MPMATH", "mp_model", "mp_rnea", "mp_M", "relative_error", "max_abs",
           "to_float"]
