"""The names of q's and v's entries are unique (``CONFIGURATION_NAMES``, ``JOINT_NAMES`` of
every generated module): a joint named like an entry of a compound joint is refused in one line
naming it and the compound joint, in every format and through a scene; the names that do not
collide are read as before (identity: the same model without the clash has the entries the
kinds say)."""

from __future__ import annotations

import pytest

import eomgen
from eomgen.errors import DescriptionError, EomgenError
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import run_in_process, write
from support.extras import need

ARM = """name: clash
links:
  - {name: base}
  - {name: arm, mass: 1.0, com: [0, 0, -0.5], inertia: {ixx: 0.1, iyy: 0.1, izz: 0.05}}
  - {name: tip, mass: 0.5, com: [0, 0, -0.1], inertia: {ixx: 0.01, iyy: 0.01, izz: 0.01}}
joints:
  - {name: %s, type: %s, parent: base, child: arm}
  - {name: %s, type: revolute, parent: arm, child: tip, axis: [1, 0, 0]}
"""

MJCF = """<mujoco model="clash">
  <worldbody>
    <body name="trunk" pos="0 0 1">
      <freejoint name="root"/>
      <geom type="box" size="0.2 0.1 0.05" mass="5"/>
      <body name="leg" pos="0 0 -0.1">
        <joint name="%s" type="hinge" axis="1 0 0"/>
        <geom type="capsule" fromto="0 0 0 0 0 -0.3" size="0.02" mass="0.5"/>
      </body>
    </body>
  </worldbody>
</mujoco>
"""


@pytest.mark.parametrize("compound, kind, other", [
    ("shoulder", "spherical", "shoulder_qy"),
    ("slide", "planar", "slide_cos"),
    ("slide", "planar", "slide_x"),
])
def test_a_joint_named_like_a_compound_entry_is_refused(tmp_path, compound, kind, other):
    path = write(tmp_path / "clash.yaml", ARM % (compound, kind, other))
    with pytest.raises(DescriptionError) as caught:
        eomgen.load(path)
    message = str(caught.value)
    assert message.startswith(f"{path}: joint '{other}': '{other}' is also an entry of the "
                              f"configuration of the ")
    assert f"joint '{compound}'" in message and "\n" not in message


@pytest.mark.parametrize("compound, kind", [("shoulder", "spherical"), ("slide", "planar")])
def test_names_that_do_not_clash_are_the_kinds(tmp_path, compound, kind):
    model = eomgen.load(write(tmp_path / "ok.yaml", ARM % (compound, kind, "elbow_qy")))
    names = model.configuration_names
    assert len(set(names)) == len(names) and len(set(model.joint_names)) == model.dof
    kind_object = eomgen.model.joints.KINDS[kind]
    assert names[:kind_object.nq] == kind_object.configuration_names(compound)
    assert model.joint_names[:kind_object.nv] == kind_object.velocity_names(compound)


def test_mjcf_hinge_named_like_the_free_flyer_position(tmp_path):
    need("mujoco", reason="MJCF is read by MuJoCo's compiler")
    path = write(tmp_path / "clash.xml", MJCF % "base_qz")
    out = tmp_path / "out"
    done = run_in_process("generate", path, "-o", out, "--backend", "numpy")
    assert done.returncode == 2, done.stderr
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith(f"eomgen: error: {path}: ") and "'base_qz' is also an entry" in last
    assert not out.exists()
    fine = eomgen.load(write(tmp_path / "fine.xml", MJCF % "hip"))
    assert fine.configuration_names[-1] == "hip" and len(set(fine.configuration_names)) == 8


def test_a_scene_floating_base_on_a_robot_with_such_a_joint(tmp_path):
    robot = write(tmp_path / "robot.yaml", (ARM % ("base_y", "revolute", "elbow"))
                  .replace("type: revolute, parent: base", "type: revolute, axis: [0, 1, 0], "
                           "parent: base"))
    scene = write(tmp_path / "scene.yaml", "version: 1\nrobot: clash\nfloating_base: true\n")
    with pytest.raises(EomgenError, match="'base_y' is also an entry of the configuration of "
                                          "the free flyer joint 'base'"):
        apply_scene(eomgen.load(robot), load_scene(scene))
