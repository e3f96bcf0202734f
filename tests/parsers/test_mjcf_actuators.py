"""MuJoCo's actuators on joints (eomgen.model.Control, eomgen.symbolic.controls) against MuJoCo.

At random states and controls (some outside ctrlrange, some forces beyond forcerange):
actuator_forces against MuJoCo's qfrc_actuator and forward_dynamics_ctrl against qacc_smooth
(mj_forward, contacts disabled, no joint limits: no constraint forces); their derivative in ctrl
against central differences of forward_dynamics_ctrl. The models: tests/data/mjcf/actuated.xml
(a motor, position and velocity servos, general affine gain and bias, ctrl and force ranges,
damping and armature; one with user-defined activation dynamics left out) and gymnasium's hopper and ant (motors with
gear and ctrlrange; the ant flies: its qvel and forces mapped by eomgen.parsers.mjcf.convert).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnsupportedFeatureWarning
from support.extras import need
from support.generated import generated

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf.convert import layout, to_mujoco  # noqa: E402

DATA = Path(__file__).resolve().parent.parent / "data" / "mjcf"
OUTPUTS = ["actuator_forces", "forward_dynamics_ctrl", "forward_dynamics_ctrl_derivative_ctrl"]


def quiet_load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnsupportedFeatureWarning)
        return eomgen.load(path)


def mujoco_at(m, qpos, qvel, ctrl):
    """MuJoCo's (qfrc_actuator, qacc_smooth) at the state and the controls (contacts off)."""
    m.opt.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
    d = mujoco.MjData(m)
    d.qpos[:], d.qvel[:], d.ctrl[:] = qpos, qvel, ctrl
    mujoco.mj_forward(m, d)
    return d.qfrc_actuator.copy(), d.qacc_smooth.copy()


@pytest.fixture(scope="module")
def arm(tmp_path_factory):
    model = quiet_load(DATA / "actuated.xml")
    calls, modules = generated(model, OUTPUTS, tmp_path_factory.mktemp("arm"), ("numpy",))
    return model, mujoco.MjModel.from_xml_path(str(DATA / "actuated.xml")), calls["numpy"], \
        modules["numpy"]


def test_the_actuators_read_are_mujocos(arm):
    model, m, _, module = arm
    assert module["ACTUATOR_NAMES"] == ("m1", "p2", "v3", "g1", "m3")  # 'own' is left out
    servo = {c.name: c for c in model.controls}["p2"]
    assert (servo.joint, float(servo.gear), [float(x) for x in servo.bias]) == \
        ("j2", 1.5, [0, -30, -2])
    with pytest.warns(UnsupportedFeatureWarning, match="actuator 'own': an actuator with "
                      "its own dynamics"):
        eomgen.load(DATA / "actuated.xml")


def test_forces_and_accelerations_are_mujocos(arm):
    model, m, call, _ = arm
    rng = np.random.default_rng(7)
    worst_force = worst_acc = 0.0
    for _ in range(12):
        q, qd = rng.uniform(-1.5, 1.5, 3), rng.uniform(-3, 3, 3)
        ctrl = rng.uniform(-2, 2, m.nu)  # beyond ctrlrange and forcerange at times
        force, acc = mujoco_at(m, q, qd, ctrl)
        u = ctrl[:5]  # MuJoCo's 'own' has no activation (act = 0): no force
        ours = call("actuator_forces", q, qd, u)
        worst_force = max(worst_force, np.abs(ours - force).max() / np.abs(force).max())
        ours = call("forward_dynamics_ctrl", q, qd, u)
        worst_acc = max(worst_acc, np.abs(ours - acc).max() / np.abs(acc).max())
    assert worst_force < 1e-12 and worst_acc < 1e-11, (worst_force, worst_acc)


def test_the_clamps_hold_where_mujoco_clamps(arm):
    # m1 (ctrlrange ±1): beyond it the force stops growing; m3 (forcerange -1…1.2) saturates
    model, m, call, _ = arm
    q, qd = np.array([0.3, -0.2, 0.1]), np.array([0.5, 1.0, -0.4])
    for ctrl in ([5.0, 0, 0, 0, 0, 0], [-5.0, 0, 0, 0, 0.8, 0], [0, 0, 0, 0, -0.5, 0]):
        force, _ = mujoco_at(m, q, qd, ctrl)
        assert np.allclose(call("actuator_forces", q, qd, ctrl[:5]), force, rtol=1e-13,
                           atol=1e-13)


def test_the_derivative_in_ctrl_is_the_central_difference(arm):
    model, m, call, _ = arm
    rng = np.random.default_rng(3)
    for _ in range(4):
        q, qd, u = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 5)
        jac = call("forward_dynamics_ctrl_derivative_ctrl", q, qd, u)
        h = 1e-6
        diff = np.column_stack([
            (call("forward_dynamics_ctrl", q, qd, u + h * e)
             - call("forward_dynamics_ctrl", q, qd, u - h * e)) / (2 * h) for e in np.eye(5)])
        assert jac.shape == (3, 5)
        assert np.abs(jac - diff).max() <= 1e-6 * max(1.0, np.abs(diff).max())


