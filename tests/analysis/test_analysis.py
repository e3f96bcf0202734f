"""eomgen.analysis: the high-precision reference, the evaluation routes, ``eomgen bench`` and
``eomgen simulate`` (the hard numerical cases are in test_hard_cases.py)."""

from __future__ import annotations

import csv
import io
import warnings

import mpmath
import numpy as np
import pytest
import sympy as sp
from click.testing import CliRunner

import eomgen
from eomgen.analysis.conditioning import IllConditionedWarning, cholesky_solve
from eomgen.analysis.precision import (Reference, high_precision_model, max_abs, mp_model,
                                       mp_rnea, relative_error)
from eomgen.cli import main
from eomgen.numeric import kinetic_energy, numeric_model, potential_energy, rnea
from support.reference import random_robot
from support.extras import need

need("matplotlib")
need("scipy")

EPS = float(np.finfo(float).eps)


@pytest.fixture(scope="module")
def planar():
    return eomgen.load(eomgen.example_path("planar_2link"))


# ----------------------------------------------------------------------------------------------
# precision
# ----------------------------------------------------------------------------------------------

@pytest.mark.parametrize("seed, tree", [(0, False), (1, True)])
def test_reference_of_a_float_model_cross_checks_to_30_digits(seed, tree):
    """Random robots hold float rotations (rpy), float axes, fixed and prismatic joints, joints
    listed out of tree order: the high-precision model makes them exact, and the derived
    program and the mpmath Newton–Euler then agree to ~1e-35; both are within float64
    rounding of eomgen.numeric.rnea."""
    model = random_robot(np.random.default_rng(seed), 4, tree=tree)
    reference = Reference(model)
    rng = np.random.default_rng(seed + 10)
    states = [(rng.uniform(-3, 3, 4), rng.normal(size=4), rng.normal(size=4)) for _ in range(2)]
    assert reference.cross_check(states) < 1e-25
    nm = numeric_model(model)
    for q, qd, qdd in states:
        assert relative_error(rnea(nm, q, qd, qdd), reference.tau(q, qd, qdd)) < 1e-13


def test_high_precision_model_has_orthogonal_rotations_and_unit_axes():
    model = random_robot(np.random.default_rng(3), 3)
    exact = high_precision_model(model)

    def mp(x):
        return mpmath.mpf(sp.Float(sp.N(x, 70), 70)._mpf_)

    with mpmath.workdps(60):
        for joint in exact.joints:
            R = mpmath.matrix([[mp(x) for x in row] for row in joint.origin.rotation])
            assert mpmath.mnorm(R.T * R - mpmath.eye(3), 1) < mpmath.mpf(10) ** -50
            if joint.type.is_movable:
                assert abs(sum(mp(a) ** 2 for a in joint.axis) - 1) < mpmath.mpf(10) ** -50


def test_exact_models_are_their_own_high_precision_model(planar):
    """Integers, rationals and parameters at float values: nothing to orthogonalise; the
    planar arm's reference reuses the given dynamics when the model is exact."""
    numbers = planar.with_numeric_parameters()
    assert high_precision_model(numbers).joints == numbers.joints
    mm = mp_model(high_precision_model(planar))
    with mpmath.workdps(40):
        tau = mp_rnea(mm, [0.3, -0.2], [1.0, 0.5], [0.1, 0.2])
    reference = Reference(planar)
    assert max_abs(tau - reference.tau([0.3, -0.2], [1.0, 0.5], [0.1, 0.2])) < 1e-35


def test_relative_error_is_exact_at_the_last_bit():
    """A correctly rounded value has error ≤ 2⁻⁵³; the difference is taken in mpmath."""
    with mpmath.workdps(40):
        third = np.array([mpmath.mpf(1) / 3], dtype=object)
    error = relative_error(np.array([1 / 3]), third)
    assert 0 < error <= 2.0**-53


# ----------------------------------------------------------------------------------------------
# routes and Pinocchio
# ----------------------------------------------------------------------------------------------

