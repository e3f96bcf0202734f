"""One rule for the values a generated function refuses (docs/backends.md, "Values a function
refuses"), the same in every function: the NumPy and the fast module raise the same exception
with the same message for NaN or +-inf in an input (FloatingPointError naming the function, the
input, the state of a batch and the entry), for an input that holds no real numbers (TypeError),
for a parameter's value and for the keyword damping; an empty batch gives results of shape
(0, ...) in both. The backends that cannot raise on values (CasADi, JAX, PyTorch's printed
functions) return NaN instead.

References: where each hostile value was put (the state and entry the message must name), the
shapes of the results for one state (the empty batch's are (0,) + those), and each module's
results for valid input (NumPy and fast agree, so the checks change nothing there).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import eomgen
from eomgen.outputs import OUTPUTS
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT
from support.generated import BACKENDS, generated

WALL = ROOT / "examples/contacts/planar_2link_wall.yaml"
ARM_FUNCTIONS = ["mass_matrix", "gravity_vector", "inverse_dynamics", "forward_dynamics",
                 "linearize", "centroidal_momentum_matrix", "inverse_dynamics_derivatives"]
DAMPED = ["constrained_forward_dynamics", "constrained_forward_dynamics_derivatives",
          "operational_space_inertia", "operational_space_bias", "contact_jacobian"]
STATE = np.array([0.3, -0.7])


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    """The planar arm's modules of every loadable backend: ({backend: call}, {backend: ns})."""
    model = eomgen.load(eomgen.example_path("planar_2link"))
    return generated(model, ARM_FUNCTIONS, tmp_path_factory.mktemp("arm"))


@pytest.fixture(scope="module")
def wall(tmp_path_factory):
    """The arm with its tip on a wall: the functions taking damping, NumPy and fast."""
    model = apply_scene(eomgen.load(eomgen.example_path("planar_2link")),
                        load_scene(WALL)).model
    return generated(model, DAMPED, tmp_path_factory.mktemp("wall"), ("numpy", "fast"))


