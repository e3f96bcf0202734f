"""MJCF input (eomgen.parsers.mjcf): models read through MuJoCo's compiler agree with MuJoCo.

Against MuJoCo itself, at random states, through the layout and velocity map of
eomgen.parsers.mjcf.convert: M (armature removed) against mj_fullM minus the armature, the
drive mass matrix against mj_fullM, h = τ(q, v, 0) against qfrc_bias, the drives' damping
against qfrc_damper and the spring the warning names against qfrc_spring; link frames against
MuJoCo's body poses with q = qpos. The models: two written for these tests (tests/data/mjcf:
refs, anchors, several joints in a body, defaults and childclass, degrees, a free joint that is
not MuJoCo's first) and gymnasium's hopper and ant (tests/data/mjcf/gymnasium, MIT).
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.errors import UnknownFormatError, UnsupportedError, UnsupportedFeatureWarning
from eomgen.model import joint_actuators
from support import model_states, relative, run_cli
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.numeric.newton_euler import link_poses, numeric_model  # noqa: E402
from eomgen.parsers.mjcf import MujocoCompileError, compile_mjcf, is_mjcf  # noqa: E402
from eomgen.parsers.mjcf.convert import (  # noqa: E402
    layout, mujoco_dynamics, to_eomgen, to_mujoco)
from eomgen.parsers.mjcf.tree import rotation_of_quaternion  # noqa: E402

DATA = Path(__file__).resolve().parent.parent / "data" / "mjcf"
TOLERANCE = 1e-10


def quiet_load(path, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UnsupportedFeatureWarning)
        return eomgen.load(path, **options)


@pytest.fixture(scope="module")
def derived():
    """``{file: (model, compiled, module)}``: each model derived once (M, h; and the drive
    outputs for the fixed-base ones), its NumPy module in memory."""
    out = {}
    for name in ("arm.xml", "floating.xml", "ball.xml", "gymnasium/hopper.xml",
                 "gymnasium/ant.xml"):
        model = quiet_load(DATA / name)
        outputs = ("M", "h", "M_a", "tau_f")
        out[name] = (model, compile_mjcf(DATA / name),
                     eomgen.derive(model, outputs=outputs).lambdify().module)
    return out


states = model_states


@pytest.mark.parametrize("name", ["arm.xml", "floating.xml", "ball.xml",
                                  "gymnasium/hopper.xml", "gymnasium/ant.xml"])
def test_dynamics_agree_with_mujoco(derived, name):
    model, m, module = derived[name]
    lay = layout(m, model)
    drives = joint_actuators(model)
    armature = np.array([float(a.armature) for a in drives])
    damping = np.array([float(a.damping) for a in drives])
    friction = np.array([float(a.friction) for a in drives])
    for q, v in states(model):
        ref = mujoco_dynamics(m, lay, q, v)
        M = module.mass_matrix(q).reshape(ref["M"].shape)
        assert relative(M, ref["M"]) < TOLERANCE
        assert relative(module.nonlinear_effects(q, v).ravel(), ref["h"]) < TOLERANCE
        assert relative(M + np.diag(armature), ref["M_a"]) < TOLERANCE
        assert np.allclose(-damping * v, ref["damper"], rtol=TOLERANCE, atol=1e-14)
        # the generated drive outputs (ball joints' too: their drive on each dof)
        assert relative(module.drive_mass_matrix(q), ref["M_a"]) < TOLERANCE
        tau_f = module.friction_torque(v).ravel() - friction * np.sign(v)
        assert relative(tau_f, -ref["damper"]) < TOLERANCE
        if armature.any():
            assert relative(module.drive_mass_matrix(q), M) > 1e-6  # armature is there


def test_the_arm_has_what_the_test_needs(derived):
    """The arm's anchors, refs, drives and several-joint body are really there."""
    model, m, _ = derived["arm.xml"]
    assert np.count_nonzero(m.qpos0) == 3  # refs of slider, shoulder, wrist_slide
    assert np.count_nonzero(m.jnt_pos.any(axis=1)) == 3  # anchors off the body origins
    assert list(m.body_jntnum) == [0, 1, 1, 3, 0, 0]
    drives = {j.name: j.actuator for j in model.movable_joints}
    assert float(drives["shoulder"].friction) == 0.4
    assert float(drives["shoulder"].damping) == 0.1  # childclass "light"
    assert float(drives["slider"].damping) == 0.3