def test_every_route_agrees_with_the_reference(planar, tmp_path):
    from eomgen.analysis.routes import build_routes

    routes = build_routes(planar, tmp_path)
    names = {r.name for r in routes}
    assert {"NumPy, one state", "NumPy, batch", "NumPy float32, batch",
            "Python floats, one state", "CasADi SX, one state", "CasADi SX, map",
            "RNEA (eomgen.numeric)"} <= names
    from eomgen.codegen.backends.casadi_backend import c_compiler
    from eomgen.codegen.backends.fast_backend import python_headers

    if c_compiler() and python_headers():
        assert {"C extension (fast), one state", "C extension (fast), batch"} <= names
    reference = Reference(planar)
    rng = np.random.default_rng(0)
    q, qd, qdd = (rng.normal(size=(3, 2)) for _ in range(3))
    for route in routes:
        bound = 1e3 * (np.finfo(np.float32).eps if route.dtype == "float32" else EPS)
        tau, M = route.tau(q, qd, qdd), route.M(q)
        assert tau.shape == (3, 2) and M.shape == (3, 2, 2), route.name
        for k in range(3):
            assert relative_error(tau[k], reference.tau(q[k], qd[k], qdd[k])) < bound, route.name
            assert relative_error(M[k], reference.M(q[k])) < bound, route.name


def test_pinocchio_bridge_matches_rnea_on_a_random_tree():
    need("pinocchio")
    from eomgen.analysis.pinocchio_bridge import to_pinocchio

    model = random_robot(np.random.default_rng(4), 5, tree=True)
    pm, nm = to_pinocchio(model), numeric_model(model)
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, qd, qdd = rng.normal(size=5), rng.normal(size=5), rng.normal(size=5)
        np.testing.assert_allclose(pm.rnea(q, qd, qdd), rnea(nm, q, qd, qdd), atol=1e-10)
        M = pm.crba(q)
        zero = np.zeros(5)
        columns = np.column_stack([rnea(nm, q, zero, e) - rnea(nm, q, zero, zero)
                                   for e in np.eye(5)])
        np.testing.assert_allclose(M, columns, atol=1e-10)


# ----------------------------------------------------------------------------------------------
# bench
# ----------------------------------------------------------------------------------------------

def test_bench_measures_every_route_and_writes_tables_and_plot(planar, tmp_path):
    from eomgen.analysis.bench import prepare_bench, write_outputs

    plan = prepare_bench(planar, samples=3, repeats=3, batch_size=20, timing_states=2)
    ticks = []

    class Counter:
        def update(self, n):
            ticks.append(n)

    result = plan.run(Counter())
    assert sum(ticks) == plan.steps
    assert result.cross_check < 1e-25
    for quantity in ("tau", "M"):
        rows = result.rows(quantity)
        assert len(rows) == len(plan.routes)
        assert any(m.pareto for m in rows)
        fastest = min(rows, key=lambda m: m.time_median)
        assert fastest.pareto  # nothing is faster, so nothing beats it
        for m in rows:
            assert m.time_q1 <= m.time_median <= m.time_q3
            assert m.error_max < (1e-4 if m.dtype == "float32" else 1e-13)
    paths = write_outputs(result, tmp_path, "planar_2link")
    assert [p.name for p in paths] == ["bench_planar_2link.md", "bench_planar_2link.csv",
                                       "bench_planar_2link.png"]
    rows = list(csv.DictReader(io.StringIO(paths[1].read_text())))
    assert len(rows) == 2 * len(plan.routes)
    assert paths[2].read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "★" in paths[0].read_text()


# ----------------------------------------------------------------------------------------------
# simulate
# ----------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def pendulum_system(planar):
    from eomgen.analysis.simulate import System

    return System(planar)


