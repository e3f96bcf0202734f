"""MJCF ``connect`` and ``weld`` equalities read as loops (issue 26), checked against MuJoCo.

References, all MuJoCo's: ``efc_pos`` and ``efc_J`` of the equality rows (a connect's three
rows and a weld's translational rows are eomgen's Φ and J_l, world axes, same signs; a weld's
rotational rows are MuJoCo's in another basis: the same row space), qpos0 closing both loops
(the compiler puts the second anchor and relpose there), and the constrained accelerations of
the KKT system built from MuJoCo's mass matrix, bias, efc_J and J̇ q̇ (a central difference of
efc_J along the motion) against those of eomgen's generated M, h, J_l and J̇_l q̇. Model:
tests/data/mjcf/loops.xml (a connect and a weld with an anchor, two spatial closed chains).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import eomgen
from eomgen.errors import SceneError
from eomgen.numeric.loops import kkt_solve
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import relative, run_cli
from support.extras import need

mujoco = need("mujoco", reason="MJCF is read by MuJoCo's compiler")

from eomgen.parsers.mjcf import compile_mjcf  # noqa: E402
from eomgen.parsers.mjcf.convert import (  # noqa: E402
    layout, mujoco_dynamics, to_mujoco, velocity_map)

DATA = Path(__file__).resolve().parent.parent / "data" / "mjcf"
LOOPS = DATA / "loops.xml"


@pytest.fixture(scope="module")
def case():
    model = eomgen.load(LOOPS)
    m = compile_mjcf(LOOPS)
    module = eomgen.derive(model, outputs=("M", "h", "Phi_l", "J_l", "dJqd_l")).lambdify().module
    return model, m, layout(m, model), module


def equality_rows(m, lay, q, v):
    """MuJoCo's (efc_J in eomgen's velocities, efc_pos) of the equality rows at (q, v)."""
    data = mujoco.MjData(m)
    data.qpos[:], data.qvel[:] = to_mujoco(lay, q, v)
    mujoco.mj_forward(m, data)
    rows = np.asarray(data.efc_type) == int(mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    J = np.asarray(data.efc_J).reshape(data.nefc, m.nv)[rows]
    return J @ velocity_map(lay, data.qpos), np.asarray(data.efc_pos)[rows]


def test_connect_and_weld_are_loops(case):
    model = case[0]
    assert [(loop.name, loop.kind, loop.a.link, loop.b.link) for loop in model.loops] == [
        ("pin", "point", "B2", "A2"), ("glue", "weld", "D2", "C3")]
    assert model.dof == 11


def test_rows_are_mujocos(case):
    model, m, lay, f = case
    rng = np.random.default_rng(0)
    for _ in range(2):
        q = rng.uniform(-1, 1, model.nq)
        J_mj, pos = equality_rows(m, lay, q, np.zeros(model.dof))
        J = f.loop_jacobian(q).reshape(9, model.dof)
        assert relative(J[:6], J_mj[:6]) < 1e-12  # connect x y z, weld x y z
        assert relative(f.loop_constraint(q).ravel()[:6], pos[:6]) < 1e-12
        assert np.linalg.matrix_rank(np.vstack([J[6:], J_mj[6:]]), 1e-9) == 3  # same span
        assert np.abs(pos[6:]).max() > 1e-3  # the state is off the loop: the rows say so


def closed_state(m, lay, model):
    """``(q, v, tau)``: qpos0 (which closes the loops), a velocity of the two free motions
    (MuJoCo's efc_J null space), random efforts."""
    q = np.asarray(m.qpos0)[lay.qpos_index]
    J_mj, _ = equality_rows(m, lay, q, np.zeros(model.dof))
    rng = np.random.default_rng(1)
    v = np.linalg.svd(J_mj)[2][-2:].T @ rng.normal(size=2)
    return q, v, rng.normal(size=model.dof)


def mujoco_kkt(m, lay, model, q, v, tau):
    """q̈ of the KKT system of MuJoCo's M, bias, efc_J and J̇ q̇ (a central difference of
    efc_J along the motion), the loops held exactly."""
    J_mj, _ = equality_rows(m, lay, q, np.zeros(model.dof))

    def J_at(step):
        qpos = np.array(m.qpos0)
        mujoco.mj_integratePos(m, qpos, to_mujoco(lay, q, v)[1], step)
        return equality_rows(m, lay, qpos[lay.qpos_index], np.zeros(model.dof))[0]

    bias = (J_at(1e-5) - J_at(-1e-5)) @ v / 2e-5
    ref = mujoco_dynamics(m, lay, q, v)
    return kkt_solve(ref["M"], ref["h"], tau, J_mj, bias)[0]


def test_qpos0_closes_the_loops_and_the_constrained_accelerations_are_mujocos(case):
    model, m, lay, f = case
    q, v, tau = closed_state(m, lay, model)
    _, pos = equality_rows(m, lay, q, np.zeros(model.dof))
    assert np.abs(pos).max() < 1e-12 and np.abs(f.loop_constraint(q)).max() < 1e-12
    J = f.loop_jacobian(q).reshape(9, model.dof)
    assert np.abs(J @ v).max() < 1e-12
    qdd, _ = kkt_solve(f.mass_matrix(q).reshape(11, 11), f.nonlinear_effects(q, v).ravel(),
                       tau, J, f.loop_bias(q, v).ravel())
    assert relative(qdd, mujoco_kkt(m, lay, model, q, v, tau)) < 1e-8
    assert np.abs(J @ qdd + f.loop_bias(q, v).ravel()).max() < 1e-9


def test_a_scene_keeps_the_description_loops_and_adds_its_own(case):
    model = case[0]
    # A1's point 0.1 m from its axis held at its place at q = 0 (A1's origin and C1's, each
    # on its own axis, never move: a loop between them constrains nothing, and is refused)
    scene = load_scene("s.yaml", "version: 1\nloops:\n  - {name: extra, type: point, a: {link: "
                        "world, xyz: [0.1, 0, 0.1]}, b: {link: A1, xyz: [0.1, 0, 0]}}\n")
    reduced = apply_scene(model, scene).model
    assert [loop.name for loop in reduced.loops] == ["pin", "glue", "extra"]
    clash = load_scene("s.yaml", "version: 1\nloops:\n  - {name: pin, type: point, a: {link: A1}, "
                        "b: {link: C1}}\n")
    with pytest.raises(SceneError, match="has a loop named 'pin' already"):
        apply_scene(model, clash)


def test_site_connect_rotation_free_weld_and_a_coupling(tmp_path):
    """A connect between two sites holds their origins; a weld with torquescale 0 is a
    point loop (MuJoCo's rotational rows are then zero); with a joint equality too, J_l is
    projected onto the independent joints (J_l T). (b2's second joint leaves the mechanism one
    degree of freedom: without it, the loops make it rigid, which is refused.)"""
    path = tmp_path / "s.xml"
    path.write_text("""<mujoco model="s"><worldbody>
      <body name="a" pos="0 0 0.1"><joint name="ja" axis="0 0 1"/><geom size="0.05" pos="0.1 0 0"/>
        <site name="sa" pos="0.2 0.01 0" euler="0.1 0.2 0"/>
        <body name="a2" pos="0.2 0 0"><joint name="ja2" axis="0 1 0"/><geom size="0.05"/></body></body>
      <body name="b" pos="0.4 0 0.1"><joint name="jb" axis="1 0 0"/><geom size="0.05"/>
        <site name="sb" pos="-0.2 0.01 0"/>
        <body name="b2" pos="-0.1 0 0"><joint name="jb2" axis="0 0 1"/><joint name="jb3" axis="0 1 0"/>
          <geom size="0.05"/></body></body>
      </worldbody><equality><connect name="c" site1="sa" site2="sb"/>
      <weld name="w" body1="a2" body2="b2" torquescale="0"/>
      <joint joint1="jb2" joint2="ja2" polycoef="0.1 0.5 0 0 0"/></equality></mujoco>""",
                    encoding="utf-8")
    model, m = eomgen.load(path), compile_mjcf(path)
    assert [(loop.name, loop.kind) for loop in model.loops] == [("c", "point"), ("w", "point")]
    lay = layout(m, model)
    f = eomgen.derive(model, outputs=("Phi_l", "J_l")).lambdify().module
    assert model.joint_names == ("ja", "ja2", "jb", "jb3")
    q = np.array([0.3, -0.2, 0.5, 0.4])
    J_mj, pos = equality_rows(m, lay, q, np.zeros(4))
    J = f.loop_jacobian(q).reshape(6, 4)
    assert relative(J, J_mj[:6]) < 1e-12 and np.abs(J_mj[6]).max() < 1e-12
    assert relative(f.loop_constraint(q).ravel(), pos[:6]) < 1e-12


def test_cli_generates_the_constrained_dynamics_without_a_scene(case, tmp_path):
    """The generated constrained_forward_dynamics (the loops as the file's equalities, no
    scene) gives MuJoCo's constrained q̈."""
    model, m, lay, _ = case
    result = run_cli("generate", LOOPS, "--backend", "numpy", "--no-cache", "--outputs",
                     "constrained_forward_dynamics", "-o", tmp_path)
    assert result.exit_code == 0, result.output
    namespace: dict = {}
    exec((tmp_path / "mjcf_loops_numpy.py").read_text(encoding="utf-8"), namespace)
    assert namespace["CONTACT_ROWS"][:3] == ("pin.x", "pin.y", "pin.z")
    assert len(namespace["CONTACT_ROWS"]) == 9
    q, v, tau = closed_state(m, lay, model)
    qdd, _ = namespace["constrained_forward_dynamics"](q, v, tau)
    assert relative(np.ravel(qdd), mujoco_kkt(m, lay, model, q, v, tau)) < 1e-8