def test_q_is_qpos_and_link_frames_are_body_frames(derived):
    """Hinge and slide joints: eomgen's q is MuJoCo's qpos (refs included), and each body's
    link frame is MuJoCo's body frame (xpos, xquat)."""
    model, m, _ = derived["arm.xml"]
    nm = numeric_model(model)
    data = mujoco.MjData(m)
    for qpos, _ in states(model):
        data.qpos[:] = qpos
        mujoco.mj_kinematics(m, data)
        poses = link_poses(nm, to_eomgen(layout(m, model), qpos))
        for b in range(1, m.nbody):
            R, p = poses[m.body(b).name]
            assert np.allclose(p, data.xpos[b], atol=1e-12)
            assert np.allclose(R, rotation_of_quaternion(data.xquat[b]), atol=1e-12)


def test_names_order_and_motors(derived):
    model, m, _ = derived["arm.xml"]
    assert model.joint_names == ("slider", "shoulder", "joint2", "wrist_slide", "wrist")
    assert m.joint(2).name == ""  # the unnamed joint: MuJoCo's id 2
    assert dict(model.info)["mujoco_motors"] == (("push", "slider", 20.0),)
    assert np.allclose(model.gravity, [0.3, -0.2, -9.7])
    floating, m, _ = derived["floating.xml"]
    assert floating.free_flyer and floating.nq == 10
    assert floating.joint_names[6:] == ("hip", "knee", "rail_x")  # free flyer first
    assert [m.joint(j).name for j in range(m.njnt)] == ["rail_x", "ball_root", "root", "hip",
                                                         "knee"]
    assert dict(floating.info)["mujoco_free_joint"] == "root"
    assert "ball" not in floating.link_by_name  # the second free body, dropped


def test_free_joint_layout_against_mujoco_qpos(derived):
    """The free joint: eomgen's q has (x, y, z, qx, qy, qz, qw) where MuJoCo's qpos has
    (x, y, z, qw, qx, qy, qz); eomgen's v the body-frame linear velocity where MuJoCo's qvel has
    the world-frame one."""
    model, m, _ = derived["floating.xml"]
    lay = layout(m, model)
    ball = [9, 9, 9, 1, 0, 0, 0]
    qpos = np.array([0.7, *ball, 1, 2, 3, 0.5, 0.5, 0.5, 0.5, -0.4, 0.9])
    qvel = np.array([0.3, *[9] * 6, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0])
    q, v = to_eomgen(lay, qpos, qvel)
    assert list(q) == [1, 2, 3, 0.5, 0.5, 0.5, 0.5, -0.4, 0.9, 0.7]
    R = rotation_of_quaternion(qpos[11:15])
    assert np.allclose(v[:3], R.T @ qvel[7:10]) and list(v[3:]) == [4, 5, 6, 7, 8, 0.3]


def test_a_second_free_body_is_dropped_with_a_warning():
    with pytest.warns(UnsupportedFeatureWarning) as caught:
        model = eomgen.load(DATA / "floating.xml")
    messages = [str(w.message) for w in caught]
    assert any("joint 'ball_root' (free, body 'ball'): a second free body (body 'trunk' "
               "flies)" in text and "dropped with the 1 bodies and 1 joints" in text
               for text in messages), messages
    assert "ball_root" not in model.joint_names
    with pytest.raises(UnsupportedError, match="ball_root"):
        eomgen.load(DATA / "floating.xml", strict=True)