@pytest.mark.parametrize("name", ["hopper", "ant"])
def test_gymnasium_motors_are_mujocos(name, tmp_path):
    path = DATA / "gymnasium" / f"{name}.xml"
    model = quiet_load(path)
    m = mujoco.MjModel.from_xml_path(str(path))
    assert len(model.controls) == m.nu
    call = generated(model, ["actuator_forces"], tmp_path, ("numpy",))[0]["numpy"]
    lay = layout(m, model)
    rng = np.random.default_rng(5)
    q = [rng.uniform(-0.4, 0.4, model.nq)]
    if model.free_flyer:  # a unit quaternion (qx, qy, qz, qw)
        quat = rng.normal(size=4)
        q[0][3:7] = quat / np.linalg.norm(quat)
    q, v = q[0], rng.uniform(-1, 1, model.dof)
    qpos, qvel = to_mujoco(lay, q, v)
    ctrl = rng.uniform(-1.5, 1.5, m.nu)
    force, _ = mujoco_at(m, qpos, qvel, ctrl)
    # the actuators act on hinges only: eomgen's forces are MuJoCo's, in eomgen's order
    assert np.allclose(call("actuator_forces", q, v, ctrl), force[lay.dof_index], rtol=0,
                       atol=1e-13 * np.abs(force).max())


@pytest.mark.slow
def test_every_code_backend_gives_mujocos_forces_and_accelerations(tmp_path):
    model = quiet_load(DATA / "actuated.xml")
    m = mujoco.MjModel.from_xml_path(str(DATA / "actuated.xml"))
    calls, _ = generated(model, OUTPUTS, tmp_path)
    q, qd, ctrl = np.array([0.4, -0.7, 0.2]), np.array([1.1, 0.3, -2.0]), \
        np.array([1.7, 0.2, -1.3, 0.9, 1.5, 0.0])
    force, acc = mujoco_at(m, q, qd, ctrl)
    for name, call in calls.items():
        assert np.allclose(call("actuator_forces", q, qd, ctrl[:5]), force, rtol=1e-12,
                           atol=1e-12), name
        assert np.allclose(call("forward_dynamics_ctrl", q, qd, ctrl[:5]), acc, rtol=1e-11,
                           atol=1e-11), name


#: Springs, a fixed tendon with a spring, a dead band and damping, and two servos.
SPRUNG = """<mujoco model="sprung"><worldbody>
  <body name="a"><joint name="j1" axis="0 0 1" stiffness="3" springref="0.2" damping="0.4"/>
    <geom type="capsule" size="0.04" fromto="0 0 0 0.4 0 0" mass="1.2"/>
    <body name="b" pos="0.4 0 0"><joint name="j2" axis="0 1 0" armature="0.02"/>
      <geom type="capsule" size="0.03" fromto="0 0 0 0.3 0 0.1" mass="0.7"/>
      <body name="c" pos="0.3 0 0.1"><joint name="j3" type="slide" axis="1 0 0" stiffness="40"
          springref="0.05"/><geom type="box" size="0.03 0.03 0.03" mass="0.3"/></body>
    </body></body></worldbody>
  <tendon><fixed name="t" stiffness="5" springlength="-0.1 0.1" damping="0.3">
    <joint joint="j1" coef="1"/><joint joint="j2" coef="-0.5"/></fixed></tendon>
  <actuator><position name="p" joint="j2" kp="20" kv="1"/>
    <motor name="m" joint="j3" gear="2" ctrlrange="-1 1" ctrllimited="true"/></actuator>
</mujoco>"""


def test_springs_and_tendons_are_in_the_forward_dynamics_of_the_controls(tmp_path):
    """forward_dynamics_ctrl holds the passive forces (joint springs, damping, the tendon's
    spring with its dead band and damping): MuJoCo's whole qacc_smooth, and the passive part
    alone is qacc_smooth less what the actuators do."""
    path = tmp_path / "sprung.xml"
    path.write_text(SPRUNG, encoding="utf-8")
    model = quiet_load(path)
    out = tmp_path / "out"
    out.mkdir()
    calls, _ = generated(model, ["forward_dynamics_ctrl", "passive_forces"], out, ("numpy",))
    call = calls["numpy"]
    m = mujoco.MjModel.from_xml_path(str(path))
    rng = np.random.default_rng(11)
    for _ in range(6):
        q, qd, ctrl = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3), rng.uniform(-2, 2, 2)
        _, acc = mujoco_at(m, q, qd, ctrl)
        ours = call("forward_dynamics_ctrl", q, qd, ctrl)
        assert np.abs(ours - acc).max() <= 1e-10 * np.abs(acc).max(), (ours, acc)
        d = mujoco.MjData(m)
        d.qpos[:], d.qvel[:] = q, qd
        mujoco.mj_forward(m, d)
        assert np.abs(call("passive_forces", q, qd) - d.qfrc_passive).max() \
            <= 1e-10 * np.abs(d.qfrc_passive).max()


