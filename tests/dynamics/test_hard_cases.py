"""Hard cases for the numerics: what eomgen's generated code and RNEA do, and what they promise.

Every number is compared with the 40-digit reference of :mod:`eomgen.analysis.precision` (the
derived program in mpmath, cross-checked by an mpmath Newton–Euler recursion). The models are
written with exact numbers (integers, rationals, axis-aligned or exactly normalised axes), so the
float64 code and the reference describe the same robot; errors are errors of evaluation.

Notation: ``eps = 2.2e-16`` (float64), ``eps32 = 1.2e-7``; errors are normwise relative
(``max|x − x_ref| / max|x_ref|``) unless said otherwise.

Expected behaviour and the bounds asserted
------------------------------------------
Evaluation of M(q) and τ(q, q̇, q̈)
    A straight-line program of a few hundred operations, without any solve: each entry is a sum
    of products of bounded factors (sines, cosines, the model's numbers), so the normwise error
    is at most a modest multiple of eps and **cond(M) does not enter**. Bound:
    ``EVAL_BOUND = 1000 eps ≈ 2.2e-13`` (measured: below 2e-15 for every case here, the 30-link
    chain included). This holds for mass ratios of 1e6, near-massless links, joint speeds of
    1e3 rad/s, angles at ±π and of 1e3 or 1e6 rad (sin and cos of the given double are
    evaluated as accurately as libm does; the double 1e6 itself is exact), and zero gravity.

    Far from the root origin: the composite-body program refers every inertia to the first
    moving joint's origin, so a robot 1 km (or 1000 km) from its root origin keeps its digits
    (:func:`test_far_from_the_root_origin_the_program_keeps_its_digits`). A short link after a
    very long one (distance d from the first joint, size ℓ) had its own small M entries right
    to ``(d/ℓ)² eps`` only with that program; the body-frame CRBA, which ``derive`` builds
    where it is cheaper, keeps them (see ``docs/numerics.md``,
    :func:`test_a_long_link_before_a_short_one_keeps_the_digits_of_its_small_entries`).

RNEA's M (``eomgen.numeric.M_rnea``)
    Column i is ``RNEA(q, 0, e_i) − RNEA(q, 0, 0)``: a difference, so its absolute error is
    eps times the size of the terms, ``|M| + |g|`` (N m against kg m² per rad/s²). Bound:
    ``EVAL_BOUND (1 + |g|/|M|)``.

Forward dynamics (Cholesky solve)
    Cholesky is backward stable: the computed q̈ solves ``(M + ΔM) q̈ = b + Δb`` with
    ``|ΔM| ≲ c n eps |M|`` (Higham, *Accuracy and Stability of Numerical Algorithms*, Thm 10.4),
    and M and b carry their evaluation errors, which are relative to the *terms* of
    ``b = τ − (C q̇ + g)``, not to b. The forward error is therefore bounded by
    ``FD_BOUND = 100 n cond₂(M) eps (1 + (|τ| + |C q̇ + g|) / (|M| |q̈|))`` relative to |q̈|.
    The last factor is the cancellation in b: at 1e3 rad/s with τ balancing C q̇ ≈ 1e5, q̈ ≈ 1
    carries only about 1e-11, whatever the code. When ``cond(M) eps > 1e-6`` the module
    warns (``IllConditionedWarning``); M that is not positive definite raises
    ``numpy.linalg.LinAlgError`` naming the state; non-finite M or bias (overflow) raises
    ``FloatingPointError``. Never a silent NaN.

float32
    The same program over float32 arrays: ``F32_BOUND = 1000 eps32 ≈ 1.2e-4`` for inputs
    representable in float32. An angle of 1e3 rad is *not* (its float32 neighbours are 6e-5
    apart): wrap angles (in float64) before casting them.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import sympy as sp

from eomgen.analysis.conditioning import CONDITION_LIMIT, cholesky_solve, condition_estimate
from eomgen.analysis.precision import Reference, max_abs, relative_error
from eomgen.analysis.routes import compile_batch
from eomgen.codegen import available_backends, make_job
from eomgen.dynamics import derive
from eomgen.model import Inertial, Joint, JointType, Link, Transform, build_model
from eomgen.numeric import M_rnea, numeric_model, rnea
from support import load_module, random_states

EPS = float(np.finfo(np.float64).eps)
EPS32 = float(np.finfo(np.float32).eps)
EVAL_BOUND = 1000 * EPS
F32_BOUND = 1000 * EPS32
CROSS_CHECK_BOUND = 1e-25
R = sp.Rational


def fd_bound(case, q, qd, tau) -> tuple[float, np.ndarray]:
    """FD_BOUND at a state (see the module docstring), and the reference q̈."""
    reference = case.reference
    qdd = reference.forward_dynamics(q, qd, tau)
    M = reference.M(q)
    bias = reference.tau(q, qd, np.zeros(case.n))
    amplification = (max_abs(tau) + max_abs(bias)) / (max_abs(M) * max_abs(qdd))
    return 100 * case.n * reference.condition(q) * EPS * (1 + float(amplification)), qdd


# ----------------------------------------------------------------------------------------------
# Models (exact numbers)
# ----------------------------------------------------------------------------------------------

def rod(mass, length) -> Inertial:
    """A slender box along x (length ℓ, width ℓ/10), centre of mass at ℓ/2."""
    mass, length = sp.nsimplify(mass), sp.nsimplify(length)
    w = length / 10
    side = mass * (length**2 + w**2) / 12
    return Inertial(mass, (length / 2, 0, 0),
                    ((mass * 2 * w**2 / 12, 0, 0), (0, side, 0), (0, 0, side)))


def chain(name, masses, lengths, axes=None, kinds=None, base=(0, 0, 0),
          gravity=(0, 0, R(-981, 100))):
    """A serial chain: link k is a rod of masses[k] and lengths[k] (None: massless), joint k at
    the end of link k−1 (the first at ``base``), axes alternating z, y unless given."""
    n = len(masses)
    axes = axes or [(0, 0, 1) if k % 2 == 0 else (0, 1, 0) for k in range(n)]
    kinds = kinds or [JointType.REVOLUTE] * n
    links, joints = [Link("base")], []
    parent, offset = "base", base
    for k in range(n):
        inertial = None if masses[k] is None else rod(masses[k], lengths[k])
        links.append(Link(f"link{k}", inertial))
        joints.append(Joint(f"joint{k}", kinds[k], parent, f"link{k}",
                            Transform.from_xyz_rpy([sp.nsimplify(x) for x in offset]), axes[k]))
        parent, offset = f"link{k}", (lengths[k], 0, 0)
    return build_model("<hard case>", name, links, joints, gravity=gravity)


P, RV = JointType.PRISMATIC, JointType.REVOLUTE
MODELS = {
    # 1e6 between the heaviest and the lightest link
    "mass_ratio": lambda: chain("mass_ratio", [1000, 1, R(1, 1000)], [1, 1, 1]),
    # a near-massless distal link: cond(M) ~ 1e11
    "light_tip": lambda: chain("light_tip", [1, 1, R(1, 10**10)], [1, 1, 1]),
    # two prismatic joints whose axes differ by 1e-5 rad, with a massless link between them:
    # M restricted to them is m [[1, cos δ], [cos δ, 1]], cond ~ 4/δ² = 4e10
    "prismatic_near_singular": lambda: chain(
        "prismatic_near_singular", [None, 2, 1], [R(1, 2), R(1, 2), R(1, 2)],
        axes=[(1, 0, 0), (1, R(1, 10**5), 0), (0, 0, 1)], kinds=[P, P, RV]),
    "zero_gravity": lambda: chain("zero_gravity", [2, R(3, 2), 1], [R(1, 2), R(2, 5), R(3, 10)],
                                  gravity=(0, 0, 0)),
    # an ordinary spatial arm, for the hard *states*
    "arm": lambda: chain("arm", [2, R(3, 2), 1], [R(1, 2), R(2, 5), R(3, 10)]),
    # 30 links, 0.1 m and 1 kg each (derivation of M and tau: about 2 s)
    "chain30": lambda: chain("chain30", [1] * 30, [R(1, 10)] * 30),
}


class Case:
    """A model with its derived dynamics, generated NumPy module, reference and numeric model."""

    def __init__(self, name: str, folder):
        self.name = name
        self.model = MODELS[name]()
        self.n = self.model.dof
        self.dynamics = derive(self.model, outputs=("M", "tau"), simplify=False)
        job = make_job(self.dynamics, ("mass_matrix", "inverse_dynamics", "forward_dynamics"))
        (generated,) = available_backends()["numpy"].generate(job)
        path = folder / generated.name
        path.write_text(generated.content, encoding="utf-8")
        self.module = load_module(path, f"hard_{name}")
        self.reference = Reference(self.model, dynamics=self.dynamics)
        self.nm = numeric_model(self.model)

    def states(self, count: int, seed: int = 0):
        return random_states(seed, self.n, count)


@pytest.fixture(scope="module")
def cases(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hard_cases")
    built: dict[str, Case] = {}

    def get(name: str) -> Case:
        if name not in built:
            built[name] = Case(name, folder)
        return built[name]

    return get


def rnea_M_error(case: Case, q) -> float:
    """Error of RNEA's M relative to the size of the terms it is the difference of."""
    M_ref = case.reference.M(q)
    g_ref = case.reference.tau(q, np.zeros(case.n), np.zeros(case.n))
    scale = max_abs(M_ref) + max_abs(g_ref)
    return float(max_abs(np.array([float(x) for x in M_rnea(case.nm, q).ravel()],
                                  dtype=object) - M_ref.ravel()) / scale)