def test_momentum_rate_is_the_derivative_of_M_qd(pendulum_system):
    """ṗ = Cᵀ q̇ − g (zero torque) equals d/dt (M q̇) along the motion: the canonical form the
    implicit midpoint rule integrates."""
    system = pendulum_system
    q, qd = np.array([0.4, 1.1]), np.array([0.7, -0.3])
    qdd = system.forward_dynamics(q, qd)
    h = 1e-6

    def momentum(t):
        qt, qdt = q + t * qd + t * t / 2 * qdd, qd + t * qdd
        return system.M(qt) @ qdt

    numeric = (momentum(h) - momentum(-h)) / (2 * h)
    _, pdot = system.velocity_and_momentum_rate(q, system.M(q) @ qd)
    np.testing.assert_allclose(pdot, numeric, rtol=1e-7, atol=1e-7)


def test_integrators_converge_and_symplectic_ones_keep_energy(planar, pendulum_system):
    from eomgen.analysis.simulate import (RK4, Adaptive, ExplicitEuler, ImplicitMidpoint,
                                          SemiImplicitEuler, run_study)

    integrators = [ExplicitEuler(1e-2), SemiImplicitEuler(1e-2), RK4(1e-2), RK4(5e-3),
                   ImplicitMidpoint(1e-2), Adaptive("RK45", 1e-8)]
    study = run_study(planar, integrators, 1.0, q0=[0.5, 1.0], system=pendulum_system)
    runs = {(r.integrator, r.setting): r for r in study.runs}
    assert all(r.status == "ok" for r in study.runs)
    rk4, rk4_half = runs[("RK4", "dt = 0.01 s")], runs[("RK4", "dt = 0.005 s")]
    assert rk4.trajectory_error < 1e-4
    assert rk4_half.trajectory_error < rk4.trajectory_error / 8  # fourth order: 16×
    euler = runs[("explicit Euler", "dt = 0.01 s")]
    midpoint = runs[("implicit midpoint", "dt = 0.01 s")]
    assert midpoint.relative_energy_drift < euler.relative_energy_drift / 10
    assert runs[("RK45 (adaptive)", "rtol = 1e-08")].trajectory_error < 1e-6
    assert rk4.evaluations == 4 * 100
    assert "| RK4 | dt = 0.01 s |" in study.markdown_table()


def test_diverging_runs_are_reported_not_raised(planar, pendulum_system):
    from eomgen.analysis.simulate import ExplicitEuler, ImplicitMidpoint, run_study

    study = run_study(planar, [ImplicitMidpoint(0.5), ExplicitEuler(0.5)], 5.0,
                      q0=[2.0, 2.5], qd0=[30.0, -40.0], system=pendulum_system)
    for run in study.runs:
        assert run.status.startswith("diverged"), run
        assert run.trajectory_error == np.inf and run.energy_drift == np.inf


def test_integrators_by_name():
    from eomgen.analysis.simulate import Adaptive, RK4, integrators_named

    chosen = integrators_named(["rk4", "dop853"], [1e-2, 1e-3], [1e-6])
    assert chosen == [RK4(1e-2), RK4(1e-3), Adaptive("DOP853", 1e-6)]
    assert len(integrators_named(["all"], [1e-2], [1e-6])) == 6
    with pytest.raises(ValueError, match="unknown integrator rk5"):
        integrators_named(["rk5"], [1e-2], [1e-6])


def test_energy_is_the_numeric_one(planar, pendulum_system):
    nm = numeric_model(planar.with_numeric_parameters())
    q, qd = np.array([0.2, 0.3]), np.array([1.0, 2.0])
    K, P = pendulum_system.energy(q, qd)
    assert K == kinetic_energy(nm, q, qd) and P == potential_energy(nm, q)
    assert K == pytest.approx(0.5 * qd @ pendulum_system.M(q) @ qd, rel=1e-12)


# ----------------------------------------------------------------------------------------------
# conditioning
# ----------------------------------------------------------------------------------------------

