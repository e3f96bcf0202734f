"""The JAX backend against the NumPy module (tests/support/array_backends.py) and on its own
promises: batch shapes, dtypes, parameter defaults, jax.jit / jax.vmap / jax.grad, forward dynamics,
XLA computing each sine and cosine once, dask over JAX functions. Skips with a reason when jax
is missing (the ``jax`` extra); removing the JAX backend removes this file with it."""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.codegen.generate import generate
from support.array_backends import (
    ARGUMENTS, FUNCTIONS, ROBOTS, assert_relative, central_difference, hostile_modules,
    load_module, robot_modules, states,
)
from support.extras import need

jax = need("jax", reason="the JAX backend")
jax.config.update("jax_enable_x64", True)
jnp = jax.numpy


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    """``robot(name)``: the robot's numpy and jax modules, generated once per module."""
    return robot_modules("jax", tmp_path_factory)


@pytest.mark.parametrize("name", ROBOTS)
def test_jax_agrees_with_numpy(robot, name):
    modules = robot(name)
    n = modules.numpy.NQ
    assert modules.jax.JOINT_NAMES == modules.numpy.JOINT_NAMES and modules.jax.NQ == n
    assert modules.jax.PARAMETERS == modules.numpy.PARAMETERS
    assert set(modules.jax.__all__) | {"IllConditionedWarning"} == set(modules.numpy.__all__)
    batch = states(n)
    for function in FUNCTIONS:
        args = batch[:ARGUMENTS[function]]
        expected = getattr(modules.numpy, function)(*args)
        got = getattr(modules.jax, function)(*args)
        assert got.dtype == jnp.float64
        assert_relative(got, expected, what=f"{name} jax {function}")
        # one state in, one result out, equal to that state's row of the batch
        one = [a[2] for a in args]
        assert_relative(getattr(modules.jax, function)(*one), expected[2], what="jax single")


@pytest.mark.parametrize("name", ["planar_2link",
                                  pytest.param("panda", marks=pytest.mark.slow)])
def test_jax_jit_and_vmap_agree_with_numpy(robot, name):
    modules = robot(name)
    q, qd, qdd = states(modules.numpy.NQ, seed=1)
    functions = FUNCTIONS if name == "planar_2link" else ("inverse_dynamics",)
    for function in functions:
        args = (q, qd, qdd)[:ARGUMENTS[function]]
        expected = getattr(modules.numpy, function)(*args)
        f = getattr(modules.jax, function)
        assert_relative(jax.jit(f)(*args), expected, what=f"jit {function}")
        assert_relative(jax.jit(jax.vmap(f))(*args), expected, what=f"jit vmap {function}")


@pytest.mark.slow
def test_xla_computes_each_sine_and_cosine_once(robot):
    """Compiled for the CPU under jax.jit(jax.vmap(f)), each named sine and cosine is one
    instruction: XLA's fusion counts sin and cos as cheap and copied them into every output loop
    (the Panda's M: 112 sines for 6 joints), which made M three times slower than NumPy; the
    generated ``_kept`` makes XLA compute each once (jax_backend's docstring)."""
    import inspect
    import re

    modules = robot("puma560")
    q, qd, qdd = states(modules.numpy.NQ, seed=3)
    for function in ("mass_matrix", "coriolis_matrix", "inverse_dynamics"):
        f = getattr(modules.jax, function)
        source = inspect.getsource(f)
        args = [jnp.asarray(x) for x in (q, qd, qdd)[:ARGUMENTS[function]]]
        hlo = jax.jit(jax.vmap(f)).lower(*args).compile().as_text()
        for op, name in (("sine", "sin"), ("cosine", "cos")):
            named = source.count(f"_kept(jnp.{name}(")
            assert named > 0, function
            assert len(re.findall(rf"\b{op}\(", hlo)) == named, (function, op)


# --- derivatives: jax.grad against central differences of the NumPy module --------------------

@pytest.mark.parametrize("name", ["planar_2link", "ur5", "panda"])
def test_gradient_of_tau_matches_central_differences(robot, name):
    modules = robot(name)
    q, qd, qdd = (a[0] for a in states(modules.numpy.NQ, seed=2))
    reference = central_difference(
        lambda x: float(np.sum(modules.numpy.inverse_dynamics(x, qd, qdd))), q)
    scale = max(1.0, float(np.max(np.abs(reference))))
    grad = jax.grad(lambda x: jnp.sum(modules.jax.inverse_dynamics(x, qd, qdd)))(q)
    assert np.max(np.abs(np.asarray(grad) - reference)) <= 1e-6 * scale