def outcome(function, *args, **keywords):
    """("ok", the results' shapes) or (exception type, message) of one call."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # a warning (complex cast to real) is no answer
            result = function(*args, **keywords)
    except Exception as error:  # noqa: BLE001 - the exception is what is compared
        return type(error), str(error)
    results = result if isinstance(result, tuple) else (result,)
    return "ok", [np.shape(r) for r in results]


def hostile_calls(name, keywords):
    """(what, args, keywords, expected exception or None, words its message must hold) of
    ``name``: each hostile value placed at a known input, state and entry."""
    inputs = OUTPUTS[name].inputs
    last = inputs[-1]
    one = [STATE.copy() for _ in inputs]
    batch = [np.tile(STATE, (3, 1)) for _ in inputs]
    nan_last = [*one[:-1], np.array([0.1, np.nan])]
    inf_in_batch = [b.copy() for b in batch]
    inf_in_batch[-1][2, 0] = -np.inf
    cases = [
        ("nan", nan_last, keywords, FloatingPointError,
         f"{name}: {last} is not finite: entry 1 is nan"),
        ("-inf in a batch", inf_in_batch, keywords, FloatingPointError,
         f"{name}: {last} is not finite at state 2: entry 0 is -inf"),
        ("complex", [STATE + 0.5j, *one[1:]], keywords, TypeError,
         f"{name}: q must hold real numbers, got dtype complex128"),
        ("text", [np.array(["0.3", "1"]), *one[1:]], keywords, TypeError,
         f"{name}: q must hold real numbers, got dtype <U3"),
        ("None", [[0.3, None], *one[1:]], keywords, FloatingPointError,  # NumPy's NaN
         f"{name}: q is not finite: entry 1 is nan"),
        ("parameter nan", one, {**keywords, "m1": np.nan}, FloatingPointError,
         f"{name}(): parameter 'm1' is not finite: nan"),
        ("parameter inf", one, {**keywords, "g": np.float64(np.inf)}, FloatingPointError,
         f"{name}(): parameter 'g' is not finite"),
        ("parameter text", one, {**keywords, "l2": "1.0"}, TypeError,
         f"{name}(): parameter 'l2' must be a real number, got '1.0'"),
        ("parameter complex", one, {**keywords, "m2": 1 + 0j}, TypeError,
         f"{name}(): parameter 'm2' must be a real number"),
    ]
    if "damping" in keywords:
        for value, error, words in (
                (-1.0, ValueError, "damping must be a finite number >= 0, got -1.0"),
                (np.nan, ValueError, "damping must be a finite number >= 0, got nan"),
                (np.inf, ValueError, "damping must be a finite number >= 0, got inf"),
                ("abc", TypeError, "damping must be a real number, got 'abc'"),
                ("0.1", TypeError, "damping must be a real number, got '0.1'"),
                (1e-3j, TypeError, "damping must be a real number, got 0.001j"),
                (np.array([1e-3, 1e-3]), TypeError, "damping must be a real number")):
            cases.append((f"damping={value!r}", one, {**keywords, "damping": value}, error,
                          f"{name}(): {words}"))
    return cases


def check_alike(modules, name, keywords):
    """NumPy and fast: the same outcome for every hostile call, the one the rule names."""
    numpy, fast = modules["numpy"][name], modules["fast"][name]
    for what, args, kw, error, words in hostile_calls(name, keywords):
        got_numpy, got_fast = outcome(numpy, *args, **kw), outcome(fast, *args, **kw)
        assert got_numpy == got_fast, (name, what, got_numpy, got_fast)
        assert got_numpy[0] is error and words in got_numpy[1], (name, what, got_numpy)
    single = outcome(numpy, *[STATE] * len(OUTPUTS[name].inputs), **keywords)
    assert single[0] == "ok", (name, single)
    empty = [np.zeros((0, 2))] * len(OUTPUTS[name].inputs)
    expected = ("ok", [(0, *shape) for shape in single[1]])
    for module in (numpy, fast):
        assert outcome(module, *empty, **keywords) == expected, (name, module)


def test_numpy_and_fast_refuse_alike_in_every_function(arm):
    _, modules = arm
    if "fast" not in modules:
        pytest.skip("no C compiler or Python headers: the fast module was not built")
    for name in ARM_FUNCTIONS:
        check_alike(modules, name, {})


def test_the_keyword_damping_is_checked_alike(wall):
    _, modules = wall
    if "fast" not in modules:
        pytest.skip("no C compiler or Python headers: the fast module was not built")
    for name in DAMPED:
        check_alike(modules, name, {"damping": 1e-3} if name != "contact_jacobian" else {})
    # valid input: the checks change no result (KKT by LU in NumPy, by Cholesky in C)
    q, qd, tau = np.array([[0.3, -0.7], [1.0, 0.2]]), np.ones((2, 2)), np.ones((2, 2))
    for x, y in zip(*(modules[b]["constrained_forward_dynamics"](q, qd, tau, damping=1e-3)
                      for b in ("numpy", "fast"))):
        np.testing.assert_allclose(x, y, rtol=1e-9, atol=1e-12)


def test_the_backends_that_cannot_raise_return_nan(arm):
    """CasADi, JAX and PyTorch's printed functions: NaN in, NaN out (no exception), in the
    entries that depend on the NaN input, finite ones elsewhere."""
    calls, _ = arm
    others = [b for b in BACKENDS if b not in ("numpy", "fast")]
    if not others:
        pytest.skip("no backend without value checks is installed")
    for backend in others:
        call = calls[backend]
        M = call("mass_matrix", np.array([0.3, np.nan]))  # M depends on q2 only
        assert np.isnan(M).any() and np.isfinite(M[1, 1]), backend  # M22 = I2 + m2 lc2^2
        M = call("mass_matrix", np.array([np.nan, -0.7]))
        assert np.isfinite(M).all(), backend
        tau = call("inverse_dynamics", STATE, STATE, np.array([np.nan, 0.0]))
        assert np.isnan(tau).any(), backend
        g = call("gravity_vector", STATE, g=np.nan)
        assert np.isnan(g).all(), backend


TASK_SPACE = ["operational_space_inertia", "operational_space_bias",
              "dynamically_consistent_inverse"]


def test_an_empty_batch_of_the_task_space_functions_in_every_python_backend(tmp_path):
    """JAX and PyTorch give the task-space functions' empty batch the shapes NumPy gives,
    (0,) + one state's (the frame count is the module's, not inferred from the batch; damping
    because the planar arm's tip moves in 3 of the 6 directions)."""
    model = apply_scene(eomgen.load(eomgen.example_path("planar_2link")),
                        load_scene(WALL)).model
    have = [b for b in ("numpy", "jax", "torch") if b in BACKENDS]
    if have == ["numpy"]:
        pytest.skip("neither jax nor torch is installed (the jax and torch extras)")
    _, modules = generated(model, TASK_SPACE, tmp_path, tuple(have))
    for name in TASK_SPACE:
        count = len(OUTPUTS[name].inputs)
        single = outcome(modules["numpy"][name], *[STATE] * count, damping=1e-3)
        assert single[0] == "ok", (name, single)
        empty = [np.zeros((0, 2))] * count
        for backend in have:
            got = outcome(modules[backend][name], *empty, damping=1e-3)
            assert got == ("ok", [(0, *shape) for shape in single[1]]), (backend, name, got)
