"""The PyTorch backend against the NumPy module (tests/support/array_backends.py) and on its own
promises: tensors of shape (n,) or (N, n), the inputs' dtype and device, parameter defaults,
autograd through every output, forward dynamics with NumPy's conditioning report. Skips with a
reason when torch is missing (the ``torch`` extra)."""

from __future__ import annotations

import numpy as np
import pytest

from eomgen.codegen.generate import generate
from support.array_backends import (
    ARGUMENTS, FUNCTIONS, ROBOTS, assert_relative, central_difference, hostile_modules,
    load_module, robot_modules, states,
)
from support.extras import need

torch = need("torch", reason="the PyTorch backend")


@pytest.fixture(scope="module")
def robot(tmp_path_factory):
    """``robot(name)``: the robot's numpy and torch modules, generated once per module."""
    return robot_modules("torch", tmp_path_factory)


@pytest.mark.parametrize("name", ROBOTS)
def test_torch_agrees_with_numpy(robot, name):
    modules = robot(name)
    n = modules.numpy.NQ
    assert modules.torch.JOINT_NAMES == modules.numpy.JOINT_NAMES and modules.torch.NQ == n
    assert modules.torch.PARAMETERS == modules.numpy.PARAMETERS
    assert set(modules.torch.__all__) == set(modules.numpy.__all__)
    batch = states(n)
    for function in FUNCTIONS:
        args = batch[:ARGUMENTS[function]]
        expected = getattr(modules.numpy, function)(*args)
        got = getattr(modules.torch, function)(*(torch.from_numpy(a) for a in args))
        assert got.dtype == torch.float64
        assert_relative(got.numpy(), expected, what=f"{name} torch {function}")
        # one state in, one result out, equal to that state's row of the batch
        one = [a[2] for a in args]
        assert_relative(getattr(modules.torch, function)(*(torch.from_numpy(a) for a in one)),
                        expected[2], what="torch single")


# --- derivatives: autograd against central differences of the NumPy module ---------------------

@pytest.mark.parametrize("name", ["planar_2link", "ur5", "panda"])
def test_gradient_of_tau_matches_central_differences(robot, name):
    modules = robot(name)
    q, qd, qdd = (a[0] for a in states(modules.numpy.NQ, seed=2))
    reference = central_difference(
        lambda x: float(np.sum(modules.numpy.inverse_dynamics(x, qd, qdd))), q)
    scale = max(1.0, float(np.max(np.abs(reference))))
    q_t = torch.tensor(q, requires_grad=True)
    torch.sum(modules.torch.inverse_dynamics(q_t, torch.tensor(qd), torch.tensor(qdd))).backward()
    assert np.max(np.abs(q_t.grad.numpy() - reference)) <= 1e-6 * scale


def test_autograd_runs_through_every_output_and_parameter(robot):
    """Gradients of each output's sum w.r.t. q and a mass parameter against central
    differences of the NumPy module (forward dynamics included)."""
    modules = robot("planar_2link")
    q, qd, qdd = (a[1] for a in states(2, seed=3))
    for function in FUNCTIONS:
        args = (q, qd, qdd)[:ARGUMENTS[function]]
        f_np = getattr(modules.numpy, function)
        by_q = central_difference(lambda x: float(np.sum(f_np(x, *args[1:], m2=1.3))), q)
        by_m2 = central_difference(lambda m: float(np.sum(f_np(*args, m2=m[0]))), np.array([1.3]))
        q_t, m_t = torch.tensor(q, requires_grad=True), torch.tensor(1.3, requires_grad=True)
        rest = [torch.tensor(a) for a in args[1:]]
        torch.sum(getattr(modules.torch, function)(q_t, *rest, m2=m_t)).backward()
        np.testing.assert_allclose(q_t.grad.numpy(), by_q, atol=1e-6)
        np.testing.assert_allclose(m_t.grad.item(), by_m2[0], atol=1e-6)


# --- shapes, dtypes, parameters ---------------------------------------------------------------

