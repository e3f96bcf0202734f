"""Derivatives of the dynamics as generated outputs (issue 25): ``inverse_dynamics_derivatives``,
``forward_dynamics_derivatives``, ``gravity_derivative`` and ``linearize`` in every code backend.

References, each independent of the forward-mode program: Pinocchio's
``computeRNEADerivatives``, ``computeABADerivatives`` and
``computeGeneralizedGravityDerivatives`` (PUMA 560, UR5; the Panda when slow tests run); central
differences of the generated τ, q̈ and g (NumPy) at default and overridden symbolic parameters;
``jax.jacfwd`` of the generated JAX τ and q̈; and the module's backends against each other.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.codegen import make_job
from eomgen.dynamics import derive
from eomgen.outputs import OUTPUTS
from support import robots
from support.generated import generated
from support.reference import pin_q_order, to_pinocchio
from support.extras import need

FUNCTIONS = ["inverse_dynamics_derivatives", "forward_dynamics_derivatives",
             "gravity_derivative", "linearize"]
#: what the finite-difference and JAX checks differentiate
PLAIN = ["inverse_dynamics", "forward_dynamics", "gravity_vector"]


def results(backend, module, function, *inputs, **parameters) -> tuple:
    """The function's results as a tuple of float arrays (a CasADi function by name)."""
    declared = OUTPUTS[function]
    if backend == "casadi":
        out = module[function].call({**dict(zip(declared.inputs, inputs)), **parameters})
        return tuple(np.array(out[s], dtype=float) for s in (declared.returns or
                                                              (declared.symbol,)))
    out = module[function](*inputs, **parameters)
    return tuple(np.asarray(x, dtype=float) for x in (out if declared.returns else (out,)))


@pytest.fixture(scope="module")
def planar(tmp_path_factory):
    """The planar 2-link arm (every parameter symbolic) in every code backend."""
    model = eomgen.load(eomgen.example_path("planar_2link"))
    calls, modules = generated(model, FUNCTIONS + PLAIN, tmp_path_factory.mktemp("planar"))
    return model, calls, modules


def central_difference(f, x, h=1e-6):
    """The Jacobian of the vector function ``f`` at ``x`` by central differences, column by
    column."""
    columns = []
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h
        columns.append((np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2 * h))
    return np.stack(columns, axis=-1)


def _state(rng, n):
    return tuple(rng.uniform(-1.5, 1.5, n) for _ in range(3))


def test_every_backend_gives_the_numpy_modules_derivatives(planar):
    model, calls, modules = planar
    n, rng = model.dof, np.random.default_rng(4)
    q, qd, u = _state(rng, n)
    inputs = {"inverse_dynamics_derivatives": (q, qd, u), "gravity_derivative": (q,),
              "forward_dynamics_derivatives": (q, qd, u), "linearize": (q, qd, u)}
    shapes = {"inverse_dynamics_derivatives": [(n, n)] * 2, "gravity_derivative": [(n, n)],
              "forward_dynamics_derivatives": [(n, n)] * 3,
              "linearize": [(2 * n, 2 * n), (2 * n, n)]}
    for function, args in inputs.items():
        expected = results("numpy", modules["numpy"], function, *args)
        assert [x.shape for x in expected] == shapes[function]
        for backend, module in modules.items():
            got = results(backend, module, function, *args)
            for a, b in zip(got, expected):
                np.testing.assert_allclose(a.reshape(b.shape), b, rtol=1e-12, atol=1e-12,
                                           err_msg=f"{backend} {function}")
    # a batch: one result per state, as the single calls give (NumPy and the fast module)
    Q, QD, U = (rng.uniform(-1, 1, (3, n)) for _ in range(3))
    for backend in ("numpy", "fast"):
        if backend not in modules:
            continue
        batch = results(backend, modules[backend], "forward_dynamics_derivatives", Q, QD, U)
        for k in range(3):
            single = results("numpy", modules["numpy"], "forward_dynamics_derivatives",
                             Q[k], QD[k], U[k])
            for a, b in zip(batch, single):
                np.testing.assert_allclose(a[k], b, rtol=1e-12, atol=1e-12, err_msg=backend)


