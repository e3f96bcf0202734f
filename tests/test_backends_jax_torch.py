"""The JAX and PyTorch backends against the NumPy module (itself checked against Newton–Euler
and Pinocchio in test_codegen), against central differences for their derivatives, and on their
own promises: batch shapes, dtypes, parameter defaults, jit/vmap/grad, forward dynamics.

Robots: the bundled planar arm (all parameters symbolic) and PUMA 560, the UR5 and the Panda
(fingers locked; example-robot-data). Skips with a reason when jax, torch or the data are
missing (the ``jax`` and ``torch`` extras).
"""

from __future__ import annotations

import importlib.util
import warnings
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

import eomgen
from eomgen.codegen.generate import generate
from eomgen.codegen.scene_generate import generate_scene
from eomgen.scene import load_scene
from conftest import erd_robots_dir

jax = pytest.importorskip("jax", reason="the JAX backend needs jax: pip install 'eomgen[jax]'")
torch = pytest.importorskip("torch",
                            reason="the PyTorch backend needs torch: pip install 'eomgen[torch]'")
jax.config.update("jax_enable_x64", True)
jnp = jax.numpy

ROOT = Path(__file__).resolve().parent.parent
FUNCTIONS = ("mass_matrix", "coriolis_matrix", "gravity_vector", "inverse_dynamics",
             "forward_dynamics")
ARGUMENTS = {"mass_matrix": 1, "coriolis_matrix": 2, "gravity_vector": 1,
             "inverse_dynamics": 3, "forward_dynamics": 3}
ROBOTS = ("planar_2link", "puma560", "ur5", "panda")