def test_grad_runs_through_every_output_and_parameter(robot):
    """Gradients of each output's sum w.r.t. q and a mass parameter against central
    differences of the NumPy module (forward dynamics included)."""
    modules = robot("planar_2link")
    q, qd, qdd = (a[1] for a in states(2, seed=3))
    for function in FUNCTIONS:
        args = (q, qd, qdd)[:ARGUMENTS[function]]
        f_np = getattr(modules.numpy, function)
        by_q = central_difference(lambda x: float(np.sum(f_np(x, *args[1:], m2=1.3))), q)
        by_m2 = central_difference(lambda m: float(np.sum(f_np(*args, m2=m[0]))), np.array([1.3]))
        g_q, g_m2 = jax.grad(lambda x, m: jnp.sum(getattr(modules.jax, function)(
            x, *args[1:], m2=m)), argnums=(0, 1))(q, 1.3)
        np.testing.assert_allclose(g_q, by_q, atol=1e-6)
        np.testing.assert_allclose(g_m2, by_m2[0], atol=1e-6)


# --- shapes, dtypes, parameters ---------------------------------------------------------------

def test_parameters_left_out_take_the_descriptions_values(robot):
    modules = robot("planar_2link")
    q, qd, qdd = states(2, seed=4)
    values = dict(modules.numpy.PARAMETERS)
    assert values["g"] == 9.81 and values["m2"] == 1.0
    module = modules.jax
    default = module.inverse_dynamics(q, qd, qdd)
    explicit = module.inverse_dynamics(q, qd, qdd, **values)
    assert_relative(default, np.asarray(explicit), tol=0.0)
    # a left-out parameter is the description's value, not zero: gravity is there
    assert np.max(np.abs(np.asarray(module.gravity_vector(q)))) > 1.0
    assert np.max(np.abs(np.asarray(module.gravity_vector(q, g=0.0)))) == 0.0
    # per-state parameter arrays, as in the NumPy module
    masses = np.linspace(0.5, 2.0, len(q))
    assert_relative(module.gravity_vector(q, m2=masses),
                    modules.numpy.gravity_vector(q, m2=masses))


def test_jax_matrices_take_per_state_parameters_and_keep_float32(robot):
    """M and C are one jnp.stack of their entries (not one scatter per entry): entries that
    are scalars (structural zeros, C_22 of the planar arm) must still fill every state,
    per-state parameter arrays must stay per state, and float32 states stay float32."""
    modules = robot("planar_2link")
    q, qd, _ = states(2, seed=6)
    masses = np.linspace(0.5, 2.0, len(q))
    for function, args in (("mass_matrix", (q,)), ("coriolis_matrix", (q, qd))):
        expected = getattr(modules.numpy, function)(*args, m2=masses)
        f = getattr(modules.jax, function)
        assert_relative(f(*args, m2=masses), expected, what=function)
        assert_relative(jax.jit(jax.vmap(f))(*args, m2=masses), expected, what=function)
        low = f(*(a.astype(np.float32) for a in args), m2=masses)
        assert low.dtype == jnp.float32
        assert_relative(low, expected, tol=1e-5, what=f"{function} float32")
    C = modules.jax.coriolis_matrix(q, qd)
    assert C.shape == (len(q), 2, 2) and np.all(np.asarray(C)[:, 1, 1] == 0.0)
    assert modules.jax.coriolis_matrix(q[0], qd[0]).shape == (2, 2)


def test_bad_shapes_are_value_errors(robot):
    module = robot("planar_2link").jax
    with pytest.raises(ValueError, match=r"q must have shape \(2,\) or \(N, 2\), got \(3,\)"):
        module.mass_matrix(np.zeros(3))
    with pytest.raises(ValueError, match="same number of states, got 4 \\(q\\), 3 \\(qd\\)"):
        module.coriolis_matrix(np.zeros((4, 2)), np.zeros((3, 2)))


