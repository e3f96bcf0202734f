"""Contacts on a quaternion free flyer: eomgen.numeric.contacts' J_c, J̇_c q̇ and KKT dynamics on solo12's
feet, and ``eomgen simulate`` holding the heavy top's tip with ``floating_base: quaternion``.

References: Pinocchio on solo12 from its own URDF reader with its own JointModelFreeFlyer (q of
NQ and v of NV passed unchanged): getFrameJacobian and getFrameClassicalAcceleration
(LOCAL_WORLD_ALIGNED for point contacts, LOCAL for surface contacts) and constraintDynamics; the
energy of eomgen.numeric's Newton–Euler (independent of the derived program the simulation
integrates). The frames come from the derived program and from eomgen.numeric.frames.
"""

from __future__ import annotations

import csv

import numpy as np
import pytest

from eomgen.numeric.contacts import Contact, ContactDynamics
from eomgen.model.floating import add_free_flyer
from eomgen.numeric.frames import frame_function
from support import ROOT, erd_robots_or_skip, load_quietly, relative, run_cli, write
from support.reference import pinocchio_contacts
from support.extras import need

pin = need("pinocchio", reason="Pinocchio is the reference")

FEET = ("FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT")


@pytest.fixture(scope="module")
def solo():
    path = erd_robots_or_skip() / "solo_description" / "robots" / "solo12.urdf"
    pm = pin.buildModelFromUrdf(str(path), pin.JointModelFreeFlyer())
    return path, add_free_flyer(load_quietly(path)), pm


def states(pm, count, seed):
    rng = np.random.default_rng(seed)
    for _ in range(count):
        pin.seed(int(rng.integers(1 << 30)))
        q = pin.randomConfiguration(pm, -np.ones(pm.nq), np.ones(pm.nq))
        yield q, rng.uniform(-1, 1, pm.nv), rng.uniform(-2, 2, pm.nv)


@pytest.mark.parametrize("kind, feet, frames", [("point", FEET, "derived"),
                                                ("surface", FEET[:1], "derived"),
                                                ("point", FEET, "numeric"),
                                                ("surface", FEET[1:2], "numeric")])
def test_contact_dynamics_equal_pinocchio(solo, kind, feet, frames):
    """J_c, J̇_c v and the KKT dynamics, the frames from the derived program or from the
    numeric recursion (eomgen.numeric.frames: then nothing comes from the derivation)."""
    _, model, pm = solo
    pd = pm.createData()
    kinematics = frame_function(model, feet) if frames == "numeric" else None
    cd = ContactDynamics(model, tuple(Contact(f, kind) for f in feet),
                         frame_kinematics=kinematics)
    models, datas = pinocchio_contacts(pm, pd, feet, kind)
    rows = slice(0, 3) if kind == "point" else slice(0, 6)
    frame = pin.LOCAL_WORLD_ALIGNED if kind == "point" else pin.LOCAL  # the contacts' axes
    # a point's acceleration (classical), a surface frame's spatial acceleration (body twist)
    acceleration = (pin.getFrameClassicalAcceleration if kind == "point"
                    else pin.getFrameAcceleration)
    for q, v, tau in states(pm, 2, seed=21):
        pin.forwardKinematics(pm, pd, q, v, np.zeros(pm.nv))
        pin.computeJointJacobians(pm, pd, q)
        pin.updateFramePlacements(pm, pd)
        J = np.vstack([pin.getFrameJacobian(pm, pd, pm.getFrameId(f), frame)[rows]
                       for f in feet])
        bias = np.concatenate([acceleration(pm, pd, pm.getFrameId(f), frame).vector[rows]
                               for f in feet])
        assert relative(cd.contact_jacobian(q), J) < 1e-12
        assert relative(cd.contact_bias(q, v), bias) < 1e-12
        a = pin.constraintDynamics(pm, pd, q, v, tau, models, datas,
                                   pin.ProximalSettings(1e-14, 1e-12, 1))
        qdd, F = cd.constrained_forward_dynamics(q, v, tau)
        assert relative(qdd, a) <= 1e-8
        assert relative(F, pd.lambda_c) <= 1e-8
        assert relative(cd.inverse_dynamics(q, v, qdd, F), tau) <= 1e-10


def test_simulate_holds_a_spinning_top_on_its_tip_with_a_quaternion_base(tmp_path):
    """The command that refused a quaternion model with contacts runs the heavy top (its tip
    held, examples/contacts/top_on_a_point.yaml with floating_base: quaternion), tilted by
    0.2 rad and spun at 20 rad/s: the tip stays put (RK4 at 1 ms), the energy from
    eomgen.numeric stays (no Baumgarte: the held contact does no work), and the quaternion norm
    drift is reported: round-off, the quaternion stepped along SO(3)'s exponential."""
    need("scipy", reason="eomgen simulate")
    need("matplotlib", reason="eomgen simulate")
    scene = (ROOT / "examples" / "contacts" / "top_on_a_point.yaml").read_text("utf-8")
    assert "floating_base: true" in scene
    scene = write(tmp_path / "top.yaml", scene.replace("floating_base: true",
                                                       "floating_base: quaternion"))
    q0 = [0, 0, 0.3, 0, np.sin(0.1), 0, np.cos(0.1)]  # tilted 0.2 rad about y
    result = run_cli("simulate", str(ROOT / "examples" / "robots" / "spinning_top.yaml"),
                     "--scene", str(scene), "--duration", "0.2", "--integrators", "rk4",
                     "--dt", "1e-3", "--quiet", "--q0", ",".join(map(str, q0)),
                     "--qd0", "0,0,0,0,0,20", "-o", str(tmp_path / "out"))
    assert result.exit_code == 0, result.output
    with open(tmp_path / "out" / "simulate_spinning_top.csv", encoding="utf-8") as f:
        runs = {row["baumgarte"]: row for row in csv.DictReader(f)}
    off, on = runs["off"], runs["kp = 100, kd = 20"]
    assert off["status"] == on["status"] == "ok"
    for run in (off, on):
        assert float(run["position_drift_m"]) < 1e-8
        assert float(run["quaternion_norm_drift"]) <= 1e-12
    assert float(off["relative_energy_drift"]) < 1e-8
    md = (tmp_path / "out" / "simulate_spinning_top.md").read_text("utf-8")
    assert "‖quat‖ − 1" in md
