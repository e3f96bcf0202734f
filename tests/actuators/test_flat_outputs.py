"""The flat inverse dynamics of Spong's flexible-joint model as generated functions (issue 17):
``motor_angles``, ``motor_velocities``, ``flat_motor_torque`` and ``flat_motor_torque_smooth``
printed by every backend, against :func:`eomgen.analysis.actuators.flexible_inverse_dynamics` (its own
forward-mode program, compiled separately) at random states, and fed to
:func:`eomgen.analysis.actuators.flexible_forward_dynamics`: the simulated links follow q(t).
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import eomgen
from eomgen.analysis import actuators as A
from support.generated import BACKENDS, generated as generate_all
from support.robots import FLEXIBLE_2LINK, drive_arm as arm

FLAT = ("motor_angles", "motor_velocities", "flat_motor_torque", "flat_motor_torque_smooth")


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    model = arm()  # joint 1 rigid (armature, friction), joint 2 flexible (motor friction)
    return model, generate_all(model, FLAT, tmp_path_factory.mktemp("flat"))[0], A.actuated_model(
        eomgen.derive(model))


def _trajectory(t):
    """q(t) = a sin(ω t + φ) and its derivatives up to order 4."""
    a, w, phi = np.array([0.5, -0.8]), np.array([2.0, 3.0]), np.array([0.2, 1.0])
    s, c = np.sin(w * t + phi), np.cos(w * t + phi)
    return a * s, a * w * c, -a * w ** 2 * s, -a * w ** 3 * c, a * w ** 4 * s


def test_every_backend_matches_the_numeric_flat_inverse_dynamics(generated):
    _, calls, am = generated
    assert set(calls) == set(BACKENDS)
    rng = np.random.default_rng(7)
    for _ in range(3):
        x = [rng.uniform(-2, 2, 2) for _ in range(5)]  # q, qd, qdd, qddd, qdddd
        exact, smooth = (A.flexible_inverse_dynamics(am, *x, smooth=s) for s in (False, True))
        for backend, call in calls.items():
            theta, thetad = call("motor_angles", *x[:3]), call("motor_velocities", *x[:4])
            assert theta[0] == x[0][0] and thetad[0] == x[1][0], backend  # rigid: the link's
            np.testing.assert_allclose(theta[1:], exact["theta"], rtol=1e-12, err_msg=backend)
            np.testing.assert_allclose(thetad[1:], exact["thetad"], rtol=1e-12, err_msg=backend)
            np.testing.assert_allclose(call("flat_motor_torque", *x), exact["tau"], rtol=1e-12,
                                       err_msg=backend)
            np.testing.assert_allclose(call("flat_motor_torque_smooth", *x), smooth["tau"],
                                       rtol=1e-12, err_msg=backend)


def test_generated_torques_drive_forward_dynamics_along_the_trajectory(generated):
    from scipy.integrate import solve_ivp

    _, calls, am = generated
    call = calls["numpy"]
    q0, qd0, qdd0, q30, _ = _trajectory(0.0)
    x0 = np.concatenate([q0, qd0, call("motor_angles", q0, qd0, qdd0)[1:],
                         call("motor_velocities", q0, qd0, qdd0, q30)[1:]])
    result = solve_ivp(lambda t, x: A.flexible_forward_dynamics(
        am, x, call("flat_motor_torque_smooth", *_trajectory(t)), smooth=True), (0, 1.0), x0,
        method="DOP853", rtol=1e-11, atol=1e-11, dense_output=True)
    assert result.success
    worst = max(np.abs(result.sol(t)[:2] - _trajectory(t)[0]).max()
                for t in np.linspace(0, 1.0, 11))
    assert worst < 1e-7
    # the exact-sign torque differs from the smoothed one where the motor turns slowly
    tau = [call(f, *_trajectory(0.3)) for f in ("flat_motor_torque", "flat_motor_torque_smooth")]
    assert abs(tau[0][1] - tau[1][1]) > 1e-3


def test_flat_outputs_of_a_rigid_robot_are_a_one_line_error(tmp_path):
    from click.testing import CliRunner

    from eomgen.cli import main

    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["generate", "--backend", "numpy", "--outputs",
                                       "flat_motor_torque,motor_angles", "-o", str(out),
                                       "--no-cache", "--quiet"])
    assert result.exit_code == 2, result.output
    assert re.search(r"planar_2link\.yaml: tau_flat, theta_flat need flexible joints",
                     result.output)
    assert len(result.output.strip().splitlines()) == 1 and not out.exists()
    flexible = str(FLEXIBLE_2LINK)
    result = CliRunner().invoke(main, ["generate", flexible, "--backend", "numpy", "--outputs",
                                       "tau_flat", "-o", str(out), "--no-cache", "--quiet"])
    assert result.exit_code == 0, result.output
    text = (out / "flexible_2link_numpy.py").read_text()
    assert "def flat_motor_torque(q, qd, qdd, qddd, qdddd, *" in text