# ----------------------------------------------------------------------------------------------
# The reference itself
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["mass_ratio", "light_tip", "prismatic_near_singular",
                                  "zero_gravity", "chain30"])
def test_the_two_references_agree(cases, name):
    """The derived program at 40 digits and the mpmath Newton–Euler recursion agree to
    ~1e-35: the reference is right to far more digits than any float64 route."""
    case = cases(name)
    states = case.states(1 if name == "chain30" else 2, seed=5)
    assert case.reference.cross_check(states) < CROSS_CHECK_BOUND


# ----------------------------------------------------------------------------------------------
# Evaluation: generated NumPy code and RNEA
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["mass_ratio", "light_tip", "prismatic_near_singular",
                                  "zero_gravity", "chain30"])
def test_generated_code_and_rnea_are_accurate_whatever_the_conditioning(cases, name):
    """M and τ from the generated module and τ from RNEA within EVAL_BOUND, although cond(M)
    reaches 1e11 here: evaluation involves no solve. RNEA's M (a difference of RNEA calls)
    within EVAL_BOUND relative to |M| + |g|."""
    case = cases(name)
    states = case.states(2 if name == "chain30" else 4, seed=1)
    q, qd, qdd = (np.array(x) for x in zip(*states))
    M_batch = case.module.mass_matrix(q)
    tau_batch = case.module.inverse_dynamics(q, qd, qdd)
    for k, (qk, qdk, qddk) in enumerate(states):
        M_ref, tau_ref = case.reference.M(qk), case.reference.tau(qk, qdk, qddk)
        assert relative_error(M_batch[k], M_ref) <= EVAL_BOUND
        assert relative_error(tau_batch[k], tau_ref) <= EVAL_BOUND
        assert relative_error(case.module.inverse_dynamics(qk, qdk, qddk), tau_ref) <= EVAL_BOUND
        assert relative_error(rnea(case.nm, qk, qdk, qddk), tau_ref) <= EVAL_BOUND
        if name != "chain30":  # n + 1 RNEA calls of 31 bodies: slow, and covered by the others
            assert rnea_M_error(case, qk) <= EVAL_BOUND