#: Actuators on two fixed tendons (a position servo with a forcerange, a motor with a
#: ctrlrange; the second tendon has a spring too), a joint actuator beside them, and an
#: actuator on a spatial tendon, which stays warned about and left out.
TENDONS = """<mujoco model="tendons"><worldbody>
  <body name="a"><joint name="j1" axis="0 0 1" damping="0.2"/>
    <geom type="capsule" size="0.04" fromto="0 0 0 0.4 0 0" mass="1.2"/><site name="s1"/>
    <body name="b" pos="0.4 0 0"><joint name="j2" axis="0 1 0" armature="0.02"/>
      <geom type="capsule" size="0.03" fromto="0 0 0 0.3 0 0.1" mass="0.7"/>
      <body name="c" pos="0.3 0 0.1"><joint name="j3" type="slide" axis="1 0 0"/>
        <geom type="box" size="0.03 0.03 0.03" mass="0.3"/><site name="s2"/></body>
    </body></body></worldbody>
  <tendon><fixed name="t"><joint joint="j1" coef="1"/><joint joint="j2" coef="-0.5"/></fixed>
    <fixed name="u" stiffness="4" springlength="0.1"><joint joint="j2" coef="0.7"/>
      <joint joint="j3" coef="2"/></fixed>
    <spatial name="rope"><site site="s1"/><site site="s2"/></spatial></tendon>
  <actuator><position name="pt" tendon="t" kp="20" kv="1" gear="1.5" forcerange="-4 4"/>
    <motor name="mu" tendon="u" gear="2" ctrlrange="-1 1"/>
    <general name="gj" joint="j3" gainprm="2 0.5 0.3" gaintype="affine" biastype="affine"
      biasprm="0.1 -1 -0.2"/>
    <motor name="spatial" tendon="rope"/></actuator>
</mujoco>"""


@pytest.fixture(scope="module")
def tendons(tmp_path_factory):
    folder = tmp_path_factory.mktemp("tendons")
    path = folder / "tendons.xml"
    path.write_text(TENDONS, encoding="utf-8")
    with pytest.warns(UnsupportedFeatureWarning) as caught:
        model = eomgen.load(path)
    calls, _ = generated(model, ["actuator_forces", "forward_dynamics_ctrl"], folder,
                         ("numpy",))
    return model, mujoco.MjModel.from_xml_path(str(path)), calls["numpy"], \
        [str(w.message) for w in caught]


def test_actuators_on_fixed_tendons_are_read_and_the_spatial_one_is_warned(tendons):
    model, _, _, warned = tendons
    assert [(c.name, c.joint, c.tendon) for c in model.controls] == [
        ("pt", None, "t"), ("mu", None, "u"), ("gj", "j3", None)]
    assert [(n, float(c)) for n, c in model.controls[1].transmission] == [("j2", 0.7),
                                                                         ("j3", 2.0)]
    actuators = [w for w in warned if ": actuator" in w or "actuators" in w.split(":")[1]]
    assert len(actuators) == 1 and "actuator 'spatial': an actuator on a spatial tendon" \
        in actuators[0], warned


def test_tendon_actuators_give_mujocos_forces_and_accelerations(tendons):
    model, m, call, _ = tendons
    rng = np.random.default_rng(13)
    worst_force = worst_acc = 0.0
    for _ in range(8):
        q, qd = rng.uniform(-1, 1, 3), rng.uniform(-2, 2, 3)
        ctrl = rng.uniform(-2, 2, m.nu)  # beyond ctrlrange and forcerange at times
        ctrl[3] = 0.0  # the spatial tendon's motor, left out
        force, acc = mujoco_at(m, q, qd, ctrl)
        worst_force = max(worst_force, np.abs(call("actuator_forces", q, qd, ctrl[:3]) - force)
                          .max() / np.abs(force).max())
        worst_acc = max(worst_acc, np.abs(call("forward_dynamics_ctrl", q, qd, ctrl[:3]) - acc)
                        .max() / np.abs(acc).max())
    assert worst_force < 1e-12 and worst_acc < 1e-11, (worst_force, worst_acc)


def test_a_locked_joint_of_a_tendon_stays_in_its_length(tendons):
    """A scene holding j1 at 0.3: the tendon servo's length keeps j1's share (its position
    bias), so the forces on j2 and j3 are the whole model's at q1 = 0.3."""
    from eomgen.model.robot import lock_joints

    model, _, call, _ = tendons
    held = lock_joints(model, {"j1": 0.3})
    assert [float(c) for c in (held.controls[0].offset,)] == [0.3]
    module = eomgen.derive(held, outputs=("tau_act",)).lambdify().module
    q, qd, u = np.array([-0.4, 0.2]), np.array([0.7, -1.1]), np.array([0.5, 0.3, -0.2])
    whole = call("actuator_forces", np.r_[0.3, q], np.r_[0.0, qd], u)
    assert np.allclose(np.ravel(module.actuator_forces(q, qd, u)), whole[1:], rtol=1e-14,
                       atol=1e-14)
