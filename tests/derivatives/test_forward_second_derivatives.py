"""Second derivatives of the forward dynamics (issue 42), composed from those of the inverse
dynamics: ``forward_dynamics_second_derivatives`` (the tensor over x = (q, qd, tau)) and
``forward_dynamics_hessian`` (the Hessian of lam^T qdd) in the NumPy and CasADi modules, and
the CasADi ``forward_dynamics`` whose Jacobian's Jacobian (``jac_jac_forward_dynamics``, also
in the C library) is them, for IPOPT's exact Hessian in ``casadi.Opti``.

References, independent of the composition: the planar arm's q̈ = M⁻¹(τ − C q̇ − g) in SymPy
differentiated twice and evaluated at a rational state to 30 digits; central differences of the
generated first derivatives ∂q̈/∂x (NumPy, the SCARA with a prismatic joint); CasADi's own AD of
the SX forward dynamics (a Cholesky solve, differentiated twice), through which an MX Hessian
of a scalar function of q̈ is compared with the one built on eomgen's second derivatives.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
import sympy as sp

import eomgen
from eomgen.codegen.backends.casadi_backend import library_name
from eomgen.codegen.functions import module_name, select_functions
from eomgen.codegen.generate import render_files
from eomgen.common.compiler import c_compiler
from eomgen.errors import UnsupportedError
from support import robots
from support.extras import need
from support.generated import generated

SECOND, HESSIAN = "forward_dynamics_second_derivatives", "forward_dynamics_hessian"


def relative(a, b) -> float:
    return float(np.abs(a - b).max() / max(np.abs(b).max(), 1e-300))


@pytest.fixture(scope="module")
def scara(tmp_path_factory):
    """The SCARA (revolute, revolute, prismatic): its NumPy module."""
    model = eomgen.load(eomgen.example_path("scara_rrp"))
    _, modules = generated(model, [SECOND, HESSIAN], tmp_path_factory.mktemp("scara"),
                           backends=("numpy",))
    return model, modules["numpy"]


@pytest.fixture(scope="module")
def planar(tmp_path_factory):
    """The planar 2-link arm (every parameter symbolic): its NumPy and CasADi modules and,
    with a C compiler, the C library loaded by ``casadi.external``."""
    need("casadi", reason="the CasADi backend")
    model = eomgen.load(eomgen.example_path("planar_2link"))
    folder = tmp_path_factory.mktemp("planar")
    _, modules = generated(model, [SECOND, HESSIAN], folder, backends=("numpy", "casadi"))
    library = None
    if c_compiler():
        for f in render_files(model, ["c"], functions=select_functions([SECOND, HESSIAN])):
            path = folder / f.name
            path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
                f.content, encoding="utf-8")
        library = str(folder / library_name(module_name(model.name)))
    return model, modules, library


def state(seed, n):
    rng = np.random.default_rng(seed)
    return tuple(rng.uniform(-1.2, 1.2, n) for _ in range(4))


def test_the_tensor_is_central_differences_of_the_generated_first_derivatives(scara):
    model, m = scara
    n = model.dof
    for seed in (1, 2):
        q, qd, tau, lam = state(seed, n)
        T = m[SECOND](q, qd, tau)
        assert T.shape == (n, 9 * n * n)
        T = T.reshape(n, 3 * n, 3 * n)
        x, h = np.concatenate([q, qd, tau]), 1e-5

        def first(x):
            return np.hstack(m["forward_dynamics_derivatives"](x[:n], x[n:2 * n], x[2 * n:]))

        difference = np.stack([(first(x + h * e) - first(x - h * e)) / (2 * h)
                               for e in np.eye(3 * n)], axis=-1)
        assert relative(T, difference) < 1e-6
        np.testing.assert_allclose(T, T.transpose(0, 2, 1), rtol=0, atol=1e-12)
        # no second derivative along tau twice: qdd is affine in tau
        assert np.abs(T[:, 2 * n:, 2 * n:]).max() == 0
        H = m[HESSIAN](q, qd, tau, lam)
        np.testing.assert_allclose(H, np.einsum("i,ijk->jk", lam, T), rtol=0,
                                   atol=1e-12 * np.abs(T).max())
    # a batch gives each state's
    states = [state(seed, n) for seed in (3, 4)]
    q, qd, tau, lam = (np.stack(s) for s in zip(*states))
    for k, (q1, qd1, tau1, lam1) in enumerate(states):
        np.testing.assert_allclose(m[SECOND](q, qd, tau)[k], m[SECOND](q1, qd1, tau1),
                                   rtol=1e-14, atol=1e-14)
        np.testing.assert_allclose(m[HESSIAN](q, qd, tau, lam)[k],
                                   m[HESSIAN](q1, qd1, tau1, lam1), rtol=1e-14, atol=1e-14)


@pytest.mark.slow  # SymPy's second derivatives of M^-1 (tau - C qd - g): about 5 s
def test_the_planar_arm_against_sympy_to_30_digits(planar):
    model, modules, _ = planar
    dyn = eomgen.derive(model, outputs=["M", "C", "g"])
    q, qd, tau = (list(dyn.input_symbols[k]) for k in ("q", "qd", "tau"))
    values = {p.symbol: p.value for p in dyn.parameters}
    M = dyn.M.subs(values)
    a = M.LUsolve(sp.Matrix(tau) - (dyn.C * sp.Matrix(qd) + dyn.g).subs(values))
    x = q + qd + tau
    point = [sp.Rational(3, 10), sp.Rational(-1, 2), sp.Rational(7, 10), sp.Rational(1, 5), 2, -3]
    at = dict(zip(x, point))
    n, m = model.dof, len(x)
    expected = np.zeros((n, m, m))
    for i in range(n):
        for j in range(m):
            first = sp.diff(a[i], x[j])
            for k in range(j, m):
                expected[i, j, k] = expected[i, k, j] = float(
                    sp.diff(first, x[k]).evalf(30, subs=at))
    values = np.array([float(v) for v in point])
    state_ = (values[:n], values[n:2 * n], values[2 * n:])
    got = modules["numpy"][SECOND](*state_).reshape(n, m, m)
    assert relative(got, expected) < 1e-13
    named = dict(zip(("q", "qd", "tau"), state_))
    casadi = np.array(modules["casadi"][SECOND].call(named)["d2qdd"]).reshape(n, m, m)
    assert relative(casadi, expected) < 1e-13


def sx_reference(ca, f):
    """``f`` rebuilt on its own SX graph: CasADi's AD of the Cholesky solve."""
    inputs = [ca.SX.sym(f.name_in(i), f.sparsity_in(i)) for i in range(f.n_in())]
    return ca.Function(f.name() + "_ad", inputs, [f(*inputs)],
                       {"allow_duplicate_io_names": True})


