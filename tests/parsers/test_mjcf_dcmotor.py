"""MuJoCo's DC motors (``<dcmotor>``, :class:`eomgen.model.Control` with ``motor``): without
``inductance`` the affine force ``K/R (V − K v)``, with it the armature current as a state
``act`` (``act_dot = clamp(((V − K v)/R − i)/T, ±di_max)``, the force ``K i`` taken one step
ahead, MuJoCo's ``actearly``), ``saturation`` (the force range and the current rate limit),
``cogging`` (``A sin(N l + φ)``), on joints and a fixed tendon, with ``gear``; an actuator's
``armature`` and ``damping`` (MuJoCo 4: times ``gear²`` on its joint or tendon).

References, MuJoCo's own at random states, voltages (some beyond ``ctrlrange``) and currents
(some within the rate limit, some beyond): ``qfrc_actuator`` against ``actuator_forces`` for
the motors without a state, ``qacc_smooth`` and ``act_dot`` against ``forward_dynamics_act``
beside filters and an integrator with ``actearly``. A DC motor's thermal model, LuGre friction
and on-board controller are warned about and left out, by attribute.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedFeatureWarning
from support import relative
from support.robots import MJCF_ARM_WITH_TENDON
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import model_from_mujoco  # noqa: E402


STATELESS = f"""<mujoco model="stateless">{MJCF_ARM_WITH_TENDON}<actuator>
 <dcmotor name="a" joint="j1" resistance="2" motorconst="0.05" gear="3" armature="0.003"
   damping="0.001"/>
 <dcmotor name="b" joint="j2" nominal="12 0.8 300" cogging="0.02 4 0.3" ctrlrange="-12 12"
   ctrllimited="true" saturation="0.3"/>
 <dcmotor name="c" tendon="t" resistance="1.2" motorconst="0.04 0.06" gear="2" damping="0.02"/>
</actuator></mujoco>"""

CURRENT = f"""<mujoco model="current">{MJCF_ARM_WITH_TENDON}<actuator>
 <dcmotor name="a" joint="j1" resistance="2" motorconst="0.05" gear="3" inductance="0 0.01"/>
 <dcmotor name="b" joint="j2" resistance="1.5" motorconst="0.04 0.06" inductance="0.003 0"
   saturation="0.5 0 30" cogging="0.02 4 0.3" ctrlrange="-12 12" ctrllimited="true"/>
 <dcmotor name="c" tendon="t" nominal="12 0.8 300" inductance="0 0.002" gear="2"/>
 <position name="p" joint="j3" kp="20" timeconst="0.05"/>
 <general name="f" joint="j2" dyntype="filter" dynprm="0.03" gainprm="2" actearly="true"
   actlimited="true" actrange="-0.5 0.5"/>
 <general name="i" joint="j1" dyntype="integrator" gainprm="1" actearly="true"/>
</actuator></mujoco>"""

LEFT_OUT = f"""<mujoco model="left_out">{MJCF_ARM_WITH_TENDON}<actuator>
 <dcmotor name="hot" joint="j1" resistance="2" motorconst="0.05" thermal="1 2 0 0 0 0"/>
 <dcmotor name="sticky" joint="j2" resistance="2" motorconst="0.05" lugre="1 0 0.1 0.2 0.1"/>
 <dcmotor name="servo" joint="j3" resistance="2" motorconst="0.05" input="pos"
   controller="3 0 0.1 0 0 0"/>
 <dcmotor name="plain" joint="j3" resistance="2" motorconst="0.05"/>