def _near_pi(n):
    pi = math.pi
    values = [pi, -pi, pi - 1e-9, -pi + 1e-12, np.nextafter(pi, 4.0), -np.nextafter(pi, 4.0)]
    return np.array([values[k % len(values)] for k in range(n)])


HARD_STATES = {
    "near_pi": lambda n, rng: (_near_pi(n), rng.normal(size=n), rng.normal(size=n)),
    "thousand_rad": lambda n, rng: (1e3 * rng.choice([-1, 1], n) + rng.uniform(-3, 3, n),
                                    rng.normal(size=n), rng.normal(size=n)),
    "million_rad": lambda n, rng: (1e6 * rng.choice([-1, 1], n) + rng.uniform(-3, 3, n),
                                   rng.normal(size=n), rng.normal(size=n)),
    "fast_1e3_rad_per_s": lambda n, rng: (rng.uniform(-np.pi, np.pi, n), 1e3 * rng.normal(size=n),
                                          rng.normal(size=n)),
}


@pytest.mark.parametrize("kind", list(HARD_STATES))
def test_hard_states_evaluate_accurately(cases, kind):
    """Angles at ±π, of ±1e3 and ±1e6 rad, and joint speeds of 1e3 rad/s: M, τ and q̈ of the
    generated module, and RNEA's τ, against the reference at the same (double) inputs. At 1e6
    rad the input itself is only meaningful to 1e6·eps ≈ 2e-10 rad, but it is evaluated
    exactly as given. At 1e3 rad/s, τ is dominated by C q̇ (~1e6) and the bound is relative
    to it."""
    case = cases("arm")
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd, qdd = HARD_STATES[kind](case.n, rng)
        M_ref, tau_ref = case.reference.M(q), case.reference.tau(q, qd, qdd)
        assert relative_error(case.module.mass_matrix(q), M_ref) <= EVAL_BOUND
        assert relative_error(case.module.inverse_dynamics(q, qd, qdd), tau_ref) <= EVAL_BOUND
        assert relative_error(rnea(case.nm, q, qd, qdd), tau_ref) <= EVAL_BOUND
        tau = tau_ref_float(tau_ref)
        bound, qdd_ref = fd_bound(case, q, qd, tau)
        assert relative_error(case.module.forward_dynamics(q, qd, tau), qdd_ref) <= bound


