"""``eomgen simulate`` with contacts held and with flexible joints (issues 16 and 17).

References: the closed form of the planar arm held at its tip (docs/contact.md), the KKT
acceleration of eomgen.numeric.contacts from eomgen's numeric Newton–Euler, SciPy's rotation vector
for the SO(3) logarithm, the energy of eomgen.numeric (links) plus motors and springs, the
functions of eomgen.analysis.actuators, and the rigid model with reflected inertia integrated from
eomgen.numeric's M and h.
"""

from __future__ import annotations

import dataclasses


import numpy as np
import pytest
from click.testing import CliRunner

import eomgen
from support import ROOT
from support.extras import need
from eomgen.analysis import actuators as A
from eomgen import numeric
from eomgen.cli import _load_reduced, main
from eomgen.numeric.contacts import Contact, ContactDynamics, derived_mass_and_bias, rotation_log
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene

need("matplotlib", reason="eomgen simulate")
need("scipy", reason="eomgen simulate")
from scipy.integrate import solve_ivp  # noqa: E402
from scipy.spatial.transform import Rotation  # noqa: E402

from eomgen.analysis.simulate import (RK4, Adaptive, ExplicitEuler,  # noqa: E402
                                      SemiImplicitEuler, run_study)
from eomgen.analysis.simulate_contacts import ContactSystem, run_contact_study  # noqa: E402
from eomgen.analysis.simulate_flexible import (FlexibleSystem, flexible_start,  # noqa: E402
                                               plot_step, step_response)

WALL = ROOT / "examples/contacts/planar_2link_wall.yaml"
TOP = ROOT / "examples/robots/spinning_top.yaml"
TOP_SCENE = ROOT / "examples/contacts/top_on_a_point.yaml"
FLEXIBLE = ROOT / "examples/robots/flexible_2link.yaml"


def _wall():
    return _load_reduced(eomgen.example_path("planar_2link"), WALL, False)


def _top():
    """The top on a point in the Euler chart (its q0 six numbers; the shipped scene's
    ``floating_base: true`` is the quaternion free flyer, tests/contacts/test_simulate_quaternion)."""
    scene = dataclasses.replace(load_scene(TOP_SCENE), floating_base="euler")
    return apply_scene(eomgen.load(TOP), scene)


