"""The generated ``parallel_inverse_dynamics`` in the CasADi (and its C library), JAX and
PyTorch modules, on the five-bar (two motors, two passive elbows, a planar point loop): against
Pinocchio's ``constraintDynamics`` (the motion that efforts on the motors alone produce, and its
loop force) and against the NumPy module, one state and a batch; the ``damping`` input of each.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.codegen.backends.casadi_backend import library_name
from eomgen.numeric.loops import LoopDynamics
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT, relative
from support.generated import generated
from support.extras import need

ROBOT = ROOT / "examples/robots/fivebar.yaml"
SCENE = ROOT / "examples/loops/fivebar_loop.yaml"
NAME = "parallel_inverse_dynamics"


@pytest.fixture(scope="module")
def fivebar(tmp_path_factory):
    model = apply_scene(eomgen.load(ROBOT), load_scene(SCENE)).model
    folder = tmp_path_factory.mktemp("parallel")
    _, modules = generated(model, [NAME], folder, ("numpy", "casadi", "jax", "torch"))
    return model, modules


def _motions(model, count=3, seed=4):
    """Closed states near the five-bar's working pose (velocities on the loop), motor efforts
    alone (the passive joints' zero), and the q̈ and loop force Pinocchio's constraintDynamics
    gives them (λ on frame b in world axes: −R_a λ_pin, in the plane)."""
    pin = need("pinocchio")
    from eomgen.numeric.loops import pinocchio_loops
    from eomgen.numeric.pinocchio import to_pinocchio

    dyn = LoopDynamics(model)
    pm = to_pinocchio(model)
    p = pm.perm
    models = pinocchio_loops(model, pm)
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm.model, pm.data, models, datas)
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(count):
        q = dyn.assemble(np.array([1.2, 1.0, 1.9, -1.0]) + rng.uniform(-0.1, 0.1, 4))
        N = np.linalg.svd(dyn.loop_jacobian(q))[2][2:].T
        qd = N @ rng.uniform(-1, 1, 2)
        tau = np.zeros(4)
        tau[dyn.actuated] = rng.uniform(-0.5, 0.5, 2)
        # the loop's third (out-of-plane) row is dependent: a proximal mu
        a = pin.constraintDynamics(pm.model, pm.data, q[p], qd[p], tau[p], models, datas,
                                   pin.ProximalSettings(1e-14, 1e-12, 100))
        qdd = np.empty(4)
        qdd[p] = a
        lam = (-datas[0].oMc1.rotation @ pm.data.lambda_c[:3])[:2]
        out.append((q, qd, qdd, tau, lam))
    return out


def _call(backend, f, q, qd, qdd, **options):
    if backend == "casadi":
        result = f.call({"q": q, "qd": qd, "qdd": qdd, **options})
        return np.array(result["tau"]).ravel(), np.array(result["lambda"]).ravel()
    return tuple(np.asarray(x, dtype=float) for x in f(q, qd, qdd, **options))


@pytest.mark.slow  # four backends generated (JAX's import and jit compile): about 7 s
def test_every_python_backend_against_pinocchio_and_numpy(fivebar):
    model, modules = fivebar
    motions = _motions(model)
    assert set(modules) >= {"numpy", "casadi"}, "CasADi is a test dependency"
    q, qd, qdd, tau, lam = (np.array([m[k] for m in motions]) for k in range(5))
    reference = modules["numpy"][NAME]
    t_np, l_np = reference(q, qd, qdd)
    t_damped, l_damped = reference(q[0], qd[0], qdd[0], damping=0.05)
    assert relative(t_np, tau) <= 1e-9 and relative(l_np, lam) <= 1e-9
    assert relative(l_damped, lam[0]) > 1e-3  # the damping changes lambda
    for backend, module in modules.items():
        assert tuple(module["ACTUATED_JOINTS"]) == ("left_motor", "right_motor"), backend
        f = module[NAME]
        if backend == "jax":  # compiled once per shape: eager JAX is slow op by op
            import jax

            f = jax.jit(f)
        if backend == "casadi":  # one state a call
            t, l = (np.array(x) for x in zip(*(_call(backend, f, *m[:3]) for m in motions)))
        else:  # a batch of states (damping given: one jit trace for both calls)
            t, l = _call(backend, f, q, qd, qdd, damping=0.0)
        assert t.shape == (3, 4) and l.shape == (3, 2), backend
        assert relative(t, tau) <= 1e-9 and relative(l, lam) <= 1e-9, backend
        assert not t[:, [1, 3]].any(), backend  # the passive elbows carry nothing
        assert relative(t, t_np) <= 1e-12 and relative(l, l_np) <= 1e-12, backend
        # damping eps: (J_p J_p^T + eps 1) lambda = J_p t_p, as the NumPy module; one state
        # (JAX: the batch again, its shape compiled already)
        if backend == "jax":
            t, l = (x[0] for x in _call(backend, f, q, qd, qdd, damping=0.05))
        else:
            t, l = _call(backend, f, q[0], qd[0], qdd[0], damping=0.05)
        assert t.shape == (4,) and l.shape == (2,), backend
        assert relative(l, l_damped) <= 1e-12 and relative(t, t_damped) <= 1e-12, backend


def test_casadi_c_library(fivebar, tmp_path):
    """The C backend's shared library (CasADi's code generator) exports it too."""
    casadi = need("casadi")
    from eomgen.codegen.functions import select_functions
    from eomgen.codegen.generate import render_files
    from eomgen.common.compiler import c_compiler

    if c_compiler() is None:
        pytest.skip("needs a C compiler")
    model, modules = fivebar
    for f in render_files(model, ["c"], functions=select_functions([NAME])):
        path = tmp_path / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    library = tmp_path / library_name("fivebar")
    f = casadi.external(NAME, str(library))
    (q, qd, qdd, tau, lam), = _motions(model, count=1, seed=5)
    t, l = _call("casadi", f, q, qd, qdd)
    assert relative(t, tau) <= 1e-9 and relative(l, lam) <= 1e-9
