"""CasADi sees eomgen's derivatives with no glue (issue 42): where the derivative outputs are
generated, the CasADi module's ``forward_dynamics`` and ``inverse_dynamics`` take their Jacobian
in MX graphs (``casadi.Opti``) from ``forward_dynamics_derivatives`` and
``inverse_dynamics_derivatives`` (``custom_jacobian``), and the C backend's library exports it as
``jac_<name>``, which ``casadi.external`` finds.

References: CasADi's own AD of the same SX function (the module's ``forward_dynamics`` called on
SX symbols is inlined, so ``casadi.jacobian`` differentiates its graph), and the generated
derivative functions called directly; an Opti problem solved with the SX function.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.codegen.backends.casadi_backend import library_name
from eomgen.codegen.functions import module_name, select_functions
from eomgen.codegen.generate import render_files
from eomgen.common.compiler import c_compiler
from support.extras import need

ca = need("casadi", reason="the CasADi backend")

FUNCTIONS = ["M", "C", "g", "tau", "forward_dynamics", "forward_dynamics_derivatives",
             "inverse_dynamics_derivatives"]


def write(model, functions, folder, backends):
    for f in render_files(model, backends, functions=select_functions(functions)):
        path = folder / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")


def namespace(folder, stem):
    from eomgen.codegen.backends.casadi_backend import load_casadi
    return load_casadi(folder, stem).namespace


@pytest.fixture(scope="module")
def planar(tmp_path_factory):
    """The planar 2-link arm (every parameter symbolic): its CasADi module and, with a C
    compiler, its library loaded by ``casadi.external``."""
    model = eomgen.load(eomgen.example_path("planar_2link"))
    folder = tmp_path_factory.mktemp("planar")
    backends = ["casadi"] + (["c"] if c_compiler() else [])
    write(model, FUNCTIONS, folder, backends)
    stem = module_name(model.name)
    module = namespace(folder, stem)
    externals = {}
    if "c" in backends:
        library = str(folder / library_name(stem))
        externals = {name: ca.external(name, library)
                     for name in ("forward_dynamics", "inverse_dynamics")}
    return model, module, externals


def sx_function(f):
    """``f`` rebuilt on its own SX graph, without the custom Jacobian: CasADi's AD."""
    inputs = [ca.SX.sym(f.name_in(i), f.sparsity_in(i)) for i in range(f.n_in())]
    return ca.Function(f.name() + "_ad", inputs, [f(*inputs)],
                       {"allow_duplicate_io_names": True})


def mx_jacobian(f, ninputs):
    """``casadi.jacobian`` of ``f``'s output in an MX graph (what Opti differentiates) by its
    inputs stacked: a function of those inputs."""
    inputs = [ca.MX.sym(f.name_in(i), f.sparsity_in(i)) for i in range(ninputs)]
    stacked = ca.vertcat(*inputs)
    return ca.Function("J", inputs, [ca.jacobian(f(*inputs), stacked)])


def test_a_module_with_the_derivatives_takes_its_jacobian_from_them(planar):
    model, module, _ = planar
    assert [name for name, _ in jacobians_of(module)] == ["forward_dynamics", "inverse_dynamics"]
    fd = module["forward_dynamics"]
    assert fd.jacobian().name() == "jac_forward_dynamics"
    assert fd.jacobian().name_out()[:3] == ["jac_qdd_q", "jac_qdd_qd", "jac_qdd_tau"]


def jacobians_of(module):
    return list(module["_JACOBIANS"].items())


def parameter_values(module):
    return [float(v) for v in module["PARAMETERS"].values()]


@pytest.mark.parametrize("name, derivatives", [
    ("forward_dynamics", ("forward_dynamics_derivatives",)),
    ("inverse_dynamics", ("inverse_dynamics_derivatives", "mass_matrix"))])
def test_the_jacobian_casadi_sees_is_its_ad_and_eomgens(planar, name, derivatives):
    model, module, externals = planar
    f = module[name]
    reference = sx_function(f)
    seen = {"module": f, **({"external": externals[name]} if externals else {})}
    p = parameter_values(module)
    rng = np.random.default_rng(7)
    n = model.dof
    symbols = [ca.MX.sym(f.name_in(i), f.sparsity_in(i)) for i in range(f.n_in())]
    for _ in range(3):
        x = [rng.uniform(-2, 2, n) for _ in range(3)]
        args = x + p
        expected = mx_jacobian(reference, f.n_in())(*args).full()
        # eomgen's generated derivatives for the vector inputs, called directly
        blocks = []
        for d in derivatives:
            g = module[d]
            out = g.call({k: v for k, v in zip(f.name_in(), args) if k in g.name_in()})
            blocks += [np.array(out[k]) for k in g.name_out()]
        eomgen_blocks = np.hstack(blocks)
        for label, function in seen.items():
            # the MX Jacobian calls jac_<name> (not CasADi's AD of the graph)
            assert f"jac_{name}" in str(ca.jacobian(function(*symbols), symbols[0])), label
            got = mx_jacobian(function, f.n_in())(*args).full()
            scale = np.abs(expected).max()
            np.testing.assert_allclose(got / scale, expected / scale, rtol=0, atol=1e-12,
                                       err_msg=f"{label} {name}")
            np.testing.assert_allclose(got[:, :3 * n], eomgen_blocks, rtol=1e-12,
                                       atol=1e-12 * scale, err_msg=f"{label} {name}")


def reach(f, parameters, n, steps=5, horizon=1.0, limit=40.0, hessian="limited-memory"):
    """A reach from rest at 0 to rest at 0.5 rad per joint in ``horizon`` s, torques within
    ``limit``, minimising their squares: multiple shooting, RK4, IPOPT. Returns the solution's
    (objective, torques, iterations)."""
    opti = ca.Opti()
    X = opti.variable(2 * n, steps + 1)
    U = opti.variable(n, steps)
    dt = horizon / steps

    def xdot(x, u):
        return ca.vertcat(x[n:], f(x[:n], x[n:], u, *parameters))

    for k in range(steps):
        x, u = X[:, k], U[:, k]
        k1 = xdot(x, u)
        k2 = xdot(x + dt / 2 * k1, u)
        k3 = xdot(x + dt / 2 * k2, u)
        k4 = xdot(x + dt * k3, u)
        opti.subject_to(X[:, k + 1] == x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4))
    opti.subject_to(X[:, 0] == 0)
    opti.subject_to(X[:, steps] == ca.vertcat(0.5 * ca.DM.ones(n), ca.DM.zeros(n)))
    opti.subject_to(opti.bounded(-limit, ca.vec(U), limit))
    opti.minimize(dt * ca.sumsqr(U))
    opti.solver("ipopt", {"print_time": False},
                {"print_level": 0, "sb": "yes", "tol": 1e-10, "hessian_approximation": hessian})
    solution = opti.solve()
    return (float(solution.value(opti.f)), np.array(solution.value(U)),
            int(solution.stats()["iter_count"]))


def test_an_opti_problem_solves_with_eomgens_jacobian_to_the_same_optimum(planar):
    model, module, externals = planar
    p = parameter_values(module)
    f = module["forward_dynamics"]
    objective, torques, _ = reach(sx_function(f), p, model.dof)
    for label, function in {"module": f, **({"external": externals["forward_dynamics"]}
                                             if externals else {})}.items():
        got, got_torques, _ = reach(function, p, model.dof)
        assert abs(got - objective) <= 1e-6 * max(1.0, abs(objective)), label
        np.testing.assert_allclose(got_torques, torques, rtol=0, atol=1e-6, err_msg=label)
