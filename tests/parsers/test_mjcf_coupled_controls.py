"""The controls' outputs on a model with couplings (issue 41: dm_control's quadruped drives its
legs through tendons under tendon equalities): ``forward_dynamics_ctrl``, its derivatives and
``forward_dynamics_act`` in the independent coordinates, forces mapped by ``Tᵀ``.

References: MuJoCo's equalities are soft, so the constrained accelerations are those of a KKT
system built from MuJoCo's own arrays at eomgen's states (``mj_fullM`` with the armature,
``qfrc_smooth`` with the springs, damping, tendon and actuator forces, the equality rows of
``efc_J``: constant for joint and fixed-tendon equalities, so ``J q̈ = 0``), MuJoCo's
``act_dot``, and central differences of eomgen's own q̈ along q, q̇ and ctrl. The model: a joint
equality (an actuated follower), a tendon equality, a servo on a fixed tendon across a leader
and a follower, springs, damping and armature on followers and leaders. (Slow) a coupling
below a free joint and a ball joint with armature, damping and a spring; every code backend
gives the NumPy module's.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import eomgen
from support import model_states, relative
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import model_from_mujoco  # noqa: E402
from eomgen.parsers.mjcf.convert import (full_mass_matrix, layout, to_mujoco,  # noqa: E402
                                         velocity_map)

COUPLED = """<mujoco model="coupledctrl"><option gravity="0.3 -0.2 -9.81">
<flag contact="disable"/></option><worldbody>
<body><joint name="j1" axis="0 0 1" stiffness="2" springref="0.3" damping="0.2" armature="0.03"/>
 <geom type="capsule" size=".04" fromto="0 0 0 .4 0 0" mass="1"/>
 <body pos=".4 0 0"><joint name="j2" axis="0 1 .3" armature="0.02" damping="0.1"/>
  <geom type="capsule" size=".03" fromto="0 0 0 .3 0 .1" mass=".6"/>
  <body pos=".3 0 .1"><joint name="j3" type="slide" axis="1 0 0" armature="0.1"/>
   <geom type="box" size=".03 .03 .03" mass=".3"/>
   <body pos=".05 0 0"><joint name="j4" axis="1 0 0" stiffness="1"/>
    <geom type="capsule" size=".02" fromto="0 0 0 0 .2 0" mass=".2"/>
   </body></body></body></body></worldbody>
<tendon><fixed name="held"><joint joint="j3" coef="1"/><joint joint="j4" coef="0.5"/></fixed>
 <fixed name="drive" stiffness="3" damping="0.2"><joint joint="j1" coef="1"/>
  <joint joint="j4" coef="-0.3"/></fixed></tendon>
<equality><joint joint1="j2" joint2="j1" polycoef="0.1 -0.5 0 0 0"/><tendon tendon1="held"/>
</equality><actuator>ACTUATORS</actuator></mujoco>"""
CTRL = """<motor joint="j2" gear="2"/><position tendon="drive" kp="8" kv="0.5"/>
<velocity joint="j3" kv="2"/><motor joint="j4" ctrlrange="-1 1" ctrllimited="true"/>"""
ACT = CTRL + ('<general joint="j1" dyntype="filter" dynprm="0.2" gainprm="3" biastype="affine" '
              'biasprm="0 -1 -0.1"/>')
OUTPUTS = {"ctrl": ("qdd_ctrl", "dqdd_ctrl_dq", "dqdd_ctrl_dqd", "dqdd_dctrl"),
           "act": ("xd_act",)}


@pytest.fixture(scope="module")
def models():
    """``{name: (model, m, module)}``: the coupled model with plain actuators, and with a
    filter actuator besides (forward_dynamics_act)."""
    out = {}
    for name, actuators in (("ctrl", CTRL), ("act", ACT)):
        m = mujoco.MjModel.from_xml_string(COUPLED.replace("ACTUATORS", actuators))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            model = model_from_mujoco(m, f"{name}.xml")
        out[name] = model, m, eomgen.derive(model, outputs=OUTPUTS[name]).lambdify().module
    return out


def constrained(m, lay, q, v, ctrl, act, rows=2):
    """``(T, q̈ of MuJoCo's KKT system, act_dot)`` at eomgen's state (module docstring), the
    model's ``rows`` equality rows held."""
    data = mujoco.MjData(m)
    data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
    data.ctrl[:], data.act[:] = ctrl, act
    mujoco.mj_forward(m, data)
    full = full_mass_matrix(m, data)
    held = np.asarray(data.efc_type) == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    J = np.asarray(data.efc_J).reshape(data.nefc, m.nv)[held]
    assert len(J) == rows
    K = np.block([[full, J.T], [J, np.zeros((len(J), len(J)))]])
    qdd = np.linalg.solve(K, np.r_[data.qfrc_smooth, np.zeros(len(J))])[:m.nv]
    return velocity_map(lay, data.qpos), qdd, data.act_dot.copy()


def samples(model, m, seed):
    rng = np.random.default_rng(seed)
    for q, v in model_states(model, count=3, seed=seed):
        yield q, v, rng.uniform(-2, 2, m.nu), rng.uniform(-1, 1, m.na)


def test_the_followers_leave_the_coordinates(models):
    model = models["ctrl"][0]
    assert model.joint_names == ("j1", "j4")
    assert sorted(c.follower for c in model.couplings) == ["j2", "j3"]


def test_forward_dynamics_ctrl_is_the_constrained_mujoco_acceleration(models):
    model, m, module = models["ctrl"]
    lay = layout(m, model)
    for q, v, u, act in samples(model, m, 2):
        T, qdd, _ = constrained(m, lay, q, v, u, act)
        ours = module.forward_dynamics_ctrl(q, v, u).ravel()
        assert ours.shape == (2,)
        assert relative(T @ ours, qdd) < 1e-12


def test_forward_dynamics_act_is_the_constrained_mujoco_acceleration(models):
    model, m, module = models["act"]
    lay = layout(m, model)
    for q, v, u, act in samples(model, m, 3):
        T, qdd, act_dot = constrained(m, lay, q, v, u, act)
        ours = module.forward_dynamics_act(q, v, u, act).ravel()
        assert relative(T @ ours[:2], qdd) < 1e-12
        assert np.allclose(ours[2:], act_dot, rtol=1e-13, atol=1e-13)


def differences(f, x, h=1e-6):
    return np.column_stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(len(x))])


