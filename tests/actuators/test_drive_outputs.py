"""The drive outputs in generated modules (issue 17): armature, friction and Spong's flexible
joints printed by every backend, against independent computations:

* the mass matrix with armature and the rigid drive torques against eomgen's numeric
  Newton–Euler (:mod:`eomgen.numeric`) plus the armature and the friction law written out here
  with NumPy (d q̇ + f sign(q̇), and f tanh(q̇ / w));
* MuJoCo's ``qM`` with ``dof_armature`` and ``qfrc_passive`` with ``dof_damping`` (UR5);
* the flexible model's accelerations, assembled from the generated functions, against
  :func:`eomgen.analysis.actuators.flexible_forward_dynamics`.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

import eomgen
from eomgen.analysis import actuators as A
from eomgen.numeric import M_rnea, numeric_model, rnea
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import erd_robots_dir
from support.generated import generated
from support.robots import FLEXIBLE_2LINK, drive_arm as arm
from support.extras import need

RIGID = ("M_a", "tau_f", "tau_f_smooth", "tau_a")
FLEXIBLE = ("M_l", "tau_K", "thetadd_m", "h", "M")


def load(model, names, folder):
    """{backend: call(function, *args) -> NumPy array} (see :mod:`generated`)."""
    return generated(model, names, folder)[0]


def test_rigid_drive_outputs_in_every_backend(tmp_path):
    model = arm()
    calls = load(model, RIGID, tmp_path)
    nm = numeric_model(model)
    a = np.array([0.3, 0.5])  # joint 2's armature B2 = 0.5 (the description's)
    d, f, w = np.array([0.4, 0.05]), np.array([0.2, 0.1]), np.array([0.5, 0.5])
    rng = np.random.default_rng(2)
    for _ in range(3):
        q, qd, qdd = (rng.uniform(-2, 2, 2) for _ in range(3))
        expected = {
            "drive_mass_matrix": M_rnea(nm, q) + np.diag(a),
            "friction_torque": d * qd + f * np.sign(qd),
            "friction_torque_smooth": d * qd + f * np.tanh(qd / w),
            "drive_inverse_dynamics": rnea(nm, q, qd, qdd) + a * qdd + d * qd + f * np.sign(qd),
        }
        args = {"drive_mass_matrix": (q,), "friction_torque": (qd,),
                "friction_torque_smooth": (qd,), "drive_inverse_dynamics": (q, qd, qdd)}
        for backend, call in calls.items():
            for name, value in expected.items():
                np.testing.assert_allclose(call(name, *args[name]), value, rtol=1e-12,
                                           atol=1e-12, err_msg=f"{backend} {name}")


def test_flexible_outputs_assemble_the_spong_model(tmp_path):
    model = arm()
    calls = load(model, FLEXIBLE, tmp_path)
    am = A.actuated_model(eomgen.derive(model))
    rng = np.random.default_rng(5)
    for _ in range(3):
        q, qd, theta_m, thetad_m, tau = (rng.uniform(-1, 1, 2) for _ in range(5))
        x = np.concatenate([q, qd, theta_m[1:], thetad_m[1:]])  # one flexible joint: joint 2
        expected = A.flexible_forward_dynamics(am, x, tau, smooth=True)
        for backend, call in calls.items():
            # the documented recipe: M_l qdd = S_R (tau - tau_f) + tau_K - h
            friction = np.array([0.4 * qd[0] + 0.2 * np.tanh(qd[0] / 0.5), 0.0])
            rhs = np.array([tau[0], 0.0]) - friction + call("spring_torque", q, theta_m) \
                - call("nonlinear_effects", q, qd)
            qdd = np.linalg.solve(call("link_mass_matrix", q), rhs)
            thetadd_m = call("motor_forward_dynamics", q, theta_m, thetad_m, tau)
            np.testing.assert_allclose(qdd, expected[2:4], rtol=1e-11, atol=1e-12,
                                       err_msg=backend)
            assert thetadd_m[0] == 0.0, backend  # joint 1 is rigid
            np.testing.assert_allclose(thetadd_m[1], expected[5], rtol=1e-11, err_msg=backend)


def test_flexible_outputs_of_a_rigid_robot_are_a_one_line_error(tmp_path):
    from click.testing import CliRunner

    from eomgen.cli import main

    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["generate", "--backend", "numpy", "--outputs",
                                       "spring_torque", "-o", str(out), "--no-cache",
                                       "--quiet"])
    assert result.exit_code == 2, result.output
    assert re.search(r"planar_2link\.yaml: tau_K need flexible joints", result.output)
    assert len(result.output.strip().splitlines()) == 1 and not out.exists()
    flexible = str(FLEXIBLE_2LINK)
    result = CliRunner().invoke(main, ["generate", flexible,
                                       "--backend", "numpy", "--outputs", "tau_K,thetadd_m,M_l",
                                       "-o", str(out), "--no-cache", "--quiet"])
    assert result.exit_code == 0, result.output
    text = (out / "flexible_2link_numpy.py").read_text()
    assert "def motor_forward_dynamics(q, theta_m, thetad_m, tau, *" in text


def test_drive_mass_matrix_and_friction_match_mujoco(tmp_path):
    mujoco = need("mujoco", reason="MuJoCo is the reference")
    robots = erd_robots_dir()
    if robots is None:
        pytest.skip("example-robot-data is not installed")
    urdf = robots / "ur_description/urdf/ur5_robot.urdf"
    model = eomgen.load(urdf)
    names = model.joint_names
    rng = np.random.default_rng(3)
    armature = dict(zip(names, rng.uniform(0.05, 0.5, len(names)).tolist()))
    damping = dict(zip(names, rng.uniform(0.1, 2.0, len(names)).tolist()))
    scene = load_scene("s.yaml", text="version: 1\nactuators:\n" + "".join(
        f"  {n}: {{armature: {armature[n]!r}, damping: {damping[n]!r}}}\n" for n in names))
    model = apply_scene(model, scene).model
    calls = load(model, ("M_a", "tau_f"), tmp_path)
    text = re.sub(r"<(visual|collision)\b.*?</\1>", "", urdf.read_text(), flags=re.S)
    m = mujoco.MjSpec.from_string(text).compile()
    vadr = [m.joint(n).dofadr[0] for n in names]
    qadr = [m.joint(n).qposadr[0] for n in names]
    for n, v in zip(names, vadr):
        m.dof_armature[v], m.dof_damping[v] = armature[n], damping[n]
    data = mujoco.MjData(m)
    q, qd = rng.uniform(-2, 2, 6), rng.uniform(-2, 2, 6)
    data.qpos[qadr], data.qvel[vadr] = q, qd
    mujoco.mj_forward(m, data)
    full = np.zeros((m.nv, m.nv))
    try:
        mujoco.mj_fullM(m, data, full)
    except TypeError:
        mujoco.mj_fullM(m, full, data.qM)
    M_ref, passive = full[np.ix_(vadr, vadr)], data.qfrc_passive[vadr]
    for backend, call in calls.items():
        M_a = call("drive_mass_matrix", q)
        assert np.abs(M_a - M_ref).max() <= 1e-10 * np.abs(M_ref).max(), backend
        assert np.abs(call("friction_torque", qd) + passive).max() <= 1e-12 * np.abs(
            passive).max(), backend
