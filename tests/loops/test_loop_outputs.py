"""The loop outputs in every code backend: ``loop_constraint``, ``loop_jacobian``,
``loop_bias`` and ``constrained_forward_dynamics`` with the loop rows (and contacts and loops
together), against the numeric :class:`eomgen.numeric.loops.LoopDynamics` (checked against closed
forms and Pinocchio in the other tests of this folder)."""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.errors import GenerationError
from eomgen.numeric.loops import LoopDynamics
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT, relative
from support.generated import generated

ROBOT = ROOT / "examples/robots/fourbar.yaml"
SCENE = ROOT / "examples/loops/fourbar_loop.yaml"
LOOP_FUNCTIONS = ["loop_constraint", "loop_jacobian", "loop_bias", "constrained_forward_dynamics"]


@pytest.fixture(scope="module")
def fourbar():
    return apply_scene(eomgen.load(ROBOT), load_scene(SCENE)).model


@pytest.mark.slow  # every backend generated and loaded (the fast one compiled): about 7 s
def test_every_backend_prints_the_loop_rows(fourbar, tmp_path):
    calls, modules = generated(fourbar, LOOP_FUNCTIONS, tmp_path)
    ref = LoopDynamics(fourbar)
    q = ref.assemble([0.8, 1.0, 1.8]) + np.array([0.0, 0.02, -0.01])  # slightly open
    qd = np.array([0.4, -0.3, 0.9])
    tau = np.array([1.2, 0.0, 0.0])
    expected = {"loop_constraint": (ref.loop_constraint(q), (q,)),
                "loop_jacobian": (ref.loop_jacobian(q), (q,)),
                "loop_bias": (ref.loop_bias(q, qd), (q, qd))}
    qdd_ref, F_ref = ref.constrained_forward_dynamics(q, qd, tau)
    for backend, call in calls.items():
        for function, (value, args) in expected.items():
            got = call(function, *args).reshape(value.shape)
            np.testing.assert_allclose(got, value, rtol=1e-12, atol=1e-12,
                                       err_msg=f"{backend} {function}")
        module = modules[backend]
        assert tuple(module["LOOP_ROWS"]) == ("pin.u", "pin.v"), backend
        assert tuple(module["CONTACT_ROWS"]) == ("pin.u", "pin.v"), backend
        f = module["constrained_forward_dynamics"]
        if backend == "casadi":
            out = f.call({"q": q, "qd": qd, "tau": tau})
            qdd, F = np.array(out["qdd"]).ravel(), np.array(out["F_c"]).ravel()
        else:
            qdd, F = (np.asarray(x, dtype=float) for x in f(q, qd, tau))
        assert relative(qdd, qdd_ref) < 1e-10 and relative(F, F_ref) < 1e-10, backend


def test_loop_outputs_need_loops():
    model = eomgen.load(ROBOT)
    with pytest.raises(GenerationError, match="need loops"):
        eomgen.derive(model, outputs=("J_l",))


def test_parallel_inverse_dynamics_is_refused_where_no_backend_composes_it(fourbar):
    from eomgen.codegen.functions import select_functions
    from eomgen.codegen.generate import render_files

    with pytest.raises(GenerationError, match=r"parallel_inverse_dynamics is composed by the "
                                              r"numpy, fast, casadi, c, jax, torch backends "
                                              r"only; kernels"):
        render_files(fourbar, ["kernels"], functions=select_functions(
            ["parallel_inverse_dynamics"]), build=False)
