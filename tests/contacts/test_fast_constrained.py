"""``constrained_forward_dynamics`` composed in C by the fast module (issue 16).

References: the NumPy module's KKT solve by LU (numpy.linalg.solve of the full system, a
different algorithm from the fast module's Cholesky range-space form) and Pinocchio's
``constraintDynamics`` (CONTACT_3D, LOCAL_WORLD_ALIGNED) on the planar 2-link arm against a
wall (Pinocchio reading the arm's URDF written by tests/reference.py) and on the floating solo12
with its four feet held (through eomgen.numeric.floating_base's map to Pinocchio's free flyer).
"""

from __future__ import annotations

import dataclasses

import warnings

import numpy as np
import pytest

import eomgen
from support import ROOT, erd_robots_dir, load_module
from support.reference import pinocchio_contacts
from eomgen.numeric import floating_base
from eomgen.codegen.functions import select_functions
from eomgen.codegen.generate import render_files
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support.extras import need

WALL = ROOT / "examples/contacts/planar_2link_wall.yaml"
STANDING = ROOT / "examples/contacts/solo12_standing.yaml"
CFD = "constrained_forward_dynamics"


def relative(a, b) -> float:
    return float(np.abs(np.asarray(a) - b).max() / np.abs(b).max())


def _modules(model, tmp_path):
    """(fast, numpy) modules of ``model`` exporting constrained_forward_dynamics."""
    files = render_files(model, ["numpy", "fast"], functions=select_functions([CFD]))
    for f in files:
        path = tmp_path / f.name
        path.write_bytes(f.content) if isinstance(f.content, bytes) else path.write_text(
            f.content, encoding="utf-8")
    libraries = list(tmp_path.glob(f"{model.name}_fast.*.so"))
    if not libraries:
        pytest.skip("no C compiler or Python headers: the fast module was not built")
    loaded = []
    for name, path in ((f"{model.name}_fast", libraries[0]),
                       (f"{model.name}_numpy_{tmp_path.name}", tmp_path / f"{model.name}_numpy.py")):
        module = load_module(path, name)
        loaded.append(module)
    return loaded


# --- the planar arm on a wall -----------------------------------------------------------------

@pytest.fixture(scope="module")
def wall(tmp_path_factory):
    arm = eomgen.load(eomgen.example_path("planar_2link"))
    model = apply_scene(arm, load_scene(WALL)).model
    fast, numpy_module = _modules(model, tmp_path_factory.mktemp("wall"))
    return model, fast, numpy_module


def test_wall_fast_equals_numpy_and_refuses_the_redundant_row(wall):
    model, fast, numpy_module = wall
    assert CFD in fast.__all__ and tuple(fast.CONTACT_ROWS) == tuple(numpy_module.CONTACT_ROWS)
    rng = np.random.default_rng(3)
    q, qd, tau = rng.uniform(-2, 2, (3, 5, 2))
    for damping in (1e-9, 1e-3, 0.5):
        qdd_b, F_b = fast.constrained_forward_dynamics(q, qd, tau, damping=damping)
        assert qdd_b.shape == (5, 2) and F_b.shape == (5, 3)
        for k in range(5):
            qdd, F = fast.constrained_forward_dynamics(q[k], qd[k], tau[k], damping=damping)
            assert qdd.shape == (2,) and F.shape == (3,)
            qdd_np, F_np = numpy_module.constrained_forward_dynamics(q[k], qd[k], tau[k],
                                                                     damping=damping)
            assert relative(qdd, qdd_np) < 1e-12 and relative(F, F_np) < 1e-12, damping
            np.testing.assert_array_equal(qdd_b[k], qdd)  # the batch is the per-state loop
            np.testing.assert_array_equal(F_b[k], F)
    # the wall's z row is zero (planar arm): at damping 0 both modules refuse, alike
    for module in (fast, numpy_module):
        with pytest.raises(np.linalg.LinAlgError, match="dependent rows.*use damping > 0"):
            module.constrained_forward_dynamics(q[0], qd[0], tau[0])
    with pytest.raises(np.linalg.LinAlgError, match="at state 0"):
        fast.constrained_forward_dynamics(q, qd, tau)
    with pytest.raises(ValueError, match="damping must be a finite number >= 0"):
        fast.constrained_forward_dynamics(q[0], qd[0], tau[0], damping=-1.0)
    with pytest.raises(FloatingPointError, match="not finite"):
        fast.constrained_forward_dynamics(q[0], qd[0], np.array([np.nan, 0.0]), damping=1e-9)
    with pytest.raises(TypeError, match="unexpected keyword argument 'return_condition'"):
        fast.constrained_forward_dynamics(q[0], qd[0], tau[0], return_condition=True)


