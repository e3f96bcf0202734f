"""The fast module's batches (issue 43): lanes kernels and threads.

A batch goes four states at a time through a function's lanes kernel (SIMD vectors, sin and cos by
the runtime's vector routine, runtime ``lanes_math.c``) and across threads. Checked here on the
planar 2-link arm with every kernel given a lanes version (``LANES_OPERATIONS`` set to 0 for
this module): the batch against the same module's one-state kernel called state by state
(libm's sin and cos, scalar arithmetic), for sizes that are not multiples of four, strided and
Fortran-ordered inputs; one thread against two, bitwise; errors alike on any thread count; the
thread count's settings (``set_threads``, ``threads``, ``$EOMGEN_THREADS``).
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

import eomgen
from eomgen.codegen.backends import fast_backend
from eomgen.codegen.backends.casadi_backend import c_compiler
from eomgen.codegen.backends.fast_backend import python_headers
from eomgen.codegen.generate import render_files
from eomgen.outputs import OUTPUTS
from support import load_module

pytestmark = pytest.mark.skipif(c_compiler() is None or python_headers() is None,
                                reason="needs a C compiler and Python's C headers")

#: functions of the module (the arm's: sin and cos of q, products, quotients)
FUNCTIONS = ("mass_matrix", "inverse_dynamics", "forward_dynamics_aba", "gravity_vector",
             "inverse_dynamics_derivatives")
#: a batch whose work (states x operations) starts a second thread: EOM_WORK_PER_THREAD is
#: 400,000 operations per thread, the arm's kernels have 16 to 69
BIG = 100_003


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    """(fast module, its C source) of the planar 2-link arm, every kernel with a lanes version."""
    from eomgen.codegen.functions import select_functions

    model = eomgen.load(eomgen.example_path("planar_2link"))
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(fast_backend, "LANES_OPERATIONS", 0)
        files = render_files(model, ["fast"],
                             functions=select_functions([*FUNCTIONS, "forward_dynamics"]))
    folder = tmp_path_factory.mktemp("fast_batches")
    for f in files:
        path = folder / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    (library,) = folder.glob("planar_2link_fast*.so")
    module = load_module(library, "planar_2link_fast")
    yield module, folder, files[0].content
    module.set_threads(None)


def _inputs(name, rng, states, spread=3.0):
    return [rng.uniform(-spread, spread, (states, 2)) for _ in OUTPUTS[name].inputs]


def _flat(result, states):
    parts = result if isinstance(result, tuple) else (result,)
    return np.concatenate([np.reshape(p, (states, -1)) for p in parts], axis=1)


def test_every_function_has_a_lanes_kernel(arm):
    _, _, source = arm
    for name in FUNCTIONS:
        assert f"static void {name}_lanes(" in source, name
    assert "EOM_SIN_LANES" in source and "eom_sincos_lanes" in source


@pytest.mark.parametrize("states", [1, 2, 3, 4, 5, 7, 9, 13, 202])
def test_lanes_equal_the_one_state_kernel(arm, states):
    """Batch (lanes kernel for the first multiple of four states, one-state kernel for the
    rest) against one call per state (the one-state kernel, libm's sin and cos): 1e-14 of the
    largest entry of each state's result."""
    module, _, _ = arm
    rng = np.random.default_rng(states)
    for name in FUNCTIONS:
        function = getattr(module, name)
        inputs = _inputs(name, rng, states)
        batch = _flat(function(*inputs), states)
        for k in range(states):
            one = _flat(function(*(x[k] for x in inputs)), 1)[0]
            error = np.max(np.abs(batch[k] - one)) / max(np.max(np.abs(one)), 1e-300)
            assert error <= 1e-14, (name, states, k, error)


def test_strided_and_fortran_ordered_batches_equal_contiguous_ones(arm):
    module, _, _ = arm
    rng = np.random.default_rng(7)
    for name in FUNCTIONS:
        function = getattr(module, name)
        wide = [rng.uniform(-3, 3, (2 * 11, 4)) for _ in OUTPUTS[name].inputs]
        strided = [x[::2, 1:3] for x in wide]  # 11 states, rows and columns strided
        assert not strided[0].flags.c_contiguous
        expected = _flat(function(*[np.ascontiguousarray(x) for x in strided]), 11)
        np.testing.assert_array_equal(_flat(function(*strided), 11), expected)
        fortran = [np.asfortranarray(x) for x in strided]
        assert not fortran[0].flags.c_contiguous
        np.testing.assert_array_equal(_flat(function(*fortran), 11), expected)
        for k in range(11):
            one = _flat(function(*(x[k] for x in strided)), 1)[0]
            assert np.max(np.abs(expected[k] - one)) <= 1e-14 * np.max(np.abs(one)), name


def test_one_thread_and_two_give_bitwise_equal_results(arm):
    """Each state goes through the same kernel whatever the thread count (the parts are whole
    blocks of four states): the results are the same bits."""
    module, _, _ = arm
    rng = np.random.default_rng(3)
    for name in FUNCTIONS:
        function = getattr(module, name)
        inputs = _inputs(name, rng, BIG)
        module.set_threads(1)
        one = _flat(function(*inputs), BIG)
        module.set_threads(2)
        two = _flat(function(*inputs), BIG)
        module.set_threads(3)  # more threads than cores: still the same parts' arithmetic
        three = _flat(function(*inputs), BIG)
        assert one.tobytes() == two.tobytes() == three.tobytes(), name
    module.set_threads(None)


def test_errors_are_the_same_on_any_thread_count(arm):
    """The value rule (tests/backends/test_value_rule.py) on a big batch: the first state that
    is not finite is named, whatever the thread count."""
    module, _, _ = arm
    rng = np.random.default_rng(4)
    q, qd, qdd = _inputs("inverse_dynamics", rng, BIG)
    qd[BIG - 5, 1] = np.nan
    qd[BIG // 2 + 1, 0] = -np.inf
    messages = []
    for threads in (1, 2):
        module.set_threads(threads)
        with pytest.raises(FloatingPointError) as error:
            module.inverse_dynamics(q, qd, qdd)
        messages.append(str(error.value))
    module.set_threads(None)
    assert messages[0] == messages[1] == (
        f"inverse_dynamics: qd is not finite at state {BIG // 2 + 1}: entry 0 is -inf")


def test_forward_dynamics_on_threads_solves_and_fails_as_on_one(arm):
    """The composed forward dynamics (Cholesky per state) on 1 and 2 threads: the same bits
    and condition estimates; a batch with states whose C qd overflows names the first of them,
    whichever part (thread) it falls in."""
    module, _, _ = arm
    rng = np.random.default_rng(5)
    q, qd, tau = _inputs("forward_dynamics", rng, BIG)
    results = []
    for threads in (1, 2):
        module.set_threads(threads)
        qdd, condition = module.forward_dynamics(q, qd, tau, return_condition=True)
        results.append(qdd.tobytes() + condition.tobytes())
    assert results[0] == results[1]
    for bad in ((40_000, 90_000), (60_000, 90_000), (BIG - 1,)):
        fast = qd.copy()
        fast[list(bad), 0] = 1e200  # C qd overflows to inf
        messages = []
        for threads in (1, 2):
            module.set_threads(threads)
            with pytest.raises(FloatingPointError) as error:
                module.forward_dynamics(q, fast, tau)
            messages.append(str(error.value))
        assert messages[0] == messages[1], messages
        assert f"at state {bad[0]} " in messages[0], messages
    module.set_threads(None)


def test_set_threads_and_threads(arm):
    module, _, _ = arm
    default = module.threads()
    # the CPUs this process may use
    assert default == (len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity")
                       else os.cpu_count())
    module.set_threads(3)
    assert module.threads() == 3
    module.set_threads(None)
    assert module.threads() == default
    for value, error in ((0, ValueError), (-2, ValueError), (257, ValueError),
                         (2.0, TypeError), ("2", TypeError), (True, TypeError)):
        with pytest.raises(error, match=r"set_threads\(\): n must be an integer from 1 to 256 "
                                        r"or None"):
            module.set_threads(value)
    assert module.threads() == default


@pytest.mark.parametrize("value, expected", [("3", "3"), ("", "default"),
                                             ("zero", "ValueError: EOMGEN_THREADS must be an "
                                                      "integer from 1 to 256, got 'zero'"),
                                             ("0", "ValueError: EOMGEN_THREADS must be an "
                                                   "integer from 1 to 256, got '0'")])
def test_the_environment_variable_is_read_at_import(arm, value, expected):
    module, folder, _ = arm
    (library,) = folder.glob("planar_2link_fast*.so")
    program = (
        "import importlib.util, os, sys\n"
        f"spec = importlib.util.spec_from_file_location('planar_2link_fast', {str(library)!r})\n"
        "try:\n"
        "    m = importlib.util.module_from_spec(spec); spec.loader.exec_module(m)\n"
        "except ValueError as e:\n"
        "    print('ValueError:', e); sys.exit()\n"
        "n = m.threads(); m.set_threads(1); m.set_threads(None)\n"
        "assert m.threads() == n\n"
        "print('default' if 'EOMGEN_THREADS' not in os.environ or not os.environ["
        "'EOMGEN_THREADS'] else n)\n")
    result = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True,
                            timeout=120, env={**os.environ, "EOMGEN_THREADS": value})
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == expected


def test_a_forked_child_runs_batches_on_threads_too(arm):
    """The module's worker threads do not survive fork(): a child process (multiprocessing's
    fork start) gets a fresh pool, and its batches on 2 threads give the parent's bits."""
    import multiprocessing

    if "fork" not in multiprocessing.get_all_start_methods():
        pytest.skip("no fork() on this platform")
    module, _, _ = arm
    rng = np.random.default_rng(6)
    inputs = _inputs("inverse_dynamics", rng, BIG)
    module.set_threads(2)
    expected = module.inverse_dynamics(*inputs)  # the parent's pool is running
    with multiprocessing.get_context("fork").Pool(1) as pool:
        got = pool.apply(module.inverse_dynamics, inputs)
    module.set_threads(None)
    assert got.tobytes() == expected.tobytes()


def test_kernels_above_the_lanes_bound_get_no_lanes_version(monkeypatch):
    """LANES_MAX_OPERATIONS (the compile-time bound of issues 42 and 43) set between the arm's
    kernel sizes: the emitted source has a lanes version, FMA-cloned, for exactly the kernels
    at or below it, each kernel's size read from the source's own comment on its one-state
    version; the function table names none for the others."""
    import re

    from eomgen.codegen.functions import select_functions

    model = eomgen.load(eomgen.example_path("planar_2link"))
    functions = ("mass_matrix", "inverse_dynamics", "forward_dynamics_aba", "gravity_vector")
    monkeypatch.setattr(fast_backend, "LANES_OPERATIONS", 0)

    def emitted(bound):
        monkeypatch.setattr(fast_backend, "LANES_MAX_OPERATIONS", bound)
        (source,) = [f.content for f in render_files(
            model, ["fast"], functions=select_functions(functions), build=False)
            if f.name.endswith(".c")]
        return source

    def sizes(source):  # kernel name -> operations, from "; N operations." above its _one
        return {name: int(count) for count, name in re.findall(
            r"; (\d+) operations\. \*/\n(?:FMA_CLONES )?static void (\w+)_one\(", source)}

    operations = sizes(emitted(float("inf")))
    assert set(operations) == set(functions)
    bound = sorted(operations.values())[len(operations) // 2]
    source = emitted(bound)
    below = {name for name, count in operations.items() if count <= bound}
    assert below and below != set(operations)  # the bound cuts the arm's kernels in two
    for name in functions:
        lanes = f"FMA_CLONES static void {name}_lanes(" in source
        assert lanes == (name in below), name
        assert (f"EOM_LANES_KERNEL({name}_lanes)" in source) == (name in below), name
    assert set(re.findall(r"static void (\w+)_lanes\(", source)) == below