def test_parameters_left_out_take_the_descriptions_values(robot):
    modules = robot("planar_2link")
    q, qd, qdd = (torch.from_numpy(a) for a in states(2, seed=4))
    values = dict(modules.numpy.PARAMETERS)
    assert values["g"] == 9.81 and values["m2"] == 1.0
    module = modules.torch
    default = module.inverse_dynamics(q, qd, qdd)
    explicit = module.inverse_dynamics(q, qd, qdd, **values)
    assert_relative(default, np.asarray(explicit), tol=0.0)
    # a left-out parameter is the description's value, not zero: gravity is there
    assert np.max(np.abs(np.asarray(module.gravity_vector(q)))) > 1.0
    assert np.max(np.abs(np.asarray(module.gravity_vector(q, g=0.0)))) == 0.0
    # per-state parameter arrays, as in the NumPy module
    masses = np.linspace(0.5, 2.0, len(q))
    assert_relative(module.gravity_vector(q, m2=torch.from_numpy(masses)),
                    modules.numpy.gravity_vector(q.numpy(), m2=masses))


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


def test_bad_shapes_are_value_errors(robot):
    module = robot("planar_2link").torch
    with pytest.raises(ValueError, match=r"q must have shape \(2,\) or \(N, 2\), got \(3,\)"):
        module.mass_matrix(torch.as_tensor(np.zeros(3)))
    with pytest.raises(ValueError, match="same number of states, got 4 \\(q\\), 3 \\(qd\\)"):
        module.coriolis_matrix(torch.as_tensor(np.zeros((4, 2))), torch.as_tensor(np.zeros((3, 2))))


# --- forward dynamics: Cholesky in torch, conditioning as the NumPy module reports it ----------

def test_forward_dynamics_inverts_inverse_dynamics_and_reports_the_condition(robot):
    modules = robot("ur5")
    q, qd, qdd = states(modules.numpy.NQ, seed=6)
    tau = modules.numpy.inverse_dynamics(q, qd, qdd)
    _, expected = modules.numpy.forward_dynamics(q, qd, tau, return_condition=True)
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


def test_hostile_names_stay_text_and_the_module_runs():
    """Robot and joint names that try to break out of strings stay text; the module imports
    only torch and agrees with the NumPy module."""
    from support.robots import HOSTILE

    modules = hostile_modules("torch")
    q, qd, qdd = states(len(HOSTILE), seed=8)
    assert_relative(modules["torch"]["inverse_dynamics"](
        *(torch.from_numpy(a) for a in (q, qd, qdd))),
        modules["numpy"]["inverse_dynamics"](q, qd, qdd))


def test_parameters_named_like_the_framework_do_not_shadow_it(tmp_path):
    """A parameter named ``torch`` becomes the keyword ``torch_``; the module still reaches
    torch and the keyword's default is the description's."""
    import sympy as sp

    from eomgen.model import Inertial, Joint, JointType, Link, Parameter, Transform, build_model, vec3

    mass = sp.Symbol("torch", real=True)
    body = Inertial(mass, [0.3, 0, 0], [[0.01, 0, 0], [0, 0.01, 0], [0, 0, 0.01]])
    model = build_model("<test>", "shadowing", [Link("base"), Link("l1", body)],
                        [Joint("j1", JointType.REVOLUTE, "base", "l1", Transform(),
                               vec3([0, 0, 1]))],
                        parameters=[Parameter(mass, 1.5)], gravity=(0.0, -9.81, 0.0))
    paths = generate(model, tmp_path, "numpy,torch", cache=False)
    numpy_module, torch_module = (load_module(p, f"shadowing_{p.stem}") for p in sorted(
        paths, key=lambda p: not p.name.endswith("_numpy.py")))
    assert list(torch_module.PARAMETERS) == ["torch_"]
    q = np.array([[0.4], [1.1]])
    expected = numpy_module.gravity_vector(q)
    assert np.all(np.abs(expected) > 0)
    assert_relative(torch_module.gravity_vector(torch.from_numpy(q)), expected)
    assert_relative(torch_module.gravity_vector(torch.from_numpy(q), torch_=3.0),
                    numpy_module.gravity_vector(q, torch_=3.0))