def test_wall_statics_and_pinocchio(wall, tmp_path):
    """Statics (docs/contact.md): tau = g(q) + f (-l1 s1 - l2 s12, -l2 s12) holds the arm still
    with the wall's force (-f, 0, 0); moving, Pinocchio's proximal constraintDynamics."""
    model, fast, numpy_module = wall
    values = {s.name: v for s, v in model.parameter_values.items()}
    l1, l2, m1, m2, lc1, lc2, g0 = (values[k] for k in ("l1", "l2", "m1", "m2", "lc1", "lc2", "g"))
    q = np.array([0.4, 0.9])
    s1, c1, s12, c12 = np.sin(q[0]), np.cos(q[0]), np.sin(q.sum()), np.cos(q.sum())
    f = 3.0
    tau = np.array([(m1 * lc1 + m2 * l1) * g0 * c1 + m2 * lc2 * g0 * c12,
                    m2 * lc2 * g0 * c12]) + f * np.array([-l1 * s1 - l2 * s12, -l2 * s12])
    qdd, F = fast.constrained_forward_dynamics(q, np.zeros(2), tau, damping=1e-12)
    assert np.abs(qdd).max() < 1e-9 and np.allclose(F, [-f, 0, 0], atol=1e-8)

    pin = need("pinocchio", reason="Pinocchio is the reference")
    from support.reference import to_urdf

    path = tmp_path / "planar_2link.urdf"
    path.write_text(to_urdf(eomgen.load(eomgen.example_path("planar_2link"))), encoding="utf-8")
    pm = pin.buildModelFromUrdf(str(path))
    pm.gravity.linear = np.array([0.0, -g0, 0.0])  # the arm's gravity (0, -g, 0)
    pd = pm.createData()
    models, datas = pinocchio_contacts(pm, pd, ["tip"])
    rng = np.random.default_rng(11)
    for _ in range(3):
        q, qd, tau = rng.uniform(-2, 2, (3, 2))
        q[1] = rng.choice([-1, 1]) * rng.uniform(0.5, 2.5)  # elbow bent: damping's bias ~1e-12
        a = pin.constraintDynamics(pm, pd, q, qd, tau, models, datas,
                                   pin.ProximalSettings(1e-14, 1e-12, 20))
        qdd, F = fast.constrained_forward_dynamics(q, qd, tau, damping=1e-12)
        assert relative(qdd, a) <= 1e-8 and relative(F, pd.lambda_c) <= 1e-8


