"""Identification of models with quaternion joints (``eomgen identify``, eomgen.identification):
a floating trunk (``floating_base: quaternion``) with a ball hip and a driven revolute knee.

* The chart trajectory (:mod:`eomgen.identification.charts`) is consistent: q̇ of its q(t)
  (finite differences) is ``configuration_rate(q, v)``, and v̇ is the rate of v.
* Efforts computed by Pinocchio (a model built by hand from the same numbers with
  ``JointModelFreeFlyer``, ``JointModelSpherical``, ``model.armature``, plus viscous and
  Coulomb friction written out) along such a trajectory, written as CSV with the columns
  ``q_<CONFIGURATION_NAMES>``, ``qd_/qdd_/tau_<JOINT_NAMES>``, give back the description's
  base parameters through ``eomgen identify``.
"""

from __future__ import annotations

import csv

import numpy as np
import pytest

import eomgen
from eomgen.identification import FourierTrajectory, measurements_csv, Measurements
from eomgen.identification.charts import trajectory_states
from eomgen.model.configuration import configuration_rate
from eomgen.reduction import apply_scene
from eomgen.scene import load_scene
from support import relative, run_cli, write
from support.quaternion import HOPPER, HOPPER_SCENE as SCENE
from support.extras import need

pin = need("pinocchio", reason="the data come from Pinocchio")
need("scipy", reason="identification needs scipy")

ARMATURE, DAMPING, FRICTION = 0.05, 0.3, 0.4


@pytest.fixture(scope="module")
def hopper(tmp_path_factory):
    folder = tmp_path_factory.mktemp("hopper")
    description, scene = write(folder / "hopper.yaml", HOPPER), write(folder / "s.yaml", SCENE)
    model = apply_scene(eomgen.load(description), load_scene(scene))[0]
    return folder, description, scene, model


@pytest.fixture(scope="module")
def regressor(hopper):
    """The hopper's regressor with the knee's drive columns and its base parameters."""
    from eomgen.regressor import base_parameters, derive_regressor, identification_terms

    reg = derive_regressor(hopper[3], identification_terms(hopper[3]))
    return reg, base_parameters(reg)


@pytest.fixture(scope="module")
def pinocchio_data(hopper):
    """Pinocchio's efforts along a chart trajectory, written as CSV: (path, pm, q, v, v̇)."""
    folder, _, _, model = hopper
    pm = pinocchio_hopper(model)
    assert (pm.nq, pm.nv) == (model.nq, model.dof)
    data = pm.createData()
    t = np.linspace(0.0, 4.0, 24, endpoint=False)
    q, v, vd = trajectory_states(model, trajectory(model.dof), t)
    tau = np.array([pin.rnea(pm, data, *s).copy() for s in zip(q, v, vd)])
    tau[:, -1] += DAMPING * v[:, -1] + FRICTION * np.sign(v[:, -1])
    measured = Measurements(model.joint_names, t, q, v, vd, tau, False, "<pinocchio>",
                            configuration_names=model.configuration_names)
    return write(folder / "hopper.csv", measurements_csv(measured)), pm, q, v, vd


def pinocchio_hopper(model):
    """Pinocchio's hopper, built by hand from the numbers of :data:`HOPPER`."""
    def inertia(m, c, ixx, iyy, izz, ixy=0.0):
        return pin.Inertia(m, np.array(c), np.array([[ixx, ixy, 0], [ixy, iyy, 0], [0, 0, izz]]))

    pm = pin.Model()
    root = pm.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root_joint")
    pm.appendBodyToJoint(root, inertia(3.0, [0.02, -0.01, 0.05], 0.05, 0.06, 0.04, 0.002),
                         pin.SE3.Identity())
    hip = pm.addJoint(root, pin.JointModelSpherical(),
                      pin.SE3(np.eye(3), np.array([0.1, 0.0, -0.05])), "hip")
    pm.appendBodyToJoint(hip, inertia(1.0, [0.0, 0.01, -0.15], 0.02, 0.021, 0.004),
                         pin.SE3.Identity())
    knee = pm.addJoint(hip, pin.JointModelRY(), pin.SE3(np.eye(3), np.array([0, 0, -0.3])),
                       "knee")
    pm.appendBodyToJoint(knee, inertia(0.6, [0.01, 0.0, -0.12], 0.01, 0.011, 0.002),
                         pin.SE3.Identity())
    pm.gravity = pin.Motion(np.array([float(x) for x in model.gravity]), np.zeros(3))
    armature = np.zeros(pm.nv)
    armature[-1] = ARMATURE
    pm.armature = armature
    return pm


def trajectory(nv: int, seed: int = 0) -> FourierTrajectory:
    rng = np.random.default_rng(seed)
    return FourierTrajectory(rng.uniform(-0.3, 0.3, nv), rng.uniform(-0.5, 0.5, (nv, 2)),
                             rng.uniform(-0.5, 0.5, (nv, 2)), 2 * np.pi / 4.0)


def test_chart_trajectory_is_consistent(hopper):
    model = hopper[3]
    tr, h = trajectory(model.dof, seed=1), 1e-5
    q, v, vd = trajectory_states(model, tr, np.array([0.7 - h, 0.7, 0.7 + h]))
    assert q.shape == (3, model.nq) and v.shape == (3, model.dof)
    assert relative((q[2] - q[0]) / (2 * h), configuration_rate(q[1], v[1], model)) < 1e-8
    assert relative((v[2] - v[0]) / (2 * h), vd[1]) < 1e-8


