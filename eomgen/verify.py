"""Verification of derived dynamics: properties and identities against Newton–Euler.

Checks, in the order reported:

``M symmetric``           M − Mᵀ = 0 (exactly when the skew check below is exact; else sampled).
``M positive definite``   Cholesky succeeds at every sampled state; the smallest eigenvalue is
                          reported relative to the largest.
``Mdot - 2C skew``        N = Ṁ − 2C satisfies N + Nᵀ = 0. Exactly (polynomial reduction modulo
                          sin² + cos² = 1) for models of at most 3 joints written with exact
                          numbers (symbols, integers, pi/2); at sampled states otherwise, with Ṁ from
                          complex-step differentiation of M (exact to rounding, no step error).
``g = RNEA(q,0,0)``       the gravity vector against the numeric recursive Newton–Euler.
``M e_i = RNEA(q,0,e_i) - RNEA(q,0,0)``  every column of M.
``M qdd + C qd + g = RNEA(q,qd,qdd)``  the whole equation at random states.
``symbolic Newton-Euler tau``  when derived, the O(n) inverse dynamics equals M q̈ + C q̇ + g.

The RNEA is :mod:`eomgen.numeric`, an independent O(n) algorithm on the same model. Parameters
kept symbolic are given their default values. Errors are relative to the size of the reference
(``|a − b|_max / max(1, |b|_max)``).

With quaternion joints (a free flyer, ball joints) ``q`` is the configuration (NQ entries, each
quaternion drawn uniformly on the unit sphere) and ``qd``, ``qdd`` the velocities and
accelerations (NV); Ṁ is taken along ``q̇ = configuration_rate(q, v)``
(:mod:`eomgen.model.configuration`), and the checks are sampled (never exact).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import sympy as sp

from .dynamics import Dynamics
from .errors import ParameterError
from .model import all_scalars, massless_joints
from .model.moving_mass import massless_problem
from .numeric import numeric_model
from .outputs import BY_SYMBOL
from .numeric import rnea as numeric_rnea
from .model.configuration import configuration_rate, random_configuration
from .symbolic.evaluate import compile_program

#: Default relative tolerance of the numeric identities.
TOLERANCE = 1e-9
EXACT_MAX_DOF = 3


@dataclass(frozen=True)
class CheckResult:
    name: str
    max_abs_error: float
    max_rel_error: float
    passed: bool
    how: str  # "exact" or "N samples"


@dataclass(frozen=True)
class VerificationReport:
    robot: str
    checks: tuple[CheckResult, ...]
    #: What explains a failed check, one sentence each: the joints that move no mass
    #: (:func:`eomgen.model.massless_joints`), naming the links they carry.
    notes: tuple[str, ...] = ()

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    def format(self) -> str:
        width = max(len(c.name) for c in self.checks)
        lines = [f"Verification of {self.robot}:"]
        for c in self.checks:
            status = "ok  " if c.passed else "FAIL"
            lines.append(f"  {status} {c.name:<{width}}  max abs {c.max_abs_error:9.2e}  "
                         f"max rel {c.max_rel_error:9.2e}  ({c.how})")
        lines += [f"  {note}" for note in self.notes]
        lines.append("all checks passed" if self.passed else "SOME CHECKS FAILED")
        return "\n".join(lines)


def _rel(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    err = float(np.max(np.abs(a - b))) if a.size else 0.0
    return err, err / max(1.0, float(np.max(np.abs(b))) if b.size else 1.0)


def _is_exact(model) -> bool:
    """Exact symbolic checks need exact numbers: a float rotation is orthogonal only to rounding,
    and the identities fail by that rounding."""
    return not any(v.atoms(sp.Float) for v in all_scalars(model))


def _exact(dynamics: Dynamics, name: str) -> sp.Matrix:
    """Output ``name`` as an exact expression: program expanded, floats made exact rationals."""
    program = dynamics.program
    return program.expand(program.output(name), dynamics._full)


def _identically_zero(matrix: sp.Matrix, q) -> bool:
    """True when every entry is zero as a function of q (and everything else).

    Entries are polynomials in sin q_i, cos q_i and the other symbols (prismatic q_i, and q_i
    itself, which is algebraically independent of sin q_i and cos q_i, among them); they are
    reduced modulo sin² + cos² − 1 per joint, which decides zero exactly (no heuristic
    simplification). An entry that is not such a polynomial is reported as not zero.
    """
    sines = [sp.Symbol(f"_s{k}") for k in range(len(q))]
    cosines = [sp.Symbol(f"_c{k}") for k in range(len(q))]
    trig = {}
    for k, qk in enumerate(q):
        trig[sp.sin(qk)] = sines[k]
        trig[sp.cos(qk)] = cosines[k]
    for entry in matrix:
        e = sp.expand(sp.expand_trig(entry)).xreplace(trig)
        if not e.is_polynomial(*e.free_symbols):
            return False  # not a polynomial in sin q_i, cos q_i, q_i and the rest: undecided
        for s_k, c_k in zip(sines, cosines):
            e = sp.rem(e, s_k**2 + c_k**2 - 1, s_k) if e.has(s_k) else e
        if sp.expand(e) != 0:
            return False
    return True


def sample_states(n: int, samples: int, rng: np.random.Generator, model=None):
    """Random states: angles in [−π, π], rates and accelerations ~ N(0, 1). With a ``model``
    holding quaternion joints, ``q`` is its configuration (``model.nq`` entries): each
    quaternion uniform on the unit sphere."""
    for _ in range(samples):
        q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.normal(size=n), rng.normal(size=n)
        yield (q if model is None else random_configuration(model, q, rng)), qd, qdd


def reference_rnea(model):
    """``rnea(q, qd, qdd)`` of ``model`` by the float Newton–Euler recursion, in its
    ``joint_names`` coordinates (with coupled joints ``Tᵀ RNEA(T q + c, T q̇, T q̈)`` on the
    whole tree, :mod:`eomgen.numeric.newton_euler`)."""
    nm = numeric_model(model)
    return lambda q, qd, qdd: numeric_rnea(nm, q, qd, qdd)


def verify(dynamics: Dynamics, samples: int = 20, seed: int = 0,
           tolerance: float = TOLERANCE) -> VerificationReport:
    """Check ``dynamics`` (see module docstring) and return a report; raises nothing on failure.

    Parameters
    ----------
    dynamics:
        From :func:`eomgen.derive`, with outputs M, C and g.
    samples:
        Number of random states for the numeric checks.
    seed:
        Seed of the random states (reproducible reports).
    tolerance:
        Relative tolerance of every numeric check.
    """
    model = dynamics.model
    for name in ("M", "C", "g"):
        if name not in dynamics.outputs:
            raise ValueError(f"verification needs M, C and g; {name} was not derived")
    values = model.parameter_values
    params = [p.symbol for p in model.parameters]
    missing = [p.name for p in model.parameters if p.symbol not in values]
    if missing:
        raise ParameterError(model.source, "parameters",
                             "verification needs a value for " + ", ".join(missing))
    n = model.dof
    # the outputs of (q, q̇, q̈) only: one that takes τ (qdd_aba) or another input is not
    # checked here and would leave that input unbound
    checked = [name for name, _ in dynamics.program.outputs
               if set(getattr(BY_SYMBOL.get(name), "inputs", ())) <= {"q", "qd", "qdd"}]
    evaluate_all = compile_program(dynamics.program.pruned(checked),
                                   list(dynamics.q) + list(dynamics.qd) + list(dynamics.qdd)
                                   + params)
    zero_qdd = [0.0] * len(dynamics.qd)
    n_x = len(dynamics.q) + len(dynamics.qd)  # q (NQ) and qd (NV)

    def evaluate(*values, qdd=None):
        return evaluate_all(*values[:n_x], *(zero_qdd if qdd is None else qdd),
                            *values[n_x:])

    pvals = [values[s] for s in params]
    rnea = reference_rnea(model)
    rng = np.random.default_rng(seed)
    states = list(sample_states(n, samples, rng, model))
    checks: list[CheckResult] = []
    how = f"{samples} samples"
    # exact checks reduce polynomials in sin q_i, cos q_i: not a quaternion's entries, nor the
    # sin(0.5 q1 − 0.3 q2) of a coupled joint
    exact = (n <= EXACT_MAX_DOF and _is_exact(model) and model.nq == model.dof
             and not model.couplings)

    def record(name, pairs, how=how, extra_ok=True):
        abs_err = max((_rel(a, b)[0] for a, b in pairs), default=0.0)
        rel_err = max((_rel(a, b)[1] for a, b in pairs), default=0.0)
        checks.append(CheckResult(name, abs_err, rel_err, rel_err <= tolerance and extra_ok, how))

    results = [evaluate(*q, *qd, *pvals, qdd=qdd) for q, qd, qdd in states]

    if exact:
        M_exact = _exact(dynamics, "M")
        checks.append(CheckResult("M symmetric", 0.0, 0.0,
                                  _identically_zero(M_exact - M_exact.T, dynamics.q), "exact"))
    else:
        record("M symmetric", [(r["M"], r["M"].T) for r in results])

    min_ratio = np.inf
    pd = True
    for r in results:
        M = r["M"]
        try:
            np.linalg.cholesky(M)
        except np.linalg.LinAlgError:
            pd = False
        eig = np.linalg.eigvalsh((M + M.T) / 2)
        min_ratio = min(min_ratio, eig[0] / max(eig[-1], np.finfo(float).tiny))
    checks.append(CheckResult("M positive definite", 0.0, float(min_ratio) if n else 0.0, pd and n > 0,
                              how + "; 'rel' = smallest/largest eigenvalue"))

    if exact:
        Mdot = sp.zeros(n, n)
        for k in range(n):
            Mdot += M_exact.diff(dynamics.q[k]) * dynamics.qd[k]
        N = Mdot - 2 * _exact(dynamics, "C")
        checks.append(CheckResult("Mdot - 2C skew-symmetric", 0.0, 0.0,
                                  _identically_zero(N + N.T, dynamics.q), "exact"))
    else:
        pairs = []
        h = 1e-20
        for (q, qd, _), r in zip(states, results):
            rate = configuration_rate(q, qd, model) if model.nq > model.dof else qd
            stepped = evaluate(*(q + 1j * h * rate), *qd, *pvals)["M"]
            Mdot = stepped.imag / h
            N = Mdot - 2 * r["C"]
            pairs.append((N + N.T, np.zeros_like(N)))
        # scale by |Mdot| + |C| so the tolerance is relative
        scale = max(1.0, max(float(np.abs(r["C"]).max()) for r in results))
        abs_err = max(float(np.abs(a).max()) for a, _ in pairs)
        checks.append(CheckResult("Mdot - 2C skew-symmetric", abs_err, abs_err / scale,
                                  abs_err / scale <= tolerance, how))

    zeros = np.zeros(n)
    record("g = RNEA(q,0,0)", [(r["g"][:, 0], rnea(q, zeros, zeros))
                               for (q, _, _), r in zip(states, results)])
    columns = []
    for (q, _, _), r in zip(states, results):
        g_ref = rnea(q, zeros, zeros)
        ref = np.column_stack([rnea(q, zeros, e) - g_ref for e in np.eye(n)]) if n else np.zeros((0, 0))
        columns.append((r["M"], ref))
    record("M columns = RNEA(q,0,e_i) - RNEA(q,0,0)", columns)
    record("M qdd + C qd + g = RNEA(q,qd,qdd)",
           [(r["M"] @ qdd + r["C"] @ qd + r["g"][:, 0], rnea(q, qd, qdd))
            for (q, qd, qdd), r in zip(states, results)])
    if "tau" in dynamics.outputs:
        record("symbolic Newton-Euler tau = M qdd + C qd + g",
               [(r["tau"][:, 0], r["M"] @ qdd + r["C"] @ qd + r["g"][:, 0])
                for (q, qd, qdd), r in zip(states, results)])
    notes = tuple(f"M is singular: joint '{joint}' {massless_problem(links)}"
                  for joint, links in massless_joints(model))
    return VerificationReport(model.name, tuple(checks), notes)
