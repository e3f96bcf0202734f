"""MJCF equalities (issue 26): first-order ``joint`` equalities read as couplings, checked
against MuJoCo.

References, all MuJoCo's: its own evaluation of each equality (``efc_pos`` of the equality
rows zero at the states eomgen's layout builds, ``efc_J`` annihilating the coupled
velocities: so the gains and offsets, refs and ``c0`` included, are MuJoCo's), and the reduced
dynamics ``M_r = Tᵀ M T`` (``mj_fullM`` less the armature), the drive mass matrix
``Tᵀ mj_fullM T``, ``h_r = Tᵀ qfrc_bias`` and the damping ``Tᵀ qfrc_damper`` at those states.
Models: tests/data/mjcf/coupled.xml (fixed base: a hinge–hinge coupling, a chain of two, a
slide–slide coupling, a joint held by an equality without joint2, an inactive equality) and
coupled_floating.xml (a free joint and a ball joint with a coupling below them).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.errors import KinematicTreeError
from support import load_quietly, model_states, relative
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import compile_mjcf  # noqa: E402
from eomgen.parsers.mjcf.convert import (  # noqa: E402
    layout, mujoco_dynamics, to_eomgen, to_mujoco, velocity_map)

DATA = Path(__file__).resolve().parent.parent / "data" / "mjcf"
TOLERANCE = 1e-10


@pytest.fixture(scope="module")
def derived():
    out = {}
    for name in ("coupled.xml", "coupled_floating.xml"):
        model = load_quietly(DATA / name)
        outputs = ("M", "h") if model.quaternion_joints else ("M", "h", "M_a", "tau_f")
        out[name] = (model, compile_mjcf(DATA / name),
                     eomgen.derive(model, outputs=outputs).lambdify().module)
    return out


states = model_states


def test_followers_and_locked_joints_leave_the_coordinates(derived):
    model = derived["coupled.xml"][0]
    assert model.joint_names == ("slider", "shoulder")
    assert {c.follower: (c.leaders[0][0], float(c.leaders[0][1])) for c in model.couplings} == {
        "elbow": ("shoulder", -0.5), "wrist": ("shoulder", -1.0), "finger": ("slider", 0.3)}
    assert dict(model.info)["mujoco_locks"] == (("twist", 0.25),)
    floating = derived["coupled_floating.xml"][0]
    assert floating.joint_names[6:] == ("hip_wx", "hip_wy", "hip_wz", "knee", "shoulder")
    assert (floating.nq, floating.dof) == (13, 11)


@pytest.mark.parametrize("name", ["coupled.xml", "coupled_floating.xml"])
def test_the_couplings_are_mujocos_equalities(derived, name):
    """At eomgen's states, MuJoCo's own equality rows are satisfied, position and velocity."""
    model, m, _ = derived[name]
    lay = layout(m, model)
    data = mujoco.MjData(m)
    for q, v in states(model):
        data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
        mujoco.mj_forward(m, data)
        rows = np.asarray(data.efc_type) == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        J = np.asarray(data.efc_J).reshape(data.nefc, m.nv)[rows]
        assert rows.sum() == m.neq - (name == "coupled.xml")  # the inactive one has no row
        assert np.abs(np.asarray(data.efc_pos)[rows]).max() < 1e-12
        assert np.abs(J @ velocity_map(lay, data.qpos)).max() < 1e-12
        back = to_eomgen(lay, data.qpos, data.qvel)
        assert np.allclose(back[0], q, atol=1e-14) and np.allclose(back[1], v, atol=1e-12)


@pytest.mark.parametrize("name", ["coupled.xml", "coupled_floating.xml"])
def test_reduced_dynamics_are_mujocos_projected(derived, name):
    model, m, module = derived[name]
    lay = layout(m, model)
    for q, v in states(model):
        ref = mujoco_dynamics(m, lay, q, v)
        M = module.mass_matrix(q).reshape(ref["M"].shape)
        assert ref["M"].shape == (model.dof, model.dof)
        assert relative(M, ref["M"]) < TOLERANCE
        assert relative(module.nonlinear_effects(q, v).ravel(), ref["h"]) < TOLERANCE
        if not model.quaternion_joints:
            assert relative(module.drive_mass_matrix(q), ref["M_a"]) < TOLERANCE
            assert relative(module.friction_torque(v).ravel(), -ref["damper"]) < TOLERANCE
            # the projection is not the independent joints' own drives alone
            assert relative(M + 0.02 * np.eye(model.dof), ref["M_a"]) > 1e-3


def write(tmp_path, equalities: str, joints=("hinge",) * 3) -> Path:
    bodies = "".join(f"<body name='b{k}' pos='0.3 0 0'><joint name='j{k}' type='{kind}' "
                     "axis='0 1 0'/><geom size='0.1'/>" for k, kind in enumerate(joints, 1))
    path = tmp_path / "e.xml"
    path.write_text(f"<mujoco model='t'><worldbody>{bodies}{'</body>' * len(joints)}"
                    f"</worldbody><equality>{equalities}</equality></mujoco>", encoding="utf-8")
    return path


def test_a_follower_coupled_twice_is_refused_by_name(tmp_path):
    path = write(tmp_path, "<joint name='e1' joint1='j3' joint2='j1'/>"
                 "<joint name='e2' joint1='j3' joint2='j2'/>")
    with pytest.raises(KinematicTreeError, match=r"equality 'e2' \(joint\).*'j3' already follows"):
        load_quietly(path)


def test_a_cycle_of_equalities_is_refused_by_name(tmp_path):
    path = write(tmp_path, "<joint name='e1' joint1='j1' joint2='j2'/>"
                 "<joint name='e2' joint1='j2' joint2='j1'/>")
    with pytest.raises(KinematicTreeError, match="cycle|is itself a follower"):
        load_quietly(path)



def test_an_equality_joining_a_dropped_free_body_is_left_out_by_name(tmp_path):
    """A second free body is dropped (tests/parsers/test_mjcf.py); a joint equality or a
    connect between it and the robot goes with it, said by name."""
    path = tmp_path / "d.xml"
    path.write_text("""<mujoco model="d"><worldbody>
      <body name="robot"><freejoint/><geom size="0.1"/>
        <body name="arm" pos="0.3 0 0"><joint name="j1" axis="0 1 0"/><geom size="0.1"/>
          <body name="hand" pos="0.3 0 0"><joint name="j2" axis="0 1 0"/><geom size="0.1"/>
      </body></body></body>
      <body name="ball" pos="2 0 0"><freejoint/><geom size="0.1"/>
        <body name="flap"><joint name="f" axis="1 0 0"/><geom size="0.05"/></body></body>
      </worldbody><equality><joint name="across" joint1="f" joint2="j1"/>
      <connect name="tie" body1="flap" body2="hand" anchor="0 0 0"/>
      <joint name="kept" joint1="j2" joint2="j1" polycoef="0 0.5 0 0 0"/></equality></mujoco>""",
                    encoding="utf-8")
    with pytest.warns(UserWarning) as caught:
        model = eomgen.load(path)
    said = " | ".join(str(w.message) for w in caught)
    assert "equality 'across' (joint): it joins a dropped free body" in said
    assert "equality 'tie': it joins a dropped free body" in said
    assert model.loops == () and [c.follower for c in model.couplings] == ["j2"]
    assert model.joint_names[6:] == ("j1",)