def test_csv_columns_name_configuration_and_velocity_coordinates(pinocchio_data):
    header = next(csv.reader(pinocchio_data[0].open()))
    assert header[1:8] == [f"q_base_{a}" for a in ("x", "y", "z", "qx", "qy", "qz", "qw")]
    assert header[8:13] == ["q_hip_qx", "q_hip_qy", "q_hip_qz", "q_hip_qw", "q_knee"]
    assert header[13:20] == [f"qd_base_{a}" for a in ("vx", "vy", "vz", "wx", "wy", "wz")] + [
        "qd_hip_wx"]
    assert header[-4:] == ["tau_hip_wx", "tau_hip_wy", "tau_hip_wz", "tau_knee"]


def test_base_parameters_recovered_from_pinocchio_data(hopper, regressor, pinocchio_data):
    """read_measurements → the base regressor stacked → Gautier's weighted least squares:
    β of the description, with as many base parameters as Pinocchio's regressor has rank plus
    the knee's three drive terms (none for a virtual body, nor a drive on the free flyer or
    the ball joint)."""
    from eomgen.identification import (observation_matrix, read_measurements,
                                       weighted_least_squares)
    from eomgen.regressor import description_values

    model = hopper[3]
    reg, base = regressor
    path, pm, q, v, vd = pinocchio_data
    measured = read_measurements(path, model.joint_names, None, model.configuration_names,
                                 [j.quaternion for j in model.quaternion_joints])
    assert relative(measured.q, q) == 0 and relative(measured.qdd, vd) == 0
    W = observation_matrix(reg, base.base, measured.q, measured.qd, measured.qdd)
    estimate = weighted_least_squares(W, measured.tau)
    assert relative(estimate.beta, base.beta(description_values(reg))) < 1e-8
    data = pm.createData()
    stacked = np.vstack([pin.computeJointTorqueRegressor(pm, data, *s) for s in zip(q, v, vd)])
    names = [reg.PARAMETER_NAMES[c] for c in base.base]
    assert len(names) == np.linalg.matrix_rank(stacked) + 3
    assert names[-3:] == ["IA10", "FV10", "FC10"]


@pytest.mark.slow
def test_eomgen_identify_recovers_them_too(hopper, pinocchio_data):
    folder, description, scene, _ = hopper
    out = folder / "identified"
    result = run_cli("identify", str(description), str(pinocchio_data[0]), "--scene",
                     str(scene), "-o", str(out), "--quiet")
    assert result.exit_code == 0, result.output
    rows = list(csv.DictReader((out / "identify_hopper.csv").open()))
    estimate = np.array([float(r["estimate"]) for r in rows])
    reference = np.array([float(r["description"]) for r in rows])
    assert relative(estimate, reference) < 1e-8


def test_positions_only_data_are_refused_for_quaternion_models(hopper):
    folder, description, scene, model = hopper
    names = ["t"] + [f"q_{n}" for n in model.configuration_names] + [
        f"tau_{n}" for n in model.joint_names]
    path = write(folder / "positions.csv", ",".join(names) + "\n"
                 + ",".join(["0"] * len(names)) + "\n")
    result = run_cli("identify", str(description), str(path), "--scene", str(scene),
                     "-o", str(folder / "nothing"), "--quiet")
    assert result.exit_code == 2
    assert "qd_, qdd_ columns" in result.output and "quaternion" in result.output
    assert not (folder / "nothing").exists()


def test_excitation_and_simulated_efforts_are_pinocchios(hopper, regressor):
    """One optimiser iteration of ``excitation_trajectory`` in the chart, and the efforts
    ``simulate_measurements`` gives along it (the regressor's Y π) against Pinocchio's."""
    from eomgen.identification import excitation_trajectory, simulate_measurements

    model = hopper[3]
    reg, base = regressor
    ex = excitation_trajectory(reg, base, period=4.0, harmonics=1, maxiter=1, samples=20)
    assert ex.condition <= ex.initial_condition < 1e6
    data = simulate_measurements(model, ex.trajectory, np.linspace(0, 4, 5), actuators=reg.actuators)
    assert data.q.shape == (5, model.nq) and data.position_names == model.configuration_names
    pm = pinocchio_hopper(model)
    pdata = pm.createData()
    for q, v, vd, tau in zip(data.q, data.qd, data.qdd, data.tau):
        expected = pin.rnea(pm, pdata, q, v, vd).copy()
        expected[-1] += DAMPING * v[-1] + FRICTION * np.sign(v[-1])
        assert relative(tau, expected) < 1e-12


def test_quaternion_signs_are_made_continuous_before_filtering():
    from eomgen.identification.measurements import continuous_quaternions
    angle = np.linspace(0, 3 * np.pi, 40)  # a turn and a half about z: w changes sign
    quaternion = np.column_stack([np.zeros(40), np.zeros(40), np.sin(angle / 2),
                                  np.cos(angle / 2)])
    flipped = quaternion * np.where(quaternion[:, 3:] < 0, -1.0, 1.0)  # w ≥ 0, as a sensor
    q = np.column_stack([angle, flipped])                              # might give them
    out = continuous_quaternions(q, [1])
    assert relative(out, np.column_stack([angle, quaternion])) == 0
    assert np.any(flipped != quaternion)
