"""A loop is checked against its mechanism when the model is built (a scene applied, an MJCF
file read: eomgen.numeric.loop_checks), and refused in one line when it does not constrain
what it claims. Each refusal is backed by an independent witness from the derived program
(LoopDynamics, the symbolic loop rows) of the same model built without the check: the motion a
tilted plane lets through opens the loop in 3-D, a rigid triangle's J_l is square and
invertible, a four-bar's loop Jacobian leaves one free direction for two actuated joints. The
degrees of freedom stated for the valid loops are Grübler's (four-bar 1, five-bar 2, Delta 3)
and n − rank of the derived J_l.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import eomgen
from eomgen.errors import InvalidLoopError, SceneError
from eomgen.model import Loop, LoopFrame, Transform, vec3
from eomgen.numeric.loop_checks import LoopRows, check_loops
from eomgen.numeric.loops import LoopDynamics
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT, run_cli, write
from support.extras import need

ROBOTS, LOOPS = ROOT / "examples/robots", ROOT / "examples/loops"
TILTED = "[0.5, 0, 0.8660254037844386]"  # the x-y plane's normal turned 30° about y

SLIDER_CRANK = """name: slider_crank
gravity: [0, -9.81, 0]
links:
  - {name: ground}
  - {name: crank, mass: 1.0, com: [0.1, 0, 0], inertia: {izz: 0.01}}
  - {name: rod, mass: 1.0, com: [0.25, 0, 0], inertia: {izz: 0.02}}
  - {name: slider, mass: 0.5}
joints:
  - {name: crank_joint, type: revolute, parent: ground, child: crank, axis: CRANK_AXIS}
  - {name: rod_joint, type: revolute, parent: crank, child: rod, origin: {xyz: [0.2, 0, 0]},
     axis: [0, 0, 1]}
  - {name: slide, type: prismatic, parent: ground, child: slider, axis: [1, 0, 0]}
"""

TRIANGLE = """name: triangle
gravity: [0, -9.81, 0]
links:
  - {name: ground}
  - {name: one, mass: 1.0, com: [0.25, 0, 0], inertia: {izz: 0.02}}
  - {name: two, mass: 1.0, com: [0.2, 0, 0], inertia: {izz: 0.02}}
joints:
  - {name: j1, type: revolute, parent: ground, child: one, axis: [0, 0, 1]}
  - {name: j2, type: revolute, parent: one, child: two, origin: {xyz: [0.5, 0, 0]},
     axis: [0, 0, 1]}