</actuator></mujoco>"""


def compiled(xml):
    m = mujoco.MjModel.from_xml_string(xml)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnsupportedFeatureWarning)
        model = model_from_mujoco(m, "dcmotor.xml")
    return m, model


@pytest.fixture(scope="module")
def stateless():
    m, model = compiled(STATELESS)
    return m, model, eomgen.derive(model, outputs=("tau_act", "qdd_ctrl")).lambdify().module


@pytest.fixture(scope="module")
def current():
    m, model = compiled(CURRENT)
    return m, model, eomgen.derive(model, outputs=("xd_act",)).lambdify().module


def test_the_motors_are_read(stateless, current):
    assert [(c.name, c.dynamics) for c in stateless[1].controls] == [
        ("a", None), ("b", None), ("c", None)]
    a = stateless[1].controls[0]
    assert [float(x) for x in a.gain + a.bias] == [0.025, 0, 0, 0, 0, -0.025 * 0.05]
    drive = stateless[1].joints[0].actuator  # j1's own damping 0.01, the motor's times 3²
    assert (float(drive.armature), float(drive.damping)) == pytest.approx((0.027, 0.019))
    assert float(stateless[1].tendons[0].damping) == pytest.approx(0.08)
    controls = {c.name: c for c in current[1].controls}
    assert [c.dynamics for c in controls.values()] == [
        "dcmotor", "dcmotor", "dcmotor", "filterexact", "filter", "integrator"]
    b = controls["b"]
    assert float(b.rate_limit) == 30 and tuple(float(x) for x in b.cogging) == (0.02, 4, 0.3)
    assert float(b.timeconst) == pytest.approx(0.002)
    T = float(controls["a"].timeconst)
    assert float(controls["a"].early) == pytest.approx(T * (1 - np.exp(-0.004 / T)), rel=1e-15)
    assert float(controls["i"].early) == 0.004 and controls["p"].early is None


def states(m, rng, count=8):
    for _ in range(count):
        yield (rng.uniform(-2, 2, m.nq), rng.uniform(-3, 3, m.nv), rng.uniform(-15, 15, m.nu),
               rng.uniform(-5, 5, m.na))


def test_stateless_motors_are_mujocos(stateless):
    m, _, module = stateless
    d = mujoco.MjData(m)
    for q, qd, ctrl, _ in states(m, np.random.default_rng(1)):
        d.qpos[:], d.qvel[:], d.ctrl[:] = q, qd, ctrl
        mujoco.mj_forward(m, d)
        assert relative(module.actuator_forces(q, qd, ctrl).ravel(), d.qfrc_actuator) < 1e-12
        assert relative(module.forward_dynamics_ctrl(q, qd, ctrl).ravel(),
                        d.qacc_smooth) < 1e-12


def test_motor_currents_are_mujocos(current):
    """Half the states put motor b's current within its rate limit (30 A/s, T = 2 ms: within
    0.06 A of (V − K v)/R), half far from it."""
    m, model, module = current
    d = mujoco.MjData(m)
    b = model.controls[1]
    R, K = (float(x) for x in b.motor)
    limited = 0
    for k, (q, qd, ctrl, act) in enumerate(states(m, np.random.default_rng(2), 10)):
        if k % 2:
            voltage = np.clip(ctrl[1], -12, 12)
            act[1] = (voltage - K * qd[1]) / R + 0.05 * np.sin(k)
        d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:] = q, qd, ctrl, act
        mujoco.mj_forward(m, d)
        limited += abs(d.act_dot[1]) == 30
        ours = module.forward_dynamics_act(q, qd, ctrl, act).ravel()
        assert relative(ours[:3], d.qacc_smooth) < 1e-12
        assert relative(ours[3:], d.act_dot) < 1e-12
    assert limited == 5


def test_features_left_out_are_warned_by_attribute():
    m = mujoco.MjModel.from_xml_string(LEFT_OUT)
    with pytest.warns(UnsupportedFeatureWarning) as found:
        model = model_from_mujoco(m, "left_out.xml")
    said = "\n".join(str(w.message) for w in found)
    for name, feature in (("hot", "thermal"), ("sticky", "lugre"), ("servo", "input")):
        assert f"actuator '{name}': a DC motor's {feature}" in said
    assert [c.name for c in model.controls] == ["plain"]


@pytest.mark.slow
def test_every_code_backend_gives_mujocos_currents(current, tmp_path):
    from support.generated import generated

    m, model, _ = current
    calls, _ = generated(model, ["forward_dynamics_act"], tmp_path)
    d = mujoco.MjData(m)
    q, qd, ctrl, act = next(states(m, np.random.default_rng(7), 1))
    d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:] = q, qd, ctrl, act
    mujoco.mj_forward(m, d)
    for name, call in calls.items():
        ours = np.asarray(call("forward_dynamics_act", q, qd, ctrl, act)).ravel()
        assert relative(ours[:3], d.qacc_smooth) < 1e-11, name
        assert relative(ours[3:], d.act_dot) < 1e-11, name