def test_the_derivatives_are_central_differences(models):
    _, m, module = models["ctrl"]
    worst = 0.0
    for q, v, u, _ in samples(models["ctrl"][0], m, 4):
        def f(x, y, w):
            return module.forward_dynamics_ctrl(x, y, w).ravel()
        worst = max(worst,
                    relative(module.forward_dynamics_ctrl_derivative_q(q, v, u),
                             differences(lambda x: f(x, v, u), q)),
                    relative(module.forward_dynamics_ctrl_derivative_qd(q, v, u),
                             differences(lambda y: f(q, y, u), v)),
                    relative(module.forward_dynamics_ctrl_derivative_ctrl(q, v, u),
                             differences(lambda w: f(q, v, w), u)))
    assert worst < 1e-6, worst


@pytest.mark.slow
def test_every_code_backend_gives_the_numpy_module(models, tmp_path):
    from support.derivatives import results
    from support.generated import generated

    for name, functions in (("ctrl", ["forward_dynamics_ctrl", "forward_dynamics_ctrl_derivatives",
                                      "forward_dynamics_ctrl_derivative_ctrl"]),
                            ("act", ["forward_dynamics_act"])):
        model, m, _ = models[name]
        folder = tmp_path / name
        folder.mkdir()
        _, modules = generated(model, functions, folder)
        q, v, u, act = next(samples(model, m, 7))
        inputs = (q, v, u) if name == "ctrl" else (q, v, u, act)
        for f in functions:
            reference = results("numpy", modules["numpy"], f, *inputs)
            for backend, module in modules.items():
                for ours, theirs in zip(results(backend, module, f, *inputs), reference):
                    assert np.allclose(np.reshape(ours, theirs.shape), theirs, rtol=1e-12,
                                       atol=1e-12), (backend, f)


def floating_mjcf() -> str:
    """tests/data/mjcf/coupled_floating.xml (a free joint, a ball hip, a knee–ankle equality)
    with armature, damping and a spring on the ball and the hinges, a servo on the follower
    and a motor."""
    from pathlib import Path

    text = (Path(__file__).resolve().parent.parent / "data" / "mjcf"
            / "coupled_floating.xml").read_text(encoding="utf-8")
    for old, new in (('pos="0 0 0.05"/>', 'pos="0 0 0.05" armature="0.05" damping="0.2" '
                                          'stiffness="1"/>'),
                     ('ref="0.2"/>', 'ref="0.2" armature="0.02"/>'),
                     ('ref="-0.1"/>', 'ref="-0.1" armature="0.03" damping="0.1"/>'),
                     ("</equality>", '</equality><actuator><position joint="ankle" kp="5" '
                                     'kv="0.3"/><motor joint="shoulder"/></actuator>'),
                     ('<option gravity="0.3 -0.2 -9.81"/>',
                      '<option gravity="0.3 -0.2 -9.81"><flag contact="disable"/></option>')):
        assert old in text
        text = text.replace(old, new)
    return text


@pytest.mark.slow
def test_a_coupling_below_a_free_joint_and_a_ball_with_armature():
    """The constrained accelerations (the free joint's ``qacc = T v̇ + Ṫ v``) and the
    derivatives along the tangent (eomgen's ``integrate``)."""
    from eomgen.model.configuration import integrate

    m = mujoco.MjModel.from_xml_string(floating_mjcf())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        model = model_from_mujoco(m, "floating.xml")
    module = eomgen.derive(model, outputs=OUTPUTS["ctrl"][:3]).lambdify().module
    lay, h, worst = layout(m, model), 1e-6, 0.0
    for q, v, u, _ in samples(model, m, 5):
        T, qdd, _ = constrained(m, lay, q, v, u, [], rows=1)
        drift = np.zeros(m.nv)
        drift[0:3] = T[0:3, 0:3] @ np.cross(v[3:6], v[0:3])
        assert relative(T @ module.forward_dynamics_ctrl(q, v, u).ravel() + drift, qdd) < 1e-12

        def f(x, y):
            return module.forward_dynamics_ctrl(x, y, u).ravel()
        along = np.column_stack([(f(integrate(q, h * e, model=model), v)
                                  - f(integrate(q, -h * e, model=model), v)) / (2 * h)
                                 for e in np.eye(model.dof)])
        worst = max(worst, relative(module.forward_dynamics_ctrl_derivative_q(q, v, u), along),
                    relative(module.forward_dynamics_ctrl_derivative_qd(q, v, u),
                             differences(lambda y: f(q, y), v)))
    assert worst < 1e-6, worst