"""
PIN = "loops:\n  - {name: pin, type: point, a: {link: ground, xyz: [0.6, 0, 0]}, " \
      "b: {link: two, xyz: [0.4, 0, 0]}, plane: [0, 0, 1]}\n"


def scene(name: str, text: str):
    return load_scene(f"{name}.yaml", text="version: 1\n" + text)


def example(robot: str, loops: str, **replace_text):
    text = (LOOPS / f"{loops}.yaml").read_text()
    for old, new in replace_text.items():
        assert old in text
        text = text.replace(old, new)
    return eomgen.load(ROBOTS / f"{robot}.yaml"), load_scene(f"{loops}.yaml", text=text)


def unchecked(model, loops, actuated=()):
    """``model`` carrying ``loops`` without the checks (the witness' model)."""
    return replace(model, loops=tuple(loops), actuated=tuple(actuated))


def refused(model, sc) -> str:
    with pytest.raises(InvalidLoopError) as info:
        apply_scene(model, sc)
    assert isinstance(info.value, SceneError)
    assert "\n" not in str(info.value)
    return str(info.value)


@pytest.mark.parametrize("robot, loops, dof", [
    ("fourbar", "fourbar_loop", 1), ("fivebar", "fivebar_loop", 2), ("delta", "delta_loops", 3),
    ("fivebar", "fivebar_elbow_held", 2)])
def test_every_bundled_loop_is_accepted_with_its_degrees_of_freedom(robot, loops, dof):
    """Grübler's count, stated in the scene notes, and n − rank of the derived J_l at a
    configuration the loops close at (LoopDynamics.assemble)."""
    model, sc = example(robot, loops)
    reduced, report = apply_scene(model, sc)
    (note,) = [n for n in report.notes if n.startswith("loops")]
    assert f"the loops leave {dof} degree" in note
    mobility = check_loops(reduced)
    assert mobility.closed and mobility.dof == dof
    dyn = LoopDynamics(reduced)
    start = {"fourbar": [0.3, 1.0, 2.0], "fivebar": [1.2, 1.0, 1.9, -1.0],
             "delta": [0.3, 2.13, 0.0] * 3 + [0.0, 0.0, -0.35]}[robot]
    q = dyn.assemble(start)
    assert reduced.dof - np.linalg.matrix_rank(dyn.loop_jacobian(q), 1e-9) == dof


def test_the_numeric_rows_are_the_derived_ones():
    """The rows the checks build (float frame recursion) equal the derived Φ and J_l at random
    configurations, for a point, a hinge and a weld loop, spatial and planar."""
    model, sc = example("fivebar", "fivebar_loop")
    reduced = apply_scene(model, sc).model
    base = reduced.loops[0]
    rng = np.random.default_rng(3)
    for kind, plane in (("point", None), ("hinge", None), ("weld", None), ("weld", (0, 0, 1))):
        loop = replace(base, kind=kind, plane=plane, axis=(0.0, 0.0, 1.0))
        m = unchecked(reduced, [loop])
        rows, dyn = LoopRows(m), LoopDynamics(m)
        for _ in range(2):
            q = rng.uniform(-2, 2, m.dof)
            Phi, J, _ = rows.at(q)
            e = dyn.evaluate(q)
            assert np.allclose(Phi, e["Phi_l"], atol=1e-12), kind
            assert np.allclose(J, e["J_l"], atol=1e-12), kind


def test_a_five_bar_closed_in_a_tilted_plane_is_refused():
    """The x-y five-bar with its plane's normal turned 30°: refused; witness: the joints move
    frame b relative to frame a along that normal (the spatial loop's derived rows), while
    with the mechanism's normal the same loop is accepted (the bundled example)."""
    model, sc = example("fivebar", "fivebar_loop", **{"plane: [0, 0, 1]": f"plane: {TILTED}"})
    message = refused(model, sc)
    assert message.startswith("fivebar_loop.yaml: loops[0] '")
    assert "does not hold the motion" in message and "(0.5, 0, 0.866025)" in message
    good, _ = example("fivebar", "fivebar_loop")
    reduced = apply_scene(good, load_scene(LOOPS / "fivebar_loop.yaml")).model
    loop = reduced.loops[0]
    spatial = LoopDynamics(unchecked(reduced, [replace(loop, plane=None)]))
    n = np.array([0.5, 0, 3 ** 0.5 / 2])
    q = LoopDynamics(reduced).assemble([1.2, 1.0, 1.9, -1.0])
    assert np.abs(n @ spatial.loop_jacobian(q)).max() > 0.1  # the joints move b along n [m/rad]


def test_a_planar_loop_on_a_slider_crank_with_a_tilted_crank_axis_is_refused(tmp_path):
    """The crank's axis tilted (not the plane's normal): the x-y loop is refused; witness: the
    crank moves the crank pin out of the plane (n · J of the spatial rows ≠ 0). Upright, it is
    accepted with one degree of freedom."""
    loops = ("loops:\n  - {name: pin, type: point, a: {link: slider}, b: {link: rod, xyz: "
             "[0.5, 0, 0]}, plane: [0, 0, 1]}\nactuated: [crank_joint]\n")
    upright = eomgen.load(write(tmp_path / "up.yaml", SLIDER_CRANK.replace("CRANK_AXIS",
                                                                            "[0, 0, 1]")))
    reduced, report = apply_scene(upright, scene("crank", loops))
    assert "the loops leave 1 degree of freedom" in report.notes[-1]
    tilted = eomgen.load(write(tmp_path / "tilted.yaml",
                               SLIDER_CRANK.replace("CRANK_AXIS", "[0, 0.2, 1]")))
    message = refused(tilted, scene("crank", loops))
    assert "loops[0] 'pin': the plane (normal (0, 0, 1), world axes) does not hold" in message
    spatial = LoopDynamics(unchecked(tilted, [replace(reduced.loops[0], plane=None)]))
    assert np.abs(spatial.loop_jacobian(np.array([0.4, -0.3, 0.1]))[2]).max() > 1e-3


def test_a_loop_that_makes_a_rigid_triangle_is_refused(tmp_path):
    """Two links pinned to the ground at both ends: no degree of freedom left; witness: the
    derived J_l at the closed triangle is square and invertible (no motion keeps it closed)."""
    model = eomgen.load(write(tmp_path / "triangle.yaml", TRIANGLE))
    message = refused(model, scene("triangle", PIN))
    assert message == ("triangle.yaml: loops[0] 'pin': the loops leave no degree of freedom "
                       "(2 coordinates, 2 of the 2 loop rows independent at a closed "
                       "configuration): the mechanism is rigid")
    sc = scene("triangle", PIN)
    dyn = LoopDynamics(unchecked(model, sc.loops, ("j1",)))
    # j1 from the law of cosines (sides 0.5, 0.4 and 0.6 on the ground), j2 closed by Newton
    q = dyn.assemble([np.arccos(0.75), -1.6])
    assert np.abs(dyn.loop_constraint(q)).max() < 1e-12
    assert abs(np.linalg.det(dyn.loop_jacobian(q))) > 1e-3


def test_more_actuated_joints_than_degrees_of_freedom_are_refused():
    """The four-bar with two of its joints actuated: refused (its one degree of freedom cannot
    take two independent efforts); witness: the derived J_l's null space is one direction."""
    model, sc = example("fourbar", "fourbar_loop", **{
        "actuated: [crank_joint]": "actuated: [crank_joint, rocker_joint]"})
    message = refused(model, sc)
    assert ("loops[0] 'pin': the loops leave 1 degree of freedom, fewer than the 2 coordinates "
            "named in actuated (crank_joint, rocker_joint;") in message
    reduced = apply_scene(*example("fourbar", "fourbar_loop")).model
    dyn = LoopDynamics(reduced)
    q = dyn.assemble([0.3, 1.0, 2.0])
    assert 3 - np.linalg.matrix_rank(dyn.loop_jacobian(q), 1e-9) == 1


def test_a_loop_no_joint_moves_is_refused_alike_in_a_scene_and_in_mjcf(tmp_path):
    """A connect between bodies welded through a chain of fixed bodies, and one at a hinge's
    own axis (no joint moves its point): refused when the MJCF file is read, naming the
    equality; the same loop declared in a scene on the file without it gets the same words."""
    need("mujoco", reason="MJCF is read by MuJoCo's compiler")
    body = """<mujoco model="m"><worldbody>
      <body name="arm"><joint name="j1" axis="0 0 1"/><geom type="capsule" size="0.05" fromto="0 0 0 0.3 0 0"/>
        <body name="plate" pos="0.3 0 0"><geom size="0.02"/>
          <body name="tip" pos="0.1 0 0"><geom size="0.02"/></body></body>
        <body name="fore" pos="0.3 0 0"><joint name="j2" axis="0 1 0"/>
          <geom type="capsule" size="0.04" fromto="0 0 0 0.2 0 0"/></body></body>
      </worldbody>EQ</mujoco>"""
    plain = eomgen.load(write(tmp_path / "plain.xml", body.replace("EQ", "")))
    for eq, scene_loop, words in (
            ('<connect name="glued" body1="arm" body2="tip" anchor="0.2 0 0"/>',
             "{name: glued, type: point, a: {link: tip, xyz: [-0.2, 0, 0]}, b: {link: arm, "
             "xyz: [0.2, 0, 0]}}", "on the same rigid body 'arm': the loop constrains nothing"),
            ('<connect name="axle" body1="fore" body2="arm" anchor="0 0 0"/>',
             "{name: axle, type: point, a: {link: arm, xyz: [0.3, 0, 0]}, b: {link: fore}}",
             "along any of its rows (axle.x, axle.y, axle.z): the loop constrains nothing")):
        path = write(tmp_path / "m.xml", body.replace("EQ", f"<equality>{eq}</equality>"))
        with pytest.raises(InvalidLoopError) as info:
            eomgen.load(path)
        name = scene_loop.split(",")[0].split()[-1]
        assert str(info.value).startswith(f"{path}: equality '{name}': ")
        assert words in str(info.value)
        problem = str(info.value).split(": ", 2)[2]
        from_scene = refused(plain, scene("s", f"loops:\n  - {scene_loop}\n"))
        assert from_scene == f"s.yaml: loops[0] '{name}': {problem}"


@pytest.mark.parametrize("command", ["generate", "simulate"])
def test_the_cli_refuses_in_one_line_and_writes_nothing(tmp_path, command):
    """``eomgen generate`` (the tilted five-bar) and ``eomgen simulate`` (the rigid triangle):
    exit 2, one line naming the scene and the loop, no output folder."""
    if command == "generate":
        text = (LOOPS / "fivebar_loop.yaml").read_text().replace("plane: [0, 0, 1]",
                                                                 f"plane: {TILTED}")
        robot, extra = ROBOTS / "fivebar.yaml", ("--backend", "numpy")
    else:
        text = "version: 1\n" + PIN
        robot = write(tmp_path / "triangle.yaml", TRIANGLE)
        extra = ("--q0", "0.5,-1.5", "--duration", "0.01", "--integrators", "rk4")
    sc = write(tmp_path / "bad.yaml", text)
    out = tmp_path / "out"
    result = run_cli(command, robot, "--scene", sc, *extra, "-o", out)
    assert result.exit_code == 2, result.output
    (line,) = result.stderr.splitlines()[-1:]
    assert line.startswith(f"eomgen: error: {sc}: loops[0] '"), result.stderr
    assert not [l for l in result.stderr.splitlines() if "error" in l][1:]
    assert not out.exists()


def test_a_planar_loop_on_a_free_base_is_refused_and_a_spatial_one_accepted(tmp_path):
    """The four-bar on a free base (its ground given a mass): the base turns the mechanism out
    of the loop's world plane, so the planar loop is refused; declared spatial it is accepted,
    the base's six coordinates free (7 = 9 − 2: its out-of-plane row is dependent where the
    loop closes); witness: the spatial loop's derived z row moves at a tilted base."""
    text = (ROBOTS / "fourbar.yaml").read_text().replace(
        "  - name: ground\n", "  - name: ground\n    mass: 2.0\n"
        "    inertia: {ixx: 0.1, iyy: 0.1, izz: 0.1}\n")
    model = eomgen.load(write(tmp_path / "fourbar.yaml", text))
    loops = (LOOPS / "fourbar_loop.yaml").read_text()
    message = refused(model, load_scene("free.yaml", text=loops + "floating_base: true\n"))
    assert "loops[0] 'pin': the plane (normal (0, 0, 1), world axes) does not hold" in message
    spatial = loops.replace("    plane: [0, 0, 1]\n", "") + "floating_base: true\n"
    reduced, report = apply_scene(model, load_scene("free.yaml", text=spatial))
    assert report.mobility.dof == 7 and report.mobility.closed
    q = np.array([0, 0, 0, np.sin(0.2), 0, 0, np.cos(0.2), 0.3, 1.0, 2.0])  # base about x
    assert np.abs(LoopDynamics(reduced).loop_jacobian(q)[2, 6:]).max() > 0.01


def test_the_logs_state_the_freedom_and_explain_dependent_rows_without_contacts(tmp_path):
    """``eomgen generate`` logs the degrees of freedom and the links before and after (it said
    "23 of 17 links kept" when links were added); ``eomgen simulate`` of an MJCF four-bar (a
    spatial connect: its z row never moves) explains the damped solve by that row, not by
    contacts it does not have."""
    result = run_cli("generate", ROBOTS / "fourbar.yaml", "--scene", LOOPS / "fourbar_loop.yaml",
                     "--backend", "numpy", "--no-cache", "-o", tmp_path / "gen")
    assert result.exit_code == 0, result.output
    assert ("4 links in the description, 4 in the model" in result.stderr
            and "the loops leave 1 degree of freedom" in result.stderr)
    need("mujoco", reason="MJCF is read by MuJoCo's compiler")
    path = write(tmp_path / "closed.xml", """<mujoco model="closed"><worldbody>
      <body name="crank"><joint name="c1" axis="0 0 1"/>
        <geom type="capsule" size="0.05" fromto="0 0 0 0.2 0 0"/>
        <body name="rod" pos="0.2 0 0"><joint name="c2" axis="0 0 1"/>
          <geom type="capsule" size="0.05" fromto="0 0 0 0.3 0 0"/></body></body>
      <body name="rocker" pos="0.6 0 0"><joint name="r1" axis="0 0 1"/>
        <geom type="capsule" size="0.05" fromto="0 0 0 -0.1 0 0"/></body></worldbody>
      <equality><connect name="pin" body1="rod" body2="rocker" anchor="0.3 0 0"/></equality>
      </mujoco>""")
    result = run_cli("simulate", path, "--q0", "0,0,0", "--qd0", "1,0,0", "--duration",
                     "0.01", "--integrators", "rk4", "--dt", "0.005", "-o", tmp_path / "sim")
    assert result.exit_code == 0, result.output
    text = (tmp_path / "sim" / "simulate_closed.md").read_text()
    assert "a loop row no joint moves" in text and "contact" not in text