def test_cholesky_solve_single_batch_warning_and_errors():
    M = np.array([[2.0, 1.0], [1.0, 2.0]])
    x, condition = cholesky_solve(M, np.array([3.0, 3.0]))
    np.testing.assert_allclose(x, [1.0, 1.0])
    assert 1 <= condition <= 3.0 + 1e-12
    xs, conditions = cholesky_solve(np.stack([M, 2 * M]), np.ones((2, 2)))
    assert xs.shape == (2, 2) and conditions.shape == (2,)
    bad = np.diag([1.0, 1e-12])
    with pytest.warns(IllConditionedWarning, match="cond"):
        cholesky_solve(bad, np.ones(2))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        cholesky_solve(bad, np.ones(2), warn=False)
    with pytest.raises(np.linalg.LinAlgError, match="at state 1"):
        cholesky_solve(np.stack([M, -M]), np.ones((2, 2)))
    with pytest.raises(FloatingPointError):
        cholesky_solve(M, np.array([np.inf, 0.0]))


# ----------------------------------------------------------------------------------------------
# CLI
# ----------------------------------------------------------------------------------------------

def test_cli_simulate_writes_table_csv_and_plot(tmp_path):
    out = tmp_path / "sim"
    result = CliRunner().invoke(main, ["simulate", "--duration", "0.2", "--dt", "1e-3",
                                       "--rtol", "1e-5", "--integrators", "rk4,dop853",
                                       "--q0", "1,2", "--quiet", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "| RK4 | dt = 0.001 s |" in result.output
    names = sorted(p.name for p in out.iterdir())
    assert names == ["simulate_planar_2link.csv", "simulate_planar_2link.md",
                     "simulate_planar_2link.png"]


@pytest.mark.parametrize("args, message", [
    (["--dt", "fast"], "--dt: expected comma-separated numbers"),
    (["--integrators", "leapfrog"], "unknown integrator leapfrog"),
    (["--q0", "1,2,3"], "takes 2 values (joint1, joint2), got 3"),
    (["--dt", "-1"], "must be positive"),
])
def test_cli_simulate_refuses_bad_options_in_one_line(args, message, tmp_path):
    result = CliRunner().invoke(main, ["simulate", "--quiet", "-o", str(tmp_path)] + args)
    assert result.exit_code == 2
    assert message in result.output and result.output.count("\n") == 1


def test_cli_bench_runs(tmp_path):
    result = CliRunner().invoke(main, ["bench", "--samples", "2", "--repeats", "2",
                                       "--batch-size", "10", "--quiet", "-o", str(tmp_path)])
    assert result.exit_code == 0, result.output
    assert "## inverse dynamics" in result.output and "NumPy, batch" in result.output
    assert (tmp_path / "bench_planar_2link.png").is_file()


def test_generated_numpy_modules_include_the_one_cholesky_runtime(tmp_path):
    """One copy of the forward-dynamics solve: a generated NumPy module holds the text of
    eomgen.runtime.cholesky verbatim, and its solve and eomgen's give the same q̈ and condition
    number and both warn on the same ill-conditioned M (built with a known condition number)."""
    from eomgen.codegen.functions import select_functions
    from eomgen.codegen.generate import render_files
    from eomgen.runtime.cholesky import included_source

    arm = eomgen.load(eomgen.example_path("planar_2link"))
    (numpy_file,) = render_files(arm, ["numpy"], functions=select_functions(None))
    text = numpy_file.content
    assert included_source() in text and "import eomgen" not in text
    namespace: dict = {}
    exec(compile(text, "planar_2link_numpy.py", "exec"), namespace)  # noqa: S102
    rng = np.random.default_rng(0)
    Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    for cond in (1e3, 1e11):
        M = Q @ np.diag([1.0, 0.5, 1.0 / cond]) @ Q.T
        b = rng.normal(size=3)
        with warnings.catch_warnings(record=True) as ours:
            warnings.simplefilter("always")
            x, c = cholesky_solve(M, b)
        with warnings.catch_warnings(record=True) as theirs:
            warnings.simplefilter("always")
            x_gen, c_gen = namespace["_cholesky_solve"](M, b)
        assert np.array_equal(x, x_gen) and c == c_gen
        np.testing.assert_allclose(M @ x, b, rtol=0, atol=1e-15 * cond)
        assert (len(ours) == 1) == (len(theirs) == 1) == (cond > 1e10)