def test_nothing_of_the_arm_is_left_out():
    """arm.xml's spring (on 'wrist') is modelled (test_mjcf_passive.py) and its position servo
    is a control (test_mjcf_actuators.py): it loads without a warning, under --strict too."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", UnsupportedFeatureWarning)
        model = eomgen.load(DATA / "arm.xml")
        assert eomgen.load(DATA / "arm.xml", strict=True).joint_names == model.joint_names
    assert [c.name for c in model.controls] == ["push", "servo"]
    assert next(j for j in model.joints if j.name == "wrist").spring is not None


def test_the_spring_of_the_model_is_mujocos(derived):
    model, m, _ = derived["arm.xml"]
    lay = layout(m, model)
    spring = next(j.spring for j in model.joints if j.name == "wrist")
    k, springref = float(spring.stiffness), float(spring.reference)
    assert (k, springref) == (2.0, pytest.approx(np.radians(10)))
    for q, v in states(model):
        expected = np.zeros(model.dof)
        expected[4] = -k * (q[4] - springref)
        assert relative(mujoco_dynamics(m, lay, q, v)["spring"], expected) < TOLERANCE


WORLD = """<mujoco model="t"><worldbody>
<body name="a"><joint name="j1" axis="0 1 0"/><geom size="0.1"/>
<body name="b" pos="0.3 0 0"><joint name="j2" axis="0 1 0"/><geom size="0.1"/>
<body name="c" pos="0.3 0 0"><joint name="j3" axis="0 1 0"/><geom size="0.1"/>
</body></body></body>{extra_bodies}</worldbody>{extra}</mujoco>"""

REFUSED = {
    "quadratic joint equality": ("", "<equality><joint name='couple' joint1='j1' joint2='j2' "
                                 "polycoef='0 1 0.5 0 0'/></equality>",
                                 "equality 'couple' (joint): a joint equality of order 2"),
}


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_refused_by_name(tmp_path, case):
    bodies, extra, message = REFUSED[case]
    path = tmp_path / "r.xml"
    path.write_text(WORLD.format(extra_bodies=bodies, extra=extra), encoding="utf-8")
    with pytest.raises(UnsupportedError) as raised:
        quiet_load(path)
    assert message in str(raised.value) and "\n" not in str(raised.value)


WARNED = {
    "connect": ("<connect name='loop' body1='a' body2='c' anchor='0 0 0' active='false'/>",
                "equality 'loop' (connect, inactive): an inactive equality is not modelled"),
    "weld": ("<weld body1='a' body2='c' active='false'/>",
             "equality 'eq0' (weld, inactive): an inactive equality"),
    "tendon": ("<tendon name='te' tendon1='t' polycoef='0 0 1 0 0'/>", "equality 'te' (tendon): "
               "an order 2 equality is not modelled"),  # first order: tests/parsers/test_mjcf_passive.py
    "joint": ("<joint name='mimic' joint1='j3' joint2='j2' polycoef='0 2 0 0 0' active='false'/>",
              "equality 'mimic' (joint, inactive): an inactive equality is not modelled"),
}


@pytest.mark.parametrize("case", sorted(WARNED))
def test_equalities_are_warned_by_name_and_dropped(tmp_path, case):
    element, message = WARNED[case]
    path = tmp_path / "e.xml"
    tendon = ("<tendon><fixed name='t'><joint joint='j1' coef='1'/></fixed></tendon>"
              if case == "tendon" else "")
    path.write_text(WORLD.format(extra_bodies="", extra=f"{tendon}<equality>{element}"
                                 "</equality>"), encoding="utf-8")
    with pytest.warns(UnsupportedFeatureWarning, match=message.replace("(", r"\(")
                      .replace(")", r"\)")):
        model = eomgen.load(path)
    assert model.joint_names == ("j1", "j2", "j3")
    with pytest.raises(UnsupportedError, match="refused under --strict"):
        eomgen.load(path, strict=True)


def test_tendons_and_other_actuators_are_warned_by_name(tmp_path):
    path = tmp_path / "t.xml"
    path.write_text(WORLD.format(extra_bodies="<site name='ws'/>", extra=(
        "<tendon><fixed name='pull'><joint joint='j1' coef='1'/><joint joint='j2' coef='-1'/>"
        "</fixed></tendon><actuator><motor name='m1' joint='j1' gear='3'/>"
        "<motor name='on_tendon' tendon='pull'/><velocity name='damped' joint='j3' kv='2'/>"
        "<motor name='on_site' site='ws'/><motor name='on_site2' site='ws'/></actuator>")),
        encoding="utf-8")
    with pytest.warns(UnsupportedFeatureWarning) as caught:
        model = eomgen.load(path)
    messages = " | ".join(str(w.message) for w in caught)
    assert len(caught) == 1, messages  # the fixed tendon pulls only through its actuator
    for part in ("2 actuators 'on_site', 'on_site2': actuators on a site are not modelled",):
        assert part in messages
    # the velocity servo and the fixed tendon's motor are read; only m1 is a joint's motor
    assert [c.name for c in model.controls] == ["m1", "on_tendon", "damped"]
    assert dict(model.info)["mujoco_motors"] == (("m1", "j1", 3.0),)


def test_compiler_errors_are_one_line(tmp_path):
    path = tmp_path / "bad.xml"
    path.write_text("<mujoco><worldbody><body><joint type='hinge' axis='0 0 0'/><geom size="
                    "'.1'/></body></worldbody></mujoco>", encoding="utf-8")
    with pytest.raises(MujocoCompileError) as raised:
        eomgen.load(path)
    message = str(raised.value)
    assert message.startswith(f"{path}: MuJoCo's compiler: ") and "\n" not in message
    result = run_cli("generate", path, "--output", tmp_path / "out")
    assert result.exit_code == 2 and "MuJoCo's compiler" in result.stderr
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_sniff_and_other_xml(tmp_path):
    assert is_mjcf('<?xml version="1.0"?>\n<!-- a <robot> -->\n<mujoco model="x">')
    assert is_mjcf("<mujoco/>") and not is_mjcf("<robot name='r'/>")
    assert not is_mjcf("<mujocoX/>")
    path = tmp_path / "urdf.xml"
    path.write_text("<robot name='r'><link name='a'/></robot>", encoding="utf-8")
    with pytest.raises(UnknownFormatError, match="not an MJCF file"):
        eomgen.load(path)


def test_without_mujoco_the_error_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "mujoco", None)
    with pytest.raises(UnsupportedError, match=r"pip install 'eomgen\[simulators\]'"):
        eomgen.load(DATA / "arm.xml")


def test_cli_generates_from_mjcf(tmp_path):
    result = run_cli("generate", DATA / "gymnasium" / "hopper.xml", "--backend", "numpy",
                     "--output", tmp_path)
    assert result.exit_code == 0, result.output
    namespace: dict = {}
    exec((tmp_path / "hopper_numpy.py").read_text(encoding="utf-8"), namespace)
    assert namespace["JOINT_NAMES"] == ("rootx", "rootz", "rooty", "thigh_joint", "leg_joint",
                                        "foot_joint")


def test_compiler_warnings_are_python_warnings(tmp_path, capfd):
    path = tmp_path / "w.xml"
    path.write_text(WORLD.replace("<worldbody>", "<compiler settotalmass='5'/><worldbody>")
                    .format(extra_bodies="", extra=""), encoding="utf-8")
    with pytest.warns(UserWarning, match="MuJoCo's compiler: compiler attribute 'settotalmass'"):
        model = eomgen.load(path)
    assert "settotalmass" not in capfd.readouterr().err  # not also printed by MuJoCo
    masses = [float(link.inertial.mass) for link in model.links if link.inertial is not None]
    assert sum(masses) == pytest.approx(5.0, rel=1e-12)  # the compiler's masses


def test_states_round_trip_and_a_last_free_body_is_left_at_rest(tmp_path, derived):
    model, m, _ = derived["floating.xml"]
    lay = layout(m, model)
    q, v = next(states(model))
    qpos, qvel = to_mujoco(lay, q, v)
    assert (qpos.shape, qvel.shape) == ((m.nq,), (m.nv,))
    q2, v2 = to_eomgen(lay, qpos, qvel)
    # at round-off: v goes through the rotation of the quaternion and back (T then Tᵀ)
    eps = np.finfo(float).eps
    assert np.max(np.abs(q2 - q)) <= 4 * eps * max(1.0, np.max(np.abs(q)))
    assert np.max(np.abs(v2 - v)) <= 8 * eps * max(1.0, np.max(np.abs(v)))
    path = tmp_path / "last.xml"  # the dropped ball's coordinates after every other one
    path.write_text("<mujoco><worldbody><body name='box'><freejoint name='root'/>"
                    "<geom type='box' size='.1 .2 .3'/><body name='arm' pos='.1 0 0'>"
                    "<joint name='j' axis='0 1 1'/><geom size='.05' pos='.1 0 0'/></body>"
                    "</body><body name='ball' pos='1 0 0'><freejoint/><geom size='.1'/>"
                    "</body></worldbody></mujoco>", encoding="utf-8")
    small, m = quiet_load(path), compile_mjcf(path)
    module = eomgen.derive(small, outputs=("M", "h")).lambdify().module
    lay = layout(m, small)
    for q, v in states(small, count=2):
        ref = mujoco_dynamics(m, lay, q, v)
        assert relative(module.mass_matrix(q), ref["M"]) < TOLERANCE
        assert relative(module.nonlinear_effects(q, v).ravel(), ref["h"]) < TOLERANCE
