"""MuJoCo's PID actuators (``<pid>``, MuJoCo 4) on their position input: a position servo
``kp (c − l) − kv v``, with an integral gain the state ``act = z`` (``act_dot = c − l``, the
force ``+ ki z``), also through ``<general dyntype="pid">`` with ``actearly`` and an
``actrange``; on joints and a fixed tendon, with ctrl and force ranges. References: MuJoCo's
``qacc_smooth`` and ``act_dot`` at random states, setpoints and integrals. A PID with several
inputs (the default ``pos vel``: two controls for one actuator, MuJoCo 4's ``nu`` is then
not its actuator count), ``slewmax`` or ``imax`` is warned about by attribute.
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


PIDS = f"""<mujoco model="pids">{MJCF_ARM_WITH_TENDON}<actuator>
 <pid name="p1" joint="j1" kp="5" kv="0.5" input="pos" gear="2"/>
 <pid name="p2" joint="j2" kp="8" kv="0.3" ki="2" input="pos" ctrlrange="-1 1"
   ctrllimited="true" forcerange="-3 3" forcelimited="true"/>
 <general name="p3" tendon="t" dyntype="pid" gaintype="pid" biastype="affine" gainprm="1.5"
   biasprm="0 -4 0" dynprm="0" input="pos" actearly="true" actlimited="true"
   actrange="-0.4 0.4"/>
 <motor name="m" joint="j3" gear="2"/>
</actuator></mujoco>"""

LEFT_OUT = f"""<mujoco model="pid_left_out">{MJCF_ARM_WITH_TENDON}<actuator>
 <pid name="both" joint="j1" kp="5"/>
 <pid name="slewed" joint="j2" kp="5" input="pos" slewmax="2"/>
 <pid name="capped" joint="j3" kp="5" ki="1" imax="0.3" input="pos"/>
 <motor name="m" joint="j3"/>
</actuator></mujoco>"""


@pytest.fixture(scope="module")
def pids():
    m = mujoco.MjModel.from_xml_string(PIDS)
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnsupportedFeatureWarning)
        model = model_from_mujoco(m, "pids.xml")
    return m, model, eomgen.derive(model, outputs=("xd_act",)).lambdify().module


def test_the_pids_are_read(pids):
    _, model, module = pids
    assert [(c.name, c.dynamics) for c in model.controls] == [
        ("p1", None), ("p2", "pid"), ("p3", "pid"), ("m", None)]
    p1, p2, p3, _ = model.controls
    assert [float(x) for x in p1.gain + p1.bias] == [5, 0, 0, 0, -5, -0.5]
    assert float(p2.integral) == 2 and p2.early is None
    assert float(p3.early) == 0.004 and [float(x) for x in p3.actrange] == [-0.4, 0.4]
    assert module.ACTIVATION_NAMES == ("p2", "p3")


def test_pids_are_mujocos(pids):
    """Integrals beyond the actrange (its clamp of the early integral met) and within."""
    m, _, module = pids
    d = mujoco.MjData(m)
    rng = np.random.default_rng(4)
    for _ in range(8):
        q, qd = rng.uniform(-2, 2, m.nq), rng.uniform(-3, 3, m.nv)
        ctrl, act = rng.uniform(-2, 2, m.nu), rng.uniform(-0.8, 0.8, m.na)
        d.qpos[:], d.qvel[:], d.ctrl[:], d.act[:] = q, qd, ctrl, act
        mujoco.mj_forward(m, d)
        ours = module.forward_dynamics_act(q, qd, ctrl, act).ravel()
        assert relative(ours[:3], d.qacc_smooth) < 1e-12
        assert relative(ours[3:], d.act_dot) < 1e-12


def test_features_left_out_are_warned_by_attribute():
    m = mujoco.MjModel.from_xml_string(LEFT_OUT)
    assert m.nu == 5  # 'both' takes two controls
    with pytest.warns(UnsupportedFeatureWarning) as found:
        model = model_from_mujoco(m, "pid_left_out.xml")
    said = "\n".join(str(w.message) for w in found)
    for name, feature in (("both", "input"), ("slewed", "slewmax"), ("capped", "imax")):
        assert f"actuator '{name}': a PID's {feature}" in said
    assert [c.name for c in model.controls] == ["m"]