def tau_ref_float(tau_ref) -> np.ndarray:
    return np.array([float(x) for x in tau_ref])


# ----------------------------------------------------------------------------------------------
# Forward dynamics: accuracy, condition number, warnings, errors
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["mass_ratio", "light_tip", "prismatic_near_singular", "arm",
                                  "chain30"])
def test_forward_dynamics_error_is_bounded_by_the_condition_number(cases, name):
    """q̈ within FD_BOUND = 100 n cond(M) eps of the 40-digit solve; the returned condition
    number is a lower bound of cond₂(M), exact near the warning limit; IllConditionedWarning
    exactly when cond(M) eps > 1e-6."""
    case = cases(name)
    for q, qd, tau in case.states(1 if name == "chain30" else 3, seed=3):
        cond = case.reference.condition(q)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            qdd, estimate = case.module.forward_dynamics(q, qd, tau, return_condition=True)
        bound, qdd_ref = fd_bound(case, q, qd, tau)
        assert relative_error(qdd, qdd_ref) <= bound
        # float64 eigenvalues: the smallest carries an absolute error of about eps |M|
        assert estimate <= cond * (1 + 1e-9 + 100 * cond * EPS)
        if estimate > 1e-4 * CONDITION_LIMIT:  # computed from eigenvalues there
            assert estimate == pytest.approx(cond, rel=1e-3)
        ill = [w for w in caught if issubclass(w.category, case.module.IllConditionedWarning)]
        assert bool(ill) == (cond > CONDITION_LIMIT), (cond, [str(w.message) for w in caught])


@pytest.mark.parametrize("name", ["light_tip", "prismatic_near_singular"])
def test_ill_conditioned_mass_matrices_warn_clearly(cases, name):
    """cond(M) ≥ 1e10: the generated module and the library solve both warn, naming the
    condition number and the error it allows; batches name the state."""
    case = cases(name)
    q, qd, tau = case.states(1, seed=4)[0]
    assert case.reference.condition(q) >= 1e10
    with pytest.warns(case.module.IllConditionedWarning, match=r"ill-conditioned: cond\(M\) >= "):
        case.module.forward_dynamics(q, qd, tau)
    batch = np.stack([q, q])
    with pytest.warns(case.module.IllConditionedWarning, match="at state [01]: cond"):
        case.module.forward_dynamics(batch, np.zeros_like(batch), np.zeros_like(batch))
    assert issubclass(case.module.IllConditionedWarning, RuntimeWarning)
    from eomgen.analysis.conditioning import IllConditionedWarning

    with pytest.warns(IllConditionedWarning, match="ill-conditioned"):
        cholesky_solve(case.module.mass_matrix(q), tau)