# --- forward dynamics: a batched Cholesky, conditioning as the NumPy module reports it ---------

def test_forward_dynamics_inverts_inverse_dynamics_and_reports_the_condition(robot):
    modules = robot("ur5")
    q, qd, qdd = states(modules.numpy.NQ, seed=6)
    tau = modules.numpy.inverse_dynamics(q, qd, qdd)
    _, expected = modules.numpy.forward_dynamics(q, qd, tau, return_condition=True)
    x, condition = modules.jax.forward_dynamics(q, qd, tau, return_condition=True)
    assert_relative(x, qdd, tol=1e-10, what="jax qdd")
    d = np.asarray(condition) / expected  # the same estimate when no state is near the limit
    np.testing.assert_allclose(d, 1.0, rtol=1e-9)


def test_forward_dynamics_of_a_singular_M_is_nan(robot):
    modules = robot("planar_2link")
    q, qd, tau = (a[:3] for a in states(2, seed=7))
    massless = dict(m2=0.0, I2=0.0)  # joint 2 moves nothing: M is singular
    assert np.all(np.isnan(np.asarray(modules.jax.forward_dynamics(q, qd, tau, **massless))))


def test_hostile_names_stay_text_and_the_module_runs():
    """Robot and joint names that try to break out of strings stay text; the module imports
    only jax.numpy and agrees with the NumPy module."""
    from support.robots import HOSTILE

    modules = hostile_modules("jax")
    q, qd, qdd = states(len(HOSTILE), seed=8)
    assert_relative(modules["jax"]["inverse_dynamics"](q, qd, qdd),
                    modules["numpy"]["inverse_dynamics"](q, qd, qdd))


def test_parameters_named_like_the_framework_do_not_shadow_it(tmp_path):
    """Parameters named ``jnp`` and ``jax`` become ``jnp_``, ``jax_`` keywords; the module
    still reaches jax.numpy and the keywords' defaults are the description's."""
    import sympy as sp

    from eomgen.model import Inertial, Joint, JointType, Link, Parameter, Transform, build_model, vec3

    mass, gravity = (sp.Symbol(name, real=True) for name in ("jnp", "jax"))
    body = Inertial(mass, [0.3, 0, 0], [[0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.01]])
    model = build_model("<test>", "shadowing", [Link("base"), Link("l1", body)],
                        [Joint("j1", JointType.REVOLUTE, "base", "l1", Transform(),
                               vec3([0, 0, 1]))],
                        parameters=[Parameter(mass, 1.5), Parameter(gravity, 2.0)],
                        gravity=(0.0, -gravity, 0.0))
    paths = generate(model, tmp_path, "numpy,jax", cache=False)
    numpy_module, jax_module = (load_module(p, f"shadowing_{p.stem}") for p in sorted(
        paths, key=lambda p: not p.name.endswith("_numpy.py")))
    assert list(jax_module.PARAMETERS) == ["jax_", "jnp_"]
    q = np.array([[0.4], [1.1]])
    expected = numpy_module.gravity_vector(q)
    assert np.all(np.abs(expected) > 0)
    assert_relative(jax_module.gravity_vector(q), expected)
    assert_relative(jax_module.gravity_vector(q, jnp_=3.0), numpy_module.gravity_vector(q, jnp_=3.0))


def test_dask_map_takes_dask_inputs_and_jax_functions(robot):
    """eomgen.analysis.batch.dask_map over a JAX function (issue 12, item 7): chunks of a dask array,
    the joints of a state joined into one chunk, equal to the NumPy batch."""
    da = need("dask.array", reason="dask_map runs on dask")
    from eomgen.analysis.batch import dask_map

    modules = robot("planar_2link")
    rng = np.random.default_rng(1)
    q, qd, qdd = (rng.uniform(-np.pi, np.pi, (500, 2)) for _ in range(3))
    lazy_q = da.from_array(q, chunks=(128, 1))  # joints split too: dask_map joins them
    lazy = dask_map(jax.jit(modules.jax.inverse_dynamics), lazy_q, qd, qdd)
    assert lazy.chunks[0] == (128, 128, 128, 116)
    np.testing.assert_allclose(lazy.compute(scheduler="threads"),
                               modules.numpy.inverse_dynamics(q, qd, qdd), rtol=1e-12, atol=1e-12)