def load_module(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _generate(name: str, outdir: Path) -> list[Path]:
    backends = "numpy,jax,torch"
    if name in ("planar_2link", "puma560"):
        path = eomgen.example_path("planar_2link" if name == "planar_2link" else "puma560_dh")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # PUMA 560's published inertias warn by design
            return generate(eomgen.load(path), outdir, backends, cache=False)
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    if name == "ur5":
        return generate(eomgen.load(robots / "ur_description/urdf/ur5_robot.urdf"), outdir,
                        backends, cache=False)
    scene = load_scene(ROOT / "examples/scenes/panda_fingers_locked.yaml")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the fingers' <mimic>: locked by the scene anyway
        model = eomgen.load(robots / "panda_description/urdf/panda.urdf")
    paths, _ = generate_scene(model, scene, outdir, backends)
    return paths


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    """``robot(name)``: the robot's numpy, jax and torch modules, generated once per module."""
    built: dict[str, SimpleNamespace] = {}

    def get(name: str) -> SimpleNamespace:
        if name not in built:
            paths = _generate(name, tmp_path_factory.mktemp(name))
            modules = {}
            for kind in ("numpy", "jax", "torch"):
                path = next(p for p in paths if p.name.endswith(f"_{kind}.py"))
                modules[kind] = load_module(path, f"{name}_{kind}_under_test")
            built[name] = SimpleNamespace(**modules)
        return built[name]

    return get


def states(n: int, count: int = 5, seed: int = 0):
    rng = np.random.default_rng(seed)
    return (rng.uniform(-np.pi, np.pi, (count, n)), rng.normal(size=(count, n)),
            rng.normal(size=(count, n)))


def assert_relative(actual, expected, tol=1e-12, what=""):
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape, (what, actual.shape, expected.shape)
    scale = max(float(np.max(np.abs(expected))), np.finfo(float).tiny)
    error = float(np.max(np.abs(actual - expected))) / scale
    assert error <= tol, f"{what}: relative error {error:.2e} > {tol:.0e}"


# ----------------------------------------------------------------------------------------------
# Every output of every robot agrees with the NumPy module
# ----------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ROBOTS)
def test_backends_agree_with_numpy(robot, name):
    modules = robot(name)
    n = modules.numpy.NQ
    assert modules.jax.JOINT_NAMES == modules.torch.JOINT_NAMES == modules.numpy.JOINT_NAMES
    assert modules.jax.NQ == modules.torch.NQ == n
    assert modules.jax.PARAMETERS == modules.torch.PARAMETERS == modules.numpy.PARAMETERS
    assert set(modules.jax.__all__) | {"IllConditionedWarning"} == set(modules.numpy.__all__)
    assert set(modules.torch.__all__) == set(modules.numpy.__all__)
    batch = states(n)
    for function in FUNCTIONS:
        args = batch[:ARGUMENTS[function]]
        expected = getattr(modules.numpy, function)(*args)
        got_jax = getattr(modules.jax, function)(*args)
        assert got_jax.dtype == jnp.float64
        assert_relative(got_jax, expected, what=f"{name} jax {function}")
        got_torch = getattr(modules.torch, function)(*(torch.from_numpy(a) for a in args))
        assert got_torch.dtype == torch.float64
        assert_relative(got_torch.numpy(), expected, what=f"{name} torch {function}")
        # one state in, one result out, equal to that state's row of the batch
        one = [a[2] for a in args]
        assert_relative(getattr(modules.jax, function)(*one), expected[2], what="jax single")
        assert_relative(getattr(modules.torch, function)(*(torch.from_numpy(a) for a in one)),
                        expected[2], what="torch single")


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


# ----------------------------------------------------------------------------------------------
# Derivatives: JAX grad and torch autograd against central differences of the NumPy module
# ----------------------------------------------------------------------------------------------


def central_difference(f, x, h=1e-6):
    """d f / d x of a scalar function of a vector, by central differences (error ~ h^2)."""
    out = np.zeros_like(x)
    for i in range(x.size):
        e = np.zeros_like(x)
        e[i] = h
        out[i] = (f(x + e) - f(x - e)) / (2 * h)
    return out


@pytest.mark.parametrize("name", ["planar_2link", "ur5", "panda"])
def test_gradient_of_tau_matches_central_differences(robot, name):
    modules = robot(name)
    q, qd, qdd = (a[0] for a in states(modules.numpy.NQ, seed=2))
    reference = central_difference(
        lambda x: float(np.sum(modules.numpy.inverse_dynamics(x, qd, qdd))), q)
    scale = max(1.0, float(np.max(np.abs(reference))))
    grad_jax = jax.grad(lambda x: jnp.sum(modules.jax.inverse_dynamics(x, qd, qdd)))(q)
    assert np.max(np.abs(np.asarray(grad_jax) - reference)) <= 1e-6 * scale
    q_t = torch.tensor(q, requires_grad=True)
    torch.sum(modules.torch.inverse_dynamics(q_t, torch.tensor(qd), torch.tensor(qdd))).backward()
    assert np.max(np.abs(q_t.grad.numpy() - reference)) <= 1e-6 * scale


def test_autograd_runs_through_every_output_and_parameter(robot):
    """Gradients of each output's sum w.r.t. q and a mass parameter, both frameworks, against
    central differences of the NumPy module (forward dynamics included)."""
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
        q_t, m_t = torch.tensor(q, requires_grad=True), torch.tensor(1.3, requires_grad=True)
        rest = [torch.tensor(a) for a in args[1:]]
        torch.sum(getattr(modules.torch, function)(q_t, *rest, m2=m_t)).backward()
        np.testing.assert_allclose(q_t.grad.numpy(), by_q, atol=1e-6)
        np.testing.assert_allclose(m_t.grad.item(), by_m2[0], atol=1e-6)


# ----------------------------------------------------------------------------------------------
# Shapes, dtypes, parameters
# ----------------------------------------------------------------------------------------------


def test_parameters_left_out_take_the_descriptions_values(robot):
    modules = robot("planar_2link")
    q, qd, qdd = states(2, seed=4)
    values = dict(modules.numpy.PARAMETERS)
    assert values["g_"] == 9.81 and values["m2"] == 1.0
    for module, wrap in ((modules.jax, np.asarray), (modules.torch, torch.from_numpy)):
        default = module.inverse_dynamics(wrap(q), wrap(qd), wrap(qdd))
        explicit = module.inverse_dynamics(wrap(q), wrap(qd), wrap(qdd), **values)
        assert_relative(default, np.asarray(explicit), tol=0.0)
        # a left-out parameter is the description's value, not zero: gravity is there
        assert np.max(np.abs(np.asarray(module.gravity_vector(wrap(q))))) > 1.0
        assert np.max(np.abs(np.asarray(module.gravity_vector(wrap(q), g_=0.0)))) == 0.0
    # per-state parameter arrays, as in the NumPy module
    masses = np.linspace(0.5, 2.0, len(q))
    expected = modules.numpy.gravity_vector(q, m2=masses)
    assert_relative(modules.jax.gravity_vector(q, m2=masses), expected)
    assert_relative(modules.torch.gravity_vector(torch.from_numpy(q), m2=torch.from_numpy(masses)),
                    expected)


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


def test_torch_keeps_the_inputs_dtype_and_device(robot):
    modules = robot("planar_2link")
    q, qd, qdd = (torch.from_numpy(a) for a in states(2, seed=5))
    tau = modules.torch.inverse_dynamics(q.float(), qd.float(), qdd.float())
    assert tau.dtype == torch.float32 and tau.device == q.device
    expected = modules.numpy.inverse_dynamics(q.numpy(), qd.numpy(), qdd.numpy())
    assert_relative(tau.double(), expected, tol=1e-5)  # float32 arithmetic
    assert modules.torch.mass_matrix(q.float().to(torch.float64)).dtype == torch.float64
    assert modules.torch.gravity_vector([1, 2]).dtype == torch.get_default_dtype()
    if torch.cuda.is_available():  # pragma: no cover - no accelerator on CI
        on_gpu = modules.torch.mass_matrix(q.cuda())
        assert on_gpu.device.type == "cuda"
        assert_relative(on_gpu.cpu(), modules.numpy.mass_matrix(q.numpy()))


@pytest.mark.parametrize("kind", ["jax", "torch"])
def test_bad_shapes_are_value_errors(robot, kind):
    module = getattr(robot("planar_2link"), kind)
    wrap = np.asarray if kind == "jax" else torch.as_tensor
    with pytest.raises(ValueError, match=r"q must have shape \(2,\) or \(N, 2\), got \(3,\)"):
        module.mass_matrix(wrap(np.zeros(3)))
    with pytest.raises(ValueError, match="same number of states, got 4 \\(q\\), 3 \\(qd\\)"):
        module.coriolis_matrix(wrap(np.zeros((4, 2))), wrap(np.zeros((3, 2))))


# ----------------------------------------------------------------------------------------------
# Forward dynamics: Cholesky in each framework, conditioning as the NumPy module reports it
# ----------------------------------------------------------------------------------------------


def test_forward_dynamics_inverts_inverse_dynamics_and_reports_the_condition(robot):
    modules = robot("ur5")
    q, qd, qdd = states(modules.numpy.NQ, seed=6)
    tau = modules.numpy.inverse_dynamics(q, qd, qdd)
    _, expected = modules.numpy.forward_dynamics(q, qd, tau, return_condition=True)
    x, condition = modules.jax.forward_dynamics(q, qd, tau, return_condition=True)
    assert_relative(x, qdd, tol=1e-10, what="jax qdd")
    d = np.asarray(condition) / expected  # the same estimate when no state is near the limit
    np.testing.assert_allclose(d, 1.0, rtol=1e-9)
    x, condition = modules.torch.forward_dynamics(*(torch.from_numpy(a) for a in (q, qd, tau)),
                                                  return_condition=True)
    assert_relative(x, qdd, tol=1e-10, what="torch qdd")
    np.testing.assert_allclose(condition.numpy(), expected, rtol=1e-9)


def test_forward_dynamics_singular_and_ill_conditioned(robot):
    modules = robot("planar_2link")
    q, qd, tau = (a[:3] for a in states(2, seed=7))
    massless = dict(m2=0.0, I2=0.0)  # joint 2 moves nothing: M is singular
    with pytest.raises(torch.linalg.LinAlgError, match="not positive definite at state 0"):
        modules.torch.forward_dynamics(*(torch.from_numpy(a) for a in (q, qd, tau)), **massless)
    assert np.all(np.isnan(np.asarray(modules.jax.forward_dynamics(q, qd, tau, **massless))))
    light = dict(m2=1e-11, I2=1e-12)  # cond(M) about 1e11: both warn as NumPy does
    with pytest.warns(modules.numpy.IllConditionedWarning):
        expected, c_np = modules.numpy.forward_dynamics(q, qd, tau, return_condition=True, **light)
    with pytest.warns(modules.torch.IllConditionedWarning, match="ill-conditioned at state"):
        got, c_t = modules.torch.forward_dynamics(*(torch.from_numpy(a) for a in (q, qd, tau)),
                                                  return_condition=True, **light)
    np.testing.assert_allclose(c_t.numpy(), c_np, rtol=1e-6)
    assert_relative(got, expected, tol=1e-3)  # both carry errors up to cond(M) * eps
    bad = tau.copy()
    bad[1, 0] = np.inf
    with pytest.raises(FloatingPointError, match="not finite at state 1"):
        modules.torch.forward_dynamics(*(torch.from_numpy(a) for a in (q, qd, bad)))


def test_hostile_names_stay_text_and_the_modules_run():
    """Robot and joint names that try to break out of strings stay text; the modules import
    and agree with the NumPy module (imports only of the module's own framework)."""
    import ast

    from eomgen.codegen.generate import render_files
    from test_codegen import DOCSTRING_BREAKER, HOSTILE, hostile_star

    files = {f.name: f.content for f in render_files(hostile_star(DOCSTRING_BREAKER),
                                                     ["numpy", "jax", "torch"])}
    assert len(files) == 3
    modules = {}
    for name, content in files.items():
        tree = ast.parse(content)
        assert repr(DOCSTRING_BREAKER) in ast.get_docstring(tree)
        imports = sorted(alias.name for node in ast.walk(tree)
                         if isinstance(node, (ast.Import, ast.ImportFrom))
                         for alias in node.names)
        kind = name.rsplit("_", 1)[1][:-3]
        assert set(imports) <= {"numpy", "warnings", "jax.numpy", "cho_solve", "torch"}
        assert ("jax.numpy" in imports) == (kind == "jax")
        assert ("torch" in imports) == (kind == "torch")
        namespace: dict = {}
        exec(compile(content, name, "exec"), namespace)  # noqa: S102 - our generated code
        assert namespace["JOINT_NAMES"] == HOSTILE
        modules[kind] = namespace
    q, qd, qdd = states(len(HOSTILE), seed=8)
    expected = modules["numpy"]["inverse_dynamics"](q, qd, qdd)
    assert_relative(modules["jax"]["inverse_dynamics"](q, qd, qdd), expected)
    assert_relative(modules["torch"]["inverse_dynamics"](
        *(torch.from_numpy(a) for a in (q, qd, qdd))), expected)


def test_parameters_named_like_the_frameworks_do_not_shadow_them(tmp_path):
    """Parameters named ``torch``, ``jnp`` and ``jax`` become ``torch_``, ... keywords; the
    modules still reach their framework and the keywords' defaults are the description's."""
    import sympy as sp

    from eomgen.model import (Inertial, Joint, JointType, Link, Parameter, Transform,
                              build_model, vec3)

    mass, length, gravity = (sp.Symbol(name, real=True) for name in ("torch", "jnp", "jax"))
    body = Inertial(mass, [length, 0, 0], [[0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.01]])
    model = build_model("<test>", "shadowing", [Link("base"), Link("l1", body)],
                        [Joint("j1", JointType.REVOLUTE, "base", "l1", Transform(),
                               vec3([0, 0, 1]))],
                        parameters=[Parameter(mass, 1.5), Parameter(length, 0.3),
                                    Parameter(gravity, 2.0)], gravity=(0.0, -gravity, 0.0))
    paths = generate(model, tmp_path, "numpy,jax,torch", cache=False)
    numpy_module, jax_module, torch_module = (
        load_module(p, f"shadowing_{p.stem}") for p in sorted(paths, key=lambda p: (
            not p.name.endswith("_numpy.py"), not p.name.endswith("_jax.py"))))
    assert list(torch_module.PARAMETERS) == ["jax_", "jnp_", "torch_"]
    q = np.array([[0.4], [1.1]])
    expected = numpy_module.gravity_vector(q)
    assert np.all(np.abs(expected) > 0)
    assert_relative(jax_module.gravity_vector(q), expected)
    assert_relative(torch_module.gravity_vector(torch.from_numpy(q)), expected)
    assert_relative(torch_module.gravity_vector(torch.from_numpy(q), torch_=3.0),
                    numpy_module.gravity_vector(q, torch_=3.0))


def test_dask_map_takes_dask_inputs_and_jax_functions(robot):
    """eomgen.batch.dask_map over a JAX function (issue 12, item 7): chunks of a dask array,
    the joints of a state joined into one chunk, equal to the NumPy batch."""
    da = pytest.importorskip("dask.array", reason="dask_map needs dask: pip install 'eomgen[dask]'")
    from eomgen.batch import dask_map

    modules = robot("planar_2link")
    rng = np.random.default_rng(1)
    q, qd, qdd = (rng.uniform(-np.pi, np.pi, (500, 2)) for _ in range(3))
    lazy_q = da.from_array(q, chunks=(128, 1))  # joints split too: dask_map joins them
    lazy = dask_map(jax.jit(modules.jax.inverse_dynamics), lazy_q, qd, qdd)
    assert lazy.chunks[0] == (128, 128, 128, 116)
    np.testing.assert_allclose(lazy.compute(scheduler="threads"),
                               modules.numpy.inverse_dynamics(q, qd, qdd), rtol=1e-12, atol=1e-12)