def test_condition_estimate_is_a_lower_bound_on_random_robots():
    """(max L_ii / min L_ii)² ≤ cond₂(M) always, and close to it for robots."""
    from support.reference import random_robot

    rng = np.random.default_rng(11)
    ratios = []
    for _ in range(15):
        model = random_robot(rng, int(rng.integers(2, 7)))
        nm = numeric_model(model)
        for _ in range(3):
            M = M_rnea(nm, rng.uniform(-np.pi, np.pi, model.dof))
            try:
                L = np.linalg.cholesky(M)
            except np.linalg.LinAlgError:
                continue  # a massless branch: singular M
            ratios.append(np.linalg.cond(M) / condition_estimate(L))
    assert min(ratios) >= 1 - 1e-9
    assert np.median(ratios) < 10


def test_singular_mass_matrix_raises_a_clear_error(tmp_path):
    """A joint that moves no mass: M is singular; forward dynamics raises LinAlgError saying
    so (and which state of a batch), never returns NaN or inf."""
    model = chain("singular", [1, None], [1, 1])
    dyn = derive(model, outputs=("M", "tau"), simplify=False)
    job = make_job(dyn, ("forward_dynamics",))
    (generated,) = available_backends()["numpy"].generate(job)
    path = tmp_path / generated.name
    path.write_text(generated.content, encoding="utf-8")
    module = load_module(path, "hard_singular")
    q = np.array([0.3, 0.2])
    with pytest.raises(np.linalg.LinAlgError, match="not positive definite"):
        module.forward_dynamics(q, np.zeros(2), np.ones(2))
    with pytest.raises(np.linalg.LinAlgError, match="at state 0"):
        module.forward_dynamics(np.stack([q, q]), np.zeros((2, 2)), np.ones((2, 2)))
    with pytest.raises(np.linalg.LinAlgError, match="not positive definite"):
        cholesky_solve(module.mass_matrix(q), np.ones(2))


def test_overflow_and_nan_raise_instead_of_returning_non_finite_values(cases):
    """Joint speeds of 1e200 overflow C q̇ (1e400): FloatingPointError naming the state;
    NaN inputs likewise."""
    case = cases("arm")
    q = np.zeros(case.n)
    with np.errstate(over="ignore", invalid="ignore"):  # NumPy's own notes on the way
        with pytest.raises(FloatingPointError, match="not finite"):
            case.module.forward_dynamics(q, np.full(case.n, 1e200), np.zeros(case.n))
        batch = np.stack([q, q])
        speeds = np.stack([np.zeros(case.n), np.full(case.n, np.nan)])
        with pytest.raises(FloatingPointError, match="at state 1"):
            case.module.forward_dynamics(batch, speeds, batch)


def test_zero_gravity_is_exactly_zero(cases):
    """With gravity (0, 0, 0) the gravity terms are structural zeros: τ(q, 0, 0) and q̈(q, 0, 0)
    are exactly 0 in the generated code and in RNEA, at any q."""
    case = cases("zero_gravity")
    for q, _, _ in case.states(3, seed=8):
        zero = np.zeros(case.n)
        assert np.all(case.module.inverse_dynamics(q, zero, zero) == 0.0)
        assert np.all(case.module.forward_dynamics(q, zero, zero) == 0.0)
        assert np.all(rnea(case.nm, q, zero, zero) == 0.0)


# ----------------------------------------------------------------------------------------------
# float32
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("name", ["arm", "mass_ratio", "light_tip"])
def test_float32_program_is_accurate_to_float32(cases, name):
    """The derived program over float32 arrays, at float32-representable inputs: M and τ
    within F32_BOUND = 1000 eps32 ≈ 1.2e-4 (normwise)."""
    case = cases(name)
    d = case.dynamics
    M32 = compile_batch(d.program, d.q, ["M"], np.float32)
    tau32 = compile_batch(d.program, d.q + d.qd + d.qdd, ["tau"], np.float32)
    states = [tuple(x.astype(np.float32).astype(np.float64) for x in s)
              for s in case.states(4, seed=9)]
    q, qd, qdd = (np.array(x, dtype=np.float32) for x in zip(*states))
    (M,) = M32(*q.T)
    (tau,) = tau32(*q.T, *qd.T, *qdd.T)
    assert M.dtype == np.float32 and tau.dtype == np.float32
    for k, (qk, qdk, qddk) in enumerate(states):
        assert relative_error(M[k], case.reference.M(qk)) <= F32_BOUND
        assert relative_error(tau[k, :, 0], case.reference.tau(qk, qdk, qddk)) <= F32_BOUND


