"""MuJoCo's activation dynamics (eomgen.model.Control.dynamics): ``integrator``, ``filter`` and
``filterexact`` actuators read as controls with a state ``act``, generated as
``forward_dynamics_act(q, qd, ctrl, act) = (q̈, act_dot)``.

References, MuJoCo's: ``qacc_smooth`` and ``act_dot`` of ``mj_forward`` (contacts off) at
random states, controls (some beyond ctrlrange) and activations (some beyond actrange, which
MuJoCo applies only when it integrates act). The model: a position servo with a timeconst
(filterexact), a general filter with a ctrlrange, an intvelocity (integrator, actrange), a
general integrator on a fixed tendon with an affine bias, an ``actearly`` filter (its force at
the activation one step ahead, ``act + h act_dot``) with an ``actrange`` that clamps it.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import eomgen
from eomgen.errors import GenerationError, UnsupportedFeatureWarning
from support.extras import need
from support.generated import generated

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

ACTIVATED = """<mujoco model="activated"><worldbody>
  <body name="a"><joint name="j1" axis="0 0 1" damping="0.2" stiffness="1.5"/>
    <geom type="capsule" size="0.04" fromto="0 0 0 0.4 0 0" mass="1.2"/>
    <body name="b" pos="0.4 0 0"><joint name="j2" axis="0 1 0" armature="0.01"/>
      <geom type="capsule" size="0.03" fromto="0 0 0 0.3 0 0.1" mass="0.7"/>
      <body name="c" pos="0.3 0 0.1"><joint name="j3" type="slide" axis="1 0 0"/>
        <geom type="box" size="0.03 0.03 0.03" mass="0.3"/></body>
    </body></body></worldbody>
  <tendon><fixed name="t"><joint joint="j2" coef="0.5"/><joint joint="j3" coef="-1"/></fixed>
  </tendon>
  <actuator><position name="pf" joint="j1" kp="20" kv="1" timeconst="0.1"/>
    <general name="f" joint="j2" dyntype="filter" dynprm="0.05" gainprm="3" ctrlrange="-1 1"
      ctrllimited="true"/>
    <intvelocity name="iv" joint="j3" kp="10" actrange="-0.5 0.5"/>
    <motor name="m" joint="j2" gear="2"/>
    <general name="it" tendon="t" dyntype="integrator" gainprm="2" biastype="affine"
      biasprm="0.3 -1 -0.5"/>
    <general name="early" joint="j1" dyntype="filter" dynprm="0.2" actearly="true"
      actlimited="true" actrange="-0.6 0.6"/>
  </actuator>
</mujoco>"""


@pytest.fixture(scope="module")
def activated(tmp_path_factory):
    folder = tmp_path_factory.mktemp("activated")
    path = folder / "activated.xml"
    path.write_text(ACTIVATED, encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnsupportedFeatureWarning)
        model = eomgen.load(path)
    calls, modules = generated(model, ["forward_dynamics_act"], folder, ("numpy",))
    m = mujoco.MjModel.from_xml_path(str(path))
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    return model, m, calls["numpy"], modules["numpy"]


def test_the_activation_dynamics_are_read(activated):
    model, _, _, module = activated
    assert [(c.name, c.dynamics) for c in model.controls] == [
        ("pf", "filterexact"), ("f", "filter"), ("iv", "integrator"), ("m", None),
        ("it", "integrator"), ("early", "filter")]
    assert module["ACTIVATION_NAMES"] == ("pf", "f", "iv", "it", "early")
    assert [float(c.timeconst) for c in model.controls[:2]] == [0.1, 0.05]
    assert float(model.controls[-1].early) == 0.002  # MuJoCo's default timestep


def test_accelerations_and_activation_rates_are_mujocos(activated):
    model, m, call, _ = activated
    d = mujoco.MjData(m)
    rng = np.random.default_rng(17)
    worst_acc = worst_rate = 0.0
    for _ in range(10):
        q, qd = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)
        ctrl, act = rng.uniform(-2, 2, m.nu), rng.uniform(-1, 1, m.na)
        d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:] = q, qd, ctrl, act
        mujoco.mj_forward(m, d)
        ours = call("forward_dynamics_act", q, qd, ctrl, act)
        assert ours.shape == (3 + 5,)
        worst_acc = max(worst_acc, np.abs(ours[:3] - d.qacc_smooth).max()
                        / np.abs(d.qacc_smooth).max())
        worst_rate = max(worst_rate, np.abs(ours[3:] - d.act_dot).max()
                         / np.abs(d.act_dot).max())
    assert worst_acc < 1e-11 and worst_rate < 1e-14, (worst_acc, worst_rate)


def test_outputs_without_act_refuse_a_model_with_activations(activated):
    model = activated[0]
    with pytest.raises(GenerationError, match="actuator 'pf' has filterexact activation "
                       "dynamics: its force follows its activation act"):
        eomgen.derive(model, ["qdd_ctrl"])


@pytest.mark.slow
def test_every_code_backend_gives_mujocos_activation_rates(activated, tmp_path):
    model, m, _, _ = activated
    calls, _ = generated(model, ["forward_dynamics_act"], tmp_path)
    d = mujoco.MjData(m)
    q, qd = np.array([0.3, -0.6, 0.1]), np.array([0.8, -0.2, 1.1])
    ctrl, act = np.array([0.4, 1.7, -0.3, 0.9, 0.2, 0.5]), np.array([0.1, -0.8, 0.7, -0.3, 0.4])
    d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:] = q, qd, ctrl, act
    mujoco.mj_forward(m, d)
    expected = np.r_[d.qacc_smooth, d.act_dot]
    for name, call in calls.items():
        assert np.allclose(call("forward_dynamics_act", q, qd, ctrl, act), expected,
                           rtol=1e-11, atol=1e-11), name