def test_casadi_hessians_are_eomgens_and_equal_casadis_ad(planar):
    import casadi as ca

    model, modules, library = planar
    module = modules["casadi"]
    n = model.dof
    fd = module["forward_dynamics"]
    assert fd.jacobian().jacobian().name() == "jac_jac_forward_dynamics"
    parameters = [fd.default_in(i) for i in range(3, fd.n_in())]
    reference = sx_reference(ca, fd)
    X, L = ca.MX.sym("x", 3 * n), ca.MX.sym("lam", n)
    Xs, Ls = ca.SX.sym("x", 3 * n), ca.SX.sym("lam", n)

    def hessian(f, X, L):
        qdd = f(X[:n], X[n:2 * n], X[2 * n:], *parameters)
        # a scalar function of qdd as a Lagrangian has it: lam^T qdd + |qdd|^2
        H = ca.hessian(ca.dot(L, qdd) + ca.sumsqr(qdd), X)[0]
        return H, ca.Function("H", [X, L], [H])

    seen = {"module": fd}
    if library:
        seen["external"] = ca.external("forward_dynamics", library)
    _, expected_f = hessian(reference, Xs, Ls)
    for seed in (5, 6):
        q, qd, tau, lam = state(seed, n)
        x = np.concatenate([q, qd, tau])
        expected = expected_f(x, lam).full()
        for label, f in seen.items():
            H, function = hessian(f, X, L)
            assert "jac_jac_forward_dynamics" in str(H), label
            assert relative(function(x, lam).full(), expected) < 1e-10, label
        # the composed functions of the module against the same AD
        T = np.array(module[SECOND](q, qd, tau, *parameters)).reshape(n, 3 * n, 3 * n)
        qdd = reference(Xs[:n], Xs[n:2 * n], Xs[2 * n:], *parameters)
        ad = np.stack([ca.Function("h", [Xs], [ca.hessian(qdd[i], Xs)[0]])(x).full()
                       for i in range(n)])
        assert relative(T, ad) < 1e-12
        H = np.array(module[HESSIAN](q, qd, tau, *parameters, lam))
        assert relative(H, np.einsum("i,ijk->jk", lam, ad)) < 1e-12
        np.testing.assert_allclose(H, modules["numpy"][HESSIAN](q, qd, tau, lam),
                                   rtol=1e-12, atol=1e-12 * np.abs(H).max())


