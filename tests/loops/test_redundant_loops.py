"""Redundant loop rows: the four-bar closed by a spatial hinge (what its cut pin really is, 5
rows) where the planar point loop of examples/loops/fourbar_loop.yaml suffices. In the plane,
the hinge's z row and its two rotation rows are identically zero, so ``J_l`` (5×3) has rank 2:
the exact KKT solve refuses it, and the damped one (ε = 1e-12) gives the planar loop's q̈ and
in-plane force (itself checked against the closed form of examples/robots/fourbar.yaml in
test_fourbar.py), with nothing on the dependent rows. ``eomgen simulate`` solves it damped and
follows the planar loop's trajectory.
"""

from __future__ import annotations

import numpy as np
import pytest

import eomgen
from eomgen.numeric.loops import LoopDynamics
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT, relative
from support.extras import need

ROBOT = ROOT / "examples/robots/fourbar.yaml"
SCENE = ROOT / "examples/loops/fourbar_loop.yaml"
EPS = 1e-12


def _model(hinge: bool):
    text = SCENE.read_text()
    if hinge:
        text = text.replace("type: point", "type: hinge").replace("    plane: [0, 0, 1]\n", "")
    return apply_scene(eomgen.load(ROBOT), load_scene("fourbar_loop.yaml", text=text)).model


@pytest.fixture(scope="module")
def loops():
    planar, hinge = LoopDynamics(_model(False)), LoopDynamics(_model(True))
    assert hinge.model.loops[0].rows == ("pin.x", "pin.y", "pin.z", "pin.r1", "pin.r2")
    q = planar.assemble([0.8, 1.0, 1.8])
    N = np.linalg.svd(planar.loop_jacobian(q))[2][2:].T
    return planar, hinge, q, N @ np.array([1.3])


def test_damped_kkt_of_the_redundant_hinge_is_the_planar_loop(loops, tmp_path):
    from support.generated import generated

    planar, hinge, q, qd = loops
    J = hinge.loop_jacobian(q)
    assert J.shape == (5, 3) and np.linalg.matrix_rank(J) == 2
    tau = np.array([1.2, 0.3, -0.2])
    with pytest.raises(np.linalg.LinAlgError, match="dependent rows"):
        hinge.constrained_forward_dynamics(q, qd, tau)
    qdd, F = planar.constrained_forward_dynamics(q, qd, tau)
    qdd_d, F_d = hinge.constrained_forward_dynamics(q, qd, tau, damping=EPS)
    assert relative(qdd_d, qdd) <= 1e-9
    assert relative(F_d[:2], F) <= 1e-9  # pin.x, pin.y = pin.u, pin.v for the normal z
    assert np.abs(F_d[2:]).max() <= 1e-9 * np.abs(F).max()
    _, modules = generated(hinge.model, ["constrained_forward_dynamics"], tmp_path, ("numpy",))
    f = modules["numpy"]["constrained_forward_dynamics"]
    with pytest.raises(np.linalg.LinAlgError, match="dependent rows"):
        f(q, qd, tau)
    qdd_g, F_g = f(q, qd, tau, damping=EPS)
    assert relative(qdd_g, qdd_d) <= 1e-10 and relative(F_g, F_d) <= 1e-8


def test_simulate_solves_the_redundant_loop_damped(loops):
    need("scipy")
    from eomgen.analysis.simulate import integrators_named, simulate
    from eomgen.analysis.simulate_contacts import DEPENDENT_DAMPING
    from eomgen.analysis.simulate_loops import LoopSystem, run_loop_study

    planar, hinge, q, qd = loops
    (rk4,) = integrators_named(["rk4"], [0.002], [1e-8])
    study = run_loop_study(hinge.model, [rk4], 0.2, q0=q, qd0=qd, points=11)
    assert study.damping == DEPENDENT_DAMPING and "damped KKT solve" in study.describe()
    off, on = study.runs
    assert off.status == on.status == "ok"
    assert off.drift < 1e-8 and off.relative_energy_drift < 1e-8 and on.drift < 1e-8
    ours, _ = simulate(LoopSystem(hinge.model, dynamics=hinge, damping=DEPENDENT_DAMPING), rk4,
                       q, qd, 0.2, points=11)
    reference, _ = simulate(LoopSystem(planar.model, dynamics=planar), rk4, q, qd, 0.2,
                            points=11)
    assert np.abs(ours.q - reference.q).max() <= 1e-9
    assert np.abs(ours.q[-1] - q).max() > 0.1  # it moved