@pytest.mark.parametrize("parameters", [{}, {"m1": 2.5, "l1": 0.7}])
def test_derivatives_are_central_differences_of_the_generated_dynamics(planar, parameters):
    model, calls, modules = planar
    np_module = modules["numpy"]
    names = {p.name for p in model.parameters}
    assert set(parameters) <= names, names  # an override that exists, else the test is void
    n, rng = model.dof, np.random.default_rng(7)
    for _ in range(2):
        q, qd, qdd = _state(rng, n)
        tau = np_module["inverse_dynamics"](q, qd, qdd, **parameters)
        dq, dqd = results("numpy", np_module, "inverse_dynamics_derivatives", q, qd, qdd,
                          **parameters)
        fd_q = central_difference(lambda x: np_module["inverse_dynamics"](x, qd, qdd,
                                                                         **parameters), q)
        fd_qd = central_difference(lambda x: np_module["inverse_dynamics"](q, x, qdd,
                                                                          **parameters), qd)
        np.testing.assert_allclose(dq, fd_q, rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(dqd, fd_qd, rtol=1e-6, atol=1e-6)
        (dg,) = results("numpy", np_module, "gravity_derivative", q, **parameters)
        np.testing.assert_allclose(dg, central_difference(
            lambda x: np_module["gravity_vector"](x, **parameters), q), rtol=1e-6, atol=1e-6)
        a_q, a_qd, Minv = results("numpy", np_module, "forward_dynamics_derivatives", q, qd,
                                  tau, **parameters)
        fd = np_module["forward_dynamics"]
        np.testing.assert_allclose(a_q, central_difference(lambda x: fd(x, qd, tau,
                                                                        **parameters), q),
                                   rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(a_qd, central_difference(lambda x: fd(q, x, tau,
                                                                         **parameters), qd),
                                   rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(Minv, central_difference(lambda x: fd(q, qd, x,
                                                                         **parameters), tau),
                                   rtol=1e-6, atol=1e-6)
        A, B = results("numpy", np_module, "linearize", q, qd, tau, **parameters)

        def f(x, u):
            return np.concatenate([x[n:], fd(x[:n], x[n:], u, **parameters)])

        x = np.concatenate([q, qd])
        np.testing.assert_allclose(A, central_difference(lambda y: f(y, tau), x), rtol=1e-6,
                                   atol=1e-6)
        np.testing.assert_allclose(B, central_difference(lambda u: f(x, u), tau), rtol=1e-6,
                                   atol=1e-6)


def test_derivatives_are_jax_jacfwd_of_the_generated_jax_dynamics(planar):
    jax = need("jax")
    jax.config.update("jax_enable_x64", True)
    model, calls, modules = planar
    if "jax" not in modules:
        pytest.skip("JAX backend not loadable")
    jm, n = modules["jax"], model.dof
    rng = np.random.default_rng(11)
    q, qd, qdd = _state(rng, n)
    tau = np.asarray(jm["inverse_dynamics"](q, qd, qdd))
    expected = (jax.jacfwd(jm["inverse_dynamics"], argnums=(0, 1))(q, qd, qdd)
                + jax.jacfwd(jm["forward_dynamics"], argnums=(0, 1, 2))(q, qd, tau))
    got = (results("numpy", modules["numpy"], "inverse_dynamics_derivatives", q, qd, qdd)
           + results("numpy", modules["numpy"], "forward_dynamics_derivatives", q, qd, tau))
    for a, b in zip(got, expected):
        np.testing.assert_allclose(a, np.asarray(b), rtol=1e-10, atol=1e-12)


def _pinocchio_agreement(model, tmp_path, count=3, backends=("numpy",)):
    """The largest relative difference between each derivative and Pinocchio's, over random
    states, for each backend."""
    import pinocchio as pin

    calls, modules = generated(model, FUNCTIONS, tmp_path, backends=backends)
    pm = to_pinocchio(model)
    data, perm = pm.createData(), pin_q_order(model, pm)
    inv = np.argsort(perm)
    n, rng = model.dof, np.random.default_rng(2)
    worst: dict = {}

    def check(backend, what, ours, theirs):
        theirs = theirs[np.ix_(inv, inv)]
        err = np.abs(ours - theirs).max() / max(np.abs(theirs).max(), 1e-300)
        worst[backend, what] = max(worst.get((backend, what), 0.0), err)

    for _ in range(count):
        q, qd, u = _state(rng, n)
        pin.computeRNEADerivatives(pm, data, q[perm], qd[perm], u[perm])
        dtau = data.dtau_dq.copy(), data.dtau_dv.copy()
        pin.computeABADerivatives(pm, data, q[perm], qd[perm], u[perm])
        Minv = np.triu(data.Minv) + np.triu(data.Minv, 1).T
        dqdd = data.ddq_dq.copy(), data.ddq_dv.copy(), Minv
        dg = pin.computeGeneralizedGravityDerivatives(pm, data, q[perm]).copy()
        for backend, module in modules.items():
            for what, a, b in zip(("dtau_dq", "dtau_dqd"), results(
                    backend, module, "inverse_dynamics_derivatives", q, qd, u), dtau):
                check(backend, what, a, b)
            for what, a, b in zip(("dqdd_dq", "dqdd_dqd", "Minv"), results(
                    backend, module, "forward_dynamics_derivatives", q, qd, u), dqdd):
                check(backend, what, a, b)
            check(backend, "dg_dq", *results(backend, module, "gravity_derivative", q), dg)
            A, B = results(backend, module, "linearize", q, qd, u)
            check(backend, "A_q", A[n:, :n], dqdd[0])
            check(backend, "A_qd", A[n:, n:], dqdd[1])
            check(backend, "B", B[n:], Minv)
            assert not A[:n, :n].any() and (A[:n, n:] == np.eye(n)).all() and not B[:n].any()
    return worst


def _bundled(name):
    return lambda: eomgen.load(eomgen.example_path(name))


@pytest.mark.parametrize("make", [_bundled("planar_2link"), _bundled("stanford_rrp"),
                                  robots.puma, robots.ur5],
                         ids=["planar_2link", "stanford_rrp (prismatic)", "puma560", "ur5"])
def test_derivatives_agree_with_pinocchio(make, tmp_path):
    need("pinocchio")
    worst = _pinocchio_agreement(make(), tmp_path)
    assert len(worst) == 9 and max(worst.values()) <= 1e-10, worst


@pytest.mark.slow
def test_panda_derivatives_agree_with_pinocchio_in_numpy_and_the_fast_module(tmp_path,
                                                                              monkeypatch):
    """The kernels compiled once, without their fused multiply-add clones and lanes kernels
    (half the compile; the clones are the same code, checked against NumPy below on the planar
    arm)."""
    from eomgen.codegen.backends import fast_backend

    need("pinocchio")
    monkeypatch.setattr(fast_backend, "FMA_CLONE_OPERATIONS", float("inf"))
    monkeypatch.setattr(fast_backend, "LANES_OPERATIONS", float("inf"))  # no lanes kernels
    worst = _pinocchio_agreement(robots.panda(), tmp_path, backends=("numpy", "fast"))
    assert len(worst) == 18 and max(worst.values()) <= 1e-10, worst


def test_a_structural_zero_is_not_computed():
    """The PUMA's first joint turns about the vertical: g does not depend on q1, so the first
    column of dg/dq is an exact zero in the generated program (never an expression that
    evaluates to 0), while every joint carrying a load has a nonzero entry somewhere."""
    model = robots.puma()
    (spec,) = make_job(derive(model, ["dg_dq"]), ["gravity_derivative"]).specs
    column = spec.output[:, 0]
    assert all(e == 0 for e in column)
    assert any(e != 0 for e in spec.output[:, 1])


def test_fma_clones_of_the_fast_kernels_give_the_numpy_modules_derivatives(planar, tmp_path,
                                                                          monkeypatch):
    """Every kernel compiled in two versions (with and without fused multiply-add, the loader
    picking one; here forced on for the planar arm's small kernels), and its lanes kernel (a
    batch four states at a time), gives the NumPy module's derivatives, for one state and for
    a batch, with parameters other than the description's."""
    from eomgen.codegen.backends import fast_backend

    model, _, modules = planar
    if "fast" not in modules:
        pytest.skip("no C compiler: the fast module was not built")
    monkeypatch.setattr(fast_backend, "FMA_CLONE_OPERATIONS", 0)
    monkeypatch.setattr(fast_backend, "LANES_OPERATIONS", 0)
    _, cloned = generated(model, FUNCTIONS, tmp_path, backends=("fast",))
    source = (tmp_path / "planar_2link_fast.c").read_text(encoding="utf-8")
    for function in FUNCTIONS:  # the one-state kernel, and the batch's lanes kernel
        assert f"FMA_CLONES static void {function}_one(" in source
        assert f"FMA_CLONES static void {function}_lanes(" in source
    rng = np.random.default_rng(7)
    # 6 states: the batch's first 4 through the lanes kernel, the last 2 one by one
    Q, QD, U = (rng.uniform(-1.5, 1.5, (6, model.dof)) for _ in range(3))
    changed = {"m1": 2.5, "l1": 0.7}  # parameters broadcast to the lanes
    for function in FUNCTIONS:
        args = (Q,) if function == "gravity_derivative" else (Q, QD, U)
        batch = results("fast", cloned["fast"], function, *args, **changed)
        for k in range(len(Q)):
            expected = results("numpy", modules["numpy"], function, *(a[k] for a in args),
                               **changed)
            single = results("fast", cloned["fast"], function, *(a[k] for a in args),
                             **changed)
            for a, s, b in zip(batch, single, expected):
                np.testing.assert_allclose(s, b, rtol=1e-12, atol=1e-12, err_msg=function)
                np.testing.assert_allclose(a[k], b, rtol=1e-12, atol=1e-12, err_msg=function)