def test_redundant_contacts_need_damping(tmp_path):
    """Tip and elbow held: 4 nonzero contact rows on 2 joints. At damping 0 the fast module
    refuses (as the NumPy module does); with damping > 0 it returns NumPy's damped solution,
    whose contact rows hold up to -damping * F_c (1e-2: the damped KKT matrix then has
    cond ~ 1e3, so two algorithms agree to 1e-12; at 1e-6 they differ by ~5e-11)."""
    arm = eomgen.load(eomgen.example_path("planar_2link"))
    model = apply_scene(arm, load_scene("held.yaml", text="version: 1\ncontacts:\n"
                                        "  - {frame: tip}\n  - {frame: link2}\n")).model
    fast, numpy_module = _modules(model, tmp_path)
    q, qd, tau = np.array([0.3, 1.1]), np.array([0.5, -0.4]), np.array([2.0, 1.0])
    for module in (fast, numpy_module):
        with pytest.raises(np.linalg.LinAlgError, match=r"\(6x2\) has dependent rows"):
            module.constrained_forward_dynamics(q, qd, tau)
    qdd, F = fast.constrained_forward_dynamics(q, qd, tau, damping=1e-2)
    qdd_np, F_np = numpy_module.constrained_forward_dynamics(q, qd, tau, damping=1e-2)
    assert F.shape == (6,) and relative(qdd, qdd_np) < 1e-12 and relative(F, F_np) < 1e-12
    J = numpy_module.contact_jacobian(q)
    assert np.abs(J @ qdd + numpy_module.contact_bias(q, qd) + 1e-2 * F).max() < 1e-12


# --- solo12 with a floating base and four feet held -------------------------------------------

@pytest.mark.slow
def test_solo_fast_equals_numpy_and_pinocchio(tmp_path):
    pin = need("pinocchio", reason="Pinocchio is the reference")
    if erd_robots_dir() is None:
        pytest.skip("example-robot-data is not installed")
    path = erd_robots_dir() / "solo_description/robots/solo12.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = apply_scene(eomgen.load(path), dataclasses.replace(
            load_scene(STANDING), floating_base="euler")).model  # the Euler chart's map
    fast, numpy_module = _modules(model, tmp_path)
    assert len(fast.CONTACT_ROWS) == 12
    ref = floating_base.PinocchioFreeFlyer(path, model.joint_names)
    pm, pd, idx = ref.model, ref.data, ref.idx
    models, datas = pinocchio_contacts(pm, pd, [c.frame for c in model.contacts])
    rng = np.random.default_rng(8)
    batch = []
    for _ in range(3):
        q = rng.uniform(-1, 1, 18)
        q[4] = rng.uniform(-1.2, 1.2)  # pitch away from ±π/2 (the Euler singularity)
        qd, tau = rng.uniform(-1, 1, 18), rng.uniform(-2, 2, 18)
        batch.append((q, qd, tau))
        q_pin, v = ref.state(q, qd)
        T = floating_base.velocity_map(q)  # Pinocchio's v = T q̇
        a = pin.constraintDynamics(pm, pd, q_pin, v, np.linalg.solve(T.T, tau)[idx], models,
                                   datas, pin.ProximalSettings(1e-14, 1e-12, 1))
        a_ours = np.empty(18)
        a_ours[idx] = a
        qdd_pin = np.linalg.solve(T, a_ours - floating_base.velocity_map_dot_qd(q, qd))
        qdd, F = fast.constrained_forward_dynamics(q, qd, tau)
        qdd_np, F_np = numpy_module.constrained_forward_dynamics(q, qd, tau)
        assert relative(qdd, qdd_np) < 1e-12 and relative(F, F_np) < 1e-12
        assert relative(qdd, qdd_pin) <= 1e-8 and relative(F, pd.lambda_c) <= 1e-8
        qdd, F = fast.constrained_forward_dynamics(q, qd, tau, damping=1e-4)
        qdd_np, F_np = numpy_module.constrained_forward_dynamics(q, qd, tau, damping=1e-4)
        assert relative(qdd, qdd_np) < 1e-12 and relative(F, F_np) < 1e-12
    q, qd, tau = (np.array(x) for x in zip(*batch))
    qdd_b, F_b = fast.constrained_forward_dynamics(q, qd, tau)
    for k in range(3):
        qdd, F = fast.constrained_forward_dynamics(q[k], qd[k], tau[k])
        np.testing.assert_array_equal(qdd_b[k], qdd)
        np.testing.assert_array_equal(F_b[k], F)