def _rk4(f, x, dt, steps):
    for _ in range(steps):
        k1 = f(x)
        k2 = f(x + dt / 2 * k1)
        k3 = f(x + dt / 2 * k2)
        k4 = f(x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return x


# ----------------------------------------------------------------------------------------------
# Orientation Baumgarte (surface contacts)
# ----------------------------------------------------------------------------------------------

def test_rotation_log_is_scipys_rotation_vector():
    rng = np.random.default_rng(3)
    vectors = [rng.normal(size=3) for _ in range(5)] + [np.zeros(3), [1e-9, 0, 0],
                                                        [0, np.pi - 1e-9, 0],
                                                        [np.pi / np.sqrt(2), 0, -np.pi / np.sqrt(2)]]
    for v in vectors:
        R = Rotation.from_rotvec(v).as_matrix()
        expected = Rotation.from_matrix(R).as_rotvec()
        got = rotation_log(R)
        if np.linalg.norm(expected) > np.pi - 1e-6:  # θ = π: u and −u are the same rotation
            assert np.allclose(Rotation.from_rotvec(got).as_matrix(), R, atol=1e-12)
        else:
            assert np.allclose(got, expected, atol=1e-12), (v, got, expected)


def _surface_top(kp, kd):
    """The top's box held by a surface contact on its tip, anchored away from q0: 1 cm and a
    rotation of 0.05 rad about (1, 2, 0)/√5 (world axes)."""
    model, _ = _top()
    model = model.with_numeric_parameters()
    contact = Contact("tip", kind="surface", kp=kp, kd=kd)
    mass_and_bias = derived_mass_and_bias(model)
    probe = ContactDynamics(model, (contact,), mass_and_bias=mass_and_bias)
    q0 = np.array([0.0, 0.0, 0.3, 0.1, 0.2, -0.1])
    f = probe._kinematics(q0, np.zeros(6))["tip"]
    turn = Rotation.from_rotvec(0.05 * np.array([1.0, 2.0, 0.0]) / np.sqrt(5)).as_matrix()
    R_anchor = turn @ f["R"]
    p_anchor = f["p"] + np.array([0.01, 0.0, 0.0])
    cd = ContactDynamics(model, (contact,), {"tip": p_anchor}, {"tip": R_anchor}, mass_and_bias)
    return cd, q0, p_anchor, R_anchor


def test_surface_baumgarte_uses_the_log_of_the_relative_rotation_in_frame_axes():
    cd, q0, p_anchor, R_anchor = _surface_top(kp=100.0, kd=20.0)
    qd = np.array([0.1, -0.2, 0.05, 0.3, -0.1, 0.2])
    qdd, _ = cd.constrained_forward_dynamics(q0, qd, np.zeros(6))
    f = cd._kinematics(q0, qd)["tip"]
    error = np.concatenate([f["R"].T @ (f["p"] - p_anchor),
                            Rotation.from_matrix(R_anchor.T @ f["R"]).as_rotvec()])
    assert abs(np.linalg.norm(error[3:]) - 0.05) < 1e-12
    J = cd.contact_jacobian(q0)
    assert np.allclose(J @ qdd + cd.contact_bias(q0, qd), -20.0 * J @ qd - 100.0 * error,
                       atol=1e-9)


def test_orientation_drift_decays_with_baumgarte_and_stays_without():
    finals = {}
    for kp, kd in ((100.0, 20.0), (0.0, 20.0)):
        cd, q0, _, _ = _surface_top(kp, kd)

        def f(x):
            return np.concatenate([x[6:], cd.constrained_forward_dynamics(x[:6], x[6:],
                                                                          np.zeros(6))[0]])

        x = _rk4(f, np.concatenate([q0, np.zeros(6)]), 2e-3, 300)  # 0.6 s
        finals[kp] = cd.surface_error("tip", q=x[:6])
    # ë + 20 ė + 100 e = 0 from rest: e(t) = (1 + 10 t) e^{−10 t} e(0), 1.7 % at 0.6 s
    assert np.linalg.norm(finals[100.0][3:]) < 0.025 * 0.05
    assert np.linalg.norm(finals[100.0][:3]) < 0.025 * 0.01
    assert abs(np.linalg.norm(finals[0.0][3:]) - 0.05) < 1e-6  # without kp: it stays


# ----------------------------------------------------------------------------------------------
# Contacts held in simulation
# ----------------------------------------------------------------------------------------------

def test_one_integrated_step_is_the_kkt_acceleration():
    """One explicit Euler step of the simulator is q̇0 + h q̈ with q̈ from eomgen.numeric.contacts' KKT
    solve on eomgen's numeric Newton–Euler (not the derived program the simulator uses); one
    RK4 step agrees to O(h)."""
    model, report = _top()
    q0 = np.array([0.0, 0.0, 0.3, 0.0, 0.2, 0.1])
    system = ContactSystem(model, report.contacts, q0, baumgarte=False)
    J = system.cd.contact_jacobian(q0)
    qd0 = np.linalg.svd(J)[2][3:].T @ np.array([0.5, -0.3, 6.0])  # J q̇ = 0
    reference = ContactDynamics(model.with_numeric_parameters(), report.contacts)
    qdd, F = reference.constrained_forward_dynamics(q0, qd0, np.zeros(6))
    h = 1e-4
    q1, qd1 = ExplicitEuler(h).step(system, (q0, qd0), h)
    assert np.allclose(qd1, qd0 + h * qdd, rtol=0, atol=1e-12 * np.abs(qdd).max())
    assert np.allclose(q1, q0 + h * qd0, atol=1e-15)
    q1, qd1 = RK4(h).step(system, (q0, qd0), h)
    assert np.abs((qd1 - qd0) / h - qdd).max() < 1e-2 * np.abs(qdd).max()
    assert np.allclose(system.constrained(q0, qd0)[1], F, rtol=1e-10)


def test_wall_holds_the_arm_with_the_closed_form_force():
    """With τ = 0 the wall alone holds the arm still: Jᵀ F = g(q), F from the closed forms of
    J and g (docs/contact.md); nothing moves and the tip stays on its anchor."""
    model, report = _wall()
    values = {s.name: v for s, v in model.parameter_values.items()}
    m1, m2, l1, l2, lc1, lc2, g0 = (values[k] for k in ("m1", "m2", "l1", "l2", "lc1",
                                                         "lc2", "g"))
    q1, q2 = 0.4, 0.9
    s1, c1, s12, c12 = np.sin(q1), np.cos(q1), np.sin(q1 + q2), np.cos(q1 + q2)
    J = np.array([[-l1 * s1 - l2 * s12, -l2 * s12], [l1 * c1 + l2 * c12, l2 * c12]])
    g = np.array([(m1 * lc1 + m2 * l1) * g0 * c1 + m2 * lc2 * g0 * c12, m2 * lc2 * g0 * c12])
    study = run_contact_study(model, report.contacts, [RK4(1e-2)], 0.2, [q1, q2], points=5)
    assert np.allclose(study.initial_force[:2], np.linalg.solve(J.T, g), rtol=1e-9)
    assert abs(study.initial_force[2]) < 1e-9 and study.dependent
    for run in study.runs:
        assert run.status == "ok" and run.position_drift < 1e-12 and run.energy_drift < 1e-9


def test_baumgarte_pulls_back_a_drifting_wall_contact():
    """A start velocity the wall does not allow (J q̇0 ≠ 0): without Baumgarte J q̇ stays
    (J q̈ = −J̇ q̇) and the tip leaves its anchor; with it the error decays."""
    model, report = _wall()
    study = run_contact_study(model, report.contacts, [RK4(1e-3)], 0.5, [0.4, 0.9],
                              [0.2, -0.1], points=11)
    off, on = study.runs
    assert off.baumgarte == "off" and on.baumgarte == "kp = 100, kd = 20"
    assert study.initial_velocity_error > 0.1
    assert off.final_position_drift > 0.5 * 0.5 * study.initial_velocity_error
    assert on.final_position_drift < 1e-2 * off.final_position_drift


def test_floating_top_conserves_energy_and_drifts_less_with_baumgarte():
    model, report = _top()
    q0 = [0.0, 0.0, 0.3, 0.0, 0.2, 0.1]
    study = run_contact_study(model, report.contacts, [RK4(1e-3), SemiImplicitEuler(1e-3)],
                              0.4, q0, points=11)
    rk4_off, rk4_on, euler_off, euler_on = study.runs
    assert all(r.status == "ok" for r in study.runs)
    assert rk4_off.relative_energy_drift < 1e-7  # τ = 0, no Baumgarte: held contacts do no work
    assert rk4_off.position_drift < 1e-8
    assert euler_off.position_drift > 1e-4  # first order: the contact wanders off
    # with Baumgarte the truncation error is fed back: the drift stays at about its size over
    # kp, where without it accumulates (measured at 0.4 s: 5.8e-5 m against 3.1e-4 m)
    assert euler_on.final_position_drift < 0.3 * euler_off.final_position_drift


def test_cli_simulate_with_contacts(tmp_path):
    out = tmp_path / "wall"
    result = CliRunner().invoke(main, ["simulate", "--scene", str(WALL), "--duration", "0.1",
                                       "--integrators", "rk4,implicit-midpoint", "--dt", "1e-2",
                                       "--qd0", "0.2,-0.1", "--baumgarte", "50,10", "--quiet",
                                       "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "| RK4 | dt = 0.01 s | off |" in result.output
    assert "| RK4 | dt = 0.01 s | kp = 50, kd = 10 |" in result.output
    assert "implicit midpoint" not in result.output
    assert sorted(p.name for p in out.iterdir()) == [
        "simulate_planar_2link.csv", "simulate_planar_2link.md", "simulate_planar_2link.png"]
    bad = CliRunner().invoke(main, ["simulate", "--scene", str(WALL), "--baumgarte", "1",
                                    "--quiet", "-o", str(tmp_path / "bad")])
    assert bad.exit_code == 2 and "--baumgarte" in bad.output
    assert bad.output.count("\n") == 1 and not (tmp_path / "bad").exists()


# ----------------------------------------------------------------------------------------------
# Flexible joints
# ----------------------------------------------------------------------------------------------

@pytest.fixture(scope="module")
def flexible():
    return eomgen.load(FLEXIBLE)


def test_flexible_system_is_the_reduced_spong_model(flexible):
    system = FlexibleSystem(flexible, tau=[1.5, -0.7])
    am = A.actuated_model(eomgen.derive(flexible))
    rng = np.random.default_rng(5)
    q, qd, th, thd = rng.normal(size=(4, 2))
    x = np.concatenate([q, qd, th, thd])  # eomgen.analysis.actuators' order
    Q, Qd = np.concatenate([q, th]), np.concatenate([qd, thd])
    expected = A.flexible_forward_dynamics(am, x, [1.5, -0.7])
    got = system.forward_dynamics(Q, Qd)
    assert np.allclose(got, np.concatenate([expected[2:4], expected[6:8]]), rtol=1e-11)
    assert np.isclose(sum(system.energy(Q, Qd)), A.flexible_energy(am, x), rtol=1e-12)
    P = system.M(Q) @ Qd  # the canonical form agrees with the forward dynamics
    assert np.allclose(system.velocity(Q, P), Qd, rtol=1e-12)


def test_flexible_energy_is_conserved_and_explicit_euler_does_not_cope(flexible):
    system = FlexibleSystem(flexible)
    Q0 = flexible_start(system, [1.0, 1.0])
    study = run_study(flexible, [ExplicitEuler(1e-2), RK4(1e-3), Adaptive("Radau", 1e-8)],
                      1.0, Q0, system=system)  # output every 0.01 s: Euler's step is 0.01 s
    euler, rk4, radau = study.runs
    assert euler.setting == "dt = 0.01 s"  # not reduced to the output spacing
    assert euler.status != "ok" or euler.relative_energy_drift > 1.0  # ω h = 0.7: unstable
    assert rk4.relative_energy_drift < 1e-8 and rk4.trajectory_error < 1e-7
    assert radau.status == "ok" and radau.relative_energy_drift < 1e-6


def _rigid_reflected(model, q0, tau, duration):
    """q(T) of (M + diag(B)) q̈ + h = τ, M and h from eomgen.numeric."""
    nm = numeric.numeric_model(model.with_numeric_parameters())
    B = np.array([float(a.armature) for a in A.joint_actuators(model.with_numeric_parameters())])

    def f(t, x):
        q, qd = x[:2], x[2:]
        M = numeric.M_rnea(nm, q) + np.diag(B)
        h = numeric.rnea(nm, q, qd, np.zeros(2))
        return np.concatenate([qd, np.linalg.solve(M, tau - h)])

    result = solve_ivp(f, (0, duration), np.concatenate([q0, [0, 0]]), method="DOP853",
                       rtol=1e-11, atol=1e-11)
    return result.y[:2, -1]


def test_large_stiffness_gives_the_rigid_model_with_reflected_inertia(flexible):
    q0, tau, T = np.array([0.3, 0.5]), np.array([2.0, -1.0]), 0.3
    rigid = _rigid_reflected(flexible, q0, tau, T)
    errors = {}
    for K in (1e4, 1e6):
        stiff = {p.symbol: K for p in flexible.parameters if p.name in ("K1", "K2")}
        system = FlexibleSystem(flexible.with_numeric_parameters(stiff), tau)
        Q0 = flexible_start(system, q0)
        states, _ = Adaptive("DOP853", 1e-10).run(system, Q0, np.zeros(4), np.array([0, T]))
        errors[K] = np.abs(states[-1][0][:2] - rigid).max()
    assert errors[1e6] < 2e-5 and errors[1e6] < errors[1e4] / 20, errors


def test_step_plot_is_deterministic_and_the_motor_leads(flexible, tmp_path):
    response = step_response(flexible, [-np.pi / 2, 0.0], 5.0, 0.2, points=81)
    assert response.joint == "joint1"
    lead = response.motor - response.link
    assert lead[0] == pytest.approx(0, abs=1e-12) and lead[1:20].min() > 0
    paths = [tmp_path / "a.png", tmp_path / "b.png"]
    plot_step(response, paths[0])
    plot_step(step_response(flexible, [-np.pi / 2, 0.0], 5.0, 0.2, points=81), paths[1])
    assert paths[0].read_bytes() == paths[1].read_bytes()


def test_cli_simulate_with_flexible_joints(tmp_path):
    out = tmp_path / "flex"
    result = CliRunner().invoke(main, ["simulate", str(FLEXIBLE), "--duration", "0.1",
                                       "--integrators", "rk4,radau", "--dt", "1e-3",
                                       "--rtol", "1e-6", "--quiet", "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "highest joint frequency" in result.output and "| Radau (adaptive) |" in result.output
    assert sorted(p.name for p in out.iterdir()) == [
        "flexible_step_flexible_2link.png", "simulate_flexible_2link.csv",
        "simulate_flexible_2link.md", "simulate_flexible_2link.png"]
    assert "flexible_step_flexible_2link.png" in (out / "simulate_flexible_2link.md").read_text()
