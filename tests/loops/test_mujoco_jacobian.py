"""The loop Jacobian against MuJoCo's ``efc_J`` for the same ``equality connect`` (the
four-bar's loop declared spatial: rows x, y, z). MuJoCo's connect between ``site1`` (the loop's
frame a) and ``site2`` (frame b) has the rows ``J_a − J_b`` (world axes): ``efc_J = −J_l``.
Its soft, iteratively solved constraint forces are not compared (docs/loops.md)."""

from __future__ import annotations

import numpy as np

import eomgen
from eomgen.numeric.loops import LoopDynamics
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT
from support.extras import need

FOURBAR_MJCF = """<mujoco><option gravity="0 -9.81 0" jacobian="dense"><flag contact="disable"/></option><worldbody>
<body name="crank"><joint name="crank_joint" type="hinge" axis="0 0 1"/>
 <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.01"/>
 <body name="coupler" pos="0.2 0 0"><joint name="coupler_joint" type="hinge" axis="0 0 1"/>
  <geom type="capsule" fromto="0 0 0 0.6 0 0" size="0.01"/><site name="b" pos="0.6 0 0"/>
 </body></body>
<body name="rocker" pos="0.6 0 0"><joint name="rocker_joint" type="hinge" axis="0 0 1"/>
 <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.01"/><site name="a" pos="0.5 0 0"/></body>
</worldbody><equality><connect site1="a" site2="b"/></equality></mujoco>"""


def test_loop_jacobian_is_mujoco_connect_efc_J():
    mujoco = need("mujoco", reason="MuJoCo's connect rows are the reference")
    m = mujoco.MjModel.from_xml_string(FOURBAR_MJCF)
    d = mujoco.MjData(m)
    text = (ROOT / "examples/loops/fourbar_loop.yaml").read_text().replace(
        "    plane: [0, 0, 1]\n", "")
    model = apply_scene(eomgen.load(ROOT / "examples/robots/fourbar.yaml"),
                        load_scene("spatial.yaml", text=text)).model
    dyn = LoopDynamics(model)
    rng = np.random.default_rng(5)
    for q in (dyn.assemble([0.3, 1.0, 2.0]), rng.uniform(-3, 3, 3)):  # closed, and open
        d.qpos[:] = q
        mujoco.mj_forward(m, d)
        assert d.nefc == 3
        np.testing.assert_allclose(d.efc_J.reshape(3, m.nv), -dyn.loop_jacobian(q),
                                   rtol=1e-12, atol=1e-12)