def test_opti_with_the_exact_hessian_reaches_casadis_optimum(planar):
    """A small reach (RK4, N = 6) with IPOPT's exact Hessian: eomgen's second derivatives and
    CasADi's AD take the same iterations to the same optimum."""
    import casadi as ca

    model, modules, _ = planar
    fd = modules["casadi"]["forward_dynamics"]
    n, steps, dt = model.dof, 6, 1.0 / 6
    results = []
    for f in (fd, sx_reference(ca, fd)):
        opti = ca.Opti()
        X, U = opti.variable(2 * n, steps + 1), opti.variable(n, steps)

        def xdot(x, u):
            return ca.vertcat(x[n:], f(x[:n], x[n:], u,
                                       *[fd.default_in(i) for i in range(3, fd.n_in())]))

        for k in range(steps):
            x, u = X[:, k], U[:, k]
            k1 = xdot(x, u)
            k2 = xdot(x + dt / 2 * k1, u)
            k3 = xdot(x + dt / 2 * k2, u)
            k4 = xdot(x + dt * k3, u)
            opti.subject_to(X[:, k + 1] == x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4))
        opti.subject_to(X[:, 0] == 0)
        opti.subject_to(X[:, steps] == ca.vertcat(0.5, 0.5, 0, 0))
        opti.minimize(dt * ca.sumsqr(U))
        opti.solver("ipopt", {"print_time": False},
                    {"print_level": 0, "sb": "yes", "hessian_approximation": "exact"})
        solution = opti.solve()
        results.append((solution.stats()["iter_count"], solution.value(opti.f)))
    (iterations, optimum), (iterations_ad, optimum_ad) = results
    assert iterations == iterations_ad
    assert abs(optimum - optimum_ad) <= 1e-9 * abs(optimum_ad)


def test_a_quaternion_free_flyer_is_refused_in_one_line():
    from eomgen.reduction import apply_scene
    from eomgen.scene import load_scene

    root = robots.ROOT
    scene = load_scene(root / "examples/contacts/top_on_a_point.yaml")
    model = apply_scene(eomgen.load(root / "examples/robots/spinning_top.yaml"),
                        dataclasses.replace(scene, floating_base="quaternion"))[0]
    with pytest.raises(UnsupportedError) as error:
        render_files(model, ["numpy"], functions=select_functions([HESSIAN]))
    message = str(error.value)
    assert "\n" not in message and "d2tau not derived for a quaternion free flyer" in message
