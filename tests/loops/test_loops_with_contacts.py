"""Loops and contacts held together by ``eomgen simulate``: the five-bar closed at its end
effector, its left elbow held by a point contact (examples/loops/fivebar_elbow_held.yaml; the
contact's rows have rank 1, so the KKT system is solved damped, ε = 1e-12).

The reference is independent of eomgen's dynamics: Pinocchio's ``constraintDynamics`` with the
loop (``CONTACT_3D`` between the two distal links, ``LOCAL``) and the contact (``CONTACT_3D``
of the elbow's joint to the world, ``LOCAL_WORLD_ALIGNED``) as ``RigidConstraintModel``s,
integrated by an RK4 written here: the same trajectory over 0.2 s, and at t = 0 the same loop
forces and the same contact force on the joints (J_cᵀ F, unique where F is not).
"""

from __future__ import annotations

import csv

import numpy as np
import pytest

import eomgen
from eomgen.numeric.loops import LoopDynamics
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import ROOT, relative, run_cli
from support.extras import need

ROBOT = ROOT / "examples/robots/fivebar.yaml"
SCENE = ROOT / "examples/loops/fivebar_elbow_held.yaml"
Q0, QD0 = [1.2, 1.0, 1.9, -1.0], [0.0, -1.4, 1.0, -3.2]


@pytest.fixture(scope="module")
def model():
    return apply_scene(eomgen.load(ROBOT), load_scene(SCENE)).model


def _pinocchio_dynamics(model, q0):
    """``(q, v) -> (q̈, lambda_c)`` of Pinocchio holding the loop and the elbow at its place at
    ``q0`` (eomgen's joint order), with Pinocchio's order of the constraint rows."""
    pin = need("pinocchio")
    from eomgen.numeric.loops import pinocchio_loops
    from eomgen.numeric.pinocchio import to_pinocchio

    pm = to_pinocchio(model)
    p = pm.perm
    models = pinocchio_loops(model, pm)
    joint = pm.model.getJointId("left_elbow")  # the elbow is left_distal's origin
    models.append(pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, pm.model, joint,
                                           pin.SE3.Identity(), pin.LOCAL_WORLD_ALIGNED))
    datas = pin.StdVec_RigidConstraintData([c.createData() for c in models])
    pin.initConstraintDynamics(pm.model, pm.data, models, datas)
    # the contact's x, y, z rows have rank 1 and the loop's z row is zero: a proximal mu
    settings = pin.ProximalSettings(1e-14, 1e-12, 100)

    def accelerations(q, v):
        a = pin.constraintDynamics(pm.model, pm.data, q[p], v[p], np.zeros(4), models, datas,
                                   settings)
        qdd = np.empty(4)
        qdd[p] = a
        return qdd, pm.data.lambda_c.copy(), datas[0].oMc1.rotation

    return accelerations


def test_simulation_matches_pinocchio(model):
    need("scipy")
    from eomgen.analysis.simulate import integrators_named, simulate
    from eomgen.analysis.simulate_loops import (HeldContacts, LoopSystem, consistent_start,
                                                dependent)

    program = LoopDynamics(model)
    q0, qd0 = consistent_start(program, Q0, QD0)
    J0 = program.evaluate(q0)["J_c"]
    assert dependent(J0) and np.abs(J0 @ qd0).max() < 1e-12 and abs(qd0[3]) > 1.0
    system = LoopSystem(model, dynamics=program, contacts=HeldContacts(model, q0, False),
                        damping=1e-12)
    dt, duration = 0.002, 0.2
    (rk4,) = integrators_named(["rk4"], [dt], [1e-8])
    trajectory, _ = simulate(system, rk4, q0, qd0, duration, points=11)

    reference = _pinocchio_dynamics(model, q0)
    # t = 0: the loop forces (Pinocchio's on frame a, in its axes: lambda = -R_a lambda_pin)
    # and the elbow force on the joints
    qdd, F = system.constrained(q0, qd0)
    qdd_pin, lam_pin, R_a = reference(q0, qd0)
    assert relative(qdd, qdd_pin) <= 1e-8
    assert relative(F[3:], (-R_a @ lam_pin[:3])[:2]) <= 1e-8
    assert relative(J0[:3].T @ F[:3], J0[:3].T @ lam_pin[3:]) <= 1e-8

    q, v = q0.copy(), qd0.copy()
    states = [(q.copy(), v.copy())]
    for k in range(round(duration / dt)):
        k1 = reference(q, v)[0]
        k2 = reference(q + dt / 2 * v, v + dt / 2 * k1)[0]
        v2 = v + dt / 2 * k1
        k3 = reference(q + dt / 2 * v2, v + dt / 2 * k2)[0]
        v3 = v + dt / 2 * k2
        k4 = reference(q + dt * v3, v + dt * k3)[0]
        v4 = v + dt * k3
        q = q + dt / 6 * (v + 2 * v2 + 2 * v3 + v4)
        v = v + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        if (k + 1) % 10 == 0:
            states.append((q.copy(), v.copy()))
    assert len(states) == len(trajectory.q)
    for (q_ref, v_ref), q_ours, v_ours in zip(states, trajectory.q, trajectory.qd):
        assert np.abs(q_ours - q_ref).max() <= 1e-9
        assert np.abs(v_ours - v_ref).max() <= 1e-8
    assert np.abs(trajectory.q[-1] - q0).max() > 0.1  # it moved