def test_float32_needs_large_angles_wrapped_first(cases):
    """At 1e3 rad, casting the angle to float32 moves it by up to 3e-5 rad, and τ by as much;
    wrapping it into [−π, π) in float64 first keeps float32 accuracy."""
    case = cases("arm")
    d = case.dynamics
    tau32 = compile_batch(d.program, d.q + d.qd + d.qdd, ["tau"], np.float32)
    rng = np.random.default_rng(10)
    q = 1e3 + rng.uniform(0, 1, case.n)
    qd, qdd = rng.normal(size=case.n), rng.normal(size=case.n)
    reference = case.reference.tau(q, qd, qdd)

    def f32(x):
        return np.asarray(x, dtype=np.float32)[None, :]

    (raw,) = tau32(*f32(q).T, *f32(qd).T, *f32(qdd).T)
    wrapped_q = np.remainder(q + np.pi, 2 * np.pi) - np.pi
    (wrapped,) = tau32(*f32(wrapped_q).T, *f32(qd).T, *f32(qdd).T)
    assert relative_error(raw[0, :, 0], reference) > 10 * F32_BOUND / 1000
    assert relative_error(wrapped[0, :, 0], reference) <= F32_BOUND


# ----------------------------------------------------------------------------------------------
# Which form keeps the digits (docs/numerics.md)
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("d_over_l", [1000, 10**6])
def test_far_from_the_root_origin_the_program_keeps_its_digits(d_over_l):
    """A 2-link arm (links 1 m) whose first joint is d = 1 km (and 1000 km) from the root
    origin. The composite-body program refers inertias to the first joint's origin, so no term
    of size m d² appears: M, g and C q̇ from the program are within 1e-14 of the 40-digit
    reference (referred to the root origin, M lost (d/ℓ)² eps ≈ 1e-10 at 1 km), like the
    Newton–Euler τ."""
    model = chain("far", [1, 1], [1, 1], base=(d_over_l, 0, 0))
    dyn = derive(model, outputs=("M", "C", "g", "tau"), simplify=False)
    reference = Reference(model, dynamics=dyn)
    evaluate = compile_batch(dyn.program, dyn.q + dyn.qd + dyn.qdd, ["M", "C", "g", "tau"])
    for q, qd, qdd in random_states(12, 2, 5):
        M, C, g, tau = (x[0] for x in evaluate(*q[:, None], *qd[:, None], *qdd[:, None]))
        zero = np.zeros_like(q)
        g_ref = reference.tau(q, zero, zero)
        assert relative_error(M, reference.M(q)) <= 1e-14
        assert relative_error(g[:, 0], g_ref) <= 1e-14
        assert relative_error(C @ qd, reference.tau(q, qd, zero) - g_ref) <= 1e-14
        assert relative_error(tau[:, 0], reference.tau(q, qd, qdd)) <= EVAL_BOUND


def test_a_long_link_before_a_short_one_keeps_the_digits_of_its_small_entries():
    """Link 1 of 1 km, then a 0.1 m link. Referred to the first joint's origin (the world-frame
    composite M), the short link's own entry M_22 (≈ m ℓ²/3) came from terms of size m d² and
    was right to about (d/ℓ)² eps only, 1e4 eps measured. ``derive`` now builds this M by the
    body-frame CRBA (the cheaper program here), which refers each composite to its own joint's
    origin: M_22 keeps its digits componentwise too."""
    d, l = 1000, sp.Rational(1, 10)
    model = chain("long_short", [1, 1], [d, l])
    dyn = derive(model, outputs=("M",), simplify=False)
    reference = Reference(model, dynamics=dyn)
    M_program = compile_batch(dyn.program, dyn.q, ["M"])
    for q, _, _ in random_states(3, 2, 5):
        M_ref = reference.M(q)
        M = M_program(*q[:, None])[0][0]
        assert relative_error(M, M_ref) <= EVAL_BOUND
        assert abs(M[1, 1] - M_ref[1, 1]) / abs(M_ref[1, 1]) <= 10 * EPS