SURFACE = ("{frame: left_distal, name: elbow}",
           "{frame: right_distal, name: elbow, type: surface}")


@pytest.mark.parametrize("surface", [False, True], ids=["point", "surface"])
def test_baumgarte_pulls_the_contact_back_critically_damped(model, surface):
    """A contact started off its anchor (a motor turned 0.01 rad, the loop closed): the left
    elbow held by the point contact 2.5 mm away, or the right distal link held by a surface
    contact (position and angle), 2.5 mm and 0.024 rad away. With kp = 100, kd = 20 each error
    follows ë + kd ė + kp e = 0 from rest, e0 (1 + ωt) e^{−ωt} with ω = 10 rad/s; without
    Baumgarte it stays (the contact holds the frame where it is)."""
    need("scipy")
    from eomgen.analysis.simulate import integrators_named, simulate
    from eomgen.analysis.simulate_loops import HeldContacts, LoopSystem, consistent_start

    if surface:
        model = apply_scene(eomgen.load(ROBOT), load_scene(
            "fivebar_surface.yaml", text=SCENE.read_text().replace(*SURFACE))).model
    program = LoopDynamics(model)
    q0, _ = consistent_start(program, Q0, np.zeros(4))
    q1 = program.assemble(q0 + 0.01 * np.eye(4)[2 if surface else 0])
    (rk4,) = integrators_named(["rk4"], [0.002], [1e-8])
    law = (1 + 10 * np.linspace(0.0, 0.5, 6)) * np.exp(-10 * np.linspace(0.0, 0.5, 6))
    for on in (False, True):
        held = HeldContacts(model, q0, on)
        system = LoopSystem(model, (100.0, 20.0) if on else (0.0, 0.0), program, held, 1e-12)
        trajectory, _ = simulate(system, rk4, q1, np.zeros(4), 0.5, points=6)
        error = np.array([held.drift(q) for q in trajectory.q])  # position, angle
        assert 2e-3 < error[0, 0] < 3e-3 and (error[0, 1] > 0.02) == surface
        for k in range(2 if surface else 1):
            expected = error[0, k] * (law if on else 1.0)
            assert relative(error[:, k], expected) <= 0.01, (on, k)
        assert max(system.drift(q, v)[0] for q, v in zip(trajectory.q, trajectory.qd)) < 1e-9


def test_simulate_command_reports_loop_and_contact_drift(tmp_path):
    need("scipy")
    need("matplotlib")
    result = run_cli("simulate", ROBOT, "--scene", SCENE, "--q0", ",".join(map(str, Q0)),
                     "--qd0", ",".join(map(str, QD0)), "--duration", "0.3", "--integrators",
                     "rk4", "--dt", "0.002", "--quiet", "-o", tmp_path)
    assert result.exit_code == 0, result.output
    assert "loops held: effector" in result.output and "contacts held" in result.output
    assert "damped KKT solve" in result.output
    with open(tmp_path / "simulate_fivebar.csv", newline="") as f:
        off, on = csv.DictReader(f)
    assert off["baumgarte"] == "off" and off["status"] == on["status"] == "ok"
    # RK4 at 2 ms: the loop and the contact held to the integrator's error, energy kept
    for run in (off, on):
        assert float(run["loop_drift"]) < 1e-8 and float(run["contact_drift_m"]) < 1e-8
    assert float(off["relative_energy_drift"]) < 1e-8
    assert float(on["contact_drift_m"]) < float(off["contact_drift_m"])
